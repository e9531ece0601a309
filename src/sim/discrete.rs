//! Discrete simulation, open loop ([`simulate_discrete`]) and under state
//! feedback ([`simulate_discrete_feedback`]).

use nalgebra::{DefaultAllocator, Dim, OVector, allocator::Allocator};

use super::{Abcd, MAX_SAMPLES, Response, Sampled, Simulate, check_input, wrong_domain};
use crate::error::{Error, check_len};
use crate::model::{Discrete, Token};

/// What a discrete simulation that overflows reports.
const DIVERGED: &str = "discrete simulation (the response diverged past f64::MAX)";

/// Simulates a discrete model open loop: one sample per input, `t[k] = k dt`,
/// `y[k] = C x[k] + D u[k]`, then `x[k+1] = A x[k] + B u[k]`.
///
/// # Errors
///
/// As [`simulate_discrete_feedback`].
///
/// # Examples
///
/// ```
/// use ctrlab::{DynStateSpace, StateSpace, sim::simulate_discrete};
/// use ctrlab::nalgebra::{dvector, matrix, vector};
///
/// let sys = StateSpace::discrete(matrix![0.5], matrix![1.0], matrix![1.0], matrix![0.0], 0.1)?;
/// let r = simulate_discrete(&sys, vector![0.0], &[vector![1.0]; 3])?;
/// assert_eq!(r.output(0)?, vec![0.0, 1.0, 1.5]);
/// let d = simulate_discrete(&DynStateSpace::from(&sys), dvector![0.0], &vec![dvector![1.0]; 3])?;
/// assert_eq!(d.output(0)?, vec![0.0, 1.0, 1.5]);
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub fn simulate_discrete<S: Simulate<Domain = Discrete>>(
    sys: &S,
    x0: S::State,
    inputs: &[S::Input],
) -> Result<S::Response, Error> {
    sys.dsim(Token(()), x0, inputs.len(), |k, _x| inputs[k].clone())
}

/// Simulates a discrete model for `steps` samples with the input computed
/// from the current sample index and state, `u[k] = control(k, &x[k])`: a
/// closed loop around any controller.
///
/// # Errors
///
/// [`Error::InvalidParameter`] named `"steps"` for more than
/// [`MAX_SAMPLES`] samples, `"x0"` for a non-finite initial state, `"input"`
/// for a non-finite input sample; [`Error::LengthMismatch`] named `"x0"` or
/// `"input"` for a vector of the wrong length (a run-time-sized model);
/// [`Error::Overflow`] when the response diverges past `f64::MAX`.
///
/// # Examples
///
/// ```
/// use ctrlab::{DynStateSpace, Error, StateSpace, sim::simulate_discrete_feedback};
/// use ctrlab::nalgebra::{dvector, matrix, vector};
///
/// // x[k+1] = x + u with u = -0.5 x halves the state every sample.
/// let sys = StateSpace::discrete(matrix![1.0], matrix![1.0], matrix![1.0], matrix![0.0], 0.1)?;
/// let r = simulate_discrete_feedback(&sys, vector![8.0], 4, |_k, x| -0.5 * x)?;
/// assert_eq!(r.output(0)?, vec![8.0, 4.0, 2.0, 1.0]);
/// // u = x doubles the state every sample: past f64::MAX within 30 samples
/// // from 1e300, an error, not infinities.
/// let diverging = simulate_discrete_feedback(&sys, vector![1e300], 40, |_k, x| *x);
/// assert!(matches!(diverging, Err(Error::Overflow { .. })));
///
/// // The same loop on the model sized at run time.
/// let d = simulate_discrete_feedback(&DynStateSpace::from(&sys), dvector![8.0], 4, |_k, x| -0.5 * x)?;
/// assert_eq!(d.output(0)?, r.output(0)?);
/// assert!((d.t[3] - 0.3).abs() < 1e-15);
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub fn simulate_discrete_feedback<S: Simulate<Domain = Discrete>>(
    sys: &S,
    x0: S::State,
    steps: usize,
    control: impl FnMut(usize, &S::State) -> S::Input,
) -> Result<S::Response, Error> {
    sys.dsim(Token(()), x0, steps, control)
}

/// [`simulate_discrete_feedback`] on the matrices of a discrete model
/// (`period` is its period).
pub(super) fn dsim<N: Dim, M: Dim, P: Dim>(
    abcd: Abcd<'_, N, M, P>,
    period: Option<f64>,
    x0: OVector<f64, N>,
    steps: usize,
    control: impl FnMut(usize, &OVector<f64, N>) -> OVector<f64, M>,
) -> Result<Response<N, P>, Error>
where
    DefaultAllocator: Allocator<N, N> + Allocator<N, M> + Allocator<P, N> + Allocator<P, M>,
    DefaultAllocator: Allocator<N> + Allocator<M> + Allocator<P>,
{
    let Some(dt) = period else {
        return Err(wrong_domain("a continuous model is simulated by simulate"));
    };
    if steps > MAX_SAMPLES {
        return Err(Error::InvalidParameter {
            name: "steps",
            value: steps as f64,
            reason: "more samples than MAX_SAMPLES",
        });
    }
    check_len("x0", abcd.0.nrows(), x0.len())?;
    if let Some(&value) = x0.iter().find(|v| !v.is_finite()) {
        return Err(Error::InvalidParameter {
            name: "x0",
            value,
            reason: "the initial state must be finite",
        });
    }
    let (t, x, y) = discrete_feedback(abcd, dt, x0, steps, control)?;
    Ok(Response { t, x, y })
}

/// The times (`k dt`), states and outputs of the discrete `(A, B, C, D)`
/// with period `dt` for `steps` samples from `x0` under
/// `u[k] = control(k, &x[k])`: the one implementation behind
/// [`simulate_discrete`], [`simulate_discrete_feedback`] and the discrete
/// standard responses, for both model sizes. `steps` and `x0` are the
/// caller's to check. For fixed-size matrices nothing in the
/// loop allocates.
pub(crate) fn discrete_feedback<N: Dim, M: Dim, P: Dim>(
    (a, b, c, d): Abcd<'_, N, M, P>,
    dt: f64,
    x0: OVector<f64, N>,
    steps: usize,
    mut control: impl FnMut(usize, &OVector<f64, N>) -> OVector<f64, M>,
) -> Result<Sampled<N, P>, Error>
where
    DefaultAllocator: Allocator<N, N> + Allocator<N, M> + Allocator<P, N> + Allocator<P, M>,
    DefaultAllocator: Allocator<N> + Allocator<M> + Allocator<P>,
{
    // The times grow with k: the last one finite makes every one finite.
    if steps > 0 && !((steps - 1) as f64 * dt).is_finite() {
        return Err(Error::InvalidParameter {
            name: "dt",
            value: dt,
            reason: "the last sample time (steps − 1) · dt exceeds f64::MAX s",
        });
    }
    let mut ts = Vec::with_capacity(steps);
    let mut xs = Vec::with_capacity(steps);
    let mut ys = Vec::with_capacity(steps);
    let mut x = x0;
    for k in 0..steps {
        let u = control(k, &x);
        if u.len() != b.ncols() {
            check_input(&u, b.ncols())?;
        }
        let y = c * &x + d * &u;
        let next = a * &x + b * &u;
        // Stop at the first overflow: a controller would otherwise see
        // infinities and the error would blame its input. A non-finite
        // input makes every entry of the next state non-finite, so this
        // one check also catches it (but for a model without states); then
        // the input is blamed.
        if next.iter().chain(y.iter()).any(|v| !v.is_finite())
            || (x.is_empty() && u.iter().any(|v| !v.is_finite()))
        {
            check_input(&u, b.ncols())?;
            return Err(Error::Overflow {
                operation: DIVERGED,
            });
        }
        // Everything inside the loop, whose speed is the latency of
        // `control` and `A x + B u`: a pass after it would cost more.
        ts.push(k as f64 * dt);
        xs.push(x);
        ys.push(y);
        x = next;
    }
    Ok((ts, xs, ys))
}
