//! System identification from recorded data, for any linear-in-parameters
//! model.
//!
//! - [`LeastSquares`]: batch linear least squares by QR (faer inside, never
//!   the normal equations), with covariance, standard errors, residual RMS,
//!   R², fit % and condition number; the covariance classical or
//!   Newey–West ([`Covariance`]) for equation errors that are correlated
//!   from row to row, as differenced samples' are.
//! - [`Rls`]: recursive least squares, fixed size and allocation-free, with
//!   a forgetting factor, for identification inside the control loop.
//! - [`etfe`] and [`spa`]: a frequency response from input/output data, raw
//!   (the ratio of the DFTs) or smoothed (Blackman–Tukey), MATLAB's names.
//!
//! The lab's two-cart regressors (equations (6)–(11)) build on these in
//! [`lab::ident`](crate::lab::ident).
//!
//! # Examples
//!
//! ```
//! use ctrlab::ident::LeastSquares;
//!
//! // y = 2 a + 3 b from four noiseless rows.
//! let mut ls = LeastSquares::new(2);
//! for (a, b) in [(1.0, 0.0), (0.0, 1.0), (1.0, 1.0), (2.0, -1.0)] {
//!     ls.push_row(&[a, b], 2.0 * a + 3.0 * b)?;
//! }
//! let fit = ls.solve()?;
//! assert!((fit.theta[0] - 2.0).abs() < 1e-12 && (fit.theta[1] - 3.0).abs() < 1e-12);
//! # Ok::<(), ctrlab::Error>(())
//! ```

mod covariance;
mod hac;
mod influence;
mod least_squares;
mod rls;
mod solve;
mod spectral;
// The streamed least squares of the lab's long stages.
#[cfg(any(feature = "lab", test))]
mod tsqr;

#[cfg(feature = "lab")]
pub(crate) use covariance::newey_west_of;
pub use covariance::{Covariance, MAX_LAGS, newey_west_lags};
#[cfg(feature = "lab")]
pub(crate) use hac::{Scratch, Series, Stats};
#[cfg(feature = "lab")]
pub(crate) use influence::{Sink, Source, influence_into};
pub use least_squares::{DEFAULT_MAX_CONDITION, LeastSquares, LeastSquaresFit};
pub use rls::Rls;
#[cfg(feature = "lab")]
pub(crate) use solve::{
    BLOCK_ROWS, BLOCKED_FROM_ROWS, NARROW, Triangular, binary_exponent, classical, equilibrate,
    equilibrate_into, fit_from, householder_narrow, pow2, scale_pow2, spread, triangular,
};
pub use spectral::{
    ETFE_MIN_INPUT, FrequencyEstimate, MAX_SPECTRAL_SAMPLES, SPA_DEFAULT_LAG, etfe, spa,
};
#[cfg(feature = "lab")]
pub(crate) use tsqr::Tsqr;
