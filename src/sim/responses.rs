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

use nalgebra::{DefaultAllocator, Dim, OVector, U1, allocator::Allocator};

use super::{Abcd, Response, Simulate, discrete_feedback, lsim_zoh, time_grid};
use crate::error::{Error, check_finite_dyn, check_len};
#[cfg(doc)]
use crate::model::StateSpace;
use crate::model::{Domain, SingleInput, Token, period_of};

/// Which standard response (the hidden argument of
/// [`Simulate`]'s implementations).
#[doc(hidden)]
#[derive(Debug, Clone, PartialEq)]
pub enum Test<X> {
    /// A unit step on the one input, from rest.
    Step,
    /// python-control's impulse, from rest.
    Impulse,
    /// The free response from this state.
    Initial(X),
}

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

/// The standard response `test` of the model `(A, B, C, D)` in `domain`:
/// the one implementation behind [`step_response`], [`impulse_response`]
/// and [`initial_response`] for both model sizes.
pub(super) fn respond<N: Dim, M: Dim, P: Dim, D: Domain>(
    abcd: Abcd<'_, N, M, P>,
    domain: D,
    test: Test<OVector<f64, N>>,
    t_end: f64,
    dt: f64,
) -> Result<Response<N, P>, Error>
where
    DefaultAllocator: Allocator<N, N> + Allocator<N, M> + Allocator<P, N> + Allocator<P, M>,
    DefaultAllocator: Allocator<N> + Allocator<M> + Allocator<P>,
{
    let (a, b, ..) = abcd;
    let (n, m) = (a.nrows(), b.ncols());
    let (dim_n, _) = a.shape_generic();
    if !matches!(test, Test::Initial(_)) && m != 1 {
        return Err(Error::DimensionMismatch {
            matrix: "B",
            expected_rows: n,
            expected_cols: 1,
            found_rows: n,
            found_cols: m,
        });
    }
    let rest = || OVector::<f64, N>::zeros_generic(dim_n, U1);
    match test {
        Test::Step => run(abcd, domain, t_end, dt, rest(), |_| 1.0),
        Test::Impulse => match period_of(&domain) {
            None => run(abcd, domain, t_end, dt, b.column(0).into_owned(), |_| 0.0),
            Some(period) => {
                let pulse = 1.0 / period;
                if !pulse.is_finite() {
                    return Err(Error::Overflow {
                        operation: "impulse response (the unit-area pulse 1/dt)",
                    });
                }
                run(abcd, domain, t_end, dt, rest(), |k| {
                    if k == 0 { pulse } else { 0.0 }
                })
            }
        },
        Test::Initial(x0) => {
            check_len("x0", n, x0.len())?;
            run(abcd, domain, t_end, dt, x0, |_| 0.0)
        }
    }
}

/// The response from `x0` to the input whose every entry is `input(k)` at
/// sample `k` (held between samples in continuous time).
fn run<N: Dim, M: Dim, P: Dim, D: Domain>(
    (a, b, c, d): Abcd<'_, N, M, P>,
    domain: D,
    t_end: f64,
    dt: f64,
    x0: OVector<f64, N>,
    input: impl Fn(usize) -> f64,
) -> Result<Response<N, P>, Error>
where
    DefaultAllocator: Allocator<N, N> + Allocator<N, M> + Allocator<P, N> + Allocator<P, M>,
    DefaultAllocator: Allocator<N> + Allocator<M> + Allocator<P>,
{
    check_finite_dyn("x0", &x0)?;
    let t = grid(&domain, t_end, dt)?;
    let (_, dim_m) = b.shape_generic();
    let u = |v: f64| OVector::<f64, M>::from_element_generic(dim_m, U1, v);
    match period_of(&domain) {
        None => {
            // The input is asked for once per grid time, in order.
            let mut k = 0;
            let (x, y) = lsim_zoh(a, b, c, d, &t, x0, |_t| {
                k += 1;
                u(input(k - 1))
            })?;
            Ok(Response { t, x, y })
        }
        Some(period) => {
            let (t, x, y) =
                discrete_feedback((a, b, c, d), period, x0, t.len(), |k, _x| u(input(k)))?;
            Ok(Response { t, x, y })
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
/// use ctrlab::nalgebra::matrix;
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
///
/// // Sized at run time: the same call, the same numbers.
/// let dynamic = ctrlab::DynStateSpace::from(&sys);
/// assert_eq!(step_response(&dynamic, 1.0, 0.5)?.output(0)?, r.output(0)?);
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[doc(alias = "step")]
pub fn step_response<S: Simulate + SingleInput>(
    sys: &S,
    t_end: f64,
    dt: f64,
) -> Result<S::Response, Error> {
    sys.respond(Token(()), Test::Step, t_end, dt)
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
/// Either model size, as [`step_response`]. For a model with several
/// inputs, pick one with [`select_input`](StateSpace::select_input).
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
/// use ctrlab::nalgebra::matrix;
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
/// let dd = impulse_response(&ctrlab::DynStateSpace::from(&d), 1.0, 0.1)?;
/// assert_eq!(dd.output(0)?, rd.output(0)?);
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[doc(alias = "impulse")]
pub fn impulse_response<S: Simulate + SingleInput>(
    sys: &S,
    t_end: f64,
    dt: f64,
) -> Result<S::Response, Error> {
    sys.respond(Token(()), Test::Impulse, t_end, dt)
}

/// The free response from the state `x0` with every input held at zero
/// (python-control `initial_response`, MATLAB `initial`): `y = C x`. Any
/// number of inputs, either model size.
///
/// # Errors
///
/// As [`step_response`] (but any number of inputs); [`Error::NonFinite`]
/// named `"x0"` for a non-finite initial state; [`Error::LengthMismatch`]
/// named `"x0"` unless it has one entry per state (a run-time-sized
/// model).
///
/// # Examples
///
/// ```
/// use ctrlab::{StateSpace, sim::initial_response};
/// use ctrlab::nalgebra::{matrix, vector};
///
/// // An undamped oscillator, ω = 2 rad/s, released from x = 1: cos 2t.
/// let sys = StateSpace::continuous(matrix![0.0, 1.0; -4.0, 0.0], matrix![0.0; 1.0], matrix![1.0, 0.0], matrix![0.0])?;
/// let r = initial_response(&sys, 1.0, 0.25, vector![1.0, 0.0])?;
/// assert!((r.y[4][0] - 2f64.cos()).abs() < 1e-12);
/// let dynamic = ctrlab::DynStateSpace::from(&sys);
/// let d = initial_response(&dynamic, 1.0, 0.25, ctrlab::nalgebra::dvector![1.0, 0.0])?;
/// assert_eq!(d.output(0)?, r.output(0)?);
/// assert!(initial_response(&dynamic, 1.0, 0.25, ctrlab::nalgebra::dvector![1.0]).is_err());
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[doc(alias = "initial")]
pub fn initial_response<S: Simulate>(
    sys: &S,
    t_end: f64,
    dt: f64,
    x0: S::State,
) -> Result<S::Response, Error> {
    sys.respond(Token(()), Test::Initial(x0), t_end, dt)
}
