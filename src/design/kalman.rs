//! Steady-state Kalman filters, [`lqe`] and [`dlqe`]: the dual of the
//! linear-quadratic regulator, solved by the same Riccati solvers.

use nalgebra::{
    Complex, Const, DefaultAllocator, Dim, Dyn, OMatrix, OVector, allocator::Allocator,
};

use super::Kalman;
use super::lqr::{Lqr, regulator};
use super::riccati::{Weights, check_weights};
use crate::error::{Error, check_finite_dyn, check_shape};
use crate::kernels::linalg::{Lu, SystemAlloc};
use crate::model::{Continuous, Discrete, Token};
#[cfg(doc)]
use crate::model::{DynStateSpace, StateSpace};

/// A solved steady-state Kalman filter (linear-quadratic estimator): the
/// gain, the error covariance, the estimator's poles, and how well its
/// Riccati equation is satisfied.
///
/// The conventions are python-control's `lqe(A, G, C, QN, RN)` and
/// `dlqe(A, G, C, QN, RN)`. The plant is
///
/// ```text
/// continuous: x' = A x + B u + G w,             y = C x + D u + v
/// discrete:   x[k+1] = A x[k] + B u[k] + G w[k], y[k] = C x[k] + D u[k] + v[k]
/// ```
///
/// with white, zero-mean, uncorrelated process noise `w` (covariance `QN`,
/// or spectral density in continuous time) and measurement noise `v`
/// (covariance `RN`).
///
/// - Continuous: `gain` is `L = P Cᵀ RN⁻¹` of the filter
///   `x̂' = A x̂ + B u + L (y − C x̂ − D u)`, with `P` the stabilising
///   solution of `A P + P Aᵀ − P Cᵀ RN⁻¹ C P + G QN Gᵀ = 0`.
///   `current_gain` is `None`.
/// - Discrete: `gain` is python-control's **predictor** gain
///   `L = A P Cᵀ (C P Cᵀ + RN)⁻¹` of
///   `x̂[k+1|k] = A x̂[k|k−1] + B u[k] + L (y[k] − C x̂[k|k−1] − D u[k])`,
///   with `P` the *a priori* error covariance, the stabilising solution of
///   `P = A P Aᵀ − A P Cᵀ (C P Cᵀ + RN)⁻¹ C P Aᵀ + G QN Gᵀ`.
///   `current_gain` is `Some(M)` with `M = P Cᵀ (C P Cᵀ + RN)⁻¹`, the gain
///   of the **current-estimator** (filter) form
///   `x̂[k|k] = x̂[k|k−1] + M (y[k] − C x̂[k|k−1] − D u[k])` — the matrix
///   MATLAB's `dlqe` returns as `M`; `L = A M`.
///
/// `poles` are the eigenvalues of `A − L C` (the estimation error's
/// dynamics in both forms). The Riccati equation is solved as the LQR
/// problem of the dual system `(Aᵀ, Cᵀ)` with weights `G QN Gᵀ` and `RN`
/// (see [`Lqr`](Lqr#algorithm) for the method); `residual` and
/// `iterations` are that solver's.
///
/// One type for both model sizes, as [`Lqr`]: `Lqe<Const<N>, Const<P>>`
/// (stack matrices, `Copy`) for a `StateSpace<N, M, P, _>`, [`DynLqe`]
/// for a `DynStateSpace`.
///
/// # Examples
///
/// python-control's own test case: a random walk `x' = 0.1 w` measured
/// directly, `QN = 10`, `RN = 2`:
///
/// ```
/// use ctrlab::{StateSpace, design::lqe};
/// use ctrlab::nalgebra::matrix;
///
/// let sys = StateSpace::continuous(matrix![0.0], matrix![0.1], matrix![1.0], matrix![0.0])?;
/// let kf = lqe(&sys, &matrix![0.1], &matrix![10.0], &matrix![2.0])?;
/// // P² / RN = G QN G: P = √(0.1 · 2) and L = P / RN.
/// let p = 0.2f64.sqrt();
/// assert!((kf.covariance[(0, 0)] - p).abs() < 1e-12);
/// assert!((kf.gain[(0, 0)] - p / 2.0).abs() < 1e-12);
/// assert!(kf.current_gain.is_none());
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct Lqe<N: Dim, P: Dim>
where
    DefaultAllocator: Allocator<N, P> + Allocator<N, N> + Allocator<N>,
{
    /// The estimator gain `L` (`n × p`): continuous filter gain, or the
    /// discrete predictor gain (python-control's convention).
    pub gain: OMatrix<f64, N, P>,
    /// The stabilising Riccati solution `P`: the steady-state estimation
    /// error covariance (discrete: *a priori*, before the measurement).
    pub covariance: OMatrix<f64, N, N>,
    /// Discrete only: the current-estimator gain `M` (MATLAB's `dlqe` `M`),
    /// `L = A M`.
    pub current_gain: Option<OMatrix<f64, N, P>>,
    /// Poles of the estimation error, eigenvalues of `A − L C`, sorted as
    /// [`StateSpace::poles`].
    pub poles: OVector<Complex<f64>, N>,
    /// Relative residual of the Riccati equation at `P` (see [`Lqr`]).
    pub residual: f64,
    /// Doubling steps the Riccati solver took.
    pub iterations: usize,
}

/// The [`Lqe`] of a model sized at run time, its matrices `DMatrix`es.
///
/// # Examples
///
/// ```
/// use ctrlab::{DynStateSpace, design::{DynLqe, lqe}};
/// use ctrlab::nalgebra::dmatrix;
///
/// let sys = DynStateSpace::continuous(dmatrix![0.0], dmatrix![0.1], dmatrix![1.0], dmatrix![0.0])?;
/// let kf: DynLqe = lqe(&sys, &dmatrix![0.1], &dmatrix![10.0], &dmatrix![2.0])?;
/// assert_eq!(kf.gain.shape(), (1, 1));
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub type DynLqe = Lqe<Dyn, Dyn>;

impl<const N: usize, const P: usize> Copy for Lqe<Const<N>, Const<P>> {}

/// Continuous-time steady-state Kalman filter (linear-quadratic
/// estimator): python-control's `lqe(A, G, C, QN, RN)` with `A`, `C` from
/// `sys` (its outputs are the measurements) and the process noise entering
/// through `g` (`n × w`; pass `sys.b()` for noise on the input). See [`Lqe`]
/// for the conventions.
///
/// Either model size ([`Kalman`]): `G`, `QN` (`w × w`) and `RN` (`p × p`)
/// are `SMatrix`es for a fixed-size model, `DMatrix`es for a
/// `DynStateSpace` (their shapes checked when called); the result is an
/// [`Lqe`] of the model's sizes.
///
/// # Errors
///
/// [`Error::DimensionMismatch`] naming `"G"`, `"QN"` or `"RN"` for a
/// matrix of the wrong shape (a run-time-sized model);
/// [`Error::NonFinite`] for a non-finite `G`, `QN` or `RN`;
/// [`Error::InvalidMatrix`] named `"QN"` unless it is symmetric positive
/// semidefinite, `"RN"` unless symmetric positive definite;
/// [`Error::NoConvergence`] if the doubling does not converge;
/// [`Error::Unstable`] if no solution stabilises the estimator (`(A, C)`
/// not detectable, or `(A, G QN^½)` with an uncontrollable mode on the
/// imaginary axis).
///
/// # Examples
///
/// The lab's plant with both positions measured to about an encoder count
/// and a 1 N force disturbance:
///
/// ```
/// use ctrlab::{MassSpring, Cart, design::lqe, lab};
/// use ctrlab::nalgebra::{matrix, SMatrix};
///
/// let plant = MassSpring::nominal().state_space(Cart::Two)?
///     .with_output(lab::position_output_matrix(), matrix![0.0; 0.0])?;
/// let count = 0.080 / 8192.0; // m
/// let rn = SMatrix::<f64, 2, 2>::identity() * (count * count / 12.0);
/// let kf = lqe(&plant, plant.b(), &matrix![1.0], &rn)?;
/// assert!(kf.poles.iter().all(|p| p.re < 0.0));
/// assert!(kf.residual < 1e-9);
///
/// // The same filter for the model sized at run time.
/// let dynamic = ctrlab::DynStateSpace::from(&plant);
/// let heap = |m: &[f64], r, c| ctrlab::nalgebra::DMatrix::from_column_slice(r, c, m);
/// let d = lqe(&dynamic, dynamic.b(), &ctrlab::nalgebra::dmatrix![1.0], &heap(rn.as_slice(), 2, 2))?;
/// assert_eq!(d.gain.as_slice(), kf.gain.as_slice());
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub fn lqe<S, G>(
    sys: &S,
    g: &G,
    qn: &S::NoiseCovariance,
    rn: &S::OutputWeight,
) -> Result<S::Lqe, Error>
where
    S: Kalman<G, Domain = Continuous>,
{
    sys.estimator(Token(()), g, qn, rn)
}

/// Discrete-time steady-state Kalman filter: python-control's
/// `dlqe(A, G, C, QN, RN)`, with `gain` the predictor gain
/// `L = A P Cᵀ (C P Cᵀ + RN)⁻¹` and `current_gain` the current-estimator
/// gain `M = P Cᵀ (C P Cᵀ + RN)⁻¹` (MATLAB's `dlqe`); see [`Lqe`].
/// Either model size, as [`lqe`].
///
/// # Errors
///
/// As [`lqe`]; [`Error::Unstable`] means an estimator pole on or outside
/// the unit circle.
///
/// # Examples
///
/// ```
/// use ctrlab::{MassSpring, Cart, Discretization, design::dlqe, lab};
/// use ctrlab::nalgebra::{matrix, SMatrix};
///
/// let plant = MassSpring::nominal().state_space(Cart::Two)?
///     .with_output(lab::position_output_matrix(), matrix![0.0; 0.0])?
///     .discretize(0.002, Discretization::Zoh)?;
/// let rn = SMatrix::<f64, 2, 2>::identity() * 1e-11;
/// let kf = dlqe(&plant, plant.b(), &matrix![1.0], &rn)?;
/// assert!(kf.poles.iter().all(|z| z.norm() < 1.0));
/// // The predictor gain is A times the current-estimator gain.
/// let m = kf.current_gain.unwrap();
/// assert!((plant.a() * m - kf.gain).norm() <= 1e-12 * kf.gain.norm());
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub fn dlqe<S, G>(
    sys: &S,
    g: &G,
    qn: &S::NoiseCovariance,
    rn: &S::OutputWeight,
) -> Result<S::Lqe, Error>
where
    S: Kalman<G, Domain = Discrete>,
{
    sys.estimator(Token(()), g, qn, rn)
}

/// The steady-state filter of `(A, C)` with noise `G`, `QN`, `RN` and
/// sampling period `period` (`None`: continuous): the one implementation
/// behind [`lqe`] and [`dlqe`] for both model sizes, as the regulator of
/// the dual `(Aᵀ, Cᵀ)`.
pub(super) fn estimator<N: Dim, P: Dim, W: Dim>(
    a: &OMatrix<f64, N, N>,
    c: &OMatrix<f64, P, N>,
    g: &OMatrix<f64, N, W>,
    qn: &OMatrix<f64, W, W>,
    rn: &OMatrix<f64, P, P>,
    period: Option<f64>,
) -> Result<Lqe<N, P>, Error>
where
    DefaultAllocator: SystemAlloc<N, P> + SystemAlloc<N, W> + Allocator<P, P> + Allocator<P, N>,
{
    let (n, p, w) = (a.nrows(), c.nrows(), g.ncols());
    check_shape("G", g, n, w)?;
    check_shape("QN", qn, w, w)?;
    check_shape("RN", rn, p, p)?;
    let q = noise_weight(g, qn, rn)?;
    let sol = regulator(&a.transpose(), &c.transpose(), &q, rn, period).map_err(estimator_error)?;
    let current = match period {
        None => None,
        Some(_) => {
            let pct = &sol.riccati * c.transpose();
            // M = P Cᵀ (C P Cᵀ + RN)⁻¹, by a right solve.
            let current = Lu::solve_right(&(c * &pct + rn), &pct, "DLQE (C P Cᵀ + RN)")?;
            if current.iter().any(|v| !v.is_finite()) {
                return Err(Error::Overflow {
                    operation: "DLQE gain",
                });
            }
            Some(current)
        }
    };
    Ok(from_dual(sol, current))
}

/// Checks the noise covariances and returns `G QN Gᵀ`, symmetrised.
fn noise_weight<N: Dim, W: Dim, P: Dim>(
    g: &OMatrix<f64, N, W>,
    qn: &OMatrix<f64, W, W>,
    rn: &OMatrix<f64, P, P>,
) -> Result<OMatrix<f64, N, N>, Error>
where
    DefaultAllocator: SystemAlloc<N, W> + Allocator<P, P>,
{
    check_finite_dyn("G", g)?;
    check_weights(qn, rn, Weights::Regulator(["QN", "RN"]), true)?;
    let gqg = g * qn * g.transpose();
    let q = (&gqg + gqg.transpose()) * 0.5;
    if q.iter().any(|v| !v.is_finite()) {
        return Err(Error::Overflow {
            operation: "G QN Gᵀ",
        });
    }
    Ok(q)
}

/// The estimator from the dual regulator.
fn from_dual<N: Dim, P: Dim>(sol: Lqr<N, P>, current_gain: Option<OMatrix<f64, N, P>>) -> Lqe<N, P>
where
    DefaultAllocator: SystemAlloc<N, P>,
{
    Lqe {
        gain: sol.gain.transpose(),
        covariance: sol.riccati,
        current_gain,
        // eig(Aᵀ − Cᵀ Lᵀ) = eig(A − L C).
        poles: sol.poles,
        residual: sol.residual,
        iterations: sol.iterations,
    }
}

/// Restates the dual LQR's refusal in the estimator's terms.
fn estimator_error(e: Error) -> Error {
    match e {
        Error::Unstable { re, im, .. } => Error::Unstable {
            operation: "Kalman filter: the Riccati solution does not stabilise the estimator \
                        (is (A, C) detectable and (A, G QN Gᵀ) stabilisable?)",
            re,
            im,
        },
        other => other,
    }
}
