//! The simulated card: registers, latch, watchdog, PWM delay, noise, friction, configurations.

use super::*;

#[test]
fn card_id_and_probe() {
    let (_clock, card) = sim(SimulatedRig::default());
    let mut pc104 = Pc104::new(card);
    assert_eq!(
        pc104.probe_id(SIMULATED_CARD_ID).unwrap(),
        SIMULATED_CARD_ID
    );
    let err = pc104.probe_id(0x3c).unwrap_err();
    assert_eq!(err.kind(), PortErrorKind::NotPresent);
    assert!(err.to_string().contains("0xa5"), "{err}");
    // An unmapped address reads an open bus.
    assert_eq!(pc104.port_mut().read_register(0x99).unwrap(), 0xff);
}

#[test]
fn plant_matches_the_exact_zoh_discretisation() {
    // The card's RK4 sub-steps against the crate's exact ZOH model: the
    // voltage is held between accesses, so the two agree to RK4's error.
    // The ideal rig: friction and the PWM delay are not in the linear model.
    let truth = SimulatedRig::default_truth();
    let (clock, card) = sim(SimulatedRig {
        calibration: Calibration {
            watchdog_timeout: None,
            ..ideal().calibration
        },
        ..ideal()
    });
    let mut pc104 = Pc104::new(card);
    let d = truth
        .state_space(Cart::Two)
        .unwrap()
        .discretize(0.002, Discretization::Zoh)
        .unwrap();
    let mut x = SVector::<f64, 4>::zeros();
    let mut scale = 1e-3f64;
    for k in 0..1000 {
        // A varying, quantisable input: duty steps of 0.1 %.
        let duty = ((k % 50) as i16 - 25) * 8;
        pc104.set_pwm(0, duty).unwrap();
        let volts = 24.0 * f64::from(duty) / 1000.0;
        x = d.advance(&x, &vector![volts]);
        clock.advance_nanos(PERIOD_NS);
        pc104.latch().unwrap();
        let got = pc104.port().true_state();
        scale = scale.max(x.norm());
        // RK4's local error is about (hω)⁵/120 of the state, with the
        // fastest mode |s| = 50.6 rad/s of the default truth and
        // h = 0.25 ms: 2.7e-12 per sub-step, 2.1e-8 after the 8000 sub-steps
        // of this run, inside the 1e-7 bound.
        assert!((got - x).norm() <= 1e-7 * scale, "step {k}: {got} vs {x}");
    }
}

#[test]
fn a_latch_captures_the_counts_of_the_state_at_that_instant() {
    let (clock, card) = sim(SimulatedRig {
        initial_state: [0.004, 0.0, -0.013, 0.0],
        // Noiseless: the count is exactly the rounded state.
        calibration: Calibration {
            watchdog_timeout: None,
            ..ideal().calibration
        },
        ..ideal()
    });
    let mut pc104 = Pc104::new(card);
    for _ in 0..200 {
        clock.advance_nanos(1_300_000);
        pc104.latch().unwrap();
        let truth = pc104.port().true_state();
        assert_eq!(pc104.port().time(), clock.now());
        // Advancing the clock after the latch does not change what is read.
        clock.advance_nanos(700_000);
        let c1 = pc104.read_counter(0).unwrap();
        let c2 = pc104.read_counter(1).unwrap();
        assert_eq!(c1, (truth[0] / MPC).round() as i64);
        assert_eq!(c2, (truth[2] / MPC).round() as i64);
    }
}

#[test]
fn clearing_zeroes_the_counters_where_the_carts_are() {
    let (clock, card) = sim(SimulatedRig {
        initial_state: [0.004, 0.0, 0.013, 0.0],
        // Noiseless: the counts are exactly the rounded state.
        ..ideal()
    });
    let mut pc104 = Pc104::new(card);
    pc104.latch().unwrap();
    assert_eq!(pc104.read_counter(1).unwrap(), (0.013 / MPC).round() as i64);
    pc104.clear_counters().unwrap();
    pc104.latch().unwrap();
    assert_eq!(pc104.read_counter(0).unwrap(), 0);
    assert_eq!(pc104.read_counter(1).unwrap(), 0);
    // Afterwards the counters follow the carts from there.
    clock.advance(0.01).unwrap();
    pc104.latch().unwrap();
    let x = pc104.port().true_state();
    let expected = ((x[2] / MPC).round() - (0.013 / MPC).round()) as i64;
    assert_eq!(pc104.read_counter(1).unwrap(), expected);
    assert_ne!(expected, 0);
}

#[test]
fn watchdog_zeroes_the_pwm_when_not_kicked() {
    // No PWM delay: a duty applies when written, so the hand-switched
    // reference below is exact (the delay's own test is further down).
    let config = SimulatedRig {
        initial_state: [0.0, 0.0, 0.0, 0.0],
        ..ideal()
    };
    let (clock, card) = sim(config.clone());
    let mut pc104 = Pc104::new(card);
    pc104.set_pwm(0, 500).unwrap();
    clock.advance(0.050).unwrap();
    pc104.kick_watchdog().unwrap(); // at 50 ms: the deadline moves to 150 ms
    clock.advance(0.099).unwrap();
    pc104.latch().unwrap();
    assert_eq!(
        pc104.port().pwm_duty(0),
        500,
        "149 ms: still kicked in time"
    );
    clock.advance(0.002).unwrap();
    pc104.latch().unwrap();
    assert_eq!(pc104.port().pwm_duty(0), 0, "151 ms: the watchdog tripped");
    assert_eq!(pc104.port().voltage(), 0.0);
    // Until a kick, new duties are refused.
    pc104.set_pwm(0, 300).unwrap();
    assert_eq!(pc104.port().pwm_duty(0), 0);
    pc104.kick_watchdog().unwrap();
    pc104.set_pwm(0, 300).unwrap();
    assert_eq!(pc104.port().pwm_duty(0), 300);

    // The trip happened at exactly 150 ms of card time: the same card with no
    // watchdog, switched off by hand at 150 ms, ends in the same state.
    let (clock2, card2) = sim(SimulatedRig {
        calibration: Calibration {
            watchdog_timeout: None,
            ..config.calibration
        },
        ..config
    });
    let mut reference = Pc104::new(card2);
    reference.set_pwm(0, 500).unwrap();
    clock2.advance(0.150).unwrap();
    reference.set_pwm(0, 0).unwrap();
    clock2.advance(0.001).unwrap();
    reference.latch().unwrap();
    let (a, b) = (pc104.port().true_state(), reference.port().true_state());
    assert!((a - b).norm() <= 1e-12 * b.norm(), "{a} vs {b}");
    assert!(b[2] > 0.0);
}

#[test]
fn the_pwm_delay_applies_a_duty_exactly_that_long_after_its_write() {
    // The realistic rig (friction, stiction, 0.15 ms delay) against the same
    // rig without the delay, whose write is made 0.15 ms later by hand. Both
    // cards are accessed at the same instants, so they integrate the same
    // sub-steps and end in the same state.
    let delayed = SimulatedRig {
        calibration: Calibration {
            watchdog_timeout: None,
            ..Calibration::default()
        },
        ..Default::default()
    };
    let delay = delayed.card.pwm_delay;
    assert_eq!(delay, 0.15e-3);
    let (clock, card) = sim(delayed.clone());
    let (clock2, card2) = sim(SimulatedRig {
        card: CardSettings {
            pwm_delay: 0.0,
            ..delayed.card
        },
        ..delayed
    });
    let (mut a, mut b) = (Pc104::new(card), Pc104::new(card2));
    clock.advance(0.001).unwrap();
    clock2.advance(0.001).unwrap();
    a.set_pwm(0, 500).unwrap(); // 12 V, 13.3 N: breaks away
    b.latch().unwrap(); // the same access instant, no write
    assert_eq!(a.port().pwm_duty(0), 0, "not applied when written");
    clock.advance(0.1e-3).unwrap();
    clock2.advance(0.1e-3).unwrap();
    a.latch().unwrap();
    b.latch().unwrap();
    assert_eq!(a.port().pwm_duty(0), 0, "nor 0.1 ms later");
    clock.advance(delay - 0.1e-3).unwrap();
    clock2.advance(delay - 0.1e-3).unwrap();
    a.latch().unwrap();
    b.set_pwm(0, 500).unwrap();
    assert_eq!(a.port().pwm_duty(0), 500, "applied at the delay");
    clock.advance(0.05).unwrap();
    clock2.advance(0.05).unwrap();
    a.latch().unwrap();
    b.latch().unwrap();
    let (x, y) = (a.port().true_state(), b.port().true_state());
    assert!(y[2] > 0.0, "cart 2 moved: {y}");
    assert!((x - y).norm() <= 1e-12 * y.norm(), "{x} vs {y}");
}

#[test]
fn the_watchdog_also_cancels_a_pwm_write_in_flight() {
    // On the realistic rig a write takes 0.15 ms to apply: one made just
    // before the watchdog trips never applies, and the trip is at exactly
    // the timeout (100 ms after the card was created, its last kick).
    let (clock, card) = sim(SimulatedRig::default());
    let mut pc104 = Pc104::new(card);
    pc104.set_pwm(0, 500).unwrap();
    clock.advance(0.0999).unwrap();
    pc104.set_pwm(0, 300).unwrap(); // would apply at 100.05 ms
    clock.advance(0.00009).unwrap();
    pc104.latch().unwrap();
    assert_eq!(pc104.port().pwm_duty(0), 500, "99.99 ms: not yet");
    clock.advance(0.0001).unwrap();
    pc104.latch().unwrap();
    assert_eq!(
        pc104.port().pwm_duty(0),
        0,
        "100.09 ms: tripped, write lost"
    );
    // Until a kick, delayed writes are zeroed too.
    pc104.set_pwm(0, 300).unwrap();
    clock.advance(0.001).unwrap();
    pc104.latch().unwrap();
    assert_eq!(pc104.port().pwm_duty(0), 0);
    pc104.kick_watchdog().unwrap();
    pc104.set_pwm(0, 300).unwrap();
    clock.advance(0.001).unwrap();
    pc104.latch().unwrap();
    assert_eq!(pc104.port().pwm_duty(0), 300);
}

#[test]
fn noise_is_seeded_and_of_the_configured_size() {
    let run = |seed: u64| {
        let (_clock, card) = sim(SimulatedRig {
            card: CardSettings {
                encoder_noise: 3.0,
                seed,
                ..CardSettings::default()
            },
            ..Default::default()
        });
        let mut pc104 = Pc104::new(card);
        (0..4000)
            .map(|_| {
                pc104.latch().unwrap();
                // The plant is at rest at 0: the count is pure noise.
                pc104.read_raw_counter(1).unwrap() as i32
            })
            .collect::<Vec<_>>()
    };
    let a = run(1);
    assert_eq!(a, run(1));
    assert_ne!(a, run(2));
    let n = a.len() as f64;
    let mean = a.iter().map(|&c| f64::from(c)).sum::<f64>() / n;
    let var = a
        .iter()
        .map(|&c| (f64::from(c) - mean).powi(2))
        .sum::<f64>()
        / n;
    // Rounding adds 1/12 count² to σ² = 9; 4000 samples: the standard error
    // of the mean is 0.05 counts, of the variance about 0.2 counts².
    assert!(mean.abs() < 0.25, "mean {mean}");
    assert!((var - (9.0 + 1.0 / 12.0)).abs() < 1.0, "variance {var}");
}

#[test]
fn coulomb_friction_sticks_below_breakaway_and_stops_in_the_dead_band() {
    // Coulomb friction alone (the ideal rig's stiction is 0, taken as the
    // Coulomb force): the breakaway force is 2 N.
    let truth = MassSpring::nominal();
    let (clock, card) = sim(SimulatedRig {
        friction: Friction::coulomb([0.0, 2.0]),
        calibration: Calibration {
            watchdog_timeout: None,
            ..Calibration::default()
        },
        ..SimulatedRig::ideal(truth)
    });
    let mut pc104 = Pc104::new(card);
    // 1.008 N (42 ‰ of 24 V with the nominal 1 N/V) against 2 N: no motion.
    pc104.set_pwm(0, 42).unwrap();
    clock.advance(2.0).unwrap();
    pc104.latch().unwrap();
    assert_eq!(pc104.port().true_state(), SVector::<f64, 4>::zeros());

    // 12 N: cart 2 breaks away, oscillates, and sticks for good somewhere
    // in the dead band where the springs and motor are within ±2 N.
    pc104.set_pwm(0, 500).unwrap();
    clock.advance(10.0).unwrap();
    pc104.latch().unwrap();
    let x = pc104.port().true_state();
    assert_eq!(x[3], 0.0, "cart 2 has stuck");
    let force_on_cart2 = truth.k2 * (x[0] - x[2]) + 12.0;
    assert!(force_on_cart2.abs() <= 2.0, "net force {force_on_cart2} N");
    // Cart 1 has no friction: it has settled where its springs balance.
    let x1_rest = truth.k2 * x[2] / (truth.k1 + truth.k2);
    assert!((x[0] - x1_rest).abs() < 1e-9, "{x}");
    // And the dead band is a real band: frictionless, x2 would be 24 mm.
    assert!(x[2] > 0.020 && x[2] < 0.028, "{x}");
}

#[test]
fn stiction_holds_a_cart_that_coulomb_friction_alone_would_let_slide() {
    // 2.208 N (92 ‰ of 24 V at 1 N/V) on cart 2: more than its 2 N of
    // sliding friction, less than the 2.4 N breakaway of the default rig.
    let run = |stiction: [f64; 2]| {
        let (clock, card) = sim(SimulatedRig {
            friction: Friction {
                coulomb: [0.0, 2.0],
                stiction,
            },
            calibration: Calibration {
                watchdog_timeout: None,
                ..Calibration::default()
            },
            ..SimulatedRig::ideal(MassSpring::nominal())
        });
        let mut pc104 = Pc104::new(card);
        pc104.set_pwm(0, 92).unwrap();
        clock.advance(1.0).unwrap();
        pc104.latch().unwrap();
        pc104.port().true_state()
    };
    assert_eq!(run([0.0, 2.4]), SVector::<f64, 4>::zeros());
    assert!(run([0.0, 0.0])[2] > 0.0);
    assert_eq!(SimulatedRig::default().friction.stiction, [1.2, 2.4]);
}

#[test]
fn invalid_configurations_are_refused() {
    let default = SimulatedRig::default();
    for (bad, name) in [
        (
            SimulatedRig {
                card: CardSettings {
                    max_substep: 0.0,
                    ..default.card
                },
                ..default.clone()
            },
            "card.max_substep",
        ),
        (
            SimulatedRig {
                card: CardSettings {
                    encoder_noise: -1.0,
                    ..default.card
                },
                ..default.clone()
            },
            "card.encoder_noise",
        ),
        (
            SimulatedRig {
                calibration: Calibration {
                    encoder_channels: [1, 1],
                    ..default.calibration
                },
                ..default.clone()
            },
            "calibration.encoder_channels[1]",
        ),
        (
            SimulatedRig {
                calibration: Calibration {
                    watchdog_timeout: Some(f64::NAN),
                    ..default.calibration
                },
                ..default.clone()
            },
            "calibration.watchdog_timeout",
        ),
        (
            SimulatedRig {
                truth: MassSpring {
                    m2: 0.0,
                    ..MassSpring::nominal()
                },
                ..default.clone()
            },
            "truth.m2",
        ),
    ] {
        match bad.card(&Clock::RealTime) {
            Err(e) => assert_eq!(e.key(), name),
            Ok(_) => panic!("expected {name} refused"),
        }
    }
}
