//! Where time comes from: [`Clock`] (wall-clock or virtual) and
//! [`VirtualClock`], shared simulated time for the simulated card and the
//! control loop, optionally with a seeded [`Jitter`] schedule that makes
//! the loop's ticks late and stall as on a loaded machine.

use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};

use super::{ConfigError, PortError};
use crate::signal::Rng;

/// Where the control loop and the simulated card take their time from.
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
    /// Wall-clock time (`std::time::Instant`). The loop sleeps until each
    /// deadline (the last 200 µs are spun for precision); a simulated card
    /// integrates its plant to the time of each access. Not a real-time
    /// kernel: expect occasional lateness of tens of µs or more under load.
    RealTime,
    /// Simulated time: each tick of the loop advances the [`VirtualClock`]
    /// by exactly one period and never sleeps, so a 5 s experiment on a
    /// [`SimulatedCard`](super::SimulatedCard) sharing the same clock runs
    /// as fast as the CPU allows and is exactly reproducible. With a
    /// [`Jitter`] schedule ([`VirtualClock::with_jitter`]) each tick wakes
    /// up late by the schedule's seeded lateness instead, and the loop
    /// treats it as it treats a late tick on the wall clock.
    Virtual(VirtualClock),
}

/// A cheap, cloneable handle to shared simulated time, counted in whole
/// nanoseconds from zero.
///
/// Every clone sees the same time. A [`SimulatedCard`](super::SimulatedCard)
/// built on a virtual clock advances its plant to the clock's time whenever
/// it is accessed, so a loop that advances the clock by exactly one period
/// per tick advances the plant by exactly one period per tick, as fast as
/// the CPU allows. Time only moves forward.
///
/// # Examples
///
/// ```
/// use ctrlab::hw::VirtualClock;
///
/// let clock = VirtualClock::new();
/// let card_side = clock.clone();
/// clock.advance(0.002)?;
/// assert_eq!(card_side.now_nanos(), 2_000_000);
/// assert_eq!(card_side.now(), 0.002);
/// # Ok::<(), ctrlab::hw::PortError>(())
/// ```
#[derive(Debug, Clone, Default)]
pub struct VirtualClock {
    nanos: Arc<AtomicU64>,
    /// How late the loop's ticks wake up on this handle (none: on time).
    jitter: Option<Jitter>,
}

/// A seeded schedule of late ticks and stalls for the control loop on a
/// [`VirtualClock`]: a real-time-like clock that is still exactly
/// reproducible.
///
/// Tick `k` wakes up [`lateness(k)`](Self::lateness) seconds after its
/// deadline: with probability `stall_fraction` a stall of between half of
/// `stall` and `stall` (uniform), else with probability `late_fraction` a
/// lateness uniform in `[0, max_late)`, else none. The draw for tick `k`
/// depends only on the seed and `k` (splitmix64, [`Rng`]), so the same
/// schedule gives the same run. The loop ([`run`](super::run)) handles a
/// late wake-up as on the wall clock: a tick a period or more late skips
/// the deadlines it missed ([`LoopStats::skipped`](super::LoopStats)),
/// and the next tick keeps its own deadline, however soon that is. Skipped
/// deadlines are timing faults there too: a schedule that skips more than
/// [`LoopConfig::max_timing_faults`](super::LoopConfig) deadlines within
/// its window stops the run, unless the limit is raised.
///
/// # Examples
///
/// ```
/// use ctrlab::hw::Jitter;
/// let jitter = Jitter { seed: 7, late_fraction: 0.1, max_late: 0.004, stall_fraction: 0.01, stall: 0.010 };
/// assert!(jitter.validate().is_ok());
/// let late = (0..10_000).filter(|&k| jitter.lateness(k) > 0.0).count();
/// assert!((1000..1300).contains(&late), "{late}"); // about 11 %
/// assert!((0..10_000).all(|k| jitter.lateness(k) < 0.010));
/// assert_eq!(jitter.lateness(42), jitter.lateness(42)); // reproducible
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Jitter {
    /// Seed of the schedule.
    pub seed: u64,
    /// Fraction of ticks that are late (0–1).
    pub late_fraction: f64,
    /// Longest lateness of a late tick, s (≥ 0).
    pub max_late: f64,
    /// Fraction of ticks that stall (0–1; with `late_fraction`, at most 1).
    pub stall_fraction: f64,
    /// Longest stall, s (≥ 0); a stall lasts between half of it and it.
    pub stall: f64,
}

impl Jitter {
    /// Checks the fields.
    ///
    /// # Errors
    ///
    /// [`ConfigError::Invalid`] naming the first bad field: a fraction
    /// outside 0–1 (or the two summing to more than 1), a duration that is
    /// negative or not finite.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::Jitter;
    /// let bad = Jitter { seed: 0, late_fraction: 0.8, max_late: 0.001, stall_fraction: 0.3, stall: 0.01 };
    /// assert_eq!(bad.validate().unwrap_err().key(), "stall_fraction");
    /// ```
    pub fn validate(&self) -> Result<(), ConfigError> {
        let fraction = |f: f64| (0.0..=1.0).contains(&f);
        let duration = |d: f64| d.is_finite() && d >= 0.0;
        if !fraction(self.late_fraction) {
            return Err(ConfigError::invalid(
                "late_fraction",
                self.late_fraction,
                "must be within 0-1",
            ));
        }
        if !(fraction(self.stall_fraction) && self.late_fraction + self.stall_fraction <= 1.0) {
            return Err(ConfigError::invalid(
                "stall_fraction",
                self.stall_fraction,
                "must be within 0-1, and at most 1 with late_fraction",
            ));
        }
        if !duration(self.max_late) {
            return Err(ConfigError::invalid(
                "max_late",
                self.max_late,
                "must be finite and >= 0 s",
            ));
        }
        if !duration(self.stall) {
            return Err(ConfigError::invalid(
                "stall",
                self.stall,
                "must be finite and >= 0 s",
            ));
        }
        Ok(())
    }

    /// How late tick `k` wakes up after its deadline, s (0 for a tick on
    /// time).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::Jitter;
    /// let stalls = Jitter { seed: 1, late_fraction: 0.0, max_late: 0.0, stall_fraction: 1.0, stall: 0.01 };
    /// assert!((0..100).all(|k| (0.005..=0.01).contains(&stalls.lateness(k))));
    /// ```
    pub fn lateness(&self, k: u64) -> f64 {
        // Three draws per tick, from the tick's own place in the stream.
        let start = self
            .seed
            .wrapping_add(k.wrapping_mul(3).wrapping_mul(0x9e37_79b9_7f4a_7c15));
        let mut rng = Rng::new(start);
        let (which, first, _) = (rng.uniform(), rng.uniform(), rng.uniform());
        if which < self.stall_fraction {
            self.stall * (0.5 + 0.5 * first)
        } else if which < self.stall_fraction + self.late_fraction {
            self.max_late * first
        } else {
            0.0
        }
    }
}

impl VirtualClock {
    /// A clock at time zero.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::hw::VirtualClock;
    /// assert_eq!(VirtualClock::new().now(), 0.0);
    /// ```
    pub fn new() -> Self {
        Self::default()
    }

    /// This handle with the loop's ticks made late by `jitter`. Only the
    /// control loop consults the schedule, on the handle it is given
    /// ([`Clock::Virtual`]); every clone still shares the same time.
    ///
    /// # Errors
    ///
    /// [`ConfigError::Invalid`] for an invalid schedule
    /// ([`Jitter::validate`]).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::{Jitter, VirtualClock};
    /// let jitter = Jitter { seed: 3, late_fraction: 0.2, max_late: 0.002, stall_fraction: 0.0, stall: 0.0 };
    /// let clock = VirtualClock::new().with_jitter(jitter)?;
    /// assert_eq!(clock.jitter(), Some(&jitter));
    /// assert_eq!(VirtualClock::new().jitter(), None);
    /// # Ok::<(), ctrlab::hw::ConfigError>(())
    /// ```
    pub fn with_jitter(self, jitter: Jitter) -> Result<Self, ConfigError> {
        jitter.validate()?;
        Ok(Self {
            jitter: Some(jitter),
            ..self
        })
    }

    /// The schedule of late ticks on this handle, if any.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::hw::VirtualClock;
    /// assert!(VirtualClock::new().jitter().is_none());
    /// ```
    pub fn jitter(&self) -> Option<&Jitter> {
        self.jitter.as_ref()
    }

    /// The current time, s.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::hw::VirtualClock;
    /// let clock = VirtualClock::new();
    /// clock.advance_nanos(1_500_000_000);
    /// assert_eq!(clock.now(), 1.5);
    /// ```
    pub fn now(&self) -> f64 {
        self.now_nanos() as f64 * 1e-9
    }

    /// The current time, ns.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::hw::VirtualClock;
    /// let clock = VirtualClock::new();
    /// clock.advance_nanos(7);
    /// assert_eq!(clock.now_nanos(), 7);
    /// ```
    pub fn now_nanos(&self) -> u64 {
        self.nanos.load(Ordering::Acquire)
    }

    /// Moves time forward by `dt` seconds, rounded to the nearest
    /// nanosecond.
    ///
    /// # Errors
    ///
    /// [`PortError::InvalidCommand`] when `dt` is negative or not finite, or
    /// when the clock would pass `u64::MAX` ns (584 years); time is then
    /// left unchanged. (The clock is the simulated card's time: refusing to
    /// move it is the simulated card refusing a command.)
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::hw::{PortErrorKind, VirtualClock};
    /// let clock = VirtualClock::new();
    /// clock.advance(0.25)?;
    /// assert_eq!(clock.now_nanos(), 250_000_000);
    /// assert_eq!(clock.advance(-1.0).unwrap_err().kind(), PortErrorKind::InvalidCommand);
    /// // Never wraps around to the past (u64::MAX ns is 1.8e10 s).
    /// clock.advance(1e10)?;
    /// assert!(clock.advance(1e10).is_err());
    /// assert_eq!(clock.now(), 1e10 + 0.25);
    /// # Ok::<(), ctrlab::hw::PortError>(())
    /// ```
    pub fn advance(&self, dt: f64) -> Result<(), PortError> {
        let nanos = dt * 1e9;
        let refuse = |now: u64| PortError::InvalidCommand {
            what: "clock advance (s)",
            channel: None,
            value: dt,
            limit: (u64::MAX - now) as f64 * 1e-9,
        };
        if !(nanos.is_finite() && nanos >= 0.0 && nanos < u64::MAX as f64) {
            return Err(refuse(self.now_nanos()));
        }
        let step = nanos.round() as u64;
        self.nanos
            .fetch_update(Ordering::AcqRel, Ordering::Acquire, |now| {
                now.checked_add(step)
            })
            .map(|_| ())
            .map_err(refuse)
    }

    /// Moves time forward by `dt` nanoseconds, saturating at `u64::MAX` ns
    /// (584 years) rather than wrapping around to the past.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::hw::VirtualClock;
    /// let clock = VirtualClock::new();
    /// for _ in 0..500 {
    ///     clock.advance_nanos(2_000_000);
    /// }
    /// assert_eq!(clock.now(), 1.0);
    /// clock.advance_nanos(u64::MAX);
    /// clock.advance_nanos(1);
    /// assert_eq!(clock.now_nanos(), u64::MAX);
    /// ```
    pub fn advance_nanos(&self, dt: u64) {
        // The closure always returns `Some`, so the update cannot fail.
        let _ = self
            .nanos
            .fetch_update(Ordering::AcqRel, Ordering::Acquire, |now| {
                Some(now.saturating_add(dt))
            });
    }
}
