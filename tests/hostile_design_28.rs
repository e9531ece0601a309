//! Issue 28's bad input that got a wrong answer from the designs and
//! models: every `Ok` holds finite numbers, and a product that overflows
//! is refused where it is formed, naming what overflowed.

use ctrlab::design::{AntiWindup, EstimatorForm, IntegralFeedback, Observer, ObserverController};
use ctrlab::nalgebra::{dmatrix, dvector, matrix, vector};
use ctrlab::{Controller, DynStateSpace, Error, StateSpace};

fn overflow(err: Error, names: &str) {
    match &err {
        Error::Overflow { operation } => assert!(operation.contains(names), "{err}"),
        _ => panic!("expected an overflow naming {names}, got {err:?}"),
    }
}

#[test]
fn a_current_estimator_whose_correction_overflows_is_refused() {
    // A⁻¹ L = 1e9 / 1e-300: was accepted, its first estimate NaN.
    let model = StateSpace::discrete(
        matrix![1e-300],
        matrix![1.0],
        matrix![1e-10],
        matrix![0.0],
        0.1,
    )
    .unwrap();
    let err = Observer::new(&model, matrix![1e9], EstimatorForm::Current).unwrap_err();
    overflow(err, "A⁻¹ L");
    // The predictor form never forms A⁻¹ L: accepted, and finite.
    let mut obs = Observer::new(&model, matrix![1e9], EstimatorForm::Predictor).unwrap();
    assert!(obs.correct(&vector![1.0]).iter().all(|v| v.is_finite()));
    // L C itself overflowing is refused too.
    let model = StateSpace::discrete(
        matrix![0.5],
        matrix![1.0],
        matrix![1e300],
        matrix![1e300],
        0.1,
    )
    .unwrap();
    let err = Observer::new(&model, matrix![1e300], EstimatorForm::Predictor).unwrap_err();
    overflow(err, "L");
}

fn plant(d: f64, dt: f64) -> StateSpace<1, 1, 1, ctrlab::model::Discrete> {
    StateSpace::discrete(matrix![0.5], matrix![1.0], matrix![1.0], matrix![d], dt).unwrap()
}

#[test]
fn a_subnormal_integral_gain_with_back_calculation_is_refused() {
    // K_z⁺ = 1 / 1e-310 overflows: was accepted, NaN on the second step.
    let anti_windup = AntiWindup::BackCalculation {
        tracking: 0.1,
        deadband: 0.0,
    };
    let err =
        IntegralFeedback::new(&plant(0.0, 0.1), &matrix![0.2, 1e-310], anti_windup).unwrap_err();
    overflow(err, "K_z");
    // Without anti-windup nothing is inverted: accepted, finite.
    let mut c =
        IntegralFeedback::new(&plant(0.0, 0.1), &matrix![0.2, 1e-310], AntiWindup::None).unwrap();
    for _ in 0..3 {
        assert!(
            c.update(&vector![0.5], &vector![1.0])
                .iter()
                .all(|v| v.is_finite())
        );
    }
}

#[test]
fn an_integrated_feedthrough_that_overflows_is_refused() {
    // T D = 10 · 1e308.
    let err = IntegralFeedback::new(&plant(1e308, 10.0), &matrix![0.2, -3.0], AntiWindup::None)
        .unwrap_err();
    overflow(err, "T D");
    // H D = 1e200 · 1e200 in the observer-based controller.
    let model = plant(1e200, 0.1);
    let observer = Observer::new(&model, matrix![0.5], EstimatorForm::Predictor).unwrap();
    let err = ObserverController::new(
        observer,
        &matrix![0.2, -3.0],
        matrix![1e200],
        AntiWindup::None,
    )
    .unwrap_err();
    overflow(err, "T D");
}

#[test]
fn a_run_time_model_step_that_overflows_is_refused() {
    let sys = DynStateSpace::discrete(
        dmatrix![2.0],
        dmatrix![1.0],
        dmatrix![3.0],
        dmatrix![1e308],
        0.1,
    )
    .unwrap();
    // 2 · 1e308 and 3 · 1e308: were Ok([inf]).
    overflow(
        sys.advance(&dvector![1e308], &dvector![0.0]).unwrap_err(),
        "advance",
    );
    overflow(
        sys.output(&dvector![1e308], &dvector![0.0]).unwrap_err(),
        "output",
    );
    overflow(
        sys.output(&dvector![0.0], &dvector![10.0]).unwrap_err(),
        "output",
    );
    // A non-finite state or input is named.
    let err = sys
        .advance(&dvector![f64::NAN], &dvector![0.0])
        .unwrap_err();
    assert!(
        matches!(
            err,
            Error::InvalidData {
                what: "x",
                index: 0,
                ..
            }
        ),
        "{err:?}"
    );
    let err = sys
        .output(&dvector![0.0], &dvector![f64::INFINITY])
        .unwrap_err();
    assert!(
        matches!(
            err,
            Error::InvalidData {
                what: "u",
                index: 0,
                ..
            }
        ),
        "{err:?}"
    );
    assert_eq!(
        sys.advance(&dvector![1.0], &dvector![1.0]).unwrap(),
        dvector![3.0]
    );
}
