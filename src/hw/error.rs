//! The hardware layer's errors, one type per concern, each with a `kind()`:
//!
//! - [`PortError`]: talking to the card failed or was refused (an EPP
//!   timeout, no card, no permission, a busy port, an OS error, a command
//!   the driver refuses, a simulated card that cannot go on);
//! - [`ConfigError`]: a configuration value is invalid (a register map, a
//!   calibration, a simulated card or rig, a loop or real-time setting),
//!   named by its key;
//! - [`LoopFault`]: what [`run`](super::run) halted the rig for (a travel
//!   limit, lost timing, a panic, a stop request, a bus fault, a motor or
//!   an encoder that does not respond, a drive held at its limit);
//! - [`RealTimeError`]: real-time scheduling was asked for and not granted;
//! - [`RigError`]: any of them, what a [`Rig`](super::Rig) and
//!   [`run`](super::run) return, so `?` carries each of the others into it.

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

// ---- the port ----------------------------------------------------------------

/// The category of a [`PortError`].
///
/// `#[non_exhaustive]`: match with a wildcard arm.
///
/// # Examples
///
/// ```
/// use ctrlab::hw::{CycleKind, PortError, PortErrorKind};
/// let e = PortError::Timeout { cycle: CycleKind::DataRead, register: Some(0x20) };
/// assert_eq!(e.kind(), PortErrorKind::Timeout);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum PortErrorKind {
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
    /// The driver refused a command that is out of range or not finite (a
    /// NaN voltage, a PWM duty beyond ±1000, a channel that does not exist).
    InvalidCommand,
    /// A simulated card cannot go on: its plant state left the finite
    /// numbers, or its clock jumped further ahead than it can catch up
    /// within a bounded amount of work.
    Simulation,
}

/// Talking to the card failed, or the driver refused a command: what an
/// [`EppPort`](super::EppPort) (`Ppdev`, [`SimulatedCard`](super::SimulatedCard),
/// the [`testing`](super::testing) fakes) and the [`Pc104`](super::Pc104)
/// driver return. Each variant carries what is needed to act on it: which
/// cycle and register, which device, which value.
///
/// `#[non_exhaustive]`: match with a wildcard arm, or on [`kind`](Self::kind).
///
/// # Examples
///
/// ```
/// use ctrlab::hw::{PortError, PortErrorKind};
/// let busy = PortError::Busy { device: "/dev/parport0".into(), reason: "lp holds it".into() };
/// assert_eq!(busy.kind(), PortErrorKind::Busy);
/// assert!(busy.to_string().starts_with("/dev/parport0 is held by another driver"));
/// ```
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum PortError {
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
    /// A command is out of range or not finite: the driver refuses it
    /// (nothing is written).
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
    /// A simulated card cannot go on (see [`PortErrorKind::Simulation`]);
    /// its time and plant state are left where they were before the access.
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

impl PortError {
    /// The category of this error.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::{PortError, PortErrorKind};
    /// let e = PortError::InvalidCommand { what: "voltage", channel: None, value: f64::NAN, limit: 24.0 };
    /// assert_eq!(e.kind(), PortErrorKind::InvalidCommand);
    /// ```
    pub fn kind(&self) -> PortErrorKind {
        match self {
            PortError::Timeout { .. } => PortErrorKind::Timeout,
            PortError::NotPresent { .. } => PortErrorKind::NotPresent,
            PortError::Permission { .. } => PortErrorKind::Permission,
            PortError::Busy { .. } => PortErrorKind::Busy,
            PortError::Io { .. } => PortErrorKind::Io,
            PortError::InvalidCommand { .. } => PortErrorKind::InvalidCommand,
            PortError::Simulation { .. } => PortErrorKind::Simulation,
        }
    }

    /// Adds the card register to a [`Timeout`](PortError::Timeout) that
    /// does not name one yet; other errors pass through unchanged. Drivers
    /// call it so an error says where on the card it happened.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::{CycleKind, PortError};
    /// let e = PortError::Timeout { cycle: CycleKind::DataRead, register: None }.at_register(0x21);
    /// assert!(matches!(e, PortError::Timeout { register: Some(0x21), .. }));
    /// assert!(e.to_string().contains("0x21"));
    /// ```
    pub fn at_register(self, address: u8) -> Self {
        match self {
            PortError::Timeout {
                cycle,
                register: None,
            } => PortError::Timeout {
                cycle,
                register: Some(address),
            },
            other => other,
        }
    }
}

// ---- configuration -----------------------------------------------------------

/// The category of a [`ConfigError`].
///
/// `#[non_exhaustive]`: match with a wildcard arm.
///
/// # Examples
///
/// ```
/// use ctrlab::hw::{ConfigErrorKind, RegisterMap};
/// let clash = RegisterMap { control: 0x10, ..RegisterMap::default() };
/// assert_eq!(clash.validate().unwrap_err().kind(), ConfigErrorKind::Conflict);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum ConfigErrorKind {
    /// A value outside what it may be on its own (not finite, not
    /// positive, a channel that does not exist).
    Invalid,
    /// A value that clashes with another setting (two registers at one
    /// address, one channel for two carts, a period the controller was not
    /// designed for).
    Conflict,
}

/// A configuration value is invalid: which key, the value, and why. What
/// the validators of the register map, the calibration, the simulated card
/// and rig, the loop and the real-time options return.
///
/// The key is the field's name as the configuration spells it, dotted and
/// indexed where the value sits in a table or an array
/// (`travel_limits[1]`, `calibration.card_id`, `friction.coulomb[0]`); a
/// configuration made of parts names its parts' errors under their table
/// ([`in_table`](Self::in_table)), so code and file name a bad value alike.
///
/// `#[non_exhaustive]`: match with a wildcard arm, or on [`kind`](Self::kind).
///
/// # Examples
///
/// ```
/// use ctrlab::hw::{ConfigError, ConfigErrorKind};
/// let e = ConfigError::invalid("max_substep", 0.0, "must be finite and > 0");
/// assert_eq!((e.kind(), e.key(), e.value()), (ConfigErrorKind::Invalid, "max_substep", 0.0));
/// assert_eq!(e.to_string(), "invalid configuration `max_substep` = 0: must be finite and > 0");
/// ```
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ConfigError {
    /// A value outside what it may be on its own.
    #[error("invalid configuration `{key}` = {value}: {reason}")]
    Invalid {
        /// The field's key (see [`ConfigError`]).
        key: String,
        /// The offending value.
        value: f64,
        /// What the value must satisfy.
        reason: &'static str,
    },
    /// A value that clashes with another setting (named in the reason).
    #[error("conflicting configuration `{key}` = {value}: {reason}")]
    Conflict {
        /// The field's key (see [`ConfigError`]): of two that clash, the
        /// one checked last.
        key: String,
        /// The offending value.
        value: f64,
        /// What it clashes with.
        reason: &'static str,
    },
}

impl ConfigError {
    /// An [`Invalid`](ConfigError::Invalid) value.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::ConfigError;
    /// let e = ConfigError::invalid("period", -1.0, "must be finite and > 0 s");
    /// assert!(matches!(e, ConfigError::Invalid { ref key, .. } if key == "period"));
    /// ```
    pub fn invalid(key: impl Into<String>, value: f64, reason: &'static str) -> Self {
        ConfigError::Invalid {
            key: key.into(),
            value,
            reason,
        }
    }

    /// A [`Conflict`](ConfigError::Conflict) with another setting.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::{ConfigError, ConfigErrorKind};
    /// let e = ConfigError::conflict("encoder_channels[1]", 1.0, "the same channel as cart 1's");
    /// assert_eq!(e.kind(), ConfigErrorKind::Conflict);
    /// ```
    pub fn conflict(key: impl Into<String>, value: f64, reason: &'static str) -> Self {
        ConfigError::Conflict {
            key: key.into(),
            value,
            reason,
        }
    }

    /// The category of this error.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::{ConfigError, ConfigErrorKind};
    /// assert_eq!(ConfigError::invalid("x", 0.0, "must be > 0").kind(), ConfigErrorKind::Invalid);
    /// ```
    pub fn kind(&self) -> ConfigErrorKind {
        match self {
            ConfigError::Invalid { .. } => ConfigErrorKind::Invalid,
            ConfigError::Conflict { .. } => ConfigErrorKind::Conflict,
        }
    }

    /// The key of the field at fault.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::ConfigError;
    /// assert_eq!(ConfigError::invalid("seed", 0.0, "why").key(), "seed");
    /// ```
    pub fn key(&self) -> &str {
        match self {
            ConfigError::Invalid { key, .. } | ConfigError::Conflict { key, .. } => key,
        }
    }

    /// The offending value.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::ConfigError;
    /// assert_eq!(ConfigError::invalid("seed", 7.0, "why").value(), 7.0);
    /// ```
    pub fn value(&self) -> f64 {
        match self {
            ConfigError::Invalid { value, .. } | ConfigError::Conflict { value, .. } => *value,
        }
    }

    /// What the value must satisfy, or what it clashes with.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::ConfigError;
    /// assert_eq!(ConfigError::invalid("seed", 7.0, "why").reason(), "why");
    /// ```
    pub fn reason(&self) -> &'static str {
        match self {
            ConfigError::Invalid { reason, .. } | ConfigError::Conflict { reason, .. } => reason,
        }
    }

    /// The same error with its key under `table`: `table.key`. A
    /// configuration made of parts names its parts' errors so.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::ConfigError;
    /// let e = ConfigError::invalid("travel_limits[1]", -0.05, "must be finite and > 0");
    /// assert_eq!(e.in_table("calibration").key(), "calibration.travel_limits[1]");
    /// ```
    #[must_use]
    pub fn in_table(mut self, table: &str) -> Self {
        let (ConfigError::Invalid { key, .. } | ConfigError::Conflict { key, .. }) = &mut self;
        *key = format!("{table}.{key}");
        self
    }

    /// The same error under another key (a value derived from a
    /// configuration's field, reported under that field's key).
    #[must_use]
    #[cfg(feature = "lab")]
    pub(crate) fn with_key(mut self, new: String) -> Self {
        let (ConfigError::Invalid { key, .. } | ConfigError::Conflict { key, .. }) = &mut self;
        *key = new;
        self
    }
}

/// Checks that `value` is finite and > 0 (the validators' most common rule).
pub(crate) fn check_positive(key: &'static str, value: f64) -> Result<(), ConfigError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(ConfigError::invalid(key, value, "must be finite and > 0"))
    }
}

/// Each of `values` finite and > 0, the key of a bad one indexed
/// (`travel_limits[1]`).
#[cfg(feature = "lab")]
pub(crate) fn check_all_positive(key: &'static str, values: &[f64]) -> Result<(), ConfigError> {
    match values.iter().position(|v| !(v.is_finite() && *v > 0.0)) {
        None => Ok(()),
        Some(i) => Err(ConfigError::invalid(
            format!("{key}[{i}]"),
            values[i],
            "must be finite and > 0",
        )),
    }
}

// ---- the loop ----------------------------------------------------------------

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
/// returned; [`run`](super::run) keeps the recording up to it.
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
    #[error("axis {axis} at {position} m is beyond its travel limit ±{limit} m; rig halted")]
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
    /// with a stale command; without a watchdog, nothing would stop a motor
    /// left at its last command.
    #[error(
        "{what} took {gap:.4} s at t = {at:.4} s, longer than the {limit:.4} s allowed (half the watchdog timeout, 25 periods on a card without one, or `LoopConfig::max_gap`); rig halted"
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
        "the drive stayed at its limit (±{volts} V) for {seconds:.3} s, the {limit} s allowed (calibration `max_saturation_time`): the controller cannot reach its reference or a measurement is wrong; rig halted"
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

// ---- real time ---------------------------------------------------------------

const HINT_PRIORITY: &str = "Grant real-time priority: raise the rtprio limit (`ulimit -r 99`, or `@realtime - rtprio 99` in /etc/security/limits.conf and add the user to group realtime), give the binary CAP_SYS_NICE (`sudo setcap cap_sys_nice,cap_ipc_lock+ep <binary>`), or run as root";
const HINT_MEMORY: &str = "Grant memory locking: raise the memlock limit (`ulimit -l unlimited`, or `@realtime - memlock unlimited` in /etc/security/limits.conf), give the binary CAP_IPC_LOCK, or set `lock_memory: false`";
const HINT_CPU: &str = "Pick a CPU this process may run on (see `nproc` and `taskset -p $$`)";

/// The category of a [`RealTimeError`].
///
/// `#[non_exhaustive]`: match with a wildcard arm.
///
/// # Examples
///
/// ```
/// use ctrlab::hw::{RealTimeError, RealTimeErrorKind};
/// assert_eq!(RealTimeError::Unsupported.kind(), RealTimeErrorKind::Unsupported);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum RealTimeErrorKind {
    /// The loop's thread could not be pinned to the CPU asked for.
    Affinity,
    /// Memory could not be locked (`mlockall`).
    LockMemory,
    /// SCHED_FIFO at the priority asked for was refused.
    Priority,
    /// This platform has no real-time scheduling the crate can set.
    Unsupported,
}

/// Real-time scheduling ([`RealTime`](super::RealTime)) was asked for and
/// could not be set up; [`run`](super::run) then runs nothing. Each message
/// says how to grant what was refused.
///
/// `#[non_exhaustive]`: match with a wildcard arm, or on [`kind`](Self::kind).
///
/// # Examples
///
/// ```
/// use ctrlab::hw::{RealTimeError, RealTimeErrorKind};
/// let e = RealTimeError::Priority {
///     priority: 80,
///     source: std::io::Error::from_raw_os_error(1),
/// };
/// assert_eq!(e.kind(), RealTimeErrorKind::Priority);
/// assert!(e.to_string().starts_with("cannot set SCHED_FIFO priority 80: "));
/// assert!(e.to_string().contains("rtprio"));
/// ```
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum RealTimeError {
    /// Pinning the loop's thread to a CPU was refused.
    #[error("cannot pin the loop to CPU {cpu}: {source}. {}", HINT_CPU)]
    Affinity {
        /// The CPU asked for.
        cpu: usize,
        /// The operating system's answer.
        #[source]
        source: std::io::Error,
    },
    /// Locking memory was refused.
    #[error("cannot lock memory (mlockall): {source}. {}", HINT_MEMORY)]
    LockMemory {
        /// The operating system's answer.
        #[source]
        source: std::io::Error,
    },
    /// SCHED_FIFO at the priority asked for was refused.
    #[error(
        "cannot set SCHED_FIFO priority {priority}: {source}. {}",
        HINT_PRIORITY
    )]
    Priority {
        /// The priority asked for.
        priority: i32,
        /// The operating system's answer.
        #[source]
        source: std::io::Error,
    },
    /// Real-time scheduling is only implemented on Linux.
    #[error("cannot set real-time scheduling: only implemented on Linux. Run without `realtime`")]
    Unsupported,
}

impl RealTimeError {
    /// The category of this error.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::{RealTimeError, RealTimeErrorKind};
    /// let e = RealTimeError::LockMemory { source: std::io::Error::from_raw_os_error(12) };
    /// assert_eq!(e.kind(), RealTimeErrorKind::LockMemory);
    /// ```
    pub fn kind(&self) -> RealTimeErrorKind {
        match self {
            RealTimeError::Affinity { .. } => RealTimeErrorKind::Affinity,
            RealTimeError::LockMemory { .. } => RealTimeErrorKind::LockMemory,
            RealTimeError::Priority { .. } => RealTimeErrorKind::Priority,
            RealTimeError::Unsupported => RealTimeErrorKind::Unsupported,
        }
    }
}

// ---- any of them ---------------------------------------------------------------

/// The category of a [`RigError`]: its concern, with that concern's kind.
/// It compares equal to the inner kind, so a caller can ask either
/// `kind() == RigErrorKind::Fault(LoopFaultKind::TravelLimit)` or simply
/// `kind() == LoopFaultKind::TravelLimit`.
///
/// `#[non_exhaustive]`: match with a wildcard arm.
///
/// # Examples
///
/// ```
/// use ctrlab::hw::{LoopFault, LoopFaultKind, RigError, RigErrorKind};
/// let e = RigError::from(LoopFault::Interrupted { at: 0.5 });
/// assert_eq!(e.kind(), RigErrorKind::Fault(LoopFaultKind::Interrupted));
/// assert_eq!(e.kind(), LoopFaultKind::Interrupted);
/// assert!(matches!(e.kind(), RigErrorKind::Fault(_)));
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum RigErrorKind {
    /// A [`PortError`].
    Port(PortErrorKind),
    /// A [`ConfigError`].
    Config(ConfigErrorKind),
    /// A [`LoopFault`].
    Fault(LoopFaultKind),
    /// A [`RealTimeError`].
    RealTime(RealTimeErrorKind),
}

impl PartialEq<PortErrorKind> for RigErrorKind {
    fn eq(&self, other: &PortErrorKind) -> bool {
        *self == RigErrorKind::Port(*other)
    }
}

impl PartialEq<ConfigErrorKind> for RigErrorKind {
    fn eq(&self, other: &ConfigErrorKind) -> bool {
        *self == RigErrorKind::Config(*other)
    }
}

impl PartialEq<LoopFaultKind> for RigErrorKind {
    fn eq(&self, other: &LoopFaultKind) -> bool {
        *self == RigErrorKind::Fault(*other)
    }
}

impl PartialEq<RealTimeErrorKind> for RigErrorKind {
    fn eq(&self, other: &RealTimeErrorKind) -> bool {
        *self == RigErrorKind::RealTime(*other)
    }
}

/// Anything that can go wrong running a rig: what the [`Rig`](super::Rig)
/// trait's methods, [`run`](super::run) (in its
/// [`RunError`](super::RunError)) and the lab's rig return. It is one of
/// the errors by concern, each converting into it, so `?` carries a port
/// error, a configuration error, a loop fault or a real-time error up the
/// stack; its message is the inner error's.
///
/// `#[non_exhaustive]`: match with a wildcard arm, or on [`kind`](Self::kind).
///
/// # Examples
///
/// ```
/// use ctrlab::hw::{CycleKind, PortError, PortErrorKind, RigError};
///
/// fn read() -> Result<u8, RigError> {
///     Err(PortError::Timeout { cycle: CycleKind::DataRead, register: Some(0x20) })?
/// }
/// let e = read().unwrap_err();
/// assert_eq!(e.kind(), PortErrorKind::Timeout);
/// assert!(matches!(e, RigError::Port(PortError::Timeout { .. })));
/// assert_eq!(e.to_string(), "EPP data read timed out at register 0x20");
/// ```
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum RigError {
    /// Talking to the card failed, or the driver refused a command.
    #[error(transparent)]
    Port(#[from] PortError),
    /// A configuration value is invalid.
    #[error(transparent)]
    Config(#[from] ConfigError),
    /// The rig was halted for a fault.
    #[error(transparent)]
    Fault(#[from] LoopFault),
    /// Real-time scheduling could not be set up.
    #[error(transparent)]
    RealTime(#[from] RealTimeError),
}

impl RigError {
    /// The category of this error: its concern and that concern's kind.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::{ConfigError, ConfigErrorKind, RigError, RigErrorKind};
    /// let e = RigError::from(ConfigError::invalid("period", 0.0, "must be finite and > 0 s"));
    /// assert_eq!(e.kind(), RigErrorKind::Config(ConfigErrorKind::Invalid));
    /// ```
    pub fn kind(&self) -> RigErrorKind {
        match self {
            RigError::Port(e) => RigErrorKind::Port(e.kind()),
            RigError::Config(e) => RigErrorKind::Config(e.kind()),
            RigError::Fault(e) => RigErrorKind::Fault(e.kind()),
            RigError::RealTime(e) => RigErrorKind::RealTime(e.kind()),
        }
    }
}
