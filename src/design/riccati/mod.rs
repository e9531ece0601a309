//! Algebraic Riccati equations and linear-quadratic regulators sized at run
//! time: [`care`], [`dare`] and `DynStateSpace::lqr`, the one
//! implementation behind the fixed-size [`lqr`](super::lqr) and
//! [`dlqr`](super::dlqr) too. The method is documented on [`DynLqr`].

mod kernels;
mod solver;

use nalgebra::allocator::Allocator;
use nalgebra::{Cholesky, Complex, DMatrix, DefaultAllocator, Dim, OMatrix};

use crate::error::{Error, check_finite_dyn, check_shape};
use crate::kernels::reduce::pow2_floor;
use crate::model::{Continuous, Discrete, DynStateSpace};
pub(crate) use solver::{Solution, continuous, discrete};

/// A solved algebraic Riccati equation, or linear-quadratic regulator, sized
/// at run time: the gain, the stabilising solution, the closed-loop poles,
/// and how well the equation is satisfied. The run-time counterpart of
/// [`Lqr`](super::Lqr), returned by [`care`], [`dare`] and
/// [`DynStateSpace::lqr`].
///
/// # Discretization
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
/// and `H → X` quadratically. The continuous equation
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
/// below could still lower it, a few other shifts (γ/2, 2γ, γ/4, 4γ,
/// γ/10, 10γ) are tried and the best solution kept.
///
/// On an ill-conditioned problem (a large `X` from nearly cancelling terms)
/// the doubling alone can stop at a relative residual of about 1e-9. Up to
/// three Newton steps follow it (while the residual is above 4ε), each
/// kept only if it lowers the residual:
/// a Lyapunov equation of the closed loop for the continuous case (solved
/// by the matrix-sign-function iteration), a Stein equation for the
/// discrete one (squared Smith). Every step of every part costs `O(N³)`:
/// LU solves, products and inverses, no `N² × N²` system. The code is
/// generic over nalgebra's dimensions, so the fixed-size [`lqr`](super::lqr)
/// runs it on stack matrices and `DynStateSpace::lqr` on heap ones, with
/// cache-blocked products (matrixmultiply) at large `N`.
///
/// A discrete equation with a singular (positive semidefinite) `R`, which
/// only [`dare`] accepts, is first solved with `R + δ I`
/// (`δ = 10⁻⁸ (‖R‖ + ‖B‖² ‖Q‖)`), and Newton's method on the true equation
/// (it needs only `R + Bᵀ X B` invertible) takes it from there.
///
/// Every solution's closed loop is checked: one that is not stable is
/// refused with [`Error::Unstable`]. The relative residual of the Riccati
/// equation is returned in [`DynLqr::residual`] and is not a refusal
/// criterion: callers that need a bound check it.
///
/// # Examples
///
/// ```
/// use ctrlab::design::care;
/// use nalgebra::dmatrix;
///
/// // x' = x + u (unstable), q = r = 1: X = 1 + √2, K = X.
/// let sol = care(&dmatrix![1.0], &dmatrix![1.0], &dmatrix![1.0], &dmatrix![1.0])?;
/// assert!((sol.riccati[(0, 0)] - (1.0 + 2f64.sqrt())).abs() < 1e-12);
/// assert!((sol.gain[(0, 0)] - (1.0 + 2f64.sqrt())).abs() < 1e-12);
/// assert!((sol.poles[0].re + 2f64.sqrt()).abs() < 1e-12);
/// assert!(sol.residual < 1e-12);
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct DynLqr {
    /// The optimal state gain `K` (`m × n`) of `u = −K x` (SI: input unit
    /// per state unit): `R⁻¹ Bᵀ X` in continuous time,
    /// `(R + Bᵀ X B)⁻¹ Bᵀ X A` in discrete time.
    pub gain: DMatrix<f64>,
    /// The stabilising solution `X` (`n × n`, symmetric) of the Riccati
    /// equation; for a regulator the optimal cost from `x₀` is `x₀ᵀ X x₀`
    /// (units of the cost per squared state unit).
    pub riccati: DMatrix<f64>,
    /// Poles of the closed loop `A − B K` (s-plane in rad/s, or z-plane),
    /// sorted as [`DynStateSpace::poles`].
    pub poles: Vec<Complex<f64>>,
    /// Relative residual of the Riccati equation at `X`: the Frobenius norm
    /// of the equation's left side minus its right, over the sum of the
    /// norms of its terms (dimensionless).
    pub residual: f64,
    /// Doubling steps the solver took.
    pub iterations: usize,
}

/// Which weights a caller accepts.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Weights {
    /// A regulator or estimator: `Q` symmetric positive semidefinite, `R`
    /// symmetric positive definite; errors name them as given
    /// (`["Q", "R"]`, or `["QN", "RN"]` for a Kalman filter).
    Regulator([&'static str; 2]),
    /// A Riccati equation as SciPy's solvers take it: `Q` symmetric (of any
    /// inertia), `R` symmetric positive definite (continuous) or positive
    /// semidefinite (discrete, where only `R + Bᵀ X B` is inverted).
    Equation,
}

/// Continuous-time algebraic Riccati equation
/// `Aᵀ X + X A − X B R⁻¹ Bᵀ X + Q = 0`: its stabilising solution `X` (the
/// one that makes `A − B R⁻¹ Bᵀ X` stable), with the gain
/// `K = R⁻¹ Bᵀ X`; SciPy's `solve_continuous_are(a, b, q, r)`, MATLAB's
/// `icare(A, B, Q, R)`. Sizes are taken from the matrices: `A` and `Q` are
/// `n × n`, `B` is `n × m`, `R` is `m × m`. The method is described on
/// [`DynLqr`]; `O(n³)` per step.
///
/// Unlike [`DynStateSpace::lqr`], `Q` may be indefinite (only symmetric), as
/// SciPy allows; the solution is then not necessarily positive
/// semidefinite.
///
/// # Errors
///
/// [`Error::DimensionMismatch`] naming the first matrix of the wrong shape;
/// [`Error::NonFinite`] for a non-finite entry; [`Error::InvalidMatrix`]
/// unless `Q` is symmetric and `R` symmetric positive definite;
/// [`Error::Singular`], [`Error::Overflow`] or [`Error::NoConvergence`] if
/// the doubling breaks down for every shift; [`Error::Unstable`] if the
/// solution does not stabilise `A − B K` (no stabilising solution exists).
///
/// # Examples
///
/// SciPy's CAREX 1 (a double integrator):
///
/// ```
/// use ctrlab::design::care;
/// use nalgebra::dmatrix;
///
/// let a = dmatrix![0.0, 1.0; 0.0, 0.0];
/// let b = dmatrix![0.0; 1.0];
/// let sol = care(&a, &b, &dmatrix![1.0, 0.0; 0.0, 2.0], &dmatrix![1.0])?;
/// // X = [2 1; 1 2], K = [1 2].
/// assert!((&sol.riccati - dmatrix![2.0, 1.0; 1.0, 2.0]).amax() < 1e-14);
/// assert!((&sol.gain - dmatrix![1.0, 2.0]).amax() < 1e-14);
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[doc(alias = "solve_continuous_are")]
#[doc(alias = "icare")]
pub fn care(
    a: &DMatrix<f64>,
    b: &DMatrix<f64>,
    q: &DMatrix<f64>,
    r: &DMatrix<f64>,
) -> Result<DynLqr, Error> {
    check_problem(a, b, q, r)?;
    continuous(a, b, q, r, Weights::Equation).map(DynLqr::from)
}

/// Discrete-time algebraic Riccati equation
/// `X = Aᵀ X A − Aᵀ X B (R + Bᵀ X B)⁻¹ Bᵀ X A + Q`: its stabilising solution
/// `X` (the one that puts the poles of `A − B K` inside the unit circle),
/// with the gain `K = (R + Bᵀ X B)⁻¹ Bᵀ X A`; SciPy's
/// `solve_discrete_are(a, b, q, r)`, MATLAB's `idare(A, B, Q, R)`. Sizes as
/// [`care`]; the method is described on [`DynLqr`].
///
/// `Q` may be indefinite and `R` singular (positive semidefinite), as SciPy
/// allows, as long as `R + Bᵀ X B` is invertible at the solution.
///
/// # Errors
///
/// As [`care`], except that `R` need only be symmetric positive
/// semidefinite; [`Error::Unstable`] means a closed-loop pole on or outside
/// the unit circle; [`Error::Singular`] if `R + Bᵀ X B` is singular.
///
/// # Examples
///
/// SciPy's DAREX 5 (a two-step delay):
///
/// ```
/// use ctrlab::design::dare;
/// use nalgebra::dmatrix;
///
/// let a = dmatrix![0.0, 1.0; 0.0, 0.0];
/// let b = dmatrix![0.0; 1.0];
/// let q = dmatrix![1.0, 2.0; 2.0, 4.0];
/// let sol = dare(&a, &b, &q, &dmatrix![1.0])?;
/// // The equation holds at X…
/// let x = &sol.riccati;
/// let res = a.transpose() * x * &a - x + &q
///     - a.transpose() * x * &b * &sol.gain;
/// assert!(res.amax() < 1e-13);
/// // …and X is the stabilising solution.
/// assert!(sol.poles.iter().all(|z| z.norm() < 1.0));
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[doc(alias = "solve_discrete_are")]
#[doc(alias = "idare")]
pub fn dare(
    a: &DMatrix<f64>,
    b: &DMatrix<f64>,
    q: &DMatrix<f64>,
    r: &DMatrix<f64>,
) -> Result<DynLqr, Error> {
    check_problem(a, b, q, r)?;
    discrete(a, b, q, r, Weights::Equation, None).map(DynLqr::from)
}

impl DynStateSpace<Continuous> {
    /// Continuous-time LQR: the gain `K = R⁻¹ Bᵀ X` (`m × n`) minimising
    /// `∫ (xᵀ Q x + uᵀ R u) dt` for `u = −K x`, with `X` the stabilising
    /// solution of the continuous algebraic Riccati equation (see
    /// [`DynLqr`]). MATLAB's and python-control's `lqr(sys, Q, R)`; the
    /// run-time counterpart of [`lqr`](crate::design::lqr).
    ///
    /// # Errors
    ///
    /// [`Error::DimensionMismatch`] unless `Q` is `n × n` and `R` `m × m`;
    /// [`Error::NonFinite`] for a non-finite weight;
    /// [`Error::InvalidMatrix`] unless `Q` is symmetric positive
    /// semidefinite and `R` symmetric positive definite;
    /// [`Error::NoConvergence`] if the doubling does not converge;
    /// [`Error::Unstable`] if the solution does not stabilise the loop (the
    /// plant is not stabilisable, or `(A, Q)` not detectable).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{Cart, DynStateSpace, MassSpring};
    /// use nalgebra::{DMatrix, dmatrix, dvector};
    ///
    /// let plant = DynStateSpace::from(MassSpring::nominal().state_space(Cart::Two)?);
    /// let q = DMatrix::from_diagonal(&dvector![0.0, 0.0, 1e6, 0.0]);
    /// let sol = plant.lqr(&q, &dmatrix![1.0])?;
    /// assert_eq!(sol.gain.shape(), (1, 4));
    /// assert!(sol.poles.iter().all(|p| p.re < 0.0));
    /// assert!(sol.residual < 1e-12);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn lqr(&self, q: &DMatrix<f64>, r: &DMatrix<f64>) -> Result<DynLqr, Error> {
        check_weight_shapes(self.states(), self.inputs(), q, r)?;
        continuous(self.a(), self.b(), q, r, Weights::Regulator(["Q", "R"])).map(DynLqr::from)
    }
}

impl DynStateSpace<Discrete> {
    /// Discrete-time LQR: the gain `K = (R + Bᵀ X B)⁻¹ Bᵀ X A` (`m × n`)
    /// minimising `Σ (xᵀ Q x + uᵀ R u)` for `u[k] = −K x[k]`, with `X` the
    /// stabilising solution of the discrete algebraic Riccati equation (see
    /// [`DynLqr`]). MATLAB's `lqr(sys, Q, R)` on a discrete model,
    /// python-control's `dlqr`; the run-time counterpart of
    /// [`dlqr`](crate::design::dlqr).
    ///
    /// # Errors
    ///
    /// As [`DynStateSpace::<Continuous>::lqr`]; [`Error::Unstable`] means a
    /// closed-loop pole on or outside the unit circle.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{Cart, DynStateSpace, MassSpring, Discretization};
    /// use nalgebra::{DMatrix, dmatrix, dvector};
    ///
    /// let d = MassSpring::nominal().state_space(Cart::Two)?.discretize(0.002, Discretization::Zoh)?;
    /// let plant = DynStateSpace::from(d);
    /// let q = DMatrix::from_diagonal(&dvector![1e4, 0.0, 1e6, 0.0]);
    /// let sol = plant.lqr(&q, &dmatrix![1.0])?;
    /// assert!(sol.poles.iter().all(|z| z.norm() < 1.0));
    /// assert!(sol.residual < 1e-12);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[doc(alias = "dlqr")]
    pub fn lqr(&self, q: &DMatrix<f64>, r: &DMatrix<f64>) -> Result<DynLqr, Error> {
        check_weight_shapes(self.states(), self.inputs(), q, r)?;
        discrete(
            self.a(),
            self.b(),
            q,
            r,
            Weights::Regulator(["Q", "R"]),
            Some(self.dt()),
        )
        .map(DynLqr::from)
    }
}

fn check_weight_shapes(
    n: usize,
    m: usize,
    q: &DMatrix<f64>,
    r: &DMatrix<f64>,
) -> Result<(), Error> {
    check_shape("Q", q, n, n)?;
    check_shape("R", r, m, m)
}

fn check_problem(
    a: &DMatrix<f64>,
    b: &DMatrix<f64>,
    q: &DMatrix<f64>,
    r: &DMatrix<f64>,
) -> Result<(), Error> {
    let (n, m) = (a.nrows(), b.ncols());
    check_shape("A", a, n, n)?;
    check_shape("B", b, n, m)?;
    check_weight_shapes(n, m, q, r)?;
    check_finite_dyn("A", a)?;
    check_finite_dyn("B", b)
}

/// Checks the weights for `weights`; `continuous` says whether `R` must be
/// definite even for a bare equation (its inverse is in the equation).
/// Written over nalgebra's `Dim`, so a fixed-size design checks on the
/// stack.
///
/// Definiteness is tested by Cholesky factorisations of shifted copies
/// (each weight first scaled to a largest entry in `[1, 2)`, so its norm
/// cannot overflow): `Q + δ I` with `δ = 1e-12 ‖Q‖_F` factors exactly when
/// the smallest eigenvalue of `Q` is above `−δ`, and `R − δ I` with
/// `δ = ε m ‖R‖_F` when that of `R` is above `δ`; this agrees with
/// comparing the smallest eigenvalue up to rounding at the boundary, at a
/// fraction of the cost.
pub(crate) fn check_weights<N: Dim, M: Dim>(
    q: &OMatrix<f64, N, N>,
    r: &OMatrix<f64, M, M>,
    weights: Weights,
    continuous: bool,
) -> Result<(), Error>
where
    DefaultAllocator: Allocator<N, N> + Allocator<M, M>,
{
    let [q_name, r_name] = match weights {
        Weights::Regulator(names) => names,
        Weights::Equation => ["Q", "R"],
    };
    check_finite_dyn(q_name, q)?;
    check_finite_dyn(r_name, r)?;
    // Scaled to unit largest entry first: the norm of weights near
    // f64::MAX must not overflow.
    let q = q / pow2_floor(q.amax());
    let r = r / pow2_floor(r.amax());
    if (&q - q.transpose()).norm() > 1e-12 * q.norm() {
        return Err(Error::InvalidMatrix {
            matrix: q_name,
            reason: "must be symmetric",
        });
    }
    if (&r - r.transpose()).norm() > 1e-12 * r.norm() {
        return Err(Error::InvalidMatrix {
            matrix: r_name,
            reason: "must be symmetric",
        });
    }
    if matches!(weights, Weights::Regulator(_)) && !semidefinite(&q) {
        return Err(Error::InvalidMatrix {
            matrix: q_name,
            reason: "must be positive semidefinite",
        });
    }
    let m = r.nrows();
    if matches!(weights, Weights::Regulator(_)) || continuous {
        if m == 0 || !definite(&r, f64::EPSILON * m as f64 * r.norm()) {
            return Err(Error::InvalidMatrix {
                matrix: r_name,
                reason: "must be positive definite",
            });
        }
    } else if m == 0 || !semidefinite(&r) {
        return Err(Error::InvalidMatrix {
            matrix: r_name,
            reason: "must be positive semidefinite",
        });
    }
    Ok(())
}

/// Whether the symmetric `m` has no eigenvalue below `−1e-12 ‖m‖_F`.
fn semidefinite<D: Dim>(m: &OMatrix<f64, D, D>) -> bool
where
    DefaultAllocator: Allocator<D, D>,
{
    m.norm() == 0.0 || definite(m, -1e-12 * m.norm())
}

/// Whether the symmetric `m − shift I` is positive definite (its Cholesky
/// factorisation exists).
fn definite<D: Dim>(m: &OMatrix<f64, D, D>, shift: f64) -> bool
where
    DefaultAllocator: Allocator<D, D>,
{
    let mut shifted = m.clone();
    for i in 0..m.nrows() {
        shifted[(i, i)] -= shift;
    }
    Cholesky::new(shifted).is_some()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::signal::Rng;
    use nalgebra::DVector;

    /// `V diag(λ) Vᵀ` with a random orthogonal `V`, the largest `|λ|` 1 and
    /// the smallest eigenvalue `lowest` (relative to `‖·‖_F`).
    fn symmetric_with(n: usize, lowest: f64, rng: &mut Rng) -> DMatrix<f64> {
        let v = DMatrix::from_fn(n, n, |_, _| rng.gaussian()).qr().q();
        let mut lambda = DVector::from_fn(n, |_, _| 0.1 + 0.9 * rng.uniform());
        lambda[0] = 1.0;
        // ‖·‖_F is ‖λ‖₂; set the last eigenvalue to `lowest` times it.
        let rest = lambda.rows(0, n - 1).norm();
        lambda[n - 1] = lowest * rest / (1.0 - lowest * lowest).sqrt();
        &v * DMatrix::from_diagonal(&lambda) * v.transpose()
    }

    #[test]
    fn cholesky_definiteness_agrees_with_the_smallest_eigenvalue() {
        let mut rng = Rng::new(11);
        let r1 = DMatrix::identity(1, 1);
        let q1 = DMatrix::identity(1, 1);
        let regulator = Weights::Regulator(["Q", "R"]);
        for n in 2..=7 {
            for _ in 0..40 {
                let scale = 10f64.powf(rng.uniform() * 200.0 - 100.0);
                // Q: semidefinite down to −1e-12 ‖Q‖ (decided 100× away).
                for (lowest, ok) in [(-1e-10, false), (-1e-14, true), (0.0, true), (0.3, true)] {
                    let q = symmetric_with(n, lowest, &mut rng) * scale;
                    let res = check_weights(&q, &r1, regulator, true);
                    assert_eq!(res.is_ok(), ok, "Q, n = {n}, λmin = {lowest}·‖Q‖: {res:?}");
                }
                // R: definite above ε m ‖R‖ for a regulator, semidefinite
                // for a discrete equation.
                for (lowest, definite, semidefinite) in [
                    (1e-13, true, true),
                    (-1e-14, false, true),
                    (-1e-10, false, false),
                    (0.3, true, true),
                ] {
                    let r = symmetric_with(n, lowest, &mut rng) * scale;
                    let lqr = check_weights(&q1, &r, regulator, true);
                    assert_eq!(
                        lqr.is_ok(),
                        definite,
                        "R, n = {n}, λmin = {lowest}·‖R‖: {lqr:?}"
                    );
                    let equation = check_weights(&q1, &r, Weights::Equation, false);
                    assert_eq!(
                        equation.is_ok(),
                        semidefinite,
                        "R (equation), n = {n}, λmin = {lowest}·‖R‖"
                    );
                }
            }
        }
    }
}
