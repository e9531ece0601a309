//! Controllers and their design: the [`Controller`] trait that simulation and
//! hardware both drive, [`OpenLoop`], [`StateFeedback`] (`u = N r − K x`),
//! pole placement by [`acker`] (one input) and [`place`] (any number of
//! inputs, robust), and optimal gains by [`lqr`] / [`dlqr`], with the bare
//! Riccati equations by [`care`] / [`dare`] (all `O(N³)`, one
//! implementation; see [`Lqr`](Lqr#algorithm)).
//!
//! Every design takes a model of either size, `StateSpace` or
//! `DynStateSpace`, through the sealed trait [`Design`] (its table lists
//! the argument and result types of each size), and returns one result
//! type written over nalgebra's dimensions ([`Lqr`], [`Lqe`], with the
//! aliases [`DynLqr`], [`DynLqe`] for run-time sizes). Target poles are any
//! [`PoleTargets`]: real ones as plain `f64`, complex ones as
//! `Complex<f64>`.
//!
//! Beyond static state feedback:
//!
//! - integral action: [`augment_integral`], the linear-quadratic-integral
//!   designs [`lqi`] / [`dlqi`], and the controller [`IntegralFeedback`]
//!   with [`AntiWindup`];
//! - observers: [`place_observer`] (Luenberger, by placement on the dual),
//!   the steady-state Kalman filters [`lqe`] / [`dlqe`], and [`Observer`]
//!   in predictor or current-estimator form ([`EstimatorForm`]);
//! - output feedback: [`ObserverController`] (observer, state feedback and
//!   integrators on measured outputs), and [`SelectOutputs`] to run it on
//!   some of a loop's measurements (the rig's positions, not its
//!   differenced speeds);
//! - constrained model-predictive control: [`Mpc`] (input, rate and
//!   output limits, offset-free, a bounded solve per tick with a safe
//!   fallback) on the QP solver [`mpc::DenseQp`].
//!
//! The lab's per-millimetre gains are a named conversion in the lab module,
//! [`LabGains`](crate::lab).
//!
//! # Examples
//!
//! ```
//! use ctrlab::{Controller, StateSpace, design::{StateFeedback, lqr}};
//! use ctrlab::nalgebra::{matrix, vector};
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
mod integral;
mod kalman;
mod lqr;
pub mod mpc;
mod observer;
mod observer_controller;
mod place;
mod riccati;
mod robust_place;
mod system;

pub use controller::{Controller, OpenLoop};
pub use feedback::StateFeedback;
pub use integral::{AntiWindup, IntegralFeedback, augment_integral, dlqi, lqi};
pub use kalman::{DynLqe, Lqe, dlqe, lqe};
pub use lqr::{DynLqr, Lqr, dlqr, lqr};
pub use mpc::Mpc;
pub use observer::{EstimatorForm, Observer};
pub use observer_controller::{ObserverController, SelectOutputs};
pub use place::acker;
pub use riccati::{care, dare};
pub use robust_place::{place, place_observer};
pub use system::{Design, IntegralAction, Kalman, PoleTargets};
