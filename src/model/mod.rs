//! Typed linear models and the lab's two-cart plant.
//!
//! [`StateSpace`] carries its sizes and its time domain ([`Continuous`] or
//! [`Discrete`]) in its type; [`MassSpring`] turns the rig's physical
//! parameters into one.

mod mass_spring;
mod state_space;

pub use mass_spring::{MassSpring, Output};
pub use state_space::{Continuous, Discrete, Domain, StateSpace};
