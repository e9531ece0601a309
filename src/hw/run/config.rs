//! [`LoopConfig`]: how a run is driven and when it halts.

use crate::hw::{ConfigError, RealTime, StopSignal};

/// Settings of a [`run`](crate::hw::run).
///
/// # Examples
///
/// ```
/// use ctrlab::hw::LoopConfig;
/// let config = LoopConfig { duration: 3.0, ..LoopConfig::default() };
/// assert_eq!((config.max_timing_faults, config.timing_window), (25, 0.5));
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct LoopConfig {
    /// Length of the experiment, s; the loop runs `round(duration / T)`
    /// ticks at the rig's period `T` ([`Rig::period`](crate::hw::Rig::period)).
    pub duration: f64,
    /// Timing faults (overruns and skipped deadlines) within
    /// [`timing_window`](Self::timing_window) that stop the run (default
    /// 25: a tenth of the ticks of 0.5 s at 2 ms).
    pub max_timing_faults: usize,
    /// The window timing faults are counted over, s (default 0.5).
    pub timing_window: f64,
    /// Longest allowed time between two samples, or for one controller
    /// update, s. `None` (the default) means half the rig's
    /// [`watchdog_timeout`](crate::hw::Rig::watchdog_timeout), or [`GAP_PERIODS`]
    /// periods for a rig without a watchdog (50 ms at the lab's 2 ms): the
    /// loop always has a gap limit ([`gap_limit`](Self::gap_limit)). Must be
    /// at least the period (`f64::INFINITY` switches the check off).
    pub max_gap: Option<f64>,
    /// Real-time scheduling for the loop's thread (Linux; opt in).
    pub realtime: Option<RealTime>,
    /// A stop request checked every tick (e.g. Ctrl-C:
    /// [`StopSignal::on_interrupt`]).
    pub stop: Option<StopSignal>,
}

/// The default gap limit of a rig without a watchdog, in periods: the
/// loop halts after this many periods without a sample (or a controller
/// update that long). 25 periods is 50 ms at the lab's 2 ms, what half the
/// lab card's 100 ms watchdog allows.
///
/// # Examples
///
/// ```
/// use ctrlab::hw::{GAP_PERIODS, LoopConfig};
/// assert_eq!(LoopConfig::default().gap_limit(0.002, None), GAP_PERIODS * 0.002);
/// ```
pub const GAP_PERIODS: f64 = 25.0;

impl LoopConfig {
    /// The gap limit a run of a rig with period `period` (s) and watchdog
    /// `watchdog_timeout` (s, if it has one) uses, s: [`max_gap`](Self::max_gap)
    /// if set, else half the watchdog timeout, else [`GAP_PERIODS`]
    /// periods.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::LoopConfig;
    /// let config = LoopConfig::default();
    /// assert_eq!(config.gap_limit(0.002, Some(0.1)), 0.05);
    /// assert_eq!(config.gap_limit(0.002, None), 0.05); // 25 periods: still a limit
    /// let set = LoopConfig { max_gap: Some(0.02), ..config };
    /// assert_eq!(set.gap_limit(0.002, None), 0.02);
    /// ```
    pub fn gap_limit(&self, period: f64, watchdog_timeout: Option<f64>) -> f64 {
        self.max_gap
            .or_else(|| watchdog_timeout.map(|w| 0.5 * w))
            .unwrap_or(GAP_PERIODS * period)
    }
}

impl Default for LoopConfig {
    fn default() -> Self {
        Self {
            duration: 5.0,
            max_timing_faults: 25,
            timing_window: 0.5,
            max_gap: None,
            realtime: None,
            stop: None,
        }
    }
}

pub(super) fn check_config(config: &LoopConfig, period: f64) -> Result<usize, ConfigError> {
    let invalid = |key: &'static str, value, reason| ConfigError::invalid(key, value, reason);
    if !(period.is_finite() && period >= 1e-6) {
        return Err(invalid(
            "period",
            period,
            "the rig's period must be finite and >= 1 µs",
        ));
    }
    let duration = config.duration;
    if !(duration.is_finite() && duration >= period) {
        return Err(invalid(
            "duration",
            duration,
            "must be finite and at least one period, s",
        ));
    }
    let ticks = (duration / period).round();
    if ticks > crate::sim::MAX_SAMPLES as f64 {
        return Err(invalid(
            "duration",
            duration,
            "more ticks than sim::MAX_SAMPLES",
        ));
    }
    if config.max_timing_faults == 0 {
        return Err(invalid("max_timing_faults", 0.0, "must be at least 1"));
    }
    if !(config.timing_window.is_finite() && config.timing_window > 0.0) {
        return Err(invalid(
            "timing_window",
            config.timing_window,
            "must be finite and > 0 s",
        ));
    }
    if let Some(gap) = config.max_gap
        && gap.is_nan()
    {
        return Err(invalid("max_gap", gap, "must be a number of seconds"));
    }
    Ok(ticks as usize)
}
