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
use ctrlab::hw::{
    Clock, ConfigErrorKind, LoopConfig, LoopFault, LoopStats, Pc104, PortError, RigError, RunError,
    VirtualClock,
};
use ctrlab::lab::ident::{Summary, summarize};
use ctrlab::lab::ident_input::{
    AmplitudeChoice, AmplitudeSearch, IdentInput, IdentRuns, IdentSignal, PROBE_DURATION,
    ProbeFault, ProbeOutcome, Reason, RunFault, peaks,
};
use ctrlab::lab::protocol::{IDENT_DURATION, IDENT_RUNS, PERIOD};
use ctrlab::lab::{Calibration, CardSettings, FileError, RigConfig, SimulatedRig, Unmodelled};
use ctrlab::nalgebra::vector;
use ctrlab::signal::Signal;

/// `sim` with noise seed `seed` at the lab's period, as lab5's backend
/// runs each experiment.
fn with_seed(sim: &SimulatedRig, seed: u64) -> SimulatedRig {
    SimulatedRig {
        card: CardSettings { seed, ..sim.card },
        period: PERIOD,
        ..sim.clone()
    }
}

/// [`common::lighter`] with the unmodelled effects off: the amplitude
/// search's machinery on a rig the test sets; its bounds were measured
/// without them.
fn lighter() -> SimulatedRig {
    SimulatedRig {
        unmodelled: Unmodelled::NONE,
        ..common::lighter()
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
            ProbeOutcome::of(run(sim, 100 + n, ident, volts, PROBE_DURATION))
                .map_err(|e| Box::new(e) as Box<dyn std::error::Error>)
        })
        .unwrap()
}

/// lab5's identification runs at `volts`: seeds 1 to 5.
fn ident_runs(sim: &SimulatedRig, ident: &IdentInput, volts: f64) -> IdentRuns {
    IdentRuns::collect(1..=IDENT_RUNS, |seed| {
        Ok::<_, Box<RunFault>>(run(sim, seed, ident, volts, IDENT_DURATION))
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
        Ok::<_, Box<RunFault>>(run(&sim, seed, &ident, volts, IDENT_DURATION))
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
        Ok::<_, Box<RunFault>>(run(&sim, seed, &ident, 8.0, IDENT_DURATION))
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

// ---- review fixes: halted probes, faults in the runs, the drive's range ----

/// `sim`'s card with cart 2's encoder read from counter 2, which the card
/// leaves unconnected (a dead encoder), an open-loop run of `input`.
fn dead_encoder_run(
    sim: &SimulatedRig,
    seed: u64,
    input: &dyn Signal,
    duration: f64,
) -> Result<Recording, Box<RunError>> {
    let sim = with_seed(sim, seed);
    let clock = Clock::Virtual(VirtualClock::new());
    let card = Pc104::with_map(sim.card(&clock).unwrap(), sim.card.map).unwrap();
    let cal = Calibration {
        encoder_channels: [0, 2],
        ..sim.calibration
    };
    let rig = ctrlab::lab::MassSpringRig::with_clock(card, cal, sim.period, clock.clone()).unwrap();
    let config = LoopConfig {
        duration,
        ..LoopConfig::default()
    };
    ctrlab::hw::run(
        rig,
        ctrlab::OpenLoop,
        |t| vector![input.value(t)],
        &clock,
        &config,
    )
    .map(|out| out.recording)
}

#[test]
fn a_probe_the_rig_halts_at_the_travel_limit_lowers_the_amplitude_and_is_not_a_measurement() {
    // The lighter rig with cart 2's limit at 4 mm: the first probe (2 V)
    // runs into it. The old search took its peaks up to the halt as a
    // measurement (Reason::Scaled, "predicted"); now it is the answer that
    // the amplitude must come down, said so.
    let sim = SimulatedRig {
        calibration: Calibration {
            travel_limits: [0.05, 0.004],
            ..Calibration::default()
        },
        ..lighter()
    };
    let ident = IdentInput::default();
    let choice = choose(&sim, &ident);
    let halted = choice
        .halted
        .expect("the first probe halts at cart 2's 4 mm");
    assert_eq!(halted.volts, 2.0);
    assert!(choice.probes.is_empty(), "no probe after the halt");
    assert_eq!(choice.reason, Reason::Halted { cart: 1 });
    assert!(
        choice.predicted.is_none(),
        "nothing completed to predict from"
    );
    // In proportion to what it reached (at least the limit, as the fault
    // says: the read past it is not recorded): below 60 % of the probe's
    // volts.
    assert!(halted.peaks[1] > 0.004, "{:?}", halted.peaks);
    let ceiling = 2.0 * 0.6 * 0.004 / halted.peaks[1];
    assert!(
        choice.volts <= ceiling && choice.volts > ceiling - 0.01,
        "{}",
        choice.volts
    );
    assert!(choice.volts < 0.6 * halted.volts);
    println!(
        "halted probe: {:.2} V reached {:.2} mm; chosen {:.2} V",
        halted.volts,
        halted.peaks[1] * 1e3,
        choice.volts
    );
    assert!(choice.reason.to_string().contains("not a prediction"));
}

#[test]
fn a_probe_halted_by_a_dead_encoder_stops_before_identification_with_the_fault_named() {
    // Cart 2's encoder dead on the lighter rig: the first probe (2 V,
    // which moves the carts there) is halted by EncoderNotFollowing, and
    // the search stops, naming it, instead of taking cart 2's 0 mm as a
    // peak (which would have let the amplitude rise to what cart 1 alone
    // allows).
    let sim = lighter();
    let ident = IdentInput::default();
    let mut n = 0;
    let err = AmplitudeSearch::new(ident.volts, sim.calibration.travel_limits)
        .unwrap()
        .run(|volts| {
            n += 1;
            let input = ident.input(volts, IDENT_DURATION).unwrap();
            Ok::<_, ProbeFault>(
                ProbeOutcome::of(dead_encoder_run(&sim, 100 + n, &input, PROBE_DURATION)).unwrap(),
            )
        })
        .unwrap_err();
    assert_eq!((err.number, err.volts), (1, 2.0));
    assert!(
        matches!(
            err.error,
            RigError::Fault(LoopFault::EncoderNotFollowing { cart: 2, .. })
        ),
        "{}",
        err.error
    );
    let text = err.to_string();
    assert!(
        text.contains("probe run 1 at 2.00 V") && text.contains("encoder of cart 2"),
        "{text}"
    );
}

/// A run the rig halted with `error`.
fn halted_with(error: RigError) -> Box<RunError> {
    Box::new(RunError {
        error,
        recording: Recording::new(ctrlab::lab::schema()),
        last_measurement: None,
        stats: LoopStats::default(),
    })
}

#[test]
fn ident_runs_go_on_only_after_a_travel_limit_or_saturation() {
    let too_big = [
        LoopFault::TravelLimit {
            axis: 2,
            position: 0.0501,
            limit: 0.05,
        },
        LoopFault::Saturated {
            volts: 24.0,
            seconds: 2.0,
            limit: 2.0,
        },
    ];
    for fault in too_big {
        let mut made = Vec::new();
        let runs = IdentRuns::collect(1..=3, |seed| {
            made.push(seed);
            Ok::<_, Box<RunFault>>(if seed == 2 {
                Err(halted_with(RigError::Fault(fault.clone())))
            } else {
                Ok(Recording::new(ctrlab::lab::schema()))
            })
        })
        .unwrap();
        assert_eq!(made, [1, 2, 3], "{fault}");
        assert_eq!(runs.halted.len(), 1);
    }
    let not_the_input: Vec<RigError> = vec![
        RigError::Fault(LoopFault::BusFault {
            channel: 1,
            counts: 900,
            interval: 0.002,
            speed: 4.4,
            limit: 2.0,
        }),
        RigError::Fault(LoopFault::EncoderNotFollowing {
            cart: 2,
            channel: 2,
            other: 1,
            volts: 2.0,
            seconds: 0.5,
            moved: 120,
            counts: 3,
        }),
        RigError::Fault(LoopFault::NotResponding {
            volts: 6.0,
            seconds: 0.5,
            counts: 3,
        }),
        RigError::Fault(LoopFault::Gap {
            what: "the time since the last watchdog kick",
            gap: 0.2,
            limit: 0.1,
            at: 1.0,
        }),
        RigError::Fault(LoopFault::Interrupted { at: 1.0 }),
        RigError::Fault(LoopFault::Panicked {
            what: "controller",
            message: "boom".into(),
            at: 1.0,
        }),
        RigError::Port(PortError::InvalidCommand {
            what: "voltage",
            channel: Some(0),
            value: f64::NAN,
            limit: 24.0,
        }),
    ];
    for error in not_the_input {
        let name = error.to_string();
        let mut error = Some(error);
        let mut made = Vec::new();
        let err = IdentRuns::collect(1..=3, |seed| {
            made.push(seed);
            Ok::<_, Box<RunFault>>(if seed == 2 {
                Err(halted_with(error.take().unwrap()))
            } else {
                Ok(Recording::new(ctrlab::lab::schema()))
            })
        })
        .unwrap_err();
        assert_eq!((err.seed, made), (2, vec![1, 2]), "{name}");
        assert_eq!(err.error.to_string(), name);
        assert!(
            err.to_string()
                .starts_with("identification run 2 was halted"),
            "{err}"
        );
    }
}

#[test]
fn ident_volts_above_the_drive_full_scale_are_refused_in_code_and_card_file() {
    let cal = Calibration::default();
    let over = IdentInput {
        volts: cal.volts_full_scale + 0.5,
        ..IdentInput::default()
    };
    assert!(over.validate().is_ok(), "within 1000 V on its own");
    let err = over.check_drive(cal.volts_full_scale).unwrap_err();
    assert_eq!(
        (err.kind(), err.key()),
        (ConfigErrorKind::Conflict, "volts")
    );
    assert!(err.to_string().contains("volts_full_scale"), "{err}");
    let at = IdentInput {
        volts: cal.volts_full_scale,
        ..IdentInput::default()
    };
    assert!(at.check_drive(cal.volts_full_scale).is_ok());
    // The card file: [ident] volts = 24.5 on a 24 V drive.
    let text = RigConfig::new(Default::default(), cal).to_toml();
    let err = RigConfig::from_toml(&format!("{text}\n[ident]\nvolts = 24.5\n")).unwrap_err();
    let FileError::Invalid { error, .. } = err else {
        panic!("{err}")
    };
    assert_eq!(error, over.check_drive(24.0).unwrap_err().in_table("ident"));
    assert_eq!(error.key(), "ident.volts");
    // A 12 V drive refuses the lab's default 8 V? No: 8 V is within it;
    // 12.5 V is not.
    let small = Calibration {
        volts_full_scale: 12.0,
        ..cal
    };
    let config = RigConfig {
        ident: IdentInput {
            volts: 12.5,
            ..IdentInput::default()
        },
        ..RigConfig::new(Default::default(), small)
    };
    assert_eq!(config.validate().unwrap_err().key(), "ident.volts");
}
