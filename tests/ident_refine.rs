//! Validation by simulation and the output-error refinement, on the
//! simulated rig (Coulomb friction with stiction above it, PWM delay,
//! encoder quantisation and noise) over several truths: the refined model
//! reproduces a fresh run at least as well as the least-squares one, and
//! its parameters are within the bounds of the truth.

// Built on the two-cart lab (its plant, simulated rig or card).
#![cfg(feature = "lab")]

mod common;

use common::{friction_rig, open_loop, try_open_loop};
use ctrlab::hw::LoopFaultKind;
use ctrlab::lab::ident::{
    Bootstrap, MassSpringEstimate, Options, Refined, SimulationModel, SpringModel, bootstrap,
    identify_with, refine_with, validate, validate_with,
};
use ctrlab::lab::{CardSettings, MassSpring, SimulatedRig};
use ctrlab::signal::{Prbs, SquareWave};
use ctrlab::{Error, Recording};

/// A 5 s run of the lab's square wave on `sim`, of force `8 + 2 F_max` N
/// (9 to 14 N; ±8 V is 8.9 N on the default motor): enough above the
/// friction for both carts to slide, within the ±50 mm travel.
/// A truth whose springs and damping let cart 2 overshoot the travel at
/// that force gets the drive 10 % lower until the run stays within it.
fn square_run(sim: &SimulatedRig) -> Recording {
    let mut volts = volts(sim);
    loop {
        match try_open_loop(sim, &SquareWave::new(volts, 0.2).unwrap(), 5.0) {
            Err(e) if e.error.kind() == LoopFaultKind::TravelLimit && volts > 1.0 => volts *= 0.9,
            run => return run.unwrap(),
        }
    }
}

/// The runs' drive, V: `8 + 2 F_max` N on the default truth's springs,
/// scaled by their compliance over `sim`'s (cart 2's static deflection
/// stays that of the default springs: 20 % softer springs at the full
/// force overshoot the ±50 mm travel).
fn volts(sim: &SimulatedRig) -> f64 {
    let compliance = |p: &MassSpring| 1.0 / p.k1 + 1.0 / p.k2;
    let force = 8.0 + 2.0 * sim.friction.coulomb[0].max(sim.friction.coulomb[1]);
    force * compliance(&SimulatedRig::default_truth()) / compliance(&sim.truth) / sim.truth.gain
}

/// The fresh run a model is validated on: another input, a PRBS (40 ms
/// clock) of the same force as [`square_run`].
fn prbs_run(sim: &SimulatedRig) -> Recording {
    open_loop(sim, &Prbs::new(volts(sim), 0.04, 7, 0x35).unwrap(), 5.0)
}

fn rig(gain: f64, friction: [f64; 2], seed: u64) -> SimulatedRig {
    friction_rig(
        MassSpring {
            gain,
            ..SimulatedRig::default_truth()
        },
        friction,
        seed,
    )
}

/// Identifies `sim`'s square-wave run with Coulomb friction and refines
/// it: the estimate, the refined result and its errors against the truth,
/// % (k1, k2, b1, b2, K; then F1, F2).
fn refine_square_run(
    sim: &SimulatedRig,
) -> (MassSpringEstimate, Refined, [(&'static str, f64); 7]) {
    let options = Options {
        springs: SpringModel::Separate,
        coulomb: true,
        ..Options::default()
    };
    let rec = square_run(sim);
    let ls = identify_with(&rec, 1.3, 0.7, &options).unwrap();
    let r = refine_with(&rec, &ls, &sim.simulation_model()).unwrap();
    let (t, f) = (sim.truth, sim.friction.coulomb);
    let err = |got: f64, want: f64| (got / want - 1.0) * 100.0;
    let errors = [
        ("k1", err(r.plant.k1, t.k1)),
        ("k2", err(r.plant.k2, t.k2)),
        ("b1", err(r.plant.b1, t.b1)),
        ("b2", err(r.plant.b2, t.b2)),
        ("K", err(r.plant.gain, t.gain)),
        ("F1", err(r.coulomb[0], f[0])),
        ("F2", err(r.coulomb[1], f[1])),
    ];
    (ls, r, errors)
}

/// The bounds: k1, k2, b1, b2 and K within 1 %, the Coulomb forces
/// within 10 % of the truth.
fn within_bounds(errors: &[(&str, f64); 7]) -> bool {
    errors
        .iter()
        .enumerate()
        .all(|(i, (_, e))| e.abs() < if i < 5 { 1.0 } else { 10.0 })
}

#[test]
fn refinement_recovers_the_truth_and_validates_on_a_fresh_run() {
    for (gain, friction) in [
        (1.11, [1.0, 2.0]),
        (0.8, [0.5, 0.5]),
        (2.0, [3.0, 3.0]),
        (1.5, [2.0, 1.0]),
    ] {
        let sim = rig(gain, friction, 7);
        let (ls, r, errors) = refine_square_run(&sim);
        let model = sim.simulation_model();
        let prbs = prbs_run(&rig(gain, friction, 8));
        let c = ls.coulomb.unwrap();
        let ls_coulomb = [c[0].value.max(0.0), c[1].value.max(0.0)];
        let ls_fit = validate_with(&prbs, &ls.plant(), ls_coulomb, &model).unwrap();
        let fresh = validate_with(&prbs, &r.plant, r.coulomb, &model).unwrap();
        println!(
            "K = {gain}, F = {friction:?}: {errors:.2?} %; fit on its run {:.2?} → {:.2?} %, \
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
        assert!(
            within_bounds(&errors),
            "K = {gain}, F = {friction:?}: {errors:.2?} %"
        );
        assert!(r.refined.fit_percent[1] >= r.start.fit_percent[1] - 1e-9);
        assert!(fresh.fit_percent[1] > 90.0 && fresh.fit_percent[0] > 80.0);
    }
}

/// The card's structure reproduces the card: its truth, simulated from
/// the recorded input, is off the noise-free encoder readings by their
/// quantisation alone (one count is 9.77 µm; a uniform rounding error has
/// an RMS of 2.8 µm), on the square wave and on a PRBS. Without the delay,
/// without the stiction or at one step per sample, cart 2's error is
/// larger: measured 30×, 1.47× and 54× on the square wave, 23×, 3.0× and
/// 34× on the PRBS.
#[test]
fn the_cards_structure_reproduces_the_card_to_its_quantisation() {
    let mut sim = rig(1.11, [1.0, 2.0], 1);
    sim.card.encoder_noise = 0.0;
    let model = sim.simulation_model();
    let count = sim.metres_per_count();
    for rec in [square_run(&sim), prbs_run(&sim)] {
        let v = validate_with(&rec, &sim.truth, sim.friction.coulomb, &model).unwrap();
        println!("card's structure: RMS {:.3e} m", v.rms_error[1]);
        assert!(v.rms_error.iter().all(|e| *e < 0.35 * count), "{v:?}");
        for other in [
            SimulationModel {
                input_delay: 0.0,
                ..model
            },
            SimulationModel {
                stiction_ratio: [1.0; 2],
                ..model
            },
            SimulationModel {
                max_substep: 0.002,
                ..model
            },
        ] {
            let w = validate_with(&rec, &sim.truth, sim.friction.coulomb, &other).unwrap();
            println!("{other:?}: RMS {:.3e} m", w.rms_error[1]);
            assert!(w.rms_error[1] > 1.4 * v.rms_error[1], "{other:?}: {w:?}");
        }
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
    let model = SimulationModel::default();
    for (bad, field) in [
        (
            SimulationModel {
                input_delay: 0.002,
                ..model
            },
            "input_delay",
        ),
        (
            SimulationModel {
                input_delay: f64::NAN,
                ..model
            },
            "input_delay",
        ),
        (
            SimulationModel {
                max_substep: 1e-6,
                ..model
            },
            "max_substep",
        ),
        (
            SimulationModel {
                max_substep: -1.0,
                ..model
            },
            "max_substep",
        ),
        (
            SimulationModel {
                stiction_ratio: [1.0, f64::INFINITY],
                ..model
            },
            "stiction_ratio",
        ),
    ] {
        let got = validate_with(&rec, &plant, [0.0; 2], &bad);
        assert!(
            matches!(got, Err(Error::InvalidParameter { name, .. }) if name == field),
            "{bad:?}: {got:?}"
        );
    }
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

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig {
        cases: std::env::var("REFINE_CASES").ok().and_then(|c| c.parse().ok()).unwrap_or(8),
        max_shrink_iters: 16,
        ..proptest::prelude::ProptestConfig::default()
    })]
    /// Any plausible truth: motor gain 0.8–2 N/V, Coulomb forces 0.5–3 N
    /// (stiction 20 % above), springs and viscous frictions within ±20 % of
    /// the default truth, any noise seed: the refinement of the square-wave
    /// run, with the card's structure, meets the bounds. Prints each
    /// case's errors and the worst so far.
    ///
    /// 8 cases per run (`REFINE_CASES` sets more). Over 300 cases (release,
    /// 7 s) the worst errors were k1 0.10, k2 0.19, b1 0.44, b2 0.69,
    /// K 0.34, F1 0.59 and F2 2.98 %. With one integration step per 2 ms
    /// sample instead (stick decisions only at samples, no delay, no
    /// stiction) K was 1.26 % and F2 7.8 % high at K = 0.8 N/V.
    #[test]
    fn refinement_recovers_any_plausible_truth(
        gain in 0.8f64..2.0, f1 in 0.5f64..3.0, f2 in 0.5f64..3.0,
        k1 in 0.8f64..1.2, k2 in 0.8f64..1.2, b1 in 0.8f64..1.2, b2 in 0.8f64..1.2,
        seed in 0u64..1_000_000,
    ) {
        static WORST: std::sync::Mutex<[f64; 7]> = std::sync::Mutex::new([0.0; 7]);
        let d = SimulatedRig::default_truth();
        let truth = MassSpring {
            k1: k1 * d.k1, k2: k2 * d.k2, b1: b1 * d.b1, b2: b2 * d.b2, gain, ..d
        };
        let sim = friction_rig(truth, [f1, f2], seed);
        let (_, r, errors) = refine_square_run(&sim);
        if let Ok(mut worst) = WORST.lock() {
            for (w, (_, e)) in worst.iter_mut().zip(&errors) {
                *w = w.max(e.abs());
            }
            eprintln!(
                "{truth:?}, F [{f1:.2}, {f2:.2}] N, seed {seed}: {errors:.2?} %, {} simulations; \
                 worst so far (k1, k2, b1, b2, K, F1, F2) {:.2?} %",
                r.evaluations, *worst
            );
        }
        proptest::prop_assert!(within_bounds(&errors), "{truth:?}, F [{f1}, {f2}]: {errors:.2?} %");
    }
}

/// The bootstrap's standard errors on one run of the default card (lab5's
/// ±8 V square wave; seeded, so the same every time) are of the size of
/// the refined parameters' spread over 400 such seeded runs
/// (`ident_coverage`'s measurement: k1 0.0079, k2 0.0092, b1 0.040, b2
/// 0.053, K 0.041, F1 0.13, F2 0.20 % of the truth): within a factor of 3
/// either way with 8 resamples (measured on seeds 1–5: 0.46 to 1.97×);
/// sandwich standard errors from the Jacobian came out 2–9× below it.
/// Bad options are refused.
#[test]
fn bootstrap_errors_are_the_size_of_the_spread() {
    let sim = SimulatedRig {
        card: CardSettings {
            seed: 1,
            ..CardSettings::default()
        },
        // Off: the bootstrap against the refinement's own structure
        // (bounds measured without the unmodelled effects).
        unmodelled: ctrlab::lab::Unmodelled::NONE,
        ..SimulatedRig::default()
    };
    let options = Options {
        springs: SpringModel::Separate,
        coulomb: true,
        ..Options::default()
    };
    let rec = open_loop(&sim, &SquareWave::new(8.0, 0.2).unwrap(), 5.0);
    let ls = identify_with(&rec, 1.3, 0.7, &options).unwrap();
    let model = sim.simulation_model();
    let r = refine_with(&rec, &ls, &model).unwrap();
    let resampling = Bootstrap {
        resamples: 8,
        seed: 1,
        ..Bootstrap::default()
    };
    let se = bootstrap(&rec, &options, &r, &model, &resampling).unwrap();
    let (t, f) = (sim.truth, sim.friction.coulomb);
    let truth = [t.k1, t.k2, t.b1, t.b2, t.gain, f[0], f[1]];
    let relative: Vec<f64> = se
        .to_array()
        .iter()
        .zip(truth)
        .map(|(s, t)| s / t)
        .collect();
    let spread = [7.9e-5, 9.2e-5, 4.0e-4, 5.3e-4, 4.1e-4, 1.3e-3, 2.0e-3];
    let ratios: Vec<f64> = relative.iter().zip(spread).map(|(s, w)| s / w).collect();
    println!(
        "bootstrap se / spread: {ratios:.2?}, {} simulations",
        se.evaluations
    );
    assert!(
        ratios.iter().all(|r| (1.0 / 3.0..3.0).contains(r)),
        "{ratios:?}"
    );
    let n = rec.len();
    for (bad, name) in [
        (
            Bootstrap {
                resamples: 1,
                ..resampling
            },
            "resamples",
        ),
        (
            Bootstrap {
                resamples: 1001,
                ..resampling
            },
            "resamples",
        ),
        (
            Bootstrap {
                block: 0,
                ..resampling
            },
            "block",
        ),
        (
            Bootstrap {
                block: n + 1,
                ..resampling
            },
            "block",
        ),
    ] {
        let got = bootstrap(&rec, &options, &r, &model, &bad);
        assert!(
            matches!(got, Err(Error::InvalidParameter { name: n, .. }) if n == name),
            "{bad:?}: {got:?}"
        );
    } // A refined model that is not one: an error naming it, not a panic.
    let mut broken = r;
    broken.plant.k1 = f64::NAN;
    let got = bootstrap(&rec, &options, &broken, &model, &resampling);
    assert!(
        matches!(got, Err(Error::InvalidParameter { name: "k1", .. })),
        "{got:?}"
    );
    broken = r;
    broken.coulomb[1] = -1.0;
    let got = bootstrap(&rec, &options, &broken, &model, &resampling);
    assert!(
        matches!(
            got,
            Err(Error::InvalidParameter {
                name: "coulomb",
                ..
            })
        ),
        "{got:?}"
    );
}
