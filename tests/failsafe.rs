//! The real rig in real time, and safe when it goes wrong: the fail-safes
//! behind the loop, each through the full stack (`hw::run` →
//! `MassSpringRig` → `Pc104` → the simulated card).
//!
//! - a dead encoder on the driven cart (cart 2), from the start or dying
//!   mid-run, halts the rig before the true cart passes its travel limit,
//!   and a drive held at its limit is halted after
//!   `Calibration::max_saturation_time`;
//! - a card without a watchdog is driven only when acknowledged, and the
//!   loop keeps a gap limit of its own;
//! - SIGINT, SIGTERM, SIGHUP, SIGQUIT and SIGTSTP each stop the run with its
//!   recording;
//! - a panic in `Controller::applied` or `Controller::reset` ends the run
//!   named, with the recording and the PWM at zero;
//! - halting zeroes every PWM channel of the card, not only the motor's.
//!
//! At small drives and at both drive limits: `tests/failsafe_small_drive.rs`.
//!
//! The true plant state comes from the simulated card
//! (`SimulatedCard::true_state`), never from the encoders under test.

// Built on the two-cart lab (its plant, simulated rig or card).
#![cfg(feature = "lab")]

mod common;

use common::{assert_recorded, loop_config as config};
use std::time::Duration;

use ctrlab::hw::testing::{Cycle, RecordingPort};
use ctrlab::hw::{
    Clock, ConfigErrorKind, GAP_PERIODS, LoopConfig, LoopFault, LoopFaultKind, PWM_CHANNELS, Pc104,
    Rig, RigError, RunError, SimulatedCard, VirtualClock, run,
};
use ctrlab::lab::{
    Calibration, Cart, FrictionPlant, LabGains, MassSpring, MassSpringRig, RigConfig, SimulatedRig,
};
use ctrlab::nalgebra::{SVector, vector};
use ctrlab::{Controller, OpenLoop, Schema};

const PERIOD: f64 = 0.002;

/// The lab's simulated card (two carts with friction inside).
type Card = SimulatedCard<FrictionPlant, 4>;
/// The lab's rig on it.
type SimRig = MassSpringRig<Card>;

/// `sim`'s card on `clock` read by a rig with `calibration` (which may wire
/// the carts differently from the card).
fn rig_with(sim: &SimulatedRig, calibration: Calibration, clock: &Clock) -> SimRig {
    let card = Pc104::with_map(sim.card(clock).unwrap(), sim.card.map).unwrap();
    MassSpringRig::with_clock(card, calibration, sim.period, clock.clone()).unwrap()
}

/// Every PWM channel of the card applies 0, once the PWM delay has passed.
fn assert_every_channel_off(rig: &mut SimRig, clock: &VirtualClock) {
    clock
        .advance(SimulatedRig::default().card.pwm_delay)
        .unwrap();
    let card = rig.card_mut().port_mut();
    card.sync().unwrap();
    for channel in 0..PWM_CHANNELS {
        assert_eq!(card.pwm_duty(channel), 0, "PWM channel {channel}");
    }
}

/// A rig that passes everything to the lab's rig inside and, at every read,
/// notes how far each true cart has gone from its rest position (m).
struct Watched<'a> {
    rig: &'a mut SimRig,
    furthest: [f64; 2],
}

impl Watched<'_> {
    fn note(&mut self) {
        let x = self.rig.card().port().true_state();
        for cart in 0..2 {
            self.furthest[cart] = self.furthest[cart].max(x[2 * cart].abs());
        }
    }
}

impl Rig<1, 4> for Watched<'_> {
    fn read(&mut self) -> Result<SVector<f64, 4>, RigError> {
        let y = self.rig.read();
        self.note();
        y
    }
    fn apply(&mut self, u: &SVector<f64, 1>) -> Result<SVector<f64, 1>, RigError> {
        self.rig.apply(u)
    }
    fn halt(&mut self) -> Result<(), RigError> {
        self.rig.halt()
    }
    fn period(&self) -> f64 {
        Rig::period(&*self.rig)
    }
    fn schema(&self) -> Schema {
        self.rig.schema()
    }
    fn watchdog_timeout(&self) -> Option<f64> {
        self.rig.watchdog_timeout()
    }
    fn restart(&mut self) {
        self.rig.restart();
    }
}

/// Lets the halted carts coast for `seconds` on the card's clock and
/// returns how far each true cart went meanwhile (m), `furthest` included.
fn coast(rig: &mut SimRig, clock: &VirtualClock, seconds: f64, furthest: [f64; 2]) -> [f64; 2] {
    let mut furthest = furthest;
    for _ in 0..(seconds / 1e-3).round() as usize {
        clock.advance(1e-3).unwrap();
        let card = rig.card_mut().port_mut();
        card.sync().unwrap();
        let x = card.true_state();
        for cart in 0..2 {
            furthest[cart] = furthest[cart].max(x[2 * cart].abs());
        }
    }
    furthest
}

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
