//! Integral action and observers in closed loop, on the lab's plant as the
//! rig runs it: anti-windup under the drive's ±24 V, and the
//! observer-based LQI controller on measured positions reaching the
//! setpoint to within an encoder count despite Coulomb friction, where the
//! lab's own law cannot.

// Built on the two-cart lab (its plant, simulated rig or card).
#![cfg(feature = "lab")]

mod common;

use common::{
    PERIOD, last, position_model as model, positions_lqi, run_on_rig, saturated, simulate_on,
};
use ctrlab::data::Recording;
use ctrlab::design::{AntiWindup, EstimatorForm, IntegralFeedback, Observer, dlqi};
use ctrlab::lab::{Friction, LabGains, SimulatedRig};
use ctrlab::sim::run_sampled;
use ctrlab::{Cart, Controller, MassSpring};
use nalgebra::{SMatrix, SVector, matrix, vector};

const SETPOINT: f64 = 0.030;

fn peak(rec: &Recording, name: &str) -> f64 {
    rec.channel(name)
        .unwrap()
        .iter()
        .copied()
        .fold(f64::MIN, f64::max)
}

// ---- anti-windup ---------------------------------------------------------------

/// Full-state LQI on cart 2, stiff enough that 30 mm asks far more than
/// 24 V at the start.
fn full_state_lqi(anti_windup: AntiWindup) -> IntegralFeedback<4, 1, 1> {
    let plant = model();
    let tracked = plant
        .with_output(Cart::Two.selection(), matrix![0.0])
        .unwrap();
    let q = SMatrix::<f64, 5, 5>::from_diagonal(&vector![0.0, 0.0, 1e8, 0.0, 1e12]);
    let sol = dlqi(&tracked, &q, &matrix![1.0]).unwrap();
    IntegralFeedback::new(&tracked, &sol.gain, anti_windup).unwrap()
}

fn run_full_state(controller: IntegralFeedback<4, 1, 1>) -> Recording {
    let sim = SimulatedRig::ideal(MassSpring::nominal());
    run_sampled(
        sim.plant(),
        |x: &SVector<f64, 4>| *x,
        controller,
        |_| vector![SETPOINT],
        SVector::zeros(),
        &sim.sampled_config(3.0),
    )
    .unwrap()
}

#[test]
fn back_calculation_cuts_the_overshoot_that_windup_causes() {
    let wound = run_full_state(full_state_lqi(AntiWindup::None));
    let guarded = run_full_state(full_state_lqi(AntiWindup::BackCalculation {
        tracking: 0.01,
        deadband: 0.024,
    }));
    for rec in [&wound, &guarded] {
        assert!(
            saturated(rec) > 10,
            "the drive must saturate for the test to mean anything"
        );
        assert!((last(rec, "x2") - SETPOINT).abs() < 1e-6, "both settle");
    }
    let overshoot = |rec: &Recording| (peak(rec, "x2") - SETPOINT) / SETPOINT * 100.0;
    let (without, with) = (overshoot(&wound), overshoot(&guarded));
    println!(
        "overshoot without anti-windup {without:.2} %, with back-calculation {with:.2} %; \
         saturated samples {} and {}",
        saturated(&wound),
        saturated(&guarded)
    );
    assert!(without > 2.0 * with + 5.0, "{without} % vs {with} %");
}

// ---- the observer-based controller on the rig, positions only ---------------------

/// The largest |x2 − setpoint| over the last `window` seconds.
fn final_error(rec: &Recording, window: f64) -> f64 {
    let x2 = rec.channel("x2").unwrap();
    let from = x2.len() - (window / PERIOD).round() as usize;
    x2[from..]
        .iter()
        .map(|x| (x - SETPOINT).abs())
        .fold(0.0, f64::max)
}

#[test]
fn observer_lqi_on_positions_reaches_the_setpoint_within_a_count_despite_friction() {
    let sim = SimulatedRig {
        // Coulomb friction only (breakaway at the same force), no delay
        // or noise: what this controller was designed against.
        friction: Friction::coulomb([1.0, 2.0]),
        ..SimulatedRig::ideal(MassSpring::nominal())
    };
    let count = sim.metres_per_count();
    let duration = 3.0;
    let lab_law = LabGains::new([0.0, 0.0, 10.0, 0.1], Cart::Two)
        .state_feedback()
        .unwrap();
    for (path, ours, theirs) in [
        (
            "run_sampled",
            simulate_on(
                &sim,
                positions_lqi(sim.metres_per_count()),
                SETPOINT,
                duration,
            ),
            simulate_on(&sim, lab_law, SETPOINT, duration),
        ),
        (
            "hw::run on the simulated rig",
            run_on_rig(
                &sim,
                positions_lqi(sim.metres_per_count()),
                SETPOINT,
                duration,
            ),
            run_on_rig(&sim, lab_law, SETPOINT, duration),
        ),
    ] {
        let (e_ours, e_lab) = (final_error(&ours, 0.5), final_error(&theirs, 0.5));
        println!(
            "{path}: over the last 0.5 s, |x2 − 30 mm| ≤ {:.4} mm ({:.2} counts) with LQI + \
             Kalman on positions; {:.4} mm ({:.1} counts) with the lab's law; peak x2 {:.3} mm, \
             {} saturated samples",
            e_ours * 1e3,
            e_ours / count,
            e_lab * 1e3,
            e_lab / count,
            peak(&ours, "x2") * 1e3,
            saturated(&ours),
        );
        assert!(e_ours <= count * (1.0 + 1e-9), "{path}: {e_ours} m");
        assert!(
            e_lab > 10.0 * count,
            "{path}: the lab's law has a standing error"
        );
    }
}
#[test]
fn with_time_the_integrator_unsticks_the_cart_onto_the_setpoints_count() {
    // Stuck one count off, cart 2 needs the integrator to move the input
    // across the friction's ±2 N band (4 V at 1 N/V) at a rate set by a
    // one-count error: about three more seconds. Then x2 reads exactly the
    // setpoint's count (30 mm is 3072 counts).
    let sim = SimulatedRig {
        // Coulomb friction only (breakaway at the same force), no delay
        // or noise: what this controller was designed against.
        friction: Friction::coulomb([1.0, 2.0]),
        ..SimulatedRig::ideal(MassSpring::nominal())
    };
    let rec = simulate_on(&sim, positions_lqi(sim.metres_per_count()), SETPOINT, 6.0);
    assert!(final_error(&rec, 0.2) < 0.5 * sim.metres_per_count());
}

// ---- refusals --------------------------------------------------------------------

#[test]
fn bad_anti_windup_settings_and_divergent_observers_are_refused() {
    use ctrlab::Error;
    let plant = model()
        .with_output(Cart::Two.selection(), matrix![0.0])
        .unwrap();
    let gain = matrix![0.0, 0.0, 100.0, 1.0, -1000.0];
    let err = IntegralFeedback::new(
        &plant,
        &gain,
        AntiWindup::BackCalculation {
            tracking: 0.001,
            deadband: 0.0,
        },
    )
    .unwrap_err();
    assert!(
        matches!(
            err,
            Error::InvalidParameter {
                name: "tracking",
                ..
            }
        ),
        "{err:?}"
    );
    let err = IntegralFeedback::new(
        &plant,
        &gain,
        AntiWindup::BackCalculation {
            tracking: 0.01,
            deadband: -1.0,
        },
    )
    .unwrap_err();
    assert!(
        matches!(
            err,
            Error::InvalidParameter {
                name: "deadband",
                ..
            }
        ),
        "{err:?}"
    );
    let err = IntegralFeedback::new(
        &plant,
        &matrix![0.0, f64::NAN, 0.0, 0.0, 0.0],
        AntiWindup::None,
    )
    .unwrap_err();
    assert!(
        matches!(err, Error::NonFinite { matrix: "K", .. }),
        "{err:?}"
    );

    // No correction at all: the nominal plant's lightly damped modes decay,
    // so the open-loop "observer" converges; a gain that overcorrects does
    // not.
    let m = model();
    assert!(Observer::new(&m, SMatrix::zeros(), EstimatorForm::Predictor).is_ok());
    let err = Observer::new(
        &m,
        SMatrix::<f64, 4, 2>::from_element(100.0),
        EstimatorForm::Current,
    )
    .unwrap_err();
    assert!(matches!(err, Error::Unstable { .. }), "{err:?}");
    // The current form needs D = 0.
    let with_d = m.with_output(*m.c(), matrix![0.0; 1.0]).unwrap();
    let err = Observer::new(&with_d, SMatrix::zeros(), EstimatorForm::Current).unwrap_err();
    assert!(
        matches!(err, Error::InvalidMatrix { matrix: "D", .. }),
        "{err:?}"
    );
}

#[test]
fn the_compensator_forgets_its_run_and_claims_the_models_period() {
    let sim = SimulatedRig::ideal(MassSpring::nominal());
    let mut c = positions_lqi(sim.metres_per_count());
    assert_eq!(c.period(), Some(PERIOD));
    let first = simulate_on(&sim, &mut c, SETPOINT, 0.5);
    assert_ne!(c.inner().integrators()[0], 0.0);
    assert_ne!(c.inner().observer().estimate(), SVector::<f64, 4>::zeros());
    c.reset();
    assert_eq!(c.inner().integrators()[0], 0.0);
    assert_eq!(c.inner().observer().estimate(), SVector::<f64, 4>::zeros());
    // The loop resets it too: the same run again, bit for bit.
    assert_eq!(simulate_on(&sim, &mut c, SETPOINT, 0.5), first);
}

/// The compensator folds its observer into the law (`K_x (I − M C)` on the
/// prediction, `K_x M` on the measurement) and predicts with `A − L C`;
/// run against the documented recursions written out, through saturation
/// and a reset, both estimator forms, it gives the same inputs and
/// estimates to rounding.
#[test]
fn the_folded_update_is_the_documented_recursion() {
    use ctrlab::design::{ObserverController, dlqe};
    let plant = model();
    let h = matrix![0.0, 1.0];
    let tracked = plant.with_output(h * plant.c(), matrix![0.0]).unwrap();
    let q = SMatrix::<f64, 5, 5>::from_diagonal(&vector![0.0, 0.0, 1e7, 0.0, 1e10]);
    let k = dlqi(&tracked, &q, &matrix![1.0]).unwrap().gain;
    let rn = SMatrix::<f64, 2, 2>::identity() * 1e-10;
    let l = dlqe(&plant, plant.b(), &matrix![10.0], &rn).unwrap().gain;
    let (a, b, cm) = (*plant.a(), *plant.b(), *plant.c());
    let m_current = a.try_inverse().unwrap() * l;
    for (form, m) in [
        (EstimatorForm::Predictor, SMatrix::<f64, 4, 2>::zeros()),
        (EstimatorForm::Current, m_current),
    ] {
        let observer = Observer::new(&plant, l, form).unwrap();
        let mut c = ObserverController::new(observer, &k, h, AntiWindup::None).unwrap();
        let (mut p, mut z) = (SVector::<f64, 4>::zeros(), 0.0);
        let kx = k.fixed_view::<1, 4>(0, 0);
        for i in 0..400 {
            if i == 250 {
                c.reset();
                (p, z) = (SVector::zeros(), 0.0);
            }
            // Measurements that wander, a setpoint step, a ±24 V drive.
            let t = i as f64 * PERIOD;
            let y = vector![0.01 * (7.0 * t).sin(), 0.02 * (3.0 * t).cos()];
            let r = vector![if i < 100 { 0.0 } else { SETPOINT }];
            let u = c.update(&y, &r);
            let estimate = p + m * (y - cm * p);
            let expected = -(kx * estimate)[0] - k[4] * z;
            assert!(
                (u[0] - expected).abs() <= 1e-9 * expected.abs().max(1.0),
                "{form:?} k = {i}: {} V against {expected} V",
                u[0]
            );
            let est = c.observer().estimate();
            assert!((est - estimate).amax() <= 1e-12 * estimate.amax().max(1e-3));
            let applied = u.map(|v| v.clamp(-24.0, 24.0));
            c.applied(&applied);
            z += (r[0] - y[1]) * PERIOD;
            p = a * p + b * applied + l * (y - cm * p);
            assert!((c.integrators()[0] - z).abs() <= 1e-12 * z.abs().max(1e-6));
        }
    }
}
