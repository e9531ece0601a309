//! [`Poles`]: a list of poles (or zeros) as an engineer writes it.

use std::fmt;

use nalgebra::Complex;

use crate::model::display::number;

/// Relative distance within which two poles print as one conjugate pair.
const PAIR_RTOL: f64 = 1e-9;

/// Prints a list of poles (or zeros) as `-3.71 ± 22.2j, -5`: a conjugate
/// pair once, with `±` and its positive imaginary part; a real pole as its
/// real part; in the order given (the models' `poles()` sort them), a pair
/// where its first member stands. Numbers print as a model's do: five
/// significant digits (`{}`), a number of decimals (`{:.2}`), or the
/// shortest exact form (`{:#}`). An empty list prints nothing.
///
/// Wraps any slice: a model's `poles()`, the `poles` of an
/// [`Lqr`](crate::design::Lqr) (`.as_slice()`), a transfer function's
/// zeros.
///
/// # Examples
///
/// ```
/// use ctrlab::{Cart, MassSpring, analysis::Poles};
/// use ctrlab::nalgebra::Complex;
///
/// let p = [Complex::new(-3.71, -22.2), Complex::new(-3.71, 22.2), Complex::new(-5.0, 0.0)];
/// assert_eq!(Poles(&p).to_string(), "-3.71 ± 22.2j, -5");
/// assert_eq!(format!("{:.2}", Poles(&p)), "-3.71 ± 22.20j, -5.00");
/// // A complex pole without its conjugate keeps its sign.
/// assert_eq!(Poles(&[Complex::new(0.5, -1.0)]).to_string(), "0.5 - 1j");
///
/// // The lab's plant: two lightly damped pairs.
/// let poles = MassSpring::nominal().state_space(Cart::Two)?.poles()?;
/// assert_eq!(format!("{:.1}", Poles(&poles)), "-3.7 ± 50.2j, -3.7 ± 20.5j");
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Poles<'a>(pub &'a [Complex<f64>]);

impl fmt::Display for Poles<'_> {
    /// See [`Poles`].
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::analysis::Poles;
    /// use ctrlab::nalgebra::Complex;
    ///
    /// let p = [Complex::new(-1.0, 0.0), Complex::new(-0.1, 2.0), Complex::new(-0.1, -2.0)];
    /// assert_eq!(format!("{}", Poles(&p)), "-1, -0.1 ± 2j");
    /// ```
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let poles = self.0;
        let mut paired = vec![false; poles.len()];
        let mut first = true;
        for (i, &p) in poles.iter().enumerate() {
            if paired[i] {
                continue;
            }
            if !first {
                write!(f, ", ")?;
            }
            first = false;
            let re = number(p.re, f);
            if p.im == 0.0 {
                write!(f, "{re}")?;
                continue;
            }
            let im = number(p.im.abs(), f);
            let partner = (i + 1..poles.len())
                .find(|&j| !paired[j] && (poles[j] - p.conj()).norm() <= PAIR_RTOL * p.norm());
            match partner {
                Some(j) => {
                    paired[j] = true;
                    write!(f, "{re} ± {im}j")?;
                }
                None if p.im < 0.0 => write!(f, "{re} - {im}j")?,
                None => write!(f, "{re} + {im}j")?,
            }
        }
        Ok(())
    }
}
