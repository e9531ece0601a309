//! MATLAB's `stepinfo` definitions, beside the crate's own.

use super::StepInfoOptions;

/// Whose definitions the step figures follow; see the
/// [module docs](super#definitions) for both, side by side.
///
/// [`Matlab`](Self::Matlab) follows the definitions on MATLAB's `stepinfo`
/// reference page (R2021b and later), so that a figure can be compared with
/// MATLAB's one for one:
///
/// - `y_init` = [`initial_value`](StepInfoOptions::initial_value), else 0
///   (the output before the step); `y_final` =
///   [`final_value`](StepInfoOptions::final_value), else the last sample
///   (a model: its DC gain);
/// - `RiseTime`: from `y_init + lo·(y_final − y_init)` to
///   `y_init + hi·(y_final − y_init)`
///   ([`rise_limits`](StepInfoOptions::rise_limits), MATLAB's
///   `RiseTimeLimits`, default `[0.1 0.9]`);
/// - `SettlingTime`: the first time after which
///   `|y − y_final| ≤ ST·|y_final − y_init|`, with `ST` =
///   [`settling_band`](StepInfoOptions::settling_band), MATLAB's
///   `SettlingTimeThreshold` (default 0.02);
/// - `TransientTime`: the first time after which `|y − y_final| ≤ ST·e_max`,
///   `e_max` the largest `|y − y_final|`;
/// - `SettlingMin` / `SettlingMax`: extremes of `y` once it has reached the
///   upper rise level;
/// - `Overshoot`: `max(0, 100·max(y_n − 1))` and `Undershoot`:
///   `max(0, −100·min(y_n))`, percent of the normalised response
///   `y_n = (y − y_init)/(y_final − y_init)`;
/// - `Peak`: the largest `|y − y_init|` (MATLAB: "peak absolute value of
///   y(t)", the same for its `y_init = 0`), `PeakTime` its (first) time.
///
/// Crossing times are interpolated linearly between samples (MATLAB does so
/// too: on MATLAB's own grid the reference example's rise and settling
/// times agree to its printed four decimals, while snapping to a sample is
/// off by 0.006 and 0.03 s), except for a discrete model, whose response is
/// a sequence (a level is reached at a sample). A response whose last
/// sample is outside the band is [`Error::NotSettled`](crate::Error::NotSettled)
/// where MATLAB prints `NaN`.
///
/// # Examples
///
/// ```
/// use ctrlab::metrics::{Definition, StepInfoOptions, step_info};
///
/// // Data that starts at 0.2 and settles at 1: MATLAB measures the step
/// // from y_init = 0 unless told otherwise, the crate from the first sample.
/// let t: Vec<f64> = (0..=2000).map(|k| k as f64 * 0.01).collect();
/// let y: Vec<f64> = t.iter().map(|t| 1.0 - 0.8 * (-t).exp()).collect();
/// let ours = step_info(&t, &y, &StepInfoOptions::default())?;
/// let matlab = step_info(&t, &y, &StepInfoOptions::matlab())?;
/// assert_eq!(StepInfoOptions::matlab().definition, Definition::Matlab);
/// // 10 % → 90 % of the way from 0.2 to 1 takes ln 9 s; from 0 to 1, the
/// // 10 % level is passed at t = 0 and 90 % reached at ln 8 s.
/// assert!((ours.rise_time - 9f64.ln()).abs() < 1e-4);
/// assert!((matlab.rise_time - 8f64.ln()).abs() < 1e-4);
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum Definition {
    /// The crate's definitions (the [module docs](super#definitions)).
    #[default]
    Ctrlab,
    /// MATLAB's documented `stepinfo` definitions.
    Matlab,
}

impl StepInfoOptions {
    /// MATLAB's `stepinfo` defaults: [`Definition::Matlab`], a 2 %
    /// settling threshold, 10–90 % rise, `y_init = 0`, `y_final` the last
    /// sample (a model's DC gain), no reference.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{StateSpace, StepInfoOptions, step_info_of};
    /// use ctrlab::nalgebra::matrix;
    ///
    /// // stepinfo(tf(1, [1 1])): a first-order lag, τ = 1 s.
    /// let lag = StateSpace::continuous(matrix![-1.0], matrix![1.0], matrix![1.0], matrix![0.0])?;
    /// let info = step_info_of(&lag, 8.0, 0.001, &StepInfoOptions::matlab())?;
    /// assert!((info.rise_time - 9f64.ln()).abs() < 1e-6);
    /// assert!((info.settling_time - 50f64.ln()).abs() < 1e-6);
    /// assert!((info.peak - 1.0).abs() < 1e-3 && info.overshoot == 0.0);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn matlab() -> Self {
        Self {
            definition: Definition::Matlab,
            ..Self::default()
        }
    }
}
