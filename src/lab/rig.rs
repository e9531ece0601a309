//! The lab's two-cart rig on the PC104 card, [`MassSpringRig`].

mod checks;
mod history;

use std::time::Instant;

use crate::nalgebra::{SVector, vector};

use super::Calibration;
use crate::data::Schema;
use crate::hw::{
    Clock, ConfigError, EppPort, LATE_FRACTION, LoopFault, MAX_DUTY, PWM_CHANNELS, Pc104,
    PortError, Rig, RigError,
};
use history::{History, Read};

/// The cart the motor drives (cart 2, [`Cart::Two`](super::Cart::Two)), as
/// an index into the calibration's per-cart arrays.
const DRIVEN: usize = 1;
/// The other cart (cart 1), moved only through the spring between them.
const OTHER: usize = 0;

/// The lab's two-cart rig on a [`Pc104`] card: counts to metres, volts to
/// PWM duty, with the safety the rig needs. A [`Rig`] with one input (the
/// motor, V) and four measurements `[x1, v1, x2, v2]` (m, m/s), named by
/// [`schema`](super::schema).
///
/// - Building it probes the card's ID ([`Calibration::card_id`]): an open
///   bus (`0x00` or `0xff`) or another card is refused before anything is
///   written.
/// - [`read_state`](Self::read_state) latches both counters **and kicks the
///   watchdog** in one control write, reads cart 1's and cart 2's counters,
///   and returns `[x1, v1, x2, v2]`; each speed is the count change over
///   the actual interval since a stored read at least
///   `(1 − LATE_FRACTION) T` old (never over the few µs after a late
///   tick), timed on the rig's [`Clock`] (the first read reports zero
///   speeds).
/// - Every read checks the measurement is physical, halting the rig
///   otherwise: a cart beyond its travel limit ([`LoopFault::TravelLimit`]),
///   a count change of more than one count faster than
///   [`Calibration::max_speed`]
///   ([`LoopFault::BusFault`]: a flipped bit, a glitch on the bus), a
///   change of drive that does not move the driven cart's (cart 2's)
///   encoder ([`LoopFault::NotResponding`]), or one that moves cart 1 while
///   cart 2's encoder stays still ([`LoopFault::EncoderNotFollowing`]: a
///   dead encoder, with which cart 2's travel limit cannot be checked).
/// - [`apply_voltage`](Self::apply_voltage) saturates to
///   ±`volts_full_scale` and quantises to the card's 0.1 % duty steps; a
///   non-finite command halts the rig and returns
///   [`PortError::InvalidCommand`]. A command more than the watchdog timeout
///   after the last read would re-energise a motor the card has cut: it is
///   refused ([`LoopFault::Gap`]) and the rig halted. A drive held at one
///   limit for longer than [`Calibration::max_saturation_time`] is refused
///   too ([`LoopFault::Saturated`]), and the rig halted (a flip to the
///   other limit starts the time again).
/// - Halting ([`Rig::halt`], and before any fault above) sets **every** PWM
///   channel of the card to zero, the motor's first: a channel the
///   calibration does not name may still have been set (by another
///   program, or a card file naming the wrong channel).
/// - Dropping the rig halts it the same way (errors ignored: there is no
///   one left to tell).
///
/// Nothing allocates in `read_state` or `apply_voltage`. The simulated rig
/// in one call is [`SimulatedRig::rig`](super::SimulatedRig::rig).
///
/// # Examples
///
/// ```
/// use ctrlab::hw::{Clock, VirtualClock};
/// use ctrlab::lab::SimulatedRig;
///
/// let clock = VirtualClock::new();
/// let mut rig = SimulatedRig::default().rig(&Clock::Virtual(clock.clone()))?;
/// assert_eq!(rig.apply_voltage(100.0)?, 24.0); // saturates at 24 V
/// clock.advance(0.02)?;
/// let x = rig.read_state()?; // the drive took the duty 0.15 ms after the write
/// assert_eq!(rig.card().port().pwm_duty(0), 1000);
/// assert!(x[2] > 0.0 && x[2] < 0.05);
/// assert!(rig.apply_voltage(f64::NAN).is_err());
/// clock.advance(0.001)?; // past the PWM delay
/// rig.card_mut().port_mut().sync()?;
/// assert_eq!(rig.card().port().pwm_duty(0), 0); // halted
/// # Ok::<(), ctrlab::hw::RigError>(())
/// ```
#[derive(Debug)]
pub struct MassSpringRig<P: EppPort> {
    card: Pc104<P>,
    calibration: Calibration,
    period: f64,
    clock: Clock,
    start: Instant,
    /// The last reads, to take speeds over an interval of about a period.
    history: History,
    /// Time of the last watchdog kick (s on `clock`).
    last_kick: Option<f64>,
    /// The voltage last applied, V.
    volts: f64,
    /// The counts when the driven cart's encoder last moved
    /// `stall_counts` (or at the run's first read), the drive then, V, and
    /// when, s on `clock`.
    motion: Option<([i64; 2], f64, f64)>,
    /// The episode of a drive that has differed from that by `stall_volts`
    /// or more with no motion of the driven cart's encoder.
    stall: Option<Episode>,
    /// The driven cart at rest, the baseline of the follow check.
    rest: Option<Rest>,
    /// Since when the drive has been at its limit (s on `clock`), and at
    /// which end (the duty's sign).
    saturated: Option<(f64, i16)>,
    /// Cart 1's counts at the start of the quiet check's window, and when
    /// (s on `clock`); see `check_quiet`.
    quiet: Option<(i64, f64)>,
}

/// A change of drive of `stall_volts` or more that the driven cart's
/// encoder has not answered yet.
#[derive(Debug, Clone, Copy)]
struct Episode {
    /// When it was first seen, s on the rig's clock.
    since: f64,
    /// The smallest change of drive over it, V.
    weakest: f64,
}

/// The driven cart at rest: at the run's first read, or once its encoder
/// has not moved `stall_counts` for `follow_time`.
#[derive(Debug, Clone, Copy)]
struct Rest {
    /// The other cart's counts then.
    other: i64,
    /// The drive then, V.
    drive: f64,
    /// A change of drive from it not answered yet.
    pushed: Option<Episode>,
}

impl<P: EppPort> MassSpringRig<P> {
    /// The rig on `card` with `calibration`, read every `period` seconds,
    /// timed on the wall clock. Reads the card's ID register once.
    ///
    /// # Errors
    ///
    /// [`RigError::Config`] for an invalid calibration or a period that is
    /// not finite and > 0; [`PortError::NotPresent`] when the ID
    /// register reads an open bus or another ID; port errors.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::{ConfigErrorKind, Pc104, PortErrorKind, testing::RegisterFile};
    /// use ctrlab::lab::{Calibration, MassSpringRig};
    ///
    /// let mut regs = RegisterFile::new();
    /// regs.set(0x00, 0xa5); // the ID register
    /// let rig = MassSpringRig::new(Pc104::new(regs.clone()), Calibration::default(), 0.002)?;
    /// assert_eq!(rig.period(), 0.002);
    /// let bad = MassSpringRig::new(Pc104::new(regs), Calibration::default(), 0.0);
    /// assert_eq!(bad.unwrap_err().kind(), ConfigErrorKind::Invalid);
    /// // No card: the bus reads 0xff.
    /// let mut open = RegisterFile::new();
    /// open.set(0x00, 0xff);
    /// let err = MassSpringRig::new(Pc104::new(open), Calibration::default(), 0.002).unwrap_err();
    /// assert_eq!(err.kind(), PortErrorKind::NotPresent);
    /// # Ok::<(), ctrlab::hw::RigError>(())
    /// ```
    pub fn new(card: Pc104<P>, calibration: Calibration, period: f64) -> Result<Self, RigError> {
        Self::with_clock(card, calibration, period, Clock::RealTime)
    }

    /// [`new`](Self::new) with the speeds and watchdog timed on `clock` (a
    /// simulated card's virtual clock).
    ///
    /// # Errors
    ///
    /// As [`new`](Self::new).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::{Clock, Pc104, VirtualClock};
    /// use ctrlab::lab::{MassSpringRig, SimulatedRig};
    /// let sim = SimulatedRig::default();
    /// let clock = Clock::Virtual(VirtualClock::new());
    /// let rig = MassSpringRig::with_clock(Pc104::new(sim.card(&clock)?), sim.calibration, 0.002, clock)?;
    /// assert_eq!(rig.calibration().card_id, 0xa5);
    /// # Ok::<(), ctrlab::hw::RigError>(())
    /// ```
    pub fn with_clock(
        mut card: Pc104<P>,
        calibration: Calibration,
        period: f64,
        clock: Clock,
    ) -> Result<Self, RigError> {
        calibration.validate()?;
        if !(period.is_finite() && period > 0.0) {
            return Err(ConfigError::invalid("period", period, "must be finite and > 0 s").into());
        }
        card.probe_id(calibration.card_id)?;
        Ok(Self {
            card,
            calibration,
            period,
            clock,
            start: Instant::now(),
            history: History::default(),
            last_kick: None,
            volts: 0.0,
            motion: None,
            stall: None,
            rest: None,
            saturated: None,
            quiet: None,
        })
    }

    /// The card driver.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{hw::Clock, lab::SimulatedRig};
    /// let rig = SimulatedRig::default().rig(&Clock::RealTime)?;
    /// assert_eq!(rig.card().port().voltage(), 0.0);
    /// # Ok::<(), ctrlab::hw::RigError>(())
    /// ```
    pub fn card(&self) -> &Pc104<P> {
        &self.card
    }

    /// The card driver, mutably (to clear counters, probe the ID, …).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{hw::{Clock, SIMULATED_CARD_ID}, lab::SimulatedRig};
    /// let mut rig = SimulatedRig::default().rig(&Clock::RealTime)?;
    /// assert_eq!(rig.card_mut().probe_id(SIMULATED_CARD_ID)?, SIMULATED_CARD_ID);
    /// # Ok::<(), ctrlab::hw::RigError>(())
    /// ```
    pub fn card_mut(&mut self) -> &mut Pc104<P> {
        &mut self.card
    }

    /// The calibration.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{hw::Clock, lab::SimulatedRig};
    /// let rig = SimulatedRig::default().rig(&Clock::RealTime)?;
    /// assert_eq!(rig.calibration().volts_full_scale, 24.0);
    /// # Ok::<(), ctrlab::hw::RigError>(())
    /// ```
    pub fn calibration(&self) -> &Calibration {
        &self.calibration
    }

    /// The sampling period the loop runs the rig at, s.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{hw::Clock, lab::SimulatedRig};
    /// let rig = SimulatedRig { period: 0.001, ..Default::default() }.rig(&Clock::RealTime)?;
    /// assert_eq!(rig.period(), 0.001);
    /// # Ok::<(), ctrlab::hw::RigError>(())
    /// ```
    pub fn period(&self) -> f64 {
        self.period
    }

    /// Now on the rig's clock, s.
    fn now(&self) -> f64 {
        match &self.clock {
            Clock::Virtual(c) => c.now_nanos() as f64 / 1e9,
            Clock::RealTime => self.start.elapsed().as_secs_f64(),
        }
    }

    /// The duty for `volts` (finite): saturated, quantised to 0.1 %.
    fn duty(&self, volts: f64) -> i16 {
        let full = self.calibration.volts_full_scale;
        let fraction = volts.clamp(-full, full) / full;
        (fraction * f64::from(MAX_DUTY)).round() as i16
    }

    /// Halts and returns `error`: the fault is what to report; should the
    /// halt fail too, the caller's own halt or the card's watchdog follows.
    fn fault<T>(&mut self, error: impl Into<RigError>) -> Result<T, RigError> {
        self.halt_motor().ok();
        Err(error.into())
    }

    /// Samples the state `[x1, v1, x2, v2]` (m, m/s): latches the counters
    /// and kicks the watchdog in one control write, then reads both
    /// counters. [`Rig::read`] is this.
    ///
    /// # Late ticks
    ///
    /// The rig keeps its last few reads (a fixed array: nothing is
    /// allocated). Each speed is the count change since the latest stored
    /// read at least `(1 − LATE_FRACTION) T` old (3/4 of the period `T`,
    /// [`LATE_FRACTION`]), over the actual interval between the two time
    /// stamps; only when no stored read is that old (reads faster than the
    /// period, outside the control loop) the oldest stored one is used,
    /// over an interval taken as `(1 − LATE_FRACTION) T` at least. In
    /// [`hw::run`](crate::hw::run) the read two ticks back is always more
    /// than a period old, so after a late tick the next speed is taken over
    /// two ticks instead of over the few µs left to the next deadline: one
    /// count of quantisation over 5 µs would read as 2 m/s, over 3/4 of a
    /// period it stays within 4/3 of a count per period. On time, the
    /// previous read is one period old and is the one used.
    ///
    /// The bus-fault check is judged over the same stored read and the
    /// longest the interval can have been: a change of one count either
    /// way is quantisation, never a fault, whatever the interval; more is a
    /// [`LoopFault::BusFault`] when it is faster than
    /// [`Calibration::max_speed`].
    ///
    /// # Errors
    ///
    /// Port errors; after halting: [`LoopFault::TravelLimit`] when a cart is
    /// beyond its limit, [`LoopFault::BusFault`] for a count change of more
    /// than one count faster than the carts can move, [`LoopFault::NotResponding`] for a change of
    /// drive the driven cart's encoder does not answer within
    /// [`Calibration::stall_time`], [`LoopFault::EncoderNotFollowing`] for
    /// one that moved the other cart and not, within
    /// [`Calibration::follow_time`], the driven cart's encoder.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{hw::Clock, lab::SimulatedRig};
    /// use ctrlab::nalgebra::vector;
    /// let mut rig = SimulatedRig { initial_state: [0.001, 0.0, 0.002, 0.0], ..Default::default() }
    ///     .rig(&Clock::RealTime)?;
    /// let x = rig.read_state()?; // the counters count from where they were cleared: 0
    /// assert_eq!(x[3], 0.0);
    /// # Ok::<(), ctrlab::hw::RigError>(())
    /// ```
    pub fn read_state(&mut self) -> Result<SVector<f64, 4>, RigError> {
        let cal = self.calibration;
        // The latch happens between these two instants: a preemption in
        // between widens the bracket, never shortens an interval.
        let before = self.now();
        self.card.latch_and_kick()?;
        let after = self.now();
        self.last_kick = Some(after);
        let counts = [
            self.card.read_counter(cal.encoder_channels[0])?,
            self.card.read_counter(cal.encoder_channels[1])?,
        ];
        let stamp = 0.5 * (before + after);
        // A read at least 3/4 of a period old: never a speed over the µs
        // after a late tick, and (unlike the nominal period as the interval)
        // still the actual interval, so a skipped deadline or a stall does
        // not inflate the speed. On time, the previous read (one period
        // old) is the one used: the same numbers as differencing over it.
        let min_age = (1.0 - LATE_FRACTION) * self.period;
        let base = self.history.base(stamp, min_age);
        self.history.push(Read {
            counts,
            stamp,
            earliest: before,
        });
        let (previous, interval, longest) = match base {
            // Speeds over the best estimate of the interval; the bus-fault
            // check over the longest it can have been.
            // The speeds' interval is at least 3/4 of a period even when no
            // stored read is that old (reads faster than the period): a
            // speed is never a count over a few µs.
            Some(read) if stamp > read.stamp => (
                read.counts,
                (stamp - read.stamp).max(min_age),
                after - read.earliest,
            ),
            _ => (counts, 0.0, 0.0),
        };
        let mut x = SVector::<f64, 4>::zeros();
        for cart in 0..2 {
            let scale = cal.sign[cart] * cal.metres_per_count;
            let moved = counts[cart].saturating_sub(previous[cart]);
            x[2 * cart] = counts[cart] as f64 * scale;
            if interval > 0.0 {
                let fastest = moved as f64 * scale / longest;
                // One count either way is quantisation (or an encoder's
                // edge jitter), at any interval.
                if moved.saturating_abs() > 1 && fastest.abs() > cal.max_speed {
                    // The sample is not a measurement: forget the reads.
                    self.history = History::default();
                    return self.fault(LoopFault::BusFault {
                        channel: cal.encoder_channels[cart],
                        counts: moved,
                        interval: longest,
                        speed: fastest,
                        limit: cal.max_speed,
                    });
                }
                x[2 * cart + 1] = moved as f64 * scale / interval;
            }
        }
        for cart in 0..2 {
            let (position, limit) = (x[2 * cart], cal.travel_limits[cart]);
            if position.abs() > limit {
                return self.fault(LoopFault::TravelLimit {
                    axis: cart + 1,
                    position,
                    limit,
                });
            }
        }
        self.check_response(counts, after)?;
        Ok(x)
    }

    /// Applies `volts` to the motor, saturated to ±`volts_full_scale` and
    /// quantised to the card's 0.1 % duty steps, and returns the voltage
    /// actually applied, V. [`Rig::apply`] is this.
    ///
    /// # Errors
    ///
    /// Port errors; after halting: [`PortError::InvalidCommand`] for a
    /// non-finite voltage, [`LoopFault::Gap`] when the watchdog timeout has
    /// passed since the last read (the card has cut the motor; applying now
    /// would re-energise it with a stale command), [`LoopFault::Saturated`]
    /// when the drive would stay at its limit (±`volts_full_scale`) beyond
    /// [`Calibration::max_saturation_time`].
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{hw::Clock, lab::SimulatedRig};
    /// let mut rig = SimulatedRig::default().rig(&Clock::RealTime)?;
    /// assert_eq!(rig.apply_voltage(1.01)?, 1.008); // 42 duty steps of 24 mV
    /// # Ok::<(), ctrlab::hw::RigError>(())
    /// ```
    pub fn apply_voltage(&mut self, volts: f64) -> Result<f64, RigError> {
        if !volts.is_finite() {
            let error = PortError::InvalidCommand {
                what: "voltage",
                channel: Some(self.calibration.pwm_channel),
                value: volts,
                limit: self.calibration.volts_full_scale,
            };
            return self.fault(error);
        }
        if let (Some(timeout), Some(kick)) = (self.calibration.watchdog_timeout, self.last_kick) {
            let now = self.now();
            if now - kick >= timeout && volts != 0.0 {
                let error = LoopFault::Gap {
                    what: "the time since the last watchdog kick",
                    gap: now - kick,
                    limit: timeout,
                    at: now,
                };
                return self.fault(error);
            }
        }
        let duty = self.duty(volts);
        if duty.abs() == MAX_DUTY {
            let now = self.now();
            // Time pushing one way against the limit: a flip from one end
            // to the other (a bang-bang square wave at full scale) starts
            // it again, as the drive has just done something else.
            let since = match self.saturated {
                Some((since, end)) if end == duty.signum() => since,
                _ => now,
            };
            self.saturated = Some((since, duty.signum()));
            let limit = self.calibration.max_saturation_time;
            if now - since >= limit {
                let error = LoopFault::Saturated {
                    volts: self.calibration.volts_full_scale,
                    seconds: now - since,
                    limit,
                };
                return self.fault(error);
            }
        } else {
            self.saturated = None;
        }
        self.card.set_pwm(self.calibration.pwm_channel, duty)?;
        self.volts = f64::from(duty) / f64::from(MAX_DUTY) * self.calibration.volts_full_scale;
        Ok(self.volts)
    }

    /// Zeroes every PWM channel, the motor's first; every channel is
    /// tried even if one fails, and the first failure is returned.
    fn halt_motor(&mut self) -> Result<(), PortError> {
        self.volts = 0.0;
        self.saturated = None;
        let motor = self.calibration.pwm_channel;
        let mut result = self.card.set_pwm(motor, 0);
        for channel in (0..PWM_CHANNELS).filter(|&c| c != motor) {
            let zeroed = self.card.set_pwm(channel, 0);
            if result.is_ok() {
                result = zeroed;
            }
        }
        result
    }
}

impl<P: EppPort> Rig<1, 4> for MassSpringRig<P> {
    #[inline]
    fn read(&mut self) -> Result<SVector<f64, 4>, RigError> {
        self.read_state()
    }

    #[inline]
    fn apply(&mut self, u: &SVector<f64, 1>) -> Result<SVector<f64, 1>, RigError> {
        Ok(vector![self.apply_voltage(u[0])?])
    }

    fn halt(&mut self) -> Result<(), RigError> {
        Ok(self.halt_motor()?)
    }

    fn period(&self) -> f64 {
        self.period
    }

    fn schema(&self) -> Schema {
        super::schema()
    }

    fn watchdog_timeout(&self) -> Option<f64> {
        self.calibration.watchdog_timeout
    }

    fn kick_watchdog(&mut self) -> Result<(), RigError> {
        self.card.kick_watchdog()?;
        self.last_kick = Some(self.now());
        Ok(())
    }

    fn restart(&mut self) {
        self.history = History::default();
        self.motion = None;
        self.stall = None;
        self.rest = None;
        self.saturated = None;
        self.quiet = None;
    }
}

impl<P: EppPort> Drop for MassSpringRig<P> {
    /// Halts: every PWM channel to zero, as [`Rig::halt`].
    fn drop(&mut self) {
        // Best effort: a failing port cannot be reported from a destructor,
        // and the card's watchdog zeroes the PWM anyway (if it has one).
        self.halt_motor().ok();
    }
}
