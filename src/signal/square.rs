//! [`SquareWave`]: the lab's ±amplitude identification input.

use super::{Signal, check_amplitude};
use crate::error::Error;

/// A square wave: `+amplitude` on `[0, h)`, `−amplitude` on `[h, 2h)`, and so
/// on, with `h` the [`half_period`](SquareWave::half_period).
///
/// The value is `+amplitude` when `⌊t / h⌋` is even and `−amplitude` when it
/// is odd, so negative `t` continues the wave periodically (`−amplitude` on
/// `[−h, 0)`). NaN `t` gives `+amplitude`, the value at `t = 0`. For
/// `t ≥ 0` this is exactly the lab's
/// `if ((t / h) as u64).is_multiple_of(2) { a } else { -a }`, including its
/// saturation: `t / h` beyond `u64::MAX` (and `t = +∞`) gives `−amplitude`.
/// As there, the switches sit where the computed quotient `t / h` crosses an
/// integer, so a time computed as `k·h` can round into the previous half
/// period.
/// Beyond 2⁵³ half periods `f64` no longer resolves single half periods and
/// the wave is no longer meaningful, though it stays finite.
///
/// # Examples
///
/// ```
/// use ctrlab::signal::{Signal, SquareWave};
/// // The lab's identification input: ±2 V, switching every 0.2 s.
/// let u = SquareWave::new(2.0, 0.2)?;
/// assert_eq!(u.sample(0.0, 0.1, 6), [2.0, 2.0, -2.0, -2.0, 2.0, 2.0]);
/// assert_eq!(u.value(-0.1), -2.0);
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SquareWave {
    amplitude: f64,
    half_period: f64,
}

impl SquareWave {
    /// A square wave of `±amplitude` (input unit) switching every
    /// `half_period` seconds.
    ///
    /// # Errors
    ///
    /// [`Error::InvalidParameter`] naming `"amplitude"` when it is not finite,
    /// or `"half_period"` when it is not finite and > 0 s or when the period
    /// `2·half_period` overflows.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{Error, signal::{Signal, SquareWave}};
    /// assert_eq!(SquareWave::new(1.0, 0.5)?.value(0.75), -1.0);
    /// assert!(matches!(
    ///     SquareWave::new(1.0, 0.0),
    ///     Err(Error::InvalidParameter { name: "half_period", .. })
    /// ));
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn new(amplitude: f64, half_period: f64) -> Result<Self, Error> {
        check_amplitude(amplitude)?;
        if !(half_period.is_finite() && half_period > 0.0 && (2.0 * half_period).is_finite()) {
            return Err(Error::InvalidParameter {
                name: "half_period",
                value: half_period,
                reason: "half period must be finite and > 0 s, with a finite period",
            });
        }
        Ok(SquareWave {
            amplitude,
            half_period,
        })
    }

    /// The amplitude (input unit): the wave switches between `+amplitude`
    /// and `−amplitude`.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::signal::SquareWave;
    /// assert_eq!(SquareWave::new(1.5, 0.2)?.amplitude(), 1.5);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[must_use]
    pub fn amplitude(&self) -> f64 {
        self.amplitude
    }

    /// Time between switches (s).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::signal::SquareWave;
    /// assert_eq!(SquareWave::new(1.5, 0.2)?.half_period(), 0.2);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[must_use]
    pub fn half_period(&self) -> f64 {
        self.half_period
    }

    /// The full period, `2·half_period` (s).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::signal::SquareWave;
    /// assert_eq!(SquareWave::new(1.5, 0.2)?.period(), 0.4);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[must_use]
    pub fn period(&self) -> f64 {
        2.0 * self.half_period
    }
}

impl Signal for SquareWave {
    #[inline]
    fn value(&self, t: f64) -> f64 {
        let q = (t / self.half_period).floor();
        // `as` saturates and maps NaN to 0. For q ≥ 0 (t ≥ 0) this is the
        // lab's `(t / h) as u64`; for q < 0, ⌊t / h⌋ and its negation have
        // the same parity. NaN fails `q >= 0.0` and gives index 0.
        let k = if q >= 0.0 { q as u64 } else { (-q) as u64 };
        if k.is_multiple_of(2) {
            self.amplitude
        } else {
            -self.amplitude
        }
    }
}
