//! Algebraic Riccati equations sized at run time, [`care`] and [`dare`]:
//! the one implementation behind [`lqr`](super::lqr) and
//! [`dlqr`](super::dlqr) too, for both model sizes. The method is
//! documented on [`Lqr`](super::Lqr#algorithm).

mod kernels;
mod solver;

use nalgebra::allocator::Allocator;
use nalgebra::{Cholesky, DMatrix, DefaultAllocator, Dim, OMatrix};

use super::lqr::{DynLqr, Lqr};
use crate::error::{Error, check_finite_dyn, check_shape};
use crate::kernels::reduce::pow2_floor;
pub(crate) use solver::{Solution, continuous, discrete};

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
/// [`Lqr`](super::Lqr#algorithm); `O(n³)` per step.
///
/// Unlike [`lqr`](super::lqr), `Q` may be indefinite (only symmetric), as
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
/// use ctrlab::nalgebra::dmatrix;
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
    continuous(a, b, q, r, Weights::Equation).map(Lqr::from)
}

/// Discrete-time algebraic Riccati equation
/// `X = Aᵀ X A − Aᵀ X B (R + Bᵀ X B)⁻¹ Bᵀ X A + Q`: its stabilising solution
/// `X` (the one that puts the poles of `A − B K` inside the unit circle),
/// with the gain `K = (R + Bᵀ X B)⁻¹ Bᵀ X A`; SciPy's
/// `solve_discrete_are(a, b, q, r)`, MATLAB's `idare(A, B, Q, R)`. Sizes as
/// [`care`]; the method is described on [`Lqr`](super::Lqr#algorithm).
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
/// use ctrlab::nalgebra::dmatrix;
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
    discrete(a, b, q, r, Weights::Equation, None).map(Lqr::from)
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
