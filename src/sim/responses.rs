//! A model's responses to the standard test inputs, in either time domain,
//! under python-control's names: [`step_response`], [`impulse_response`]
//! and [`initial_response`].
//!
//! Each takes the model, `t_end` and `dt` and returns its [`Response`] on
//! [`time_grid`]`(t_end, dt)`. A continuous model is simulated exactly (ZOH
//! is exact for these inputs), so `dt` only chooses where the response is
//! sampled; a discrete model's response exists only at its samples, so
//! there `dt` must be its period `sys.dt()` (checked: a different value is
//! almost certainly a mistake, not a request to resample).

use nalgebra::SVector;

use super::{Response, Solver, simulate, simulate_discrete_feedback, time_grid};
use crate::error::{Error, check_finite};
use crate::model::{Domain, StateSpace, period_of};

/// The grid of a response of a model in `domain`.
pub(super) fn grid<D: Domain>(domain: &D, t_end: f64, dt: f64) -> Result<Vec<f64>, Error> {
    match period_of(domain) {
        None => time_grid(t_end, dt),
        // NaN fails the comparison too.
        Some(period) if (dt - period).abs() <= 1e-9 * period => time_grid(t_end, period),
        Some(_) => Err(Error::InvalidParameter {
            name: "dt",
            value: dt,
            reason: "must be the discrete model's sampling period sys.dt() \
                     (its response exists only at its samples)",
        }),
    }
}

/// The response from `x0` to the input `input(k)` at sample `k` (held
/// between samples in continuous time).
fn respond<const N: usize, const M: usize, const P: usize, D: Domain>(
    sys: &StateSpace<N, M, P, D>,
    t_end: f64,
    dt: f64,
    x0: SVector<f64, N>,
    input: impl Fn(usize) -> SVector<f64, M>,
) -> Result<Response<N, P>, Error> {
    check_finite("x0", &x0)?;
    let t = grid(&sys.domain(), t_end, dt)?;
    let (a, b, c, d) = (*sys.a(), *sys.b(), *sys.c(), *sys.d());
    match period_of(&sys.domain()) {
        None => {
            let continuous = StateSpace::continuous(a, b, c, d)?;
            // `simulate` asks for the input once per grid time, in order.
            let mut k = 0;
            let next = |_t: f64| {
                k += 1;
                input(k - 1)
            };
            simulate(&continuous, &t, x0, next, Solver::Zoh)
        }
        Some(period) => {
            let discrete = StateSpace::discrete(a, b, c, d, period)?;
            simulate_discrete_feedback(&discrete, x0, t.len(), |k, _x| input(k))
        }
    }
}

/// The unit step response of a single-input model from rest (python-control
/// `step_response`, MATLAB `step`): `u = 1` from `t = 0` on, so
/// `y[0] = D`. For a model with several inputs, pick one with
/// [`StateSpace::select_input`].
///
/// # Errors
///
/// As [`time_grid`] and [`discretize`](StateSpace::discretize);
/// [`Error::InvalidParameter`] named `"dt"` for a discrete model unless `dt`
/// is its period; [`Error::Overflow`] for a response that diverges past
/// `f64::MAX`.
///
/// # Examples
///
/// ```
/// use ctrlab::{StateSpace, sim::step_response};
/// use nalgebra::matrix;
///
/// // First-order lag, τ = 0.5 s: y(τ) = 1 - e^-1.
/// let sys = StateSpace::continuous(matrix![-2.0], matrix![2.0], matrix![1.0], matrix![0.0])?;
/// let r = step_response(&sys, 1.0, 0.5)?;
/// assert!((r.y[1][0] - (1.0 - (-1.0f64).exp())).abs() < 1e-14);
///
/// // Its exact discretisation has the same step response at the samples.
/// let d = sys.discretize(0.5, ctrlab::Discretization::Zoh)?;
/// let rd = step_response(&d, 1.0, d.dt())?;
/// assert!((rd.y[1][0] - r.y[1][0]).abs() < 1e-14);
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[doc(alias = "step")]
pub fn step_response<const N: usize, const P: usize, D: Domain>(
    sys: &StateSpace<N, 1, P, D>,
    t_end: f64,
    dt: f64,
) -> Result<Response<N, P>, Error> {
    respond(sys, t_end, dt, SVector::zeros(), |_| {
        SVector::from_element(1.0)
    })
}

/// The impulse response of a single-input model from rest, as
/// python-control 0.10.2 defines it (`control/timeresp.py`,
/// `impulse_response`):
///
/// - continuous: the response to a unit Dirac impulse `δ(t)`, i.e. the free
///   response from `x(0) = B` (`y(t) = C e^{At} B`). The impulse `D δ(t)`
///   that a feedthrough passes straight to the output has no finite value
///   and is left out (python-control warns about it);
/// - discrete: the response to a **unit-area pulse** `u[0] = 1/dt`, `u[k] = 0`
///   after (not the unit sample `u[0] = 1`), so that it approximates the
///   continuous impulse response of the model it was sampled from:
///   `y[0] = D/dt`, `y[k] = C A^(k−1) B / dt`. The Markov parameters
///   `C A^(k−1) B` are `dt · y[k]`.
///
/// For a model with several inputs, pick one with
/// [`StateSpace::select_input`].
///
/// # Errors
///
/// As [`step_response`]; [`Error::Overflow`] for a period so short that
/// `1/dt` overflows.
///
/// # Examples
///
/// ```
/// use ctrlab::{Discretization, StateSpace, sim::impulse_response};
/// use nalgebra::matrix;
///
/// // A lag 1/(τ s + 1), τ = 0.5 s: g(t) = e^{−t/τ} / τ.
/// let sys = StateSpace::continuous(matrix![-2.0], matrix![2.0], matrix![1.0], matrix![0.0])?;
/// let r = impulse_response(&sys, 1.0, 0.5)?;
/// assert!((r.y[1][0] - 2.0 * (-1.0f64).exp()).abs() < 1e-14);
///
/// // Discrete: y[1] = C B / dt.
/// let d = sys.discretize(0.1, Discretization::Zoh)?;
/// let rd = impulse_response(&d, 1.0, 0.1)?;
/// assert_eq!(rd.y[0][0], 0.0);
/// assert!((rd.y[1][0] - d.b()[(0, 0)] / 0.1).abs() < 1e-12);
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[doc(alias = "impulse")]
pub fn impulse_response<const N: usize, const P: usize, D: Domain>(
    sys: &StateSpace<N, 1, P, D>,
    t_end: f64,
    dt: f64,
) -> Result<Response<N, P>, Error> {
    match period_of(&sys.domain()) {
        None => respond(sys, t_end, dt, sys.b().column(0).into_owned(), |_| {
            SVector::zeros()
        }),
        Some(period) => {
            let pulse = 1.0 / period;
            if !pulse.is_finite() {
                return Err(Error::Overflow {
                    operation: "impulse response (the unit-area pulse 1/dt)",
                });
            }
            respond(sys, t_end, dt, SVector::zeros(), |k| {
                SVector::from_element(if k == 0 { pulse } else { 0.0 })
            })
        }
    }
}

/// The free response from the state `x0` with every input held at zero
/// (python-control `initial_response`, MATLAB `initial`): `y = C x`.
///
/// # Errors
///
/// As [`step_response`]; [`Error::NonFinite`] named `"x0"` for a non-finite
/// initial state.
///
/// # Examples
///
/// ```
/// use ctrlab::{StateSpace, sim::initial_response};
/// use nalgebra::{matrix, vector};
///
/// // An undamped oscillator, ω = 2 rad/s, released from x = 1: cos 2t.
/// let sys = StateSpace::continuous(matrix![0.0, 1.0; -4.0, 0.0], matrix![0.0; 1.0], matrix![1.0, 0.0], matrix![0.0])?;
/// let r = initial_response(&sys, 1.0, 0.25, vector![1.0, 0.0])?;
/// assert!((r.y[4][0] - 2f64.cos()).abs() < 1e-12);
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[doc(alias = "initial")]
pub fn initial_response<const N: usize, const M: usize, const P: usize, D: Domain>(
    sys: &StateSpace<N, M, P, D>,
    t_end: f64,
    dt: f64,
    x0: SVector<f64, N>,
) -> Result<Response<N, P>, Error> {
    respond(sys, t_end, dt, x0, |_| SVector::zeros())
}
