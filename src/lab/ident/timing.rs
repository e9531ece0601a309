//! The recording's time stamps: split at gaps into segments, each checked
//! for jitter and given its own mean period.

use crate::error::Error;
use crate::kernels::reduce::max_step_deviation;

/// An interval longer than `GAP_RATIO` times the median interval is a gap:
/// the recording is split there, and no regression row spans it.
///
/// A missed tick of the rig's loop leaves an interval of two periods (or
/// more); ordinary jitter stays far below one and a half. The mirror image
/// splits the recording too: an interval shorter than `2 − GAP_RATIO`
/// times the median (half of it). The loop's deadlines are absolute, so a
/// sample taken a part `L` of a period late is followed by an interval of
/// `T − L`: late by more than half a period, the sample is a gap on one side
/// and this short interval on the other, and is left out alone.
///
/// # Examples
///
/// ```
/// use ctrlab::{Recording, lab::ident::{GAP_RATIO, Options, identify_with}};
///
/// let mut rec = Recording::read_csv(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ident_square_wave.csv"))?;
/// // A missed tick: from sample 1000 on, everything one period (2 ms) later.
/// for t in &mut rec.time_mut()[1000..] {
///     *t += 0.002;
/// }
/// let est = identify_with(&rec, 1.3, 0.7, &Options::default())?;
/// assert_eq!((est.timing.gaps, est.timing.segments), (1, 2));
/// assert!((est.timing.longest_gap - 2.0 * 0.002).abs() < 1e-12);
/// assert!(2.0 > GAP_RATIO && 1.05 < GAP_RATIO); // a gap, and jitter
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub const GAP_RATIO: f64 = 1.5;

/// Default tolerance for the jitter of the sampling intervals within a
/// segment, as a fraction of the segment's mean period (5 %, i.e. 100 µs at
/// the rig's 2 ms): [`Options::max_jitter`](super::Options::max_jitter).
///
/// # Examples
///
/// ```
/// use ctrlab::lab::ident::{DEFAULT_MAX_JITTER, Options};
/// assert_eq!(Options::default().max_jitter, DEFAULT_MAX_JITTER);
/// ```
pub const DEFAULT_MAX_JITTER: f64 = 0.05;

/// Up to this jitter a recording whose every interval is within the
/// tolerance of the overall mean has no split: the median is then within
/// the same tolerance of the mean, `(1 + j) ≤ GAP_RATIO · (1 − j)` and
/// `(1 − j) ≥ (2 − GAP_RATIO)(1 + j)` for `j ≤ 0.2`. Such recordings
/// (nearly all) skip the median.
const FAST_PATH_JITTER: f64 = 0.2;

/// What the identification found, and tolerated, in a recording's time
/// stamps: the gaps it split the recording at, the segments between them,
/// and the jitter within the segments.
///
/// A segment is a run of samples with no gap inside (no interval longer
/// than [`GAP_RATIO`] times the median interval, none shorter than
/// `2 − GAP_RATIO` times it) and no interval further than the jitter
/// tolerance from the median (a sample a little late is split off, not
/// differenced across: a loaded machine's recording degrades to shorter
/// segments instead of being refused). Each segment of three or more samples gives
/// its `len − 2` regression rows, with its own mean sampling period;
/// segments of one or two samples give none (their samples are counted in
/// `unused_samples`).
///
/// # Examples
///
/// ```
/// use ctrlab::{Recording, lab::ident::{Scheme, identify}};
///
/// let rec = Recording::read_csv(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ident_square_wave.csv"))?;
/// let timing = identify(&rec, 1.3, 0.7, Scheme::Central)?.timing;
/// // A uniformly sampled recording: one segment, every row, no gap.
/// assert_eq!((timing.segments, timing.rows, timing.gaps), (1, rec.len() - 2, 0));
/// assert!(timing.max_jitter < 1e-9);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Timing {
    /// Segments that gave rows (three or more samples).
    pub segments: usize,
    /// Regression rows the segments give, `Σ (len − 2)`: the rows of each
    /// stage without the Coulomb column (with it, each stage keeps only the
    /// rows where its cart moves; see the stage fits' `rows`).
    pub rows: usize,
    /// Gaps the recording was split at: intervals longer than
    /// [`GAP_RATIO`] times the median.
    pub gaps: usize,
    /// Longest gap, s (0 without gaps).
    pub longest_gap: f64,
    /// Intervals shorter than `2 − GAP_RATIO` times the median (each after
    /// a sample taken over half a period late), where the recording was
    /// split too.
    pub short_intervals: usize,
    /// Other intervals further than the jitter tolerance from the median
    /// (a late sample: too irregular to difference across, too short to be
    /// a gap), where the recording was split too.
    pub jittered: usize,
    /// Samples in segments too short to give a row (one or two samples
    /// between gaps).
    pub unused_samples: usize,
    /// Largest jitter kept: the largest deviation of an interval from its
    /// segment's mean period, as a fraction of that period (about twice
    /// [`Options::max_jitter`](super::Options::max_jitter) at most).
    pub max_jitter: f64,
    /// Shortest mean period of a segment that gave rows, s.
    pub min_period: f64,
    /// Longest mean period of a segment that gave rows, s.
    pub max_period: f64,
}

/// One run of samples `start..end` between gaps, of at least three
/// samples; its rows are `row0 .. row0 + end − start − 2` of each column.
#[derive(Debug, Clone, Copy)]
pub(super) struct Segment {
    pub start: usize,
    pub end: usize,
    pub row0: usize,
    /// Mean sampling period, s.
    pub dt: f64,
}

impl Segment {
    /// Number of rows.
    pub fn rows(&self) -> usize {
        self.end - self.start - 2
    }
}

/// The segments of time column `t` (finite values) and what was found.
/// Row-giving segments only; the mean period over them is returned too
/// (`Σ spans / Σ intervals`; for one segment exactly its own period).
pub(super) fn segments(t: &[f64], max_jitter: f64) -> Result<(Vec<Segment>, Timing, f64), Error> {
    let n = t.len();
    if n < 3 {
        return Ok((
            Vec::new(),
            Timing {
                unused_samples: n,
                ..Timing::default()
            },
            f64::NAN,
        ));
    }
    // Fast path: every interval within the tolerance of the overall mean
    // (vectorised, as `Recording::sample_period`): one segment, no gap,
    // and the same period, bit for bit, as the uniform check computes.
    let dt = (t[n - 1] - t[0]) / (n - 1) as f64;
    let worst = max_step_deviation(t, dt);
    if dt.is_finite() && dt > 0.0 && worst <= max_jitter.min(FAST_PATH_JITTER) * dt {
        let timing = Timing {
            segments: 1,
            rows: n - 2,
            max_jitter: worst / dt,
            min_period: dt,
            max_period: dt,
            ..Timing::default()
        };
        return Ok((
            vec![Segment {
                start: 0,
                end: n,
                row0: 0,
                dt,
            }],
            timing,
            dt,
        ));
    }
    // The values are finite (checked by the caller).
    if let Some(k) = (1..n).find(|&k| t[k] <= t[k - 1]) {
        return Err(Error::InvalidRecording {
            index: k,
            reason: format!(
                "time {} s does not increase (previous {} s)",
                t[k],
                t[k - 1]
            ),
        });
    }
    let mut intervals: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
    let mid = intervals.len() / 2;
    let median = *intervals.select_nth_unstable_by(mid, f64::total_cmp).1;
    drop(intervals);
    let (gap, short) = (GAP_RATIO * median, (2.0 - GAP_RATIO) * median);
    let (late, early) = ((1.0 + max_jitter) * median, (1.0 - max_jitter) * median);

    let mut timing = Timing {
        min_period: f64::INFINITY,
        max_period: 0.0,
        ..Timing::default()
    };
    let mut segs = Vec::new();
    let (mut span, mut steps) = (0.0, 0usize);
    let mut start = 0;
    for end in 1..=n {
        if end < n {
            let interval = t[end] - t[end - 1];
            if interval > gap {
                timing.gaps += 1;
                timing.longest_gap = timing.longest_gap.max(interval);
            } else if interval < short {
                timing.short_intervals += 1;
            } else if interval > late || interval < early {
                timing.jittered += 1;
            } else {
                continue;
            }
        }
        let len = end - start;
        if len < 3 {
            timing.unused_samples += len;
        } else {
            let dt = (t[end - 1] - t[start]) / (len - 1) as f64;
            if !(dt.is_finite() && dt > 0.0) {
                // An overflowing span: nothing to difference over.
                return Err(Error::InvalidRecording {
                    index: start,
                    reason: format!("the time stamps from {} s on overflow", t[start]),
                });
            }
            for k in start + 1..end {
                // Every interval here is within the tolerance of the
                // median, so within about twice it of the segment's mean.
                let jitter = ((t[k] - t[k - 1]) - dt).abs() / dt;
                timing.max_jitter = timing.max_jitter.max(jitter);
            }
            segs.push(Segment {
                start,
                end,
                row0: timing.rows,
                dt,
            });
            timing.segments += 1;
            timing.rows += len - 2;
            timing.min_period = timing.min_period.min(dt);
            timing.max_period = timing.max_period.max(dt);
            span += t[end - 1] - t[start];
            steps += len - 1;
        }
        start = end;
    }
    let mean = match segs.as_slice() {
        [one] => one.dt,
        _ => span / steps as f64,
    };
    if segs.is_empty() {
        timing.min_period = 0.0;
    }
    Ok((segs, timing, mean))
}
