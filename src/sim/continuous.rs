//! Continuous simulation: [`simulate`] on a time grid, by exact ZOH steps
//! or RK4 ([`Solver`]), and the ZOH recursion behind it and the continuous
//! standard responses.

use nalgebra::{DefaultAllocator, Dim, OMatrix, OVector, allocator::Allocator};

use super::{
    Abcd, MAX_RK4_STEPS, Response, Simulate, Solver, States, check_grid, check_input, check_state,
    grid_rounding, uniform_step, wrong_domain,
};
use crate::discretize::{Held, zoh};
use crate::error::Error;
use crate::model::{Continuous, Token};

/// Simulates a continuous model over the time grid `t` (s, strictly
/// increasing) from state `x0`.
///
/// The input is sampled at each grid time and held until the next, as a
/// digital controller applies it; use a finer grid for a smooth input.
/// [`Solver::Zoh`] is exact for that input, [`Solver::Rk4`] integrates it.
/// A grid whose intervals agree to within the rounding of its times (any
/// `k·dt` or accumulated grid) is simulated with one discretisation.
///
/// # Errors
///
/// [`Error::InvalidParameter`] named `"t"` for an empty, non-finite or
/// non-increasing grid (or more than [`MAX_SAMPLES`](super::MAX_SAMPLES) points), named
/// `"substeps"` for zero RK4 sub-steps or more than [`MAX_RK4_STEPS`] in all,
/// named `"input"` for a non-finite input sample; [`Error::NonFinite`] named
/// `"x0"` for a non-finite initial state; [`Error::LengthMismatch`] named
/// `"x0"` or `"input"` for a vector of the wrong length (a run-time-sized
/// model); [`Error::Overflow`] when the response diverges past `f64::MAX`;
/// errors of [`discretize`](crate::StateSpace::discretize).
///
/// # Examples
///
/// ```
/// use ctrlab::{DynStateSpace, MassSpring, Cart, sim::{simulate, time_grid, Solver}};
/// use ctrlab::nalgebra::{DVector, dvector, vector};
///
/// let sys = MassSpring::nominal().state_space(Cart::Two)?;
/// let t = time_grid(10.0, 0.002)?;
/// let r = simulate(&sys, &t, vector![0.0, 0.0, 0.0, 0.0], |_t| vector![10.0], Solver::Zoh)?;
/// // 10 N on cart 2 settles at 20 mm.
/// assert!((r.y.last().unwrap()[0] - 0.020).abs() < 1e-9);
///
/// // The same model sized at run time.
/// let dynamic = DynStateSpace::from(&sys);
/// let d = simulate(&dynamic, &t, DVector::zeros(4), |_t| dvector![10.0], Solver::Zoh)?;
/// assert_eq!(d.output(0)?, r.output(0)?);
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[doc(alias = "lsim")]
pub fn simulate<S: Simulate<Domain = Continuous>>(
    sys: &S,
    t: &[f64],
    x0: S::State,
    input: impl FnMut(f64) -> S::Input,
    solver: Solver,
) -> Result<S::Response, Error> {
    sys.lsim(Token(()), t, x0, input, solver)
}

/// [`simulate`] on the matrices of a continuous model (`period` is `None`).
pub(super) fn lsim<N: Dim, M: Dim, P: Dim>(
    (a, b, c, d): Abcd<'_, N, M, P>,
    period: Option<f64>,
    t: &[f64],
    x0: OVector<f64, N>,
    mut input: impl FnMut(f64) -> OVector<f64, M>,
    solver: Solver,
) -> Result<Response<N, P>, Error>
where
    DefaultAllocator: Allocator<N, N> + Allocator<N, M> + Allocator<P, N> + Allocator<P, M>,
    DefaultAllocator: Allocator<N> + Allocator<M> + Allocator<P>,
{
    if period.is_some() {
        return Err(wrong_domain(
            "a discrete model is simulated by simulate_discrete",
        ));
    }
    check_grid(t)?;
    check_state(&x0, a.nrows())?;
    if let Solver::Rk4 { substeps } = solver {
        let bad = |reason| Error::InvalidParameter {
            name: "substeps",
            value: substeps as f64,
            reason,
        };
        if substeps == 0 {
            return Err(bad("RK4 needs at least one sub-step per interval"));
        }
        match substeps.checked_mul(t.len() - 1) {
            Some(total) if total <= MAX_RK4_STEPS => {}
            _ => return Err(bad("more than sim::MAX_RK4_STEPS RK4 steps in all")),
        }
    }
    let Solver::Rk4 { substeps } = solver else {
        let (x, y) = lsim_zoh(a, b, c, d, t, x0, input)?;
        return Ok(Response {
            t: t.to_vec(),
            x,
            y,
        });
    };
    let mut xs = Vec::with_capacity(t.len());
    let mut ys = Vec::with_capacity(t.len());
    let mut x = x0;
    let uniform = uniform_step(t, grid_rounding(t));
    for (k, &tk) in t.iter().enumerate() {
        let u = input(tk);
        check_input(&u, b.ncols())?;
        ys.push(c * &x + d * &u);
        xs.push(x.clone());
        let Some(&next) = t.get(k + 1) else { break };
        let h = uniform.unwrap_or(next - tk);
        let hs = h / substeps as f64;
        for _ in 0..substeps {
            rk4_step(a, b, hs, &mut x, &u);
        }
    }
    let finite = |v: &[f64]| v.iter().fold(true, |ok, v| ok & v.is_finite());
    if !xs
        .iter()
        .zip(&ys)
        .all(|(x, y)| finite(x.as_slice()) & finite(y.as_slice()))
    {
        return Err(Error::Overflow {
            operation: DIVERGED_CONTINUOUS,
        });
    }
    Ok(Response {
        t: t.to_vec(),
        x: xs,
        y: ys,
    })
}

/// One classical RK4 step of `x' = A x + B u` with `u` held: the
/// arithmetic of [`Rk4`](crate::integrate::Rk4) on a linear model, for
/// matrices of either size (nothing allocated for fixed sizes).
fn rk4_step<N: Dim, M: Dim>(
    a: &OMatrix<f64, N, N>,
    b: &OMatrix<f64, N, M>,
    h: f64,
    x: &mut OVector<f64, N>,
    u: &OVector<f64, M>,
) where
    DefaultAllocator: Allocator<N, N> + Allocator<N, M> + Allocator<N> + Allocator<M>,
{
    let half = 0.5 * h;
    let f = |x: &OVector<f64, N>| a * x + b * u;
    let k1 = f(x);
    let k2 = f(&(&*x + &k1 * half));
    let k3 = f(&(&*x + &k2 * half));
    let k4 = f(&(&*x + &k3 * h));
    *x += (k1 + (k2 + k3) * 2.0 + k4) * (h / 6.0);
}

/// What a continuous simulation that overflows reports.
const DIVERGED_CONTINUOUS: &str = "simulation (the response diverged past f64::MAX)";

/// The states and outputs of `(A, B, C, D)` over the grid `t` (checked)
/// from `x0` (checked) under the input `input(t)` held between grid times,
/// by exact ZOH steps: the one implementation behind [`simulate`] (both
/// model sizes) and the continuous standard responses. For fixed-size
/// matrices nothing in the loop allocates.
pub(crate) fn lsim_zoh<N: Dim, M: Dim, P: Dim>(
    a: &OMatrix<f64, N, N>,
    b: &OMatrix<f64, N, M>,
    c: &OMatrix<f64, P, N>,
    d: &OMatrix<f64, P, M>,
    t: &[f64],
    x0: OVector<f64, N>,
    mut input: impl FnMut(f64) -> OVector<f64, M>,
) -> Result<States<N, P>, Error>
where
    DefaultAllocator: Allocator<N, N> + Allocator<N, M> + Allocator<P, N> + Allocator<P, M>,
    DefaultAllocator: Allocator<N> + Allocator<M> + Allocator<P>,
{
    let mut xs = Vec::with_capacity(t.len());
    let mut ys = Vec::with_capacity(t.len());
    let mut x = x0;
    // Intervals that differ by no more than the rounding of the grid's
    // times are one interval: a uniform grid is one discretisation with its
    // mean step (no drift), however its times were rounded.
    let tol = grid_rounding(t);
    let uniform = uniform_step(t, tol);
    if let Some(h) = uniform {
        // One discretisation for the whole grid, and a loop that holds
        // only the recursion and the stores.
        let (ad, bd) = zoh(a, b, h)?;
        // The finite check folded into the loop: once a state component is
        // not finite, every component of every later state is not (`A x`
        // sums every column, and 0·∞ and 0·NaN are NaN), so the last state
        // stands for all; each output is probed with `0·v` (0, or NaN for ±∞ and NaN).
        let mut probe = 0.0;
        for &tk in t {
            let u = input(tk);
            check_input(&u, b.ncols())?;
            let y = c * &x + d * &u;
            probe += y.iter().map(|v| v * 0.0).sum::<f64>();
            let next = &ad * &x + &bd * &u;
            xs.push(x);
            ys.push(y);
            x = next;
        }
        let last = xs.last().is_none_or(|x| x.iter().all(|v| v.is_finite()));
        if !(last && probe == 0.0) {
            return Err(Error::Overflow {
                operation: DIVERGED_CONTINUOUS,
            });
        }
        return Ok((xs, ys));
    }
    // ZOH matrices, recomputed only when the interval length changes.
    let mut cached: Option<(f64, Held<N, M>)> = None;
    for (k, &tk) in t.iter().enumerate() {
        let u = input(tk);
        check_input(&u, b.ncols())?;
        let y = c * &x + d * &u;
        let next = match t.get(k + 1) {
            None => None,
            Some(&next) => {
                let h = next - tk;
                let same = matches!(&cached, Some((hc, ..)) if (hc - h).abs() <= tol);
                if !same {
                    cached = Some((h, zoh(a, b, h)?));
                }
                cached.as_ref().map(|(_, (ad, bd))| ad * &x + bd * &u)
            }
        };
        xs.push(x);
        ys.push(y);
        match next {
            Some(next) => x = next,
            None => break,
        }
    }
    let finite = |v: &[f64]| v.iter().fold(true, |ok, v| ok & v.is_finite());
    if xs
        .iter()
        .zip(&ys)
        .all(|(x, y)| finite(x.as_slice()) & finite(y.as_slice()))
    {
        Ok((xs, ys))
    } else {
        Err(Error::Overflow {
            operation: DIVERGED_CONTINUOUS,
        })
    }
}
