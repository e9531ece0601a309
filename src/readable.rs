//! Numbers in messages: short and exact. `Display` for `f64` writes every
//! digit of `1e300` (301 characters) and of `1e-300`; an error message
//! should not.

use std::fmt;

/// An `f64` as a message shows it: the shortest digits that read back to
/// the same value, in positional form between 1e-4 and 1e15 (`0.002`,
/// `1500`), in exponent form outside (`1e300`, `5e-324`); `NaN`, `inf`,
/// `-inf` as Rust writes them. At most 24 characters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Readable(pub(crate) f64);

impl fmt::Display for Readable {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let x = self.0;
        let magnitude = x.abs();
        if !x.is_finite() || x == 0.0 || (1e-4..1e15).contains(&magnitude) {
            write!(f, "{x}")
        } else {
            write!(f, "{x:e}")
        }
    }
}

#[cfg(test)]
mod tests {
    use super::Readable;
    use proptest::prelude::*;

    #[test]
    fn extremes_are_short_and_ordinary_numbers_positional() {
        let cases = [
            (1e300, "1e300"),
            (-1e-300, "-1e-300"),
            (5e-324, "5e-324"),
            (f64::MAX, "1.7976931348623157e308"),
            (0.002, "0.002"),
            (1500.0, "1500"),
            (-0.0, "-0"),
            (f64::NAN, "NaN"),
            (f64::NEG_INFINITY, "-inf"),
            (1e15, "1e15"),
            (1e-5, "1e-5"),
        ];
        for (x, text) in cases {
            assert_eq!(Readable(x).to_string(), text, "{x:?}");
        }
    }

    proptest! {
        /// Short, and exact: every finite value reads back bit for bit.
        #[test]
        fn reads_back_exactly_in_at_most_24_characters(bits in any::<u64>()) {
            let x = f64::from_bits(bits);
            let text = Readable(x).to_string();
            prop_assert!(text.len() <= 24, "{text}");
            if x.is_finite() {
                prop_assert_eq!(text.parse::<f64>().unwrap().to_bits(), x.to_bits());
            }
        }
    }
}
