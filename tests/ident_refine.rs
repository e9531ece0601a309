//! Validation by simulation and the output-error refinement, on the
//! simulated rig (Coulomb friction with stiction above it, PWM delay,
//! encoder quantisation and noise) over several truths: the refined model
//! reproduces a fresh run at least as well as the least-squares one, and
//! its parameters are within the bounds of the truth.

mod common;

use common::open_loop;
use ctrlab::lab::ident::{Options, identify_separate_springs_with, refine, validate};
use ctrlab::lab::{MassSpring, SimulatedRig};
use ctrlab::signal::{Prbs, SquareWave};
use ctrlab::{Error, Recording};

/// A 5 s run of the lab's square wave on `sim`, of force `8 + 2 F_max` N
/// (9 to 14 N; ±8 V is 8.9 N on the default motor): enough above the
/// friction for both carts to slide, within the ±50 mm travel.
fn square_run(sim: &SimulatedRig) -> Recording {
    let volts = (8.0 + 2.0 * sim.coulomb_friction[0].max(sim.coulomb_friction[1])) / sim.truth.gain;
    open_loop(sim, &SquareWave::new(volts, 0.2).unwrap(), 5.0)
}

/// The fresh run a model is validated on: another input, a PRBS (40 ms
/// clock) of the same force as [`square_run`].
fn prbs_run(sim: &SimulatedRig) -> Recording {
    let volts = (8.0 + 2.0 * sim.coulomb_friction[0].max(sim.coulomb_friction[1])) / sim.truth.gain;
    open_loop(sim, &Prbs::new(volts, 0.04, 7, 0x35).unwrap(), 5.0)
}

fn rig(gain: f64, friction: [f64; 2], seed: u64) -> SimulatedRig {
    SimulatedRig {
        truth: MassSpring {
            gain,
            ..SimulatedRig::default_truth()
        },
        coulomb_friction: friction,
        stiction: friction.map(|f| 1.2 * f),
        seed,
        ..SimulatedRig::default()
    }
}

#[test]
fn refinement_recovers_the_truth_and_validates_on_a_fresh_run() {
    let options = Options {
        coulomb: true,
        ..Options::default()
    };
    for (gain, friction) in [
        (1.11, [1.0, 2.0]),
        (0.8, [0.5, 0.5]),
        (2.0, [3.0, 3.0]),
        (1.5, [2.0, 1.0]),
    ] {
        let sim = rig(gain, friction, 7);
        let rec = square_run(&sim);
        let ls = identify_separate_springs_with(&rec, 1.3, 0.7, &options).unwrap();
        let r = refine(&rec, &ls).unwrap();
        let t = sim.truth;
        let err = |got: f64, want: f64| (got / want - 1.0) * 100.0;
        let errors = [
            ("k1", err(r.plant.k1, t.k1)),
            ("k2", err(r.plant.k2, t.k2)),
            ("b1", err(r.plant.b1, t.b1)),
            ("b2", err(r.plant.b2, t.b2)),
            ("K", err(r.plant.gain, t.gain)),
        ];
        let forces = [
            err(r.coulomb[0], friction[0]),
            err(r.coulomb[1], friction[1]),
        ];
        let ls_fit = validate(&prbs_run(&rig(gain, friction, 8)), &ls.plant(), {
            let c = ls.coulomb.unwrap();
            [c[0].value.max(0.0), c[1].value.max(0.0)]
        })
        .unwrap();
        let fresh = validate(&prbs_run(&rig(gain, friction, 8)), &r.plant, r.coulomb).unwrap();
        println!(
            "K = {gain}, F = {friction:?}: {errors:.2?}, F {forces:.1?} %; fit on its run {:.2?} → {:.2?} %, \
             on a fresh PRBS run LS {:.2?} / refined {:.2?} %, {} simulations; \
             whiteness {:.3} (bound {:.3}), independence {:.3}",
            r.start.fit_percent,
            r.refined.fit_percent,
            ls_fit.fit_percent,
            fresh.fit_percent,
            r.evaluations,
            fresh.whiteness.max_correlation,
            fresh.whiteness.bound,
            fresh.independence.max_correlation,
        );
        for (name, e) in errors {
            assert!(
                e.abs() < 1.0,
                "K = {gain}, F = {friction:?}: {name} {e:+.2} %"
            );
        }
        for e in forces {
            assert!(
                e.abs() < 10.0,
                "K = {gain}, F = {friction:?}: Coulomb {e:+.1} %"
            );
        }
        assert!(r.refined.fit_percent[1] >= r.start.fit_percent[1] - 1e-9);
        assert!(fresh.fit_percent[1] > 90.0 && fresh.fit_percent[0] > 80.0);
    }
}

#[test]
fn validation_refuses_what_it_cannot_simulate() {
    let rec = square_run(&rig(1.11, [1.0, 2.0], 1));
    let plant = SimulatedRig::default_truth();
    assert!(matches!(
        validate(&rec, &plant, [f64::NAN, 0.0]),
        Err(Error::InvalidParameter {
            name: "coulomb",
            ..
        })
    ));
    assert!(matches!(
        validate(&rec, &MassSpring { k1: -1.0, ..plant }, [0.0, 0.0]),
        Err(Error::InvalidParameter { .. })
    ));
    let short = Recording::from_columns(
        ctrlab::lab::schema(),
        rec.time()[..10].to_vec(),
        vec![
            rec.channel("u").unwrap()[..10].to_vec(),
            rec.channel("x1").unwrap()[..10].to_vec(),
            rec.channel("v1").unwrap()[..10].to_vec(),
            rec.channel("x2").unwrap()[..10].to_vec(),
            rec.channel("v2").unwrap()[..10].to_vec(),
        ],
    );
    if let Ok(short) = short {
        assert!(matches!(
            validate(&short, &plant, [0.0, 0.0]),
            Err(Error::InvalidParameter {
                name: "recording",
                ..
            })
        ));
    }
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(24))]
    /// Any plant and forces: no panic, and `Ok` holds finite figures.
    #[test]
    fn validation_never_panics_and_ok_is_finite(
        k1 in -1e4f64..1e7, k2 in 0.0f64..1e7, b1 in -1.0f64..1e4, b2 in 0.0f64..1e4,
        gain in -10.0f64..1e4, f1 in -1.0f64..1e3, f2 in 0.0f64..1e3,
    ) {
        static REC: std::sync::OnceLock<Recording> = std::sync::OnceLock::new();
        let rec = REC.get_or_init(|| square_run(&rig(1.11, [1.0, 2.0], 3)));
        let plant = MassSpring { k1, k2, b1, b2, gain, ..SimulatedRig::default_truth() };
        if let Ok(v) = validate(rec, &plant, [f1, f2]) {
            let figures = [v.fit_percent[0], v.fit_percent[1], v.rms_error[0], v.rms_error[1],
                           v.whiteness.max_correlation, v.independence.max_correlation];
            proptest::prop_assert!(figures.iter().all(|f| f.is_finite()), "{v:?}");
        }
    }
}
