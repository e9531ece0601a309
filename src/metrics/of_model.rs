//! Step figures of a model ([`step_info_of`], [`step_info_mimo`]) and of a
//! recording's channel ([`step_info_channel`]).

use super::step_info::{Crossings, measure};
use super::{StepInfo, StepInfoOptions, step_info};
use crate::data::Recording;
use crate::error::Error;
#[cfg(doc)]
use crate::model::StateSpace;
use crate::model::{Domain, DynStateSpace, LinearSystem, Siso, Token, period_of};
use crate::sim::step_response;

/// Step-response figures of a stable single-input single-output model,
/// continuous or discrete: its unit step response from rest on
/// [`time_grid`](crate::sim::time_grid)`(t_end, dt)` (see
/// [`step_response`]: exact for a continuous model; for a discrete one `dt`
/// must be its period `sys.dt()`), with the final value the model's DC gain
/// unless `options.final_value` says otherwise. The initial value is `D`
/// (the first sample) under the crate's definitions, 0 (the output before
/// the step) under MATLAB's. A discrete model's crossing times are sample
/// times (see the [module docs](super#definitions)).
///
/// Either model size ([`Siso`]: a fixed-size model with one input and one
/// output, or a `DynStateSpace`, whose sizes are checked when called); the
/// same code and numbers for both.
///
/// # Errors
///
/// [`Error::DimensionMismatch`] unless a run-time-sized model has one
/// input (named `"B"`) and one output (named `"C"`);
/// [`Error::Unstable`] naming the first unstable pole; errors of
/// [`dc_gain`](StateSpace::dc_gain), [`step_response`] and [`step_info`]
/// (in particular [`Error::NotSettled`] if `t_end` is too short).
///
/// # Examples
///
/// ```
/// use ctrlab::{MassSpring, Cart, Discretization, lab::LabGains, metrics::{StepInfoOptions, step_info_of}};
///
/// let plant = MassSpring::nominal().state_space(Cart::Two)?;
/// let cl = LabGains::new([0.0, 0.0, 10.0, 0.1], Cart::Two).state_feedback()?.closed_loop(&plant)?;
/// let info = step_info_of(&cl, 2.0, 0.0005, &StepInfoOptions { reference: Some(1.0), ..Default::default() })?;
/// // Table 2, row [0 0 10 0.1]: about 5 % overshoot, settled in about 0.2 s.
/// assert!((info.overshoot - 5.03).abs() < 0.5 && (info.settling_time - 0.2).abs() < 0.01);
///
/// // The same loop sampled every 2 ms: its figures are sample times.
/// let d = cl.discretize(0.002, Discretization::Zoh)?;
/// let di = step_info_of(&d, 2.0, d.dt(), &StepInfoOptions::default())?;
/// assert!((di.settling_time / 0.002 - (di.settling_time / 0.002).round()).abs() < 1e-9);
/// assert!((di.settling_time - info.settling_time).abs() <= 0.002);
///
/// // The loop sized at run time: the same figures.
/// let dynamic = step_info_of(&ctrlab::DynStateSpace::from(&cl), 2.0, 0.0005,
///                            &StepInfoOptions { reference: Some(1.0), ..Default::default() })?;
/// assert_eq!(dynamic, info);
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[doc(alias = "stepinfo")]
pub fn step_info_of<S: Siso>(
    sys: &S,
    t_end: f64,
    dt: f64,
    options: &StepInfoOptions,
) -> Result<StepInfo, Error> {
    let (n, m, p) = (sys.states(), sys.inputs(), sys.outputs());
    if m != 1 || p != 1 {
        let (matrix, rows, cols, found_rows, found_cols) = if m != 1 {
            ("B", n, 1, n, m)
        } else {
            ("C", 1, n, p, n)
        };
        return Err(Error::DimensionMismatch {
            matrix,
            expected_rows: rows,
            expected_cols: cols,
            found_rows,
            found_cols,
        });
    }
    channels(&sys.to_dyn(Token(())), t_end, dt, options)?
        .pop()
        .and_then(|mut row| row.pop())
        .unwrap_or(Err(Error::OutOfRange {
            what: "channel",
            index: 0,
            len: 0,
        }))
}

/// Refuses the options that name one number for every channel.
fn check_mimo_options(options: &StepInfoOptions) -> Result<(), Error> {
    for (name, value) in [
        ("initial_value", options.initial_value),
        ("final_value", options.final_value),
        ("reference", options.reference),
    ] {
        if let Some(value) = value {
            return Err(Error::InvalidParameter {
                name,
                value,
                reason: "is one number for every channel: leave it None for \
                         step_info_mimo (each channel's final value is its DC gain)",
            });
        }
    }
    Ok(())
}

/// Step-response figures of every channel of a stable model with `m`
/// inputs and `p` outputs, continuous or discrete, of either size (MATLAB's
/// `stepinfo` and python-control's `step_info` of a MIMO model):
/// `[output][input]` (`p` rows of `m`), the figures of output `i` for a
/// unit step on input `j` alone, from rest, each against its own DC gain,
/// as [`step_info_of`] computes them.
///
/// Each channel has its own `Result`: a channel with no step (a zero DC
/// gain, as between the blocks of a block-diagonal model) is
/// [`Error::InvalidData`] while the others have their figures.
///
/// # Errors
///
/// The outer `Result`: [`Error::InvalidParameter`] for bad options, or for
/// an `initial_value`, `final_value` or `reference` (one number cannot
/// serve every channel: use [`step_info`] on one channel's response);
/// [`Error::Unstable`]; errors of [`dc_gain`](StateSpace::dc_gain) and
/// [`step_response`]. Each channel's: those of [`step_info`].
///
/// # Examples
///
/// ```
/// use ctrlab::{Error, StateSpace, StepInfoOptions, metrics::step_info_mimo};
/// use ctrlab::nalgebra::matrix;
///
/// // Two lags, τ = 0.1 s and 1 s, one per input and output.
/// let sys = StateSpace::continuous(
///     matrix![-10.0, 0.0; 0.0, -1.0], matrix![10.0, 0.0; 0.0, 1.0],
///     matrix![1.0, 0.0; 0.0, 1.0], matrix![0.0, 0.0; 0.0, 0.0],
/// )?;
/// let info = step_info_mimo(&sys, 10.0, 0.001, &StepInfoOptions::default())?;
/// let (fast, slow) = (info[0][0].as_ref().unwrap(), info[1][1].as_ref().unwrap());
/// assert!((fast.rise_time - 0.1 * 9f64.ln()).abs() < 1e-6);
/// assert!((slow.rise_time - 9f64.ln()).abs() < 1e-6);
/// // Input 2 does not reach output 1.
/// assert!(matches!(info[0][1], Err(Error::InvalidData { .. })));
/// // The same figures for the model sized at run time.
/// let dynamic = step_info_mimo(&ctrlab::DynStateSpace::from(&sys), 10.0, 0.001, &StepInfoOptions::default())?;
/// assert_eq!(dynamic, info);
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub fn step_info_mimo<S: LinearSystem>(
    sys: &S,
    t_end: f64,
    dt: f64,
    options: &StepInfoOptions,
) -> Result<Vec<Vec<Result<StepInfo, Error>>>, Error> {
    check_mimo_options(options)?;
    channels(&sys.to_dyn(Token(())), t_end, dt, options)
}

/// The figures of every channel, `[output][input]`; `options.final_value`,
/// when given, serves them all (the callers allow it for one channel only).
/// Written once, on the model sized at run time (a fixed-size model is
/// copied to the heap: one copy, for a computation that allocates its
/// responses anyway).
fn channels<D: Domain>(
    sys: &DynStateSpace<D>,
    t_end: f64,
    dt: f64,
    options: &StepInfoOptions,
) -> Result<Vec<Vec<Result<StepInfo, Error>>>, Error> {
    options.validate()?;
    if let Some(p) = sys.unstable_pole()? {
        return Err(Error::Unstable {
            operation: "step metrics of a model",
            re: p.re,
            im: p.im,
        });
    }
    let gain = match options.final_value {
        Some(_) => None,
        None => Some(sys.dc_gain()?),
    };
    let crossings = match period_of(&sys.domain()) {
        None => Crossings::Interpolated,
        Some(_) => Crossings::AtSamples,
    };
    let mut responses = Vec::with_capacity(sys.inputs());
    for j in 0..sys.inputs() {
        responses.push(step_response(&sys.select_input(j)?, t_end, dt)?);
    }
    Ok((0..sys.outputs())
        .map(|i| {
            responses
                .iter()
                .enumerate()
                .map(|(j, r)| {
                    let y: Vec<f64> = r.y.iter().map(|y| y[i]).collect();
                    let final_value = options.final_value.or(gain.as_ref().map(|g| g[(i, j)]));
                    measure(
                        &r.t,
                        &y,
                        &StepInfoOptions {
                            final_value,
                            ..*options
                        },
                        crossings,
                    )
                })
                .collect()
        })
        .collect())
}

/// [`step_info`] of channel `channel` of a recording (from the rig's loop or
/// the sampled-data simulator), against its time stamps.
///
/// # Errors
///
/// [`Error::Channel`] when the recording has no such channel (the message
/// lists those it has); the errors of [`step_info`].
///
/// # Examples
///
/// ```
/// use ctrlab::data::{Recording, Schema};
/// use ctrlab::metrics::{StepInfoOptions, step_info_channel};
///
/// // A first-order rise to 1 with τ = 0.1 s, sampled every 10 ms.
/// let mut rec = Recording::new(Schema::numbered(1, 1)?);
/// for k in 0..300 {
///     let t = k as f64 * 0.01;
///     rec.push(t, &[1.0], &[1.0 - (-t / 0.1).exp()])?;
/// }
/// let info = step_info_channel(&rec, "y", &StepInfoOptions::default())?;
/// assert!((info.rise_time - 0.1 * 9f64.ln()).abs() < 1e-3);
/// assert!(step_info_channel(&rec, "x2", &StepInfoOptions::default()).is_err());
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub fn step_info_channel(
    recording: &Recording,
    channel: &str,
    options: &StepInfoOptions,
) -> Result<StepInfo, Error> {
    step_info(recording.time(), recording.channel(channel)?, options)
}
