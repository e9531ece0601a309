//! Model reduction by balanced truncation, square-root method (MATLAB's
//! `balred`), on both model types: the run-time-sized implementation
//! here, which the fixed-size method calls.

use nalgebra::DMatrix;

use super::gramian::{GramianKind, HankelSvd, gramian_factor, hankel_svd};
use crate::error::Error;
#[cfg(doc)]
use crate::model::Continuous;
use crate::model::{Domain, DynStateSpace, StateSpace};

const OPERATION: &str = "balred";

/// How many states [`DynStateSpace::balred`] keeps.
///
/// # Examples
///
/// ```
/// use ctrlab::DynStateSpace;
/// use ctrlab::analysis::ReducedOrder;
/// use ctrlab::nalgebra::dmatrix;
///
/// let sys = DynStateSpace::continuous(dmatrix![-1.0, 0.0; 0.0, -10.0], dmatrix![1.0; 1.0],
///                                     dmatrix![1.0, 0.1], dmatrix![0.0])?;
/// // σ ≈ [0.50, 0.0033]: a tolerance of 0.01 keeps one state.
/// assert_eq!(sys.balred(ReducedOrder::Tolerance(0.01))?.model.states(), 1);
/// assert_eq!(sys.balred(ReducedOrder::States(2))?.model.states(), 2);
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ReducedOrder {
    /// Keep exactly this many states (at most the model's).
    States(usize),
    /// Keep every state whose Hankel singular value is above this
    /// tolerance (output units per input unit, absolute; finite, `≥ 0`),
    /// and any state tied with the last one kept (see
    /// [`DynStateSpace::balred`]).
    Tolerance(f64),
}

/// A reduced model from balanced truncation, with the Hankel singular
/// values of the full model and the error bound.
///
/// # Examples
///
/// ```
/// use ctrlab::DynStateSpace;
/// use ctrlab::analysis::ReducedOrder;
/// use ctrlab::nalgebra::dmatrix;
///
/// let sys = DynStateSpace::continuous(dmatrix![-1.0, 0.0; 0.0, -10.0], dmatrix![1.0; 1.0],
///                                     dmatrix![1.0, 0.1], dmatrix![0.0])?;
/// let reduced = sys.balred(ReducedOrder::States(1))?;
/// assert_eq!((reduced.model.states(), reduced.hankel.len()), (1, 2));
/// // The bound is twice the Hankel singular value dropped.
/// assert!((reduced.error_bound - 2.0 * reduced.hankel[1]).abs() < 1e-15);
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct BalancedTruncation<S> {
    /// The reduced model: `r` states, the inputs, outputs, `D` and time
    /// domain of the full one; in continuous time its realisation is
    /// balanced (both Gramians `diag(σ₁ … σᵣ)`), in discrete time it is
    /// the truncated block of the balanced full model (whose Gramians
    /// differ from `diag(σ₁ … σᵣ)`).
    pub model: S,
    /// The full model's Hankel singular values, descending (as
    /// [`DynStateSpace::hsvd`]).
    pub hankel: Vec<f64>,
    /// `2 Σ_{i>r} σᵢ`: a bound on the peak gain of the error,
    /// `‖G − Gᵣ‖_∞` (largest singular value over all frequencies, output
    /// units per input unit). Repeated values are counted each time, so
    /// where some are equal it is looser than Glover's bound (each
    /// distinct value once).
    pub error_bound: f64,
}

/// The relative gap `100 n ε` (times `σ₁`) below which two Hankel
/// singular values count as equal, and a value as zero: the values come
/// from an SVD of `Ro Rcᵀ` accurate to a few `ε σ₁`.
fn tie(n: usize, sigma1: f64) -> f64 {
    100.0 * n as f64 * f64::EPSILON * sigma1
}

/// The number of states to keep for `order`, given `σ` descending.
fn kept(order: ReducedOrder, sigma: &[f64]) -> Result<usize, Error> {
    let n = sigma.len();
    let tol = tie(n, sigma.first().copied().unwrap_or(0.0));
    let splits = |r: usize| r > 0 && r < n && sigma[r - 1] - sigma[r] <= tol;
    match order {
        ReducedOrder::States(r) => {
            if r > n {
                return Err(Error::InvalidParameter {
                    name: "order",
                    value: r as f64,
                    reason: "more states than the model has",
                });
            }
            if r > 0 && sigma[r - 1] <= tol {
                return Err(Error::InvalidParameter {
                    name: "order",
                    value: r as f64,
                    reason: "keeps a state whose Hankel singular value is zero to rounding \
                             (uncontrollable or unobservable): ask for fewer states",
                });
            }
            if splits(r) {
                return Err(Error::InvalidParameter {
                    name: "order",
                    value: r as f64,
                    reason: "falls inside a group of equal Hankel singular values, which \
                             balanced truncation cannot split: keep the whole group or none",
                });
            }
            Ok(r)
        }
        ReducedOrder::Tolerance(t) => {
            if !(t.is_finite() && t >= 0.0) {
                return Err(Error::InvalidParameter {
                    name: "tolerance",
                    value: t,
                    reason: "the Hankel singular value tolerance must be finite and non-negative",
                });
            }
            let floor = t.max(tol);
            let mut r = sigma.iter().filter(|&&s| s > floor).count();
            // A group of equal values straddling the tolerance is kept
            // whole, short of its members that are zero to rounding.
            while splits(r) && sigma[r] > tol {
                r += 1;
            }
            Ok(r)
        }
    }
}

impl<D: Domain> DynStateSpace<D> {
    /// Balanced truncation of a stable model by the square-root method
    /// (Tombs and Postlethwaite 1987; MATLAB's `balred` with its
    /// default balanced-truncation method): `r` states kept
    /// ([`ReducedOrder`]), the reduced model in the same time domain.
    ///
    /// With `Wc = Rcᵀ Rc` and `Wo = Roᵀ Ro` ([`gram_factor`](Self::gram_factor))
    /// and the SVD `Ro Rcᵀ = U Σ Vᵀ` (the Hankel singular values,
    /// [`hsvd`](Self::hsvd)), `T = Rcᵀ Vᵣ Σᵣ^(−1/2)` and
    /// `L = Roᵀ Uᵣ Σᵣ^(−1/2)` (`Lᵀ T = I`) give
    /// `(Lᵀ A T, Lᵀ B, C T, D)`, never inverting a Gramian. In either
    /// time domain the reduced model is stable when `σᵣ > σᵣ₊₁` (Pernebo
    /// and Silverman 1982; Al-Saggaf and Franklin 1987 for discrete time),
    /// and `‖G − Gᵣ‖_∞ ≤ 2 Σ_{i>r} σᵢ`
    /// ([`BalancedTruncation::error_bound`]). `D` is kept, so the DC gain
    /// is not matched (MATLAB's `'Truncate'`, not `'MatchDC'`).
    ///
    /// Equal Hankel singular values (within `100 n ε σ₁`) cannot be split:
    /// their balanced states are any rotation of each other, and keeping
    /// part of the group gives a reduced model that depends on rounding
    /// and need not be stable. `ReducedOrder::States(r)` with `σᵣ` tied to
    /// `σᵣ₊₁` is refused, as is an `r` that keeps a `σ` that is zero to
    /// that tolerance (an uncontrollable or unobservable state, which
    /// `Σᵣ^(−1/2)` would divide by); `ReducedOrder::Tolerance` keeps the
    /// whole group that straddles it, and never keeps a zero `σ`.
    ///
    /// The states of the result are signed as the SVD leaves them:
    /// another implementation's reduced model may differ by the sign of a
    /// state (its transfer function does not).
    ///
    /// # Errors
    ///
    /// [`Error::Unstable`] (operation `"balred"`) naming the first pole on
    /// or outside the stability boundary; [`Error::InvalidParameter`]
    /// named `"order"` for more states than the model's, a tied or zero
    /// `σᵣ` as above, or `"tolerance"` for a negative or non-finite one;
    /// as [`hsvd`](Self::hsvd); [`Error::Overflow`] if the reduced
    /// matrices overflow.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::DynStateSpace;
    /// use ctrlab::analysis::ReducedOrder;
    /// use ctrlab::nalgebra::dmatrix;
    ///
    /// // Two decoupled channels with σ = 3 and 1/4: dropping the second
    /// // costs its peak gain 1/2, the bound 2 σ₂.
    /// let sys = DynStateSpace::continuous(dmatrix![-1.0, 0.0; 0.0, -2.0],
    ///                                     dmatrix![2.0, 0.0; 0.0, 1.0],
    ///                                     dmatrix![3.0, 0.0; 0.0, 1.0], dmatrix![0.0, 0.0; 0.0, 0.0])?;
    /// let red = sys.balred(ReducedOrder::States(1))?;
    /// assert!((red.error_bound - 0.5).abs() < 1e-15);
    /// assert!((red.model.a()[(0, 0)] + 1.0).abs() < 1e-14);
    /// assert!((red.model.dc_gain()?[(0, 0)] - 6.0).abs() < 1e-13);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[doc(alias = "balanced_truncation")]
    #[doc(alias = "balreal")]
    pub fn balred(&self, order: ReducedOrder) -> Result<BalancedTruncation<Self>, Error> {
        let rc = gramian_factor(self, GramianKind::Controllability, OPERATION)?.factor;
        let ro = gramian_factor(self, GramianKind::Observability, OPERATION)?.factor;
        let HankelSvd { u, sigma, v } = hankel_svd(&rc, &ro, OPERATION)?;
        let r = kept(order, &sigma)?;
        let n = self.states();
        let scale = DMatrix::from_fn(
            r,
            r,
            |i, j| {
                if i == j { sigma[i].sqrt().recip() } else { 0.0 }
            },
        );
        let t = rc.transpose() * v.columns(0, r) * &scale;
        let l = ro.transpose() * u.columns(0, r) * &scale;
        let lt = l.transpose();
        let model = Self::from_computed(
            &lt * self.a() * &t,
            &lt * self.b(),
            self.c() * &t,
            self.d().clone(),
            self.domain(),
            OPERATION,
        )?;
        let error_bound = 2.0 * sigma[r..n].iter().sum::<f64>();
        Ok(BalancedTruncation {
            model,
            hankel: sigma,
            error_bound,
        })
    }
}

impl<const N: usize, const M: usize, const P: usize, D: Domain> StateSpace<N, M, P, D> {
    /// Balanced truncation to `R` states, `R` fixed at compile time
    /// (`sys.balred::<2>()`): [`DynStateSpace::balred`] with
    /// `ReducedOrder::States(R)`, the result a `StateSpace<R, M, P, D>` in
    /// the same time domain ([`Continuous`] or discrete) as `self`.
    ///
    /// # Errors
    ///
    /// As [`DynStateSpace::balred`]: [`Error::InvalidParameter`] named
    /// `"order"` for `R > N`, or for an `R` that splits a group of equal
    /// Hankel singular values or keeps a zero one; [`Error::Unstable`] for
    /// an unstable model.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{Cart, MassSpring, StateSpace};
    ///
    /// // The rig's two modes, reduced to the first: a 2-state model of
    /// // cart 2 within the bound of the full one at every frequency.
    /// let plant = MassSpring::nominal().state_space(Cart::Two)?;
    /// let red = plant.balred::<2>()?;
    /// let reduced: StateSpace<2, 1, 1> = red.model;
    /// assert!(reduced.is_stable()?);
    /// assert!(red.hankel[1] > red.hankel[2]);
    /// assert!((plant.dc_gain()? - reduced.dc_gain()?).amax() <= red.error_bound);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[doc(alias = "balanced_truncation")]
    pub fn balred<const R: usize>(
        &self,
    ) -> Result<BalancedTruncation<StateSpace<R, M, P, D>>, Error> {
        let BalancedTruncation {
            model,
            hankel,
            error_bound,
        } = DynStateSpace::from(self).balred(ReducedOrder::States(R))?;
        Ok(BalancedTruncation {
            model: StateSpace::try_from(&model)?,
            hankel,
            error_bound,
        })
    }
}
