//! Typed models: linear [`StateSpace`] models with their sizes and time
//! domain ([`Continuous`] or [`Discrete`]) in the type, [`DynStateSpace`]
//! models sized at run time with the domain still in the type, and the
//! [`Dynamics`] trait any plant (linear or not) implements for simulation,
//! and [`LinearSystem`], the sealed trait through which one free function
//! (`lqr`, `step_response`, …) takes either model type (its docs say how
//! the crate's calling style and result types were chosen).
//!
//! This is the bottom layer: it names no particular plant (the lab's
//! two-cart plant is [`lab::MassSpring`](crate::lab::MassSpring)).

pub(crate) mod display;
mod dyn_state_space;
mod dynamics;
mod interconnect;
mod state_space;
mod system;

pub use dyn_state_space::DynStateSpace;
pub use dynamics::Dynamics;
pub use interconnect::Sign;
pub(crate) use state_space::period_of;
pub use state_space::{Continuous, Discrete, Domain, StateSpace};
pub(crate) use system::Token;
pub use system::{LinearSystem, SingleInput, Siso};
