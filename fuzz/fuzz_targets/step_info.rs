//! `step_info` on arbitrary samples and options: the input is read as
//! little-endian f64s, five option values first, then `(t, y)` pairs.
#![no_main]

use ctrlab::{StepInfoOptions, step_info};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let values: Vec<f64> = data
        .chunks_exact(8)
        .map(|c| f64::from_le_bytes(c.try_into().unwrap_or([0; 8])))
        .collect();
    if values.len() < 5 {
        return;
    }
    let (head, samples) = values.split_at(5);
    let t: Vec<f64> = samples.iter().step_by(2).copied().collect();
    let y: Vec<f64> = samples.iter().skip(1).step_by(2).copied().collect();
    let n = t.len().min(y.len());
    // Half the runs with the raw times, half with them made increasing.
    let mut sorted = t[..n].to_vec();
    sorted.sort_by(f64::total_cmp);
    let options = [
        StepInfoOptions::default(),
        StepInfoOptions {
            settling_band: head[0],
            rise_limits: (head[1], head[2]),
            final_window: head[3],
            final_value: head[4].is_finite().then_some(head[4]),
            ..StepInfoOptions::default()
        },
        StepInfoOptions::matlab(),
        StepInfoOptions {
            settling_band: head[0],
            initial_value: head[1].is_finite().then_some(head[1]),
            final_value: head[4].is_finite().then_some(head[4]),
            ..StepInfoOptions::matlab()
        },
    ];
    for opts in &options {
        for times in [&t[..n], &sorted[..]] {
            if let Ok(info) = step_info(times, &y[..n], opts) {
                for v in [
                    info.rise_time,
                    info.transient_time,
                    info.settling_time,
                    info.settling_min,
                    info.settling_max,
                    info.overshoot,
                    info.undershoot,
                    info.peak,
                    info.peak_time,
                    info.steady_state_value,
                ] {
                    assert!(v.is_finite(), "{info:?}");
                }
            }
        }
    }
});
