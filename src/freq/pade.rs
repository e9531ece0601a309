//! Rational approximations of a time delay `e^{−sT}` ([`pade`]).

use super::TransferFunction;
use crate::error::Error;

/// The highest denominator degree [`pade`] takes. Past about 10 the
/// coefficients span more decades than a double resolves (at T = 1 the
/// constant term of order 20 is 1.3e30 times the leading one), and a
/// delay that needs it is better simulated as a delay.
///
/// # Examples
///
/// ```
/// use ctrlab::freq::{MAX_PADE_ORDER, pade};
/// // Order 20 is the last taken: degree 20 over degree 20.
/// assert_eq!(pade(0.01, MAX_PADE_ORDER)?.den().len(), MAX_PADE_ORDER + 1);
/// assert!(pade(0.01, MAX_PADE_ORDER + 1).is_err());
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub const MAX_PADE_ORDER: usize = 20;

/// The Padé approximation of order `order` of a delay of `delay` seconds:
/// the transfer function `N(s) / D(s)` of degree `order` over `order`
/// whose Taylor series matches `e^{−s·delay}` to the highest power, all-pass
/// (`|N(jω) / D(jω)| = 1`), with `D` monic. A zero delay gives `1 / 1`.
///
/// The coefficients are those of python-control's `pade(T, n)` and
/// MATLAB's `pade(T, N)` (Golub and Van Loan, *Matrix Computations*,
/// algorithm 11.3.1): `N(s) = Σ c_k (−sT)^k`, `D(s) = Σ c_k (sT)^k` with
/// `c_k = (2n − k)! n! / ((2n)! k! (n − k)!)`, scaled so that `D` is monic.
///
/// # Errors
///
/// [`Error::InvalidParameter`] for a negative or non-finite `delay` (named
/// `"delay"`) or an `order` above [`MAX_PADE_ORDER`] (named `"order"`);
/// [`Error::Overflow`] when a coefficient is not representable (a delay of
/// 1e300 s at order 2, say).
///
/// # Examples
///
/// A 0.1 s delay to first order, `(−s + 20) / (s + 20)`:
///
/// ```
/// use ctrlab::freq::pade;
/// let d = pade(0.1, 1)?;
/// assert_eq!((d.num(), d.den()), (&[-1.0, 20.0][..], &[1.0, 20.0][..]));
/// // All-pass, and at low frequency the delay's phase, −ωT.
/// let g = d.evaluate(ctrlab::nalgebra::Complex::new(0.0, 1.0))?;
/// assert!((g.norm() - 1.0).abs() < 1e-15);
/// assert!((g.arg() + 0.1).abs() < 1e-4);
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub fn pade(delay: f64, order: usize) -> Result<TransferFunction, Error> {
    pade_with_degrees(delay, order, order)
}

/// The Padé approximation of a delay of `delay` seconds with a numerator
/// of degree `numerator_degree` under a denominator of degree
/// `denominator_degree` (python-control's `pade(T, n, numdeg)`): strictly
/// proper when the numerator's degree is lower, which a simulation of
/// `D = 0` models needs. `N(s) = Σ a_k (−sT)^k` with `a_k = (p + q − k)!
/// q! / ((p + q)! k! (q − k)!)` (q the numerator's degree, p the
/// denominator's), `D(s)` likewise with `p`; `D` monic.
///
/// # Errors
///
/// As [`pade`], and [`Error::InvalidParameter`] named `"numerator_degree"`
/// when it exceeds the denominator's.
///
/// # Examples
///
/// Vajta's table (python-control's reference): degrees 1 over 2 at T = 1
/// are `(−2s + 6) / (s² + 4s + 6)`.
///
/// ```
/// use ctrlab::freq::pade_with_degrees;
/// let d = pade_with_degrees(1.0, 1, 2)?;
/// assert_eq!(d.num(), &[-2.0, 6.0]);
/// assert_eq!(d.den(), &[1.0, 4.0, 6.0]);
/// assert!(pade_with_degrees(1.0, 3, 2).is_err());
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[doc(alias = "pade")]
pub fn pade_with_degrees(
    delay: f64,
    numerator_degree: usize,
    denominator_degree: usize,
) -> Result<TransferFunction, Error> {
    if !(delay.is_finite() && delay >= 0.0) {
        return Err(Error::InvalidParameter {
            name: "delay",
            value: delay,
            reason: "must be finite and ≥ 0 (s)",
        });
    }
    let (q, p) = (numerator_degree, denominator_degree);
    if p > MAX_PADE_ORDER {
        return Err(Error::InvalidParameter {
            name: "order",
            value: p as f64,
            reason: "at most MAX_PADE_ORDER (20)",
        });
    }
    if q > p {
        return Err(Error::InvalidParameter {
            name: "numerator_degree",
            value: q as f64,
            reason: "must not exceed the denominator's degree",
        });
    }
    if delay == 0.0 {
        return TransferFunction::continuous(&[1.0], &[1.0]);
    }
    // Descending powers; the constant terms are 1, then each power's
    // coefficient from the one below it, as python-control accumulates
    // them (the same operations, so the same roundings).
    let (qf, pf) = (q as f64, p as f64);
    let mut num = vec![0.0; q + 1];
    num[q] = 1.0;
    let mut c = 1.0;
    for k in 1..=q {
        let kf = k as f64;
        c *= -delay * (qf - kf + 1.0) / (qf + pf - kf + 1.0) / kf;
        num[q - k] = c;
    }
    let mut den = vec![0.0; p + 1];
    den[p] = 1.0;
    let mut c = 1.0;
    for k in 1..=p {
        let kf = k as f64;
        c *= delay * (pf - kf + 1.0) / (qf + pf - kf + 1.0) / kf;
        den[p - k] = c;
    }
    let lead = den[0];
    let scaled = |v: &mut Vec<f64>| v.iter_mut().for_each(|x| *x /= lead);
    scaled(&mut num);
    scaled(&mut den);
    let representable = |v: &[f64]| v.iter().all(|x| x.is_finite() && *x != 0.0);
    if !(lead.is_finite() && lead != 0.0 && representable(&num) && representable(&den)) {
        return Err(Error::Overflow {
            operation: "Padé approximation (the delay is too long or too short for the order)",
        });
    }
    TransferFunction::continuous(&num, &den)
}
