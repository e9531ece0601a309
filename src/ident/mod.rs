//! System identification from recorded data.
//!
//! - [`LeastSquares`]: batch linear least squares by QR (faer inside, never
//!   the normal equations), with covariance, standard errors, residual RMS,
//!   R², fit % and condition number.
//! - [`Rls`]: recursive least squares, fixed size and allocation-free, with
//!   a forgetting factor, for identification inside the control loop.
//! - [`mass_spring`]: the lab's regressors for the two-cart plant
//!   (equations (6)–(11)), in the lab's form ([`Scheme::Lab`]) and without
//!   its half-sample bias ([`Scheme::Central`]).
//!
//! # Examples
//!
//! ```
//! use ctrlab::{Recording, ident::{identify, Scheme}};
//!
//! let rec = Recording::read_csv(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ident_square_wave.csv"))?;
//! let est = identify(&rec, 1.3, 0.7, Scheme::Central)?;
//! assert!((est.b2.value / 6.1 - 1.0).abs() < 0.003);
//! # Ok::<(), ctrlab::Error>(())
//! ```

mod least_squares;
pub mod mass_spring;
mod rls;

pub use least_squares::{DEFAULT_MAX_CONDITION, LeastSquares, LeastSquaresFit};
pub use mass_spring::{MassSpringEstimate, Scheme, identify};
pub use rls::Rls;
