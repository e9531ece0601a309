//! The rig on the simulated card: static deflection, friction dead band, speeds, saturation, halting.

use super::*;

fn rig_on(config: SimulatedRig) -> (VirtualClock, MassSpringRig<Card>) {
    let clock = VirtualClock::new();
    let rig = config.rig(&Clock::Virtual(clock.clone())).unwrap();
    (clock, rig)
}

#[test]
fn a_rig_on_another_register_map_reads_and_drives_its_card() {
    // The driver takes the card's map: the same run reads the same counts
    // whatever the addresses.
    let run = |map: ctrlab::hw::RegisterMap| {
        let sim = SimulatedRig {
            card: CardSettings {
                map,
                ..ideal().card
            },
            ..ideal()
        };
        let (clock, mut rig) = rig_on(sim);
        let mut x = rig.read_state().unwrap();
        for _ in 0..250 {
            rig.apply_voltage(6.0).unwrap();
            clock.advance_nanos(PERIOD_NS);
            x = rig.read_state().unwrap();
        }
        x
    };
    let default = run(ctrlab::hw::RegisterMap::default());
    let moved = run(ctrlab::hw::RegisterMap {
        control: 0x02,
        pwm_low: [0x40, 0x42, 0x44, 0x46],
        pwm_high: [0x41, 0x43, 0x45, 0x47],
        encoder: [0x80, 0x84, 0x88, 0x8c],
        ..ctrlab::hw::RegisterMap::default()
    });
    assert!(default[2] > 0.005, "{default}");
    assert_eq!(moved, default);
}

/// Holds `volts` for `seconds`, reading every 2 ms; returns the last state.
fn hold<P: EppPort>(
    clock: &VirtualClock,
    rig: &mut MassSpringRig<P>,
    volts: f64,
    seconds: f64,
) -> SVector<f64, 4> {
    let mut x = rig.read_state().unwrap();
    for _ in 0..(seconds / 0.002).round() as usize {
        rig.apply_voltage(volts).unwrap();
        clock.advance_nanos(PERIOD_NS);
        x = rig.read_state().unwrap();
    }
    x
}

#[test]
fn open_loop_reaches_the_static_deflection_of_the_truth() {
    // Without friction (ideal rigs) the carts settle exactly where the
    // truth's springs put them; the realistic rig's dead band is the next
    // test.
    for (config, volts) in [(nominal_config(), 12.0), (ideal(), 3.0), (ideal(), -4.8)] {
        let truth = config.truth;
        let (clock, mut rig) = rig_on(config);
        let x = hold(&clock, &mut rig, volts, 10.0);
        // 12 V, 3 V and -4.8 V are exact multiples of the 24 mV duty step.
        let (x1, x2) = truth.static_deflection(truth.gain * volts).unwrap();
        // Encoder quantisation: half a count (plus the residual transient,
        // at most e^(-37) of the initial deflection after 10 s, the slowest
        // decay rate being 3.7 /s on the nominal plant, 4.26 /s on the
        // default truth: nothing).
        assert!(
            (x[0] - x1).abs() <= MPC / 2.0 + 1e-9,
            "{truth:?}: x1 {} vs {x1}",
            x[0]
        );
        assert!(
            (x[2] - x2).abs() <= MPC / 2.0 + 1e-9,
            "{truth:?}: x2 {} vs {x2}",
            x[2]
        );
        assert_eq!((x[1], x[3]), (0.0, 0.0), "at rest the counts do not change");
    }
}

#[test]
fn the_realistic_rig_stops_within_its_friction_dead_band() {
    // The default rig: 3 V (3.33 N on the 1.11 N/V motor) breaks cart 2
    // away (2.4 N of stiction), and the carts stop where the other forces
    // on each are within its breakaway force, not at the frictionless
    // static deflection.
    let sim = SimulatedRig::default();
    let (truth, stiction) = (sim.truth, sim.friction.stiction);
    let volts = 3.0; // 125 duty steps exactly
    let (clock, mut rig) = rig_on(sim.clone());
    let measured = hold(&clock, &mut rig, volts, 10.0);
    let x = rig.card().port().true_state();
    assert_eq!((x[1], x[3]), (0.0, 0.0), "both carts stuck: {x}");
    let on_cart1 = -(truth.k1 + truth.k2) * x[0] + truth.k2 * x[2];
    let on_cart2 = truth.k2 * (x[0] - x[2]) + truth.gain * volts;
    assert!(on_cart1.abs() <= stiction[0], "{on_cart1} N on cart 1");
    assert!(on_cart2.abs() <= stiction[1], "{on_cart2} N on cart 2");
    // The band is wide: 2.4 N on cart 2 is ±4.9 mm of x2 about the 6.8 mm
    // frictionless deflection.
    let (_, x2_static) = truth.static_deflection(truth.gain * volts).unwrap();
    println!("x2 {} mm, frictionless {} mm", x[2] * 1e3, x2_static * 1e3);
    assert!(x[2] > 0.0 && x[2] < 2.0 * x2_static, "{x}");
    assert!(
        (x[2] - x2_static).abs() > 10.0 * MPC,
        "friction made no difference: {x}"
    );
    // What the rig reads is that state, give or take the encoder noise:
    // σ = 0.3 count plus half a count of rounding; 3 counts is 8σ.
    for i in [0, 2] {
        assert!(
            (measured[i] - x[i]).abs() <= 3.0 * MPC,
            "{i}: {measured} vs {x}"
        );
    }
}

#[test]
fn speeds_are_count_differences_over_the_actual_interval() {
    // Speeds are differenced over the time between two reads on the rig's
    // clock, whatever the interval: here alternately 2 ms and 3.1 ms.
    let (clock, mut rig) = rig_on(nominal_config());
    let mut previous = rig.read_state().unwrap();
    let mut moved = false;
    for k in 0..200 {
        rig.apply_voltage(10.0).unwrap();
        let interval = if k % 2 == 0 { 0.002 } else { 0.0031 };
        clock.advance(interval).unwrap();
        let x = rig.read_state().unwrap();
        for i in [0, 2] {
            let expected = (x[i] - previous[i]) / interval;
            assert!((x[i + 1] - expected).abs() <= 1e-9 * expected.abs().max(1.0));
        }
        moved |= x[3] > 0.01;
        previous = x;
    }
    assert!(moved);
}

#[test]
fn voltages_saturate_and_quantise() {
    // No PWM delay, so the card shows each duty as it is written.
    let (_clock, mut rig) = rig_on(ideal());
    for (volts, duty) in [
        (100.0, 1000),
        (-1e9, -1000),
        (24.0, 1000),
        (6.0, 250),
        (0.0119, 0),
        (0.0121, 1),
        (-0.0372, -2), // -1.55 counts of 0.1 %
    ] {
        let applied = rig.apply_voltage(volts).unwrap();
        assert_eq!(rig.card().port().pwm_duty(0), duty, "{volts} V");
        assert_eq!(applied, f64::from(duty) * 24.0 / 1000.0, "{volts} V");
    }
}

#[test]
fn non_finite_voltage_halts_the_rig() {
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        // No PWM delay, so the card shows the 10 V and then the halt at once.
        let (_clock, mut rig) = rig_on(ideal());
        rig.apply_voltage(10.0).unwrap();
        assert_eq!(rig.card().port().pwm_duty(0), 417); // 10 V / 24 mV
        let err = rig.apply_voltage(bad).unwrap_err();
        assert_eq!(err.kind(), PortErrorKind::InvalidCommand, "{bad}");
        assert_eq!(rig.card().port().pwm_duty(0), 0, "{bad}");
    }
}

#[test]
fn travel_limit_breach_halts_the_rig() {
    // The realistic rig: 24 V (26.6 N on the 1.11 N/V motor) would deflect
    // cart 2 by 54 mm at rest, less 4 mm for its 2 N of friction, and the
    // step overshoots: past the ±50 mm limit.
    let sim = SimulatedRig::default();
    let (_, x2_static) = sim.truth.static_deflection(sim.truth.gain * 24.0).unwrap();
    assert!(x2_static > 0.054 && sim.calibration.travel_limits == [0.05, 0.05]);
    let (clock, mut rig) = rig_on(sim);
    let mut err = None;
    for _ in 0..5000 {
        rig.apply_voltage(24.0).unwrap();
        clock.advance_nanos(PERIOD_NS);
        if let Err(e) = rig.read_state() {
            err = Some(e);
            break;
        }
    }
    match err {
        // Axis 2 is cart 2.
        Some(RigError::Fault(LoopFault::TravelLimit {
            axis: 2,
            position,
            limit,
        })) => {
            assert_eq!(limit, 0.05);
            // Found at the first sample past it: within one period at the
            // largest speed the rig accepts (any faster is a bus fault).
            let step = Calibration::default().max_speed * 0.002;
            assert!(position > 0.05 && position < 0.05 + step, "{position}");
        }
        other => panic!("expected a travel-limit breach of cart 2, got {other:?}"),
    }
    // The halt was written; the drive takes it the PWM delay later.
    assert_eq!(rig.card().port().pwm_duty(0), 1000, "24 V until then");
    clock
        .advance(SimulatedRig::default().card.pwm_delay)
        .unwrap();
    rig.card_mut().port_mut().sync().unwrap();
    assert_eq!(rig.card().port().pwm_duty(0), 0);
}

#[test]
fn dropping_the_rig_zeroes_the_pwm() {
    // No PWM delay, so the card shows each duty as it is written.
    let (_clock, mut card) = sim(ideal());
    {
        let mut rig =
            MassSpringRig::new(Pc104::new(&mut card), Calibration::default(), 0.002).unwrap();
        rig.apply_voltage(-12.0).unwrap();
        assert_eq!(rig.card().port().pwm_duty(0), -500);
    }
    assert_eq!(card.pwm_duty(0), 0);
}

#[test]
fn read_state_kicks_the_watchdog_and_stopping_trips_it() {
    // Without stiction (1.2 V, 1.3 N would not move the realistic rig's
    // cart 2) and without the PWM delay.
    let (clock, mut rig) = rig_on(ideal());
    // A 1 s run of a loop that reads and writes every period: never trips.
    let x = hold(&clock, &mut rig, 1.2, 1.0);
    assert!(x[2] > 0.0);
    assert_eq!(rig.card().port().pwm_duty(0), 50);
    // The loop stops: 100 ms later the card has zeroed the PWM by itself.
    clock.advance(0.101).unwrap();
    rig.card_mut().port_mut().sync().unwrap();
    assert_eq!(rig.card().port().pwm_duty(0), 0);
}

#[test]
fn encoder_signs_and_channels_follow_the_calibration() {
    let (clock, card) = sim(SimulatedRig {
        initial_state: [0.002, 0.0, 0.005, 0.0],
        // Noiseless: the counts are exactly the rounded state.
        calibration: Calibration {
            encoder_channels: [3, 2],
            ..ideal().calibration
        },
        ..ideal()
    });
    let cal = Calibration {
        sign: [-1.0, 1.0],
        encoder_channels: [3, 2],
        ..Calibration::default()
    };
    let mut rig =
        MassSpringRig::with_clock(Pc104::new(card), cal, 0.002, Clock::Virtual(clock.clone()))
            .unwrap();
    clock.advance(0.0).unwrap();
    let x = rig.read_state().unwrap();
    assert_eq!(x[0], -(0.002 / MPC).round() * MPC);
    assert_eq!(x[2], (0.005 / MPC).round() * MPC);
}

#[test]
fn a_dead_port_surfaces_as_an_error_from_the_rig() {
    // Dead from the start: building the rig fails at the ID probe (cycle 0,
    // its address write).
    let (_clock, card) = sim(SimulatedRig::default());
    let port = RecordingPort::new(card).fail_from(0);
    let err = MassSpringRig::new(Pc104::new(port), Calibration::default(), 0.002).unwrap_err();
    assert!(matches!(
        err,
        RigError::Port(PortError::Timeout {
            cycle: CycleKind::AddressWrite,
            register: Some(0x00)
        })
    ));
    // Dead after the probe (cycles 0–1): cycle 2 is the latch's address write.
    let (_clock, card) = sim(SimulatedRig::default());
    let port = RecordingPort::new(card).fail_from(PROBE_CYCLES);
    let mut rig = MassSpringRig::new(Pc104::new(port), Calibration::default(), 0.002).unwrap();
    let err = rig.read_state().unwrap_err();
    assert!(matches!(
        err,
        RigError::Port(PortError::Timeout {
            cycle: CycleKind::AddressWrite,
            register: Some(0x01)
        })
    ));
}

#[test]
fn a_fault_at_any_cycle_of_an_iteration_is_reported_and_halting_still_works() {
    // An iteration is 22 cycles: latch+kick (2), two counters (2 × 8), PWM
    // (4); before them, building the rig probes the ID (2). No PWM delay, so
    // the card's duty is the last one written whole.
    const CYCLES: usize = 22;
    for k in 0..CYCLES {
        let (clock, card) = sim(ideal());
        let port = RecordingPort::new(card).fail_at(PROBE_CYCLES + CYCLES + k);
        let virtual_clock = Clock::Virtual(clock.clone());
        let mut rig = MassSpringRig::with_clock(
            Pc104::new(port),
            Calibration::default(),
            0.002,
            virtual_clock,
        )
        .unwrap();
        rig.read_state().unwrap();
        rig.apply_voltage(6.0).unwrap();
        assert_eq!(rig.card().port().attempts(), PROBE_CYCLES + CYCLES);
        clock.advance_nanos(PERIOD_NS);
        let result = rig
            .read_state()
            .and_then(|_| rig.apply_voltage(3.0).map(drop));
        let err = result.expect_err("the injected fault surfaces");
        assert_eq!(err.kind(), PortErrorKind::Timeout, "cycle {k}");
        // Cut in the read (k < 18) the new command is never sent; cut in the
        // PWM write (even after its low byte, k = 20, 21) the card keeps the
        // previous duty whole: only the high byte applies a duty.
        assert_eq!(rig.card().port().inner().pwm_duty(0), 250, "cycle {k}");
        // The port works again: the caller's halt reaches the card.
        rig.halt().unwrap();
        assert_eq!(rig.card().port().inner().pwm_duty(0), 0, "cycle {k}");
    }
}
