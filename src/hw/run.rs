//! The fixed-period control loop: drives any [`Controller`] against any
//! [`Rig`] at the rig's period `T` on absolute deadlines, records every
//! sample with its actual time, and fails safe.
//!
//! Deadlines are `t0 + k T`, never "now + T", so timing errors do not
//! accumulate (no drift). The loop stops, halts the rig (PWM to zero) and
//! returns the error with everything recorded so far on any of:
//!
//! - a rig error (port fault, travel limit, bus fault, a motor that does
//!   not respond, a non-finite command);
//! - a panic anywhere in the loop: the controller (its `update`, `applied`
//!   or `reset`), the reference function, or the rig's `read` or `apply`
//!   ([`LoopFault::Panicked`], naming where);
//! - too many timing faults — overruns (a tick whose work ends after the
//!   next deadline) and skipped deadlines (the loop fell a period or more
//!   behind) — within a window ([`LoopFault::TimingFaults`]);
//! - a gap: two samples, or a controller update, further apart than
//!   `max_gap` (by default half the rig's watchdog timeout, after which the
//!   card's watchdog would cut the motor and the next kick would silently
//!   re-energise it with a stale command; on a rig without a watchdog
//!   [`GAP_PERIODS`] periods, the software's own limit, as nothing else
//!   would stop a motor left at its last command) ([`LoopFault::Gap`]);
//! - a stop request, e.g. Ctrl-C, a closed terminal or Ctrl-Z through
//!   [`StopSignal::on_interrupt`] ([`LoopFault::Interrupted`]).
//!
//! In every case the rig is halted and the run returns what it recorded.
//!
//! The recording's time stamps are the actual sampling (latch) instants on
//! the monotonic clock, so a missed tick shows as a gap, never papered over;
//! its inputs are those the rig reports as applied.
//!
//! # Late ticks
//!
//! One policy, from the loop to the analyses:
//!
//! - A tick keeps its absolute deadline `k T` whatever happened before it.
//!   A tick whose sample is taken [`LATE_FRACTION`] of a period or more
//!   after its deadline is *late* ([`LoopStats::late`]); the next tick
//!   still samples at its own deadline, so it follows the late one by less
//!   than `(1 − LATE_FRACTION) T` — as little as a few µs.
//! - A tick that wakes up a whole period or more after its deadline skips
//!   the deadlines it missed ([`LoopStats::skipped`]) and samples at once:
//!   never two samples back to back on stale time. Too many skipped
//!   deadlines and overruns in a window stop the run
//!   ([`LoopFault::TimingFaults`]); an interval longer than `max_gap`
//!   stops it too ([`LoopFault::Gap`]).
//! - Both show in the recording, which is not resampled: its time stamps
//!   are the actual instants (a late sample is stamped late, a skipped
//!   deadline leaves a longer interval), with no extra column.
//! - Nothing downstream differentiates over a short interval:
//!   [`MassSpringRig::read_state`](crate::lab::MassSpringRig::read_state)
//!   takes its speeds over a stored sample at least `(1 − LATE_FRACTION) T`
//!   old (in the loop, the sample two ticks back always is), and its bus
//!   fault check allows a change of one count over any interval; the lab's
//!   identification splits the recording at short intervals and gaps, and
//!   its simulation applies each input its delay after the sample's actual
//!   instant ([`lab::ident`](crate::lab::ident)).
//!
//! The same policy runs on a [`VirtualClock`](super::VirtualClock) with a
//! seeded [`Jitter`](super::Jitter) schedule, which makes ticks late and
//! stall reproducibly for tests.

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::time::{Duration, Instant};

use nalgebra::SVector;

mod config;
mod stats;

use super::realtime;
use crate::data::Recording;
use crate::design::Controller;
use crate::hw::{Clock, ConfigError, LoopFault, Rig, RigError, StopSignal};

use config::check_config;
pub use config::{GAP_PERIODS, LoopConfig};
use stats::finish_stats;
pub use stats::{LATE_FRACTION, LoopStats};

/// A run that ended in an error: the error, with what was recorded before it.
///
/// # Examples
///
/// ```
/// use ctrlab::hw::{Clock, LoopConfig, LoopFaultKind, VirtualClock, run};
/// use ctrlab::{OpenLoop, lab::SimulatedRig};
/// use ctrlab::nalgebra::vector;
///
/// let clock = VirtualClock::new();
/// let rig = SimulatedRig::default().rig(&Clock::Virtual(clock.clone()))?;
/// // Full drive (26.7 N at 24 V on the default truth) runs cart 2 past its ±50 mm limit.
/// let err = run(rig, OpenLoop, |_| vector![24.0], &Clock::Virtual(clock), &LoopConfig::default()).unwrap_err();
/// assert_eq!(err.error.kind(), LoopFaultKind::TravelLimit);
/// assert!(!err.recording.is_empty()); // everything before the breach
/// # Ok::<(), ctrlab::hw::RigError>(())
/// ```
#[derive(Debug)]
pub struct RunError {
    /// What went wrong.
    pub error: RigError,
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
/// use ctrlab::nalgebra::vector;
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

/// How far the loop sleeps before spinning to a deadline without
/// real-time scheduling.
const SPIN: Duration = Duration::from_micros(200);

/// Runs `controller` against `rig` for `config.duration` seconds at the
/// rig's period `T`, with reference `reference(t)` (SI, `t` in s from the
/// start), timed by `clock`.
///
/// Each tick `k`, at the absolute deadline `k T`: check the stop request,
/// read the measurements (on [`MassSpringRig`](crate::lab::MassSpringRig)
/// this latches the counters and kicks the card's watchdog), evaluate the
/// reference at the sampling instant, update the controller, apply its
/// input, tell the controller what was applied ([`Controller::applied`]),
/// and record `(t, applied input, measurements)` with `t` the actual
/// sampling instant. At the end the rig is halted. The loop does not call
/// [`Rig::kick_watchdog`] on its own: a rig with a watchdog kicks it in
/// `read`, as `MassSpringRig` does (one control write latches and kicks).
///
/// The same controller object runs unchanged in the sampled-data simulator
/// [`sim::run_sampled`](crate::sim::run_sampled), which follows the same
/// order. Panics in the controller (`update`, `applied`, `reset`), the
/// reference and the rig's `read` and `apply` are caught (unless the binary
/// is built with `panic = "abort"`): the rig is halted and the recording
/// kept, as for any other fault.
///
/// # Errors
///
/// A [`RunError`] (boxed: it carries the whole recording) holding the
/// error, every sample recorded before it, the measurements read in the
/// failing tick if there were any, and the statistics. The rig has been
/// halted (best effort: a dead port cannot be told, but then the card's
/// watchdog stops the motor). Causes, by the [`RigError`] they come as:
///
/// - [`RigError::Port`] and [`RigError::Fault`] from the rig (a port fault,
///   [`LoopFault::TravelLimit`], [`LoopFault::BusFault`],
///   [`LoopFault::NotResponding`], a non-finite command);
/// - [`RigError::Fault`] from the loop: a panic in the controller, the
///   reference or the rig ([`LoopFault::Panicked`], its `what` saying
///   where); `max_timing_faults` overruns and skipped deadlines within
///   `timing_window` ([`LoopFault::TimingFaults`]); two samples, or one
///   controller update, further apart than the gap limit
///   ([`LoopConfig::gap_limit`], [`LoopFault::Gap`]); a stop request
///   ([`LoopFault::Interrupted`]);
/// - [`RigError::Config`] for a bad `config` (named by its field), a rig
///   whose period is not finite and ≥ 1 µs, a controller designed for
///   another period, or a rig whose schema does not have `M` inputs and `P`
///   measurements, and [`RigError::RealTime`] when real-time scheduling was
///   asked for and not granted (nothing is run then).
///
/// # Examples
///
/// The lab's cart-2 controller `Kf = [0 0 10 0.1]` (per mm) on the simulated
/// card with the nominal plant, 1 s of virtual time in a few milliseconds:
///
/// ```
/// use ctrlab::hw::{Clock, LoopConfig, VirtualClock, run};
/// use ctrlab::lab::{Cart, LabGains, MassSpring, SimulatedRig};
/// use ctrlab::nalgebra::vector;
///
/// let clock = VirtualClock::new();
/// let mut rig = SimulatedRig::ideal(MassSpring::nominal())
///     .rig(&Clock::Virtual(clock.clone()))?;
/// let controller = LabGains::new([0.0, 0.0, 10.0, 0.1], Cart::Two).state_feedback()?;
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
            return Err(ConfigError::conflict(
                "period",
                period,
                "the rig's period differs from the one the controller was designed for",
            ));
        }
        if schema.inputs().len() != M || schema.measurements().len() != P {
            return Err(ConfigError::conflict(
                "schema",
                schema.len() as f64,
                "the rig's schema does not have one channel per input and measurement",
            ));
        }
        Ok(ticks)
    });
    let max_gap = config.gap_limit(period, rig.watchdog_timeout());
    let checked = checked.and_then(|ticks| {
        if max_gap < period {
            return Err(ConfigError::conflict(
                "max_gap",
                max_gap,
                "must be at least the rig's period (half the watchdog timeout by default)",
            ));
        }
        if let Some(rt) = &config.realtime {
            rt.validate(period)?;
        }
        Ok(ticks)
    });
    let realtime = match (checked, &config.realtime) {
        (Ok(ticks), Some(rt)) => realtime::enter(rt).map(|guard| (ticks, Some(guard))),
        (Ok(ticks), None) => Ok((ticks, None)),
        (Err(e), _) => Err(e.into()),
    };
    let (ticks, _realtime_guard) = match realtime {
        Ok(ok) => ok,
        Err(error) => {
            return Err(Box::new(RunError {
                error,
                recording: Recording::new(schema),
                last_measurement: None,
                stats: LoopStats::default(),
            }));
        }
    };
    let spin = config.realtime.map_or(SPIN, |rt| rt.spin);
    let mut recording = Recording::with_capacity(schema, ticks);
    let mut lateness = Vec::with_capacity(ticks);
    if config.realtime.is_some() {
        // Fault the pages in now (they stay, locked), not in the first ticks.
        recording.prefault();
        lateness.resize(ticks, 0.0);
        lateness.clear();
    }
    let mut faults = FaultWindow::new(config.max_timing_faults, config.timing_window, ticks);
    let mut stats = LoopStats::default();
    let mut consecutive = 0usize;

    let wall_start = Instant::now();
    let virtual_start = match clock {
        Clock::Virtual(c) => c.now_nanos(),
        Clock::RealTime => 0,
    };
    let period_ns = (period * 1e9).round() as u64;
    let mut previous_sample: Option<f64> = None;

    macro_rules! fail {
        ($error:expr, $last:expr) => {
            return Err(stop(rig, $error.into(), recording, $last, stats, lateness))
        };
    }

    if let Err(payload) = catch_unwind(AssertUnwindSafe(|| controller.reset())) {
        fail!(panicked("controller (reset)", &payload, 0.0), None);
    }
    // The rig may have been used before: its last sample is not this run's.
    rig.restart();
    // A second Ctrl-C now only raises the flag: the loop halts the rig.
    let _running = super::stop::Running::enter();

    let mut k = 0usize;
    while k < ticks {
        let deadline = k as f64 * period;
        if config.stop.as_ref().is_some_and(StopSignal::is_requested) {
            fail!(LoopFault::Interrupted { at: deadline }, None);
        }
        // Wait for the absolute deadline k·T; `t` is the sampling instant.
        let (t, late) = match clock {
            Clock::Virtual(c) if c.jitter().is_none() => {
                // Time is kept in whole nanoseconds, and so is the record.
                let offset = (k as u64).saturating_mul(period_ns);
                let target = virtual_start.saturating_add(offset);
                c.advance_nanos(target.saturating_sub(c.now_nanos()));
                (offset as f64 * 1e-9, 0.0)
            }
            _ => {
                // When the loop wakes up: now on the wall clock; on a
                // jittered virtual clock, the deadline (or now, if past it)
                // plus the schedule's lateness for this tick.
                let elapsed = match clock {
                    Clock::Virtual(c) => {
                        let offset = (k as u64).saturating_mul(period_ns);
                        let target = virtual_start.saturating_add(offset);
                        let lateness = c.jitter().map_or(0.0, |j| j.lateness(k as u64));
                        let wake = target
                            .max(c.now_nanos())
                            .saturating_add((lateness * 1e9).round() as u64);
                        c.advance_nanos(wake.saturating_sub(c.now_nanos()));
                        c.now_nanos().saturating_sub(virtual_start) as f64 * 1e-9
                    }
                    Clock::RealTime => wall_start.elapsed().as_secs_f64(),
                };
                if elapsed > (k + 1) as f64 * period {
                    // A whole period or more behind (the OS took the CPU):
                    // skip the missed deadlines rather than run them back
                    // to back on stale time. Each is a timing fault, and
                    // the recording shows the gap.
                    let behind = ((elapsed / period) as usize).min(ticks);
                    let missed = behind - k;
                    stats.skipped += missed;
                    k = behind;
                    if faults.add(elapsed, missed) {
                        fail!(timing_faults(&faults, period, elapsed), None);
                    }
                    if k >= ticks {
                        break;
                    }
                }
                match clock {
                    Clock::Virtual(c) => {
                        let t = c.now_nanos().saturating_sub(virtual_start) as f64 * 1e-9;
                        (t, (t - k as f64 * period).max(0.0))
                    }
                    Clock::RealTime => {
                        let target = wall_start + Duration::from_secs_f64(k as f64 * period);
                        realtime::sleep_until(target, spin);
                        let now = Instant::now();
                        (
                            (now - wall_start).as_secs_f64(),
                            (now - target).as_secs_f64(),
                        )
                    }
                }
            }
        };
        lateness.push(late);
        if late >= LATE_FRACTION * period {
            stats.late += 1;
        }
        if let Some(previous) = previous_sample {
            let interval = t - previous;
            stats.max_interval = stats.max_interval.max(interval);
            if interval > max_gap {
                let error = LoopFault::Gap {
                    what: "the interval between two samples",
                    gap: interval,
                    limit: max_gap,
                    at: t,
                };
                fail!(error, None);
            }
        }

        let y = match catch_unwind(AssertUnwindSafe(|| rig.read())) {
            Ok(Ok(y)) => y,
            Ok(Err(error)) => fail!(error, None),
            Err(payload) => fail!(panicked("rig (read)", &payload, t), None),
        };
        previous_sample = Some(t);
        let r = match catch_unwind(AssertUnwindSafe(|| reference(t))) {
            Ok(r) => r,
            Err(payload) => fail!(
                panicked("reference", &payload, t),
                Some(y.as_slice().to_vec())
            ),
        };
        let u = match catch_unwind(AssertUnwindSafe(|| controller.update(&y, &r))) {
            Ok(u) => u,
            Err(payload) => fail!(
                panicked("controller", &payload, t),
                Some(y.as_slice().to_vec())
            ),
        };
        if let Clock::RealTime = clock {
            // The watchdog counts from the kick in `read`: a controller that
            // took too long must not have its stale command applied.
            let took = wall_start.elapsed().as_secs_f64() - t;
            if took > max_gap {
                let error = LoopFault::Gap {
                    what: "the controller",
                    gap: took,
                    limit: max_gap,
                    at: t,
                };
                fail!(error, Some(y.as_slice().to_vec()));
            }
        }
        let applied = match catch_unwind(AssertUnwindSafe(|| rig.apply(&u))) {
            Ok(Ok(v)) => v,
            Ok(Err(error)) => fail!(error, Some(y.as_slice().to_vec())),
            Err(payload) => fail!(
                panicked("rig (apply)", &payload, t),
                Some(y.as_slice().to_vec())
            ),
        };
        let told = catch_unwind(AssertUnwindSafe(|| controller.applied(&applied)));
        // Cannot fail: the schema's sizes were checked above.
        recording.push_vectors(t, &applied, &y).ok();
        stats.ticks += 1;
        if let Err(payload) = told {
            // The input reached the motor, so its sample is recorded; then
            // the rig is halted.
            fail!(panicked("controller (applied)", &payload, t), None);
        }

        // An overrun: this tick's work ended after the next deadline. The
        // tick is `k` now, after any skip: the deadline taken at the top of
        // the loop was the one the skip passed over.
        let end = match clock {
            Clock::RealTime => Some(wall_start.elapsed().as_secs_f64()),
            // A jittered virtual clock stands in for the wall clock (its
            // work takes no time, so only a miscounted skip would show).
            Clock::Virtual(c) if c.jitter().is_some() => {
                Some(c.now_nanos().saturating_sub(virtual_start) as f64 * 1e-9)
            }
            Clock::Virtual(_) => None,
        };
        if let Some(end) = end {
            if end > (k + 1) as f64 * period {
                stats.overruns += 1;
                consecutive += 1;
                stats.max_consecutive_overruns = stats.max_consecutive_overruns.max(consecutive);
                if faults.add(end, 1) {
                    fail!(timing_faults(&faults, period, end), None);
                }
            } else {
                consecutive = 0;
            }
        }
        k += 1;
    }
    match catch_unwind(AssertUnwindSafe(|| rig.halt())) {
        Ok(Ok(())) => {}
        Ok(Err(error)) => fail!(error, None),
        Err(payload) => fail!(
            panicked("rig (halt)", &payload, ticks as f64 * period),
            None
        ),
    }
    finish_stats(&mut stats, &mut lateness);
    Ok(RunOutcome { recording, stats })
}

/// The last `limit` timing faults' times, to count them in a window.
/// Allocated once, before the loop; a limit beyond the run's ticks can
/// never be reached, so it stores nothing.
struct FaultWindow {
    times: Vec<f64>,
    next: usize,
    count: usize,
    window: f64,
    limit: usize,
}

impl FaultWindow {
    fn new(limit: usize, window: f64, ticks: usize) -> Self {
        let capacity = if limit > ticks { 0 } else { limit.max(1) };
        Self {
            times: vec![f64::NEG_INFINITY; capacity],
            next: 0,
            count: 0,
            window,
            limit,
        }
    }

    /// Records `n` faults at time `t`; true when the window now holds
    /// `limit` faults.
    fn add(&mut self, t: f64, n: usize) -> bool {
        let capacity = self.times.len();
        if capacity == 0 {
            return false;
        }
        for _ in 0..n.min(capacity) {
            self.times[self.next] = t;
            self.next = (self.next + 1) % capacity;
        }
        self.count = self.count.saturating_add(n);
        // The oldest of the last `capacity` faults is at `next`.
        n >= capacity || (self.count >= capacity && t - self.times[self.next] <= self.window)
    }
}

fn timing_faults(faults: &FaultWindow, period: f64, at: f64) -> LoopFault {
    LoopFault::TimingFaults {
        faults: faults.limit,
        window: faults.window,
        period,
        at,
    }
}

/// The message of a caught panic.
fn panicked(what: &'static str, payload: &Box<dyn std::any::Any + Send>, at: f64) -> LoopFault {
    let message = payload
        .downcast_ref::<&str>()
        .map(|s| (*s).to_owned())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "(a panic without a message)".to_owned());
    LoopFault::Panicked { what, message, at }
}

/// Halts the rig after `error` and packs up what was recorded.
fn stop<G: Rig<M, P>, const M: usize, const P: usize>(
    mut rig: G,
    error: RigError,
    recording: Recording,
    last_measurement: Option<Vec<f64>>,
    mut stats: LoopStats,
    mut lateness: Vec<f64>,
) -> Box<RunError> {
    // The error to report is the cause; a failing halt is left to the card's
    // watchdog, and so is a rig whose halt panics (after its read or apply
    // did).
    catch_unwind(AssertUnwindSafe(|| rig.halt())).ok();
    finish_stats(&mut stats, &mut lateness);
    Box::new(RunError {
        error,
        recording,
        last_measurement,
        stats,
    })
}
