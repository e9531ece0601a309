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

mod config;
mod loop_fault;
mod port;
mod real_time;

#[cfg(feature = "lab")]
pub(crate) use config::check_all_positive;
pub(crate) use config::check_positive;
pub use config::{ConfigError, ConfigErrorKind};
pub use loop_fault::{LoopFault, LoopFaultKind};
pub use port::{CycleKind, PortError, PortErrorKind};
pub use real_time::{RealTimeError, RealTimeErrorKind};

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
