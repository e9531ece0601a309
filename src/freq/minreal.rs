//! Pole-zero cancellation in a transfer function (`minreal`).

use super::poly;
use super::tf::TransferFunction;
use crate::error::Error;
use crate::model::Domain;

impl<D: Domain> TransferFunction<D> {
    /// The transfer function with its cancelling pole-zero pairs removed
    /// (MATLAB's and python-control's `minreal`), as python-control 0.10.2
    /// does it: each zero `z` in turn cancels the first remaining pole
    /// within `tol` of it, by default `1000 max(ε, |z| √ε)`; the result is
    /// `(b₀ / a₀) ∏(s − zᵢ) / ∏(s − pⱼ)` over what remains, with the
    /// leading coefficients `b₀`, `a₀` of the numerator and denominator
    /// (so its denominator is monic).
    ///
    /// # Errors
    ///
    /// [`Error::InvalidParameter`] (`"tol"`) for a negative or non-finite
    /// tolerance; the errors of [`poles`](Self::poles) and
    /// [`zeros`](Self::zeros); [`Error::Overflow`] if the gain or a
    /// coefficient is not finite.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::freq::TransferFunction;
    ///
    /// // 2 (s + 1) / ((s + 1)(s + 3)) = 2 / (s + 3).
    /// let g = TransferFunction::continuous(&[2.0, 2.0], &[1.0, 4.0, 3.0])?;
    /// let m = g.minimal_realization(None)?;
    /// assert_eq!(m.num(), &[2.0]);
    /// assert!((m.den()[0] - 1.0).abs() < 1e-15 && (m.den()[1] - 3.0).abs() < 1e-12);
    /// // No pole within 1e-3 of the zero at −1.01: nothing cancels ...
    /// let h = TransferFunction::continuous(&[1.0, 1.01], &[1.0, 4.0, 3.0])?;
    /// assert_eq!(h.minimal_realization(Some(1e-3))?.den().len(), 3);
    /// // ... but within 0.1 it does.
    /// assert_eq!(h.minimal_realization(Some(0.1))?.den().len(), 2);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[doc(alias = "minreal")]
    pub fn minimal_realization(&self, tol: Option<f64>) -> Result<Self, Error> {
        crate::analysis::minreal::check_tolerance(
            tol,
            "the cancellation tolerance must be finite and non-negative",
        )?;
        let zeros = self.zeros()?;
        let mut poles = self.poles()?;
        let gain = self.num()[0] / self.den()[0];
        if !gain.is_finite() {
            return Err(Error::Overflow {
                operation: "minreal (gain num₀ / den₀)",
            });
        }
        let sqrt_eps = f64::EPSILON.sqrt();
        let mut kept = Vec::with_capacity(zeros.len());
        for z in zeros {
            let t = tol.unwrap_or_else(|| 1000.0 * f64::EPSILON.max(z.norm() * sqrt_eps));
            match poles.iter().position(|p| (z - p).norm() < t) {
                Some(i) => {
                    poles.remove(i);
                }
                None => kept.push(z),
            }
        }
        let num: Vec<f64> = poly::from_roots(&kept).iter().map(|c| gain * c).collect();
        let den = poly::from_roots(&poles);
        if num.iter().chain(&den).any(|c| !c.is_finite()) {
            return Err(Error::Overflow {
                operation: "minreal",
            });
        }
        Self::with_domain(&num, &den, self.domain())
    }
}
