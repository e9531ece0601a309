//! [`ProbeError`]: why the probe stopped.

use crate::hw::{ConfigError, PortError};

/// Why the probe stopped.
///
/// # Examples
///
/// ```
/// use ctrlab::hw::probe::{Operator, Probe, ProbeError, ProbeOptions};
/// use ctrlab::hw::testing::RegisterFile;
/// # use ctrlab::hw::probe::Hands;
/// # struct Nobody;
/// # impl<P> Operator<P> for Nobody {
/// #     fn tell(&mut self, _: &str) {}
/// #     fn confirm(&mut self, _: &str) -> bool { false }
/// #     fn hands(&mut self, _: Hands) {}
/// #     fn wait(&mut self, _: &mut P, _: f64) {}
/// # }
/// // Every address reads 0: the blind scan finds no card.
/// let blind = ProbeOptions { scan: true, ..Default::default() };
/// let mut probe = Probe::new(RegisterFile::new(), Nobody, blind)?;
/// let err = probe.scan().unwrap_err();
/// assert!(matches!(err, ProbeError::NoCard { .. }));
/// assert!(err.to_string().contains("every address reads 0x00"));
/// // The default probe, given a map, finds no ID where the map says.
/// let mut probe = Probe::new(RegisterFile::new(), Nobody, ProbeOptions::default())?;
/// let err = probe.check_id().unwrap_err();
/// assert!(matches!(err, ProbeError::WrongMap { .. }));
/// assert!(err.to_string().contains("nothing was written"));
/// # Ok::<(), ctrlab::hw::RigError>(())
/// ```
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ProbeError {
    /// The port failed (a timeout here means no card answers).
    #[error(transparent)]
    Port(#[from] PortError),
    /// The register map the steps found does not hold together (two
    /// registers at one address): the card is not the one the probe
    /// understands.
    #[error("the register map found is invalid: {0}")]
    InvalidMap(#[from] ConfigError),
    /// No card answers: every address reads the same idle value, or EPP
    /// cycles time out. Nothing was written.
    #[error(
        "no card: {reason}. Check the cable, the card's power and the BIOS EPP mode; nothing was written to the card"
    )]
    NoCard {
        /// What the scans saw.
        reason: String,
    },
    /// The operator declined a step; the probe stopped before it.
    #[error("stopped before {step}: not confirmed")]
    Declined {
        /// The step not taken.
        step: &'static str,
    },
    /// A step did not find what it looks for.
    #[error("{what} not found: {hint}")]
    NotFound {
        /// What was looked for.
        what: &'static str,
        /// What to check or try.
        hint: &'static str,
    },
    /// The card works in a way the crate's driver does not support.
    #[error("unsupported card: {what}")]
    Unsupported {
        /// What is different.
        what: &'static str,
    },
    /// Positive duty moves the cart towards the wall.
    #[error(
        "motor polarity reversed: positive duty moved cart {axis} towards the wall ({counts} counts); swap the motor leads"
    )]
    ReversedMotor {
        /// The cart that moved.
        axis: usize,
        /// How far, counts (sign-corrected).
        counts: i64,
    },
    /// The card does not answer as the given register map says (the
    /// default probe, which confirms a map): a wrong map, or a card other
    /// than the one the card file describes.
    #[error(
        "the card does not answer as the given register map says: {reason}. Check the map (the card file's [map]) against the lab's existing driver or the FPGA's sources"
    )]
    WrongMap {
        /// What the card did instead.
        reason: String,
    },
    /// A step of the blind scan was called without
    /// [`ProbeOptions::scan`](super::ProbeOptions::scan). Nothing was read
    /// or written.
    #[error(
        "the blind scan writes test patterns to card addresses no map describes, which on an FPGA can hit configuration registers; it runs only when asked for (ProbeOptions::scan, the probe example's --scan). Nothing was read or written"
    )]
    ScanNotEnabled,
    /// A stop was requested ([`StopSignal`](crate::hw::StopSignal): Ctrl-C,
    /// SIGTERM or code); the probe zeroed the PWM it had driven and
    /// stopped.
    #[error("stopped on request (Ctrl-C or a stop signal); the PWM the probe drove was zeroed")]
    Interrupted,
    /// A step was called before the one it needs.
    #[error("{step} needs {needs} first")]
    OutOfOrder {
        /// The step called.
        step: &'static str,
        /// The step it needs.
        needs: &'static str,
    },
}
