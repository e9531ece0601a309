//! The fixed-period loop through the full driver stack
//! (`MassSpringRig` → `Pc104` → `SimulatedCard`): agreement with the design
//! module's simulation, and failing safe.
//!
//! Checks of the loop's and the driver's exact behaviour run on
//! [`SimulatedRig::ideal`] (no friction, stiction, PWM delay or noise: the
//! card's duty is the last one written, and linear references apply); runs
//! meant to look like the lab's run on the realistic default rig. The
//! fault-injection tests of issue 9 are in `faults.rs`.

// Built on the two-cart lab (its plant, simulated rig or card).
#![cfg(feature = "lab")]

use ctrlab::hw::testing::RecordingPort;
use ctrlab::hw::{
    Clock, EppPort, LoopConfig, LoopFault, LoopFaultKind, Pc104, PortErrorKind, Rig, RigError,
    SimulatedCard, VirtualClock, run,
};
use ctrlab::lab::{
    Calibration, CardSettings, FrictionPlant, LabGains, MassSpringRig, SimulatedRig,
};
use ctrlab::signal::{Signal, SquareWave};
use ctrlab::{Cart, Controller, Discretization, MassSpring, OpenLoop, StepInfoOptions, step_info};
use nalgebra::{SVector, vector};
use proptest::prelude::*;

const PERIOD: f64 = 0.002;
/// EPP cycles of one tick: latch+kick (2), two 4-byte counters (16), PWM (4).
const CYCLES_PER_TICK: usize = 22;
/// EPP cycles of the ID probe when a rig is built (address write, data read).
const PROBE_CYCLES: usize = 2;

/// The lab's simulated card (the two carts with friction inside).
type Card = SimulatedCard<FrictionPlant, 4>;

fn card(config: SimulatedRig) -> (VirtualClock, Card) {
    let clock = VirtualClock::new();
    let card = config.card(&Clock::Virtual(clock.clone())).unwrap();
    (clock, card)
}

/// The simulated rig in one call, over a fresh virtual clock.
fn sim_rig(config: SimulatedRig) -> (VirtualClock, MassSpringRig<Card>) {
    let clock = VirtualClock::new();
    let rig = config.rig(&Clock::Virtual(clock.clone())).unwrap();
    (clock, rig)
}

/// The lab's rig on any port (a card behind a fault-injecting port), timed
/// on the card's virtual clock.
fn rig<P: EppPort>(port: P, clock: &VirtualClock) -> MassSpringRig<P> {
    let clock = Clock::Virtual(clock.clone());
    MassSpringRig::with_clock(Pc104::new(port), Calibration::default(), PERIOD, clock).unwrap()
}

/// The default truth without friction, stiction, PWM delay or noise.
fn ideal() -> SimulatedRig {
    SimulatedRig::ideal(SimulatedRig::default_truth())
}

fn config(duration: f64) -> LoopConfig {
    LoopConfig {
        duration,
        ..LoopConfig::default()
    }
}

/// The sampled loop as the design module sees it, with no driver, no
/// registers and no quantisation: the exact ZOH plant at T = 2 ms, the same
/// `StateFeedback`, and the state measured as the rig measures it (positions,
/// velocities by backward difference over one period).
fn sampled_simulation(
    plant: &MassSpring,
    mut controller: impl Controller<4, 1, 1>,
    setpoint: f64,
    ticks: usize,
) -> Vec<f64> {
    let d = plant
        .state_space(Cart::Two)
        .unwrap()
        .discretize(PERIOD, Discretization::Zoh)
        .unwrap();
    let mut x = SVector::<f64, 4>::zeros();
    let mut previous = x;
    let mut x2 = Vec::with_capacity(ticks);
    for _ in 0..ticks {
        let measured = vector![
            x[0],
            (x[0] - previous[0]) / PERIOD,
            x[2],
            (x[2] - previous[2]) / PERIOD
        ];
        previous = x;
        let u = controller.update(&measured, &vector![setpoint]);
        x2.push(x[2]);
        d.advance_mut(&mut x, &u);
    }
    x2
}

#[test]
fn table2_row_through_the_full_stack_matches_the_simulation() {
    // Truth = the nominal model (1 N/V), no noise, no friction or stiction,
    // no PWM delay (the ideal rig), the lab's 30 mm setpoint. At 1 N/V the loop asks for up to 300 V (10 V/mm
    // × 30 mm), which a 24 V drive would clip: saturation is a nonlinearity
    // the linear design model does not have, so this check of the driver
    // stack gives the card a 400 V supply (PWM steps of 0.4 V) to compare
    // like with like. Saturation itself is exercised by the lab5 rig runs.
    let truth = MassSpring::nominal();
    let supply = 400.0;
    let clock = VirtualClock::new();
    let sim = SimulatedRig {
        calibration: Calibration {
            volts_full_scale: supply,
            ..Calibration::default()
        },
        ..SimulatedRig::ideal(truth)
    };
    let gains = [0.0, 0.0, 10.0, 0.1];
    let ctrl = LabGains::new(gains, Cart::Two).state_feedback().unwrap();
    let setpoint = 0.030;
    // The simulated rig's calibration has the card's supply as full scale.
    assert_eq!(sim.calibration.volts_full_scale, supply);
    // 300 N on cart 2 drives it past the 2 m/s that the lab's 24 V motor
    // can reach (the rig would call that a bus fault): this unphysical drive
    // needs a looser plausibility limit, well above the run's peak speed
    // (printed: 2.007 m/s, at the 5th sample).
    let calibration = Calibration {
        max_speed: 10.0,
        ..sim.calibration
    };
    let virtual_clock = Clock::Virtual(clock.clone());
    let card = Pc104::new(sim.card(&virtual_clock).unwrap());
    let rig = MassSpringRig::with_clock(card, calibration, PERIOD, virtual_clock).unwrap();
    let out = run(
        rig,
        ctrl,
        |_| vector![setpoint],
        &Clock::Virtual(clock),
        &config(2.0),
    )
    .unwrap();
    let rec = out.recording;
    assert_eq!(rec.len(), 1000);
    let u = rec.channel("u").unwrap();
    assert!(u.iter().all(|u| u.abs() < supply), "no saturation");
    let (t, x2) = (rec.time(), rec.channel("x2").unwrap());
    let peak = rec
        .channel("v2")
        .unwrap()
        .iter()
        .fold(0.0f64, |m, v| m.max(v.abs()));
    println!("peak speed of cart 2: {peak} m/s");

    let sim = sampled_simulation(&truth, ctrl, setpoint, rec.len());
    let mm = |v: &[f64]| v.iter().map(|x| x * 1e3).collect::<Vec<_>>();
    let options = StepInfoOptions {
        reference: Some(setpoint * 1e3),
        ..Default::default()
    };
    let on_rig = step_info(t, &mm(x2), &options).unwrap();
    let simulated = step_info(t, &mm(&sim), &options).unwrap();
    println!("rig {on_rig:?}\nsim {simulated:?}");
    assert!((on_rig.overshoot - simulated.overshoot).abs() < 1.0);
    assert!((on_rig.settling_time - simulated.settling_time).abs() < 0.010);
    // Steady state within a few encoder counts (9.77 µm each).
    assert!((on_rig.steady_state_value - simulated.steady_state_value).abs() < 0.03);

    // And the sampled loop is close to the continuous design: the 2 ms
    // sampling costs a few points of overshoot at most for these poles.
    let plant = truth.state_space(Cart::Two).unwrap();
    let cl = ctrl.closed_loop(&plant).unwrap();
    let continuous = ctrlab::step_info_of(&cl, 2.0, PERIOD, &StepInfoOptions::default()).unwrap();
    println!("continuous design {continuous:?}");
    assert!((on_rig.overshoot - continuous.overshoot).abs() < 5.0);
}

#[test]
fn a_virtual_run_is_reproducible_and_records_the_applied_voltage() {
    // The realistic rig (friction, stiction, PWM delay, noise): all of it
    // is deterministic for a given seed. ±5 V is 5.55 N on the 1.11 N/V
    // motor, enough to break cart 2 away (2.4 N), under the 6 V the stall
    // check watches.
    let make = || {
        let (clock, rig) = sim_rig(SimulatedRig {
            card: CardSettings {
                encoder_noise: 0.5,
                seed: 7,
                ..CardSettings::default()
            },
            ..Default::default()
        });
        let square = SquareWave::new(5.0, 0.2).unwrap();
        run(
            rig,
            OpenLoop,
            |t| vector![square.value(t)],
            &Clock::Virtual(clock),
            &config(1.0),
        )
        .unwrap()
    };
    let (a, b) = (make(), make());
    assert_eq!(a.recording, b.recording);
    // ±5 V is a whole number of 24 mV duty steps? 5/0.024 = 208.3: the card
    // applies 208 steps = 4.992 V, and that is what is recorded.
    assert!(
        a.recording
            .channel("u")
            .unwrap()
            .iter()
            .all(|u| (u.abs() - 4.992).abs() < 1e-12)
    );
    // And the carts moved (by far more than the noise): x2 swings by
    // millimetres (11 mm of static deflection each way without friction).
    let x2 = a.recording.channel("x2").unwrap();
    let swing = x2.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    assert!(swing > 0.005, "{swing}");
    let t = a.recording.time();
    assert!(t.windows(2).all(|w| ((w[1] - w[0]) - PERIOD).abs() < 1e-12));
    assert_eq!(a.stats.ticks, 500);
    assert_eq!(a.stats.overruns, 0);
}

#[test]
fn a_travel_limit_breach_halts_and_keeps_the_recording() {
    // The realistic rig: +24 V (26.6 N on the 1.11 N/V motor) would deflect
    // cart 2 by 54 mm at rest, and the step overshoots: past ±50 mm.
    let (clock, mut rig) = sim_rig(SimulatedRig::default());
    let err = run(
        &mut rig,
        OpenLoop,
        |_| vector![24.0],
        &Clock::Virtual(clock.clone()),
        &config(5.0),
    )
    .unwrap_err();
    assert_eq!(err.error.kind(), LoopFaultKind::TravelLimit);
    assert!(
        err.last_measurement.is_none(),
        "the breach is found in the read"
    );
    let n = err.recording.len();
    assert!(n > 10 && n < 2500, "{n} samples before the breach");
    assert!(
        err.recording
            .channel("x2")
            .unwrap()
            .iter()
            .all(|x| x.abs() <= 0.05)
    );
    // The halt was written; the drive takes it the PWM delay later.
    clock
        .advance(SimulatedRig::default().card.pwm_delay)
        .unwrap();
    rig.card_mut().port_mut().sync().unwrap();
    assert_eq!(rig.card().port().pwm_duty(0), 0);
}

#[test]
fn a_non_finite_command_halts_the_same_way() {
    struct NanAfter(usize);
    impl Controller<4, 1, 1> for NanAfter {
        fn update(&mut self, _y: &SVector<f64, 4>, _r: &SVector<f64, 1>) -> SVector<f64, 1> {
            self.0 = self.0.saturating_sub(1);
            vector![if self.0 == 0 { f64::NAN } else { 3.0 }]
        }
    }
    // No PWM delay: the card's duty is the halt as soon as it is written.
    let (clock, mut rig) = sim_rig(ideal());
    let err = run(
        &mut rig,
        NanAfter(11),
        |_| vector![0.0],
        &Clock::Virtual(clock),
        &config(1.0),
    )
    .unwrap_err();
    assert_eq!(err.error.kind(), PortErrorKind::InvalidCommand);
    assert_eq!(err.recording.len(), 10);
    assert!(
        err.last_measurement.is_some(),
        "the failing tick's state is kept"
    );
    assert_eq!(rig.card().port().pwm_duty(0), 0);
    assert!(err.to_string().contains("10 samples"));
}

#[test]
fn a_dead_port_leaves_the_motor_to_the_watchdog() {
    // Every cycle fails from tick 50 on, so even the halt cannot reach the
    // card: the last duty stays until the card's watchdog (100 ms) trips.
    // No PWM delay, so the watchdog's trip is the only change of duty.
    let (clock, card) = card(ideal());
    let port = RecordingPort::new(card).fail_from(PROBE_CYCLES + 50 * CYCLES_PER_TICK);
    let mut rig = rig(port, &clock);
    let err = run(
        &mut rig,
        OpenLoop,
        |_| vector![6.0],
        &Clock::Virtual(clock.clone()),
        &config(1.0),
    )
    .unwrap_err();
    assert_eq!(err.error.kind(), PortErrorKind::Timeout);
    assert_eq!(err.recording.len(), 50);
    assert_eq!(
        rig.card().port().inner().pwm_duty(0),
        250,
        "6 V still applied"
    );
    // The run ended at the tick-50 deadline, 100 ms; the last kick was tick
    // 49's latch at 98 ms, so the watchdog trips at 198 ms.
    clock.advance(0.097).unwrap();
    let card = rig.card_mut().port_mut().inner_mut();
    card.sync().unwrap();
    assert_eq!(card.pwm_duty(0), 250, "not yet at 197 ms");
    clock.advance(0.002).unwrap();
    card.sync().unwrap();
    assert_eq!(card.pwm_duty(0), 0, "the watchdog zeroed the PWM");
}

#[test]
fn overruns_stop_the_loop_safely() {
    /// A controller that takes longer than the period, every time.
    struct Slow;
    impl Controller<4, 1, 1> for Slow {
        fn update(&mut self, _y: &SVector<f64, 4>, _r: &SVector<f64, 1>) -> SVector<f64, 1> {
            std::thread::sleep(std::time::Duration::from_millis(3));
            vector![1.0]
        }
    }
    // No PWM delay: the card's duty is the halt as soon as it is written.
    let mut rig = ideal().rig(&Clock::RealTime).unwrap();
    let cfg = LoopConfig {
        duration: 1.0,
        max_timing_faults: 3,
        ..LoopConfig::default()
    };
    let err = run(&mut rig, Slow, |_| vector![0.0], &Clock::RealTime, &cfg).unwrap_err();
    assert_eq!(err.error.kind(), LoopFaultKind::Timing);
    // Each 3 ms tick overruns and makes the loop skip the deadline it
    // overran: two faults a tick, so three faults end it in the second.
    assert!(
        matches!(
            err.error,
            RigError::Fault(LoopFault::TimingFaults { faults: 3, .. })
        ),
        "{}",
        err.error
    );
    assert!(err.recording.len() <= 2, "{}", err.recording.len());
    assert!(err.stats.overruns + err.stats.skipped >= 3);
    assert_eq!(rig.card().port().pwm_duty(0), 0);
}

#[test]
fn a_short_stall_is_skipped_not_caught_up() {
    /// Stalls 7 ms (3.5 periods) once, at tick 5.
    struct Stall(usize);
    impl Controller<4, 1, 1> for Stall {
        fn update(&mut self, _y: &SVector<f64, 4>, _r: &SVector<f64, 1>) -> SVector<f64, 1> {
            self.0 += 1;
            if self.0 == 6 {
                std::thread::sleep(std::time::Duration::from_millis(7));
            }
            vector![1.0]
        }
    }
    // No limit on timing faults within reach: a busy machine's own skipped
    // deadlines must not end this run; the limit is tested above.
    let cfg = LoopConfig {
        max_timing_faults: 10_000,
        ..config(0.05)
    };
    // Up to 5 attempts: a busy machine (a parallel build on two CPUs) can
    // take the CPU from the loop for more than 50 ms (an error), or between
    // the loop's time stamp and the rig's latch after the stall, which shows
    // as a speed that does not match the recorded interval. Neither is what
    // this test checks; a fault of the library shows in every attempt.
    // (Shorter hiccups only add gaps and skipped deadlines of their own,
    // which the checks below allow for.)
    let mut why = String::new();
    let out = (0..5)
        .find_map(|_| {
            // Without stiction, 1 V moves the carts (on the realistic rig
            // 1.1 N would not break cart 2 away), so the speed over the gap
            // is measurable.
            let rig = ideal().rig(&Clock::RealTime).unwrap();
            let attempt = run(rig, Stall(0), |_| vector![0.0], &Clock::RealTime, &cfg);
            why = match &attempt {
                Err(e) => e.to_string(),
                Ok(out) => match disturbance(out) {
                    None => return attempt.ok(),
                    Some(why) => why,
                },
            };
            println!("disturbed, trying again: {why}");
            None
        })
        .unwrap_or_else(|| panic!("every attempt was disturbed; the last: {why}"));
    let s = &out.stats;
    // Tick 5's work ends at least 7 ms after its deadline (10 ms), past
    // deadlines 12 and 14 ms at least: two or more are skipped, not run late.
    assert!(s.skipped >= 2, "{s:?}");
    assert!(s.overruns >= 1, "{s:?}");
    assert_eq!(s.ticks + s.skipped, 25, "{s:?}");
    let rec = &out.recording;
    assert_eq!(rec.len(), s.ticks);
    let t = rec.time();
    let gap = t.windows(2).map(|w| w[1] - w[0]).fold(0.0, f64::max);
    assert!(
        gap >= 3.0 * PERIOD - 1e-12,
        "the recording shows the gap: {gap}"
    );
    // The first sample after the stall (the 6th update, sample 5) has its
    // speed over the actual interval (the rig times its latches itself,
    // within microseconds of the loop).
    let after = 6;
    assert!(t[after] - t[after - 1] > 0.007, "{t:?}");
    let (x2, v2) = (rec.channel("x2").unwrap(), rec.channel("v2").unwrap());
    let over_gap = (x2[after] - x2[after - 1]) / (t[after] - t[after - 1]);
    assert!(over_gap != 0.0, "the cart moved during the gap");
    assert!(
        (v2[after] / over_gap - 1.0).abs() < 0.05,
        "speed {} vs {over_gap} over the gap",
        v2[after]
    );
    assert!(s.lateness_p50 <= s.lateness_p99 && s.lateness_p99 <= s.lateness_max);
}

/// What disturbed a run of `a_short_stall_is_skipped_not_caught_up`, if
/// anything did: so little of the CPU that it ran fewer than 7 of its 25
/// deadlines, or a speed after the stall (sample 6) more than 5 % from the
/// count change over the recorded interval.
fn disturbance(out: &ctrlab::hw::RunOutcome) -> Option<String> {
    let t = out.recording.time();
    if t.len() < 7 {
        return Some(format!("only {} samples: {}", t.len(), out.stats));
    }
    let (x2, v2) = (
        out.recording.channel("x2").ok()?,
        out.recording.channel("v2").ok()?,
    );
    let over_gap = (x2[6] - x2[5]) / (t[6] - t[5]);
    if (v2[6] / over_gap - 1.0).abs() >= 0.05 {
        return Some(format!("speed {} vs {over_gap} over the gap", v2[6]));
    }
    None
}

#[test]
fn a_reused_rig_starts_each_run_with_a_fresh_speed_estimate() {
    let (clock, mut rig) = sim_rig(SimulatedRig::default());
    let push = run(
        &mut rig,
        OpenLoop,
        |_| vector![6.0],
        &Clock::Virtual(clock.clone()),
        &config(0.5),
    )
    .unwrap();
    assert!(push.recording.channel("x2").unwrap().last().unwrap() > &0.005);
    clock.advance(1.0).unwrap(); // carts swing back while nobody looks
    let again = run(
        &mut rig,
        OpenLoop,
        |_| vector![0.0],
        &Clock::Virtual(clock),
        &config(0.1),
    )
    .unwrap();
    let v = again.recording.channel("v2").unwrap();
    // Not (x now − x at the end of the last run) / T.
    assert_eq!(v[0], 0.0);
    assert!(again.recording.channel("v1").unwrap()[0] == 0.0);
}

/// A controller designed for sampling period `.0` (s) that outputs nothing.
struct DesignedFor(f64);
impl Controller<4, 1, 1> for DesignedFor {
    fn update(&mut self, _y: &SVector<f64, 4>, _r: &SVector<f64, 1>) -> SVector<f64, 1> {
        vector![0.0]
    }
    fn period(&self) -> Option<f64> {
        Some(self.0)
    }
}

/// A rig that reports period `.1` and is otherwise rig `.0`: the loop has no
/// period of its own any more, it takes the rig's.
struct ClaimsPeriod<R>(R, f64);
impl<R: Rig<1, 4>> Rig<1, 4> for ClaimsPeriod<R> {
    fn read(&mut self) -> Result<SVector<f64, 4>, RigError> {
        self.0.read()
    }
    fn apply(&mut self, u: &SVector<f64, 1>) -> Result<SVector<f64, 1>, RigError> {
        self.0.apply(u)
    }
    fn halt(&mut self) -> Result<(), RigError> {
        self.0.halt()
    }
    fn period(&self) -> f64 {
        self.1
    }
    fn schema(&self) -> ctrlab::Schema {
        self.0.schema()
    }
}

#[test]
fn a_loop_at_another_period_than_the_rig_is_refused() {
    // The loop runs at the rig's period; a controller designed for another
    // one (here 1 ms on the 2 ms rig) is refused before anything runs.
    let (clock, mut rig) = sim_rig(SimulatedRig::default());
    let cfg = config(0.1);
    let err = run(
        &mut rig,
        DesignedFor(0.001),
        |_| vector![1.0],
        &Clock::Virtual(clock.clone()),
        &cfg,
    )
    .unwrap_err();
    assert!(matches!(
        err.error,
        RigError::Config(ref e) if e.key() == "period"
    ));
    assert!(err.recording.is_empty());
    assert_eq!(rig.card().port().pwm_duty(0), 0);
    // The same controller designed for the rig's 2 ms runs.
    let out = run(
        &mut rig,
        DesignedFor(PERIOD),
        |_| vector![1.0],
        &Clock::Virtual(clock),
        &cfg,
    )
    .unwrap();
    assert_eq!(out.recording.len(), 50);
}

#[test]
fn bad_loop_settings_are_refused_before_anything_runs() {
    let default = LoopConfig::default();
    // (loop settings, the period the rig reports, the field refused)
    for (cfg, period, name) in [
        (default.clone(), 0.0, "period"),
        (default.clone(), f64::NAN, "period"),
        (
            LoopConfig {
                duration: 0.001,
                ..LoopConfig::default()
            },
            PERIOD,
            "duration",
        ),
        (
            LoopConfig {
                duration: f64::INFINITY,
                ..LoopConfig::default()
            },
            PERIOD,
            "duration",
        ),
        (
            LoopConfig {
                max_timing_faults: 0,
                ..LoopConfig::default()
            },
            PERIOD,
            "max_timing_faults",
        ),
        (
            LoopConfig {
                timing_window: 0.0,
                ..LoopConfig::default()
            },
            PERIOD,
            "timing_window",
        ),
        (
            LoopConfig {
                max_gap: Some(0.001),
                ..LoopConfig::default()
            },
            PERIOD,
            "max_gap",
        ),
    ] {
        let (clock, mut rig) = sim_rig(SimulatedRig::default());
        let err = run(
            ClaimsPeriod(&mut rig, period),
            OpenLoop,
            |_| vector![1.0],
            &Clock::Virtual(clock),
            &cfg,
        )
        .unwrap_err();
        match err.error {
            RigError::Config(e) => assert_eq!(e.key(), name),
            other => panic!("{name}: {other}"),
        }
        assert!(err.recording.is_empty());
        assert_eq!(rig.card().port().pwm_duty(0), 0);
    }
    // The lab's rig itself refuses a period that is not finite and > 0.
    for period in [0.0, f64::NAN] {
        let bad = SimulatedRig {
            period,
            ..Default::default()
        };
        match bad.rig(&Clock::Virtual(VirtualClock::new())) {
            Err(RigError::Config(e)) => assert_eq!(e.key(), "period"),
            other => panic!("period {period}: {other:?}"),
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    #[test]
    fn a_fault_at_any_cycle_ends_the_run_with_everything_before_it(k in 0usize..(40 * CYCLES_PER_TICK)) {
        // No PWM delay: the card's duty is the halt as soon as it is written.
        let (clock, card) = card(ideal());
        let port = RecordingPort::new(card).fail_at(PROBE_CYCLES + k);
        let mut rig = rig(port, &clock);
        let result = run(&mut rig, OpenLoop, |_| vector![3.0], &Clock::Virtual(clock), &config(0.1));
        let err = result.expect_err("cycle k is inside the 50-tick run");
        prop_assert_eq!(err.error.kind(), PortErrorKind::Timeout);
        let tick = k / CYCLES_PER_TICK;
        prop_assert_eq!(err.recording.len(), tick);
        // Cut in the read (first 18 cycles) there is no state of that tick;
        // cut in the PWM write there is.
        prop_assert_eq!(err.last_measurement.is_some(), k % CYCLES_PER_TICK >= 18);
        prop_assert!(err.recording.channel("u").unwrap().iter().all(|u| (u - 3.0).abs() < 0.012));
        prop_assert_eq!(rig.card().port().inner().pwm_duty(0), 0);
    }
}

/// A rig whose halt panics: one state, its input echoed.
struct HaltPanics;

impl Rig<1, 1> for HaltPanics {
    fn read(&mut self) -> Result<SVector<f64, 1>, RigError> {
        Ok(vector![0.0])
    }
    fn apply(&mut self, u: &SVector<f64, 1>) -> Result<SVector<f64, 1>, RigError> {
        Ok(*u)
    }
    fn halt(&mut self) -> Result<(), RigError> {
        panic!("halt register write refused")
    }
    fn period(&self) -> f64 {
        0.01
    }
}

#[test]
fn a_panic_in_the_final_halt_is_an_error_that_keeps_the_recording() {
    let config = LoopConfig {
        duration: 0.1,
        ..LoopConfig::default()
    };
    let err = run(
        HaltPanics,
        OpenLoop,
        |_| vector![1.0],
        &Clock::Virtual(VirtualClock::new()),
        &config,
    )
    .unwrap_err();
    match &err.error {
        RigError::Fault(LoopFault::Panicked { what, message, .. }) => {
            assert_eq!(what.to_string(), "rig (halt)");
            assert_eq!(message.to_string(), "halt register write refused");
        }
        other => panic!("expected Panicked, got {other:?}"),
    }
    assert_eq!(err.recording.len(), 10, "every sample of the run is kept");
}

/// Real-time settings no Linux thread can take are refused by name before
/// the loop starts, nothing written to the card: a CPU beyond a CPU set's
/// 1024 (libc's bounds-checked `CPU_SET` used to abort the process) and a
/// spin longer than the period (`Duration::MAX` used to overflow the clock).
#[test]
fn impossible_real_time_settings_are_refused_by_name_before_the_loop() {
    use ctrlab::hw::RealTime;
    use std::time::Duration;
    let cases = [
        (
            "cpu",
            RealTime {
                cpu: Some(1024),
                ..RealTime::default()
            },
        ),
        (
            "cpu",
            RealTime {
                cpu: Some(usize::MAX),
                ..RealTime::default()
            },
        ),
        (
            "spin",
            RealTime {
                spin: Duration::MAX,
                ..RealTime::default()
            },
        ),
        (
            "spin",
            RealTime {
                spin: Duration::from_millis(3),
                ..RealTime::default()
            },
        ),
        (
            "priority",
            RealTime {
                priority: 0,
                ..RealTime::default()
            },
        ),
    ];
    for (key, rt) in cases {
        let (clock, mut rig) = sim_rig(ideal());
        let cfg = LoopConfig {
            duration: 0.01,
            realtime: Some(rt),
            ..LoopConfig::default()
        };
        let err = run(
            &mut rig,
            OpenLoop,
            |_| vector![0.0],
            &Clock::Virtual(clock),
            &cfg,
        )
        .unwrap_err();
        match &err.error {
            RigError::Config(c) => assert_eq!(c.key(), key, "{rt:?}: {}", err.error),
            other => panic!("{rt:?}: not a configuration error: {other}"),
        }
        assert!(err.recording.is_empty(), "{rt:?}: the loop ran");
    }
}
