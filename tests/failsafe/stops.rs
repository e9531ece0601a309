//! Stop signals, panics in a controller, and halting: every PWM channel zeroed, the recording kept.

use super::*;

// ---- signals --------------------------------------------------------------------------

#[cfg(unix)]
#[test]
fn each_stop_signal_halts_the_rig_and_keeps_the_recording() {
    use signal_hook::consts::{SIGHUP, SIGINT, SIGQUIT, SIGTERM, SIGTSTP};
    // Registering replaces these signals' default actions (ending, dumping
    // core, suspending) for the whole test binary, so it must succeed
    // before anything raises them; from then on they only raise the flag.
    // This is the binary's only test that raises or registers signals.
    let stop = ctrlab::hw::StopSignal::on_interrupt().expect("signal handlers registered");
    for (signal, name) in [
        (SIGINT, "SIGINT"),
        (SIGTERM, "SIGTERM"),
        (SIGHUP, "SIGHUP"),
        (SIGQUIT, "SIGQUIT"),
        (SIGTSTP, "SIGTSTP"),
    ] {
        stop.clear();
        let sim = SimulatedRig::default();
        let clock = VirtualClock::new();
        let mut rig = sim.rig(&Clock::Virtual(clock.clone())).unwrap();
        let cfg = LoopConfig {
            stop: Some(stop.clone()),
            ..config(1.0)
        };
        let mut raised = false;
        let err = run(
            &mut rig,
            OpenLoop,
            |t| {
                if t >= 0.1 - 1e-9 && !raised {
                    raised = true;
                    // To this thread: its handler (signal-hook's, which
                    // only stores the flag) has run when raise returns.
                    signal_hook::low_level::raise(signal).expect(name);
                }
                vector![3.0]
            },
            &Clock::Virtual(clock.clone()),
            &cfg,
        )
        .unwrap_err();
        // Stopped at the tick after the one that raised it (tick 50,
        // t = 0.1 s): ticks 0–50 recorded, nothing read in tick 51.
        assert_eq!(err.error.kind(), LoopFaultKind::Interrupted, "{name}");
        match err.error {
            RigError::Fault(LoopFault::Interrupted { at }) => {
                assert!((at - 51.0 * PERIOD).abs() < 1e-12, "{name}: {at}")
            }
            ref other => panic!("{name}: expected Interrupted, got {other:?}"),
        }
        assert_recorded(&err, 51, 0.1);
        assert!(
            err.recording
                .channel("u")
                .unwrap()
                .iter()
                .all(|u| (u - 3.0).abs() < 0.012),
            "{name}: the motor was on"
        );
        assert_every_channel_off(&mut rig, &clock);
        assert!(stop.is_requested(), "{name}");
    }
}

// ---- panics ---------------------------------------------------------------------------

/// 3 V throughout; panics in its `applied` at the `at`-th call (counted
/// from 1), or in `reset`.
struct Panics {
    applied: usize,
    at: Option<usize>,
    in_reset: bool,
}

impl Controller<4, 1, 1> for Panics {
    fn update(&mut self, _y: &SVector<f64, 4>, _r: &SVector<f64, 1>) -> SVector<f64, 1> {
        vector![3.0]
    }
    fn applied(&mut self, _u: &SVector<f64, 1>) {
        self.applied += 1;
        if Some(self.applied) == self.at {
            panic!("anti-windup state out of range");
        }
    }
    fn reset(&mut self) {
        if self.in_reset {
            panic!("no initial state for this reference");
        }
    }
}

/// The realistic rig with PWM channel 2 (which the calibration does not
/// use) set by someone else: a halt must zero it too.
fn rig_with_a_stray_channel() -> (VirtualClock, SimRig) {
    let clock = VirtualClock::new();
    let mut rig = SimulatedRig::default()
        .rig(&Clock::Virtual(clock.clone()))
        .unwrap();
    rig.card_mut().set_pwm(2, 400).unwrap();
    clock.advance(0.001).unwrap();
    rig.card_mut().port_mut().sync().unwrap();
    assert_eq!(rig.card().port().pwm_duty(2), 400);
    (clock, rig)
}

#[test]
fn a_panic_in_applied_halts_the_rig_and_keeps_the_recording() {
    let (clock, mut rig) = rig_with_a_stray_channel();
    let controller = Panics {
        applied: 0,
        at: Some(25),
        in_reset: false,
    };
    let err = run(
        &mut rig,
        controller,
        |_| vector![0.0],
        &Clock::Virtual(clock.clone()),
        &config(1.0),
    )
    .unwrap_err();
    assert_eq!(err.error.kind(), LoopFaultKind::Panic);
    match &err.error {
        RigError::Fault(LoopFault::Panicked { what, message, at }) => {
            assert_eq!(*what, "controller (applied)");
            assert_eq!(message, "anti-windup state out of range");
            assert!((at - 24.0 * PERIOD).abs() < 1e-12, "{at}");
        }
        other => panic!("expected Panicked, got {other:?}"),
    }
    let text = err.error.to_string();
    assert!(
        text.contains("controller (applied) panicked") && text.contains("anti-windup"),
        "{text}"
    );
    // Ticks 0–24 recorded: tick 24's 3 V reached the motor before the
    // panic, so its sample is there.
    assert_recorded(&err, 25, 24.0 * PERIOD);
    assert!(err.last_measurement.is_none());
    assert!(
        err.recording
            .channel("u")
            .unwrap()
            .iter()
            .all(|u| (u - 3.0).abs() < 0.012),
        "the motor was on"
    );
    assert_every_channel_off(&mut rig, &clock);
}

#[test]
fn a_panic_in_reset_halts_the_rig_before_the_first_tick() {
    let (clock, mut rig) = rig_with_a_stray_channel();
    // The motor left on by what ran before.
    rig.apply_voltage(6.0).unwrap();
    let controller = Panics {
        applied: 0,
        at: None,
        in_reset: true,
    };
    let err = run(
        &mut rig,
        controller,
        |_| vector![0.0],
        &Clock::Virtual(clock.clone()),
        &config(1.0),
    )
    .unwrap_err();
    assert_eq!(err.error.kind(), LoopFaultKind::Panic);
    match &err.error {
        RigError::Fault(LoopFault::Panicked { what, message, at }) => {
            assert_eq!(*what, "controller (reset)");
            assert_eq!(message, "no initial state for this reference");
            assert_eq!(*at, 0.0);
        }
        other => panic!("expected Panicked, got {other:?}"),
    }
    // Nothing was run: an empty recording with the lab's channels, kept.
    assert!(err.recording.is_empty());
    assert_eq!(err.recording.schema(), &ctrlab::lab::schema());
    assert!(err.last_measurement.is_none());
    assert_every_channel_off(&mut rig, &clock);
}

// ---- halting ----------------------------------------------------------------------------

#[test]
fn halt_zeroes_every_pwm_channel() {
    let clock = VirtualClock::new();
    let mut rig = SimulatedRig::default()
        .rig(&Clock::Virtual(clock.clone()))
        .unwrap();
    rig.apply_voltage(12.0).unwrap();
    for (channel, duty) in [(1, -250), (2, 400), (3, 1000)] {
        rig.card_mut().set_pwm(channel, duty).unwrap();
    }
    clock.advance(0.001).unwrap();
    rig.card_mut().port_mut().sync().unwrap();
    let duties: Vec<i16> = (0..PWM_CHANNELS)
        .map(|c| rig.card().port().pwm_duty(c))
        .collect();
    assert_eq!(duties, [500, -250, 400, 1000]);
    rig.halt().unwrap();
    assert_every_channel_off(&mut rig, &clock);

    // The motor on another channel than 0: it is zeroed first, and the
    // rest after it.
    let sim = SimulatedRig {
        calibration: Calibration {
            pwm_channel: 3,
            ..Calibration::default()
        },
        ..SimulatedRig::ideal(MassSpring::nominal())
    };
    let mut port = RecordingPort::new(sim.card(&Clock::RealTime).unwrap());
    let mut rig = MassSpringRig::new(Pc104::new(&mut port), sim.calibration, PERIOD).unwrap();
    rig.halt().unwrap();
    drop(rig);
    let high_bytes: Vec<u8> = port
        .log()
        .iter()
        .filter_map(|c| match c {
            Cycle::AddressWrite(a @ (0x11 | 0x13 | 0x15 | 0x17)) => Some(*a),
            _ => None,
        })
        .collect();
    // The halt, then the drop's halt: channel 3 first each time.
    assert_eq!(high_bytes, [0x17, 0x11, 0x13, 0x15, 0x17, 0x11, 0x13, 0x15]);
}

#[test]
fn dropping_the_rig_zeroes_every_pwm_channel() {
    let clock = VirtualClock::new();
    let virtual_clock = Clock::Virtual(clock.clone());
    let sim = SimulatedRig::default();
    let mut card = sim.card(&virtual_clock).unwrap();
    {
        let mut rig = MassSpringRig::with_clock(
            Pc104::new(&mut card),
            sim.calibration,
            PERIOD,
            virtual_clock.clone(),
        )
        .unwrap();
        rig.apply_voltage(-6.0).unwrap();
        rig.card_mut().set_pwm(1, 700).unwrap();
    }
    clock.advance(0.001).unwrap();
    card.sync().unwrap();
    for channel in 0..PWM_CHANNELS {
        assert_eq!(card.pwm_duty(channel), 0, "PWM channel {channel}");
    }
}
