//! The two-cart lab: everything that is about this one rig. The lab
//! itself — the rig, its equations and its tables — is restated in the
//! repository's [lab guide](https://github.com/ctrlab-rs/ctrlab/blob/main/docs/lab.md)
//! (`docs/lab.md`).
//!
//! The generic modules never name a cart; this one builds the lab on them:
//!
//! - the plant: [`MassSpring`] (equations (1)–(3), (14)) and [`Cart`];
//! - the lab's per-millimetre gains,
//!   [`LabGains`] (Kf in V/mm and V/(mm/s), and the setpoint's column
//!   `G`), to an SI [`StateFeedback`](crate::StateFeedback) and back;
//! - the identification of equations (4)–(11) from a recording, in
//!   [`ident`];
//! - the rig: [`MassSpringRig`] on the PC104 card with its [`Calibration`]
//!   (a real card's register map and calibration come from its card file,
//!   [`RigConfig`]; a file's faults are a [`FileError`] that says the
//!   path, the line and the key),
//!   and in simulation [`SimulatedRig`] (the plant with stick–slip
//!   [`FrictionPlant`] inside the register-level card, in one call), made
//!   of its truth, [`Friction`], [`CardSettings`] and [`Calibration`], with
//!   its [`EncoderSensor`] for the sampled-data simulator;
//! - the lab's recording layout, [`schema`]: input `u` (V), measurements
//!   `x1` (m), `v1` (m/s), `x2` (m), `v2` (m/s);
//! - how the lab's experiments are run (period, masses, identification
//!   input), [`protocol`]; an identification input that respects the
//!   rig's travel (its signal and amplitude, scaled from probe runs),
//!   [`ident_input`];
//! - the lab's tables as data (the gains of Tables 2, 5 and 6, their
//!   setpoints and groups of rows) and their computations, [`tables`];
//! - the LQI design to a spec on an identified model, [`lqi`];
//! - the other sections of the lab's report as typed results:
//!   [`excitation`] (which input identifies best), [`validation`] (the
//!   models on a fresh run, refined) and [`frequency`] (the measured
//!   response against the model); Tables 3 and 4 are
//!   [`ident::summarize`].
//!
//! # Examples
//!
//! The lab's cart-2 controller run twice, unchanged: in the sampled-data
//! simulator and on the simulated rig (card, driver, 2 ms loop). Both give
//! the same recording to within an encoder count.
//!
//! ```
//! use ctrlab::hw::{self, Clock, LoopConfig, VirtualClock};
//! use ctrlab::lab::{Cart, LabGains, MassSpring, SimulatedRig};
//! use ctrlab::sim::run_sampled;
//! use ctrlab::nalgebra::vector;
//!
//! let sim = SimulatedRig::ideal(MassSpring::nominal());
//! let law = LabGains::new([0.0, 0.0, 10.0, 0.1], Cart::Two).state_feedback()?;
//! let simulated = run_sampled(sim.plant(), sim.sensor(), law, |_| vector![0.030],
//!                             vector![0.0, 0.0, 0.0, 0.0], &sim.sampled_config(1.0))?;
//!
//! let clock = VirtualClock::new();
//! let rig = sim.rig(&Clock::Virtual(clock.clone()))?;
//! let measured = hw::run(rig, law, |_| vector![0.030], &Clock::Virtual(clock),
//!                        &LoopConfig { duration: 1.0, ..Default::default() })?.recording;
//!
//! let (a, b) = (simulated.channel("x2")?, measured.channel("x2")?);
//! assert!(a.iter().zip(b).all(|(a, b)| (a - b).abs() <= sim.metres_per_count() * 1.0001));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod calibration;
mod config;
pub mod excitation;
mod file;
pub mod frequency;
mod friction_plant;
mod gains;
pub mod ident;
pub mod ident_input;
pub mod lqi;
pub mod mpc;
mod plant;
mod probe;
pub mod protocol;
mod rig;
mod sensor;
mod simulated;
pub mod tables;
pub mod validation;

pub use calibration::Calibration;
pub use config::RigConfig;
pub use file::{FileError, FileErrorKind};
pub use friction_plant::FrictionPlant;
pub use gains::LabGains;
pub use plant::{Cart, MassSpring};
pub use probe::SimulatedOperator;
pub use rig::MassSpringRig;
pub use sensor::EncoderSensor;
pub use simulated::{CardSettings, Friction, SimulatedRig, Unmodelled};

use nalgebra::SMatrix;

use crate::data::{Channel, Schema};

/// The output matrix that picks both carts' positions `[x1, x2]` out of the
/// state `[x1, v1, x2, v2]`: what the encoders really measure (the rig's
/// speeds are differenced positions). For an observer's model
/// ([`StateSpace::with_output`](crate::StateSpace::with_output)) and to
/// select the measurements an observer-based controller uses
/// ([`SelectOutputs`](crate::design::SelectOutputs)).
///
/// # Examples
///
/// ```
/// use ctrlab::nalgebra::{matrix, vector};
/// let c = ctrlab::lab::position_output_matrix();
/// assert_eq!(c, matrix![1.0, 0.0, 0.0, 0.0; 0.0, 0.0, 1.0, 0.0]);
/// assert_eq!(c * vector![0.01, 0.5, 0.02, -0.1], vector![0.01, 0.02]);
/// ```
pub fn position_output_matrix() -> SMatrix<f64, 2, 4> {
    SMatrix::<f64, 2, 4>::new(1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0)
}

/// The lab's recording layout: input `u` in V, measurements `x1` (m),
/// `v1` (m/s), `x2` (m), `v2` (m/s), the state `[x1, v1, x2, v2]` the rig
/// reads. Its CSV header is `t_s,u_V,x1_m,v1_m_s,x2_m,v2_m_s`; the lab's own
/// logs (`t_s,u,x1_mm,x2_mm`) read as the same channels, without velocities.
///
/// # Examples
///
/// ```
/// let s = ctrlab::lab::schema();
/// assert_eq!(s.inputs()[0].unit, "V");
/// let names: Vec<_> = s.measurements().iter().map(|c| c.name.as_str()).collect();
/// assert_eq!(names, ["x1", "v1", "x2", "v2"]);
/// ```
pub fn schema() -> Schema {
    Schema::new(
        vec![Channel::new("u", "V")],
        vec![
            Channel::new("x1", "m"),
            Channel::new("v1", "m/s"),
            Channel::new("x2", "m"),
            Channel::new("v2", "m/s"),
        ],
    )
    // Constant, valid names (the doctest above builds it): never fails.
    .expect("the lab's channel names are valid")
}

/// The recording's channel of `cart`'s position in [`schema`]: `x1` or
/// `x2`.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::{Cart, position_channel, schema};
/// assert_eq!(position_channel(Cart::Two), "x2");
/// assert!(schema().position(position_channel(Cart::One)).is_some());
/// ```
pub fn position_channel(cart: Cart) -> &'static str {
    match cart {
        Cart::One => "x1",
        Cart::Two => "x2",
    }
}
