//! How the lab's experiments are run: the loop's period, the masses the lab
//! weighs, the identification input and how many runs, the length of a
//! closed-loop run. Shared by lab5, its tests and the benches, so that
//! they run the same experiments.
//!
//! # Examples
//!
//! ```
//! use ctrlab::lab::protocol;
//! use ctrlab::signal::Signal;
//! let wave = protocol::ident_square_wave()?;
//! assert_eq!((wave.value(0.1), wave.value(0.3)), (8.0, -8.0));
//! assert_eq!(protocol::IDENT_DURATION / protocol::PERIOD, 2500.0);
//! # Ok::<(), ctrlab::Error>(())
//! ```

use crate::error::Error;
use crate::signal::SquareWave;

/// The loop's period, s.
pub const PERIOD: f64 = 0.002;
/// Cart 1's mass, kg: the lab weighs the carts.
pub const M1: f64 = 1.3;
/// Cart 2's mass, kg.
pub const M2: f64 = 0.7;
/// The identification input's amplitude, V: a ±8 V square wave is about
/// ±9 N, well clear of the friction. Near the first mode it swings the
/// default simulated rig's cart 2 ±31 mm, more than 60 % of its ±50 mm,
/// and a lighter-damped rig past its end stops: lab5 asks for this and
/// lowers it from probe runs ([`ident_input`](super::ident_input)).
pub const IDENT_VOLTS: f64 = 8.0;
/// The square wave's half period, s.
pub const IDENT_HALF_PERIOD: f64 = 0.2;
/// Each identification run's length, s.
pub const IDENT_DURATION: f64 = 5.0;
/// Identification runs (Tables 3 and 4), and runs of each input compared.
pub const IDENT_RUNS: u64 = 5;
/// Each closed-loop run's length (Tables 5 and 6), s.
pub const STEP_DURATION: f64 = 3.0;

/// The identification input: ±[`IDENT_VOLTS`], [`IDENT_HALF_PERIOD`] half
/// period, starting high.
///
/// # Errors
///
/// None with the lab's constants; the signal's own checks otherwise.
pub fn ident_square_wave() -> Result<SquareWave, Error> {
    SquareWave::new(IDENT_VOLTS, IDENT_HALF_PERIOD)
}
