//! Step figures of a model ([`step_info_of`]) and of a recording's channel
//! ([`step_info_channel`]).

use super::{StepInfo, StepInfoOptions, step_info};
use crate::data::Recording;
use crate::error::Error;
use crate::model::{Continuous, StateSpace};
use crate::sim::step_response;

/// Step-response figures of a stable single-input single-output continuous
/// model: its unit step response from rest on [`time_grid`](crate::sim::time_grid)`(t_end, dt)`
/// (exact ZOH), with the final value the model's DC gain unless
/// `options.final_value` says otherwise, and `y₀ = D`.
///
/// # Errors
///
/// [`Error::Unstable`] naming the first unstable pole; errors of
/// [`dc_gain`](StateSpace::dc_gain), [`step_response`] and [`step_info`]
/// (in particular [`Error::NotSettled`] if `t_end` is too short).
///
/// # Examples
///
/// ```
/// use ctrlab::{MassSpring, Cart, design::StateFeedback, metrics::{StepInfoOptions, step_info_of}};
///
/// let plant = MassSpring::nominal().state_space(Cart::Two)?;
/// let cl = StateFeedback::from_lab_gains([0.0, 0.0, 10.0, 0.1], Cart::Two)?.closed_loop(&plant)?;
/// let info = step_info_of(&cl, 2.0, 0.0005, &StepInfoOptions { reference: Some(1.0), ..Default::default() })?;
/// // Table 2, row [0 0 10 0.1]: about 5 % overshoot, settled in about 0.2 s.
/// assert!((info.overshoot - 5.03).abs() < 0.5 && (info.settling_time - 0.2).abs() < 0.01);
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub fn step_info_of<const N: usize>(
    sys: &StateSpace<N, 1, 1, Continuous>,
    t_end: f64,
    dt: f64,
    options: &StepInfoOptions,
) -> Result<StepInfo, Error> {
    options.validate()?;
    if let Some(p) = sys.unstable_pole()? {
        return Err(Error::Unstable {
            operation: "step metrics of a model",
            re: p.re,
            im: p.im,
        });
    }
    let final_value = match options.final_value {
        Some(v) => v,
        None => sys.dc_gain()?[(0, 0)],
    };
    let r = step_response(sys, t_end, dt)?;
    let y: Vec<f64> = r.y.iter().map(|y| y[0]).collect();
    step_info(
        &r.t,
        &y,
        &StepInfoOptions {
            final_value: Some(final_value),
            ..*options
        },
    )
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
/// let mut rec = Recording::new(Schema::numbered(1, 1));
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
