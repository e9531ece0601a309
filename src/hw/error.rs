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
    /// The control loop missed its deadlines too many times in a row; the
    /// rig has been halted.
    Overrun,
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
    #[error("permission denied on {device} (is the user in the `lp` group?)")]
    Permission {
        /// The device path.
        device: String,
        /// The operating system's error.
        #[source]
        source: std::io::Error,
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
    /// The control loop overran its period too many times in a row.
    #[error(
        "control loop overran its {period} s period {consecutive} times in a row (last tick took {last_tick} s); rig halted"
    )]
    Overrun {
        /// Consecutive overruns when the loop gave up.
        consecutive: usize,
        /// The loop's period, s.
        period: f64,
        /// How long the last tick's work took, s.
        last_tick: f64,
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
            HwError::Io { .. } => HwErrorKind::Io,
            HwError::TravelLimit { .. } => HwErrorKind::TravelLimit,
            HwError::InvalidCommand { .. } => HwErrorKind::InvalidCommand,
            HwError::InvalidConfig { .. } => HwErrorKind::InvalidConfig,
            HwError::Overrun { .. } => HwErrorKind::Overrun,
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
