//! Cart 2's effective mass left free (`Options::free_m2`): on the
//! simulated rig (Coulomb friction with stiction above it, PWM delay,
//! quantised and noisy encoders) whose motor adds inertia to cart 2.

// Built on the two-cart lab (its plant, simulated rig or card).
#![cfg(feature = "lab")]

mod common;

use common::{friction_rig, open_loop};
use ctrlab::Recording;
use ctrlab::ident::Covariance;
use ctrlab::lab::ident::{Options, SpringModel, identify_with};
use ctrlab::lab::{MassSpring, SimulatedRig};
use ctrlab::signal::SquareWave;

/// The rig with cart 2's effective mass `m2` (kg) and Coulomb friction
/// `friction` (N), stiction 20 % above it.
fn rig(m2: f64, friction: [f64; 2], seed: u64) -> SimulatedRig {
    let truth = MassSpring {
        m2,
        ..SimulatedRig::default_truth()
    };
    friction_rig(truth, friction, seed)
}

/// The lab's square wave, 5 s, of force `8 + 2 F_max` N.
fn square_run(sim: &SimulatedRig) -> Recording {
    let f = sim.friction.coulomb[0].max(sim.friction.coulomb[1]);
    let volts = (8.0 + 2.0 * f) / sim.truth.gain;
    open_loop(sim, &SquareWave::new(volts, 0.2).unwrap(), 5.0)
}

const FREE: Options = Options {
    springs: SpringModel::Separate,
    coulomb: true,
    free_m2: true,
    ..Options::DEFAULT
};

fn percent(got: f64, want: f64) -> f64 {
    (got / want - 1.0) * 100.0
}

#[test]
fn a_motor_heavier_than_the_weighed_cart_is_found() {
    // 0.7 kg weighed, 0.15 kg of rotor inertia reflected through the
    // pinion.
    for (friction, seed) in [([1.0, 2.0], 3), ([0.5, 0.5], 4), ([2.0, 2.0], 5)] {
        let sim = rig(0.85, friction, seed);
        let rec = square_run(&sim);
        let t = sim.truth;
        let free = identify_with(&rec, 1.3, 0.7, &FREE).unwrap();
        let m2 = free.m2_estimate.unwrap();
        assert_eq!(free.m2, m2.value);
        assert_eq!(free.plant().m2, m2.value);
        let errors = [
            ("m2", percent(m2.value, t.m2)),
            ("K", percent(free.gain.value, t.gain)),
            ("b2", percent(free.b2.value, t.b2)),
            (
                "F2",
                percent(free.coulomb.unwrap()[1].value, friction[1]) / 10.0,
            ),
        ];
        println!(
            "F = {friction:?}: {errors:.2?} %, se(m2) {:.2} %",
            100.0 * m2.relative_error()
        );
        for (name, e) in errors {
            assert!(
                e.abs() < 1.0,
                "F = {friction:?}: {name} {e:+.2} % (F2 in tens of %)"
            );
        }
        assert!(m2.std_error > 0.0 && m2.relative_error() < 0.01, "{m2:?}");
        // With the weighed mass the gain and friction absorb the inertia.
        let weighed = Options {
            free_m2: false,
            ..FREE
        };
        let fixed = identify_with(&rec, 1.3, 0.7, &weighed).unwrap();
        assert_eq!((fixed.m2_estimate, fixed.m2), (None, 0.7));
        assert!(percent(fixed.gain.value, t.gain) > 5.0, "{:?}", fixed.gain);
    }
}

#[test]
fn free_mass_with_equal_springs_and_either_covariance() {
    let rec = Recording::read_csv(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/ident_square_wave.csv"
    ))
    .unwrap();
    let hac = identify_with(
        &rec,
        1.3,
        0.7,
        &Options {
            free_m2: true,
            ..Options::DEFAULT
        },
    )
    .unwrap();
    let classical = identify_with(
        &rec,
        1.3,
        0.7,
        &Options {
            free_m2: true,
            covariance: Covariance::Classical,
            ..Options::DEFAULT
        },
    )
    .unwrap();
    // The fixture's truth: m2 = 0.7 kg, K = 8.5 N/V, b2 = 6.1 N·s/m.
    let m2 = hac.m2_estimate.unwrap();
    assert!(percent(m2.value, 0.7).abs() < 0.5, "{m2:?}");
    assert!(percent(hac.gain.value, 8.5).abs() < 0.5, "{:?}", hac.gain);
    // The estimates do not depend on the covariance, bit for bit.
    assert_eq!(hac.second.theta, classical.second.theta);
    assert_eq!(hac.second.theta.len(), 3);
    // The classical errors: the normalised fit's, by the delta method;
    // both finite and of the size of the error.
    for e in [hac.m2_estimate.unwrap(), classical.m2_estimate.unwrap()] {
        assert!(e.std_error.is_finite() && e.std_error > 0.0 && e.relative_error() < 0.01);
    }
}
