//! [`PortError`]: talking to the card failed or was refused.

use crate::readable::Readable;
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
/// [`EppPort`](crate::hw::EppPort) (`Ppdev`, [`SimulatedCard`](crate::hw::SimulatedCard),
/// the [`testing`](crate::hw::testing) fakes) and the [`Pc104`](crate::hw::Pc104)
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
    #[error("invalid {what}{}: {} (limit {})", channel_suffix(*.channel), Readable(*.value), Readable(*.limit))]
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
