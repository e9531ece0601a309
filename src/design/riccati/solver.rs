//! The solvers themselves, written once over nalgebra's dimensions: the
//! Cayley transform and doubling, Newton refinement, the residuals, and the
//! closed-loop check. [`Lqr`](crate::design::Lqr#algorithm) documents the method.

use nalgebra::{Complex, DMatrix, DefaultAllocator, Dim, OMatrix, allocator::Allocator};

use super::kernels::{
    MAX_ITERATIONS, Square, finite, fro, inverse, lyapunov, sda, stein, symmetrize,
};
use super::{Weights, check_weights};
use crate::analysis::{eigenvalues_dyn, first_unstable_dyn};
use crate::error::Error;
use crate::kernels::linalg::{Lu, SystemAlloc};
use crate::kernels::reduce::pow2_floor;

/// A continuous solution with a relative residual above this after Newton
/// refinement is retried with another Cayley shift, unless Newton stalled
/// (the residual is then the problem's rounding floor); the best is kept.
const GOOD_RESIDUAL: f64 = 1e-13;
/// A Newton stall above this relative residual is not the problem's
/// rounding floor but a poor start (doubling on an ill-conditioned
/// Hamiltonian): the other shifts are tried.
const STALL_FLOOR: f64 = 1e-8;
/// Newton refinement steps after the doubling, at most.
const REFINE_STEPS: usize = 3;
/// Newton steps after doubling on a regularised `R` (a discrete equation
/// with a singular `R`): the start is then about 1e-8 away, so Newton is the
/// solver here, not a polish, and runs until the residual stops falling.
const REGULARISED_REFINE_STEPS: usize = 12;
/// Cayley shifts tried, as multiples of the Hamiltonian's scale.
const SHIFTS: [f64; 7] = [1.0, 0.5, 2.0, 0.25, 4.0, 0.1, 10.0];

/// A solution in the caller's matrix sizes; [`Lqr`](crate::design::Lqr)
/// is built from it.
pub(crate) struct Solution<N: Dim, M: Dim>
where
    DefaultAllocator: SystemAlloc<N, M>,
{
    pub(crate) gain: OMatrix<f64, M, N>,
    pub(crate) riccati: Square<N>,
    pub(crate) poles: Vec<Complex<f64>>,
    pub(crate) residual: f64,
    pub(crate) iterations: usize,
}

/// A copy on the heap, for the checks and diagnostics written for
/// run-time-sized matrices (outside the iterations).
fn heap<R: Dim, C: Dim>(m: &OMatrix<f64, R, C>) -> DMatrix<f64>
where
    DefaultAllocator: Allocator<R, C>,
{
    DMatrix::from_iterator(m.nrows(), m.ncols(), m.iter().copied())
}

/// The continuous solver behind [`care`](crate::design::care) and
/// [`lqr`](crate::design::lqr); shapes already checked.
pub(crate) fn continuous<N: Dim, M: Dim>(
    a: &Square<N>,
    b: &OMatrix<f64, N, M>,
    q: &Square<N>,
    r: &OMatrix<f64, M, M>,
    weights: Weights,
) -> Result<Solution<N, M>, Error>
where
    DefaultAllocator: SystemAlloc<N, M>,
{
    check_weights(q, r, weights, true)?;
    let (q, r, weight) = balance_weights(q, r);
    let (dim, _) = a.shape_generic();
    let r_inv_bt = Lu::new(&r, "LQR (R)")?.solve(&b.transpose());
    let mut g = b * &r_inv_bt;
    symmetrize(&mut g);
    let eval = |x: &Square<N>| care_eval(a, b, &r_inv_bt, &q, x);
    // Newton step: (A − G X)ᵀ Δ + Δ (A − G X) + Res(X) = 0.
    let newton = |x: &Square<N>, res: &Square<N>| {
        let a_c = a - b * (&r_inv_bt * x);
        lyapunov(&a_c, res)
    };

    let scale = fro(a).max((fro(&g) * fro(&q)).sqrt());
    let gamma0 = if scale > 0.0 && scale.is_finite() {
        scale
    } else {
        1.0
    };
    let id = Square::<N>::identity_generic(dim, dim);
    let mut best: Option<(Square<N>, usize, f64)> = None;
    let mut last_err = None;
    for factor in SHIFTS {
        let gamma = gamma0 * factor;
        let attempt = (|| {
            let a_g = a - &id * gamma;
            let a_g_inv_g = Lu::new(&a_g, "LQR Cayley transform (A − γI)")?.solve(&g);
            let w = a_g.transpose() + &q * &a_g_inv_g;
            let w_inv = inverse(&w, "LQR Cayley transform (W)")?;
            let e0 = &id + w_inv.transpose() * (2.0 * gamma);
            let mut g0 = &a_g_inv_g * &w_inv * (2.0 * gamma);
            // H₀ = 2γ W⁻¹ Q A_γ⁻¹; Q A_γ⁻¹ = (A_γ⁻ᵀ Q)ᵀ as Q is symmetric.
            let q_a_inv = Lu::new(&a_g.transpose(), "LQR Cayley transform (A − γI)")?
                .solve(&q)
                .transpose();
            let mut h0 = &w_inv * &q_a_inv * (2.0 * gamma);
            symmetrize(&mut g0);
            symmetrize(&mut h0);
            sda(e0, g0, h0)
        })();
        match attempt {
            Ok((x, iterations)) => {
                let (x, res, stalled) =
                    refine(x, REFINE_STEPS, 4.0 * f64::EPSILON, false, &eval, &newton);
                if best.as_ref().is_none_or(|(_, _, r)| res < *r) {
                    best = Some((x, iterations, res));
                }
                // Another shift helps only where Newton could not finish
                // the job; at a stall the residual is the problem's floor,
                // and every shift lands on it (7 times the cost for nothing).
                if res <= GOOD_RESIDUAL || stalled && res <= STALL_FLOOR {
                    break;
                }
            }
            Err(e) => last_err = Some(e),
        }
    }
    let Some((x, iterations, residual)) = best else {
        let err = last_err.unwrap_or(Error::NoConvergence {
            operation: "LQR Riccati doubling",
            iterations: MAX_ITERATIONS,
        });
        return Err(explain(a, b, None).unwrap_or(err));
    };
    let gain = &r_inv_bt * &x;
    finish(a, b, gain, x, weight, residual, iterations, None)
}

/// The discrete solver behind [`dare`](crate::design::dare) and
/// [`dlqr`](crate::design::dlqr); shapes already checked. `period` is the
/// model's (`None` for a bare equation).
pub(crate) fn discrete<N: Dim, M: Dim>(
    a: &Square<N>,
    b: &OMatrix<f64, N, M>,
    q: &Square<N>,
    r: &OMatrix<f64, M, M>,
    weights: Weights,
    period: Option<f64>,
) -> Result<Solution<N, M>, Error>
where
    DefaultAllocator: SystemAlloc<N, M>,
{
    check_weights(q, r, weights, false)?;
    let (q, r, weight) = balance_weights(q, r);
    let (m, _) = r.shape_generic();
    // A singular R (accepted for an equation only) is regularised for the
    // doubling, which needs R⁻¹; Newton on the true equation then removes δ.
    let (r_inv_bt, regularised) = match Lu::new(&r, "LQR (R)") {
        Ok(r_lu) => (r_lu.solve(&b.transpose()), false),
        Err(e) if matches!(weights, Weights::Regulator(_)) => return Err(e),
        Err(_) => {
            let delta = 1e-8 * (fro(&r) + fro(b).powi(2) * fro(&q));
            let delta = if delta > 0.0 && delta.is_finite() {
                delta
            } else {
                1.0
            };
            let r_reg = &r + OMatrix::<f64, M, M>::identity_generic(m, m) * delta;
            let r_lu = Lu::new(&r_reg, "DLQR (R + δI)")?;
            (r_lu.solve(&b.transpose()), true)
        }
    };
    let mut g = b * &r_inv_bt;
    symmetrize(&mut g);
    let (x, iterations) =
        sda(a.clone(), g, q.clone()).map_err(|err| explain(a, b, Some(1.0)).unwrap_or(err))?;
    let eval = |x: &Square<N>| match dare_gain(a, b, &r, x) {
        Ok(gain) => dare_eval(a, b, &q, x, &gain),
        Err(_) => (x * 0.0, f64::INFINITY),
    };
    // Newton (Hewer) step: Δ − A_clᵀ Δ A_cl = Res(X), A_cl = A − B K(X).
    let newton = |x: &Square<N>, res: &Square<N>| {
        let gain = dare_gain(a, b, &r, x).ok()?;
        let a_cl = a - b * &gain;
        stein(&a_cl, res)
    };
    let steps = if regularised {
        REGULARISED_REFINE_STEPS
    } else {
        REFINE_STEPS
    };
    let (x, residual, _) = refine(x, steps, 4.0 * f64::EPSILON, regularised, &eval, &newton);
    let gain = dare_gain(a, b, &r, &x)?;
    finish(
        a,
        b,
        gain,
        x,
        weight,
        residual,
        iterations,
        Some(period.unwrap_or(1.0)),
    )
}

/// Why no solution was found, when the plant says so: the first unstable
/// eigenvalue of `A` that the input cannot reach (`[A − λI, B]` loses rank
/// by the PBH test, to 1e-8 of `‖A‖ + ‖B‖`), as [`Error::Unstable`].
/// Without a stabilisable `(A, B)` the stabilising solution does not exist
/// and the doubling diverges; this names the mode. Only run on failure:
/// one SVD per unstable eigenvalue.
fn explain<N: Dim, M: Dim>(
    a: &Square<N>,
    b: &OMatrix<f64, N, M>,
    period: Option<f64>,
) -> Option<Error>
where
    DefaultAllocator: SystemAlloc<N, M>,
{
    let (a, b) = (heap(a), heap(b));
    let (n, m) = (a.nrows(), b.ncols());
    let poles = eigenvalues_dyn(&a).ok()?;
    let scale = fro(&a) + fro(&b);
    let zero = Complex::new(0.0, 0.0);
    let p = poles.into_iter().find(|&p| {
        let unstable = match period {
            None => p.re >= 0.0,
            Some(_) => p.norm() >= 1.0,
        };
        let pbh = DMatrix::from_fn(n, n + m, |i, j| {
            if j < n {
                Complex::new(a[(i, j)], 0.0) - if i == j { p } else { zero }
            } else {
                Complex::new(b[(i, j - n)], 0.0)
            }
        });
        // `A − p I` overflows for entries near f64::MAX (nalgebra's SVD
        // panics on the NaN that follows): nothing can be concluded then.
        // Otherwise the matrix is scaled by a power of two (exact) so that
        // its largest entry is in [1, 2) before the SVD.
        let big = pbh
            .iter()
            .fold(0.0f64, |m, z| m.max(z.re.abs()).max(z.im.abs()));
        if !unstable || !big.is_finite() || !scale.is_finite() {
            return false;
        }
        let unit = pow2_floor(big);
        let pbh = pbh.unscale(unit);
        pbh.try_svd(false, false, f64::EPSILON, 100 * (n + m))
            .is_some_and(|svd| svd.singular_values.min() * unit <= 1e-8 * scale)
    })?;
    Some(Error::Unstable {
        operation: "LQR: no stabilising Riccati solution, (A, B) is not stabilisable \
                    (an unstable mode the input cannot reach)",
        re: p.re,
        im: p.im,
    })
}

/// Newton refinement of a Riccati solution: up to `steps` steps, each kept
/// only if it lowers the relative residual, and none once that is below
/// `good` unless `to_stagnation`; returns `X`, its residual, and whether
/// the refinement stalled (a Newton step was solved but did not lower the
/// residual: `X` is then as accurate as rounding lets this problem be).
/// `step(X, Res)` solves the correction's linear equation.
fn refine<N: Dim>(
    mut x: Square<N>,
    steps: usize,
    good: f64,
    to_stagnation: bool,
    eval: &impl Fn(&Square<N>) -> (Square<N>, f64),
    step: &impl Fn(&Square<N>, &Square<N>) -> Option<Square<N>>,
) -> (Square<N>, f64, bool)
where
    DefaultAllocator: Allocator<N, N>,
{
    let (mut res, mut residual) = eval(&x);
    for _ in 0..steps {
        if residual == 0.0 || residual <= good && !to_stagnation {
            break;
        }
        let Some(delta) = step(&x, &res) else {
            break;
        };
        if !finite(&delta) {
            break;
        }
        let mut next = &x + &delta;
        symmetrize(&mut next);
        let (next_res, next_residual) = eval(&next);
        if next_residual < residual {
            (x, res, residual) = (next, next_res, next_residual);
        } else {
            return (x, residual, true);
        }
    }
    (x, residual, false)
}

/// The solution: `riccati` is of the weights scaled by `weight` (see
/// [`balance_weights`]) and is scaled back here; the closed loop must be
/// stable in the domain of `period` (`None`: continuous).
#[allow(clippy::too_many_arguments)]
fn finish<N: Dim, M: Dim>(
    a: &Square<N>,
    b: &OMatrix<f64, N, M>,
    gain: OMatrix<f64, M, N>,
    riccati: Square<N>,
    weight: f64,
    residual: f64,
    iterations: usize,
    period: Option<f64>,
) -> Result<Solution<N, M>, Error>
where
    DefaultAllocator: SystemAlloc<N, M>,
{
    if !finite(&gain) {
        return Err(Error::Overflow {
            operation: "LQR gain",
        });
    }
    let riccati = riccati * (1.0 / weight);
    if !finite(&riccati) {
        return Err(Error::Overflow {
            operation: "LQR Riccati solution (X exceeds f64::MAX for these weights)",
        });
    }
    let a_cl = heap(&(a - b * &gain));
    let poles = eigenvalues_dyn(&a_cl)?;
    if let Some(p) = first_unstable_dyn(&poles, &a_cl, period) {
        return Err(Error::Unstable {
            operation: "LQR: the Riccati solution does not stabilise the loop \
                        (is (A, B) stabilisable and (A, Q) detectable?)",
            re: p.re,
            im: p.im,
        });
    }
    Ok(Solution {
        gain,
        riccati,
        poles,
        residual,
        iterations,
    })
}

/// `Q` and `R` times one power of two `c` that brings the geometric mean of
/// their largest entries near 1 (the LQR problem does not change when both
/// weights are scaled alike: `X` scales with them, `K` not at all), and
/// `c`. Weights of 1e308 then neither overflow nor make `R⁻¹` underflow.
fn balance_weights<N: Dim, M: Dim>(
    q: &Square<N>,
    r: &OMatrix<f64, M, M>,
) -> (Square<N>, OMatrix<f64, M, M>, f64)
where
    DefaultAllocator: SystemAlloc<N, M>,
{
    let (q_max, r_max) = (q.amax(), r.amax());
    let (sq, sr) = (pow2_floor(q_max), pow2_floor(r_max));
    // 1 / √(sq sr), rounded to a power of two, without forming sq sr.
    let c = if q_max > 0.0 && r_max > 0.0 {
        1.0 / pow2_floor(sq.sqrt() * sr.sqrt())
    } else if q_max > 0.0 {
        1.0 / sq
    } else {
        1.0 / sr
    };
    (q * c, r * c, c)
}

/// The CARE left side `Aᵀ X + X A − X G X + Q` and its relative norm.
///
/// `X G X` is formed as `(X B)(R⁻¹ Bᵀ X)`: with a large `X`, the product
/// `(X G) X` loses about `ε ‖X G‖ ‖X‖`, which can be a 1e-9 part of the
/// result, while the factored form stays near `ε ‖X G X‖`.
fn care_eval<N: Dim, M: Dim>(
    a: &Square<N>,
    b: &OMatrix<f64, N, M>,
    r_inv_bt: &OMatrix<f64, M, N>,
    q: &Square<N>,
    x: &Square<N>,
) -> (Square<N>, f64)
where
    DefaultAllocator: SystemAlloc<N, M>,
{
    let at_x = a.transpose() * x;
    let xgx = (x * b) * (r_inv_bt * x);
    let lhs = &at_x + at_x.transpose() - &xgx + q;
    let rel = relative(fro(&lhs), &[2.0 * fro(&at_x), fro(&xgx), fro(q)]);
    (lhs, rel)
}

/// `K = (R + Bᵀ X B)⁻¹ Bᵀ X A`.
fn dare_gain<N: Dim, M: Dim>(
    a: &Square<N>,
    b: &OMatrix<f64, N, M>,
    r: &OMatrix<f64, M, M>,
    x: &Square<N>,
) -> Result<OMatrix<f64, M, N>, Error>
where
    DefaultAllocator: SystemAlloc<N, M>,
{
    let bt_x = b.transpose() * x;
    let s = r + &bt_x * b;
    Ok(Lu::new(&s, "DLQR (R + Bᵀ X B)")?.solve(&(&bt_x * a)))
}

/// The DARE residual `Aᵀ X A − Aᵀ X B K + Q − X` (with `K` the optimal gain
/// for `X`) and its relative norm.
fn dare_eval<N: Dim, M: Dim>(
    a: &Square<N>,
    b: &OMatrix<f64, N, M>,
    q: &Square<N>,
    x: &Square<N>,
    gain: &OMatrix<f64, M, N>,
) -> (Square<N>, f64)
where
    DefaultAllocator: SystemAlloc<N, M>,
{
    let at = a.transpose();
    let atxa = &at * (x * a);
    let cross = (&at * (x * b)) * gain;
    let lhs = &atxa - &cross + q - x;
    let rel = relative(fro(&lhs), &[fro(&atxa), fro(x), fro(&cross), fro(q)]);
    (lhs, rel)
}

fn relative(err: f64, terms: &[f64]) -> f64 {
    let scale: f64 = terms.iter().sum();
    if scale > 0.0 { err / scale } else { err }
}
