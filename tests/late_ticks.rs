//! Late ticks, from the loop to the analyses (the issue "The real rig in
//! real time, and safe when it goes wrong", items 1 and 2).
//!
//! - The rig's speeds and bus-fault check after a late tick, on a memory
//!   card whose counts and clock the test sets: one count over 5 µs is
//!   neither a fault nor a speed spike; many counts in a period still halt.
//! - Runs through `hw::run` on a virtual clock with a seeded [`Jitter`]
//!   schedule (late ticks, stalls of several periods): they complete, every
//!   late tick and skipped deadline is counted in `LoopStats` and seen in
//!   the recording's time stamps, and the recorded speeds are differences
//!   over at least 3/4 of a period.
//! - Identification, validation, refinement and bootstrap on such
//!   recordings, within the bounds they keep on the ideal clock.

// Built on the two-cart lab (its plant, simulated rig or card).
#![cfg(feature = "lab")]

use ctrlab::hw::testing::RegisterFile;
use ctrlab::hw::{
    Clock, Jitter, LATE_FRACTION, LoopConfig, LoopFault, LoopFaultKind, Pc104, RigError,
    RunOutcome, VirtualClock, run,
};
use ctrlab::lab::ident::{
    Bootstrap, MassSpringEstimate, Options, SimulationModel, SpringModel, bootstrap, identify_with,
    refine_with, validate_with,
};
use ctrlab::lab::{
    Calibration, CardSettings, Cart, Friction, LabGains, MassSpring, MassSpringRig, SimulatedRig,
    Unmodelled,
};
use ctrlab::metrics::{StepInfoOptions, step_info_channel};
use ctrlab::signal::{Signal, SquareWave};
use ctrlab::{Error, OpenLoop, Recording};
use nalgebra::vector;

const PERIOD: f64 = 0.002;
const PERIOD_NS: u64 = 2_000_000;
/// One count of the default calibration, m.
const COUNT: f64 = 0.080 / 8192.0;

// ---------------------------------------------------------------------
// The rig on a memory card: counts and time set by the test.
// ---------------------------------------------------------------------

/// The lab's rig on a memory card (ID 0xa5, counters at zero), timed on
/// `clock`.
fn memory_rig(clock: &VirtualClock) -> MassSpringRig<RegisterFile> {
    let mut regs = RegisterFile::new();
    regs.set(0x00, 0xa5);
    MassSpringRig::with_clock(
        Pc104::new(regs),
        Calibration::default(),
        PERIOD,
        Clock::Virtual(clock.clone()),
    )
    .unwrap()
}

/// Sets cart 2's counter (encoder 1, registers 0x24–0x27) and reads the
/// state at `t_nanos` on the clock.
fn read_at(
    rig: &mut MassSpringRig<RegisterFile>,
    clock: &VirtualClock,
    t_nanos: u64,
    cart2_counts: u32,
) -> Result<nalgebra::SVector<f64, 4>, RigError> {
    clock.advance_nanos(t_nanos - clock.now_nanos());
    rig.card_mut().port_mut().set_u32_le(0x24, cart2_counts);
    rig.read_state()
}

#[test]
fn one_count_over_5_us_after_a_late_tick_is_neither_a_bus_fault_nor_a_speed_spike() {
    let clock = VirtualClock::new();
    let mut rig = memory_rig(&clock);
    // Ticks 0 and 1 on time; tick 2 late by T − 5 µs; tick 3 on time, 5 µs
    // later, one count further: the "1 counts in 0.0000 s" (one
    // count over 5 µs is 1.95 m/s, over 4.87 µs the reported 2.006 m/s).
    read_at(&mut rig, &clock, 0, 0).unwrap();
    read_at(&mut rig, &clock, PERIOD_NS, 0).unwrap();
    let late = read_at(&mut rig, &clock, 3 * PERIOD_NS - 5_000, 0).unwrap();
    assert_eq!(late[3], 0.0);
    let x = read_at(&mut rig, &clock, 3 * PERIOD_NS, 1).unwrap();
    // The speed is the count over the read two ticks back (tick 1, 4 ms
    // earlier), not over the 5 µs: 9.765625 µm / 4 ms = 2.44 mm/s.
    assert_eq!(x[2], COUNT);
    let want = COUNT / (2.0 * PERIOD);
    assert!((x[3] - want).abs() < 1e-12 * want, "{} vs {want}", x[3]);
    // Differenced over the 5 µs it would have been 1.95 m/s, 800 times that.
    assert!(x[3] < 0.01 * COUNT / 5e-6, "{}", x[3]);
    // The issue's own figures: one count over 4.87 µs, 2.006 m/s.
    read_at(&mut rig, &clock, 5 * PERIOD_NS - 4_870, 1).unwrap();
    let x = read_at(&mut rig, &clock, 5 * PERIOD_NS, 2).unwrap();
    let want = COUNT / (5.0 * PERIOD - (3.0 * PERIOD));
    assert!((x[3] - want).abs() < 1e-12 * want, "{} vs {want}", x[3]);
}

#[test]
fn one_count_is_quantisation_at_any_interval_and_speeds_never_come_from_microseconds() {
    let clock = VirtualClock::new();
    let mut rig = memory_rig(&clock);
    // Reads 5 µs apart with nothing older stored (outside the loop): one
    // count either way is never a fault, and the speed is taken over 3/4 of
    // a period at least.
    read_at(&mut rig, &clock, 0, 0).unwrap();
    let up = read_at(&mut rig, &clock, 5_000, 1).unwrap();
    let min_interval = (1.0 - LATE_FRACTION) * PERIOD;
    assert!((up[3] - COUNT / min_interval).abs() < 1e-12, "{}", up[3]);
    assert!(up[3] < 0.01, "{} m/s", up[3]);
    // Back down one count 5 µs later: still one count from the oldest read.
    let down = read_at(&mut rig, &clock, 10_000, 0).unwrap();
    assert_eq!(down[3], 0.0);
    let down = read_at(&mut rig, &clock, 15_000, u32::MAX).unwrap(); // −1 count
    assert!(
        (down[3] + COUNT / min_interval).abs() < 1e-12,
        "{}",
        down[3]
    );
}

#[test]
fn many_counts_in_one_period_are_still_a_bus_fault() {
    let clock = VirtualClock::new();
    let mut rig = memory_rig(&clock);
    read_at(&mut rig, &clock, 0, 0).unwrap();
    read_at(&mut rig, &clock, PERIOD_NS, 0).unwrap();
    // A flipped bit 11: 2048 counts, 20 mm in 2 ms, 10 m/s.
    let err = read_at(&mut rig, &clock, 2 * PERIOD_NS, 2048).unwrap_err();
    match err {
        RigError::Fault(LoopFault::BusFault {
            channel,
            counts,
            interval,
            speed,
            limit,
        }) => {
            assert_eq!((channel, counts), (1, 2048));
            assert!((interval - PERIOD).abs() < 1e-12, "{interval}");
            assert!((speed - 2048.0 * COUNT / PERIOD).abs() < 1e-9, "{speed}");
            assert_eq!(limit, 2.0);
        }
        other => panic!("expected a bus fault, got {other:?}"),
    }
    // After a late tick the check is over the read two ticks back: the
    // same glitch 5 µs after a late read is still a fault (over 2 ms + 5 µs).
    let clock = VirtualClock::new();
    let mut rig = memory_rig(&clock);
    read_at(&mut rig, &clock, 0, 0).unwrap();
    read_at(&mut rig, &clock, PERIOD_NS, 0).unwrap();
    read_at(&mut rig, &clock, 3 * PERIOD_NS - 5_000, 0).unwrap();
    let err = read_at(&mut rig, &clock, 3 * PERIOD_NS, 2048).unwrap_err();
    assert_eq!(err.kind(), LoopFaultKind::BusFault);
    // And two counts over 5 µs with nothing older stored: 3.9 m/s over the
    // only interval there is, a fault (only one count is quantisation).
    let clock = VirtualClock::new();
    let mut rig = memory_rig(&clock);
    read_at(&mut rig, &clock, 0, 0).unwrap();
    let err = read_at(&mut rig, &clock, 5_000, 2).unwrap_err();
    assert_eq!(err.kind(), LoopFaultKind::BusFault);
}

// ---------------------------------------------------------------------
// Runs through hw::run on a jittered virtual clock.
// ---------------------------------------------------------------------

/// The test's real-time-like schedule: 10 % of ticks late by up to three
/// periods (a third of them past the next deadline), and one in 200
/// stalled for 4 to 8 periods (8–16 ms, well within the 50 ms gap limit).
fn jitter(seed: u64) -> Jitter {
    Jitter {
        seed,
        late_fraction: 0.1,
        max_late: 3.0 * PERIOD,
        stall_fraction: 0.005,
        stall: 8.0 * PERIOD,
    }
}

/// The loop's settings for jittered runs: `duration`, and timing faults
/// that never stop the run (the schedule skips about 25 deadlines per
/// 0.5 s, the default limit; here the downstream is under test).
fn jittered_config(duration: f64) -> LoopConfig {
    LoopConfig {
        duration,
        max_timing_faults: 100_000,
        ..LoopConfig::default()
    }
}

/// `input` open loop on `sim`'s rig for `duration`, on a virtual clock
/// with `jitter` (or an ideal one).
fn open_loop(
    sim: &SimulatedRig,
    input: &dyn Signal,
    duration: f64,
    jitter: Option<Jitter>,
) -> RunOutcome {
    let mut clock = VirtualClock::new();
    if let Some(j) = jitter {
        clock = clock.with_jitter(j).unwrap();
    }
    let rig = sim.rig(&Clock::Virtual(clock.clone())).unwrap();
    run(
        rig,
        OpenLoop,
        |t| vector![input.value(t)],
        &Clock::Virtual(clock),
        &jittered_config(duration),
    )
    .unwrap()
}

/// The sampling instants the schedule gives, ns, and the deadlines it
/// skips: tick `k` wakes `lateness(k)` after its deadline (or after the
/// previous wake-up, if that is later), and one that wakes after the next
/// deadline skips to the last deadline passed.
fn schedule(jitter: &Jitter, ticks: u64) -> (Vec<u64>, u64) {
    let (mut times, mut skipped, mut now, mut k) = (Vec::new(), 0, 0u64, 0u64);
    while k < ticks {
        now = now.max(k * PERIOD_NS) + (jitter.lateness(k) * 1e9).round() as u64;
        if now > (k + 1) * PERIOD_NS {
            let behind = (now / PERIOD_NS).min(ticks);
            skipped += behind - k;
            k = behind;
            if k >= ticks {
                break;
            }
        }
        times.push(now);
        k += 1;
    }
    (times, skipped)
}

/// Each recorded speed is the position change over the newest earlier
/// sample at least 3/4 of a period older (from the recording alone).
fn assert_speeds_over_three_quarters_of_a_period(rec: &Recording) {
    let t = rec.time();
    for (x, v) in [("x1", "v1"), ("x2", "v2")] {
        let (x, v) = (rec.channel(x).unwrap(), rec.channel(v).unwrap());
        for k in 1..t.len() {
            let base = (0..k)
                .rev()
                .find(|&j| t[k] - t[j] >= (1.0 - LATE_FRACTION) * PERIOD - 1e-12)
                .unwrap_or(0);
            let want = (x[k] - x[base]) / (t[k] - t[base]).max(0.75 * PERIOD);
            assert!(
                (v[k] - want).abs() <= 1e-9 * want.abs().max(1e-3),
                "sample {k} at {} s: {} vs {want}",
                t[k],
                v[k]
            );
        }
    }
}

#[test]
fn a_run_with_late_ticks_and_stalls_completes_with_every_one_counted() {
    let sim = SimulatedRig::default(); // friction, PWM delay, noise
    let square = SquareWave::new(8.0, 0.2).unwrap();
    let j = jitter(11);
    let out = open_loop(&sim, &square, 5.0, Some(j));
    let (rec, s) = (&out.recording, &out.stats);
    println!("{s}");
    // Every deadline is a sample or a skipped deadline.
    assert_eq!(s.ticks, rec.len());
    assert_eq!(s.ticks + s.skipped, 2500);
    // The time stamps are the schedule's wake-up instants, to the ns.
    let (times, skipped) = schedule(&j, 2500);
    assert_eq!(s.skipped as u64, skipped);
    assert_eq!(times.len(), rec.len());
    for (k, (&got, &want)) in rec.time().iter().zip(&times).enumerate() {
        assert!(
            (got - want as f64 * 1e-9).abs() < 1e-12,
            "{k}: {got} vs {want} ns"
        );
    }
    // Late ticks, from the recording alone: a stamp a quarter period or more
    // past the deadline before it.
    let late = rec
        .time()
        .iter()
        .filter(|&&t| {
            let ns = (t * 1e9).round() as u64;
            ns % PERIOD_NS >= PERIOD_NS / 4
        })
        .count();
    assert_eq!(s.late, late);
    // A tick that wakes up late and skips does its work at once: it ends
    // before its own next deadline, so no tick of a run whose work takes
    // no time is an overrun (a skip once also counted as one, judged
    // against the deadline the skip had passed over).
    assert_eq!(s.overruns, 0, "{s:?}");
    // Measured on seed 11: 169 late, 263 skipped, the shortest interval
    // 6.4 µs, the longest 16.3 ms (a stall); the figures only need to be
    // there.
    assert!(s.late > 100 && s.skipped > 50, "{s:?}");
    assert!(
        s.lateness_max < PERIOD && s.lateness_max >= 0.9 * PERIOD,
        "{s:?}"
    );
    let intervals: Vec<f64> = rec.time().windows(2).map(|w| w[1] - w[0]).collect();
    let shortest = intervals.iter().copied().fold(f64::INFINITY, f64::min);
    let longest = intervals.iter().copied().fold(0.0, f64::max);
    println!("shortest interval {shortest:e} s, longest {longest:e} s");
    assert!(shortest < 0.1 * PERIOD && longest > 4.0 * PERIOD);
    assert!((s.max_interval - longest).abs() < 1e-15);
    assert_speeds_over_three_quarters_of_a_period(rec);
    // No speed spike: the largest recorded |v2| is that of the same run on
    // the ideal clock (measured 0.771 and 0.762 m/s); differenced over the
    // previous sample it would have been 1.54 m/s (a count and the noise
    // over a few µs).
    let ideal = open_loop(&sim, &square, 5.0, None).recording;
    let largest = |rec: &Recording| {
        rec.channel("v2")
            .unwrap()
            .iter()
            .fold(0.0f64, |m, v| m.max(v.abs()))
    };
    let x2 = rec.channel("x2").unwrap();
    let naive = (1..rec.len())
        .map(|k| ((x2[k] - x2[k - 1]) / intervals[k - 1]).abs())
        .fold(0.0, f64::max);
    let (recorded, reference) = (largest(rec), largest(&ideal));
    println!(
        "largest |v2|: {recorded} m/s, ideal clock {reference} m/s, over the previous sample {naive} m/s"
    );
    assert!(recorded < 1.05 * reference, "{recorded} vs {reference}");
    assert!(naive > 1.5 * reference, "{naive} vs {reference}");
}

#[test]
fn on_the_ideal_virtual_clock_nothing_is_late_and_speeds_are_over_one_period() {
    let sim = SimulatedRig::default();
    let out = open_loop(&sim, &SquareWave::new(8.0, 0.2).unwrap(), 1.0, None);
    let s = &out.stats;
    assert_eq!(
        (s.ticks, s.late, s.skipped, s.lateness_max),
        (500, 0, 0, 0.0)
    );
    let rec = &out.recording;
    let (t, x2, v2) = (
        rec.time(),
        rec.channel("x2").unwrap(),
        rec.channel("v2").unwrap(),
    );
    for k in 1..rec.len() {
        // The card's clock in seconds is ns / 1e9, the recording's ns · 1e-9.
        let want = (x2[k] - x2[k - 1]) / (t[k] - t[k - 1]);
        assert!((v2[k] - want).abs() <= 1e-9 * want.abs().max(1e-6), "{k}");
    }
}

// ---------------------------------------------------------------------
// The analyses on jittered recordings.
// ---------------------------------------------------------------------

/// Separate springs, Central.
const SEPARATE: Options = Options {
    springs: SpringModel::Separate,
    ..Options::DEFAULT
};

/// Errors of `est` against `truth`, % (k1, k2, b1, b2, K).
fn errors(est: &MassSpringEstimate, truth: &MassSpring) -> [f64; 5] {
    let e = |got: f64, want: f64| (got / want - 1.0) * 100.0;
    [
        e(est.k1().value, truth.k1),
        e(est.k2().value, truth.k2),
        e(est.b1.value, truth.b1),
        e(est.b2.value, truth.b2),
        e(est.gain.value, truth.gain),
    ]
}

#[test]
fn identification_on_jittered_and_stalled_recordings_stays_within_its_bounds() {
    // As tests/hw_ident.rs, with its bound: the ideal rig (no friction or
    // delay, which the linear regressors cannot model) with 0.5 counts of
    // encoder noise, the lab's ±8 V square wave for 5 s, five runs whose
    // mean is within 1 % of the truth; here each run on its own jittered
    // clock: 3 % of ticks late by up to three periods, one in 500 stalled
    // for 4–8 periods. The recordings are split at every late sample and
    // stall (`Timing`), so fewer rows are fitted.
    //
    // Measured over ten sets of five runs (jitter seeds 100 + 10 s + 1..=5,
    // s = 0..10): the worst mean error 0.72 % (b2; k1 0.09, k2 0.12, b1
    // 0.26, K 0.19 %), the worst single run 1.40 % (b2). The same scan with
    // the harsher schedule of the loop test (10 % late, one in 200 stalled)
    // gave means up to 1.50 % (b2) and single runs up to 3.5 %; plain
    // dropped samples on the ideal clock give the same (15 % dropped:
    // single runs up to 3.6 %), so it is the rows lost at the splits, not
    // the timing: the ideal clock's worst single run is 0.37 %.
    let truth = SimulatedRig::default_truth();
    let square = SquareWave::new(8.0, 0.2).unwrap();
    let mut estimates = Vec::new();
    for seed in 1..=5 {
        let sim = SimulatedRig {
            card: CardSettings {
                encoder_noise: 0.5,
                seed,
                ..CardSettings::ideal()
            },
            ..SimulatedRig::ideal(truth)
        };
        let schedule = Jitter {
            late_fraction: 0.03,
            stall_fraction: 0.002,
            ..jitter(100 + seed)
        };
        let out = open_loop(&sim, &square, 5.0, Some(schedule));
        assert!(out.stats.late > 0 && out.stats.skipped > 0, "{}", out.stats);
        let est = identify_with(&out.recording, truth.m1, truth.m2, &SEPARATE).unwrap();
        let timing = est.timing;
        assert!(timing.gaps > 0 && timing.short_intervals + timing.jittered > 0);
        println!("seed {seed}: {:.3?} %, {timing:?}", errors(&est, &truth));
        estimates.push(errors(&est, &truth));
    }
    let mean: [f64; 5] = std::array::from_fn(|i| estimates.iter().map(|e| e[i]).sum::<f64>() / 5.0);
    println!("mean of five: {mean:.3?} %");
    assert!(mean.iter().all(|e| e.abs() < 1.0), "{mean:?}");
}

/// The realistic rig (Coulomb friction with stiction, the drive's 0.15 ms
/// delay) without encoder noise.
fn noiseless_rig() -> SimulatedRig {
    SimulatedRig {
        friction: Friction {
            coulomb: [1.0, 2.0],
            stiction: [1.2, 2.4],
        },
        card: CardSettings {
            encoder_noise: 0.0,
            ..CardSettings::default()
        },
        // Off: these tests check the timing machinery (late ticks, the
        // input delay on actual instants) against the model, not realism.
        unmodelled: Unmodelled::NONE,
        ..SimulatedRig::default()
    }
}

#[test]
fn the_input_delay_is_applied_on_the_actual_instants_and_not_refused() {
    // The case: a real-time recording with intervals shorter than
    // the drive's 0.15 ms delay was refused ("the input delay must be
    // shorter than the recording's shortest interval").
    let sim = noiseless_rig();
    let model = sim.simulation_model();
    assert_eq!(model.input_delay, 0.15e-3);
    let square = SquareWave::new(9.0, 0.2).unwrap();
    for seed in [11, 12, 13] {
        let rec = open_loop(&sim, &square, 5.0, Some(jitter(seed))).recording;
        let shortest = rec
            .time()
            .windows(2)
            .map(|w| w[1] - w[0])
            .fold(f64::INFINITY, f64::min);
        let short = rec
            .time()
            .windows(2)
            .filter(|w| w[1] - w[0] < 0.15e-3)
            .count();
        // The card's truth, simulated from the recorded input, is off the
        // noise-free readings by their quantisation alone, as on the ideal
        // clock (tests/ident_refine.rs: RMS below 0.35 counts); without
        // the delay it is not.
        let v = validate_with(&rec, &sim.truth, sim.friction.coulomb, &model).unwrap();
        let no_delay = SimulationModel {
            input_delay: 0.0,
            ..model
        };
        let w = validate_with(&rec, &sim.truth, sim.friction.coulomb, &no_delay).unwrap();
        println!(
            "seed {seed}: shortest interval {shortest:e} s, {short} below the delay; RMS {:.3e} m \
             ({:.3} counts), without the delay {:.3e} m",
            v.rms_error[1],
            v.rms_error[1] / COUNT,
            w.rms_error[1]
        );
        assert!(v.rms_error.iter().all(|e| *e < 0.35 * COUNT), "{v:?}");
        assert!(w.rms_error[1] > 1.4 * v.rms_error[1], "{w:?}");
    }
    // A delay of the recording's typical interval or more is still refused:
    // the drive would replace every command before it took effect.
    let rec = open_loop(&sim, &square, 1.0, Some(jitter(11))).recording;
    let too_long = SimulationModel {
        input_delay: PERIOD,
        ..model
    };
    assert!(matches!(
        validate_with(&rec, &sim.truth, sim.friction.coulomb, &too_long),
        Err(Error::InvalidParameter {
            name: "input_delay",
            ..
        })
    ));
}

#[test]
fn refinement_and_bootstrap_on_jittered_recordings_stay_within_their_bounds() {
    // tests/ident_refine.rs's bounds: k1, k2, b1, b2 and K within 1 %, the
    // Coulomb forces within 10 % of the truth, on the realistic rig (with
    // 0.5 counts of noise) and the square wave of 8 + 2 F_max N.
    let sim = SimulatedRig {
        friction: Friction {
            coulomb: [1.0, 2.0],
            stiction: [1.2, 2.4],
        },
        // Off: ident_refine's bounds are the refinement's against its own
        // model structure; jitter is what this test adds.
        unmodelled: Unmodelled::NONE,
        ..SimulatedRig::default()
    };
    let volts = 12.0 / sim.truth.gain;
    let square = SquareWave::new(volts, 0.2).unwrap();
    let options = Options {
        coulomb: true,
        ..SEPARATE
    };
    let model = sim.simulation_model();
    let mut worst = [0.0f64; 7];
    for seed in [21, 22, 23] {
        let rec = open_loop(&sim, &square, 5.0, Some(jitter(seed))).recording;
        let ls = identify_with(&rec, 1.3, 0.7, &options).unwrap();
        let r = refine_with(&rec, &ls, &model).unwrap();
        let (t, f) = (sim.truth, sim.friction.coulomb);
        let e = |got: f64, want: f64| (got / want - 1.0) * 100.0;
        let errors = [
            e(r.plant.k1, t.k1),
            e(r.plant.k2, t.k2),
            e(r.plant.b1, t.b1),
            e(r.plant.b2, t.b2),
            e(r.plant.gain, t.gain),
            e(r.coulomb[0], f[0]),
            e(r.coulomb[1], f[1]),
        ];
        println!(
            "seed {seed}: {errors:.3?} %, fit {:.2?} → {:.2?} %",
            r.start.fit_percent, r.refined.fit_percent
        );
        assert!(r.refined.fit_percent[1] >= r.start.fit_percent[1] - 1e-9);
        for (w, e) in worst.iter_mut().zip(errors) {
            *w = w.max(e.abs());
        }
        if seed == 21 {
            // The bootstrap resamples the same recording's time stamps.
            let b = bootstrap(
                &rec,
                &options,
                &r,
                &model,
                &Bootstrap {
                    resamples: 4,
                    ..Bootstrap::default()
                },
            )
            .unwrap();
            println!("bootstrap: {b:?}");
            assert!(b.k1 > 0.0 && b.k1 < 0.01 * t.k1, "{b:?}");
            assert!(b.gain > 0.0 && b.gain < 0.01 * t.gain, "{b:?}");
        }
    }
    // Measured over jitter seeds 21–23: at most 0.021 % (b1) on k1, k2,
    // b1, b2 and K, 0.058 % (F1) on the forces, as on the ideal clock; the
    // fits 99.98–99.99 %.
    println!("worst {worst:.3?} %");
    assert!(
        worst
            .iter()
            .enumerate()
            .all(|(i, e)| *e < if i < 5 { 1.0 } else { 10.0 }),
        "{worst:?}"
    );
}

/// The lab's cart-2 state feedback `Kf = [0 0 10 0.1]` (per mm: 0.1 V per
/// mm/s of cart 2's speed) toward 30 mm for 1.5 s on the nominal ideal rig
/// with 0.5 counts of encoder noise, on a clock with `jitter` or an ideal
/// one.
fn closed_loop_step(jitter: Option<Jitter>) -> RunOutcome {
    let sim = SimulatedRig {
        card: CardSettings {
            encoder_noise: 0.5,
            ..CardSettings::ideal()
        },
        ..SimulatedRig::ideal(MassSpring::nominal())
    };
    let mut clock = VirtualClock::new();
    if let Some(j) = jitter {
        clock = clock.with_jitter(j).unwrap();
    }
    let rig = sim.rig(&Clock::Virtual(clock.clone())).unwrap();
    let controller = LabGains::new([0.0, 0.0, 10.0, 0.1], Cart::Two)
        .state_feedback()
        .unwrap();
    run(
        rig,
        controller,
        |_| vector![0.030],
        &Clock::Virtual(clock),
        &jittered_config(1.5),
    )
    .unwrap()
}

#[test]
fn a_closed_loop_step_under_late_ticks_has_the_ideal_clocks_step_metrics() {
    let options = StepInfoOptions::default();
    let ideal = closed_loop_step(None);
    let reference = step_info_channel(&ideal.recording, "x2", &options).unwrap();
    for seed in [31, 32, 33] {
        let out = closed_loop_step(Some(jitter(seed)));
        assert!(out.stats.late > 0 && out.stats.skipped > 0, "{}", out.stats);
        // The step metrics take the actual instants, jitter and gaps alike.
        let info = step_info_channel(&out.recording, "x2", &options).unwrap();
        // The drive never saw a speed spike: a count over a few µs through
        // 0.1 V per mm/s would have been a kick of 24 V (saturated) once
        // settled, where the noise moves it by a fraction of a volt.
        let u = out.recording.channel("u").unwrap();
        let t = out.recording.time();
        // The largest change of the drive between two samples once settled.
        let largest_after = |u: &[f64], t: &[f64]| {
            (1..u.len())
                .filter(|&k| t[k - 1] > 0.5)
                .fold(0.0f64, |m, k| m.max((u[k] - u[k - 1]).abs()))
        };
        let u_late = largest_after(u, t);
        let u_ideal = largest_after(
            ideal.recording.channel("u").unwrap(),
            ideal.recording.time(),
        );
        println!(
            "seed {seed}: rise {:.4} s (ideal {:.4}), settling {:.4} s (ideal {:.4}), overshoot \
             {:.2} % (ideal {:.2}), final {:.5} m (ideal {:.5}); largest |Δu| after 0.5 s {u_late:.3} V \
             (ideal {u_ideal:.3})",
            info.rise_time,
            reference.rise_time,
            info.settling_time,
            reference.settling_time,
            info.overshoot,
            reference.overshoot,
            info.steady_state_value,
            reference.steady_state_value
        );
        // Measured on seeds 31–33 against the ideal clock: rise 33.5–33.8 ms
        // (33.8), settling 212.2–212.5 ms (214.4), overshoot 2.64–2.98 %
        // (3.01 %), final value equal to 10 µm, largest |Δu| once settled
        // 2.74–2.98 V (2.64 V). The bounds: a period or two, a percent, a
        // few counts, twice the ideal kick.
        assert!((info.rise_time - reference.rise_time).abs() < 2.0 * PERIOD);
        assert!((info.settling_time - reference.settling_time).abs() < 3.0 * PERIOD);
        assert!((info.overshoot - reference.overshoot).abs() < 1.0);
        assert!((info.steady_state_value - reference.steady_state_value).abs() < 3.0 * COUNT);
        assert!(u_late < 2.0 * u_ideal.max(0.5), "{u_late} V vs {u_ideal} V");
    }
}
