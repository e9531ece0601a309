//! [`step_info`]: the figures of sampled data.

use super::{Definition, SettleFailure, StepInfo, StepInfoOptions, scan};
use crate::error::Error;

/// Step-response figures of sampled data `y` at times `t` (s, strictly
/// increasing), under the definitions `options.definition` names (see the
/// [module docs](super#definitions)); crossing times are interpolated. One
/// pass over the samples (with a check of them before it), plus early-exit
/// searches through the transient; allocates nothing.
///
/// # Errors
///
/// - [`Error::LengthMismatch`] if `y` and `t` differ in length;
/// - [`Error::InvalidData`] for fewer than 3 samples, a non-finite sample, a
///   non-increasing `t`, no step (`Δ = 0`), or a response that never reaches
///   the upper rise level;
/// - [`Error::InvalidParameter`] for bad options;
/// - [`Error::NotSettled`] when `y` is outside the band anywhere in the final
///   window (under [`Definition::Matlab`]: at the last sample), with its
///   [`SettleFailure`] (diverging, oscillating, or a record too short);
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
    measure(t, y, options, Crossings::Interpolated)
}

/// How a crossing time between two samples is found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Crossings {
    /// Samples of a curve: interpolated linearly between them.
    Interpolated,
    /// A sequence (a discrete model's response): a level is reached at the
    /// first sample that reaches it.
    AtSamples,
}

/// [`step_info`] with the crossing rule of the data's kind.
pub(super) fn measure(
    t: &[f64],
    y: &[f64],
    options: &StepInfoOptions,
    crossings: Crossings,
) -> Result<StepInfo, Error> {
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
    // One branch-free scan first; locate the culprit only when there is one.
    if !scan::all_valid(t, y) {
        return Err(locate_bad_sample(t, y));
    }

    let t0 = t[0];
    let matlab = options.definition == Definition::Matlab;
    // Final window: the last ⌈w·n⌉ samples, at least one; MATLAB asks only
    // for the last sample.
    let window = if matlab {
        1
    } else {
        ((options.final_window * n as f64).ceil() as usize).clamp(1, n)
    };
    let window_start = n - window;
    let half = window / 2;
    // The estimated final value and the trend check's two half means.
    let means = (options.final_value.is_none() && window >= 2)
        .then(|| scan::window_means(&y[window_start..], half));
    let y0 = match (options.initial_value, matlab) {
        (Some(v), _) => v,
        (None, true) => 0.0,
        (None, false) => y[0],
    };
    let yf = match (options.final_value, matlab, means) {
        (Some(v), _, _) => v,
        (None, true, _) => y[n - 1],
        (None, false, Some([all, _, _])) => all,
        (None, false, None) => mean(&y[window_start..]),
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
    let not_settled = |last_outside: f64| Error::NotSettled {
        last_outside,
        window_start: t[window_start] - t0,
        cause: settle_failure(y, yf, window_start),
    };
    if let Some([_, first, second]) = means {
        // An estimated final value cannot reveal a response still creeping
        // towards its end (it moves with it), so also ask for no trend: the
        // two halves of the final window agree to a quarter of the band.
        // Halved before subtracting: the difference of two finite means
        // can overflow, and then the response certainly trends.
        if (0.5 * second - 0.5 * first).abs() > 0.125 * band {
            return Err(not_settled(t[n - 1] - t0));
        }
    }
    // Progress along the step, 0 at y₀ and 1 at y∞.
    let progress = |v: f64| (v - y0) / delta;

    // Rise: first crossings of the two levels, searched first (the
    // settling extremes start at the upper one) and reported after the
    // settling figures, whose errors come first.
    let (lo, hi) = options.rise_limits;
    let cross = |level: f64, from: usize| -> Option<(usize, f64)> {
        let i = scan::first_where(y, from, |v| progress(v) >= level)?;
        if i == 0 || progress(y[i - 1]) >= level || crossings == Crossings::AtSamples {
            return Some((i, t[i]));
        }
        let target = y0 + level * delta;
        Some((i, crossing(t[i - 1], y[i - 1], t[i], y[i], target)))
    };
    let rise_lo = cross(lo, 0);
    let rise_hi = rise_lo.and_then(|(i_lo, _)| cross(hi, i_lo));

    // The one pass over all samples: the extremes (the peak, the
    // undershoot and the largest error come from them), those from the
    // upper rise level on, and the last sample outside the band.
    let sweep = scan::sweep(y, rise_hi.map_or(n, |(i, _)| i), yf, band);
    let (y_min, y_max) = (sweep.min, sweep.max);

    // When |y − y∞| enters [0, threshold] for good: after the last sample
    // outside, `j`, which must come before the final window.
    let settles = |j: Option<usize>, threshold: f64| -> Result<f64, Error> {
        let Some(j) = j else {
            return Ok(0.0);
        };
        if j + 1 >= n {
            return Err(not_settled(t[n - 1] - t0));
        }
        let ts = match crossings {
            Crossings::AtSamples => t[j + 1],
            Crossings::Interpolated => {
                let edge = if y[j] > yf {
                    yf + threshold
                } else {
                    yf - threshold
                };
                crossing(t[j], y[j], t[j + 1], y[j + 1], edge)
            }
        } - t0;
        if j + 1 > window_start {
            return Err(not_settled(ts));
        }
        Ok(ts)
    };
    let j_settled = sweep.last_outside;
    let settling_time = settles(j_settled, band)?;
    // Largest error, halved so that it cannot overflow (y∞ was checked
    // against y₀, not against every sample).
    let half_error = (0.5 * y_max - 0.5 * yf)
        .abs()
        .max((0.5 * y_min - 0.5 * yf).abs());
    let transient_band = (options.settling_band * half_error * 2.0).min(f64::MAX);
    // Every sample after the last one outside the settling band is inside
    // a wider band too: only the samples before it need a look.
    let end = if transient_band >= band {
        j_settled.map_or(0, |j| j + 1)
    } else {
        n
    };
    let j_transient = scan::last_where(&y[..end], |v| (v - yf).abs() > transient_band);
    let transient_time = settles(j_transient, transient_band)?;

    let (_, t_lo) = rise_lo.ok_or(Error::InvalidData {
        what: "y",
        index: n,
        reason: "response never reaches the lower rise level",
    })?;
    let (_, t_hi) = rise_hi.ok_or(Error::InvalidData {
        what: "y",
        index: n,
        reason: "response never reaches the upper rise level",
    })?;

    // The peak is the extreme in the step's direction, the undershoot the
    // other.
    let (along, wrong_way) = if delta > 0.0 {
        (y_max, y_min)
    } else {
        (y_min, y_max)
    };
    // MATLAB's peak is the largest |y − y₀|, which may lie the wrong way.
    let (peak, peak_i) = if matlab {
        let peak = (along - y0).abs().max((wrong_way - y0).abs());
        (peak, scan::first_where(y, 0, |v| (v - y0).abs() == peak))
    } else {
        (along, scan::first_where(y, 0, |v| v == along))
    };
    let peak_i = peak_i.unwrap_or(0);
    let (peak_p, min_p) = (progress(along), progress(wrong_way));
    let info = StepInfo {
        rise_time: t_hi - t_lo,
        settling_time,
        transient_time,
        settling_min: sweep.tail_min,
        settling_max: sweep.tail_max,
        overshoot: (100.0 * (peak_p - 1.0)).max(0.0),
        // Written out so that no undershoot is +0, never -0 (printed "-0").
        undershoot: if min_p < 0.0 { -100.0 * min_p } else { 0.0 },
        peak,
        peak_time: t[peak_i] - t0,
        steady_state_value: yf,
        steady_state_error: options.reference.map(|r| r - yf),
    };
    check_measured(&info)?;
    Ok(info)
}

/// Every figure must be a finite number: a peak a googol of steps away,
/// or times spanning more than `f64::MAX` seconds, are errors, not `inf`.
pub(super) fn check_measured(info: &StepInfo) -> Result<(), Error> {
    let figures = [
        (info.rise_time, "step metrics: rise time overflows"),
        (info.settling_time, "step metrics: settling time overflows"),
        (
            info.transient_time,
            "step metrics: transient time overflows",
        ),
        (info.peak_time, "step metrics: peak time overflows"),
        (info.peak, "step metrics: peak |y − y₀| overflows"),
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
pub(super) fn mean(y: &[f64]) -> f64 {
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
pub(super) fn settle_failure(y: &[f64], yf: f64, window_start: usize) -> SettleFailure {
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
pub(super) fn locate_bad_sample(t: &[f64], y: &[f64]) -> Error {
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
pub(super) fn crossing(ta: f64, ya: f64, tb: f64, yb: f64, level: f64) -> f64 {
    let dy = yb - ya;
    if dy == 0.0 {
        return tb;
    }
    let f = ((level - ya) / dy).clamp(0.0, 1.0);
    ta + f * (tb - ta)
}
