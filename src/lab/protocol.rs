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
///
/// # Examples
///
/// ```
/// use ctrlab::lab::protocol::PERIOD;
/// assert_eq!(1.0 / PERIOD, 500.0); // a 500 Hz loop
/// ```
pub const PERIOD: f64 = 0.002;
/// Cart 1's mass, kg: the lab weighs the carts.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::protocol::{M1, M2};
/// assert!((M1 + M2 - 2.0).abs() < 1e-12); // 2 kg on the track
/// assert!(M1 > M2);
/// ```
pub const M1: f64 = 1.3;
/// Cart 2's mass, kg.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::protocol::{M1, M2};
/// assert!(M2 > 0.0 && M2 / M1 < 1.0); // the motor's cart is the lighter
/// ```
pub const M2: f64 = 0.7;
/// The identification input's amplitude, V: a ±8 V square wave is about
/// ±9 N, well clear of the friction. Near the first mode it swings the
/// default simulated rig's cart 2 ±31 mm, more than 60 % of its ±50 mm,
/// and a lighter-damped rig past its end stops: lab5 asks for this and
/// lowers it from probe runs ([`ident_input`](super::ident_input)).
///
/// # Examples
///
/// ```
/// use ctrlab::lab::protocol::IDENT_VOLTS;
/// let full_scale = ctrlab::lab::Calibration::default().volts_full_scale;
/// assert!(IDENT_VOLTS > 0.0 && IDENT_VOLTS < full_scale); // inside the ±24 V drive
/// ```
pub const IDENT_VOLTS: f64 = 8.0;
/// The square wave's half period, s.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::protocol::{IDENT_HALF_PERIOD, PERIOD};
/// // Each half period is a whole number of loop periods: 100.
/// assert!((IDENT_HALF_PERIOD / PERIOD - 100.0).abs() < 1e-9);
/// ```
pub const IDENT_HALF_PERIOD: f64 = 0.2;
/// Each identification run's length, s.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::protocol::{IDENT_DURATION, IDENT_HALF_PERIOD};
/// // A run is a whole number of half periods: 25 (12½ periods).
/// assert!((IDENT_DURATION / IDENT_HALF_PERIOD - 25.0).abs() < 1e-12);
/// ```
pub const IDENT_DURATION: f64 = 5.0;
/// Identification runs (Tables 3 and 4), and runs of each input compared.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::protocol::{IDENT_DURATION, IDENT_RUNS};
/// assert_eq!(IDENT_RUNS as f64 * IDENT_DURATION, 25.0); // s of identification data
/// ```
pub const IDENT_RUNS: u64 = 5;
/// Each closed-loop run's length (Tables 5 and 6), s.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::protocol::{PERIOD, STEP_DURATION};
/// // A whole number of loop periods: 1500 ticks per run.
/// assert!((STEP_DURATION / PERIOD - 1500.0).abs() < 1e-9);
/// ```
pub const STEP_DURATION: f64 = 3.0;

/// The identification input: ±[`IDENT_VOLTS`], [`IDENT_HALF_PERIOD`] half
/// period, starting high.
///
/// # Errors
///
/// None with the lab's constants; the signal's own checks otherwise.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::protocol::{self, IDENT_HALF_PERIOD, IDENT_VOLTS};
/// use ctrlab::signal::Signal;
/// let wave = protocol::ident_square_wave()?;
/// assert_eq!(wave.value(0.0), IDENT_VOLTS); // starts high
/// assert_eq!(wave.value(IDENT_HALF_PERIOD + 0.01), -IDENT_VOLTS);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn ident_square_wave() -> Result<SquareWave, Error> {
    SquareWave::new(IDENT_VOLTS, IDENT_HALF_PERIOD)
}

/// [`Error::InvalidParameter`] named `"volts"` unless `volts` (a peak drive,
/// V) is finite and positive: a drive of zero identifies nothing, and the
/// lab's inputs are given by their peak.
pub(crate) fn check_volts(volts: f64) -> Result<(), Error> {
    if volts.is_finite() && volts > 0.0 {
        Ok(())
    } else {
        Err(Error::InvalidParameter {
            name: "volts",
            value: volts,
            reason: "must be finite and > 0 V",
        })
    }
}
