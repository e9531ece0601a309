//! [`LoopFault`]: what the control loop halted the rig for.

use crate::readable::Readable;

/// The category of a [`LoopFault`].
///
/// `#[non_exhaustive]`: match with a wildcard arm.
///
/// # Examples
///
/// ```
/// use ctrlab::hw::{LoopFault, LoopFaultKind};
/// assert_eq!(LoopFault::Interrupted { at: 1.0 }.kind(), LoopFaultKind::Interrupted);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum LoopFaultKind {
    /// A moving part left its software travel limits.
    TravelLimit,
    /// The control loop lost its timing: too many overruns or skipped
    /// deadlines in a window, or a gap between samples long enough for the
    /// card's watchdog to trip.
    Timing,
    /// The controller (its update, `applied` or `reset`), the reference
    /// function or the rig's read or apply panicked.
    Panic,
    /// The run was interrupted (Ctrl-C, SIGTERM, SIGHUP, SIGQUIT, Ctrl-Z's
    /// SIGTSTP, or a stop request).
    Interrupted,
    /// A measurement is physically impossible (an encoder count jumped
    /// further in one sample than the carts can move): a bus or encoder
    /// fault.
    BusFault,
    /// Sustained drive with no encoder motion: the motor, its driver or the
    /// encoders are not responding (the driven cart's encoder among them:
    /// [`LoopFault::EncoderNotFollowing`]).
    NotResponding,
    /// The drive stayed at its limit (saturated) longer than allowed.
    Saturated,
}

/// What the control loop, or a rig checking its measurements and commands,
/// halted the rig for. The rig has been halted (PWM to zero) before this is
/// returned; [`run`](crate::hw::run) keeps the recording up to it.
///
/// `#[non_exhaustive]`: match with a wildcard arm, or on [`kind`](Self::kind).
///
/// # Examples
///
/// ```
/// use ctrlab::hw::{LoopFault, LoopFaultKind};
/// let e = LoopFault::TravelLimit { axis: 2, position: 0.16, limit: 0.15 };
/// assert_eq!(e.kind(), LoopFaultKind::TravelLimit);
/// assert!(e.to_string().contains("axis 2"));
/// ```
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum LoopFault {
    /// A moving part (an axis: one of the lab's carts) left its software
    /// travel limit; the rig was halted first.
    #[error("axis {axis} at {} m is beyond its travel limit ±{} m; rig halted", Readable(*.position), Readable(*.limit))]
    TravelLimit {
        /// Which axis, counted from 1 (the lab: cart 1 or 2).
        axis: usize,
        /// Its measured position, m.
        position: f64,
        /// The limit it broke, m (symmetric about zero).
        limit: f64,
    },
    /// Too many timing faults (overruns and skipped deadlines) within a
    /// window of time.
    #[error(
        "control loop lost its timing: {faults} timing faults (overruns or skipped deadlines) within {} s at t = {at:.4} s, period {} s; rig halted",
        Readable(*.window), Readable(*.period)
    )]
    TimingFaults {
        /// Faults counted in the window when the loop gave up.
        faults: usize,
        /// The window, s.
        window: f64,
        /// The loop's period, s.
        period: f64,
        /// Time into the run, s.
        at: f64,
    },
    /// Too long without a sample (or a controller that took too long): the
    /// card's watchdog may trip and, kicked again, re-energise the motor
    /// with a stale command; without a watchdog, nothing would stop a motor
    /// left at its last command.
    #[error(
        "{what} took {gap:.4} s at t = {at:.4} s, longer than the {} s allowed (half the watchdog timeout, 25 periods on a card without one, or `LoopConfig::max_gap`); rig halted",
        Readable(*.limit)
    )]
    Gap {
        /// What took too long (`"the interval between two samples"`,
        /// `"the controller"`).
        what: &'static str,
        /// How long it took, s.
        gap: f64,
        /// The limit, s.
        limit: f64,
        /// Time into the run, s.
        at: f64,
    },
    /// The controller, the reference function or the rig panicked; the
    /// panic was caught, the rig halted and the recording kept.
    #[error("the {what} panicked at t = {at:.4} s: {message}; rig halted")]
    Panicked {
        /// Where: `"controller"` (its update), `"controller (applied)"`,
        /// `"controller (reset)"` (before the first tick, `at` = 0),
        /// `"reference"`, `"rig (read)"` or `"rig (apply)"`.
        what: &'static str,
        /// The panic's message.
        message: String,
        /// Time into the run, s.
        at: f64,
    },
    /// The run was stopped by a signal or a stop request.
    #[error(
        "interrupted at t = {at:.4} s (Ctrl-C, SIGTERM, SIGHUP, SIGQUIT, Ctrl-Z or a stop request); rig halted"
    )]
    Interrupted {
        /// Time into the run, s.
        at: f64,
    },
    /// An encoder moved further in one sample than the rig can physically
    /// move: a bus or counter fault (a flipped bit), not a measurement.
    #[error(
        "bus fault: encoder {channel} implies {speed:.3} m/s (limit {} m/s): {counts} counts in {interval:.4} s; rig halted",
        Readable(*.limit)
    )]
    BusFault {
        /// The encoder channel.
        channel: usize,
        /// The count change in the sample.
        counts: i64,
        /// Over this interval, s.
        interval: f64,
        /// The speed it implies, m/s.
        speed: f64,
        /// The largest plausible speed, m/s.
        limit: f64,
    },
    /// Sustained drive, no motion of the driven cart's encoder.
    #[error(
        "motor or encoder not responding: a change of drive of {volts:.2} V held for {seconds:.3} s did not move the driven cart's encoder {counts} counts; check the motor, its driver and the encoder's wiring; rig halted"
    )]
    NotResponding {
        /// The change of drive, V (its smallest magnitude over the episode).
        volts: f64,
        /// How long, s.
        seconds: f64,
        /// The motion threshold, counts.
        counts: i64,
    },
    /// The drive moved the carts (the other cart's encoder counted) but
    /// the driven cart's own encoder did not follow: a dead or disconnected
    /// encoder, with which the driven cart's travel limit cannot be
    /// checked.
    #[error(
        "the encoder of cart {cart} (the driven cart, encoder channel {channel}) does not follow the drive: a change of {volts:.2} V moved cart {other} {moved} counts within {seconds:.3} s while cart {cart}'s encoder moved fewer than {counts}; check that encoder and its channel in the calibration; rig halted"
    )]
    EncoderNotFollowing {
        /// The driven cart, counted from 1 (the lab: cart 2).
        cart: usize,
        /// Its encoder channel.
        channel: usize,
        /// The other cart, counted from 1.
        other: usize,
        /// The change of drive, V (its smallest magnitude over the episode).
        volts: f64,
        /// How long the driven cart's encoder had not answered, s.
        seconds: f64,
        /// How far the other cart moved meanwhile, counts.
        moved: i64,
        /// The motion threshold, counts.
        counts: i64,
    },
    /// The drive stayed at its limit longer than allowed: a controller
    /// that cannot reach its reference, or a measurement that is wrong,
    /// pushing with everything it has.
    #[error(
        "the drive stayed at its limit (±{} V) for {seconds:.3} s, the {} s allowed (calibration `max_saturation_time`): the controller cannot reach its reference or a measurement is wrong; rig halted",
        Readable(*.volts), Readable(*.limit)
    )]
    Saturated {
        /// The drive's limit, V (magnitude).
        volts: f64,
        /// How long the drive had been at it, s.
        seconds: f64,
        /// The longest allowed, s.
        limit: f64,
    },
}

impl LoopFault {
    /// The category of this fault.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::{LoopFault, LoopFaultKind};
    /// let gap = LoopFault::Gap { what: "the controller", gap: 0.2, limit: 0.05, at: 1.0 };
    /// assert_eq!(gap.kind(), LoopFaultKind::Timing);
    /// let pinned = LoopFault::Saturated { volts: 24.0, seconds: 2.0, limit: 2.0 };
    /// assert_eq!(pinned.kind(), LoopFaultKind::Saturated);
    /// assert!(pinned.to_string().contains("max_saturation_time"));
    /// ```
    pub fn kind(&self) -> LoopFaultKind {
        match self {
            LoopFault::TravelLimit { .. } => LoopFaultKind::TravelLimit,
            LoopFault::TimingFaults { .. } | LoopFault::Gap { .. } => LoopFaultKind::Timing,
            LoopFault::Panicked { .. } => LoopFaultKind::Panic,
            LoopFault::Interrupted { .. } => LoopFaultKind::Interrupted,
            LoopFault::BusFault { .. } => LoopFaultKind::BusFault,
            LoopFault::NotResponding { .. } | LoopFault::EncoderNotFollowing { .. } => {
                LoopFaultKind::NotResponding
            }
            LoopFault::Saturated { .. } => LoopFaultKind::Saturated,
        }
    }
}
