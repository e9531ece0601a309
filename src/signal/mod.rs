//! Test inputs: steps, square waves, and the identification inputs
//! (pseudo-random binary sequences, chirps, multisines), with the crate's
//! seeded random generator.
//!
//! A [`Signal`] is a pure function of time: [`value`](Signal::value) takes `t`
//! in seconds from the start of the run and returns an amplitude in the
//! input's own unit (volts on the rig, newtons in simulation). Evaluating a
//! signal twice at the same `t` gives the same value, so the same input can be
//! replayed on the simulated plant and on the rig, or sampled after the fact
//! to label a [`Recording`](crate::Recording).
//!
//! - [`Step`]: 0 before its switching time, its amplitude from then on.
//! - [`SquareWave`]: ±amplitude, switching every half period.
//! - [`Prbs`]: a maximum-length pseudo-random binary sequence, the classic
//!   identification input with a flat spectrum up to about 0.44 / clock Hz.
//! - [`Chirp`]: one sine sweep from `f0` to `f1` Hz, linear (flat spectrum
//!   over the band) or logarithmic (the same time per octave).
//! - [`Multisine`]: equal cosines on chosen harmonics of `1 / T`, an exact
//!   line spectrum (no leakage over whole periods), Schroeder or random
//!   phases.
//! - [`Rng`]: splitmix64 with Box–Muller normal samples, for reproducible
//!   noise (the simulated card's measurement noise uses the same stream).
//!
//! Constructors validate their parameters and return
//! [`Error::InvalidParameter`] naming the offending one; a constructed signal
//! returns a finite value at every finite `t`, and no method panics on any
//! input, NaN and infinities included.
//!
//! # Examples
//!
//! ```
//! use ctrlab::signal::{Prbs, Signal, SquareWave, Step};
//!
//! // A 2 V step at t = 0.5 s, sampled every 0.25 s.
//! let step = Step::new(2.0, 0.5)?;
//! assert_eq!(step.sample(0.0, 0.25, 4), [0.0, 0.0, 2.0, 2.0]);
//!
//! // ±1.5 V switching every 0.2 s: +1.5 V on [0, 0.2) s, −1.5 V on [0.2, 0.4) s.
//! let square = SquareWave::new(1.5, 0.2)?;
//! assert_eq!(square.value(0.1), 1.5);
//! assert_eq!(square.value(0.3), -1.5);
//!
//! // A 7-bit PRBS of ±1 V clocked every 10 ms repeats after 127 bits (1.27 s).
//! let prbs = Prbs::new(1.0, 0.01, 7, 1)?;
//! assert_eq!(prbs.len(), 127);
//! assert!((prbs.period() - 1.27).abs() < 1e-12);
//! assert_eq!(prbs.value(0.005), prbs.value(0.005 + prbs.period()));
//! # Ok::<(), ctrlab::Error>(())
//! ```

use crate::error::Error;

mod chirp;
mod multisine;
mod prbs;
mod rng;
mod square;
mod step;

pub use chirp::{Chirp, Sweep};
pub use multisine::{MULTISINE_MAX_LINES, Multisine, Phases};
pub use prbs::Prbs;
pub use rng::Rng;
pub use square::SquareWave;
pub use step::Step;

/// An input signal: a pure function from time (s, from the start of the run)
/// to an amplitude in the input's unit (V on the rig, N in simulation).
///
/// Implement [`value`](Signal::value); [`sample`](Signal::sample) is provided.
/// References to signals are signals too, and the trait is dyn-compatible,
/// so `&dyn Signal` works where the signal is chosen at run time.
///
/// The signals in this module return their value at `t = 0` when `t` is NaN,
/// so a NaN clock never reaches an actuator as a NaN command.
///
/// # Examples
///
/// ```
/// use ctrlab::signal::{Signal, SquareWave, Step};
///
/// /// A ramp of `slope` units per second.
/// struct Ramp {
///     slope: f64,
/// }
///
/// impl Signal for Ramp {
///     fn value(&self, t: f64) -> f64 {
///         self.slope * t
///     }
/// }
///
/// assert_eq!(Ramp { slope: 2.0 }.sample(0.0, 0.5, 3), [0.0, 1.0, 2.0]);
///
/// // Chosen at run time, through `&dyn Signal`.
/// let step = Step::new(1.0, 0.0)?;
/// let square = SquareWave::new(1.0, 0.1)?;
/// let inputs: [&dyn Signal; 2] = [&step, &square];
/// assert!(inputs.iter().all(|s| s.value(0.05) == 1.0));
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub trait Signal {
    /// The signal's value at time `t` (s, from the start of the run), in the
    /// input's unit.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::signal::{Signal, Step};
    /// let step = Step::new(3.0, 1.0)?;
    /// assert_eq!(step.value(0.999), 0.0);
    /// assert_eq!(step.value(1.0), 3.0);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[must_use]
    fn value(&self, t: f64) -> f64;

    /// `n` values at `t0 + k·dt` for `k = 0, 1, …, n − 1` (times in s).
    ///
    /// Each time is computed as `t0 + k as f64 * dt`, not by accumulating
    /// `dt`, so long records do not drift.
    ///
    /// # Panics
    ///
    /// Only as any `Vec` does, when `n` values do not fit in memory.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::signal::{Signal, SquareWave};
    /// let square = SquareWave::new(1.0, 0.2)?;
    /// // 2 ms samples: 100 per half period.
    /// let u = square.sample(0.0, 0.002, 400);
    /// assert_eq!(u.len(), 400);
    /// assert_eq!((u[50], u[150], u[250], u[350]), (1.0, -1.0, 1.0, -1.0));
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[must_use]
    fn sample(&self, t0: f64, dt: f64, n: usize) -> Vec<f64> {
        (0..n).map(|k| self.value(t0 + k as f64 * dt)).collect()
    }
}

impl<S: Signal + ?Sized> Signal for &S {
    #[inline]
    fn value(&self, t: f64) -> f64 {
        (**self).value(t)
    }

    fn sample(&self, t0: f64, dt: f64, n: usize) -> Vec<f64> {
        (**self).sample(t0, dt, n)
    }
}

/// Checks that an amplitude is finite.
pub(crate) fn check_amplitude(amplitude: f64) -> Result<(), Error> {
    if amplitude.is_finite() {
        Ok(())
    } else {
        Err(Error::InvalidParameter {
            name: "amplitude",
            value: amplitude,
            reason: "amplitude must be finite",
        })
    }
}
