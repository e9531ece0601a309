//! [`HwError`]: everything that can go wrong talking to the rig, with context.

use std::fmt;

/// Which of the three EPP primitives a failed cycle was.
///
/// # Examples
///
/// ```
/// use ctrlab::hw::CycleKind;
/// assert_eq!(CycleKind::DataRead.to_string(), "data read");
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum CycleKind {
    /// An EPP address-write cycle (selects a card register).
    AddressWrite,
    /// An EPP data-read cycle (reads the selected register).
    DataRead,
    /// An EPP data-write cycle (writes the selected register).
    DataWrite,
}

impl fmt::Display for CycleKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            CycleKind::AddressWrite => "address write",
            CycleKind::DataRead => "data read",
            CycleKind::DataWrite => "data write",
        })
    }
}

/// The category of a [`HwError`], for callers that branch on what happened
/// rather than on the details.
///
/// `#[non_exhaustive]`: match with a wildcard arm.
///
/// # Examples
///
/// ```
/// use ctrlab::hw::{CycleKind, HwError, HwErrorKind};
/// let e = HwError::Timeout { cycle: CycleKind::DataRead, register: Some(0x20) };
/// assert_eq!(e.kind(), HwErrorKind::Timeout);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum HwErrorKind {
    /// The card did not complete an EPP handshake in time (or a read/write
    /// transferred fewer bytes than asked).
    Timeout,
    /// The device or card is not there (no such port, wrong card ID, no EPP).
    NotPresent,
    /// The operating system refused access to the device.
    Permission,
    /// Another driver or program holds the device (the printer driver `lp`
    /// on a parallel port).
    Busy,
    /// Any other operating-system I/O failure.
    Io,
    /// A moving part left its software travel limits; the rig has been halted.
    TravelLimit,
    /// A command was out of range or not finite (a NaN voltage, a PWM duty
    /// beyond ±1000, a channel that does not exist).
    InvalidCommand,
    /// A configuration value (register map, calibration, simulated card) is
    /// invalid.
    InvalidConfig,
    /// The control loop lost its timing: too many overruns or skipped
    /// deadlines in a window, or a gap between samples long enough for the
    /// card's watchdog to trip; the rig has been halted.
    Timing,
    /// The controller or the reference function panicked; the rig has been
    /// halted.
    Panic,
    /// The run was interrupted (Ctrl-C, SIGTERM, or a stop request); the rig
    /// has been halted.
    Interrupted,
    /// A measurement is physically impossible (an encoder count jumped
    /// further in one sample than the carts can move): a bus or encoder
    /// fault; the rig has been halted.
    BusFault,
    /// Sustained drive with no encoder motion: the motor, its driver or the
    /// encoders are not responding; the rig has been halted.
    NotResponding,
    /// Real-time scheduling (SCHED_FIFO, memory locking, CPU affinity) was
    /// asked for but could not be set up.
    RealTime,
    /// A simulated card cannot go on: its plant state left the finite
    /// numbers, or its clock jumped further ahead than it can catch up
    /// within a bounded amount of work.
    Simulation,
}

/// Everything that can go wrong in the `hw` module. Each variant carries the
/// context needed to act on it: which cycle and register, which device,
/// which axis and limit, which value.
///
/// `#[non_exhaustive]`: match with a wildcard arm, or on [`kind`](Self::kind).
///
/// # Examples
///
/// ```
/// use ctrlab::hw::{HwError, HwErrorKind};
/// let e = HwError::TravelLimit { axis: 2, position: 0.16, limit: 0.15 };
/// assert_eq!(e.kind(), HwErrorKind::TravelLimit);
/// assert!(e.to_string().contains("axis 2"));
/// let busy = HwError::Busy { device: "/dev/parport0".into(), reason: "lp holds it".into() };
/// assert_eq!(busy.kind(), HwErrorKind::Busy);
/// assert!(busy.to_string().starts_with("/dev/parport0 is held by another driver"));
/// ```
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum HwError {
    /// An EPP cycle timed out or transferred fewer bytes than asked.
    #[error("EPP {cycle} timed out{}", register_suffix(*.register))]
    Timeout {
        /// The cycle that failed.
        cycle: CycleKind,
        /// The card register being accessed, when the caller knows it.
        register: Option<u8>,
    },
    /// The device or the card is not present.
    #[error("{device} is not present: {reason}")]
    NotPresent {
        /// The device path or card name.
        device: String,
        /// Why it is considered absent.
        reason: String,
    },
    /// The operating system refused access.
    #[error(
        "permission denied on {device}: parallel ports belong to the `lp` group; add yourself \
         with `sudo usermod -aG lp $USER`, then log out and in again (groups are read at login)"
    )]
    Permission {
        /// The device path.
        device: String,
        /// The operating system's error.
        #[source]
        source: std::io::Error,
    },
    /// Another driver or program holds the device.
    #[error("{device} is held by another driver: {reason}")]
    Busy {
        /// The device path.
        device: String,
        /// What failed, what probably holds it, and how to free it.
        reason: String,
    },
    /// Another operating-system I/O failure.
    #[error("{operation} on {device} failed: {source}")]
    Io {
        /// The device path.
        device: String,
        /// What was being done (`"PPCLAIM"`, `"open"`, …).
        operation: &'static str,
        /// The operating system's error.
        #[source]
        source: std::io::Error,
    },
    /// A moving part (an axis: one of the lab's carts) left its software
    /// travel limit; the rig was halted first.
    #[error("axis {axis} at {position} m is beyond its travel limit ±{limit} m; rig halted")]
    TravelLimit {
        /// Which axis, counted from 1 (the lab: cart 1 or 2).
        axis: usize,
        /// Its measured position, m.
        position: f64,
        /// The limit it broke, m (symmetric about zero).
        limit: f64,
    },
    /// A command is out of range or not finite.
    #[error("invalid {what}{}: {value} (limit {limit})", channel_suffix(*.channel))]
    InvalidCommand {
        /// What was commanded (`"voltage"`, `"PWM duty"`, `"PWM channel"`, …).
        what: &'static str,
        /// The channel addressed, when there is one.
        channel: Option<usize>,
        /// The offending value.
        value: f64,
        /// The limit it had to respect (magnitude).
        limit: f64,
    },
    /// A configuration value is invalid.
    #[error("invalid configuration `{name}` = {value}: {reason}")]
    InvalidConfig {
        /// The field's name as it appears in the API.
        name: &'static str,
        /// The offending value.
        value: f64,
        /// What the value must satisfy.
        reason: &'static str,
    },
    /// Too many timing faults (overruns and skipped deadlines) within a
    /// window of time.
    #[error(
        "control loop lost its timing: {faults} timing faults (overruns or skipped deadlines) within {window} s at t = {at:.4} s, period {period} s; rig halted"
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
    /// with a stale command.
    #[error(
        "{what} took {gap:.4} s at t = {at:.4} s, longer than the {limit:.4} s allowed (half the watchdog timeout); rig halted"
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
    /// The controller or reference function panicked.
    #[error("the {what} panicked at t = {at:.4} s: {message}; rig halted")]
    Panicked {
        /// `"controller"` or `"reference"`.
        what: &'static str,
        /// The panic's message.
        message: String,
        /// Time into the run, s.
        at: f64,
    },
    /// The run was stopped by a signal or a stop request.
    #[error("interrupted at t = {at:.4} s (Ctrl-C, SIGTERM or a stop request); rig halted")]
    Interrupted {
        /// Time into the run, s.
        at: f64,
    },
    /// An encoder moved further in one sample than the rig can physically
    /// move: a bus or counter fault (a flipped bit), not a measurement.
    #[error(
        "bus fault: encoder {channel} implies {speed:.3} m/s (limit {limit} m/s): {counts} counts in {interval:.4} s; rig halted"
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
    /// Sustained drive, no motion.
    #[error(
        "motor or encoder not responding: {volts:.2} V applied for {seconds:.3} s and no encoder moved more than {counts} counts; rig halted"
    )]
    NotResponding {
        /// The drive applied, V (its smallest magnitude over the episode).
        volts: f64,
        /// How long, s.
        seconds: f64,
        /// The motion threshold, counts.
        counts: i64,
    },
    /// Real-time scheduling could not be set up.
    #[error("cannot {what}: {reason}. {hint}")]
    RealTime {
        /// What was asked (`"set SCHED_FIFO priority 80"`, `"lock memory"`, …).
        what: String,
        /// The operating system's answer.
        reason: String,
        /// How to grant it.
        hint: &'static str,
    },
    /// A simulated card cannot go on (see [`HwErrorKind::Simulation`]); its
    /// time and plant state are left where they were before the access.
    #[error("simulated card at t = {at:.4} s: {reason}")]
    Simulation {
        /// What went wrong, with the numbers.
        reason: String,
        /// The card's time, s.
        at: f64,
    },
}

fn register_suffix(register: Option<u8>) -> String {
    register.map_or_else(String::new, |r| format!(" at register {r:#04x}"))
}

fn channel_suffix(channel: Option<usize>) -> String {
    channel.map_or_else(String::new, |c| format!(" on channel {c}"))
}

impl HwError {
    /// The category of this error.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::{HwError, HwErrorKind};
    /// let e = HwError::InvalidCommand { what: "voltage", channel: None, value: f64::NAN, limit: 24.0 };
    /// assert_eq!(e.kind(), HwErrorKind::InvalidCommand);
    /// ```
    pub fn kind(&self) -> HwErrorKind {
        match self {
            HwError::Timeout { .. } => HwErrorKind::Timeout,
            HwError::NotPresent { .. } => HwErrorKind::NotPresent,
            HwError::Permission { .. } => HwErrorKind::Permission,
            HwError::Busy { .. } => HwErrorKind::Busy,
            HwError::Io { .. } => HwErrorKind::Io,
            HwError::TravelLimit { .. } => HwErrorKind::TravelLimit,
            HwError::InvalidCommand { .. } => HwErrorKind::InvalidCommand,
            HwError::InvalidConfig { .. } => HwErrorKind::InvalidConfig,
            HwError::TimingFaults { .. } | HwError::Gap { .. } => HwErrorKind::Timing,
            HwError::Panicked { .. } => HwErrorKind::Panic,
            HwError::Interrupted { .. } => HwErrorKind::Interrupted,
            HwError::BusFault { .. } => HwErrorKind::BusFault,
            HwError::NotResponding { .. } => HwErrorKind::NotResponding,
            HwError::RealTime { .. } => HwErrorKind::RealTime,
            HwError::Simulation { .. } => HwErrorKind::Simulation,
        }
    }

    /// An [`InvalidConfig`](HwError::InvalidConfig) error (crate helper for
    /// the validators).
    pub(crate) fn invalid_config(name: &'static str, value: f64, reason: &'static str) -> Self {
        HwError::InvalidConfig {
            name,
            value,
            reason,
        }
    }

    /// Adds the card register to a [`Timeout`](HwError::Timeout) that does
    /// not name one yet; other errors pass through unchanged. Drivers call it
    /// so an error says where on the card it happened.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::{CycleKind, HwError};
    /// let e = HwError::Timeout { cycle: CycleKind::DataRead, register: None }.at_register(0x21);
    /// assert!(matches!(e, HwError::Timeout { register: Some(0x21), .. }));
    /// assert!(e.to_string().contains("0x21"));
    /// ```
    pub fn at_register(self, address: u8) -> Self {
        match self {
            HwError::Timeout {
                cycle,
                register: None,
            } => HwError::Timeout {
                cycle,
                register: Some(address),
            },
            other => other,
        }
    }
}
