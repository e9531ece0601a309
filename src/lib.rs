//! # ctrlab
//!
//! Control engineering for a real lab, in Rust: typed state-space models,
//! discretisation and simulation, identification from recorded data,
//! state-feedback design and step metrics, and a hardware layer that runs
//! the same controller on the rig at 2 ms; built around the two-cart
//! mass-spring rig of a university control lab (`cargo run --release
//! --example lab5` reproduces the whole lab on the simulated rig).
//!
//! Modelling and simulation:
//!
//! - [`model`]: [`StateSpace`] with its sizes and time domain in the type, and
//!   the lab's plant [`MassSpring`].
//! - [`discretize`]: ZOH (exact), Tustin, forward and backward Euler, and
//!   [`expm`](discretize::expm).
//! - [`integrate`]: the [`Dynamics`] trait and the [`Rk4`] and [`Euler`]
//!   steppers.
//! - [`sim`]: continuous and discrete simulation and step responses.
//!
//! Analysis and design:
//!
//! - [`analysis`]: poles, stability, DC gain, damping, controllability and
//!   observability.
//! - [`design`]: the [`Controller`] trait, [`StateFeedback`] (the lab's
//!   per-millimetre form and the textbook form), [`OpenLoop`], [`acker`],
//!   [`lqr`], [`dlqr`].
//! - [`metrics`]: [`step_info`] / [`step_info_of`] (rise and settling time,
//!   overshoot, steady state) with interpolated crossing times.
//! - `plot` (feature `plot`, on by default): SVG figures of time responses.
//!
//! Data and identification:
//!
//! - [`data`]: [`Recording`]s of a run (time, input, cart states) and their
//!   CSV form, units in the header.
//! - [`ident`]: least squares by QR ([`LeastSquares`]), recursive least
//!   squares ([`Rls`]) and the lab's two-cart identification
//!   ([`ident::mass_spring`]).
//!
//! Hardware:
//!
//! - [`hw`]: the lab's card over the parallel port (EPP), its register-level
//!   simulation, the [`Rig`](hw::Rig) a controller runs against, and the
//!   fixed-period control loop [`run`](hw::run).
//!
//! Units are SI throughout (m, m/s, N, V, s); the lab's millimetres appear
//! only in printed tables and at named conversions.
//!
//! ## Example
//!
//! ```
//! use ctrlab::{MassSpring, Method, Output, sim::step_response};
//!
//! let plant = MassSpring::nominal().state_space(Output::Cart2)?;
//! // The discrete model the 2 ms control loop sees.
//! let discrete = plant.discretize(0.002, Method::Zoh)?;
//! assert_eq!(discrete.dt(), 0.002);
//!
//! // A 1 N step on cart 2 settles at 2 mm (two 1000 N/m springs in series).
//! let r = step_response(&plant, 10.0, 0.002)?;
//! assert!((r.y.last().unwrap()[0] - 0.002).abs() < 1e-9);
//! # Ok::<(), ctrlab::Error>(())
//! ```
#![deny(missing_docs)]
#![deny(unsafe_code)]

pub mod analysis;
pub mod data;
pub mod design;
pub mod discretize;
mod error;
pub mod hw;
pub mod ident;
pub mod integrate;
mod linalg;
pub mod metrics;
pub mod model;
#[cfg(feature = "plot")]
pub mod plot;
mod reduce;
pub mod sim;

pub use analysis::Damping;
pub use data::Recording;
pub use design::{Controller, Lqr, OpenLoop, StateFeedback, acker, dlqr, lqr};
pub use discretize::Method;
pub use error::Error;
pub use ident::{LeastSquares, LeastSquaresFit, Rls};
pub use integrate::{Dynamics, Euler, Integrator, Rk4};
pub use metrics::{StepInfo, StepInfoOptions, step_info, step_info_of};
pub use model::{Continuous, Discrete, Domain, MassSpring, Output, StateSpace};
pub use sim::{Response, step_response};

// The README's code blocks are compiled and run as doctests.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
pub struct ReadmeDoctests;
