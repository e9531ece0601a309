//! Linear-quadratic regulators, [`lqr`] and [`dlqr`], for either model
//! size: a front end to the Riccati solvers of [`super::riccati`], which
//! run on stack matrices for a fixed-size model and on heap ones for a
//! model sized at run time; and their result, [`Lqr`].

use std::fmt;

use nalgebra::{
    Complex, Const, DefaultAllocator, Dim, Dyn, OMatrix, OVector, U1, allocator::Allocator,
};

use super::Design;
use super::riccati::{self, Solution, Weights};
use crate::analysis::Poles;
use crate::error::{Error, check_shape};
use crate::kernels::linalg::SystemAlloc;
use crate::model::{Continuous, Discrete, Token, display};

/// A solved linear-quadratic regulator: the gain, the Riccati solution, the
/// closed-loop poles, and how well the Riccati equation is satisfied.
///
/// One type for both model sizes, written over nalgebra's dimensions: a
/// `StateSpace<N, M, P, _>`'s regulator is an `Lqr<Const<N>, Const<M>>`
/// whose matrices are `SMatrix`es on the stack (and which is `Copy`); a
/// `DynStateSpace`'s (and [`care`](super::care)'s, [`dare`](super::dare)'s)
/// is a [`DynLqr`], `Lqr<Dyn, Dyn>`, with `DMatrix`es. The poles are an
/// `OVector` of `N` complex numbers either way (index it, iterate it, or
/// print it with [`Poles`]).
///
/// # Algorithm
///
/// The discrete equation
/// `X = Aᵀ X A − Aᵀ X B (R + Bᵀ X B)⁻¹ Bᵀ X A + Q` is the fixed point of the
/// structure-preserving doubling algorithm (SDA) of Chu, Fan and Lin (2005):
/// with `E₀ = A`, `G₀ = B R⁻¹ Bᵀ`, `H₀ = Q`,
///
/// ```text
/// W = I + G H,  E ← E W⁻¹ E,  G ← G + E W⁻¹ G Eᵀ,  H ← H + Eᵀ H W⁻¹ E
/// ```
///
/// and `H → X` quadratically, `E → 0`. The doubling stops when a step
/// changes `H` by less than 1e-15 of its norm *and* `‖E‖ ≤ 1e-3`: with
/// weights decades apart (`Q = diag(1e9, 1e-9)`) the part of `H` along the
/// lightly weighted mode starts below that step size and grows while `E`
/// does, so a settled `H` alone is not convergence. `W` is nonsingular
/// (every eigenvalue at least 1 for `G`, `H` positive semidefinite) however
/// ill-conditioned it gets meanwhile, and is refused only for a zero pivot.
/// The continuous equation
/// `Aᵀ X + X A − X B R⁻¹ Bᵀ X + Q = 0` is first mapped to that form by the
/// Cayley transform of its Hamiltonian with a shift `γ > 0`
/// (`A_γ = A − γ I`, `W_γ = A_γᵀ + Q A_γ⁻¹ G`, `E₀ = I + 2γ W_γ⁻ᵀ`,
/// `G₀ = 2γ A_γ⁻¹ G W_γ⁻¹`, `H₀ = 2γ W_γ⁻¹ Q A_γ⁻¹`; Chu, Fan, Lin and Weng,
/// 2004). Neither needs a stable or invertible `A`, so both converge for
/// unstable plants: the only requirements are the usual LQR ones, `(A, B)`
/// stabilisable and `(A, Q)` detectable, with no closed-loop pole on the
/// stability boundary. The shift starts at
/// `γ = max(‖A‖_F, √(‖G‖_F ‖Q‖_F))`, the scale of the Hamiltonian's
/// eigenvalues; if the residual stays above 1e-13 and the Newton steps
/// below could still lower it (or they stall above 1e-8, which is a poor
/// start rather than the problem's rounding floor), a few other shifts
/// (γ/2, 2γ, γ/4, 4γ, γ/10, 10γ) are tried and the best solution kept.
///
/// On an ill-conditioned problem (a large `X` from nearly cancelling terms)
/// the doubling alone can stop at a relative residual of about 1e-9. Up to
/// three Newton steps follow it (while the residual is above 4ε), each
/// kept only if it lowers the residual:
/// a Lyapunov equation of the closed loop for the continuous case (solved
/// by the matrix-sign-function iteration), a Stein equation for the
/// discrete one (squared Smith). Every step of every part costs `O(N³)`:
/// LU solves, products and inverses, no `N² × N²` system. The code is
/// generic over nalgebra's dimensions, so [`lqr`] runs it on stack
/// matrices for a fixed-size model and on heap ones for a `DynStateSpace`
/// (and [`care`](super::care), [`dare`](super::dare)), with cache-blocked
/// products (matrixmultiply) at large `N`.
///
/// A discrete equation with a singular (positive semidefinite) `R`, which
/// only [`dare`](super::dare) accepts, is first solved with `R + δ I`
/// (`δ = 10⁻⁸ (‖R‖ + ‖B‖² ‖Q‖)`), and Newton's method on the true equation
/// (it needs only `R + Bᵀ X B` invertible) takes it from there.
///
/// Every solution's closed loop is checked: one that is not stable is
/// refused with [`Error::Unstable`]. The relative residual of the Riccati
/// equation is returned in [`Lqr::residual`] and is not a refusal criterion:
/// callers that need a bound check it (the tests require < 1e-9).
///
/// # Examples
///
/// ```
/// use ctrlab::{DynStateSpace, StateSpace, design::lqr};
/// use ctrlab::nalgebra::{dmatrix, matrix};
///
/// // x' = x + u (unstable), q = r = 1: X = 1 + √2, K = X.
/// let sys = StateSpace::continuous(matrix![1.0], matrix![1.0], matrix![1.0], matrix![0.0])?;
/// let sol = lqr(&sys, &matrix![1.0], &matrix![1.0])?;
/// assert!((sol.gain[(0, 0)] - (1.0 + 2f64.sqrt())).abs() < 1e-12);
/// assert!((sol.poles[0].re + 2f64.sqrt()).abs() < 1e-12);
/// assert!(sol.residual < 1e-12);
///
/// // The same fields, sized at run time.
/// let dynamic = lqr(&DynStateSpace::from(&sys), &dmatrix![1.0], &dmatrix![1.0])?;
/// assert_eq!(dynamic.gain.as_slice(), sol.gain.as_slice());
/// assert_eq!(dynamic.poles.as_slice(), sol.poles.as_slice());
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct Lqr<N: Dim, M: Dim>
where
    DefaultAllocator: Allocator<M, N> + Allocator<N, N> + Allocator<N>,
{
    /// The optimal state gain `K` (`m × n`) of `u = −K x` (SI: input unit
    /// per state unit): `R⁻¹ Bᵀ X` in continuous time,
    /// `(R + Bᵀ X B)⁻¹ Bᵀ X A` in discrete time.
    pub gain: OMatrix<f64, M, N>,
    /// The stabilising solution `X` (`n × n`, symmetric) of the Riccati
    /// equation; for a regulator the optimal cost from `x₀` is `x₀ᵀ X x₀`
    /// (units of the cost per squared state unit).
    pub riccati: OMatrix<f64, N, N>,
    /// Poles of the closed loop `A − B K` (s-plane in rad/s, or z-plane),
    /// sorted as [`StateSpace::poles`](crate::StateSpace::poles).
    pub poles: OVector<Complex<f64>, N>,
    /// Relative residual of the Riccati equation at `X`: the Frobenius norm
    /// of the equation's left side minus its right, over the sum of the
    /// norms of its terms (dimensionless).
    pub residual: f64,
    /// Doubling steps the solver took.
    pub iterations: usize,
}

/// The [`Lqr`] of a model sized at run time (and of [`care`](super::care)
/// and [`dare`](super::dare)): `DMatrix` gain and Riccati solution.
///
/// # Examples
///
/// ```
/// use ctrlab::design::{DynLqr, care};
/// use ctrlab::nalgebra::dmatrix;
///
/// let sol: DynLqr = care(&dmatrix![1.0], &dmatrix![1.0], &dmatrix![1.0], &dmatrix![1.0])?;
/// assert_eq!(sol.gain.shape(), (1, 1));
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub type DynLqr = Lqr<Dyn, Dyn>;

impl<const N: usize, const M: usize> Copy for Lqr<Const<N>, Const<M>> {}

impl<N: Dim, M: Dim> From<Solution<N, M>> for Lqr<N, M>
where
    DefaultAllocator: SystemAlloc<N, M>,
{
    fn from(sol: Solution<N, M>) -> Self {
        let (n, _) = sol.riccati.shape_generic();
        Self {
            poles: OVector::from_iterator_generic(n, U1, sol.poles.iter().copied()),
            gain: sol.gain,
            riccati: sol.riccati,
            residual: sol.residual,
            iterations: sol.iterations,
        }
    }
}

impl<N: Dim, M: Dim> fmt::Display for Lqr<N, M>
where
    DefaultAllocator: Allocator<M, N> + Allocator<N, N> + Allocator<N>,
{
    /// The gain `K` row by row and the closed-loop poles, in the
    /// formatter's precision (`{:.3}`: three decimals) or to five
    /// significant digits (`{}`), as a model prints (see
    /// [`StateSpace`'s `Display`](crate::StateSpace#impl-Display-for-StateSpace<N,+M,+P,+D>)).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{StateSpace, design::lqr};
    /// use ctrlab::nalgebra::matrix;
    ///
    /// // A double integrator, q = diag(1, 0), r = 1: K = [1, √2].
    /// let sys = StateSpace::continuous(matrix![0.0, 1.0; 0.0, 0.0], matrix![0.0; 1.0],
    ///                                  matrix![1.0, 0.0], matrix![0.0])?;
    /// let sol = lqr(&sys, &matrix![1.0, 0.0; 0.0, 0.0], &matrix![1.0])?;
    /// assert_eq!(sol.to_string(), "K =\n       1  1.4142\npoles = -0.70711 ± 0.70711j\n");
    /// assert_eq!(format!("{sol:.2}"), "K =\n  1.00  1.41\npoles = -0.71 ± 0.71j\n");
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        display::write_matrix(f, "K", &self.gain)?;
        write!(f, "poles = ")?;
        fmt::Display::fmt(&Poles(self.poles.as_slice()), f)?;
        writeln!(f)
    }
}

/// Continuous-time LQR: the gain `K = R⁻¹ Bᵀ X` minimising
/// `∫ (xᵀ Q x + uᵀ R u) dt` for `u = −K x`, with `X` the stabilising
/// solution of the continuous algebraic Riccati equation (solved by SDA
/// after a Cayley transform; see [`care`](super::care)). MATLAB's and
/// python-control's `lqr(sys, Q, R)`.
///
/// Either model size ([`Design`]): `Q` is `n × n` and `R` `m × m`, as
/// `SMatrix`es for a fixed-size model (checked at compile time), as
/// `DMatrix`es for a `DynStateSpace` (checked when called); the result is
/// an [`Lqr`] of the model's sizes.
///
/// # Errors
///
/// [`Error::DimensionMismatch`] unless `Q` is `n × n` and `R` `m × m` (a
/// run-time-sized model); [`Error::NonFinite`] for a non-finite `Q` or
/// `R`; [`Error::InvalidMatrix`] unless `Q` is symmetric positive
/// semidefinite and `R` symmetric positive definite;
/// [`Error::NoConvergence`] if the doubling does not converge;
/// [`Error::Unstable`] if the solution does not stabilise the loop (the
/// plant is not stabilisable, or `(A, Q)` not detectable).
///
/// # Examples
///
/// ```
/// use ctrlab::{DynStateSpace, MassSpring, Cart, design::lqr};
/// use ctrlab::nalgebra::{DMatrix, SMatrix, dmatrix, dvector, matrix, vector};
///
/// let plant = MassSpring::nominal().state_space(Cart::Two)?;
/// let q = SMatrix::<f64, 4, 4>::from_diagonal(&vector![0.0, 0.0, 1e6, 0.0]);
/// let sol = lqr(&plant, &q, &matrix![1.0])?;
/// assert!(sol.poles.iter().all(|p| p.re < 0.0));
/// assert!(sol.residual < 1e-9);
///
/// // Sized at run time: the same call and numbers.
/// let dynamic = DynStateSpace::from(&plant);
/// let q = DMatrix::from_diagonal(&dvector![0.0, 0.0, 1e6, 0.0]);
/// let d = lqr(&dynamic, &q, &dmatrix![1.0])?;
/// assert_eq!(d.gain.as_slice(), sol.gain.as_slice());
/// assert!(lqr(&dynamic, &q, &dmatrix![1.0, 0.0; 0.0, 1.0]).is_err()); // R is 1 × 1
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub fn lqr<S: Design<Domain = Continuous>>(
    sys: &S,
    q: &S::StateWeight,
    r: &S::InputWeight,
) -> Result<S::Lqr, Error> {
    sys.regulator(Token(()), q, r)
}

/// Discrete-time LQR: the gain `K = (R + Bᵀ X B)⁻¹ Bᵀ X A` minimising
/// `Σ (xᵀ Q x + uᵀ R u)` for `u[k] = −K x[k]`, with `X` the stabilising
/// solution of the discrete algebraic Riccati equation (solved by SDA; see
/// [`care`](super::care)). python-control's `dlqr(sys, Q, R)`, MATLAB's
/// `lqr` on a discrete model. Either model size, as [`lqr`].
///
/// # Errors
///
/// As [`lqr`]; [`Error::Unstable`] means a closed-loop pole on or outside the
/// unit circle.
///
/// # Examples
///
/// ```
/// use ctrlab::{DynStateSpace, MassSpring, Discretization, Cart, design::dlqr};
/// use ctrlab::nalgebra::{DMatrix, SMatrix, dmatrix, matrix, vector};
///
/// let d = MassSpring::nominal().state_space(Cart::Two)?.discretize(0.002, Discretization::Zoh)?;
/// let q = SMatrix::<f64, 4, 4>::from_diagonal(&vector![1e4, 0.0, 1e6, 0.0]);
/// let sol = dlqr(&d, &q, &matrix![1.0])?;
/// assert!(sol.poles.iter().all(|z| z.norm() < 1.0));
/// assert!(sol.residual < 1e-9);
/// let dynamic = dlqr(&DynStateSpace::from(&d), &DMatrix::from_column_slice(4, 4, q.as_slice()), &dmatrix![1.0])?;
/// assert_eq!(dynamic.gain.as_slice(), sol.gain.as_slice());
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[doc(alias = "lqr")]
pub fn dlqr<S: Design<Domain = Discrete>>(
    sys: &S,
    q: &S::StateWeight,
    r: &S::InputWeight,
) -> Result<S::Lqr, Error> {
    sys.regulator(Token(()), q, r)
}

/// The regulator of `(A, B)` with sampling period `period` (`None`:
/// continuous) for weights of any size (checked here): the one
/// implementation behind [`lqr`] and [`dlqr`] for both model sizes.
pub(crate) fn regulator<N: Dim, M: Dim>(
    a: &OMatrix<f64, N, N>,
    b: &OMatrix<f64, N, M>,
    q: &OMatrix<f64, N, N>,
    r: &OMatrix<f64, M, M>,
    period: Option<f64>,
) -> Result<Lqr<N, M>, Error>
where
    DefaultAllocator: SystemAlloc<N, M>,
{
    let (n, m) = (a.nrows(), b.ncols());
    check_shape("Q", q, n, n)?;
    check_shape("R", r, m, m)?;
    let weights = Weights::Regulator(["Q", "R"]);
    let sol = match period {
        None => riccati::continuous(a, b, q, r, weights)?,
        Some(dt) => riccati::discrete(a, b, q, r, weights, Some(dt))?,
    };
    Ok(Lqr::from(sol))
}
