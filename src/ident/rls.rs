//! Recursive least squares with exponential forgetting, fixed size.

use nalgebra::{SMatrix, SVector};

use crate::error::Error;
use crate::kernels::reduce::pow2_floor;

/// Recursive least squares for `P` parameters, with forgetting factor `μ`:
/// each [`update`](Self::update) with a row `φᵀ θ = y` costs O(P²), uses
/// only the stack and allocates nothing, so it can run inside the control
/// loop.
///
/// The update is the standard one, minimising `Σ μ^(n−k) (y(k) − φ(k)ᵀθ)²`
/// plus the prior's term:
///
/// ```text
/// e = y − φᵀθ,   g = Pφ / (μ + φᵀPφ),   θ ← θ + g e,   P ← (P − g φᵀP) / μ
/// ```
///
/// With `μ = 1` and a vague prior (`P₀ = δ I`, δ large against
/// `1/‖Φ‖²`) it converges to the batch [`LeastSquares`](super::LeastSquares)
/// estimate: it minimises `‖Φθ − λ‖² + ‖θ − θ₀‖²/δ`. With `μ < 1` old data
/// fade with time constant `1/(1 − μ)` rows; without excitation `P` then
/// grows by `1/μ` per update ("covariance wind-up"), so pause the updates
/// when the input is quiet.
///
/// # Examples
///
/// ```
/// use ctrlab::ident::Rls;
/// use ctrlab::nalgebra::vector;
///
/// let mut rls = Rls::<2>::new(1.0, 1e6)?;
/// for k in 0..100 {
///     let x = k as f64 * 0.1;
///     rls.update(&vector![1.0, x], 2.0 + 3.0 * x)?;
/// }
/// assert!((rls.theta()[0] - 2.0).abs() < 1e-4 && (rls.theta()[1] - 3.0).abs() < 1e-5);
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rls<const P: usize> {
    theta: SVector<f64, P>,
    p: SMatrix<f64, P, P>,
    forgetting: f64,
    updates: u64,
}

impl<const P: usize> Rls<P> {
    /// Starts from `θ₀ = 0` and `P₀ = p0 · I` (a large `p0` means a vague
    /// prior), with forgetting factor `forgetting` in (0, 1] (1: no
    /// forgetting).
    ///
    /// # Errors
    ///
    /// [`Error::InvalidParameter`] for a forgetting factor outside (0, 1]
    /// or a `p0` that is not finite and > 0.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::{Error, ident::Rls};
    /// assert!(Rls::<2>::new(0.99, 1e3).is_ok());
    /// assert!(matches!(Rls::<2>::new(1.5, 1e3), Err(Error::InvalidParameter { name: "forgetting", .. })));
    /// ```
    pub fn new(forgetting: f64, p0: f64) -> Result<Self, Error> {
        if !(p0.is_finite() && p0 > 0.0) {
            return Err(Error::InvalidParameter {
                name: "p0",
                value: p0,
                reason: "initial covariance scale must be finite and > 0",
            });
        }
        Self::with_prior(
            forgetting,
            SVector::zeros(),
            SMatrix::from_diagonal_element(p0),
        )
    }

    /// Starts from a prior estimate `theta0` with covariance-like matrix
    /// `p0` (symmetric positive definite; only finiteness is checked).
    ///
    /// # Errors
    ///
    /// [`Error::InvalidParameter`] for a forgetting factor outside (0, 1];
    /// [`Error::NonFinite`] for a non-finite `theta0` or `p0`.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::ident::Rls;
    /// # use ctrlab::nalgebra::{vector, matrix};
    /// let rls = Rls::with_prior(1.0, vector![950.0, 12.0], matrix![1e2, 0.0; 0.0, 1e2])?;
    /// assert_eq!(rls.theta()[0], 950.0);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn with_prior(
        forgetting: f64,
        theta0: SVector<f64, P>,
        p0: SMatrix<f64, P, P>,
    ) -> Result<Self, Error> {
        if !(forgetting > 0.0 && forgetting <= 1.0) {
            return Err(Error::InvalidParameter {
                name: "forgetting",
                value: forgetting,
                reason: "forgetting factor must be in (0, 1]",
            });
        }
        crate::error::check_finite("theta0", &theta0)?;
        crate::error::check_finite("p0", &p0)?;
        Ok(Self {
            theta: theta0,
            p: p0,
            forgetting,
            updates: 0,
        })
    }

    /// Adds the row `φᵀ θ = y` and returns the a-priori prediction error
    /// `y − φᵀθ` (before the update). Allocation-free.
    ///
    /// # Errors
    ///
    /// [`Error::InvalidParameter`] (`"phi"` or `"y"`) for a non-finite
    /// input, and [`Error::Overflow`] if the update would make the estimate
    /// non-finite; in both cases the state is left unchanged.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::ident::Rls;
    /// # use ctrlab::nalgebra::vector;
    /// let mut rls = Rls::<1>::new(1.0, 1e8)?;
    /// let e = rls.update(&vector![2.0], 6.0)?;
    /// assert_eq!(e, 6.0); // θ₀ = 0 predicted 0
    /// assert!((rls.theta()[0] - 3.0).abs() < 1e-6);
    /// assert!(rls.update(&vector![f64::NAN], 1.0).is_err());
    /// assert_eq!(rls.updates(), 1);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[inline]
    pub fn update(&mut self, phi: &SVector<f64, P>, y: f64) -> Result<f64, Error> {
        if !y.is_finite() {
            return Err(Error::InvalidParameter {
                name: "y",
                value: y,
                reason: "RLS measurement must be finite",
            });
        }
        if let Some(&bad) = phi.iter().find(|v| !v.is_finite()) {
            return Err(Error::InvalidParameter {
                name: "phi",
                value: bad,
                reason: "RLS regressor must be finite",
            });
        }
        let e = y - phi.dot(&self.theta);
        let p_phi = self.p * phi;
        let q = phi.dot(&p_phi);
        // One compare: an overflowed q (∞, or NaN from ∞ − ∞) fails it too.
        let (theta, mut p) = if q <= f64::MAX / 4.0 {
            // The textbook update, while φᵀPφ is representable.
            let gain = p_phi / (self.forgetting + q);
            // P is symmetric, so φᵀP = (Pφ)ᵀ.
            let p = (self.p - gain * p_phi.transpose()) / self.forgetting;
            (self.theta + gain * e, p)
        } else {
            self.scaled_update(phi, e)
        };
        // Symmetrise to stop round-off drift.
        p = (p + p.transpose()) * 0.5;
        if !(e.is_finite()
            && theta.iter().all(|v| v.is_finite())
            && p.iter().all(|v| v.is_finite()))
        {
            return Err(Error::Overflow {
                operation: "RLS update",
            });
        }
        self.theta = theta;
        self.p = p;
        self.updates += 1;
        Ok(e)
    }

    /// The update for a `φ` so large that `φᵀPφ` overflows (φ = 1e200
    /// would make the textbook gain 0): with `φ = s φ̃` (`s` a power of two,
    /// `max |φ̃|` in `[1, 2)`) the gain is `P φ̃ (e / s) / (μ / s² + φ̃ᵀPφ̃)`
    /// and `P ← (P − P φ̃ φ̃ᵀ P c) / μ` with `c = 1 / (μ / s² + φ̃ᵀPφ̃)`: the
    /// same algebra, without the overflow. Returns `(θ, P)` before
    /// symmetrising.
    #[cold]
    fn scaled_update(
        &self,
        phi: &SVector<f64, P>,
        e: f64,
    ) -> (SVector<f64, P>, SMatrix<f64, P, P>) {
        let s = pow2_floor(phi.amax());
        let phi = phi * (1.0 / s);
        let p_phi = self.p * phi;
        let denom = self.forgetting / s / s + phi.dot(&p_phi);
        // Both terms underflowed: φ̃ᵀPφ̃ = 0, so Pφ̃ = 0 (P is positive
        // semidefinite) and there is nothing to learn along φ.
        let (step, c) = if denom == 0.0 {
            (0.0, 0.0)
        } else {
            (e / s / denom, 1.0 / denom)
        };
        let p = (self.p - p_phi * (p_phi.transpose() * c)) / self.forgetting;
        (self.theta + p_phi * step, p)
    }

    /// The current estimate `θ`.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::ident::Rls;
    /// assert_eq!(Rls::<3>::new(1.0, 1.0)?.theta().len(), 3);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn theta(&self) -> &SVector<f64, P> {
        &self.theta
    }

    /// The current matrix `P` (the covariance of `θ` up to the noise
    /// variance factor).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::ident::Rls;
    /// # use ctrlab::nalgebra::vector;
    /// let mut rls = Rls::<1>::new(1.0, 100.0)?;
    /// rls.update(&vector![1.0], 1.0)?;
    /// assert!(rls.covariance()[(0, 0)] < 1.0); // one observation shrinks it
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn covariance(&self) -> &SMatrix<f64, P, P> {
        &self.p
    }

    /// The forgetting factor.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::ident::Rls;
    /// assert_eq!(Rls::<2>::new(0.98, 1.0)?.forgetting(), 0.98);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn forgetting(&self) -> f64 {
        self.forgetting
    }

    /// Number of successful updates.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::ident::Rls;
    /// assert_eq!(Rls::<2>::new(1.0, 1.0)?.updates(), 0);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn updates(&self) -> u64 {
        self.updates
    }
}
