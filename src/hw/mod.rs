//! Hardware: the [`Rig`] trait any controller runs against, the
//! fixed-period control loop [`run`], and the lab's FPGA card over the
//! parallel port with a register-level simulation of it.
//!
//! The layers, bottom up:
//!
//! - [`EppPort`]: the three IEEE 1284 EPP primitives (address write, data
//!   read, data write), with [`PortError`]. Implemented by `Ppdev` (Linux
//!   `/dev/parportN`, feature `ppdev`), by [`SimulatedCard`], and by the
//!   fakes in [`testing`].
//! - [`Pc104`]: the card driver (PWM duty, counters latched together and
//!   unwrapped, counter clear, ID probe, watchdog kick) over a documented,
//!   replaceable [`RegisterMap`].
//! - [`SimulatedCard`]: the card emulated register by register, with any
//!   plant ([`Dynamics`](crate::Dynamics), input in volts) inside that
//!   follows a [`Clock`]: a [`VirtualClock`] or real time.
//! - [`Rig`]: measurements in, inputs out, at a fixed period; [`run`]
//!   drives one with any [`Controller`](crate::Controller) and returns a
//!   [`Recording`](crate::Recording).
//!
//! Errors follow concerns, each with a `kind()`: [`PortError`] for talking
//! to the card, [`ConfigError`] for a configuration value (named by its
//! key), [`LoopFault`] for what halts a run, [`RealTimeError`] for
//! real-time scheduling; [`RigError`], what a [`Rig`] and [`run`] return, is
//! any of them, and `?` converts each into it.
//!
//! This module names no cart: the lab's two-cart rig on the card is
//! [`lab::MassSpringRig`](crate::lab::MassSpringRig), and the simulated one
//! in one call is [`lab::SimulatedRig`](crate::lab::SimulatedRig).
//!
//! # Examples
//!
//! The whole stack on the simulated card, with virtual time: push with 12 V
//! and watch cart 2 settle at its static deflection.
//!
//! ```
//! use ctrlab::hw::{Clock, Rig, VirtualClock};
//! use ctrlab::lab::{MassSpring, SimulatedRig};
//!
//! let clock = VirtualClock::new();
//! let mut rig = SimulatedRig::ideal(MassSpring::nominal())
//!     .rig(&Clock::Virtual(clock.clone()))?;
//! let mut x = rig.read_state()?;
//! for _ in 0..5000 {
//!     rig.apply_voltage(12.0)?; // 12 N with the nominal 1 N/V
//!     clock.advance_nanos(2_000_000);
//!     x = rig.read_state()?;
//! }
//! // 12 N over two 1000 N/m springs in series: x2 = 24 mm, within a count.
//! assert!((x[2] - 0.024).abs() < 1e-5);
//! # Ok::<(), ctrlab::hw::RigError>(())
//! ```

mod clock;
mod epp;
mod error;
mod pc104;
#[cfg(all(feature = "ppdev", target_os = "linux"))]
#[cfg_attr(docsrs, doc(cfg(all(feature = "ppdev", target_os = "linux"))))]
mod ppdev;
mod ppdev_options;
pub mod probe;
mod realtime;
mod rig;
mod run;
mod sim_card;
mod sim_config;
mod stop;
pub mod testing;

pub use clock::{Clock, Jitter, VirtualClock};
pub use epp::EppPort;
#[cfg(feature = "lab")]
pub(crate) use error::check_all_positive;
pub(crate) use error::check_positive;
pub use error::{
    ConfigError, ConfigErrorKind, CycleKind, LoopFault, LoopFaultKind, PortError, PortErrorKind,
    RealTimeError, RealTimeErrorKind, RigError, RigErrorKind,
};
pub use pc104::{
    ENCODER_CHANNELS, MAX_DUTY, PWM_CHANNELS, PWM_DIRECTION_BIT, Pc104, RegisterMap,
    duty_from_bytes, pwm_bytes,
};
#[cfg(all(feature = "ppdev", target_os = "linux"))]
#[cfg_attr(docsrs, doc(cfg(all(feature = "ppdev", target_os = "linux"))))]
pub use ppdev::{PortModes, Ppdev, ioctl};
pub use ppdev_options::PpdevOptions;
pub use realtime::RealTime;
pub use rig::Rig;
pub use run::{GAP_PERIODS, LATE_FRACTION, LoopConfig, LoopStats, RunError, RunOutcome, run};
pub use sim_card::{MAX_CATCH_UP_STEPS, SimulatedCard};
pub use sim_config::{SIMULATED_CARD_ID, SimulatedCardConfig};
pub use stop::StopSignal;
