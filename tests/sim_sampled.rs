//! `run_sampled`'s quantisers and sensors on the inputs issue 28 found
//! wrong: a measurement step of 1e-310 recorded `inf`, a NaN sensor was
//! recorded inside `Ok`, ±1 V in 0.4 V steps applied 1.2 V, and an input
//! step of 1e-310 was reported as a diverging plant.

use ctrlab::sim::{SampledConfig, run_sampled};
use ctrlab::{Error, OpenLoop, StateSpace};
use nalgebra::{SVector, matrix, vector};

/// A stable lag `x' = −x + u`, `y = x`.
fn lag() -> StateSpace<1, 1, 1, ctrlab::Continuous> {
    StateSpace::continuous(matrix![-1.0], matrix![1.0], matrix![1.0], matrix![0.0]).unwrap()
}

/// The input `r` itself (open loop), over 0.1 s at 10 ms.
fn run(r: f64, config: SampledConfig<1, 1>) -> Result<ctrlab::Recording, Error> {
    let sensor = |x: &SVector<f64, 1>| *x;
    run_sampled(
        lag(),
        sensor,
        OpenLoop,
        move |_| vector![r],
        vector![0.5],
        &config,
    )
}

#[test]
fn a_measurement_step_finer_than_f64_leaves_the_measurement_alone() {
    let config = SampledConfig {
        quantisation: [1e-310],
        ..SampledConfig::new(0.01, 0.1)
    };
    let rec = run(1.0, config).unwrap();
    let ideal = run(1.0, SampledConfig::new(0.01, 0.1)).unwrap();
    assert_eq!(rec.channel("y").unwrap(), ideal.channel("y").unwrap());
}

#[test]
fn an_input_step_finer_than_f64_leaves_the_input_alone() {
    let config = SampledConfig {
        input_quantisation: [1e-310],
        ..SampledConfig::new(0.01, 0.1)
    };
    let rec = run(1.0, config).unwrap();
    assert!(rec.channel("u").unwrap().iter().all(|&u| u == 1.0));
}

#[test]
fn a_quantised_input_never_rounds_past_its_saturation() {
    // ±1 V in 0.4 V steps: 1 rounds to 1.2 (2.5 steps, half away from
    // zero); the largest step within ±1 is 0.8.
    for (r, applied) in [(5.0, 0.8), (-5.0, -0.8), (0.5, 0.4), (0.3, 0.4)] {
        let config = SampledConfig {
            saturation: [1.0],
            input_quantisation: [0.4],
            ..SampledConfig::new(0.01, 0.1)
        };
        let rec = run(r, config).unwrap();
        assert!(
            rec.channel("u").unwrap().iter().all(|&u| u == applied),
            "r = {r}: {:?}",
            rec.channel("u")
        );
    }
    // A limit below half a step: only 0 is within it.
    let config = SampledConfig {
        saturation: [0.1],
        input_quantisation: [0.4],
        ..SampledConfig::new(0.01, 0.1)
    };
    assert!(
        run(5.0, config)
            .unwrap()
            .channel("u")
            .unwrap()
            .iter()
            .all(|&u| u == 0.0)
    );
    // The lab's drive: ±24 V in 24 mV steps reaches 24 V exactly.
    let config = SampledConfig {
        saturation: [24.0],
        input_quantisation: [0.024],
        ..SampledConfig::new(0.01, 0.1)
    };
    assert!(
        run(30.0, config)
            .unwrap()
            .channel("u")
            .unwrap()
            .iter()
            .all(|&u| u == 24.0)
    );
}

#[test]
fn a_sensor_returning_nan_is_refused_by_name() {
    let sensor = |_: &SVector<f64, 1>| vector![f64::NAN];
    let err = run_sampled(
        lag(),
        sensor,
        OpenLoop,
        |_| vector![1.0],
        vector![0.0],
        &SampledConfig::new(0.01, 0.1),
    )
    .unwrap_err();
    assert!(
        matches!(
            err,
            Error::InvalidParameter {
                name: "measurement",
                ..
            }
        ),
        "{err}"
    );
}
