//! The multi-pass `step_info` of before the one-pass kernel (test only):
//! the new kernel must give the same figures and errors, bit for bit.

use super::step_info::{
    Crossings, check_measured, crossing, locate_bad_sample, mean, settle_failure,
};
use super::{Definition, StepInfo, StepInfoOptions};
use crate::error::Error;

/// The multi-pass implementation `step_info` had before its one-pass
/// kernel, kept to test that kernel against.
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
    // Branch-free scans first (they vectorise); locate the culprit only
    // when there is one.
    let y_ok = y.iter().fold(true, |ok, v| ok & v.is_finite());
    let t_ok = t.iter().fold(true, |ok, v| ok & v.is_finite())
        && t.windows(2).fold(true, |ok, w| ok & (w[1] > w[0]));
    if !y_ok || !t_ok {
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
    let y0 = match (options.initial_value, matlab) {
        (Some(v), _) => v,
        (None, true) => 0.0,
        (None, false) => y[0],
    };
    let yf = match (options.final_value, matlab) {
        (Some(v), _) => v,
        (None, true) => y[n - 1],
        (None, false) => mean(&y[window_start..]),
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
            return Err(not_settled(t[n - 1] - t0));
        }
    }
    // Progress along the step, 0 at y₀ and 1 at y∞.
    let progress = |v: f64| (v - y0) / delta;

    // Extremes by branch-free folds (all samples are finite by now): the
    // peak, the undershoot and the largest error all come from them.
    let extremes = |ys: &[f64]| {
        ys.iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| {
                (lo.min(v), hi.max(v))
            })
    };
    let (y_min, y_max) = extremes(y);

    // The last sample of y[..end] with |y − y∞| above `threshold`.
    let last_outside =
        |threshold: f64, end: usize| y[..end].iter().rposition(|&v| (v - yf).abs() > threshold);
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
    let j_settled = last_outside(band, n);
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
    let transient_time = settles(last_outside(transient_band, end), transient_band)?;

    // Rise: first crossings of the two levels.
    let (lo, hi) = options.rise_limits;
    let cross = |level: f64, from: usize| -> Option<(usize, f64)> {
        let i = (from..n).find(|&i| progress(y[i]) >= level)?;
        if i == 0 || progress(y[i - 1]) >= level || crossings == Crossings::AtSamples {
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

    // The peak is the extreme in the step's direction, the undershoot the
    // other.
    let (along, wrong_way) = if delta > 0.0 {
        (y_max, y_min)
    } else {
        (y_min, y_max)
    };
    // MATLAB's peak is the largest |y − y₀|, which may lie the wrong way.
    let peak = if matlab {
        (along - y0).abs().max((wrong_way - y0).abs())
    } else {
        along
    };
    let peak_i = y
        .iter()
        .position(|&v| {
            if matlab {
                (v - y0).abs() == peak
            } else {
                v == peak
            }
        })
        .unwrap_or(0);
    let (peak_p, min_p) = (progress(along), progress(wrong_way));
    let (s_min, s_max) = extremes(&y[i_hi..]);
    let info = StepInfo {
        rise_time: t_hi - t_lo,
        settling_time,
        transient_time,
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
    check_measured(&info)?;
    Ok(info)
}

#[cfg(test)]
mod tests {
    use super::super::step_info::measure as one_pass;
    use super::*;
    use proptest::prelude::*;

    /// Responses of every kind `step_info` meets: oscillating, monotone,
    /// never settling (ramps, sustained or growing oscillations), noisy
    /// and plain random sequences, scaled, shifted and flipped.
    fn response() -> impl Strategy<Value = (Vec<f64>, Vec<f64>)> {
        (
            3usize..400,
            0u8..6,
            (0.02..1.5f64, 0.5..30.0f64, 0.01..0.2f64),
            (-5.0..5.0f64, 0.1..10.0f64, any::<bool>()),
            (0.0..0.05f64, any::<u64>(), any::<bool>()),
        )
            .prop_map(
                |(n, kind, (zeta, wn, dt), (offset, gain, flip), (noise, seed, jitter))| {
                    // A small deterministic generator: reproducible, no new
                    // dependency.
                    let mut state = seed | 1;
                    let mut rand = move || {
                        state ^= state << 13;
                        state ^= state >> 7;
                        state ^= state << 17;
                        (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
                    };
                    let mut t = Vec::with_capacity(n);
                    let mut tk = 0.0;
                    for _ in 0..n {
                        t.push(tk);
                        tk += if jitter {
                            dt * (1.0 + 0.5 * rand())
                        } else {
                            dt
                        };
                    }
                    let y = t
                        .iter()
                        .map(|&t| {
                            let s = match kind {
                                0 => {
                                    let z = zeta.min(0.99);
                                    let wd = wn * (1.0 - z * z).sqrt();
                                    1.0 - (-z * wn * t).exp()
                                        * ((wd * t).cos()
                                            + z / (1.0 - z * z).sqrt() * (wd * t).sin())
                                }
                                1 => 1.0 - (-wn * t / 5.0).exp(),
                                2 => t * wn,
                                3 => 1.0 - (wn * t).cos(),
                                4 => 1.0 - (zeta * t).exp() * (wn * t).cos(),
                                _ => rand() * 4.0,
                            };
                            let v = offset + gain * (s + noise * rand());
                            if flip { -v } else { v }
                        })
                        .collect();
                    (t, y)
                },
            )
    }

    fn options() -> impl Strategy<Value = StepInfoOptions> {
        (
            (0.005..0.3f64, 0.0..0.5f64, 0.5..1.0f64, 0.01..1.0f64),
            (
                proptest::option::of(-2.0..2.0f64),
                proptest::option::of(-2.0..12.0f64),
                proptest::option::of(-2.0..2.0f64),
            ),
            any::<bool>(),
        )
            .prop_map(|((band, lo, hi, window), (init, fin, reference), matlab)| {
                StepInfoOptions {
                    settling_band: band,
                    rise_limits: (lo, hi),
                    final_window: window,
                    initial_value: init,
                    final_value: fin,
                    reference,
                    definition: if matlab {
                        Definition::Matlab
                    } else {
                        Definition::Ctrlab
                    },
                }
            })
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(4000))]
        /// The one-pass kernel gives the multi-pass one's figures and errors,
        /// bit for bit (Debug prints every f64 exactly, its sign too).
        #[test]
        fn one_pass_equals_multi_pass(
            (t, y) in response(),
            options in options(),
            at_samples in any::<bool>(),
            defaults in any::<bool>(),
        ) {
            let options = if defaults { StepInfoOptions::default() } else { options };
            let crossings = if at_samples { Crossings::AtSamples } else { Crossings::Interpolated };
            let new = one_pass(&t, &y, &options, crossings);
            let old = measure(&t, &y, &options, crossings);
            prop_assert_eq!(format!("{new:?}"), format!("{old:?}"));
        }
    }
}
