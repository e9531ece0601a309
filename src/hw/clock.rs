//! Where time comes from: [`Clock`] (wall-clock or virtual) and
//! [`VirtualClock`], shared simulated time for the simulated card and the
//! control loop.

use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};

use super::PortError;

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
    /// as fast as the CPU allows and is exactly reproducible.
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
