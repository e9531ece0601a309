//! Linear-quadratic regulators on fixed-size models: a front end to the
//! Riccati solvers of [`super::riccati`], which run here on stack matrices.

use nalgebra::{Complex, Const, SMatrix};

use super::riccati::{self, Solution, Weights};
use crate::error::Error;
use crate::model::{Continuous, Discrete, StateSpace};

/// A solved linear-quadratic regulator: the gain, the Riccati solution, the
/// closed-loop poles, and how well the Riccati equation is satisfied.
///
/// # Discretization
///
/// The fixed-size front end of the solvers behind `DynStateSpace::lqr`,
/// the same code on stack matrices: the method (doubling,
/// after a Cayley transform in continuous time, then Newton refinement, all
/// `O(N³)`) is described on [`DynLqr`](super::DynLqr), which [`care`](super::care),
/// [`dare`](super::dare) and `DynStateSpace::lqr` return.
///
/// Every solution's closed loop is checked: one that is not stable is
/// refused with [`Error::Unstable`]. The relative residual of the Riccati
/// equation is returned in [`Lqr::residual`] and is not a refusal criterion:
/// callers that need a bound check it (the tests require < 1e-9).
///
/// # Examples
///
/// ```
/// use ctrlab::{StateSpace, design::lqr};
/// use nalgebra::matrix;
///
/// // x' = x + u (unstable), q = r = 1: X = 1 + √2, K = X.
/// let sys = StateSpace::continuous(matrix![1.0], matrix![1.0], matrix![1.0], matrix![0.0])?;
/// let sol = lqr(&sys, &matrix![1.0], &matrix![1.0])?;
/// assert!((sol.gain[(0, 0)] - (1.0 + 2f64.sqrt())).abs() < 1e-12);
/// assert!((sol.poles[0].re + 2f64.sqrt()).abs() < 1e-12);
/// assert!(sol.residual < 1e-12);
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lqr<const N: usize, const M: usize> {
    /// The optimal state gain `K` of `u = −K x` (SI: input unit per state
    /// unit).
    pub gain: SMatrix<f64, M, N>,
    /// The stabilising solution `X` of the Riccati equation (symmetric,
    /// positive semidefinite); the optimal cost from `x₀` is `x₀ᵀ X x₀`.
    pub riccati: SMatrix<f64, N, N>,
    /// Poles of the closed loop `A − B K`, sorted as
    /// [`StateSpace::poles`].
    pub poles: [Complex<f64>; N],
    /// Relative residual of the Riccati equation at `X`: the Frobenius norm
    /// of the equation's left side minus its right, over the sum of the
    /// norms of its terms.
    pub residual: f64,
    /// Doubling steps the solver took.
    pub iterations: usize,
}

/// Continuous-time LQR: the gain `K = R⁻¹ Bᵀ X` minimising
/// `∫ (xᵀ Q x + uᵀ R u) dt`, with `X` from the continuous algebraic Riccati
/// equation (solved by SDA after a Cayley transform; see [`Lqr`]). The
/// problem python-control's `lqr(A, B, Q, R)` solves.
///
/// # Errors
///
/// [`Error::NonFinite`] for a non-finite `Q` or `R`; [`Error::InvalidMatrix`]
/// unless `Q` is symmetric positive semidefinite and `R` symmetric positive
/// definite; [`Error::NoConvergence`] if the doubling does not converge;
/// [`Error::Unstable`] if the solution does not stabilise the loop (the plant
/// is not stabilisable, or `(A, Q)` not detectable).
///
/// # Examples
///
/// ```
/// use ctrlab::{MassSpring, Cart, design::lqr};
/// use nalgebra::{SMatrix, matrix};
///
/// let plant = MassSpring::nominal().state_space(Cart::Two)?;
/// let q = SMatrix::<f64, 4, 4>::from_diagonal(&nalgebra::vector![0.0, 0.0, 1e6, 0.0]);
/// let sol = lqr(&plant, &q, &matrix![1.0])?;
/// assert!(sol.poles.iter().all(|p| p.re < 0.0));
/// assert!(sol.residual < 1e-9);
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub fn lqr<const N: usize, const M: usize, const P: usize>(
    sys: &StateSpace<N, M, P, Continuous>,
    q: &SMatrix<f64, N, N>,
    r: &SMatrix<f64, M, M>,
) -> Result<Lqr<N, M>, Error> {
    let sol = riccati::continuous(sys.a(), sys.b(), q, r, Weights::Regulator(["Q", "R"]))?;
    Ok(fixed(sol))
}

/// Discrete-time LQR: the gain `K = (R + Bᵀ X B)⁻¹ Bᵀ X A` minimising
/// `Σ (xᵀ Q x + uᵀ R u)`, with `X` from the discrete algebraic Riccati
/// equation (solved by SDA; see [`Lqr`]). The problem
/// python-control's `dlqr(A, B, Q, R)` solves.
///
/// # Errors
///
/// As [`lqr`]; [`Error::Unstable`] means a closed-loop pole on or outside the
/// unit circle.
///
/// # Examples
///
/// ```
/// use ctrlab::{MassSpring, Discretization, Cart, design::dlqr};
/// use nalgebra::{SMatrix, matrix, vector};
///
/// let d = MassSpring::nominal().state_space(Cart::Two)?.discretize(0.002, Discretization::Zoh)?;
/// let q = SMatrix::<f64, 4, 4>::from_diagonal(&vector![1e4, 0.0, 1e6, 0.0]);
/// let sol = dlqr(&d, &q, &matrix![1.0])?;
/// assert!(sol.poles.iter().all(|z| z.norm() < 1.0));
/// assert!(sol.residual < 1e-9);
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub fn dlqr<const N: usize, const M: usize, const P: usize>(
    sys: &StateSpace<N, M, P, Discrete>,
    q: &SMatrix<f64, N, N>,
    r: &SMatrix<f64, M, M>,
) -> Result<Lqr<N, M>, Error> {
    let sol = riccati::discrete(
        sys.a(),
        sys.b(),
        q,
        r,
        Weights::Regulator(["Q", "R"]),
        Some(sys.dt()),
    )?;
    Ok(fixed(sol))
}

/// The solver's solution in the fixed-size result (`N` poles by
/// construction).
fn fixed<const N: usize, const M: usize>(sol: Solution<Const<N>, Const<M>>) -> Lqr<N, M> {
    let mut poles = [Complex::new(0.0, 0.0); N];
    poles.copy_from_slice(&sol.poles);
    Lqr {
        gain: sol.gain,
        riccati: sol.riccati,
        poles,
        residual: sol.residual,
        iterations: sol.iterations,
    }
}

pub(crate) fn symmetric<const N: usize>(m: &SMatrix<f64, N, N>) -> SMatrix<f64, N, N> {
    (m + m.transpose()) * 0.5
}

/// `Q` symmetric positive semidefinite, `R` symmetric positive definite;
/// errors name them as `names` (`["Q", "R"]`, or `["QN", "RN"]` for a
/// Kalman filter's noise covariances).
pub(crate) fn check_weights<const N: usize, const M: usize>(
    q: &SMatrix<f64, N, N>,
    r: &SMatrix<f64, M, M>,
    names: [&'static str; 2],
) -> Result<(), Error> {
    riccati::check_weights(q, r, Weights::Regulator(names), true)
}
