//! The names most programs use, in one import: `use ctrlab::prelude::*;`.
//!
//! Small on purpose (as faer's): the model types and their time domains,
//! discretisation, the controller seam, the everyday design, simulation and
//! metrics calls (free functions that take either model size), the pole
//! printer, recordings, and the error. Everything else is imported
//! from its module by name.
//!
//! # Examples
//!
//! ```
//! use ctrlab::prelude::*;
//! use ctrlab::nalgebra::matrix;
//!
//! // A cart of 1 kg on a 100 N/m spring, pushed by a force (N).
//! let plant = StateSpace::continuous(
//!     matrix![0.0, 1.0; -100.0, -2.0],
//!     matrix![0.0; 1.0],
//!     matrix![1.0, 0.0],
//!     matrix![0.0],
//! )?;
//! let discrete = plant.discretize(0.002, Discretization::Zoh)?;
//! assert!(discrete.is_stable()?);
//! let k = place(&plant, [-20.0, -30.0])?; // real poles as plain numbers
//! let closed = StateSpace::continuous(plant.a() - plant.b() * k, *plant.b(), *plant.c(), *plant.d())?;
//! assert_eq!(Poles(&closed.poles()?).to_string(), "-30, -20");
//! let (t_end, dt) = (10.0, 0.001); // s
//! let info = step_info_of(&plant, t_end, dt, &StepInfoOptions::default())?;
//! assert!((info.steady_state_value - 0.01).abs() < 1e-6); // 1 N / 100 N/m
//! # Ok::<(), ctrlab::Error>(())
//! ```

pub use crate::analysis::Poles;
pub use crate::data::Recording;
pub use crate::design::{Controller, StateFeedback, acker, dlqr, lqr, place, place_observer};
pub use crate::discretize::Discretization;
pub use crate::error::Error;
pub use crate::metrics::{StepInfo, StepInfoOptions, step_info, step_info_of};
pub use crate::model::{Continuous, Discrete, DynStateSpace, StateSpace};
pub use crate::sim::step_response;
