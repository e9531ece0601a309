//! Step-response figures: rise time, settling time, overshoot, peak and
//! steady state, from sampled data ([`step_info`]) or from a model
//! ([`step_info_of`]).
//!
//! ```
//! use ctrlab::{StateSpace, StepInfoOptions, step_info_of};
//! use nalgebra::matrix;
//!
//! // A first-order lag, τ = 0.1 s: rise time τ ln 9, 2 % settling τ ln 50.
//! let lag = StateSpace::continuous(matrix![-10.0], matrix![10.0], matrix![1.0], matrix![0.0])?;
//! let info = step_info_of(&lag, 2.0, 0.01, &StepInfoOptions::default())?;
//! assert!((info.rise_time - 0.1 * 9f64.ln()).abs() < 1e-3);
//! assert!((info.settling_time - 0.1 * 50f64.ln()).abs() < 1e-3);
//! # Ok::<(), ctrlab::Error>(())
//! ```
//!
//! # Definitions
//!
//! With `y₀` the initial value, `y∞` the final value and `Δ = y∞ − y₀`
//! (the step, of either sign), and every time measured from the first sample
//! `t[0]` (the step instant):
//!
//! - **rise time**: from the first crossing of `y₀ + lo·Δ` to the first
//!   later crossing of `y₀ + hi·Δ` (default 10 % and 90 %);
//! - **settling time**: when `y` enters the band `|y − y∞| ≤ band·|Δ|`
//!   (default 2 %) for the last time;
//! - **overshoot**: `100 · (peak − y∞) / Δ` in percent, at least 0;
//! - **undershoot**: `100 · (y₀ − y)/Δ` at its largest, in percent, at least 0
//!   (how far the response first goes the wrong way);
//! - **peak**, **peak time**: the sample farthest from `y₀` in the step's
//!   direction, and its time;
//! - **settling min / max**: extremes of `y` from the upper rise crossing on.
//!
//! Measuring everything from `y₀` and `Δ` makes the figures independent of
//! an offset in the data (a position that starts at 5 mm).
//!
//! # Differences from MATLAB `stepinfo` and python-control `step_info`
//!
//! - Crossing times (rise and settling) are **interpolated linearly**
//!   between the two samples around the crossing; MATLAB and python-control
//!   snap them to a sample, so they differ by up to one sample period.
//! - The settling band is relative to `|Δ|` (python-control: to `|y∞|`,
//!   the same for a step from 0; MATLAB: to the peak error).
//! - `peak` is the signed sample value (python-control and MATLAB report
//!   `max |y|`; they agree for a positive step from 0).
//! - A response that is not inside its band over the final window (by
//!   default the last 5 % of the record), or that diverges, is an
//!   [`Error::NotSettled`], never a number; python-control returns figures
//!   of whatever the record holds. When the final value is estimated from
//!   the data (the window's mean), the response must also show no trend
//!   there: the means of the window's two halves must agree to a quarter of
//!   the band.

use crate::data::Recording;
use crate::error::Error;
pub use crate::error::SettleFailure;
use crate::model::{Continuous, StateSpace};
use crate::sim::step_response;

/// Step-response figures; see the [module docs](self) for the exact
/// definitions. Times in seconds from the first sample, values in the units
/// of `y`, overshoot and undershoot in percent.
///
/// # Examples
///
/// ```
/// use ctrlab::metrics::{StepInfoOptions, step_info};
///
/// let t: Vec<f64> = (0..=400).map(|k| k as f64 * 0.01).collect();
/// let y: Vec<f64> = t.iter().map(|t| 1.0 - (-t / 0.2f64).exp()).collect();
/// let info = step_info(&t, &y, &StepInfoOptions::default())?;
/// assert!((info.rise_time - 0.2 * 9f64.ln()).abs() < 1e-3);
/// assert!((info.settling_time - 0.2 * 50f64.ln()).abs() < 1e-3);
/// // No overshoot (bar the hair between the final window's mean and 1).
/// assert!(info.overshoot < 1e-6);
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepInfo {
    /// Time from the lower to the upper rise level, s.
    pub rise_time: f64,
    /// Time after which `y` stays inside the settling band, s.
    pub settling_time: f64,
    /// Smallest `y` from the upper rise crossing on.
    pub settling_min: f64,
    /// Largest `y` from the upper rise crossing on.
    pub settling_max: f64,
    /// Percent by which the peak exceeds the final value, relative to the
    /// step `Δ`; 0 if it never does.
    pub overshoot: f64,
    /// Percent by which `y` goes the wrong way from `y₀`, relative to `Δ`.
    pub undershoot: f64,
    /// The sample farthest from `y₀` in the step's direction.
    pub peak: f64,
    /// Time of [`peak`](Self::peak), s (a sample time).
    pub peak_time: f64,
    /// The final value `y∞` used for every figure.
    pub steady_state_value: f64,
    /// `reference − y∞` when a reference was given.
    pub steady_state_error: Option<f64>,
}

/// Options for [`step_info`]. `Default` gives a 2 % band, 10–90 % rise,
/// initial value from the first sample, final value from the last 5 % of the
/// record, no reference.
///
/// # Examples
///
/// ```
/// use ctrlab::metrics::StepInfoOptions;
///
/// let o = StepInfoOptions { settling_band: 0.05, reference: Some(0.030), ..Default::default() };
/// assert_eq!(o.rise_limits, (0.1, 0.9));
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepInfoOptions {
    /// Half-width of the settling band as a fraction of `|Δ|`, in (0, 1).
    pub settling_band: f64,
    /// Rise levels as fractions of `Δ`, `0 ≤ lo < hi ≤ 1`.
    pub rise_limits: (f64, f64),
    /// `y₀`; `None` takes the first sample.
    pub initial_value: Option<f64>,
    /// `y∞`; `None` takes the mean of the final window ([`step_info_of`]
    /// uses the model's DC gain instead).
    pub final_value: Option<f64>,
    /// The setpoint, for [`StepInfo::steady_state_error`].
    pub reference: Option<f64>,
    /// The final window as a fraction of the samples, in (0, 1]: `y` must
    /// stay inside the band over it, and its mean is the default `y∞`.
    pub final_window: f64,
}

impl Default for StepInfoOptions {
    fn default() -> Self {
        Self {
            settling_band: 0.02,
            rise_limits: (0.1, 0.9),
            initial_value: None,
            final_value: None,
            reference: None,
            final_window: 0.05,
        }
    }
}

impl StepInfoOptions {
    fn validate(&self) -> Result<(), Error> {
        let bad = |name, value, reason| {
            Err(Error::InvalidParameter {
                name,
                value,
                reason,
            })
        };
        let b = self.settling_band;
        if !(b > 0.0 && b < 1.0) {
            return bad("settling_band", b, "must be in (0, 1)");
        }
        let (lo, hi) = self.rise_limits;
        if !(lo >= 0.0 && lo < hi && hi <= 1.0) {
            return bad("rise_limits", lo, "must satisfy 0 <= lo < hi <= 1");
        }
        let w = self.final_window;
        if !(w > 0.0 && w <= 1.0) {
            return bad("final_window", w, "must be in (0, 1]");
        }
        for (name, v) in [
            ("initial_value", self.initial_value),
            ("final_value", self.final_value),
            ("reference", self.reference),
        ] {
            if let Some(v) = v
                && !v.is_finite()
            {
                return bad(name, v, "must be finite");
            }
        }
        Ok(())
    }
}

/// Step-response figures of sampled data `y` at times `t` (s, strictly
/// increasing). One pass over the data for each figure; allocates nothing.
///
/// # Errors
///
/// - [`Error::LengthMismatch`] if `y` and `t` differ in length;
/// - [`Error::InvalidData`] for fewer than 3 samples, a non-finite sample, a
///   non-increasing `t`, no step (`Δ = 0`), or a response that never reaches
///   the upper rise level;
/// - [`Error::InvalidParameter`] for bad options;
/// - [`Error::NotSettled`] when `y` is outside the band anywhere in the final
///   window, with its [`SettleFailure`] (diverging, oscillating, or a
///   record too short);
/// - [`Error::Overflow`] when a figure is not representable (an overshoot
///   of 10³⁰⁰ % of a tiny step, times spanning more than `f64::MAX` s).
///
/// # Examples
///
/// ```
/// use ctrlab::{Error, metrics::{StepInfoOptions, step_info}};
///
/// let t: Vec<f64> = (0..100).map(|k| k as f64 * 0.1).collect();
/// // A ramp never settles.
/// let err = step_info(&t, &t, &StepInfoOptions::default()).unwrap_err();
/// assert!(matches!(err, Error::NotSettled { .. }));
/// ```
pub fn step_info(t: &[f64], y: &[f64], options: &StepInfoOptions) -> Result<StepInfo, Error> {
    options.validate()?;
    if y.len() != t.len() {
        return Err(Error::LengthMismatch {
            what: "y",
            expected: t.len(),
            found: y.len(),
        });
    }
    let n = t.len();
    if n < 3 {
        return Err(Error::InvalidData {
            what: "y",
            index: n,
            reason: "step metrics need at least 3 samples",
        });
    }
    // Branch-free scans first (they vectorise); locate the culprit only
    // when there is one.
    let y_ok = y.iter().fold(true, |ok, v| ok & v.is_finite());
    let t_ok = t.iter().fold(true, |ok, v| ok & v.is_finite())
        && t.windows(2).fold(true, |ok, w| ok & (w[1] > w[0]));
    if !y_ok || !t_ok {
        return Err(locate_bad_sample(t, y));
    }

    let t0 = t[0];
    // Final window: the last ⌈w·n⌉ samples, at least one.
    let window = ((options.final_window * n as f64).ceil() as usize).clamp(1, n);
    let window_start = n - window;
    let y0 = options.initial_value.unwrap_or(y[0]);
    let yf = match options.final_value {
        Some(v) => v,
        None => mean(&y[window_start..]),
    };
    let delta = yf - y0;
    if !delta.is_finite() {
        return Err(Error::Overflow {
            operation: "step metrics (the step y∞ − y₀ exceeds f64::MAX)",
        });
    }
    let scale = y0.abs().max(yf.abs());
    if delta.abs() <= 4.0 * f64::EPSILON * scale || delta == 0.0 {
        return Err(Error::InvalidData {
            what: "y",
            index: 0,
            reason: "no step: the final value equals the initial value",
        });
    }
    let band = options.settling_band * delta.abs();
    if options.final_value.is_none() && window >= 2 {
        // An estimated final value cannot reveal a response still creeping
        // towards its end (it moves with it), so also ask for no trend: the
        // two halves of the final window agree to a quarter of the band.
        let half = window / 2;
        let first = mean(&y[window_start..window_start + half]);
        let second = mean(&y[n - half..]);
        // Halved before subtracting: the difference of two finite means
        // can overflow, and then the response certainly trends.
        if (0.5 * second - 0.5 * first).abs() > 0.125 * band {
            return Err(Error::NotSettled {
                last_outside: t[n - 1] - t0,
                window_start: t[window_start] - t0,
                cause: settle_failure(y, yf, window_start),
            });
        }
    }
    // Progress along the step, 0 at y₀ and 1 at y∞.
    let progress = |v: f64| (v - y0) / delta;

    // Settling: last sample outside the band.
    let settling_time = match y.iter().rposition(|&v| (v - yf).abs() > band) {
        None => 0.0,
        Some(j) if j + 1 >= n => {
            return Err(Error::NotSettled {
                last_outside: t[n - 1] - t0,
                window_start: t[window_start] - t0,
                cause: settle_failure(y, yf, window_start),
            });
        }
        Some(j) => {
            let edge = if y[j] > yf { yf + band } else { yf - band };
            let ts = crossing(t[j], y[j], t[j + 1], y[j + 1], edge) - t0;
            if j + 1 > window_start {
                return Err(Error::NotSettled {
                    last_outside: ts,
                    window_start: t[window_start] - t0,
                    cause: settle_failure(y, yf, window_start),
                });
            }
            ts
        }
    };

    // Rise: first crossings of the two levels.
    let (lo, hi) = options.rise_limits;
    let cross = |level: f64, from: usize| -> Option<(usize, f64)> {
        let i = (from..n).find(|&i| progress(y[i]) >= level)?;
        if i == 0 || progress(y[i - 1]) >= level {
            return Some((i, t[i]));
        }
        let target = y0 + level * delta;
        Some((i, crossing(t[i - 1], y[i - 1], t[i], y[i], target)))
    };
    let (i_lo, t_lo) = cross(lo, 0).ok_or(Error::InvalidData {
        what: "y",
        index: n,
        reason: "response never reaches the lower rise level",
    })?;
    let (i_hi, t_hi) = cross(hi, i_lo).ok_or(Error::InvalidData {
        what: "y",
        index: n,
        reason: "response never reaches the upper rise level",
    })?;

    // Extremes by branch-free folds (all samples are finite by now); the
    // peak is the extreme in the step's direction, the undershoot the other.
    let extremes = |ys: &[f64]| {
        ys.iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| {
                (lo.min(v), hi.max(v))
            })
    };
    let (y_min, y_max) = extremes(y);
    let (peak, wrong_way) = if delta > 0.0 {
        (y_max, y_min)
    } else {
        (y_min, y_max)
    };
    let peak_i = y.iter().position(|&v| v == peak).unwrap_or(0);
    let (peak_p, min_p) = (progress(peak), progress(wrong_way));
    let (s_min, s_max) = extremes(&y[i_hi..]);
    let info = StepInfo {
        rise_time: t_hi - t_lo,
        settling_time,
        settling_min: s_min,
        settling_max: s_max,
        overshoot: (100.0 * (peak_p - 1.0)).max(0.0),
        // Written out so that no undershoot is +0, never -0 (printed "-0").
        undershoot: if min_p < 0.0 { -100.0 * min_p } else { 0.0 },
        peak,
        peak_time: t[peak_i] - t0,
        steady_state_value: yf,
        steady_state_error: options.reference.map(|r| r - yf),
    };
    check_figures(&info)?;
    Ok(info)
}

/// Every figure must be a finite number: a peak a googol of steps away,
/// or times spanning more than `f64::MAX` seconds, are errors, not `inf`.
fn check_figures(info: &StepInfo) -> Result<(), Error> {
    let figures = [
        (info.rise_time, "step metrics: rise time overflows"),
        (info.settling_time, "step metrics: settling time overflows"),
        (info.peak_time, "step metrics: peak time overflows"),
        (
            info.overshoot,
            "step metrics: overshoot overflows (a peak far beyond a tiny step)",
        ),
        (
            info.undershoot,
            "step metrics: undershoot overflows (a dip far beyond a tiny step)",
        ),
        (
            info.steady_state_error.unwrap_or(0.0),
            "step metrics: steady-state error overflows",
        ),
    ];
    match figures.iter().find(|(v, _)| !v.is_finite()) {
        Some(&(_, operation)) => Err(Error::Overflow { operation }),
        None => Ok(()),
    }
}

/// Mean of finite samples that cannot overflow: the plain sum when it is
/// finite (the common case, and bit-for-bit the straightforward mean), else
/// the sum of the samples divided first.
fn mean(y: &[f64]) -> f64 {
    let n = y.len() as f64;
    let sum = y.iter().sum::<f64>();
    if sum.is_finite() {
        sum / n
    } else {
        y.iter().map(|v| v / n).sum()
    }
}

/// Why `y` is not settled about `yf`, from its final window (from
/// `window_start`) and the stretch of equal length before it: a growing
/// deviation is [`SettleFailure::Diverging`], repeated crossings of `yf`
/// without decay [`SettleFailure::Oscillating`], anything else (a decaying
/// error) [`SettleFailure::TooShort`].
#[cold]
fn settle_failure(y: &[f64], yf: f64, window_start: usize) -> SettleFailure {
    let window = &y[window_start..];
    let half = window.len() / 2;
    // Largest deviation from yf, halved so that it cannot overflow.
    let amplitude = |s: &[f64]| {
        s.iter()
            .fold(0.0f64, |m, v| m.max((0.5 * v - 0.5 * yf).abs()))
    };
    let crossings = window
        .windows(2)
        .filter(|w| (w[0] > yf) != (w[1] > yf))
        .count();
    if half >= 1 && crossings >= 2 {
        let (first, second) = (amplitude(&window[..half]), amplitude(&window[half..]));
        return if second > 1.1 * first {
            SettleFailure::Diverging
        } else if second >= 0.9 * first {
            SettleFailure::Oscillating
        } else {
            SettleFailure::TooShort
        };
    }
    // No oscillation: compare the drift over the window with the drift over
    // the stretch before it; a drift that does not slow down diverges.
    let len = window.len();
    if len < 2 || window_start < len {
        return SettleFailure::TooShort;
    }
    // (A ramp drifts equally; a decay with a time constant 100 windows long
    // would look the same, and then the record is far too short anyway.)
    let drift = |s: &[f64]| (0.5 * s[s.len() - 1] - 0.5 * s[0]).abs();
    let before = &y[window_start - len..window_start];
    if drift(window) >= 0.99 * drift(before) && drift(window) > 0.0 {
        SettleFailure::Diverging
    } else {
        SettleFailure::TooShort
    }
}

/// The first non-finite sample or non-increasing time, as an error.
#[cold]
fn locate_bad_sample(t: &[f64], y: &[f64]) -> Error {
    if let Some(i) = y.iter().position(|v| !v.is_finite()) {
        return Error::InvalidData {
            what: "y",
            index: i,
            reason: "sample is not finite",
        };
    }
    if let Some(i) = t.iter().position(|v| !v.is_finite()) {
        return Error::InvalidData {
            what: "t",
            index: i,
            reason: "time is not finite",
        };
    }
    let i = (1..t.len()).find(|&i| t[i] <= t[i - 1]).unwrap_or(0);
    Error::InvalidData {
        what: "t",
        index: i,
        reason: "time must be strictly increasing",
    }
}

/// Time at which the segment from `(ta, ya)` to `(tb, yb)` reaches `level`.
#[inline]
fn crossing(ta: f64, ya: f64, tb: f64, yb: f64, level: f64) -> f64 {
    let dy = yb - ya;
    if dy == 0.0 {
        return tb;
    }
    let f = ((level - ya) / dy).clamp(0.0, 1.0);
    ta + f * (tb - ta)
}

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
