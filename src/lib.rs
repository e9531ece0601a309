//! # ctrlab
//!
//! Control engineering for a real lab, in Rust: typed state-space models,
//! discretisation and simulation, identification from recorded data,
//! state-feedback design and step metrics, and a hardware layer that runs
//! the same controller on the rig; built around the two-cart mass-spring
//! rig of a university control lab (`cargo run --release --example lab5`
//! reproduces the whole lab on the simulated rig), and generic everywhere
//! else.
//!
//! Modelling and simulation:
//!
//! - [`model`]: [`StateSpace`] with its sizes and time domain in the type,
//!   [`DynStateSpace`] with its sizes chosen at run time (interconnections
//!   [`series`](DynStateSpace::series),
//!   [`parallel`](DynStateSpace::parallel),
//!   [`feedback`](DynStateSpace::feedback) and
//!   [`append`](DynStateSpace::append)), and the [`Dynamics`] trait any
//!   plant implements.
//! - [`discretize`]: ZOH (exact), Tustin, forward and backward Euler, and
//!   [`expm`](discretize::expm); back with [`d2c`](StateSpace::d2c) (each
//!   method inverted) and [`logm`](discretize::logm).
//! - [`integrate`]: the [`Rk4`] and [`Euler`] steppers.
//! - [`sim`]: continuous and discrete simulation, step, impulse and
//!   initial-condition responses in either time domain, and the
//!   sampled-data simulator [`run_sampled`] (a continuous plant under a
//!   discrete controller, with hold, delay, saturation, quantisation and
//!   noise).
//! - [`signal`]: test inputs (step, square wave, PRBS) and the crate's
//!   seeded random generator.
//!
//! Analysis and design:
//!
//! - [`analysis`]: poles, stability, DC gain, damping, controllability and
//!   observability; Lyapunov and Sylvester equations
//!   ([`lyap`](analysis::lyap), [`dlyap`](analysis::dlyap),
//!   [`sylvester`](analysis::sylvester), the discrete Sylvester equation
//!   [`dsylvester`](analysis::dsylvester), and the Gramian's factor
//!   [`lyapchol`](analysis::lyapchol), [`dlyapchol`](analysis::dlyapchol));
//!   Gramians ([`gram`](StateSpace::gram)), Hankel singular values
//!   ([`hsvd`](StateSpace::hsvd)) and balanced truncation
//!   ([`balred`](StateSpace::balred)); system norms
//!   ([`h2_norm`](analysis::h2_norm), [`hinf_norm`](analysis::hinf_norm)
//!   with its peak frequency).
//! - [`design`]: the [`Controller`] trait (measurements and reference in,
//!   input out; told what was applied), [`StateFeedback`], [`OpenLoop`],
//!   [`acker`], [`place`], [`lqr`], [`dlqr`], Riccati solvers that scale
//!   ([`care`](design::care), [`dare`](design::dare)); integral action
//!   ([`lqi`](design::lqi), [`IntegralFeedback`](design::IntegralFeedback)
//!   with anti-windup), observers and Kalman filters
//!   ([`place_observer`](design::place_observer), [`lqe`](design::lqe),
//!   [`dlqe`](design::dlqe), [`Observer`](design::Observer)) and the
//!   observer-based [`ObserverController`](design::ObserverController).
//! - [`freq`]: transfer functions ([`TransferFunction`], [`TransferMatrix`],
//!   [`Zpk`]) and `ss2tf`/`tf2ss`, invariant zeros, frequency responses
//!   ([`bode`], [`nyquist`], [`frequency_response`]) in rad/s, dB and
//!   degrees, [`stability_margins`] (gain, phase, delay) and [`bandwidth`],
//!   root loci ([`freq::root_locus`]) and pole-zero maps
//!   ([`freq::pole_zero_map`]).
//! - [`metrics`]: [`step_info`] / [`step_info_of`] / [`step_info_mimo`]
//!   (rise, settling and transient time, overshoot, steady state) of data
//!   or of any model, with interpolated crossing times, under the crate's
//!   definitions or MATLAB's.
//! - `plot` (feature `plot`, on by default): SVG figures of time responses.
//!
//! Data and identification:
//!
//! - [`data`]: [`Recording`]s (time stamps, inputs as applied, measurements,
//!   each a named [`Channel`] with its unit) and their CSV form.
//! - [`ident`]: least squares by QR ([`LeastSquares`]) and recursive least
//!   squares ([`Rls`]); frequency responses from data
//!   ([`etfe`](ident::etfe), [`spa`](ident::spa)).
//!
//! Hardware:
//!
//! - [`hw`]: the [`Rig`](hw::Rig) trait, the fixed-period control loop
//!   [`run`](hw::run), the lab's card over the parallel port (EPP) and its
//!   register-level simulation.
//!
//! The lab:
//!
//! - [`lab`]: the two-cart plant [`MassSpring`] and [`Cart`], the lab's
//!   per-millimetre gains, its identification (equations (4)–(11)), the
//!   rig on the card and the simulated rig in one call.
//!
//! ## Features
//!
//! | feature | default | what it adds | what it pulls |
//! |---|---|---|---|
//! | (core) | always | models, discretisation, analysis, frequency tools, design, simulation, metrics, recordings and CSV, identification, signals | nalgebra, faer, rustfft, csv-core, thiserror |
//! | `hw` | via `lab` | [`hw`]: the `Rig` trait, the fixed-period loop, real-time scheduling, stop signals, the PC104 card driver and its simulation, the probe | serde, signal-hook, libc |
//! | `lab` | yes | [`lab`]: the two-cart plant, its identification and refinement, the simulated rig, card and truth files (implies `hw`) | toml, serde_path_to_error |
//! | `plot` | yes | `plot`, `bode_svg`, `bode_marked_svg`, `nyquist_svg`, `root_locus_svg`, `pole_zero_svg`: SVG figures | plotters (SVG backend only) |
//! | `ppdev` | no | `hw::Ppdev`: the real card on a Linux parallel port (implies `hw`) | |
//!
//! A crate that wants the mathematics only depends on
//! `ctrlab = { version = "0.3", default-features = false }`: the hardware
//! and lab stacks and their dependencies are not compiled.
//!
//! ## One calling style
//!
//! An operation is one free function (or one method of a sealed trait) that
//! takes either model size, with one result shape whose dimensions follow the
//! model's: `lqr(&sys, &q, &r)`, `place(&sys, [-2.0, -3.0])`,
//! `step_response(&sys, t_end, dt)`, `step_info_of(&sys, ..)`, `bode(&sys,
//! &w)` and `stability_margins(&sys)` accept a [`StateSpace`] and a
//! [`DynStateSpace`] alike (the frequency tools any transfer-function form
//! too), through the sealed traits [`LinearSystem`], [`Design`] and
//! [`Simulate`]. Target poles may be plain `f64` (real) or
//! [`Complex`](nalgebra::Complex). Results such as [`Lqr`] and [`Response`]
//! are generic over nalgebra's dimensions, so a fixed-size model gets
//! fixed-size matrices and a run-time-sized one `DMatrix`es ([`DynLqr`],
//! [`DynResponse`]).
//!
//! ## Errors by concern
//!
//! [`Error`] is the numeric error (a bad argument, a singular matrix, an
//! unstable system), with [`Error::kind`]. Whatever does I/O has its own:
//! [`data::CsvError`] for recordings, `plot::PlotError` for figures,
//! `hw::PortError` for the bus, `hw::LoopFault` for the loop's safety
//! halts, `hw::ConfigError` for settings, `lab::FileError` for the lab's
//! TOML files; each keeps its cause as `source()` and has a `kind()`.
//!
//! Layers point one way: private kernels and [`model`] at the bottom;
//! [`discretize`], [`integrate`], [`analysis`], [`freq`] on them; [`design`],
//! [`sim`], [`metrics`], [`data`], [`ident`], [`signal`] above; [`hw`]
//! above those; [`lab`] on top. Units are SI throughout (m, m/s, N, V, s);
//! the lab's millimetres appear only in printed tables and at named
//! conversions. Names follow MATLAB and python-control where one exists
//! (search docs.rs for `c2d`, `ctrb`, `dcgain`, `lsim`, …).
//!
//! ## Example
//!
//! ```
//! use ctrlab::{Cart, MassSpring, Discretization, sim::step_response};
//!
//! let plant = MassSpring::nominal().state_space(Cart::Two)?;
//! // The discrete model the 2 ms control loop sees.
//! let discrete = plant.discretize(0.002, Discretization::Zoh)?;
//! assert_eq!(discrete.dt(), 0.002);
//!
//! // A 1 N step on cart 2 settles at 2 mm (two 1000 N/m springs in series).
//! let (t_end, dt) = (10.0, 0.002); // s
//! let r = step_response(&plant, t_end, dt)?;
//! assert!((r.y.last().unwrap()[0] - 0.002).abs() < 1e-9);
//! # Ok::<(), ctrlab::Error>(())
//! ```
#![deny(missing_docs)]
#![deny(unsafe_code)]
#![cfg_attr(docsrs, feature(doc_cfg))]

pub mod analysis;
pub mod data;
pub mod design;
pub mod discretize;
mod error;
pub mod freq;
#[cfg(feature = "hw")]
#[cfg_attr(docsrs, doc(cfg(feature = "hw")))]
pub mod hw;
pub mod ident;
pub mod integrate;
mod kernels;
#[cfg(feature = "lab")]
#[cfg_attr(docsrs, doc(cfg(feature = "lab")))]
pub mod lab;
pub mod metrics;
pub mod model;
pub mod nalgebra;
#[cfg(feature = "plot")]
#[cfg_attr(docsrs, doc(cfg(feature = "plot")))]
pub mod plot;
pub mod prelude;
mod readable;
pub mod signal;
pub mod sim;

pub use analysis::{Damping, Poles};
pub use data::{Channel, Recording, Schema};
pub use design::{
    Controller, Design, DynLqr, Lqr, OpenLoop, StateFeedback, acker, dlqr, lqr, place,
};
pub use discretize::Discretization;
pub use error::{Error, ErrorKind};
pub use freq::{
    Bode, FrequencyDomain, FrequencyResponse, Margins, TransferFunction, TransferMatrix, Zpk,
    bandwidth, bode, frequency_response, logspace, nyquist, stability_margins,
};
pub use ident::{LeastSquares, LeastSquaresFit, Rls};
pub use integrate::{Euler, Integrator, Rk4};
#[cfg(feature = "lab")]
pub use lab::{Cart, MassSpring};
pub use metrics::{StepInfo, StepInfoOptions, step_info, step_info_mimo, step_info_of};
pub use model::{
    Continuous, Discrete, Domain, DynStateSpace, Dynamics, LinearSystem, SingleInput, Siso,
    StateSpace,
};
pub use sim::{
    DynResponse, Response, Simulate, impulse_response, initial_response, run_sampled, step_response,
};

// The README's code blocks are compiled and run as doctests, and so are the
// guides' that hold Rust (the others' blocks are shell and text).
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
pub struct ReadmeDoctests;
#[cfg(doctest)]
#[doc = include_str!("../docs/lab.md")]
pub struct LabGuideDoctests;
#[cfg(doctest)]
#[doc = include_str!("../docs/identification.md")]
pub struct IdentificationGuideDoctests;
