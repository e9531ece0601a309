//! Step metrics against python-control's step_info rows (fixture), closed-form
//! responses, and arbitrary input (never a panic).

// Built on the two-cart lab (its plant, simulated rig or card).
#![cfg(feature = "lab")]

mod common;

use ctrlab::lab::LabGains;
use ctrlab::metrics::step_info_channel;
use ctrlab::sim::{Solver, simulate, time_grid};
use ctrlab::{
    Cart, Controller, Error, MassSpring, Recording, StateSpace, StepInfoOptions, step_info,
    step_info_of,
};
use nalgebra::{SVector, matrix, vector};
use proptest::prelude::*;

#[test]
fn table_2_rows_match_python_control() {
    let fx = common::nominal_fixture();
    let rows = fx["feedback"].as_array().unwrap();
    assert!(!rows.is_empty());
    for row in rows {
        let f = |k: &str| row[k].as_f64().unwrap();
        let kf: Vec<f64> = row["kf"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect();
        assert_eq!(row["cart"].as_u64(), Some(2));
        let plant = MassSpring::nominal().state_space(Cart::Two).unwrap();
        let ctrl = LabGains::new([kf[0], kf[1], kf[2], kf[3]], Cart::Two)
            .state_feedback()
            .unwrap();
        let cl = ctrl.closed_loop(&plant).unwrap();
        let setpoint = f("setpoint_mm") / 1000.0;
        // The fixture's grid: 0.5 ms out to 20 s.
        let t = time_grid(f("t_end"), f("grid_dt")).unwrap();
        let r = simulate(
            &cl,
            &t,
            SVector::zeros(),
            |_| vector![setpoint],
            Solver::Zoh,
        )
        .unwrap();
        let y_mm: Vec<f64> = r.y.iter().map(|y| y[0] * 1000.0).collect();
        // python-control takes the final value from the DC gain; so do we.
        let final_mm = cl.dc_gain().unwrap()[(0, 0)] * f("setpoint_mm");
        let info = step_info(
            &r.t,
            &y_mm,
            &StepInfoOptions {
                final_value: Some(final_mm),
                reference: Some(f("setpoint_mm")),
                ..Default::default()
            },
        )
        .unwrap();
        let dt = f("grid_dt");
        assert!(
            (info.overshoot - f("overshoot_pct")).abs() <= 0.5,
            "{kf:?} POT {}",
            info.overshoot
        );
        // python-control snaps crossings to the grid, we interpolate: at most
        // one sample apart, plus the interpolation itself (issue: 2 ms).
        assert!(
            (info.settling_time - f("settling_time")).abs() <= 0.002,
            "{kf:?} Ts {}",
            info.settling_time
        );
        assert!(
            (info.rise_time - f("rise_time")).abs() <= 0.002,
            "{kf:?} Tr {}",
            info.rise_time
        );
        assert!(
            (info.peak_time - f("peak_time")).abs() <= dt,
            "{kf:?} Tp {}",
            info.peak_time
        );
        assert!(
            (info.peak - f("peak_mm")).abs() <= 1e-6,
            "{kf:?} peak {}",
            info.peak
        );
        assert!((info.steady_state_value - f("steady_state_mm")).abs() <= 1e-6);
        let err = info.steady_state_error.unwrap();
        assert!(
            (err - f("steady_state_error_mm")).abs() <= 1e-6,
            "{kf:?} ess {err}"
        );
    }
}

#[test]
fn step_info_of_a_recorded_channel() {
    // Table 2, row [0 0 10 0.1], recorded in the lab's schema (u, x1, v1,
    // x2, v2) as the rig's loop records it; the input is the controller's.
    let plant = MassSpring::nominal().state_space(Cart::Two).unwrap();
    let mut ctrl = LabGains::new([0.0, 0.0, 10.0, 0.1], Cart::Two)
        .state_feedback()
        .unwrap();
    let cl = ctrl.closed_loop(&plant).unwrap();
    let setpoint = 0.030;
    let t = time_grid(2.0, 0.0005).unwrap();
    let r = simulate(
        &cl,
        &t,
        SVector::zeros(),
        |_| vector![setpoint],
        Solver::Zoh,
    )
    .unwrap();
    let mut rec = Recording::with_capacity(ctrlab::lab::schema(), t.len());
    for (tk, x) in t.iter().zip(&r.x) {
        let u = ctrl.update(x, &vector![setpoint]);
        rec.push_vectors(*tk, &u, x).unwrap();
    }
    let opts = StepInfoOptions {
        reference: Some(setpoint),
        ..Default::default()
    };
    let x2: Vec<f64> = r.x.iter().map(|x| x[2]).collect();
    let info = step_info_channel(&rec, "x2", &opts).unwrap();
    assert_eq!(info, step_info(&t, &x2, &opts).unwrap());
    // About 5 % overshoot, as in the fixture's row.
    assert!((info.overshoot - 5.03).abs() < 0.5, "{}", info.overshoot);
    match step_info_channel(&rec, "y", &opts) {
        Err(Error::Channel { name, reason }) => {
            assert_eq!(name, "y");
            assert!(reason.contains("t, u, x1, v1, x2, v2"), "{reason}");
        }
        other => panic!("expected Error::Channel, got {other:?}"),
    }
}

fn first_order(tau: f64, offset: f64, dt: f64, t_end: f64) -> (Vec<f64>, Vec<f64>) {
    let t: Vec<f64> = time_grid(t_end, dt).unwrap();
    let y = t.iter().map(|t| offset + 1.0 - (-t / tau).exp()).collect();
    (t, y)
}

#[test]
fn first_order_rise_and_settling_times_on_a_coarse_grid() {
    let tau = 0.5;
    // Ten samples per time constant: snapping to the grid would be off by up
    // to 0.05 s (2.6 % of the settling time); interpolation is not.
    let (t, y) = first_order(tau, 0.0, tau / 10.0, 20.0 * tau);
    let info = step_info(&t, &y, &StepInfoOptions::default()).unwrap();
    let (tr, ts) = (tau * 9f64.ln(), tau * 50f64.ln());
    assert!(
        (info.rise_time - tr).abs() <= 1e-3 * tr,
        "rise {}",
        info.rise_time
    );
    assert!(
        (info.settling_time - ts).abs() <= 1e-3 * ts,
        "settling {}",
        info.settling_time
    );
    // The default final value is the mean of the last 5 %, a hair (~1e-9)
    // below the last samples, so the "overshoot" is that hair, not zero.
    assert!(info.overshoot < 1e-6, "overshoot {}", info.overshoot);
    assert_eq!(info.undershoot, 0.0);
    assert_eq!(info.steady_state_error, None);
    // The default final value (mean of the last 5 %) is e^-19-close to 1.
    assert!((info.steady_state_value - 1.0).abs() < 1e-7);
}

#[test]
fn an_offset_does_not_change_the_times() {
    let tau = 0.5;
    let (t, y) = first_order(tau, 0.0, tau / 10.0, 20.0 * tau);
    let (_, y5) = first_order(tau, 5.0, tau / 10.0, 20.0 * tau);
    let a = step_info(&t, &y, &StepInfoOptions::default()).unwrap();
    let b = step_info(&t, &y5, &StepInfoOptions::default()).unwrap();
    // Same times up to rounding of the shifted samples.
    assert!((a.rise_time - b.rise_time).abs() < 1e-9);
    assert!((a.settling_time - b.settling_time).abs() < 1e-9);
    assert!((b.steady_state_value - 6.0).abs() < 1e-7);
    assert!((b.settling_time - tau * 50f64.ln()).abs() <= 1e-3 * tau * 50f64.ln());
}

#[test]
fn a_negative_step_has_the_same_figures() {
    let tau = 0.2;
    let (t, y) = first_order(tau, 0.0, 0.01, 20.0 * tau);
    let neg: Vec<f64> = y.iter().map(|v| -v).collect();
    let a = step_info(&t, &y, &StepInfoOptions::default()).unwrap();
    let b = step_info(&t, &neg, &StepInfoOptions::default()).unwrap();
    assert!((a.rise_time - b.rise_time).abs() < 1e-12);
    assert!((a.settling_time - b.settling_time).abs() < 1e-12);
    // The peak is the sample farthest along the step: the most negative one.
    assert_eq!(b.peak, neg.iter().copied().fold(f64::INFINITY, f64::min));
    assert_eq!(a.peak, -b.peak);
}

/// Unit step response of ωn² / (s² + 2ζωn s + ωn²), closed form.
fn second_order(zeta: f64, wn: f64, t: f64) -> f64 {
    let wd = wn * (1.0 - zeta * zeta).sqrt();
    1.0 - (-zeta * wn * t).exp() * ((wd * t).cos() + zeta * wn / wd * (wd * t).sin())
}

#[test]
fn second_order_model_overshoot_is_the_textbook_value() {
    let (zeta, wn) = (0.3, 20.0);
    let sys = common::second_order(zeta, wn);
    let info = step_info_of(
        &sys,
        3.0,
        1e-4,
        &StepInfoOptions {
            reference: Some(1.0),
            ..Default::default()
        },
    )
    .unwrap();
    let want = 100.0 * (-zeta * std::f64::consts::PI / (1.0 - zeta * zeta).sqrt()).exp();
    // The peak is a sample: with dt = 1e-4 s it is at most dt/2 from the true
    // peak, where y' = 0, so the error is O(y''·dt²) ≈ 1e-6 %.
    assert!(
        (info.overshoot - want).abs() < 1e-4,
        "{} vs {want}",
        info.overshoot
    );
    let tp = std::f64::consts::PI / (wn * (1.0 - zeta * zeta).sqrt());
    assert!((info.peak_time - tp).abs() <= 1e-4);
    assert_eq!(info.steady_state_error, Some(0.0));
    assert!((info.settling_max - info.peak).abs() < 1e-15);
}

#[test]
fn second_order_data_overshoot_for_several_dampings() {
    for zeta in [0.1, 0.2, 0.4, 0.6, 0.8] {
        let wn = 5.0;
        let t = time_grid(30.0, 1e-3).unwrap();
        let y: Vec<f64> = t.iter().map(|&t| second_order(zeta, wn, t)).collect();
        let info = step_info(
            &t,
            &y,
            &StepInfoOptions {
                final_value: Some(1.0),
                ..Default::default()
            },
        )
        .unwrap();
        let want = 100.0 * (-zeta * std::f64::consts::PI / (1.0 - zeta * zeta).sqrt()).exp();
        assert!(
            (info.overshoot - want).abs() < 1e-3,
            "ζ = {zeta}: {} vs {want}",
            info.overshoot
        );
    }
}

#[test]
fn unsettled_and_diverging_responses_are_errors() {
    let t = time_grid(2.0, 0.01).unwrap();
    // Still rising at the end.
    let slow: Vec<f64> = t.iter().map(|t| 1.0 - (-t / 1.0f64).exp()).collect();
    assert!(matches!(
        step_info(
            &t,
            &slow,
            &StepInfoOptions {
                final_value: Some(1.0),
                ..Default::default()
            }
        ),
        Err(Error::NotSettled { .. })
    ));
    assert!(matches!(
        step_info(&t, &slow, &StepInfoOptions::default()),
        Err(Error::NotSettled { .. })
    ));
    // Growing oscillation.
    let growing: Vec<f64> = t
        .iter()
        .map(|t| 1.0 - (0.5 * t).exp() * (20.0 * t).cos())
        .collect();
    assert!(matches!(
        step_info(&t, &growing, &StepInfoOptions::default()),
        Err(Error::NotSettled { .. })
    ));
    // An unstable model is refused before it is simulated.
    let unstable =
        StateSpace::continuous(matrix![0.5], matrix![1.0], matrix![1.0], matrix![0.0]).unwrap();
    assert!(matches!(
        step_info_of(&unstable, 5.0, 0.01, &StepInfoOptions::default()),
        Err(Error::Unstable { re, .. }) if re == 0.5
    ));
}

#[test]
fn bad_input_is_an_error() {
    let t = [0.0, 1.0, 2.0, 3.0];
    let opts = StepInfoOptions::default();
    assert_eq!(
        step_info(&t, &[0.0, 1.0], &opts).unwrap_err(),
        Error::LengthMismatch {
            what: "y",
            expected: 4,
            found: 2
        }
    );
    assert!(matches!(
        step_info(&t, &[0.0, f64::NAN, 1.0, 1.0], &opts),
        Err(Error::InvalidData {
            what: "y",
            index: 1,
            ..
        })
    ));
    assert!(matches!(
        step_info(&[0.0, 2.0, 1.0, 3.0], &[0.0, 1.0, 1.0, 1.0], &opts),
        Err(Error::InvalidData {
            what: "t",
            index: 2,
            ..
        })
    ));
    assert!(matches!(
        step_info(&t, &[1.0; 4], &opts),
        Err(Error::InvalidData { what: "y", .. })
    ));
    assert!(matches!(
        step_info(&t[..2], &[0.0, 1.0], &opts),
        Err(Error::InvalidData { .. })
    ));
    let bad = StepInfoOptions {
        settling_band: 0.0,
        ..opts
    };
    assert!(matches!(
        step_info(&t, &[0.0, 1.0, 1.0, 1.0], &bad),
        Err(Error::InvalidParameter {
            name: "settling_band",
            ..
        })
    ));
    let bad = StepInfoOptions {
        rise_limits: (0.9, 0.1),
        ..opts
    };
    assert!(matches!(
        step_info(&t, &[0.0, 1.0, 1.0, 1.0], &bad),
        Err(Error::InvalidParameter {
            name: "rise_limits",
            ..
        })
    ));
    let bad = StepInfoOptions {
        reference: Some(f64::INFINITY),
        ..opts
    };
    assert!(matches!(
        step_info(&t, &[0.0, 1.0, 1.0, 1.0], &bad),
        Err(Error::InvalidParameter {
            name: "reference",
            ..
        })
    ));
}

#[test]
fn undershoot_of_a_non_minimum_phase_response() {
    // y = 1 − e^−t − 2 t e^−t dips to −2/e² ≈ … below 0 first: the step
    // response of (1 − s)/(s + 1)² (closed form).
    let t = time_grid(30.0, 1e-3).unwrap();
    let y: Vec<f64> = t
        .iter()
        .map(|&t| 1.0 - (-t).exp() - 2.0 * t * (-t).exp())
        .collect();
    let info = step_info(
        &t,
        &y,
        &StepInfoOptions {
            final_value: Some(1.0),
            ..Default::default()
        },
    )
    .unwrap();
    // Minimum at t = 0.5: y = 1 − 2 e^−0.5.
    let want = -100.0 * (1.0 - 2.0 * (-0.5f64).exp());
    assert!(
        (info.undershoot - want).abs() < 1e-4,
        "{} vs {want}",
        info.undershoot
    );
}

proptest! {
    #[test]
    fn step_info_never_panics(
        t in proptest::collection::vec(prop_oneof![-1e3..1e3f64, Just(f64::NAN), Just(f64::INFINITY)], 0..40),
        y in proptest::collection::vec(prop_oneof![-1e3..1e3f64, Just(f64::NAN), Just(f64::NEG_INFINITY)], 0..40),
        band in -0.5..1.5f64,
        window in -0.5..1.5f64,
    ) {
        let opts = StepInfoOptions { settling_band: band, final_window: window, ..Default::default() };
        if let Ok(info) = step_info(&t, &y, &opts) {
            prop_assert!(info.rise_time.is_finite() && info.settling_time.is_finite());
            prop_assert!(info.overshoot >= 0.0 && info.undershoot >= 0.0);
        }
    }

    #[test]
    fn step_info_on_sorted_finite_data_never_panics(
        dy in proptest::collection::vec(-10.0..10.0f64, 3..200),
    ) {
        let t: Vec<f64> = (0..dy.len()).map(|k| k as f64 * 0.01).collect();
        let y: Vec<f64> = dy.iter().scan(0.0, |s, d| { *s += d; Some(*s) }).collect();
        match step_info(&t, &y, &StepInfoOptions::default()) {
            Ok(info) => {
                prop_assert!(info.settling_time >= 0.0 && info.settling_time <= t[t.len() - 1]);
                prop_assert!(info.rise_time >= 0.0);
                prop_assert!(info.settling_min <= info.settling_max);
            }
            Err(e) => {
                let expected = matches!(e, Error::NotSettled { .. } | Error::InvalidData { .. });
                prop_assert!(expected, "unexpected error {:?}", e);
            }
        }
    }

    #[test]
    fn times_do_not_depend_on_offset_or_scale(
        tau in 0.05..2.0f64,
        offset in -100.0..100.0f64,
        scale in prop_oneof![-50.0..-0.01f64, 0.01..50.0f64],
    ) {
        let t = time_grid(25.0 * tau, tau / 20.0).unwrap();
        let base: Vec<f64> = t.iter().map(|t| 1.0 - (-t / tau).exp()).collect();
        let moved: Vec<f64> = base.iter().map(|v| offset + scale * v).collect();
        let a = step_info(&t, &base, &StepInfoOptions::default()).unwrap();
        let b = step_info(&t, &moved, &StepInfoOptions::default()).unwrap();
        // Only rounding of the transformed samples differs.
        prop_assert!((a.rise_time - b.rise_time).abs() <= 1e-8 * tau);
        prop_assert!((a.settling_time - b.settling_time).abs() <= 1e-8 * tau);
    }
}
