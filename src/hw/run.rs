//! The fixed-period control loop: drives any [`Controller`] against any
//! [`Rig`] at period `T` (2 ms by default) on absolute deadlines, records every
//! sample, and stops safely.
//!
//! Deadlines are `t0 + k T`, never "now + T", so timing errors do not
//! accumulate (no drift). A tick whose work ends after the next deadline is an
//! *overrun*; `max_consecutive_overruns` of them in a row halt the rig and end
//! the run with [`HwError::Overrun`]. On any error the rig is halted
//! (PWM to zero) and the error comes back together with everything recorded
//! so far: nothing measured is lost.

use std::time::{Duration, Instant};

use nalgebra::SVector;

use crate::data::Recording;
use crate::design::Controller;
use crate::hw::{HwError, Rig, VirtualClock};

/// Where the loop's time comes from.
///
/// # Examples
///
/// ```
/// use ctrlab::hw::{Clock, VirtualClock};
/// let time = VirtualClock::new();
/// let clock = Clock::Virtual(time.clone()); // the card gets the same handle
/// assert!(matches!(clock, Clock::Virtual(_)));
/// assert_eq!(time.now(), 0.0);
/// ```
#[derive(Debug, Clone)]
pub enum Clock {
    /// Wall-clock time: the loop sleeps until each deadline (the last
    /// 200 µs are spun for precision). Not a real-time kernel: expect
    /// occasional lateness of tens of µs or more under load.
    RealTime,
    /// Simulated time: each tick advances the [`VirtualClock`] by exactly one
    /// period and never sleeps, so a 5 s experiment on the
    /// [`SimulatedCard`](crate::hw::SimulatedCard) (sharing the same clock) runs
    /// as fast as the CPU allows and is exactly reproducible.
    Virtual(VirtualClock),
}

/// Settings of a [`run`].
///
/// # Examples
///
/// ```
/// use ctrlab::hw::LoopConfig;
/// let config = LoopConfig { duration: 3.0, ..LoopConfig::default() };
/// assert_eq!((config.period, config.max_consecutive_overruns), (0.002, 5));
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct LoopConfig {
    /// Sampling period `T`, s (default 0.002).
    pub period: f64,
    /// Length of the experiment, s; the loop runs `round(duration / period)`
    /// ticks.
    pub duration: f64,
    /// Consecutive overruns that stop the run (default 5).
    pub max_consecutive_overruns: usize,
}

impl Default for LoopConfig {
    fn default() -> Self {
        Self {
            period: 0.002,
            duration: 5.0,
            max_consecutive_overruns: 5,
        }
    }
}

/// Timing statistics of a run. Lateness is how long after its deadline a tick
/// started, s (always 0 on the virtual clock).
///
/// # Examples
///
/// ```
/// use ctrlab::hw::LoopStats;
/// let s = LoopStats::default();
/// assert_eq!((s.ticks, s.overruns, s.lateness_max), (0, 0, 0.0));
/// ```
#[derive(Debug, Clone, Default, PartialEq)]
pub struct LoopStats {
    /// Ticks executed.
    pub ticks: usize,
    /// Ticks whose work ended after the next deadline.
    pub overruns: usize,
    /// Deadlines skipped because the loop fell a whole period or more
    /// behind (real-time clock only); nothing is recorded for them.
    pub skipped: usize,
    /// Longest run of consecutive overruns.
    pub max_consecutive_overruns: usize,
    /// Median lateness, s.
    pub lateness_p50: f64,
    /// 99th-percentile lateness, s.
    pub lateness_p99: f64,
    /// Largest lateness, s.
    pub lateness_max: f64,
}

/// A run that ended in an error: the error, with what was recorded before it.
///
/// # Examples
///
/// ```
/// use ctrlab::hw::{run, Calibration, Clock, HwErrorKind, LoopConfig, MassSpringRig, Pc104, SimulatedCard, SimulatedCardConfig, VirtualClock};
/// use ctrlab::OpenLoop;
///
/// let clock = VirtualClock::new();
/// let card = SimulatedCard::virtual_time(SimulatedCardConfig::default(), &clock)?;
/// let rig = MassSpringRig::new(Pc104::new(card), Calibration::default(), 0.002)?;
/// // Full drive on the default truth (8.5 N/V) runs cart 2 into its travel limit.
/// let err = run(rig, OpenLoop, |_| 24.0, &Clock::Virtual(clock), &LoopConfig::default()).unwrap_err();
/// assert_eq!(err.error.kind(), HwErrorKind::TravelLimit);
/// assert!(!err.recording.is_empty()); // everything before the breach
/// # Ok::<(), ctrlab::hw::HwError>(())
/// ```
#[derive(Debug)]
pub struct RunError {
    /// What went wrong.
    pub error: HwError,
    /// Every sample completed before the fault.
    pub recording: Recording,
    /// The state read in the failing tick, when the fault came after the
    /// read (its command never reached the rig, so it is not in `recording`).
    pub last_state: Option<SVector<f64, 4>>,
    /// Timing statistics up to the fault.
    pub stats: LoopStats,
}

impl std::fmt::Display for RunError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "control loop stopped after {} samples: {}",
            self.recording.len(),
            self.error
        )
    }
}

impl std::error::Error for RunError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        Some(&self.error)
    }
}

/// A run that completed: everything recorded, and the timing statistics.
///
/// # Examples
///
/// ```
/// use ctrlab::hw::{run, Calibration, Clock, LoopConfig, MassSpringRig, Pc104, SimulatedCard, SimulatedCardConfig, VirtualClock};
/// use ctrlab::OpenLoop;
///
/// let clock = VirtualClock::new();
/// let card = SimulatedCard::virtual_time(SimulatedCardConfig::default(), &clock)?;
/// let rig = MassSpringRig::new(Pc104::new(card), Calibration::default(), 0.002)?;
/// let config = LoopConfig { duration: 0.1, ..LoopConfig::default() };
/// let out = run(rig, OpenLoop, |_| 1.2, &Clock::Virtual(clock), &config)?;
/// assert_eq!(out.recording.len(), 50);
/// assert!((out.recording.u[0] - 1.2).abs() < 1e-12); // 50 duty steps of 24 mV
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct RunOutcome {
    /// One sample per tick: time (s, from the start of the run), the voltage
    /// actually applied (V), and the state read at that tick (m, m/s).
    pub recording: Recording,
    /// Timing statistics.
    pub stats: LoopStats,
}

/// How far the real-time clock sleeps before spinning to a deadline.
const SPIN: Duration = Duration::from_micros(200);

/// Runs `controller` against `rig` for `config.duration` seconds at period
/// `config.period`, with reference `reference(t)` (SI, `t` in s from the
/// start), timed by `clock`.
///
/// Each tick `k`, at the absolute deadline `k T`: read the state (on
/// [`MassSpringRig`](crate::hw::MassSpringRig) this latches the counters and
/// kicks the card's watchdog), evaluate the reference, update the controller,
/// apply its voltage, and record `(t, applied volts, state)`. At the end the
/// rig is halted. The loop does not call [`Rig::kick_watchdog`] on its own: a
/// rig with a watchdog kicks it in `read_state`, as `MassSpringRig` does
/// (one control write latches and kicks).
///
/// # Errors
///
/// A [`RunError`] (boxed: it carries the whole recording) holding the error, every sample recorded before it, the
/// state read in the failing tick if there was one, and the statistics. The
/// rig has been halted (best effort: a dead port cannot be told, but then the
/// card's watchdog stops the motor). Causes: any rig error (port fault,
/// travel limit, non-finite command), [`HwError::Overrun`] after
/// `max_consecutive_overruns` overruns in a row, and
/// [`HwError::InvalidConfig`] for a bad `config` (nothing is run then).
///
/// # Examples
///
/// The lab's cart-2 controller `Kf = [0 0 10 0.1]` (per mm) on the simulated
/// card with the nominal plant, 1 s of virtual time in a few milliseconds:
///
/// ```
/// use ctrlab::hw::{run, Calibration, Clock, LoopConfig, MassSpringRig, Pc104, SimulatedCard, SimulatedCardConfig, VirtualClock};
/// use ctrlab::{MassSpring, Output, StateFeedback};
///
/// let clock = VirtualClock::new();
/// let config = SimulatedCardConfig { truth: MassSpring::nominal(), ..Default::default() };
/// let card = SimulatedCard::virtual_time(config, &clock)?;
/// let mut rig = MassSpringRig::new(Pc104::new(card), Calibration::default(), 0.002)?;
/// let controller = StateFeedback::from_lab_gains([0.0, 0.0, 10.0, 0.1], Output::Cart2)?;
/// let loop_config = LoopConfig { duration: 1.0, ..LoopConfig::default() };
///
/// let out = run(&mut rig, controller, |_t| 0.030, &Clock::Virtual(clock), &loop_config)?;
/// assert_eq!(out.recording.len(), 500);
/// // Cart 2 ends near the closed loop's steady state, 28.57 mm for 30 mm.
/// let x2 = *out.recording.x2.last().unwrap();
/// assert!((x2 - 0.02857).abs() < 2e-4, "{x2}");
/// assert_eq!(out.stats.overruns, 0);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn run<R, C>(
    mut rig: R,
    mut controller: C,
    mut reference: impl FnMut(f64) -> f64,
    clock: &Clock,
    config: &LoopConfig,
) -> Result<RunOutcome, Box<RunError>>
where
    R: Rig,
    C: Controller<4, 1>,
{
    let checked = check_config(config).and_then(|ticks| match rig.period() {
        Some(p) if (p - config.period).abs() > 1e-9 * p => Err(HwError::InvalidConfig {
            name: "period",
            value: config.period,
            reason: "differs from the period the rig's speed estimates assume",
        }),
        _ => Ok(ticks),
    });
    let ticks = match checked {
        Ok(ticks) => ticks,
        Err(error) => {
            return Err(Box::new(RunError {
                error,
                recording: Recording::new(),
                last_state: None,
                stats: LoopStats::default(),
            }));
        }
    };
    let period = config.period;
    let mut recording = Recording::with_capacity(ticks);
    let mut lateness = Vec::with_capacity(ticks);
    let mut stats = LoopStats::default();
    let mut consecutive = 0usize;
    controller.reset();
    // The rig may have been used before: its last sample is not this run's.
    rig.restart();

    let wall_start = Instant::now();
    let virtual_start = match clock {
        Clock::Virtual(c) => c.now_nanos(),
        Clock::RealTime => 0,
    };
    let period_ns = (period * 1e9).round() as u64;

    let mut k = 0usize;
    while k < ticks {
        // Wait for the absolute deadline k·T. On the virtual clock time is
        // kept in whole nanoseconds, and so is the recorded time.
        let (t, late) = match clock {
            Clock::Virtual(c) => {
                let offset = (k as u64).saturating_mul(period_ns);
                let target = virtual_start.saturating_add(offset);
                c.advance_nanos(target.saturating_sub(c.now_nanos()));
                (offset as f64 * 1e-9, 0.0)
            }
            Clock::RealTime => {
                let elapsed = wall_start.elapsed().as_secs_f64();
                if elapsed > (k + 1) as f64 * period {
                    // A whole period or more behind (the OS took the CPU):
                    // skip the missed deadlines rather than run them back
                    // to back on stale time, and restart the speed estimate,
                    // which would otherwise span the gap.
                    let behind = ((elapsed / period) as usize).min(ticks);
                    stats.skipped += behind - k;
                    k = behind;
                    rig.restart();
                    if k >= ticks {
                        break;
                    }
                }
                let t = k as f64 * period;
                let deadline = wall_start + Duration::from_secs_f64(t);
                sleep_until(deadline);
                (t, (Instant::now() - deadline).as_secs_f64())
            }
        };
        lateness.push(late);

        let tick = Instant::now();
        let state = match rig.read_state() {
            Ok(state) => state,
            Err(error) => return Err(stop(rig, error, recording, None, stats, lateness)),
        };
        let u = controller.update(reference(t), &state)[0];
        let applied = match rig.apply_voltage(u) {
            Ok(v) => v,
            Err(error) => return Err(stop(rig, error, recording, Some(state), stats, lateness)),
        };
        recording.push_state(t, applied, &state);
        stats.ticks += 1;

        // An overrun: this tick's work ended after the next deadline.
        if let Clock::RealTime = clock {
            let end = (Instant::now() - wall_start).as_secs_f64();
            if end > t + period {
                stats.overruns += 1;
                consecutive += 1;
                stats.max_consecutive_overruns = stats.max_consecutive_overruns.max(consecutive);
                if consecutive >= config.max_consecutive_overruns {
                    let error = HwError::Overrun {
                        consecutive,
                        period,
                        last_tick: tick.elapsed().as_secs_f64(),
                    };
                    return Err(stop(rig, error, recording, None, stats, lateness));
                }
            } else {
                consecutive = 0;
            }
        }
        k += 1;
    }
    if let Err(error) = rig.halt() {
        return Err(stop(rig, error, recording, None, stats, lateness));
    }
    finish_stats(&mut stats, &mut lateness);
    Ok(RunOutcome { recording, stats })
}

/// Halts the rig after `error` and packs up what was recorded.
fn stop<R: Rig>(
    mut rig: R,
    error: HwError,
    recording: Recording,
    last_state: Option<SVector<f64, 4>>,
    mut stats: LoopStats,
    mut lateness: Vec<f64>,
) -> Box<RunError> {
    // The error to report is the cause; a failing halt is left to the card's
    // watchdog.
    rig.halt().ok();
    finish_stats(&mut stats, &mut lateness);
    Box::new(RunError {
        error,
        recording,
        last_state,
        stats,
    })
}

fn finish_stats(stats: &mut LoopStats, lateness: &mut [f64]) {
    if lateness.is_empty() {
        return;
    }
    lateness.sort_unstable_by(f64::total_cmp);
    let at = |q: f64| lateness[((lateness.len() - 1) as f64 * q).round() as usize];
    stats.lateness_p50 = at(0.5);
    stats.lateness_p99 = at(0.99);
    stats.lateness_max = at(1.0);
}

fn check_config(config: &LoopConfig) -> Result<usize, HwError> {
    let invalid = |name, value, reason| HwError::InvalidConfig {
        name,
        value,
        reason,
    };
    let LoopConfig {
        period,
        duration,
        max_consecutive_overruns,
    } = *config;
    if !(period.is_finite() && period >= 1e-6) {
        return Err(invalid("period", period, "must be finite and >= 1 µs"));
    }
    if !(duration.is_finite() && duration >= period) {
        return Err(invalid(
            "duration",
            duration,
            "must be finite and at least one period, s",
        ));
    }
    let ticks = (duration / period).round();
    if ticks > crate::sim::MAX_SAMPLES as f64 {
        return Err(invalid(
            "duration",
            duration,
            "more ticks than sim::MAX_SAMPLES",
        ));
    }
    if max_consecutive_overruns == 0 {
        return Err(invalid(
            "max_consecutive_overruns",
            0.0,
            "must be at least 1",
        ));
    }
    Ok(ticks as usize)
}

/// Sleeps until `deadline`, spinning the last [`SPIN`] for precision.
fn sleep_until(deadline: Instant) {
    let now = Instant::now();
    if deadline > now + SPIN {
        std::thread::sleep(deadline - now - SPIN);
    }
    while Instant::now() < deadline {
        std::hint::spin_loop();
    }
}
