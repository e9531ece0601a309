//! The simulated card against independent references (the exact ZOH model,
//! static deflections, a hand-switched watchdog reference, a hand-delayed
//! PWM write), and the rig's safety: saturation, travel limits, non-finite
//! commands, drop.
//!
//! Tests of the card's and the driver's exact behaviour run on
//! [`SimulatedRig::ideal`] (no Coulomb friction, stiction, PWM delay or
//! encoder noise), so a linear reference applies to the count; tests of the
//! lab's rig as it behaves (friction dead band, travel limits under full
//! drive, the PWM delay) run on the realistic [`SimulatedRig::default`].

// Built on the two-cart lab (its plant, simulated rig or card).
#![cfg(feature = "lab")]

use ctrlab::hw::testing::RecordingPort;
use ctrlab::hw::{
    Clock, CycleKind, EppPort, LoopFault, Pc104, PortError, PortErrorKind, Rig, RigError,
    SIMULATED_CARD_ID, SimulatedCard, VirtualClock,
};
use ctrlab::lab::{
    Calibration, CardSettings, Friction, FrictionPlant, MassSpringRig, SimulatedRig, Unmodelled,
};
use ctrlab::{Cart, Discretization, MassSpring};
use nalgebra::{SVector, vector};

/// 80 mm per 8192 counts.
const MPC: f64 = 0.080 / 8192.0;
const PERIOD_NS: u64 = 2_000_000;
/// EPP cycles of the ID probe when a rig is built: address write, data read.
const PROBE_CYCLES: usize = 2;

/// The lab's simulated card (two carts, friction model inside).
type Card = SimulatedCard<FrictionPlant, 4>;

fn sim(config: SimulatedRig) -> (VirtualClock, Card) {
    let clock = VirtualClock::new();
    let card = config.card(&Clock::Virtual(clock.clone())).unwrap();
    (clock, card)
}

/// The default truth without friction, stiction, PWM delay or noise.
fn ideal() -> SimulatedRig {
    SimulatedRig::ideal(SimulatedRig::default_truth())
}

/// The nominal plant (1 N/V) without friction, stiction, PWM delay or noise.
fn nominal_config() -> SimulatedRig {
    SimulatedRig::ideal(MassSpring::nominal())
}

// ---- the simulated card ----------------------------------------------------

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

// ---- the rig ---------------------------------------------------------------

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

// ---- bit for bit -------------------------------------------------------------

/// FNV-1a over the bits of every time, input and measurement of `rec`.
fn bits(rec: &ctrlab::Recording) -> u64 {
    let mut hash = 0xcbf2_9ce4_8422_2325_u64;
    let mut eat = |v: f64| {
        for byte in v.to_bits().to_le_bytes() {
            hash = (hash ^ u64::from(byte)).wrapping_mul(0x0100_0000_01b3);
        }
    };
    rec.time().iter().for_each(|&t| eat(t));
    for i in 0.. {
        let Some(u) = rec.input(i) else { break };
        u.iter().for_each(|&v| eat(v));
    }
    for i in 0.. {
        let Some(y) = rec.measurement(i) else { break };
        y.iter().for_each(|&v| eat(v));
    }
    hash
}

/// A rig with every field of the truth file away from its default.
fn every_field_changed() -> SimulatedRig {
    SimulatedRig {
        truth: MassSpring {
            m1: 1.25,
            m2: 0.75,
            k1: 900.0,
            k2: 1100.0,
            b1: 9.0,
            b2: 6.5,
            gain: 1.3,
        },
        initial_state: [0.004, 0.0, -0.006, 0.01],
        period: 0.001,
        friction: Friction {
            coulomb: [0.5, 1.5],
            stiction: [0.7, 1.8],
        },
        // Off: the hashes below pin the plant without them (the
        // `[unmodelled]` table's own round trip is in tests/rig_config.rs).
        unmodelled: Unmodelled::NONE,
        card: CardSettings {
            pwm_delay: 0.2e-3,
            map: ctrlab::hw::RegisterMap::default(),
            encoder_noise: 0.6,
            seed: 42,
            max_substep: 0.1e-3,
        },
        calibration: Calibration {
            card_id: 0x3c,
            volts_full_scale: 12.0,
            // 2048 counts per 30 mm.
            metres_per_count: 0.03 / 2048.0,
            pwm_channel: 2,
            encoder_channels: [3, 1],
            watchdog_timeout: Some(0.05),
            travel_limits: [0.06, 0.07],
            ..Calibration::default()
        },
        // lab5's identification input: no part of the plant or the card.
        ident: ctrlab::lab::ident_input::IdentInput {
            signal: ctrlab::lab::ident_input::IdentSignal::Prbs,
            volts: 6.0,
            half_period: 0.3,
            scale_to_travel: false,
        },
    }
}

/// The recordings of seeded runs on the simulated rig, and of the
/// sampled-data simulation that predicts them, hashed bit by bit: a
/// refactoring of the rig's configuration must leave every bit of them
/// alone. (The hashes were taken before `SimulatedRig` was composed of its
/// parts, at 91112b5.)
#[test]
fn seeded_runs_are_unchanged_bit_for_bit() {
    use ctrlab::hw::{LoopConfig, run};
    use ctrlab::{OpenLoop, StateFeedback};
    let law = StateFeedback::new(
        nalgebra::matrix![0.0, 0.0, 10_000.0, 100.0],
        nalgebra::matrix![10_000.0],
    )
    .unwrap();
    let mut hashes = Vec::new();
    // The default rig as it was before its unmodelled effects: with them
    // off the plant must be the same bit for bit (`lab_unmodelled` tests
    // what they do when on).
    let before = SimulatedRig {
        unmodelled: Unmodelled::NONE,
        ..SimulatedRig::default()
    };
    for sim in [before, every_field_changed(), ideal()] {
        let config = LoopConfig {
            duration: 1.5,
            ..LoopConfig::default()
        };
        let closed = {
            let clock = VirtualClock::new();
            let rig = sim.rig(&Clock::Virtual(clock.clone())).unwrap();
            run(rig, law, |_| vector![0.02], &Clock::Virtual(clock), &config)
                .unwrap()
                .recording
        };
        let open = {
            let clock = VirtualClock::new();
            let rig = sim.rig(&Clock::Virtual(clock.clone())).unwrap();
            let square = |t: f64| vector![if (t * 3.0) as i64 % 2 == 0 { 5.0 } else { -4.0 }];
            run(rig, OpenLoop, square, &Clock::Virtual(clock), &config)
                .unwrap()
                .recording
        };
        let predicted = ctrlab::sim::run_sampled(
            sim.plant(),
            sim.sensor(),
            law,
            |_| vector![0.02],
            SVector::from(sim.initial_state),
            &sim.sampled_config(1.5),
        )
        .unwrap();
        // The runs move the carts: the hashes pin behaviour, not a rest.
        let x2 = closed.channel("x2").unwrap();
        assert!(x2[x2.len() - 1] > 0.005, "{}", x2[x2.len() - 1]);
        let x2 = open.channel("x2").unwrap();
        let range = x2.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        assert!(range > 0.002, "{range}");
        let model = sim.simulation_model();
        let scalars = [
            sim.metres_per_count(),
            model.max_substep,
            model.input_delay,
            model.stiction_ratio[0],
            model.stiction_ratio[1],
        ];
        hashes.push([
            bits(&closed),
            bits(&open),
            bits(&predicted),
            scalars
                .iter()
                .fold(0, |h: u64, v| h.rotate_left(7) ^ v.to_bits()),
        ]);
    }
    assert_eq!(hashes, EXPECTED_BITS, "{hashes:#x?}");
}

/// Per rig (default, every field changed, ideal): the closed loop, the
/// open loop, the sampled-data prediction, and the scalars.
const EXPECTED_BITS: [[u64; 4]; 3] = [
    [
        0x37a2_671a_7b5b_e822,
        0x9162_0aef_3754_fa0b,
        0x1c67_e2ae_06d2_60a0,
        0x71e0_99cd_6a5b_44c6,
    ],
    [
        0x2608_bb43_ce9a_7a0f,
        0x1491_a858_7c36_973e,
        0x7dc0_b7b8_1c31_99b5,
        0x8b9d_88a4_f682_4725,
    ],
    [
        0xb8a1_5d25_28ec_5fd3,
        0x2987_65ee_ee30_3d06,
        0x3dfb_653e_298b_ee3b,
        0x9a30_bf72_8c69_a1bd,
    ],
];
