//! The identification input that respects the rig (`lab::ident_input`),
//! run as lab5 runs it: two probe runs of the square wave, the amplitude
//! chosen so that the predicted peak of either cart is at most 60 % of its
//! travel, then the five identification runs at it, identified
//! (`lab::ident::summarize`). On the default rig and on a plausible
//! lighter-damped rig where the lab's fixed ±8 V square wave hits the end
//! stops.
//!
//! The numbers quoted are measured (virtual clock, deterministic seeds);
//! the slack on "at most 60 %" is the prediction's measured error.

// Built on the two-cart lab (its plant, simulated rig or card).
#![cfg(feature = "lab")]

mod common;

use common::try_open_loop;
use ctrlab::Recording;
use ctrlab::hw::{LoopFault, RigError};
use ctrlab::lab::ident::{Summary, summarize};
use ctrlab::lab::ident_input::{
    AmplitudeChoice, AmplitudeSearch, IdentInput, IdentRuns, IdentSignal, PROBE_DURATION, Reason,
    peaks,
};
use ctrlab::lab::protocol::{IDENT_DURATION, IDENT_RUNS, PERIOD};
use ctrlab::lab::{
    Calibration, CardSettings, FileError, Friction, MassSpring, RigConfig, SimulatedRig, Unmodelled,
};

/// `sim` with noise seed `seed` at the lab's period, as lab5's backend
/// runs each experiment.
fn with_seed(sim: &SimulatedRig, seed: u64) -> SimulatedRig {
    SimulatedRig {
        card: CardSettings { seed, ..sim.card },
        period: PERIOD,
        ..sim.clone()
    }
}

/// A plausible rig with less damping than the default: cart 2 at 0.9 kg
/// with the motor's rotor, b1 = 5 and b2 = 4 N·s/m, K = 1.2 N/V, Coulomb
/// friction 0.5 / 1 N (breakaway 1.2 × that, as the default's).
fn lighter() -> SimulatedRig {
    SimulatedRig {
        truth: MassSpring {
            m2: 0.9,
            b1: 5.0,
            b2: 4.0,
            gain: 1.2,
            ..SimulatedRig::default_truth()
        },
        friction: Friction {
            coulomb: [0.5, 1.0],
            stiction: [0.6, 1.2],
        },
        // Off: the amplitude search's machinery on a rig the test sets;
        // its bounds were measured without them.
        unmodelled: Unmodelled::NONE,
        ..SimulatedRig::default()
    }
}

/// One open-loop run of `ident`'s signal at `volts` for `duration` s
/// (the signal built for a whole run, as lab5 builds the probes'): the
/// recording, or the loop's error with what it recorded.
fn run(
    sim: &SimulatedRig,
    seed: u64,
    ident: &IdentInput,
    volts: f64,
    duration: f64,
) -> Result<Recording, Box<ctrlab::hw::RunError>> {
    let input = ident.input(volts, IDENT_DURATION).unwrap();
    try_open_loop(&with_seed(sim, seed), &input, duration)
}

/// lab5's amplitude choice: probes on seeds 101 and 102.
fn choose(sim: &SimulatedRig, ident: &IdentInput) -> AmplitudeChoice {
    let mut n = 0;
    AmplitudeSearch::new(ident.volts, sim.calibration.travel_limits)
        .unwrap()
        .run(|volts| {
            n += 1;
            let rec =
                run(sim, 100 + n, ident, volts, PROBE_DURATION).unwrap_or_else(|e| e.recording);
            peaks(&rec)
        })
        .unwrap()
}

/// lab5's identification runs at `volts`: seeds 1 to 5.
fn ident_runs(sim: &SimulatedRig, ident: &IdentInput, volts: f64) -> IdentRuns {
    IdentRuns::collect(1..=IDENT_RUNS, |seed| {
        Ok::<_, ()>(run(sim, seed, ident, volts, IDENT_DURATION))
    })
    .unwrap()
}

/// Relative error.
fn rel(got: f64, want: f64) -> f64 {
    (got / want - 1.0).abs()
}

/// The bounds `tests/lab_identification.rs` holds lab5's identification
/// to on the default rig: the separate-springs model's k1, k2, K and b2
/// within 0.5 %, the Coulomb forces within 5 %; here with the rig's own
/// (weighed) masses.
fn assert_usual_bounds(s: &Summary, sim: &SimulatedRig) {
    let (m, t) = (s.model(), sim.truth);
    for (name, got, want) in [
        ("k1", m.k1, t.k1),
        ("k2", m.k2, t.k2),
        ("K", m.gain, t.gain),
        ("b2", m.b2, t.b2),
    ] {
        assert!(rel(got, want) < 0.005, "{name}: {got} against {want}");
    }
    for (c, (got, want)) in s
        .coulomb()
        .into_iter()
        .zip(sim.friction.coulomb)
        .enumerate()
    {
        assert!(rel(got, want) < 0.05, "F{}: {got} against {want}", c + 1);
    }
}

/// Every completed run's peaks within `slack` × the allowed 60 %, and the
/// limiting cart's peak within 3 % of its prediction.
fn assert_within_travel(choice: &AmplitudeChoice, runs: &IdentRuns, slack: f64) {
    let allowed = choice.allowed();
    let predicted = choice.predicted.unwrap();
    for run in &runs.completed {
        let p = peaks(&run.recording).unwrap();
        for c in 0..2 {
            assert!(
                p[c] <= allowed[c] * slack,
                "run {} cart {}: {} mm against {} mm",
                run.seed,
                c + 1,
                p[c] * 1e3,
                allowed[c] * 1e3
            );
        }
        if let Reason::Scaled { cart } = choice.reason {
            assert!(
                rel(p[cart], predicted[cart]) < 0.03,
                "run {}: {} mm predicted {} mm",
                run.seed,
                p[cart] * 1e3,
                predicted[cart] * 1e3
            );
        }
    }
}

#[test]
fn the_default_rig_lowers_8_v_to_keep_cart_2_within_60_percent_of_its_travel() {
    // The default rig without its unmodelled effects, on which the numbers
    // below were measured: the amplitude search's own case. With them on
    // (the default now) 8 V fits: the 0.3 V deadband and the rotor's
    // 0.06 kg keep cart 2 within 30 mm, and the search keeps 8 V
    // (`Reason::Fits`; lab_unmodelled's scan prints the volts chosen).
    let sim = SimulatedRig {
        unmodelled: Unmodelled::NONE,
        ..SimulatedRig::default()
    };
    let on = choose(&SimulatedRig::default(), &IdentInput::default());
    assert_eq!((on.reason, on.volts), (Reason::Fits, 8.0));
    let ident = IdentInput::default();
    let choice = choose(&sim, &ident);
    // The 2 V probe does not break cart 2 free (2.2 N against 2.4 N of
    // breakaway: one count of noise); the 4 V probe moves it 10.64 mm. The
    // line through both extrapolates 31.9 mm at 8 V, which the fixed
    // input's run measures 31.42 mm (+1.6 %); 60 % of 50 mm is 30 mm:
    // 7.640 V.
    assert_eq!(choice.reason, Reason::Scaled { cart: 1 });
    assert_eq!(choice.probes.len(), 2);
    assert!(choice.probes[0].peaks[1] < 2e-5, "{:?}", choice.probes);
    assert!((7.6..7.7).contains(&choice.volts), "{}", choice.volts);
    let at_8 = peaks(&run(&sim, 1, &ident, 8.0, IDENT_DURATION).unwrap()).unwrap();
    let predicted_8 = choice.predicted_asked.unwrap();
    assert!(
        rel(predicted_8[1], at_8[1]) < 0.03,
        "{predicted_8:?} {at_8:?}"
    );
    assert!(at_8[1] > choice.allowed()[1], "8 V takes cart 2 past 30 mm");

    // Every run completes; cart 2 peaks at 29.60 mm (98.7 % of the 30 mm
    // allowed, −1.3 % from its prediction; cart 1 at 19.84 mm, +8 % from
    // its 18.38 mm, well inside). Slack: 1 %.
    let runs = ident_runs(&sim, &ident, choice.volts);
    assert_eq!((runs.completed.len(), runs.halted.len()), (5, 0));
    assert_within_travel(&choice, &runs, 1.01);
    // Measured: k1 +0.05 %, k2 −0.02 %, K +0.19 %, b2 −0.18 %, F1 +1.6 %,
    // F2 +1.4 %: the usual bounds hold at the lower amplitude.
    let s = summarize(runs.recordings(), sim.truth.m1, sim.truth.m2).unwrap();
    assert_usual_bounds(&s, &sim);
}

#[test]
fn on_the_lighter_damped_rig_8_v_hits_the_travel_limit_and_the_chosen_amplitude_does_not() {
    let sim = lighter();
    let ident = IdentInput::default();
    // The lab's fixed input: both carts swing past ±50 mm within 0.54 s.
    let err = run(&sim, 1, &ident, 8.0, IDENT_DURATION).unwrap_err();
    assert!(
        matches!(err.error, RigError::Fault(LoopFault::TravelLimit { .. })),
        "{err}"
    );
    assert!(err.error.to_string().contains("travel limit"), "{err}");

    // Probes: 9.06 mm at 2 V, 25.12 mm at 4 V (8.0 mm/V through both);
    // 60 % of the travel: 4.608 V, rounded down to 4.60 V, for cart 2.
    let choice = choose(&sim, &ident);
    assert_eq!(choice.reason, Reason::Scaled { cart: 1 });
    assert!((4.5..4.7).contains(&choice.volts), "{}", choice.volts);
    let runs = ident_runs(&sim, &ident, choice.volts);
    assert_eq!((runs.completed.len(), runs.halted.len()), (5, 0));
    // Cart 2 peaks at 29.91 mm (99.7 % of the 30 mm allowed, −0.3 % from
    // its prediction), cart 1 at 23.71 mm (−0.6 %). Slack: 1 %.
    assert_within_travel(&choice, &runs, 1.01);
    // With the rig's weighed masses (m2 = 0.9 kg). Measured: k1 −0.01 %,
    // k2 +0.01 %, b1 +0.16 %, b2 +0.12 %, K +0.33 %, F1 −0.3 %, F2 +2.2 %.
    let s = summarize(runs.recordings(), sim.truth.m1, sim.truth.m2).unwrap();
    assert_usual_bounds(&s, &sim);
}

#[test]
fn prbs_and_multisine_on_the_lighter_rig_stay_within_the_travel_with_the_measured_slack() {
    let sim = lighter();
    // Measured: the PRBS at 5.73 V peaks at 30.75 mm on cart 2 (102.5 %
    // of the 30 mm allowed: its largest excursion comes from a bit pattern
    // the probes at 2 and 4 V meet less squarely), the multisine at
    // 6.50 V at 29.66 mm (98.9 %). Slack: 3 %.
    for (signal, volts) in [(IdentSignal::Prbs, 5.73), (IdentSignal::Multisine, 6.50)] {
        let ident = IdentInput {
            signal,
            ..IdentInput::default()
        };
        let choice = choose(&sim, &ident);
        assert_eq!(choice.reason, Reason::Scaled { cart: 1 }, "{signal}");
        assert!(
            (choice.volts - volts).abs() < 0.05,
            "{signal}: {}",
            choice.volts
        );
        let runs = ident_runs(&sim, &ident, choice.volts);
        assert_eq!(runs.completed.len(), 5, "{signal}");
        assert_within_travel(&choice, &runs, 1.03);
    }
}

#[test]
fn runs_the_rig_halts_are_reported_and_the_others_identify() {
    let sim = lighter();
    let ident = IdentInput::default();
    let choice = choose(&sim, &ident);
    // Runs 2 and 4 are forced too far: at the lab's fixed 8 V. The others
    // at the chosen amplitude.
    let runs = IdentRuns::collect(1..=IDENT_RUNS, |seed| {
        let volts = if seed % 2 == 0 { 8.0 } else { choice.volts };
        Ok::<_, ()>(run(&sim, seed, &ident, volts, IDENT_DURATION))
    })
    .unwrap();
    let halted: Vec<u64> = runs.halted.iter().map(|h| h.seed).collect();
    let completed: Vec<u64> = runs.completed.iter().map(|r| r.seed).collect();
    assert_eq!((halted, completed), (vec![2, 4], vec![1, 3, 5]));
    for h in &runs.halted {
        assert!(
            h.error.to_string().contains("beyond its travel limit"),
            "{}",
            h.error
        );
        // What it recorded up to the fault: about half a second.
        let t = *h.recording.time().last().unwrap();
        assert!((0.3..1.0).contains(&t), "{t}");
    }
    assert!(runs.enough().is_ok());
    let s = summarize(runs.recordings(), sim.truth.m1, sim.truth.m2).unwrap();
    assert_eq!(s.average.runs, 3);
    assert_usual_bounds(&s, &sim);

    // All five forced: nothing to average, and the error says why.
    let none = IdentRuns::collect(1..=IDENT_RUNS, |seed| {
        Ok::<_, ()>(run(&sim, seed, &ident, 8.0, IDENT_DURATION))
    })
    .unwrap();
    let err = none.enough().unwrap_err();
    assert_eq!((err.completed, err.total, err.halted.len()), (0, 5, 5));
    let text = err.to_string();
    assert!(
        text.starts_with("only 0 of 5 identification runs completed")
            && text.contains("run 3: ")
            && text.contains("travel limit"),
        "{text}"
    );
}

#[test]
fn a_fixed_input_is_not_probed_and_the_card_file_checks_ident_as_code_does() {
    let fixed = AmplitudeChoice::fixed(12.0, Calibration::default().travel_limits);
    assert_eq!((fixed.volts, fixed.reason), (12.0, Reason::Fixed));
    assert!(fixed.probes.is_empty());

    let text = RigConfig::new(Default::default(), Calibration::default()).to_toml();
    assert!(!text.contains("[ident]"), "the default is not written");
    for (key, value, code) in [
        (
            "volts",
            "0.0",
            IdentInput {
                volts: 0.0,
                ..IdentInput::default()
            },
        ),
        (
            "half_period",
            "0.001",
            IdentInput {
                half_period: 0.001,
                ..IdentInput::default()
            },
        ),
    ] {
        let err = RigConfig::from_toml(&format!("{text}\n[ident]\n{key} = {value}\n")).unwrap_err();
        let FileError::Invalid { error, line, .. } = err else {
            panic!("{err}")
        };
        let code = code.validate().unwrap_err().in_table("ident");
        assert_eq!(error, code);
        assert!(line.is_some());
    }
    let typo = RigConfig::from_toml(&format!("{text}\n[ident]\nvolt = 4.0\n")).unwrap_err();
    assert_eq!(typo.key(), Some("ident.volt"));
    // A card file with an input of its own reads back equal.
    let config = RigConfig {
        ident: IdentInput {
            signal: IdentSignal::Multisine,
            volts: 5.0,
            half_period: 0.25,
            scale_to_travel: false,
        },
        ..RigConfig::new(Default::default(), Calibration::default())
    };
    let text = config.to_toml();
    assert!(
        text.contains("[ident]") && text.contains("signal = \"multisine\""),
        "{text}"
    );
    assert_eq!(RigConfig::from_toml(&text).unwrap(), config);
}
