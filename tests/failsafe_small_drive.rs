//! The fail-safes at small drives and at both drive limits, through the
//! full stack (`hw::run` -> `MassSpringRig` -> `Pc104` -> the simulated
//! card), split from `tests/failsafe.rs`:
//!
//! - a dead cart-2 encoder is caught during lab5's 2 V probe run (a drive
//!   that never changes by `stall_volts`), and the healthy rigs run every
//!   identification signal from 1 to 8 V without that fault;
//! - a square wave at full scale is not saturation at one end.

// Built on the two-cart lab (its plant, simulated rig or card).
#![cfg(feature = "lab")]

mod common;

use common::lighter;
use common::loop_config as config;

use ctrlab::OpenLoop;
use ctrlab::hw::{Clock, LoopFault, Pc104, RigError, RunError, VirtualClock, run};
use ctrlab::lab::{Calibration, MassSpringRig, SimulatedRig};
use ctrlab::nalgebra::vector;

const PERIOD: f64 = 0.002;

/// `sim`'s card on `clock` read by a rig with `calibration` (which may wire
/// the carts differently from the card).
fn rig_with(
    sim: &SimulatedRig,
    calibration: Calibration,
    clock: &Clock,
) -> MassSpringRig<ctrlab::hw::SimulatedCard<ctrlab::lab::FrictionPlant, 4>> {
    let card = Pc104::with_map(sim.card(clock).unwrap(), sim.card.map).unwrap();
    MassSpringRig::with_clock(card, calibration, sim.period, clock.clone()).unwrap()
}

/// An open-loop run of `input` on `sim` for `duration` s, read by a rig
/// with `calibration`.
fn open_loop(
    sim: &SimulatedRig,
    calibration: Calibration,
    input: &dyn ctrlab::signal::Signal,
    duration: f64,
) -> Result<ctrlab::hw::RunOutcome, Box<RunError>> {
    let clock = Clock::Virtual(VirtualClock::new());
    let rig = rig_with(sim, calibration, &clock);
    run(
        rig,
        OpenLoop,
        |t| vector![input.value(t)],
        &clock,
        &config(duration),
    )
}

#[test]
fn a_dead_cart_2_encoder_during_a_2_v_square_wave_probe_halts_with_encoder_not_following() {
    // The first probe run of lab5's identification input: ±2 V, 0.2 s half
    // period, 3 s. Its drive never changes by stall_volts (6 V) from rest,
    // so the old follow check could not arm, and the probe "measured" a
    // cart 2 that never moved.
    let sim = lighter();
    let cal = Calibration {
        encoder_channels: [0, 2],
        ..sim.calibration
    };
    let wave = ctrlab::signal::SquareWave::new(2.0, 0.2).unwrap();
    let err = open_loop(&sim, cal, &wave, 3.0).expect_err("the dead encoder is caught");
    let (volts, seconds, moved) = match err.error {
        RigError::Fault(LoopFault::EncoderNotFollowing {
            cart,
            channel,
            other,
            volts,
            seconds,
            moved,
            counts,
        }) => {
            assert_eq!((cart, channel, other, counts), (2, 2, 1, cal.stall_counts));
            (volts, seconds, moved)
        }
        ref other => panic!("expected EncoderNotFollowing, got {other:?}"),
    };
    assert!((volts - 2.0).abs() < 0.03, "{volts}");
    // Still for the stall time, cart 1 moving 1 mm (103 counts) in 0.1 s.
    assert!(seconds >= cal.stall_time && seconds < 1.0, "{seconds}");
    assert!(moved as f64 * cal.metres_per_count >= 0.001, "{moved}");
    let t = *err.recording.time().last().unwrap();
    println!(
        "dead encoder at 2 V: caught at t = {t:.3} s, cart 1 moved {moved} counts in the last window"
    );
    assert!(t < 1.0, "{t}");
}

#[test]
fn the_healthy_rigs_run_every_ident_signal_without_an_encoder_fault() {
    // The dead-encoder check at small drives must not fire on a healthy
    // rig whose friction holds cart 2 while cart 1 rings: the default and
    // the lighter-damped rig, every identification signal, 1 to 8 V, the
    // probe and run seeds lab5 uses.
    use ctrlab::lab::ident_input::{IdentInput, IdentSignal};
    for (name, base) in [("default", SimulatedRig::default()), ("lighter", lighter())] {
        for signal in IdentSignal::ALL {
            for volts in [1.0, 2.0, 3.0, 4.0, 7.64, 8.0] {
                for seed in [1, 2, 3, 4, 5, 101, 102] {
                    let sim = SimulatedRig {
                        card: ctrlab::lab::CardSettings { seed, ..base.card },
                        ..base.clone()
                    };
                    let ident = IdentInput {
                        signal,
                        ..IdentInput::default()
                    };
                    let input = ident.input(volts, 5.0).unwrap();
                    if let Err(e) = open_loop(&sim, sim.calibration, &input, 5.0) {
                        assert!(
                            matches!(e.error, RigError::Fault(LoopFault::TravelLimit { .. })),
                            "{name} {signal} {volts} V seed {seed}: {}",
                            e.error
                        );
                    }
                }
            }
        }
    }
}

#[test]
fn a_full_scale_square_wave_is_not_saturation_at_one_end() {
    // ±24 V, flipping every 0.2 s, for 1 s with max_saturation_time 0.3 s:
    // at full scale all along, but never pushing one way for 0.3 s. The
    // old timer ran across the flips and halted at 0.3 s.
    let sim = SimulatedRig::default();
    let cal = Calibration {
        max_saturation_time: 0.3,
        travel_limits: [1.0, 1.0],
        ..sim.calibration
    };
    let clock = VirtualClock::new();
    let mut rig = rig_with(&sim, cal, &Clock::Virtual(clock.clone()));
    for k in 0..500 {
        let t = k as f64 * PERIOD;
        let volts = if (t / 0.2).floor() as i64 % 2 == 0 {
            30.0
        } else {
            -30.0
        };
        let applied = rig
            .apply_voltage(volts)
            .unwrap_or_else(|e| panic!("t = {t:.3} s: {e}"));
        assert_eq!(applied.abs(), 24.0);
        clock.advance(PERIOD).unwrap();
    }
    // Off for a tick, then held at +24 V: halted once it has been there
    // 0.3 s.
    rig.apply_voltage(0.0).unwrap();
    clock.advance(PERIOD).unwrap();
    let mut halted_at = None;
    for k in 0..500 {
        if let Err(e) = rig.apply_voltage(24.0) {
            assert!(
                matches!(e, RigError::Fault(LoopFault::Saturated { limit, .. }) if limit == 0.3),
                "{e}"
            );
            halted_at = Some(k as f64 * PERIOD);
            break;
        }
        clock.advance(PERIOD).unwrap();
    }
    let at = halted_at.expect("held at one end, it is halted");
    assert!((at - 0.3).abs() < 1.5 * PERIOD, "{at}");
}
