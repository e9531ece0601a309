//! A dead or dying encoder on the driven cart: halted before the travel limit.

use super::*;

// ---- the driven cart's encoder ---------------------------------------------------

/// Table 5's Kf = [0 0 10 0] (per mm) to 30 mm at full drive on the
/// realistic rig whose cart 2 is read from counter 2, which the card leaves
/// unconnected: the encoder reads a cart at rest while the motor pushes
/// the real one. Returns the run's error, the rig and how far each true
/// cart went, coasting 2 s after the halt included.
fn dead_cart_2_encoder(calibration: Calibration) -> (RunError, [f64; 2]) {
    let sim = SimulatedRig::default();
    // The premise: cart 2 is on counter 1 on the card, nothing on counter 2.
    assert_eq!(sim.card_config().encoders, [Some(0), Some(2), None, None]);
    let clock = VirtualClock::new();
    let virtual_clock = Clock::Virtual(clock.clone());
    let mut rig = rig_with(&sim, calibration, &virtual_clock);
    let kf = LabGains::new([0.0, 0.0, 10.0, 0.0], Cart::Two)
        .state_feedback()
        .unwrap();
    let mut watched = Watched {
        rig: &mut rig,
        furthest: [0.0; 2],
    };
    let err = match run(
        &mut watched,
        kf,
        |_| vector![0.030],
        &virtual_clock,
        &config(3.0),
    ) {
        Ok(out) => panic!(
            "a dead encoder ran {} samples unnoticed",
            out.recording.len()
        ),
        Err(err) => *err,
    };
    let furthest = watched.furthest;
    assert_every_channel_off(&mut rig, &clock);
    let furthest = coast(&mut rig, &clock, 2.0, furthest);
    (err, furthest)
}

#[test]
fn a_dead_encoder_on_the_driven_cart_halts_before_the_cart_passes_its_travel() {
    let cal = Calibration {
        encoder_channels: [0, 2],
        ..Calibration::default()
    };
    let (err, furthest) = dead_cart_2_encoder(cal);
    assert_eq!(err.error.kind(), LoopFaultKind::NotResponding);
    let seconds = match err.error {
        RigError::Fault(LoopFault::EncoderNotFollowing {
            cart,
            channel,
            other,
            volts,
            seconds,
            moved,
            counts,
        }) => {
            assert_eq!((cart, channel, other), (2, 2, 1));
            assert_eq!(volts, 24.0, "full drive from the first tick");
            assert!(moved >= cal.stall_counts, "{moved}");
            assert_eq!(counts, cal.stall_counts);
            assert!(seconds >= cal.follow_time, "{seconds}");
            seconds
        }
        ref other => panic!("expected EncoderNotFollowing, got {other:?}"),
    };
    let text = err.error.to_string();
    assert!(
        text.contains("encoder of cart 2") && text.contains("channel 2"),
        "{text}"
    );
    // Found within a few periods of the follow time: the drive is applied
    // at tick 0, the stall starts at tick 1 (2 ms), cart 1 moves 3 counts
    // after a few milliseconds more.
    assert!(seconds < cal.follow_time + 10.0 * PERIOD, "{seconds}");
    let n = err.recording.len();
    assert!((5..=20).contains(&n), "{n} samples");
    assert!(
        err.recording
            .channel("x2")
            .unwrap()
            .iter()
            .all(|x| *x == 0.0),
        "the dead encoder reads a cart at rest"
    );
    assert!(
        err.recording
            .channel("u")
            .unwrap()
            .iter()
            .all(|u| *u == 24.0),
        "the motor was at full drive"
    );
    // The true carts, before and after the halt: cart 2 never reached its
    // ±50 mm (it coasts a while: the motor is off, its momentum is not).
    assert!(furthest[1] < cal.travel_limits[1], "{furthest:?}");
    assert!(furthest[0] < cal.travel_limits[0], "{furthest:?}");
    println!("true cart travel with the check: {furthest:?} m");
}

#[test]
fn without_the_follow_check_the_dead_encoder_lets_the_cart_pass_its_travel() {
    // The scenario is real: with a follow time as long as the stall time,
    // only the stall check remains (on cart 2's own encoder, 0.5 s), and
    // the true cart goes past its travel limit before it halts.
    let cal = Calibration {
        encoder_channels: [0, 2],
        follow_time: Calibration::default().stall_time,
        ..Calibration::default()
    };
    let (err, furthest) = dead_cart_2_encoder(cal);
    assert_eq!(err.error.kind(), LoopFaultKind::NotResponding);
    assert!(
        matches!(
            err.error,
            RigError::Fault(
                LoopFault::EncoderNotFollowing { .. } | LoopFault::NotResponding { .. }
            )
        ),
        "{}",
        err.error
    );
    assert!(furthest[1] > cal.travel_limits[1], "{furthest:?}");
}

#[test]
fn a_healthy_rig_runs_table_5s_step_without_a_fault() {
    // The same step with cart 2's encoder where it is: no fault, and cart 2
    // near the closed loop's steady state.
    let sim = SimulatedRig::default();
    let clock = VirtualClock::new();
    let virtual_clock = Clock::Virtual(clock.clone());
    let mut rig = rig_with(&sim, sim.calibration, &virtual_clock);
    let kf = LabGains::new([0.0, 0.0, 10.0, 0.0], Cart::Two)
        .state_feedback()
        .unwrap();
    let out = run(
        &mut rig,
        kf,
        |_| vector![0.030],
        &virtual_clock,
        &config(3.0),
    )
    .unwrap();
    assert_eq!(out.recording.len(), 1500);
}

/// Passes every cycle to the card, except that counter 1's bytes (cart 2's
/// encoder, registers 0x24–0x27) read what they read at `freeze_after`
/// reads of them: an encoder whose cable comes loose mid-run.
struct Freezes<P> {
    inner: P,
    selected: u8,
    reads: usize,
    freeze_after: usize,
    frozen: [u8; 4],
}

impl<P: ctrlab::hw::EppPort> ctrlab::hw::EppPort for Freezes<P> {
    fn write_address(&mut self, address: u8) -> Result<(), ctrlab::hw::PortError> {
        self.selected = address;
        self.inner.write_address(address)
    }
    fn read_data(&mut self) -> Result<u8, ctrlab::hw::PortError> {
        let value = self.inner.read_data()?;
        if !(0x24..=0x27).contains(&self.selected) {
            return Ok(value);
        }
        let byte = usize::from(self.selected - 0x24);
        self.reads += 1;
        if self.reads <= self.freeze_after {
            self.frozen[byte] = value;
            Ok(value)
        } else {
            Ok(self.frozen[byte])
        }
    }
    fn write_data(&mut self, value: u8) -> Result<(), ctrlab::hw::PortError> {
        self.inner.write_data(value)
    }
}

#[test]
fn an_encoder_that_dies_mid_run_is_caught_at_the_next_change_of_drive() {
    // Table 5's Kf = [0 0 10 0.1] to 30 mm; cart 2's encoder freezes at
    // 1 s (500 reads of its four bytes), with the cart settled; at 1.5 s the
    // setpoint moves to 25 mm, and the controller, blind to cart 2, drives
    // it with everything it has.
    let sim = SimulatedRig::default();
    let clock = VirtualClock::new();
    let virtual_clock = Clock::Virtual(clock.clone());
    let port = Freezes {
        inner: sim.card(&virtual_clock).unwrap(),
        selected: 0,
        reads: 0,
        freeze_after: 4 * 500,
        frozen: [0; 4],
    };
    let mut rig = MassSpringRig::with_clock(
        Pc104::new(port),
        sim.calibration,
        PERIOD,
        virtual_clock.clone(),
    )
    .unwrap();
    let kf = LabGains::new([0.0, 0.0, 10.0, 0.1], Cart::Two)
        .state_feedback()
        .unwrap();
    let reference = |t: f64| {
        if t < 1.5 {
            vector![0.030]
        } else {
            vector![0.025]
        }
    };
    let err = run(&mut rig, kf, reference, &virtual_clock, &config(3.0)).unwrap_err();
    match err.error {
        RigError::Fault(LoopFault::EncoderNotFollowing { cart, seconds, .. }) => {
            assert_eq!(cart, 2);
            assert!(seconds < 0.05, "{seconds}");
        }
        ref other => panic!("expected EncoderNotFollowing, got {other:?}"),
    }
    // Caught within a few tens of milliseconds of the new setpoint.
    let n = err.recording.len();
    assert!((750..780).contains(&n), "{n} samples");
    let cal = sim.calibration;
    let mut furthest = [0.0f64; 2];
    for _ in 0..2000 {
        clock.advance(1e-3).unwrap();
        let card = &mut rig.card_mut().port_mut().inner;
        card.sync().unwrap();
        let x = card.true_state();
        for c in 0..2 {
            furthest[c] = furthest[c].max(x[2 * c].abs());
        }
        assert_eq!(card.pwm_duty(0), 0);
    }
    println!("after the halt: {furthest:?} m");
    assert!(furthest[1] < cal.travel_limits[1], "{furthest:?}");
}
