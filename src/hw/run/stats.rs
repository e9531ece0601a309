//! [`LoopStats`]: how well a run kept its deadlines.

/// A tick whose sample is taken this fraction of the period or more after
/// its deadline is late ([`LoopStats::late`]): the next sample, taken at its
/// own deadline, follows it by less than `1 − LATE_FRACTION` periods, too
/// short an interval to difference over (see "Late ticks" in
/// [`run`](crate::hw::run)).
///
/// # Examples
///
/// ```
/// use ctrlab::hw::LATE_FRACTION;
/// // At the lab's 2 ms, a sample 0.5 ms late or more is late.
/// assert_eq!(LATE_FRACTION * 0.002, 0.5e-3);
/// ```
pub const LATE_FRACTION: f64 = 0.25;

/// Timing statistics of a run, in the spirit of cyclictest. Lateness is how
/// long after its deadline a tick's sample was taken, s (always 0 on an
/// ideal virtual clock, the [`Jitter`](crate::hw::Jitter) schedule's on a
/// jittered one).
///
/// # Examples
///
/// ```
/// use ctrlab::hw::LoopStats;
/// let s = LoopStats::default();
/// assert_eq!((s.ticks, s.overruns, s.late, s.lateness_max), (0, 0, 0, 0.0));
/// ```
#[derive(Debug, Clone, Default, PartialEq)]
pub struct LoopStats {
    /// Ticks executed (samples recorded).
    pub ticks: usize,
    /// Ticks whose work ended after the next deadline.
    pub overruns: usize,
    /// Deadlines skipped because the loop fell a whole period or more
    /// behind (on the wall clock or a jittered virtual clock); they show as
    /// gaps in the recording.
    pub skipped: usize,
    /// Ticks whose sample was taken [`LATE_FRACTION`] of a period or more
    /// after their deadline (the tick that samples after skipped deadlines
    /// among them when it is that late); each shows as a late time stamp,
    /// followed by a shorter interval.
    pub late: usize,
    /// Longest run of consecutive overruns.
    pub max_consecutive_overruns: usize,
    /// Longest interval between two recorded samples, s.
    pub max_interval: f64,
    /// Median lateness, s.
    pub lateness_p50: f64,
    /// 99th-percentile lateness, s.
    pub lateness_p99: f64,
    /// 99.9th-percentile lateness, s.
    pub lateness_p999: f64,
    /// Largest lateness, s.
    pub lateness_max: f64,
}

impl std::fmt::Display for LoopStats {
    /// A cyclictest-like summary line, in µs.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::LoopStats;
    /// let s = LoopStats { ticks: 5000, lateness_p50: 2e-6, ..Default::default() };
    /// assert!(s.to_string().starts_with("ticks 5000, p50 2.0 µs"));
    /// ```
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "ticks {}, p50 {:.1} µs, p99 {:.1} µs, p99.9 {:.1} µs, max {:.1} µs, late {}, overruns {} (longest run {}), skipped {}, longest interval {:.3} ms",
            self.ticks,
            self.lateness_p50 * 1e6,
            self.lateness_p99 * 1e6,
            self.lateness_p999 * 1e6,
            self.lateness_max * 1e6,
            self.late,
            self.overruns,
            self.max_consecutive_overruns,
            self.skipped,
            self.max_interval * 1e3
        )
    }
}

pub(super) fn finish_stats(stats: &mut LoopStats, lateness: &mut [f64]) {
    if lateness.is_empty() {
        return;
    }
    lateness.sort_unstable_by(f64::total_cmp);
    let at = |q: f64| lateness[((lateness.len() - 1) as f64 * q).round() as usize];
    stats.lateness_p50 = at(0.5);
    stats.lateness_p99 = at(0.99);
    stats.lateness_p999 = at(0.999);
    stats.lateness_max = at(1.0);
}
