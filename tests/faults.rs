//! Issue 9's fault injection through the real stack (`hw::run` →
//! `MassSpringRig` → `Pc104` → the simulated card, or a faulty port): a
//! panicking controller or reference, a stalled controller, a flipped
//! counter bit, no card, the wrong card, a motor that does not respond, too
//! many overruns, a stop request and Ctrl-C, and a stalled tick that is
//! only recorded.
//!
//! After every fault the run has ended with an error that names it (kind
//! and message), the drive is off (the halt is the last PWM write on the
//! bus, and once the card's 0.15 ms PWM delay has passed the card's duty is
//! 0), and the recording holds every sample before the fault (its length
//! and its last time stamp are checked).
//!
//! Every rig here is the lab's realistic simulated rig
//! ([`SimulatedRig::default`]: friction, stiction, PWM delay, encoder noise)
//! unless a test says otherwise, behind a [`RecordingPort`] so the bus
//! traffic can be checked.

// Built on the two-cart lab (its plant, simulated rig or card).
#![cfg(feature = "lab")]

mod common;

use common::{assert_recorded, loop_config as config};
use std::time::Duration;

use ctrlab::hw::testing::{Cycle, RecordingPort, RegisterFile};
use ctrlab::hw::{
    Clock, EppPort, LoopConfig, LoopFault, LoopFaultKind, Pc104, PortError, PortErrorKind,
    RigError, RunError, RunOutcome, SimulatedCard, StopSignal, VirtualClock, run,
};
use ctrlab::lab::{Calibration, FrictionPlant, MassSpring, MassSpringRig, SimulatedRig};
use ctrlab::{Controller, OpenLoop};
use nalgebra::{SVector, vector};

const PERIOD: f64 = 0.002;

/// The lab's simulated card (two carts with friction inside).
type Card = SimulatedCard<FrictionPlant, 4>;
/// The lab's rig on the simulated card, every bus cycle logged.
type LoggedRig = MassSpringRig<RecordingPort<Card>>;

/// `sim`'s rig on `clock`, behind a port that logs every cycle, its speeds
/// and checks timed on `clock`.
fn logged_rig(sim: &SimulatedRig, clock: &Clock) -> LoggedRig {
    let port = RecordingPort::new(sim.card(clock).unwrap());
    MassSpringRig::with_clock(Pc104::new(port), sim.calibration, sim.period, clock.clone()).unwrap()
}

/// The realistic rig on a fresh virtual clock.
fn virtual_rig(sim: &SimulatedRig) -> (VirtualClock, LoggedRig) {
    let clock = VirtualClock::new();
    let rig = logged_rig(sim, &Clock::Virtual(clock.clone()));
    (clock, rig)
}

/// The PWM duties written to channel 0 (registers 0x10, 0x11), in order,
/// from a log of bus cycles.
fn pwm_writes(log: &[Cycle]) -> Vec<(u8, u8)> {
    let mut writes = Vec::new();
    let (mut address, mut low) = (None, None);
    for cycle in log {
        match *cycle {
            Cycle::AddressWrite(a) => address = Some(a),
            Cycle::DataWrite(v) if address == Some(0x10) => low = Some(v),
            Cycle::DataWrite(v) if address == Some(0x11) => {
                writes.push((low.take().expect("low byte first"), v));
            }
            _ => {}
        }
    }
    writes
}

/// The drive is off: the last PWM write on the bus is duty 0, and once the
/// PWM delay has passed (on the card's clock) the card applies 0.
fn assert_drive_off(rig: &mut LoggedRig, clock: &Clock) {
    let writes = pwm_writes(rig.card().port().log());
    assert_eq!(writes.last(), Some(&(0, 0)), "the halt is the last write");
    let delay = SimulatedRig::default().card.pwm_delay;
    match clock {
        Clock::Virtual(c) => c.advance(delay).unwrap(),
        // Well past the delay, well before the 100 ms watchdog.
        Clock::RealTime => std::thread::sleep(Duration::from_secs_f64(delay * 4.0)),
    }
    let card = rig.card_mut().port_mut().inner_mut();
    card.sync().unwrap();
    assert_eq!(card.pwm_duty(0), 0, "the card applies the halt");
}

/// The voltage the last recorded sample applied, V.
fn last_u(err: &RunError) -> f64 {
    *err.recording.channel("u").unwrap().last().unwrap()
}

/// Runs `attempt` until it returns `Ok`, at most 5 times, and returns that.
///
/// For the runs on the real-time clock: a busy machine (a parallel build on
/// two CPUs) can take the CPU from the loop for tens of milliseconds, which
/// the loop rightly reports (a gap, skipped deadlines) but which is not the
/// fault a test injects. An attempt returns `Err(why)` when its run shows
/// such a disturbance; a fault of the library shows in every attempt, and
/// the last reason is reported.
fn undisturbed<T>(mut attempt: impl FnMut() -> Result<T, String>) -> T {
    let mut why = String::new();
    for _ in 0..5 {
        match attempt() {
            Ok(value) => return value,
            Err(reason) => {
                println!("disturbed, trying again: {reason}");
                why = reason;
            }
        }
    }
    panic!("every attempt was disturbed; the last: {why}")
}

/// Drives a constant voltage and panics at its `at`-th update (counted from
/// 1) with a `&'static str` message.
struct PanicsAt {
    updates: usize,
    at: usize,
}

impl Controller<4, 1, 1> for PanicsAt {
    fn update(&mut self, _y: &SVector<f64, 4>, _r: &SVector<f64, 1>) -> SVector<f64, 1> {
        self.updates += 1;
        if self.updates == self.at {
            panic!("gain table index out of range");
        }
        vector![3.0]
    }
}

// ---- panics ------------------------------------------------------------------

#[test]
fn a_panicking_controller_halts_the_rig_and_keeps_the_recording() {
    // 3 V (3.3 N) moves the carts: the motor is on when the panic comes.
    let (clock, mut rig) = virtual_rig(&SimulatedRig::default());
    let controller = PanicsAt { updates: 0, at: 25 };
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
            assert_eq!(*what, "controller");
            assert_eq!(message, "gain table index out of range");
            assert!((at - 24.0 * PERIOD).abs() < 1e-12, "{at}");
        }
        other => panic!("expected Panicked, got {other:?}"),
    }
    let text = err.error.to_string();
    assert!(
        text.contains("controller panicked") && text.contains("gain table index"),
        "{text}"
    );
    // Ticks 0–23 recorded; tick 24's measurement was read, its command
    // never computed.
    assert_recorded(&err, 24, 23.0 * PERIOD);
    assert!(err.last_measurement.is_some());
    assert!((last_u(&err) - 3.0).abs() < 0.012, "the motor was on");
    assert_drive_off(&mut rig, &Clock::Virtual(clock));
}

#[test]
fn a_panicking_reference_halts_the_rig_and_keeps_the_recording() {
    let (clock, mut rig) = virtual_rig(&SimulatedRig::default());
    let reference = |t: f64| {
        if t >= 0.05 - 1e-9 {
            // A String message, formatted at run time.
            panic!("no setpoint defined after {t:.3} s");
        }
        vector![3.0]
    };
    let err = run(
        &mut rig,
        OpenLoop,
        reference,
        &Clock::Virtual(clock.clone()),
        &config(1.0),
    )
    .unwrap_err();
    assert_eq!(err.error.kind(), LoopFaultKind::Panic);
    match &err.error {
        RigError::Fault(LoopFault::Panicked { what, message, at }) => {
            assert_eq!(*what, "reference");
            assert_eq!(message, "no setpoint defined after 0.050 s");
            assert!((at - 0.05).abs() < 1e-12, "{at}");
        }
        other => panic!("expected Panicked, got {other:?}"),
    }
    assert!(err.error.to_string().contains("reference panicked"));
    // Ticks 0–24 (0 … 48 ms) recorded; tick 25 was read, then the panic.
    assert_recorded(&err, 25, 24.0 * PERIOD);
    assert!(err.last_measurement.is_some());
    assert!((last_u(&err) - 3.0).abs() < 0.012, "the motor was on");
    assert_drive_off(&mut rig, &Clock::Virtual(clock));
}

// ---- a stalled controller ------------------------------------------------------

#[test]
fn a_controller_stalled_for_300_ms_is_a_gap_and_its_stale_command_never_reaches_the_motor() {
    /// 3 V, until its 11th update, which takes 300 ms and asks for 9 V.
    struct Stalls(usize);
    impl Controller<4, 1, 1> for Stalls {
        fn update(&mut self, _y: &SVector<f64, 4>, _r: &SVector<f64, 1>) -> SVector<f64, 1> {
            self.0 += 1;
            if self.0 == 11 {
                std::thread::sleep(Duration::from_millis(300));
                return vector![9.0];
            }
            vector![3.0]
        }
    }
    let clock = Clock::RealTime;
    // No limit on timing faults within reach: a busy machine's own hiccups
    // (skipped deadlines) must not end the run before the stall does.
    let cfg = LoopConfig {
        max_timing_faults: 10_000,
        ..config(1.0)
    };
    let (mut rig, err) = undisturbed(|| {
        let mut rig = logged_rig(&SimulatedRig::default(), &clock);
        let err = match run(&mut rig, Stalls(0), |_| vector![0.0], &clock, &cfg) {
            Ok(_) => panic!("a 300 ms stall must end the run"),
            Err(err) => err,
        };
        // Disturbed: the machine held the loop past the 50 ms limit before
        // the stall (ten samples are taken before it).
        match err.error {
            RigError::Fault(LoopFault::Gap {
                what: "the controller",
                ..
            }) if err.recording.len() == 10 => Ok((rig, err)),
            ref other => Err(format!("{other} after {} samples", err.recording.len())),
        }
    });
    assert_eq!(err.error.kind(), LoopFaultKind::Timing);
    match &err.error {
        RigError::Fault(LoopFault::Gap {
            what,
            gap,
            limit,
            at,
        }) => {
            assert_eq!(*what, "the controller");
            assert!(*gap >= 0.3, "{gap}");
            // Half the card's 100 ms watchdog timeout, by default.
            assert_eq!(*limit, 0.05);
            // The 11th update belongs to a tick at or after the 11th
            // deadline (later only if deadlines were skipped on a busy
            // machine).
            assert!(*at >= 10.0 * PERIOD - 1e-9, "{at}");
        }
        other => panic!("expected a Gap, got {other:?}"),
    }
    let text = err.error.to_string();
    assert!(
        text.contains("the controller took") && text.contains("half the watchdog"),
        "{text}"
    );
    // The ten ticks before it are recorded (real time: the last one at or
    // after its deadline, 18 ms, and before the stalled tick).
    assert_eq!(err.recording.len(), 10);
    let last = *err.recording.time().last().unwrap();
    let RigError::Fault(LoopFault::Gap { at, .. }) = err.error else {
        unreachable!()
    };
    assert!(last >= 9.0 * PERIOD && last < at, "{last} vs {at}");
    assert!(err.last_measurement.is_some(), "the stalled tick's read");
    // 9 V is duty 375 = 0x177: never written. The card's watchdog had cut
    // the motor 100 ms into the stall; a write now would have re-energised
    // it with a command computed from a 300 ms old measurement.
    let writes = pwm_writes(rig.card().port().log());
    assert!(!writes.contains(&(0x77, 0x01)), "{writes:?}");
    assert!(
        writes.contains(&(125, 0)),
        "3 V (duty 125) was applied before"
    );
    assert_drive_off(&mut rig, &clock);
}

// ---- the bus: a flipped bit, no card, another card ----------------------------

/// Passes every cycle to the port inside, except that the `nth` data read
/// (counted from 0) of register `address` has `mask` XORed in: one flipped
/// bit on the bus.
struct FlipBit<P> {
    inner: P,
    address: u8,
    nth: usize,
    mask: u8,
    selected: Option<u8>,
    reads: usize,
}

impl<P: EppPort> EppPort for FlipBit<P> {
    fn write_address(&mut self, address: u8) -> Result<(), PortError> {
        self.selected = Some(address);
        self.inner.write_address(address)
    }
    fn read_data(&mut self) -> Result<u8, PortError> {
        let mut value = self.inner.read_data()?;
        if self.selected == Some(self.address) {
            if self.reads == self.nth {
                value ^= self.mask;
            }
            self.reads += 1;
        }
        Ok(value)
    }
    fn write_data(&mut self, value: u8) -> Result<(), PortError> {
        self.inner.write_data(value)
    }
}

/// The lab's rig on the simulated card behind a [`FlipBit`], every bus
/// cycle logged.
type FlippingRig = MassSpringRig<RecordingPort<FlipBit<Card>>>;

/// The realistic rig behind a [`FlipBit`] on cart 2's counter byte 1
/// (register 0x25) at its `nth` read, run at 3 V for 1 s.
fn run_with_flipped_bit(
    nth: usize,
    mask: u8,
) -> (VirtualClock, FlippingRig, Result<RunOutcome, Box<RunError>>) {
    let sim = SimulatedRig::default();
    let clock = VirtualClock::new();
    let virtual_clock = Clock::Virtual(clock.clone());
    let port = FlipBit {
        inner: sim.card(&virtual_clock).unwrap(),
        address: 0x25,
        nth,
        mask,
        selected: None,
        reads: 0,
    };
    let mut rig = MassSpringRig::with_clock(
        Pc104::new(RecordingPort::new(port)),
        sim.calibration,
        PERIOD,
        virtual_clock.clone(),
    )
    .unwrap();
    let result = run(
        &mut rig,
        OpenLoop,
        |_| vector![3.0],
        &virtual_clock,
        &config(1.0),
    );
    (clock, rig, result)
}

#[test]
fn a_flipped_counter_bit_is_a_bus_fault_not_a_measurement() {
    // Bit 3 of cart 2's counter byte 1 at tick 30's read: 0x0800 = 2048
    // counts, 20 mm in 2 ms, 10 m/s: five times what the carts can do.
    let (clock, mut rig, result) = run_with_flipped_bit(30, 0x08);
    let err = result.unwrap_err();
    assert_eq!(err.error.kind(), LoopFaultKind::BusFault);
    match err.error {
        RigError::Fault(LoopFault::BusFault {
            channel,
            counts,
            interval,
            speed,
            limit,
        }) => {
            assert_eq!(channel, 1, "cart 2's encoder");
            // ±2048 plus a few counts of true motion and noise in 2 ms.
            assert!((counts.abs() - 2048).abs() < 50, "{counts}");
            assert!((interval - PERIOD).abs() < 1e-12);
            assert!(speed.abs() > 9.0 && speed.abs() < 11.0, "{speed}");
            assert_eq!(limit, Calibration::default().max_speed);
        }
        ref other => panic!("expected a BusFault, got {other:?}"),
    }
    let text = err.error.to_string();
    assert!(
        text.contains("bus fault") && text.contains("encoder 1"),
        "{text}"
    );
    // Ticks 0–29 recorded; tick 30's read is not a measurement.
    assert_recorded(&err, 30, 29.0 * PERIOD);
    assert!(err.last_measurement.is_none());
    assert!(
        err.recording
            .channel("x2")
            .unwrap()
            .iter()
            .all(|x| x.abs() < 0.01),
        "the corrupt count is not in the recording"
    );
    assert!((last_u(&err) - 3.0).abs() < 0.012, "the motor was on");
    // The drive is off: the halt was the last write, and the card applies it.
    let writes = pwm_writes(rig.card().port().log());
    assert_eq!(writes.last(), Some(&(0, 0)));
    clock
        .advance(SimulatedRig::default().card.pwm_delay)
        .unwrap();
    let card = &mut rig.card_mut().port_mut().inner_mut().inner;
    card.sync().unwrap();
    assert_eq!(card.pwm_duty(0), 0);
}

#[test]
fn a_flipped_low_bit_is_within_what_the_carts_can_do() {
    // The check is physical plausibility, not parity: bit 0 of byte 1 is
    // 256 counts, 2.5 mm in 2 ms, 1.25 m/s: a speed the carts can reach,
    // so it passes as a (wrong) measurement and the run goes on.
    let (_clock, _rig, result) = run_with_flipped_bit(30, 0x01);
    let out = result.unwrap();
    assert_eq!(out.recording.len(), 500);
}

#[test]
fn an_open_bus_is_no_card_and_nothing_is_written() {
    // An empty port reads all ones (or all zeros): the rig refuses to be
    // built after one read of the ID register, without a single write.
    for open in [0xff, 0x00] {
        let mut registers = RegisterFile::new();
        for address in 0..=255 {
            registers.set(address, open);
        }
        let mut port = RecordingPort::new(registers);
        let err =
            MassSpringRig::new(Pc104::new(&mut port), Calibration::default(), PERIOD).unwrap_err();
        assert_eq!(err.kind(), PortErrorKind::NotPresent, "{open:#04x}");
        let text = err.to_string();
        assert!(
            text.contains(&format!("reads {open:#04x}"))
                && text.contains("open bus")
                && text.contains("expected 0xa5"),
            "{text}"
        );
        assert_eq!(
            port.log(),
            &[Cycle::AddressWrite(0x00), Cycle::DataRead(open)]
        );
        assert!(
            !port.log().iter().any(|c| matches!(c, Cycle::DataWrite(_))),
            "no register was written"
        );
    }
}

#[test]
fn another_card_is_refused() {
    // A register file answering another ID.
    let mut registers = RegisterFile::new();
    registers.set(0x00, 0x3c);
    let mut port = RecordingPort::new(registers);
    let err =
        MassSpringRig::new(Pc104::new(&mut port), Calibration::default(), PERIOD).unwrap_err();
    assert_eq!(err.kind(), PortErrorKind::NotPresent);
    assert!(
        err.to_string().contains("another card answers")
            && err.to_string().contains("reads 0x3c, expected 0xa5"),
        "{err}"
    );
    assert_eq!(
        port.log(),
        &[Cycle::AddressWrite(0x00), Cycle::DataRead(0x3c)]
    );
    // A simulated card with another ID, against the lab's calibration.
    let other = SimulatedRig {
        calibration: Calibration {
            card_id: 0x5a,
            ..Calibration::default()
        },
        ..SimulatedRig::default()
    };
    let card = other.card(&Clock::Virtual(VirtualClock::new())).unwrap();
    let err = MassSpringRig::new(Pc104::new(card), Calibration::default(), PERIOD).unwrap_err();
    assert_eq!(err.kind(), PortErrorKind::NotPresent);
    assert!(err.to_string().contains("reads 0x5a"), "{err}");
    // Built as one, the simulated rig's calibration expects its own card.
    assert!(other.rig(&Clock::Virtual(VirtualClock::new())).is_ok());
}

// ---- a motor that does not respond ---------------------------------------------

#[test]
fn a_motor_that_does_not_respond_is_detected_and_halted() {
    // A card whose PWM does nothing: the realistic rig with no motor gain.
    let dead = SimulatedRig {
        truth: MassSpring {
            gain: 0.0,
            ..SimulatedRig::default_truth()
        },
        ..SimulatedRig::default()
    };
    let cal = dead.calibration;
    let (clock, mut rig) = virtual_rig(&dead);
    // 12 V (duty 500 exactly), well above the 6 V the check watches.
    let err = run(
        &mut rig,
        OpenLoop,
        |_| vector![12.0],
        &Clock::Virtual(clock.clone()),
        &config(2.0),
    )
    .unwrap_err();
    assert_eq!(err.error.kind(), LoopFaultKind::NotResponding);
    match err.error {
        RigError::Fault(LoopFault::NotResponding {
            volts,
            seconds,
            counts,
        }) => {
            assert_eq!(volts, 12.0);
            assert_eq!(counts, cal.stall_counts);
            assert!((seconds - cal.stall_time).abs() < 1e-9, "{seconds}");
        }
        ref other => panic!("expected NotResponding, got {other:?}"),
    }
    assert!(
        err.error.to_string().contains("not responding"),
        "{}",
        err.error
    );
    // The drive is applied at tick 0; the stall starts at the first read
    // that sees it, tick 1 (2 ms), and is declared at the read 0.5 s later,
    // tick 251 (502 ms): ticks 0–250 (0 … 500 ms) are recorded.
    assert_recorded(&err, 251, 0.5);
    assert!(err.last_measurement.is_none(), "found in the read");
    assert_eq!(last_u(&err), 12.0);
    assert_drive_off(&mut rig, &Clock::Virtual(clock));

    // The same drive on the healthy rig moves the carts: no fault.
    let (clock, mut rig) = virtual_rig(&SimulatedRig::default());
    let out = run(
        &mut rig,
        OpenLoop,
        |_| vector![12.0],
        &Clock::Virtual(clock),
        &config(2.0),
    )
    .unwrap();
    assert_eq!(out.recording.len(), 1000);
}

// ---- timing ----------------------------------------------------------------------

#[test]
fn too_many_overruns_stop_the_run() {
    /// Takes 3 ms, longer than the 2 ms period, every time.
    struct Slow;
    impl Controller<4, 1, 1> for Slow {
        fn update(&mut self, _y: &SVector<f64, 4>, _r: &SVector<f64, 1>) -> SVector<f64, 1> {
            std::thread::sleep(Duration::from_millis(3));
            vector![3.0]
        }
    }
    let clock = Clock::RealTime;
    let mut rig = logged_rig(&SimulatedRig::default(), &clock);
    let cfg = LoopConfig {
        duration: 1.0,
        max_timing_faults: 3,
        ..LoopConfig::default()
    };
    let err = run(&mut rig, Slow, |_| vector![0.0], &clock, &cfg).unwrap_err();
    assert_eq!(err.error.kind(), LoopFaultKind::Timing);
    let at = match err.error {
        RigError::Fault(LoopFault::TimingFaults {
            faults,
            window,
            period,
            at,
        }) => {
            assert_eq!((faults, window, period), (3, 0.5, PERIOD));
            at
        }
        ref other => panic!("expected TimingFaults, got {other:?}"),
    };
    assert!(
        err.error.to_string().contains("3 timing faults"),
        "{}",
        err.error
    );
    // Each tick overruns, and the loop skips the deadline it overran: the
    // third fault comes in the second or third tick.
    let s = &err.stats;
    assert!(s.overruns + s.skipped >= 3, "{s:?}");
    assert!(s.overruns >= 1);
    // Every tick that completed is recorded, each before the fault: one or
    // two, or none if a busy machine kept the loop from its first deadline
    // long enough to skip three.
    let n = err.recording.len();
    assert!(n <= 3, "{n}");
    assert_eq!(n, s.ticks);
    if n > 0 {
        let last = *err.recording.time().last().unwrap();
        assert!(last < at, "{last} vs {at}");
        assert!((last_u(&err) - 3.0).abs() < 0.012, "the motor was on");
    }
    assert_drive_off(&mut rig, &clock);
}

#[test]
fn a_stalled_tick_is_recorded_as_a_gap_without_halting() {
    /// Stalls 7 ms (3.5 periods) once, in its 11th update; 3 V throughout.
    struct StallOnce(usize);
    impl Controller<4, 1, 1> for StallOnce {
        fn update(&mut self, _y: &SVector<f64, 4>, _r: &SVector<f64, 1>) -> SVector<f64, 1> {
            self.0 += 1;
            if self.0 == 11 {
                std::thread::sleep(Duration::from_millis(7));
            }
            vector![3.0]
        }
    }
    let clock = Clock::RealTime;
    // No limit on timing faults within reach: the stall alone makes three
    // (an overrun and two skipped deadlines), far from the default 25, but
    // a busy machine (a parallel build on two CPUs) skips deadlines of its
    // own, and this test is about the stall, not about that limit.
    let cfg = LoopConfig {
        max_timing_faults: 10_000,
        ..config(0.2)
    };
    // Disturbed: the machine held the loop past the 50 ms limit, or took
    // so much of its time that it ran fewer than 12 of its 100 deadlines
    // (shorter hiccups only add gaps and skipped deadlines of their own,
    // which the checks below allow for).
    let (mut rig, out) = undisturbed(|| {
        let mut rig = logged_rig(&SimulatedRig::default(), &clock);
        let out = run(&mut rig, StallOnce(0), |_| vector![0.0], &clock, &cfg)
            .map_err(|e| e.to_string())?;
        match out.recording.len() {
            12.. => Ok((rig, out)),
            n => Err(format!("only {n} samples: {}", out.stats)),
        }
    });
    let s = &out.stats;
    // The stalled tick's work ends 7 ms or more after its deadline: the
    // next deadlines (2, 4 and maybe 6 ms later) are skipped, not run late,
    // and each skipped deadline is a missing sample.
    assert!(s.skipped >= 2, "{s:?}");
    assert!(s.overruns >= 1, "{s:?}");
    assert_eq!(s.ticks + s.skipped, 100, "{s:?}");
    let rec = &out.recording;
    assert_eq!(rec.len(), s.ticks);
    // The time stamps are the actual sampling instants: the gap after the
    // stalled (11th) sample is there, at least the 7 ms of the stall.
    let t = rec.time();
    let gap = t[11] - t[10];
    assert!(gap > 0.007, "the recording shows the gap: {gap}");
    let longest = t.windows(2).map(|w| w[1] - w[0]).fold(0.0, f64::max);
    assert_eq!(s.max_interval, longest);
    // Lateness is measured against the deadlines that were run (the
    // skipped ones are counted above, not as lateness): its percentiles
    // are ordered.
    assert!(
        s.lateness_p50 <= s.lateness_p99
            && s.lateness_p99 <= s.lateness_p999
            && s.lateness_p999 <= s.lateness_max,
        "{s:?}"
    );
    // No halt: every deadline was either run or skipped (above), with the
    // motor on, and only the end of the run wrote the zero duty.
    assert!(
        rec.channel("u")
            .unwrap()
            .iter()
            .all(|u| (u - 3.0).abs() < 0.012)
    );
    let writes = pwm_writes(rig.card().port().log());
    assert_eq!(writes.iter().filter(|w| **w == (0, 0)).count(), 1);
    assert_drive_off(&mut rig, &clock);
}

// ---- stopping ----------------------------------------------------------------------

#[test]
fn a_stop_request_halts_the_rig_and_keeps_the_recording() {
    let stop = StopSignal::new();
    let (clock, mut rig) = virtual_rig(&SimulatedRig::default());
    let cfg = LoopConfig {
        stop: Some(stop.clone()),
        ..config(1.0)
    };
    let trigger = stop.clone();
    let err = run(
        &mut rig,
        OpenLoop,
        move |t| {
            if t >= 0.1 - 1e-9 {
                trigger.request();
            }
            vector![3.0]
        },
        &Clock::Virtual(clock.clone()),
        &cfg,
    )
    .unwrap_err();
    assert_interrupted(&err);
    assert_drive_off(&mut rig, &Clock::Virtual(clock));
    assert!(stop.is_requested());
}

/// Stopped at the tick after the request made in tick 50 (t = 0.1 s):
/// ticks 0–50 recorded, nothing read in tick 51.
fn assert_interrupted(err: &RunError) {
    assert_eq!(err.error.kind(), LoopFaultKind::Interrupted);
    match err.error {
        RigError::Fault(LoopFault::Interrupted { at }) => {
            assert!((at - 51.0 * PERIOD).abs() < 1e-12, "{at}")
        }
        ref other => panic!("expected Interrupted, got {other:?}"),
    }
    assert!(
        err.error.to_string().contains("interrupted"),
        "{}",
        err.error
    );
    assert_recorded(err, 51, 0.1);
    assert!(err.last_measurement.is_none());
    assert!((last_u(err) - 3.0).abs() < 0.012, "the motor was on");
}

#[cfg(target_os = "linux")]
#[test]
fn ctrl_c_and_sigterm_halt_the_rig_and_keep_the_recording() {
    // Registering replaces SIGINT's and SIGTERM's default action (ending
    // the process) for the whole test binary, so it must succeed before
    // anything raises them; from then on they only raise the flag.
    let stop = StopSignal::on_interrupt().expect("signal handlers registered");
    for signal in [libc::SIGINT, libc::SIGTERM] {
        stop.clear();
        let (clock, mut rig) = virtual_rig(&SimulatedRig::default());
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
                    // To this thread: the handler has run when raise returns.
                    // SAFETY: raise only sends a signal to the calling
                    // thread; its handler (signal-hook's) only stores a flag.
                    #[allow(unsafe_code)]
                    let rc = unsafe { libc::raise(signal) };
                    assert_eq!(rc, 0);
                }
                vector![3.0]
            },
            &Clock::Virtual(clock.clone()),
            &cfg,
        )
        .unwrap_err();
        assert_interrupted(&err);
        assert_drive_off(&mut rig, &Clock::Virtual(clock));
    }
}
