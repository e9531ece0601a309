//! The fixed-period control loop: drives any [`Controller`] against any
//! [`Rig`] at the rig's period `T` on absolute deadlines, records every
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
use crate::hw::{Clock, HwError, Rig};

/// Settings of a [`run`].
///
/// # Examples
///
/// ```
/// use ctrlab::hw::LoopConfig;
/// let config = LoopConfig { duration: 3.0, ..LoopConfig::default() };
/// assert_eq!(config.max_consecutive_overruns, 5);
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct LoopConfig {
    /// Length of the experiment, s; the loop runs `round(duration / T)`
    /// ticks at the rig's period `T` ([`Rig::period`]).
    pub duration: f64,
    /// Consecutive overruns that stop the run (default 5).
    pub max_consecutive_overruns: usize,
}

impl Default for LoopConfig {
    fn default() -> Self {
        Self {
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
/// use ctrlab::hw::{Clock, HwErrorKind, LoopConfig, VirtualClock, run};
/// use ctrlab::{OpenLoop, lab::SimulatedRig};
/// use nalgebra::vector;
///
/// let clock = VirtualClock::new();
/// let rig = SimulatedRig::default().rig(&Clock::Virtual(clock.clone()))?;
/// // Full drive on the default truth (8.5 N/V) runs cart 2 into its travel limit.
/// let err = run(rig, OpenLoop, |_| vector![24.0], &Clock::Virtual(clock), &LoopConfig::default()).unwrap_err();
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
    /// The measurements read in the failing tick, when the fault came after
    /// the read (its command never reached the rig, so it is not in
    /// `recording`).
    pub last_measurement: Option<Vec<f64>>,
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
/// use ctrlab::hw::{Clock, LoopConfig, VirtualClock, run};
/// use ctrlab::{OpenLoop, lab::SimulatedRig};
/// use nalgebra::vector;
///
/// let clock = VirtualClock::new();
/// let rig = SimulatedRig::default().rig(&Clock::Virtual(clock.clone()))?;
/// let config = LoopConfig { duration: 0.1, ..LoopConfig::default() };
/// let out = run(rig, OpenLoop, |_| vector![1.2], &Clock::Virtual(clock), &config)?;
/// assert_eq!(out.recording.len(), 50);
/// assert!((out.recording.channel("u")?[0] - 1.2).abs() < 1e-12); // 50 duty steps of 24 mV
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct RunOutcome {
    /// One sample per tick: time (s, from the start of the run), the inputs
    /// actually applied, and the measurements read at that tick, named by
    /// the rig's [`schema`](Rig::schema).
    pub recording: Recording,
    /// Timing statistics.
    pub stats: LoopStats,
}

/// How far the real-time clock sleeps before spinning to a deadline.
const SPIN: Duration = Duration::from_micros(200);

/// Runs `controller` against `rig` for `config.duration` seconds at the
/// rig's period `T`, with reference `reference(t)` (SI, `t` in s from the
/// start), timed by `clock`.
///
/// Each tick `k`, at the absolute deadline `k T`: read the measurements (on
/// [`MassSpringRig`](crate::lab::MassSpringRig) this latches the counters
/// and kicks the card's watchdog), evaluate the reference, update the
/// controller, apply its input, tell the controller what was applied
/// ([`Controller::applied`]), and record `(t, applied input,
/// measurements)`. At the end the rig is halted. The loop does not call
/// [`Rig::kick_watchdog`] on its own: a rig with a watchdog kicks it in
/// `read`, as `MassSpringRig` does (one control write latches and kicks).
///
/// The same controller object runs unchanged in the sampled-data simulator
/// [`sim::run_sampled`](crate::sim::run_sampled), which follows the same
/// order.
///
/// # Errors
///
/// A [`RunError`] (boxed: it carries the whole recording) holding the
/// error, every sample recorded before it, the measurements read in the
/// failing tick if there were any, and the statistics. The rig has been
/// halted (best effort: a dead port cannot be told, but then the card's
/// watchdog stops the motor). Causes: any rig error (port fault, travel
/// limit, non-finite command), [`HwError::Overrun`] after
/// `max_consecutive_overruns` overruns in a row, and
/// [`HwError::InvalidConfig`] for a bad `config`, a rig whose period is
/// not finite and > 0, a controller designed for another period, or a rig
/// whose schema does not have `M` inputs and `P` measurements (nothing is
/// run then).
///
/// # Examples
///
/// The lab's cart-2 controller `Kf = [0 0 10 0.1]` (per mm) on the simulated
/// card with the nominal plant, 1 s of virtual time in a few milliseconds:
///
/// ```
/// use ctrlab::hw::{Clock, LoopConfig, VirtualClock, run};
/// use ctrlab::lab::{Cart, MassSpring, SimulatedRig};
/// use ctrlab::StateFeedback;
/// use nalgebra::vector;
///
/// let clock = VirtualClock::new();
/// let mut rig = SimulatedRig { truth: MassSpring::nominal(), ..Default::default() }
///     .rig(&Clock::Virtual(clock.clone()))?;
/// let controller = StateFeedback::from_lab_gains([0.0, 0.0, 10.0, 0.1], Cart::Two)?;
/// let loop_config = LoopConfig { duration: 1.0, ..LoopConfig::default() };
///
/// let out = run(&mut rig, controller, |_t| vector![0.030], &Clock::Virtual(clock), &loop_config)?;
/// assert_eq!(out.recording.len(), 500);
/// // Cart 2 ends near the closed loop's steady state, 28.57 mm for 30 mm.
/// let x2 = *out.recording.channel("x2")?.last().unwrap();
/// assert!((x2 - 0.02857).abs() < 2e-4, "{x2}");
/// assert_eq!(out.stats.overruns, 0);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn run<G, C, const M: usize, const P: usize, const R: usize>(
    mut rig: G,
    mut controller: C,
    mut reference: impl FnMut(f64) -> SVector<f64, R>,
    clock: &Clock,
    config: &LoopConfig,
) -> Result<RunOutcome, Box<RunError>>
where
    G: Rig<M, P>,
    C: Controller<P, R, M>,
{
    let period = rig.period();
    let schema = rig.schema();
    let checked = check_config(config, period).and_then(|ticks| {
        if let Some(p) = controller.period()
            && (p - period).abs() > 1e-9 * period
        {
            return Err(HwError::InvalidConfig {
                name: "period",
                value: period,
                reason: "the rig's period differs from the one the controller was designed for",
            });
        }
        if schema.inputs().len() != M || schema.measurements().len() != P {
            return Err(HwError::InvalidConfig {
                name: "schema",
                value: schema.len() as f64,
                reason: "the rig's schema does not have one channel per input and measurement",
            });
        }
        Ok(ticks)
    });
    let ticks = match checked {
        Ok(ticks) => ticks,
        Err(error) => {
            return Err(Box::new(RunError {
                error,
                recording: Recording::new(schema),
                last_measurement: None,
                stats: LoopStats::default(),
            }));
        }
    };
    let mut recording = Recording::with_capacity(schema, ticks);
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
                    // to back on stale time, and restart differenced
                    // estimates, which would otherwise span the gap.
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
        let y = match rig.read() {
            Ok(y) => y,
            Err(error) => return Err(stop(rig, error, recording, None, stats, lateness)),
        };
        let u = controller.update(&y, &reference(t));
        let applied = match rig.apply(&u) {
            Ok(v) => v,
            Err(error) => {
                let last = Some(y.as_slice().to_vec());
                return Err(stop(rig, error, recording, last, stats, lateness));
            }
        };
        controller.applied(&applied);
        // Cannot fail: the schema's sizes were checked above.
        recording.push_vectors(t, &applied, &y).ok();
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
fn stop<G: Rig<M, P>, const M: usize, const P: usize>(
    mut rig: G,
    error: HwError,
    recording: Recording,
    last_measurement: Option<Vec<f64>>,
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
        last_measurement,
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

fn check_config(config: &LoopConfig, period: f64) -> Result<usize, HwError> {
    let invalid = |name, value, reason| HwError::InvalidConfig {
        name,
        value,
        reason,
    };
    let LoopConfig {
        duration,
        max_consecutive_overruns,
    } = *config;
    if !(period.is_finite() && period >= 1e-6) {
        return Err(invalid(
            "period",
            period,
            "the rig's period must be finite and >= 1 µs",
        ));
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
