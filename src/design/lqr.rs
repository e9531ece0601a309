//! Linear-quadratic regulators by a structure-preserving doubling algorithm;
//! the method is documented on [`Lqr`].

use nalgebra::{Complex, DMatrix, SMatrix};

use crate::analysis::{eigenvalues, first_unstable};
use crate::error::{Error, check_finite};
use crate::kernels::linalg::Lu;
use crate::kernels::reduce::pow2_floor;
use crate::model::{Continuous, Discrete, StateSpace};

/// Doubling steps allowed; quadratic convergence needs far fewer (about
/// `log2` of the ratio of the fastest to the slowest closed-loop mode, +6).
const MAX_ITERATIONS: usize = 100;
/// Stop when a doubling step changes `H` by less than this, relative.
const STEP_RTOL: f64 = 1e-15;
/// A continuous solution with a relative residual above this is retried with
/// another Cayley shift; the best one is kept.
const GOOD_RESIDUAL: f64 = 1e-13;
/// Newton refinement steps after the doubling, at most.
const REFINE_STEPS: usize = 3;

/// A solved linear-quadratic regulator: the gain, the Riccati solution, the
/// closed-loop poles, and how well the Riccati equation is satisfied.
///
/// # Method
///
/// The discrete equation
/// `X = Aᵀ X A − Aᵀ X B (R + Bᵀ X B)⁻¹ Bᵀ X A + Q` is the fixed point of the
/// SDA of Chu, Fan and Lin (2005): with `E₀ = A`, `G₀ = B R⁻¹ Bᵀ`, `H₀ = Q`,
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
/// stability boundary. Everything runs on `N × N` stack matrices. The shift
/// starts at `γ = max(‖A‖_F, √(‖G‖_F ‖Q‖_F))`, the scale of the
/// Hamiltonian's eigenvalues; if the residual is above 1e-13 a few other
/// shifts (γ/2, 2γ, γ/4, 4γ, γ/10, 10γ) are tried and the best solution kept.
///
/// On an ill-conditioned problem (a large `X` from nearly cancelling terms)
/// the doubling alone can stop at a relative residual of about 1e-9. Up to
/// three Newton steps follow it (a Lyapunov equation for the continuous
/// case, a Stein equation for the discrete one, solved in Kronecker form),
/// each kept only if it lowers the residual.
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
    check_weights(q, r, ["Q", "R"])?;
    let (q, r, weight) = &balance_weights(q, r);
    let (a, b) = (*sys.a(), *sys.b());
    let r_lu = Lu::new(r, "LQR (R)")?;
    let r_inv_bt = r_lu.solve(&b.transpose());
    let g = symmetric(&(b * r_inv_bt));
    let id = SMatrix::<f64, N, N>::identity();

    let scale = a.norm().max((g.norm() * q.norm()).sqrt());
    let gamma0 = if scale > 0.0 && scale.is_finite() {
        scale
    } else {
        1.0
    };
    let mut best: Option<(SMatrix<f64, N, N>, usize, f64)> = None;
    let mut last_err = None;
    for factor in [1.0, 0.5, 2.0, 0.25, 4.0, 0.1, 10.0] {
        let gamma = gamma0 * factor;
        let attempt = (|| {
            let a_g = a - id * gamma;
            let a_g_lu = Lu::new(&a_g, "LQR Cayley transform (A − γI)")?;
            let a_g_inv_g = a_g_lu.solve(&g);
            let w = a_g.transpose() + q * a_g_inv_g;
            let w_lu = Lu::new(&w, "LQR Cayley transform (W)")?;
            let w_inv = w_lu.solve(&id);
            let e0 = id + w_inv.transpose() * (2.0 * gamma);
            let g0 = a_g_inv_g * w_inv * (2.0 * gamma);
            // H₀ = 2γ W⁻¹ Q A_γ⁻¹, the last factor by a right solve.
            let q_a_inv = Lu::solve_right(&a_g, q, "LQR Cayley transform (A − γI)")?;
            let h0 = w_inv * q_a_inv * (2.0 * gamma);
            sda(e0, symmetric(&g0), symmetric(&h0))
        })();
        match attempt {
            Ok((x, iterations)) => {
                let res = care_eval(&a, &b, &r_inv_bt, q, &x).1;
                if best.as_ref().is_none_or(|(_, _, r)| res < *r) {
                    best = Some((x, iterations, res));
                }
                if res <= GOOD_RESIDUAL {
                    break;
                }
            }
            Err(e) => last_err = Some(e),
        }
    }
    let Some((x, iterations, residual)) = best else {
        return Err(last_err.unwrap_or(Error::NoConvergence {
            operation: "LQR Riccati doubling",
            iterations: MAX_ITERATIONS,
        }));
    };
    let (x, residual) = refine(
        x,
        residual,
        |x| care_eval(&a, &b, &r_inv_bt, q, x),
        |x, res| {
            // Newton step: (A − G X)ᵀ Δ + Δ (A − G X) = −Res(X).
            let ac_t = (a - b * (r_inv_bt * x)).transpose();
            let id = DMatrix::<f64>::identity(N, N);
            let ac_t = DMatrix::from_fn(N, N, |i, j| ac_t[(i, j)]);
            (id.kronecker(&ac_t) + ac_t.kronecker(&id), -res)
        },
    );
    let gain = r_inv_bt * x;
    finish(
        gain,
        x,
        *weight,
        &(a - b * gain),
        residual,
        iterations,
        None,
    )
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
/// use ctrlab::{MassSpring, Method, Cart, design::dlqr};
/// use nalgebra::{SMatrix, matrix, vector};
///
/// let d = MassSpring::nominal().state_space(Cart::Two)?.discretize(0.002, Method::Zoh)?;
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
    check_weights(q, r, ["Q", "R"])?;
    let (q, r, weight) = &balance_weights(q, r);
    let (a, b) = (*sys.a(), *sys.b());
    let r_inv_bt = Lu::new(r, "LQR (R)")?.solve(&b.transpose());
    let g = symmetric(&(b * r_inv_bt));
    let (x, iterations) = sda(a, g, *q)?;
    let eval = |x: &SMatrix<f64, N, N>| match dare_gain(&a, &b, r, x) {
        Ok(gain) => dare_eval(&a, &b, q, x, &gain),
        Err(_) => (SMatrix::zeros(), f64::INFINITY),
    };
    let (_, residual) = eval(&x);
    let (x, residual) = refine(x, residual, eval, |x, res| {
        // Newton (Hewer) step: Δ − A_clᵀ Δ A_cl = Res(X), A_cl = A − B K(X).
        let gain = dare_gain(&a, &b, r, x).unwrap_or_else(|_| SMatrix::zeros());
        let ac_t = (a - b * gain).transpose();
        let ac_t = DMatrix::from_fn(N, N, |i, j| ac_t[(i, j)]);
        (
            DMatrix::identity(N * N, N * N) - ac_t.kronecker(&ac_t),
            *res,
        )
    });
    let gain = dare_gain(&a, &b, r, &x)?;
    finish(
        gain,
        x,
        *weight,
        &(a - b * gain),
        residual,
        iterations,
        Some(sys.dt()),
    )
}

/// The doubling iteration on `(E, G, H)`; returns `H` at convergence.
fn sda<const N: usize>(
    mut e: SMatrix<f64, N, N>,
    mut g: SMatrix<f64, N, N>,
    mut h: SMatrix<f64, N, N>,
) -> Result<(SMatrix<f64, N, N>, usize), Error> {
    let id = SMatrix::<f64, N, N>::identity();
    for it in 1..=MAX_ITERATIONS {
        // I + G H is nonsingular for G, H positive semidefinite.
        let w = Lu::new(&(id + g * h), "Riccati doubling (I + G H)")?;
        let w_e = w.solve(&e);
        let w_g = w.solve(&g);
        let h_next = symmetric(&(h + e.transpose() * h * w_e));
        g = symmetric(&(g + e * w_g * e.transpose()));
        e *= w_e;
        let step = (h_next - h).norm();
        h = h_next;
        if h.iter().any(|v| !v.is_finite()) {
            return Err(Error::Overflow {
                operation: "Riccati doubling",
            });
        }
        if step <= STEP_RTOL * h.norm() {
            return Ok((h, it));
        }
    }
    Err(Error::NoConvergence {
        operation: "Riccati doubling",
        iterations: MAX_ITERATIONS,
    })
}

/// `Q` and `R` times one power of two `c` that brings the geometric mean of
/// their largest entries near 1 (the LQR problem does not change when both
/// weights are scaled alike: `X` scales with them, `K` not at all), and
/// `c`. Weights of 1e308 then neither overflow nor make `R⁻¹` underflow.
fn balance_weights<const N: usize, const M: usize>(
    q: &SMatrix<f64, N, N>,
    r: &SMatrix<f64, M, M>,
) -> (SMatrix<f64, N, N>, SMatrix<f64, M, M>, f64) {
    let (sq, sr) = (pow2_floor(q.amax()), pow2_floor(r.amax()));
    // 1 / √(sq sr), rounded to a power of two, without forming sq sr.
    let c = if q.amax() > 0.0 {
        1.0 / pow2_floor(sq.sqrt() * sr.sqrt())
    } else {
        1.0 / sr
    };
    (q * c, r * c, c)
}

/// The solution: `riccati` is of the weights scaled by `weight` (see
/// [`balance_weights`]) and is scaled back here.
fn finish<const N: usize, const M: usize>(
    gain: SMatrix<f64, M, N>,
    riccati: SMatrix<f64, N, N>,
    weight: f64,
    a_cl: &SMatrix<f64, N, N>,
    residual: f64,
    iterations: usize,
    period: Option<f64>,
) -> Result<Lqr<N, M>, Error> {
    if gain.iter().any(|v| !v.is_finite()) {
        return Err(Error::Overflow {
            operation: "LQR gain",
        });
    }
    let riccati = riccati / weight;
    if riccati.iter().any(|v| !v.is_finite()) {
        return Err(Error::Overflow {
            operation: "LQR Riccati solution (X exceeds f64::MAX for these weights)",
        });
    }
    let poles = eigenvalues(a_cl)?;
    if let Some(p) = first_unstable(&poles, a_cl, period) {
        return Err(Error::Unstable {
            operation: "LQR: the Riccati solution does not stabilise the loop \
                        (is (A, B) stabilisable and (A, Q) detectable?)",
            re: p.re,
            im: p.im,
        });
    }
    Ok(Lqr {
        gain,
        riccati,
        poles,
        residual,
        iterations,
    })
}

/// The CARE left side `Aᵀ X + X A − X G X + Q` and its relative norm.
///
/// `X G X` is formed as `(X B)(R⁻¹ Bᵀ X)`: with a large `X`, the product
/// `(X G) X` loses about `ε ‖X G‖ ‖X‖`, which can be a 1e-9 part of the
/// result, while the factored form stays near `ε ‖X G X‖`.
fn care_eval<const N: usize, const M: usize>(
    a: &SMatrix<f64, N, N>,
    b: &SMatrix<f64, N, M>,
    r_inv_bt: &SMatrix<f64, M, N>,
    q: &SMatrix<f64, N, N>,
    x: &SMatrix<f64, N, N>,
) -> (SMatrix<f64, N, N>, f64) {
    let at_x = a.transpose() * x;
    let xgx = (x * b) * (r_inv_bt * x);
    let lhs = at_x + at_x.transpose() - xgx + q;
    let rel = relative(lhs.norm(), &[2.0 * at_x.norm(), xgx.norm(), q.norm()]);
    (lhs, rel)
}

/// `K = (R + Bᵀ X B)⁻¹ Bᵀ X A`.
fn dare_gain<const N: usize, const M: usize>(
    a: &SMatrix<f64, N, N>,
    b: &SMatrix<f64, N, M>,
    r: &SMatrix<f64, M, M>,
    x: &SMatrix<f64, N, N>,
) -> Result<SMatrix<f64, M, N>, Error> {
    let bt_x = b.transpose() * x;
    Ok(Lu::new(&(r + bt_x * b), "DLQR (R + Bᵀ X B)")?.solve(&(bt_x * a)))
}

/// The DARE residual `Aᵀ X A − Aᵀ X B K + Q − X` (with `K` the optimal gain
/// for `X`) and its relative norm.
fn dare_eval<const N: usize, const M: usize>(
    a: &SMatrix<f64, N, N>,
    b: &SMatrix<f64, N, M>,
    q: &SMatrix<f64, N, N>,
    x: &SMatrix<f64, N, N>,
    gain: &SMatrix<f64, M, N>,
) -> (SMatrix<f64, N, N>, f64) {
    let atxa = a.transpose() * x * a;
    let cross = (a.transpose() * (x * b)) * gain;
    let lhs = atxa - cross + q - x;
    let rel = relative(lhs.norm(), &[atxa.norm(), x.norm(), cross.norm(), q.norm()]);
    (lhs, rel)
}

/// Newton refinement of a Riccati solution: up to [`REFINE_STEPS`] steps,
/// each kept only if it lowers the relative residual. `step` returns the
/// Kronecker form `(L, rhs)` of the correction's linear (Lyapunov or Stein)
/// equation `L vec(Δ) = vec(rhs)`; `N²` unknowns, so this is for the small
/// models this crate targets.
fn refine<const N: usize>(
    mut x: SMatrix<f64, N, N>,
    mut residual: f64,
    eval: impl Fn(&SMatrix<f64, N, N>) -> (SMatrix<f64, N, N>, f64),
    step: impl Fn(&SMatrix<f64, N, N>, &SMatrix<f64, N, N>) -> (DMatrix<f64>, SMatrix<f64, N, N>),
) -> (SMatrix<f64, N, N>, f64) {
    for _ in 0..REFINE_STEPS {
        if residual <= 4.0 * f64::EPSILON {
            break;
        }
        let (res, _) = eval(&x);
        let (l, rhs) = step(&x, &res);
        let Some(delta) = l
            .lu()
            .solve(&DMatrix::from_column_slice(N * N, 1, rhs.as_slice()))
        else {
            break;
        };
        if delta.iter().any(|v| !v.is_finite()) {
            break;
        }
        let next = symmetric(&(x + SMatrix::<f64, N, N>::from_column_slice(delta.as_slice())));
        let (_, next_residual) = eval(&next);
        if next_residual < residual {
            x = next;
            residual = next_residual;
        } else {
            break;
        }
    }
    (x, residual)
}

fn relative(err: f64, terms: &[f64]) -> f64 {
    let scale: f64 = terms.iter().sum();
    if scale > 0.0 { err / scale } else { err }
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
    let [q_name, r_name] = names;
    check_finite(q_name, q)?;
    check_finite(r_name, r)?;
    // Scaled to unit largest entry first: the norm of weights near
    // f64::MAX must not overflow.
    let (q, r) = (&(q / pow2_floor(q.amax())), &(r / pow2_floor(r.amax())));
    let symmetric_enough = |asym: f64, norm: f64| asym <= 1e-12 * norm;
    if !symmetric_enough((q - q.transpose()).norm(), q.norm()) {
        return Err(Error::InvalidMatrix {
            matrix: q_name,
            reason: "must be symmetric",
        });
    }
    if !symmetric_enough((r - r.transpose()).norm(), r.norm()) {
        return Err(Error::InvalidMatrix {
            matrix: r_name,
            reason: "must be symmetric",
        });
    }
    let min_q = min_symmetric_eigenvalue(&DMatrix::from_fn(N, N, |i, j| q[(i, j)]))?;
    if min_q < -1e-12 * q.norm() {
        return Err(Error::InvalidMatrix {
            matrix: q_name,
            reason: "must be positive semidefinite",
        });
    }
    let min_r = min_symmetric_eigenvalue(&DMatrix::from_fn(M, M, |i, j| r[(i, j)]))?;
    if min_r <= f64::EPSILON * M as f64 * r.norm() || M == 0 {
        return Err(Error::InvalidMatrix {
            matrix: r_name,
            reason: "must be positive definite",
        });
    }
    Ok(())
}

fn min_symmetric_eigenvalue(m: &DMatrix<f64>) -> Result<f64, Error> {
    if m.is_empty() {
        return Ok(0.0);
    }
    let iterations = 200 * m.nrows();
    let eig = m
        .clone()
        .try_symmetric_eigen(f64::EPSILON, iterations)
        .ok_or(Error::NoConvergence {
            operation: "symmetric eigenvalues",
            iterations,
        })?;
    Ok(eig
        .eigenvalues
        .iter()
        .copied()
        .fold(f64::INFINITY, f64::min))
}
