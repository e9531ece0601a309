//! Controllers and their design: the [`Controller`] trait that simulation and
//! hardware both drive, [`OpenLoop`], [`StateFeedback`] (`u = N r − K x`),
//! pole placement by [`acker`], and optimal gains by [`lqr`] / [`dlqr`].
//!
//! The lab's per-millimetre gains are a named conversion in the lab module,
//! [`StateFeedback::from_lab_gains`](crate::lab).
//!
//! # Examples
//!
//! ```
//! use ctrlab::{Controller, StateSpace, design::{StateFeedback, lqr}};
//! use nalgebra::{matrix, vector};
//!
//! // A double integrator (position, speed), force input, position output.
//! let plant = StateSpace::continuous(
//!     matrix![0.0, 1.0; 0.0, 0.0], matrix![0.0; 1.0], matrix![1.0, 0.0], matrix![0.0])?;
//! let gains = lqr(&plant, &matrix![1.0, 0.0; 0.0, 0.0], &matrix![1.0])?;
//! let mut ctrl = StateFeedback::with_prefilter(&plant, gains.gain)?;
//! assert!(ctrl.closed_loop(&plant)?.is_stable()?);
//! // Measurements are the full state here; the reference is the position.
//! let u = ctrl.update(&vector![0.0, 0.0], &vector![1.0]);
//! assert!((u[0] - 1.0).abs() < 1e-9); // K = [1, √2], N = 1
//! # Ok::<(), ctrlab::Error>(())
//! ```

mod controller;
mod feedback;
mod lqr;
mod place;

pub use controller::{Controller, OpenLoop};
pub use feedback::StateFeedback;
pub use lqr::{Lqr, dlqr, lqr};
pub use place::acker;
