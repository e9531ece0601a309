//! lab5's Design section for cart 2, end to end on the simulated rig:
//! identify the plant from an open-loop run, design LQI with a Kalman
//! filter to the spec by the section's search on predictions, run the
//! design through `hw::run`, and judge the recorded step against the spec.

// Built on the two-cart lab (its plant, simulated rig or card).
#![cfg(feature = "lab")]

mod common;

use common::run_on_rig;
use ctrlab::lab::ident::{SEPARATE_SPRINGS, identify_with};
use ctrlab::lab::ident_input::{AmplitudeSearch, IdentInput, PROBE_DURATION, ProbeFault, peaks};
use ctrlab::lab::lqi::{self, Design, Metrics, Spec};
use ctrlab::lab::protocol::{self, IDENT_DURATION};
use ctrlab::lab::{CardSettings, Cart, Friction, MassSpring, SimulatedRig};
use ctrlab::signal::SquareWave;
use std::sync::OnceLock;

const SETPOINT: f64 = 0.030;

/// The plant and Coulomb friction identified from one of lab5's
/// identification runs on `sim` (the square wave of 0.2 s half period,
/// 5 s, at the amplitude lab5 chooses from its probe runs: 8 V on the
/// default rig, 7.64 V without its unmodelled effects), with the masses
/// known.
fn identified(sim: &SimulatedRig) -> (MassSpring, [f64; 2]) {
    let ident = IdentInput::default();
    let mut n = 0;
    let volts = AmplitudeSearch::new(ident.volts, sim.calibration.travel_limits)
        .unwrap()
        .run(|v| {
            n += 1;
            let probe = SimulatedRig {
                card: CardSettings {
                    seed: 100 + n,
                    ..sim.card
                },
                ..sim.clone()
            };
            let input = ident.input(v, IDENT_DURATION).unwrap();
            Ok::<_, ProbeFault>(peaks(&common::open_loop(&probe, &input, PROBE_DURATION)).unwrap())
        })
        .unwrap()
        .volts;
    let wave = SquareWave::new(volts, protocol::IDENT_HALF_PERIOD).unwrap();
    let rec = common::open_loop(sim, &wave, IDENT_DURATION);
    let (m1, m2) = (sim.truth.m1, sim.truth.m2);
    let e = identify_with(&rec, m1, m2, &SEPARATE_SPRINGS).unwrap();
    let coulomb = e.coulomb.unwrap().map(|f| f.value);
    let model = MassSpring {
        m1,
        m2,
        k1: e.k1().value,
        k2: e.k2().value,
        b1: e.b1.value,
        b2: e.b2.value,
        gain: e.gain.value,
    };
    (model, coulomb)
}

/// Cart 2's design, on the model identified from the default simulated
/// rig, made once for both tests (the search predicts 25 steps).
fn design() -> &'static Design {
    static DESIGN: OnceLock<Design> = OnceLock::new();
    DESIGN.get_or_init(|| {
        let sim = SimulatedRig::default();
        let (model, coulomb) = identified(&sim);
        let rig = lqi::predicted_rig(model, coulomb, &sim.calibration, sim.period);
        let spec = Spec::new(Cart::Two, SETPOINT, sim.calibration.volts_full_scale);
        lqi::design_search(&rig, spec).unwrap()
    })
}

/// The design's step on `sim`'s rig through `hw::run`, and its figures.
fn run(sim: &SimulatedRig) -> Metrics {
    let design = design();
    let rec = run_on_rig(sim, design.lqi.controller, SETPOINT, lqi::DURATION);
    let measured = Metrics::of(&rec, &design.spec, sim.metres_per_count()).unwrap();
    println!(
        "ρ = {:.3e} ({:?}); predicted {:?}, peak {:.2} V; measured {:?}, peak {:.2} V, {} samples at the limit",
        design.rho,
        design.choice,
        design.metrics.step,
        design.metrics.peak_u,
        measured.step,
        measured.peak_u,
        measured.clipped
    );
    measured
}

#[test]
fn cart_2_on_the_simulated_rig_meets_overshoot_settling_and_drive_and_rests_within_3_counts() {
    let sim = SimulatedRig {
        // lab5's run of this design
        card: CardSettings {
            seed: 202,
            ..CardSettings::default()
        },
        ..SimulatedRig::default()
    };
    let rig = run(&sim);
    let spec = design().spec;
    assert!(
        design().metrics.passes(&spec),
        "the prediction meets the spec"
    );
    let step = rig.step.as_ref().expect("the rig's step settles");
    assert!(step.overshoot <= spec.overshoot, "{step:?}");
    assert!(step.settling <= spec.settling, "{step:?}");
    assert!(
        rig.clipped == 0 && rig.peak_u <= spec.volts,
        "the drive stays within ±{} V: peak {} V",
        spec.volts,
        rig.peak_u
    );
    // The spec's one count is met or missed by where the cart sticks: the
    // card's carts break away 20 % above their Coulomb force, which
    // identification cannot see, and read with noise, so cart 2 stops a
    // count or two off; an integrator slow enough for the 30 mm step to
    // stay within 24 V walks it in over seconds more than the run has
    // (lab5's Design section derives the numbers). More than three counts
    // would be a worse design or plant.
    assert!(
        step.error_counts.abs() <= 3.0,
        "steady-state error {:+.2} counts",
        step.error_counts
    );
}

#[test]
fn cart_2_meets_the_whole_spec_on_a_rig_with_only_what_the_prediction_models() {
    // The default card, but sticking at its Coulomb force and read without
    // noise: the rig's physics are the prediction's then, up to the
    // identification error.
    let defaults = SimulatedRig::default();
    let sim = SimulatedRig {
        friction: Friction {
            stiction: defaults.friction.coulomb,
            ..defaults.friction
        },
        card: CardSettings {
            encoder_noise: 0.0,
            ..defaults.card
        },
        ..defaults
    };
    let rig = run(&sim);
    let spec = design().spec;
    assert!(rig.passes(&spec), "{:?}", rig.verdict(&spec));
    let p = design().metrics.step.as_ref().unwrap();
    let m = rig.step.as_ref().unwrap();
    assert!(
        (p.overshoot - m.overshoot).abs() < 0.5,
        "{p:?} against {m:?}"
    );
    assert!(
        (p.settling - m.settling).abs() < 0.01,
        "{p:?} against {m:?}"
    );
}
