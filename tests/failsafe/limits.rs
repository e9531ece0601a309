//! The drive's limit in time, and a card without a watchdog.

use super::*;

// ---- the drive's limit -------------------------------------------------------------

/// The realistic rig with stiff springs: full drive deflects cart 2 by a
/// couple of millimetres (a cart held against an end stop, say), so a
/// saturated drive can last.
fn stiff() -> SimulatedRig {
    SimulatedRig {
        truth: MassSpring {
            k1: 2e4,
            k2: 2e4,
            ..SimulatedRig::default_truth()
        },
        ..SimulatedRig::default()
    }
}

#[test]
fn time_at_the_drive_limit_is_bounded() {
    let sim = stiff();
    let cal = sim.calibration;
    assert_eq!(cal.max_saturation_time, 2.0, "the default");
    let clock = VirtualClock::new();
    let mut rig = sim.rig(&Clock::Virtual(clock.clone())).unwrap();
    // 30 V asked, 24 V applied: at the limit from tick 0.
    let err = run(
        &mut rig,
        OpenLoop,
        |_| vector![30.0],
        &Clock::Virtual(clock.clone()),
        &config(3.0),
    )
    .unwrap_err();
    assert_eq!(err.error.kind(), LoopFaultKind::Saturated);
    match err.error {
        RigError::Fault(LoopFault::Saturated {
            volts,
            seconds,
            limit,
        }) => {
            assert_eq!((volts, limit), (24.0, 2.0));
            assert!((seconds - 2.0).abs() < 1e-9, "{seconds}");
        }
        ref other => panic!("expected Saturated, got {other:?}"),
    }
    let text = err.error.to_string();
    assert!(
        text.contains("at its limit") && text.contains("max_saturation_time"),
        "{text}"
    );
    // Ticks 0–999 applied 24 V; tick 1000 (2 s after the first) was read,
    // and its command refused.
    assert_recorded(&err, 1000, 1.998);
    assert!(err.last_measurement.is_some());
    assert!(
        err.recording
            .channel("u")
            .unwrap()
            .iter()
            .all(|u| *u == 24.0)
    );
    assert_every_channel_off(&mut rig, &clock);

    // Configurable: with 5 s allowed, the same 3 s run completes.
    let patient = SimulatedRig {
        calibration: Calibration {
            max_saturation_time: 5.0,
            ..cal
        },
        ..stiff()
    };
    let clock = VirtualClock::new();
    let rig = patient.rig(&Clock::Virtual(clock.clone())).unwrap();
    let out = run(
        rig,
        OpenLoop,
        |_| vector![30.0],
        &Clock::Virtual(clock),
        &config(3.0),
    )
    .unwrap();
    assert_eq!(out.recording.len(), 1500);

    // Below the limit is not at it: 23 V for 3 s runs through.
    let clock = VirtualClock::new();
    let rig = stiff().rig(&Clock::Virtual(clock.clone())).unwrap();
    let out = run(
        rig,
        OpenLoop,
        |_| vector![23.0],
        &Clock::Virtual(clock),
        &config(3.0),
    )
    .unwrap();
    assert_eq!(out.recording.len(), 1500);
}

#[test]
fn leaving_the_limit_restarts_the_count() {
    // 1.5 s at +24 V, 0.1 s at 12 V, 1.5 s at +24 V: never 2 s at the limit
    // in one go.
    let clock = VirtualClock::new();
    let rig = stiff().rig(&Clock::Virtual(clock.clone())).unwrap();
    let reference = |t: f64| {
        if (1.5..1.6).contains(&t) {
            vector![12.0]
        } else {
            vector![30.0]
        }
    };
    let out = run(
        rig,
        OpenLoop,
        reference,
        &Clock::Virtual(clock),
        &config(3.1),
    )
    .unwrap();
    assert_eq!(out.recording.len(), 1550);
}

// ---- a card without a watchdog -------------------------------------------------------

/// A card file for the simulated card, which has no watchdog.
fn no_watchdog() -> (SimulatedRig, RigConfig) {
    let sim = SimulatedRig {
        calibration: Calibration {
            watchdog_timeout: None,
            ..Calibration::default()
        },
        ..SimulatedRig::default()
    };
    let file = RigConfig::new(sim.card.map, sim.calibration);
    (sim, file)
}

#[test]
fn a_card_without_a_watchdog_is_refused_unless_acknowledged() {
    let (sim, file) = no_watchdog();
    // The file describes the card: it loads.
    let text = file.to_toml();
    assert!(text.contains("watchdog_timeout = \"none\""), "{text}");
    assert!(text.contains("no_watchdog_acknowledged = false"), "{text}");
    let loaded = RigConfig::from_toml(&text).unwrap();
    // Building the rig from it is refused, before a single bus cycle, with
    // what to add.
    let mut port = RecordingPort::new(sim.card(&Clock::RealTime).unwrap());
    let err = loaded.rig(&mut port, PERIOD).unwrap_err();
    assert_eq!(err.kind(), ConfigErrorKind::Conflict);
    match &err {
        RigError::Config(e) => assert_eq!(e.key(), "calibration.no_watchdog_acknowledged"),
        other => panic!("expected a ConfigError, got {other:?}"),
    }
    let text_of_err = err.to_string();
    assert!(
        text_of_err.contains("no watchdog")
            && text_of_err.contains("add `no_watchdog_acknowledged = true` under [calibration]")
            && text_of_err.contains("--no-watchdog-acknowledged"),
        "{text_of_err}"
    );
    assert!(port.log().is_empty(), "{:?}", port.log());
    // The same from code as from the file.
    assert_eq!(
        format!("{:?}", file.rig(&mut port, PERIOD).unwrap_err()),
        format!("{err:?}")
    );

    // Acknowledged in the file: built (the ID probed, nothing written).
    let acknowledged = text.replace(
        "no_watchdog_acknowledged = false",
        "no_watchdog_acknowledged = true",
    );
    let loaded = RigConfig::from_toml(&acknowledged).unwrap();
    assert!(loaded.calibration.no_watchdog_acknowledged);
    let rig = loaded.rig(&mut port, PERIOD).unwrap();
    assert_eq!(rig.watchdog_timeout(), None);
    drop(rig);
    assert_eq!(
        &port.log()[..2],
        &[Cycle::AddressWrite(0x00), Cycle::DataRead(0xa5)]
    );
    // The acknowledgement and the missing watchdog are what the rig's
    // summary says.
    assert!(
        loaded.to_string().contains("acknowledged"),
        "{}",
        loaded.to_string()
    );
    // A card with a watchdog needs no acknowledgement.
    let with_watchdog = RigConfig::new(sim.card.map, Calibration::default());
    let card = SimulatedRig::default().card(&Clock::RealTime).unwrap();
    assert!(with_watchdog.rig(card, PERIOD).is_ok());
}

#[test]
fn without_a_watchdog_the_loop_keeps_a_gap_limit_of_its_own() {
    // 25 periods: 50 ms at 2 ms, what half the lab card's watchdog allows.
    let default = LoopConfig::default();
    assert_eq!(default.gap_limit(PERIOD, None), GAP_PERIODS * PERIOD);
    assert_eq!(default.gap_limit(PERIOD, None), 0.05);
    assert_eq!(default.gap_limit(PERIOD, Some(0.1)), 0.05);

    /// 3 V, until its 11th update, which takes 200 ms.
    struct Stalls(usize);
    impl Controller<4, 1, 1> for Stalls {
        fn update(&mut self, _y: &SVector<f64, 4>, _r: &SVector<f64, 1>) -> SVector<f64, 1> {
            self.0 += 1;
            if self.0 == 11 {
                std::thread::sleep(Duration::from_millis(200));
            }
            vector![3.0]
        }
    }
    let (sim, mut file) = no_watchdog();
    file.calibration.no_watchdog_acknowledged = true;
    let rig = file
        .rig(sim.card(&Clock::RealTime).unwrap(), PERIOD)
        .unwrap();
    // No limit on timing faults within reach: a busy machine's hiccups must
    // not end the run before the gap does.
    let cfg = LoopConfig {
        max_timing_faults: 10_000,
        ..config(1.0)
    };
    let err = run(rig, Stalls(0), |_| vector![0.0], &Clock::RealTime, &cfg).unwrap_err();
    assert_eq!(err.error.kind(), LoopFaultKind::Timing);
    match err.error {
        // The stalled controller, or on a busy machine a gap between two
        // samples before it: either way the 50 ms limit, without a
        // watchdog.
        RigError::Fault(LoopFault::Gap { limit, gap, .. }) => {
            assert_eq!(limit, 0.05);
            assert!(gap > limit);
        }
        ref other => panic!("expected a Gap, got {other:?}"),
    }
    assert!(err.recording.len() <= 10, "{}", err.recording.len());
    assert!(
        err.error
            .to_string()
            .contains("25 periods on a card without one"),
        "{}",
        err.error
    );
}
