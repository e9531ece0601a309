//! Step-response figures: rise time, settling and transient time,
//! overshoot, undershoot, peak and steady state, from sampled data
//! ([`step_info`], [`step_info_channel`]) or from a model, continuous or
//! discrete ([`step_info_of`] for one input and output,
//! [`step_info_mimo`] for every channel of a MIMO model), under the crate's
//! definitions or MATLAB's ([`Definition`]).
//!
//! ```
//! use ctrlab::{StateSpace, StepInfoOptions, step_info_of};
//! use ctrlab::nalgebra::matrix;
//!
//! // A first-order lag, τ = 0.1 s: rise time τ ln 9, 2 % settling τ ln 50.
//! let lag = StateSpace::continuous(matrix![-10.0], matrix![10.0], matrix![1.0], matrix![0.0])?;
//! let info = step_info_of(&lag, 2.0, 0.01, &StepInfoOptions::default())?;
//! assert!((info.rise_time - 0.1 * 9f64.ln()).abs() < 1e-3);
//! assert!((info.settling_time - 0.1 * 50f64.ln()).abs() < 1e-3);
//!
//! // The same figures under MATLAB's stepinfo definitions.
//! let m = step_info_of(&lag, 2.0, 0.01, &StepInfoOptions::matlab())?;
//! assert!((m.settling_time - info.settling_time).abs() < 1e-9);
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
//! - **transient time**: when `|y − y∞|` falls below `band` times its own
//!   largest value for the last time (MATLAB's `TransientTime`; the same as
//!   the settling time unless `y` starts away from `y₀` or overshoots by
//!   more than `Δ`);
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
//! Crossing times (rise, settling, transient) are **interpolated linearly**
//! between the two samples around the crossing, for sampled data and for a
//! continuous model. A discrete model's response is a sequence, not samples
//! of a curve: there a level is reached at the first sample that reaches it,
//! and the response settles at the sample after the last one outside the
//! band (MATLAB does the same for discrete models).
//!
//! These are [`Definition::Ctrlab`], the default. [`Definition::Matlab`]
//! ([`StepInfoOptions::matlab`]) follows MATLAB's documented `stepinfo`
//! instead; the two differ only in:
//!
//! | | `Ctrlab` (default) | `Matlab` |
//! |---|---|---|
//! | `y₀` when not given | the first sample (`D` for a model) | 0, the output before the step |
//! | `y∞` when not given | the mean of the final window (a model: its DC gain) | the last sample (a model: its DC gain) |
//! | `peak` | the signed sample farthest from `y₀` along the step | `max |y − y₀|`, a magnitude (MATLAB's "peak absolute value" for `y₀ = 0`) |
//! | settled when | inside the band over the whole final window, with no trend there when `y∞` is estimated | the last sample is inside the band |
//!
//! so a model with a feedthrough `D`, or data with an offset, gives other
//! figures under the two: MATLAB measures the step from 0 (channel (2, 1)
//! of MATLAB's MIMO example starts at `D = 0.06` against a final value of
//! −0.54: an 11.1 % undershoot). `tests/metrics_matlab.rs` checks the
//! MATLAB definitions against the figures printed on MATLAB's own
//! reference pages.
//!
//! # Errors instead of numbers
//!
//! A response that is not inside its band at the end (over the final
//! window by default, by default the last 5 % of the record; at the last
//! sample under MATLAB's definitions), or that diverges, is an
//! [`Error::NotSettled`], never a number (MATLAB reports `NaN`,
//! python-control figures of whatever the record holds). When the default
//! definitions estimate the final value from the data (the window's mean),
//! the response must also show no trend there: the means of the window's
//! two halves must agree to a quarter of the band.
//!
//! # Differences from python-control `step_info`
//!
//! - python-control snaps crossing times to a sample, so its times differ
//!   from these (and from MATLAB's) by up to one sample period.
//! - Its settling band is relative to `|y∞|` (the same as `|Δ|` for a step
//!   from 0) and its `Peak` is `max |y|`.

mod matlab;
mod of_model;
mod scan;
mod step_info;
#[cfg(test)]
mod step_info_reference;

use crate::error::Error;
pub use crate::error::SettleFailure;
pub use matlab::Definition;
pub use of_model::{step_info_channel, step_info_mimo, step_info_of};
pub use step_info::step_info;

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
    /// Time after which `|y − y∞|` stays below the band's fraction of its
    /// largest value, s (MATLAB's `TransientTime`).
    pub transient_time: f64,
    /// Smallest `y` from the upper rise crossing on.
    pub settling_min: f64,
    /// Largest `y` from the upper rise crossing on.
    pub settling_max: f64,
    /// Percent by which the peak exceeds the final value, relative to the
    /// step `Δ`; 0 if it never does.
    pub overshoot: f64,
    /// Percent by which `y` goes the wrong way from `y₀`, relative to `Δ`.
    pub undershoot: f64,
    /// The sample farthest from `y₀` in the step's direction; under
    /// [`Definition::Matlab`], the largest `|y − y₀|` (non-negative).
    pub peak: f64,
    /// Time of [`peak`](Self::peak), s (a sample time).
    pub peak_time: f64,
    /// The final value `y∞` used for every figure.
    pub steady_state_value: f64,
    /// `reference − y∞` when a reference was given.
    pub steady_state_error: Option<f64>,
}

impl std::fmt::Display for StepInfo {
    /// One figure per line, with its unit: times in s, overshoot and
    /// undershoot in %, values in the units of `y` (none printed). Numbers
    /// to five significant digits (`{}`), to a number of decimals
    /// (`{:.3}`), or exactly (`{:#}`); the steady-state error only when a
    /// reference was given.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{StateSpace, StepInfoOptions, step_info_of};
    /// use ctrlab::nalgebra::matrix;
    ///
    /// // ωn = 10 rad/s, ζ = 0.5: about 16 % overshoot.
    /// let sys = StateSpace::continuous(matrix![0.0, 1.0; -100.0, -10.0], matrix![0.0; 100.0],
    ///                                  matrix![1.0, 0.0], matrix![0.0])?;
    /// let info = step_info_of(&sys, 3.0, 0.001, &StepInfoOptions { reference: Some(1.0), ..Default::default() })?;
    /// assert_eq!(format!("{info:.3}"), "\
    /// rise time           0.164 s
    /// settling time       0.808 s
    /// transient time      0.808 s
    /// overshoot           16.303 %
    /// undershoot          0.000 %
    /// peak                1.163 at 0.363 s
    /// settling min        0.902
    /// settling max        1.163
    /// steady-state value  1.000
    /// steady-state error  0.000
    /// ");
    /// assert!(info.to_string().starts_with("rise time           0.16"));
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        use crate::model::display::number;
        let n = |v: f64| number(v, f);
        let mut rows = vec![
            ("rise time", format!("{} s", n(self.rise_time))),
            ("settling time", format!("{} s", n(self.settling_time))),
            ("transient time", format!("{} s", n(self.transient_time))),
            ("overshoot", format!("{} %", n(self.overshoot))),
            ("undershoot", format!("{} %", n(self.undershoot))),
            (
                "peak",
                format!("{} at {} s", n(self.peak), n(self.peak_time)),
            ),
            ("settling min", n(self.settling_min)),
            ("settling max", n(self.settling_max)),
            ("steady-state value", n(self.steady_state_value)),
        ];
        if let Some(e) = self.steady_state_error {
            rows.push(("steady-state error", n(e)));
        }
        for (label, value) in rows {
            writeln!(f, "{label:<20}{value}")?;
        }
        Ok(())
    }
}

/// Options for [`step_info`] and the model variants. `Default` gives the
/// crate's definitions with a 2 % band, 10–90 % rise, initial value from the
/// first sample, final value from the last 5 % of the record, no reference;
/// [`matlab`](Self::matlab) MATLAB's `stepinfo` defaults.
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
    /// `y₀`; `None` takes the first sample (under [`Definition::Matlab`]:
    /// 0).
    pub initial_value: Option<f64>,
    /// `y∞`; `None` takes the mean of the final window (under
    /// [`Definition::Matlab`]: the last sample; the model variants use the
    /// model's DC gain instead).
    pub final_value: Option<f64>,
    /// The setpoint, for [`StepInfo::steady_state_error`].
    pub reference: Option<f64>,
    /// The final window as a fraction of the samples, in (0, 1]: `y` must
    /// stay inside the band over it, and its mean is the default `y∞`
    /// (checked but not used under [`Definition::Matlab`]).
    pub final_window: f64,
    /// Whose definitions: the crate's (default) or MATLAB's.
    pub definition: Definition,
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
            definition: Definition::Ctrlab,
        }
    }
}

impl StepInfoOptions {
    pub(crate) fn validate(&self) -> Result<(), Error> {
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
