//! Discrete → continuous conversion, the inverse of each
//! [`Discretization`]: MATLAB's `d2c`. SciPy has none; its
//! `cont2discrete` followed by this recovers the continuous model (the
//! fixtures in `tests/data/d2c.json` check it).

use nalgebra::{DMatrix, DefaultAllocator, Dim, OMatrix, allocator::Allocator};

use super::logm::held_log;
use super::{Discretization, Held, ModelAlloc, Parts};
use crate::analysis::eigenvalues_dyn;
use crate::error::Error;
use crate::kernels::linalg::{Lu, frobenius};
use crate::model::{Continuous, Discrete, DynStateSpace, StateSpace};

/// Eigenvalues within this many `n ε (1 + ‖Ad‖_F)` of the pole an
/// inverse bilinear transform cannot map (`z = −1` for Tustin, `z = 0` for
/// backward Euler) are taken to be on it.
const POLE_FACTOR: f64 = 100.0;

impl<const N: usize, const M: usize, const P: usize> StateSpace<N, M, P, Discrete> {
    /// The continuous model whose discretisation by `method` at this
    /// model's period is this model: MATLAB's `d2c(sys, method)`.
    ///
    /// With `h` the period (s) and `α` the weight of
    /// [`Discretization`] (Tustin ½, forward Euler 0, backward Euler 1):
    ///
    /// - ZOH: `[[A h, B h], [0, 0]] = log([[Ad, Bd], [0, I]])`, the
    ///   principal matrix logarithm ([`logm`](super::logm)); `C = Cd`,
    ///   `D = Dd`. It exists, real, when no eigenvalue of `Ad` lies on the
    ///   closed negative real axis, and recovers a continuous model
    ///   exactly when its poles satisfy `|Im λ| h < π` (below the Nyquist
    ///   frequency); otherwise it returns the model of the principal
    ///   branch, which has the same discretisation.
    /// - The others invert `Ad = W (I + (1 − α) h A)`, `W = (I − α h A)⁻¹`:
    ///   with `V = α Ad + (1 − α) I` (which is `W`),
    ///   `A = (Ad − I) V⁻¹ / h`, `B = V⁻¹ Bd / h`, `C = Cd V⁻¹`,
    ///   `D = Dd − α C Bd` (Tustin and backward Euler change `C` and `D`
    ///   back; forward Euler keeps them).
    ///
    /// # Errors
    ///
    /// - [`Error::EigenvalueOutOfDomain`] naming the eigenvalue of `Ad`:
    ///   on the closed negative real axis or at 0 (ZOH), at `z = −1`
    ///   (Tustin), at `z = 0` (backward Euler);
    /// - [`Error::Singular`] when `V` is singular to working precision
    ///   without an eigenvalue there (Tustin, backward Euler);
    /// - [`Error::IllConditioned`] (ZOH) when the estimated relative
    ///   error of the logarithm exceeds
    ///   [`LOGM_MAX_ERROR`](super::LOGM_MAX_ERROR): a mode that decayed to
    ///   rounding within one period, a complex pair near the negative real
    ///   axis, or a period so short that `Ad` holds `A` in few digits;
    /// - [`Error::Overflow`] when the result is not representable,
    ///   [`Error::NoConvergence`] if a square-root iteration fails.
    ///
    /// (NaN entries and a period that is not finite and positive are
    /// refused when the discrete model is built.)
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{Discretization, StateSpace};
    /// use ctrlab::nalgebra::matrix;
    ///
    /// // x[k+1] = ad x[k] + bd u[k]: a = ln(ad)/h, b = bd a/(ad − 1).
    /// let (ad, bd, h) = (0.9f64, 0.2, 0.1);
    /// let sys = StateSpace::discrete(matrix![ad], matrix![bd], matrix![1.0], matrix![0.0], h)?;
    /// let c = sys.d2c(Discretization::Zoh)?;
    /// let a = ad.ln() / h;
    /// assert!((c.a()[(0, 0)] - a).abs() < 1e-14);
    /// assert!((c.b()[(0, 0)] - bd * a / (ad - 1.0)).abs() < 1e-14);
    /// // And back.
    /// let again = c.discretize(h, Discretization::Zoh)?;
    /// assert!((again.a() - sys.a()).amax() < 1e-15);
    ///
    /// // A pole at z = −0.5 has no continuous counterpart under ZOH.
    /// let alias = StateSpace::discrete(matrix![-0.5], matrix![1.0], matrix![1.0], matrix![0.0], h)?;
    /// assert!(alias.d2c(Discretization::Zoh).is_err());
    /// assert!(alias.d2c(Discretization::Tustin).is_ok());
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[doc(alias = "undiscretize")]
    pub fn d2c(&self, method: Discretization) -> Result<StateSpace<N, M, P, Continuous>, Error> {
        let ((a, b, c, d), operation) =
            d2c_parts((self.a(), self.b(), self.c(), self.d()), self.dt(), method)?;
        let mut all = a.iter().chain(b.iter()).chain(c.iter()).chain(d.iter());
        if all.any(|v| !v.is_finite()) {
            return Err(Error::Overflow { operation });
        }
        Ok(StateSpace::from_parts_unchecked(a, b, c, d, Continuous))
    }
}

impl DynStateSpace<Discrete> {
    /// The continuous model whose discretisation by `method` at this
    /// model's period is this model: the algorithm of
    /// [`StateSpace::d2c`] (see there for the formulas) on run-time sizes.
    ///
    /// # Errors
    ///
    /// As [`StateSpace::d2c`]: [`Error::EigenvalueOutOfDomain`],
    /// [`Error::Singular`], [`Error::IllConditioned`],
    /// [`Error::Overflow`], [`Error::NoConvergence`].
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{Discretization, DynStateSpace};
    /// use ctrlab::nalgebra::dmatrix;
    ///
    /// // A lightly damped mode, force input, sampled at 20 ms by Tustin.
    /// let sys = DynStateSpace::continuous(
    ///     dmatrix![0.0, 1.0; -100.0, -2.0], dmatrix![0.0; 1.0],
    ///     dmatrix![1.0, 0.0], dmatrix![0.0])?;
    /// for method in [Discretization::Zoh, Discretization::Tustin,
    ///                Discretization::ForwardEuler, Discretization::BackwardEuler] {
    ///     let back = sys.discretize(0.02, method)?.d2c(method)?;
    ///     assert!((back.a() - sys.a()).amax() < 1e-11);
    ///     assert!((back.b() - sys.b()).amax() < 1e-12);
    ///     assert!((back.d() - sys.d()).amax() < 1e-14);
    /// }
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[doc(alias = "undiscretize")]
    pub fn d2c(&self, method: Discretization) -> Result<DynStateSpace<Continuous>, Error> {
        let ((a, b, c, d), operation) =
            d2c_parts((self.a(), self.b(), self.c(), self.d()), self.dt(), method)?;
        DynStateSpace::from_computed(a, b, c, d, Continuous, operation)
    }
}

/// `(A, B, C, D)` of the discrete `(Ad, Bd, Cd, Dd)` at period `h` by the
/// inverse of `method`, with the operation's name for an overflow.
fn d2c_parts<N: Dim, M: Dim, P: Dim>(
    sys: PartsRef<'_, N, M, P>,
    h: f64,
    method: Discretization,
) -> Result<(Parts<N, M, P>, &'static str), Error>
where
    DefaultAllocator: ModelAlloc<N, M, P>,
{
    let (alpha, operation) = match method {
        Discretization::Zoh => {
            const OP: &str = "ZOH d2c (matrix logarithm of [[Ad, Bd], [0, I]])";
            let (a, b) = zoh_inverse(sys.0, sys.1, h, OP)?;
            return Ok(((a, b, sys.2.clone(), sys.3.clone()), OP));
        }
        Discretization::Tustin => (0.5, "Tustin d2c"),
        Discretization::ForwardEuler => (0.0, "forward Euler d2c"),
        Discretization::BackwardEuler => (1.0, "backward Euler d2c"),
    };
    Ok((gbt_inverse(sys, h, alpha, operation)?, operation))
}

/// `(Ad, Bd, Cd, Dd)` borrowed.
type PartsRef<'a, N, M, P> = (
    &'a OMatrix<f64, N, N>,
    &'a OMatrix<f64, N, M>,
    &'a OMatrix<f64, P, N>,
    &'a OMatrix<f64, P, M>,
);

/// `(A, B)` of a ZOH discretisation `(Ad, Bd)`: the upper blocks of the
/// logarithm of `[[Ad, Bd], [0, I]]` over `h`, on the blocks alone.
fn zoh_inverse<N: Dim, M: Dim>(
    ad: &OMatrix<f64, N, N>,
    bd: &OMatrix<f64, N, M>,
    h: f64,
    operation: &'static str,
) -> Result<Held<N, M>, Error>
where
    DefaultAllocator: Allocator<N, N> + Allocator<N, M>,
{
    let (n, m) = bd.shape_generic();
    let heap = |x: &[f64], cols: usize| DMatrix::from_column_slice(n.value(), cols, x);
    let (l, f) = held_log(
        &heap(ad.as_slice(), n.value()),
        &heap(bd.as_slice(), m.value()),
        operation,
    )?;
    let a = OMatrix::<f64, N, N>::from_fn_generic(n, n, |i, j| l[(i, j)] / h);
    let b = OMatrix::<f64, N, M>::from_fn_generic(n, m, |i, j| f[(i, j)] / h);
    Ok((a, b))
}

/// The inverse of the generalised bilinear transform with weight `alpha`
/// (see [`StateSpace::d2c`]).
fn gbt_inverse<N: Dim, M: Dim, P: Dim>(
    (ad, bd, cd, dd): PartsRef<'_, N, M, P>,
    h: f64,
    alpha: f64,
    operation: &'static str,
) -> Result<Parts<N, M, P>, Error>
where
    DefaultAllocator: ModelAlloc<N, M, P>,
{
    let (n, _) = ad.shape_generic();
    let id = OMatrix::<f64, N, N>::identity_generic(n, n);
    let step = ad - &id;
    if alpha == 0.0 {
        return Ok((step / h, bd / h, cd.clone(), dd.clone()));
    }
    // V = α Ad + (1 − α) I is singular exactly at the eigenvalue z = −(1 − α)/α.
    let pole = -(1.0 - alpha) / alpha;
    let heap = DMatrix::from_fn(n.value(), n.value(), |i, j| ad[(i, j)]);
    let tol = POLE_FACTOR * n.value() as f64 * f64::EPSILON * (1.0 + frobenius(&heap));
    if let Some(z) = eigenvalues_dyn(&heap)?
        .iter()
        .find(|z| (*z - pole).norm() <= tol)
    {
        return Err(Error::EigenvalueOutOfDomain {
            operation,
            re: z.re,
            im: z.im,
            reason: "is where the inverse transform has a pole (z = −1 for Tustin, z = 0 \
                     for backward Euler): no continuous model maps there",
        });
    }
    let v = ad * alpha + id * (1.0 - alpha);
    let lu = Lu::new(&v, operation)?;
    let a = lu.solve(&step) / h;
    let b = lu.solve(bd) / h;
    let c = Lu::solve_right(&v, cd, operation)?;
    let d = dd - &c * bd * alpha;
    Ok((a, b, c, d))
}
