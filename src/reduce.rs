//! Vectorisable reductions over long columns.
//!
//! A plain `iter().sum()` over `f64` is one long chain of dependent adds
//! (the compiler may not reassociate floating point), about four cycles per
//! element. Eight independent accumulators let it use SIMD lanes; the result
//! differs from the sequential sum only by rounding (pairwise-like, usually
//! more accurate).

const LANES: usize = 8;

/// `Σ f(x)` with eight independent accumulators.
#[inline]
pub(crate) fn sum_by(x: &[f64], f: impl Fn(f64) -> f64) -> f64 {
    let mut acc = [0.0f64; LANES];
    let chunks = x.chunks_exact(LANES);
    let rest = chunks.remainder();
    for c in chunks {
        for i in 0..LANES {
            acc[i] += f(c[i]);
        }
    }
    let mut tail = 0.0;
    for &v in rest {
        tail += f(v);
    }
    ((acc[0] + acc[4]) + (acc[1] + acc[5])) + ((acc[2] + acc[6]) + (acc[3] + acc[7])) + tail
}

/// Index of the first non-finite value, if any. The fast path is one
/// vectorised pass (`0 · x` is NaN exactly for NaN and ±∞).
#[inline]
pub(crate) fn first_non_finite(x: &[f64]) -> Option<usize> {
    if sum_by(x, |v| v * 0.0) == 0.0 {
        None
    } else {
        x.iter().position(|v| !v.is_finite())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sums_and_finds_non_finite() {
        let x: Vec<f64> = (1..=21).map(f64::from).collect();
        assert_eq!(sum_by(&x, |v| v), 231.0);
        assert_eq!(sum_by(&x, |v| v * v), 3311.0);
        assert_eq!(first_non_finite(&x), None);
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            let mut y = x.clone();
            y[13] = bad;
            assert_eq!(first_non_finite(&y), Some(13));
        }
        assert_eq!(first_non_finite(&[]), None);
    }
}
