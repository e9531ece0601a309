//! [`Step`]: a switch from zero to a constant.

use super::{Signal, check_amplitude};
use crate::error::Error;

/// A step: 0 before [`time`](Step::time), [`amplitude`](Step::amplitude) from
/// `time` on (the value at `time` itself is the amplitude).
///
/// NaN `t` gives the value at `t = 0`; `t = −∞` gives 0 and `t = +∞` the
/// amplitude.
///
/// # Examples
///
/// ```
/// use ctrlab::signal::{Signal, Step};
/// // A 10 N push on the cart at t = 0.1 s.
/// let push = Step::new(10.0, 0.1)?;
/// assert_eq!(push.sample(0.0, 0.05, 4), [0.0, 0.0, 10.0, 10.0]);
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Step {
    amplitude: f64,
    time: f64,
}

impl Step {
    /// A step of `amplitude` (input unit) switching on at `time` (s).
    ///
    /// Both must be finite; `time` may be negative (a step already on at the
    /// start of the run).
    ///
    /// # Errors
    ///
    /// [`Error::InvalidParameter`] naming `"amplitude"` or `"time"` when it
    /// is NaN or infinite.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{Error, signal::{Signal, Step}};
    /// assert_eq!(Step::new(1.0, -1.0)?.value(0.0), 1.0);
    /// assert!(matches!(
    ///     Step::new(1.0, f64::INFINITY),
    ///     Err(Error::InvalidParameter { name: "time", .. })
    /// ));
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn new(amplitude: f64, time: f64) -> Result<Self, Error> {
        check_amplitude(amplitude)?;
        if !time.is_finite() {
            return Err(Error::InvalidParameter {
                name: "time",
                value: time,
                reason: "step time must be finite (s)",
            });
        }
        Ok(Step { amplitude, time })
    }

    /// The value from [`time`](Step::time) on, in the input's unit.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::signal::Step;
    /// assert_eq!(Step::new(2.5, 0.0)?.amplitude(), 2.5);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[must_use]
    pub fn amplitude(&self) -> f64 {
        self.amplitude
    }

    /// The switching time (s).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::signal::Step;
    /// assert_eq!(Step::new(2.5, 0.3)?.time(), 0.3);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[must_use]
    pub fn time(&self) -> f64 {
        self.time
    }
}

impl Signal for Step {
    #[inline]
    fn value(&self, t: f64) -> f64 {
        let t = if t.is_nan() { 0.0 } else { t };
        if t >= self.time { self.amplitude } else { 0.0 }
    }
}
