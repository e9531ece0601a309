//! Arbitrary bytes through the CSV reader and, when it accepts them, the
//! lab's identification and step metrics: no panic, no hang, and every
//! `Ok` holds finite numbers.
#![no_main]

use ctrlab::lab::ident::{Options, Scheme, SpringModel, identify, identify_with};
use ctrlab::metrics::step_info_channel;
use ctrlab::{Recording, StepInfoOptions};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(rec) = Recording::from_reader(data) else {
        return;
    };
    assert!(rec.time().iter().all(|v| v.is_finite()));
    let _ = rec.sample_period();
    for scheme in [Scheme::Lab, Scheme::Central] {
        for (m1, m2) in [(1.3, 0.7), (1300.0, 700.0)] {
            if let Ok(est) = identify(&rec, m1, m2, scheme) {
                for e in [est.k1(), est.b1, est.gain, est.b2] {
                    assert!(e.value.is_finite() && e.std_error.is_finite(), "{est:?}");
                }
                assert!(
                    est.first.r_squared.is_finite() || est.first.r_squared == f64::NEG_INFINITY
                );
                let _ = est.warnings();
                let _ = est.state_space();
            }
            let separate = Options {
                springs: SpringModel::Separate,
                scheme,
                ..Options::DEFAULT
            };
            if let Ok(est) = identify_with(&rec, m1, m2, &separate) {
                for e in [est.k1(), est.k2(), est.b1, est.gain, est.b2] {
                    assert!(e.value.is_finite() && e.std_error.is_finite(), "{est:?}");
                }
            }
        }
    }
    for channel in rec.schema().channels() {
        if let Ok(info) = step_info_channel(&rec, &channel.name, &StepInfoOptions::default()) {
            assert!(
                info.overshoot.is_finite() && info.settling_time.is_finite(),
                "{info:?}"
            );
        }
    }
});
