//! [`Chirp`]: a sine swept once through a band of frequencies.

use std::f64::consts::TAU;

use super::{Signal, check_amplitude};
use crate::error::Error;

/// How a [`Chirp`]'s frequency moves from `f0` to `f1`.
///
/// # Examples
///
/// Halfway through a sweep from 1 to 100 Hz, the linear sweep is at the
/// arithmetic mean, the logarithmic one at the geometric mean:
///
/// ```
/// use ctrlab::signal::{Chirp, Sweep};
/// let linear = Chirp::new(1.0, 1.0, 100.0, 10.0, Sweep::Linear)?;
/// let log = Chirp::new(1.0, 1.0, 100.0, 10.0, Sweep::Logarithmic)?;
/// assert!((linear.frequency(5.0) - 50.5).abs() < 1e-12); // Hz
/// assert!((log.frequency(5.0) - 10.0).abs() < 1e-12); // Hz
/// assert!(Chirp::new(1.0, 0.0, 100.0, 10.0, Sweep::Logarithmic).is_err()); // f0 > 0
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Sweep {
    /// `f(t) = f0 + (f1 − f0)·t / T`: the same time per hertz, a flat
    /// amplitude spectrum over the band (SciPy's `chirp(method='linear')`).
    Linear,
    /// `f(t) = f0·(f1 / f0)^(t / T)`: the same time per octave, power
    /// density falling as `1 / f` (more of the run at low frequencies, where
    /// the rig's resonances are; SciPy's `method='logarithmic'`). Needs
    /// `f0 > 0`.
    Logarithmic,
}

/// A chirp (swept sine): `amplitude · sin φ(t)` for `0 ≤ t ≤ duration`,
/// with instantaneous frequency `φ'(t) / 2π` moving from `f0` to `f1` Hz as
/// the [`Sweep`] says, and 0 outside the sweep (NaN `t` gives the value at
/// 0, which is 0). The phase is
///
/// ```text
/// Linear:       φ(t) = 2π (f0 t + (f1 − f0) t² / (2T))
/// Logarithmic:  φ(t) = 2π f0 T (k^(t/T) − 1) / ln k,   k = f1 / f0
/// ```
///
/// so the signal starts at 0 with a continuous phase; it is SciPy's
/// `amplitude * chirp(t, f0, T, f1, method, phi=-90)`.
///
/// # Spectrum
///
/// A sweep spends `1 / |f'(t)|` seconds per hertz at frequency `f(t)`, so
/// its energy density is about `amplitude² / (2 |f'|)` inside `[f0, f1]`
/// and small outside: flat for the linear sweep
/// (`amplitude²·T / (2 |f1 − f0|)` per hertz), `∝ 1 / f` for the
/// logarithmic one. The band edges ripple (Fresnel ripples) unless the
/// sweep lasts many periods of `f0`. Unlike a [`Multisine`](super::Multisine)
/// the spectrum is not exactly zero between lines: record the whole sweep
/// and window the data if leakage matters. Each frequency is visited once,
/// briefly, so a lightly damped mode needs a slow sweep (many of its
/// periods per bandwidth) to respond fully.
///
/// # Examples
///
/// ```
/// use ctrlab::signal::{Chirp, Signal, Sweep};
///
/// // ±3 V from 0.5 Hz to 20 Hz in 20 s, linearly.
/// let chirp = Chirp::new(3.0, 0.5, 20.0, 20.0, Sweep::Linear)?;
/// assert_eq!(chirp.value(0.0), 0.0);
/// assert!((chirp.frequency(10.0) - 10.25).abs() < 1e-12);
/// assert_eq!(chirp.value(20.5), 0.0); // one sweep, then silence
/// assert!(chirp.sample(0.0, 0.002, 10_000).iter().all(|u| u.abs() <= 3.0));
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Chirp {
    amplitude: f64,
    f0: f64,
    f1: f64,
    duration: f64,
    sweep: Sweep,
}

impl Chirp {
    /// A sweep from `f0` to `f1` (Hz; `f1 < f0` sweeps down) over
    /// `duration` (s), of peak `amplitude` (the input's unit).
    ///
    /// # Errors
    ///
    /// [`Error::InvalidParameter`] naming `"amplitude"` (not finite), `"f0"`
    /// or `"f1"` (not finite, negative, or not positive for the logarithmic
    /// sweep), or `"duration"` (not finite and positive), or `"f1"` when the
    /// phase at the end of the sweep overflows (`f·T` beyond 1e15 cycles:
    /// no `f64` resolves the phase there).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{Error, signal::{Chirp, Sweep}};
    /// assert!(matches!(
    ///     Chirp::new(1.0, 0.0, 10.0, 5.0, Sweep::Logarithmic),
    ///     Err(Error::InvalidParameter { name: "f0", .. })
    /// ));
    /// assert!(Chirp::new(1.0, 0.0, 10.0, 5.0, Sweep::Linear).is_ok());
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn new(
        amplitude: f64,
        f0: f64,
        f1: f64,
        duration: f64,
        sweep: Sweep,
    ) -> Result<Self, Error> {
        check_amplitude(amplitude)?;
        let positive_needed = sweep == Sweep::Logarithmic;
        for (name, f) in [("f0", f0), ("f1", f1)] {
            let ok = f.is_finite() && if positive_needed { f > 0.0 } else { f >= 0.0 };
            if !ok {
                return Err(Error::InvalidParameter {
                    name,
                    value: f,
                    reason: if positive_needed {
                        "a logarithmic sweep's frequencies must be finite and > 0, Hz"
                    } else {
                        "a sweep's frequencies must be finite and >= 0, Hz"
                    },
                });
            }
        }
        if !(duration.is_finite() && duration > 0.0) {
            return Err(Error::InvalidParameter {
                name: "duration",
                value: duration,
                reason: "the sweep's duration must be finite and > 0, s",
            });
        }
        // Beyond ~1e15 cycles an f64 phase no longer resolves a cycle.
        if f0.max(f1) * duration > 1e15 {
            return Err(Error::InvalidParameter {
                name: "f1",
                value: f1,
                reason: "the sweep covers more than 1e15 cycles: its phase is not \
                         representable",
            });
        }
        Ok(Self {
            amplitude,
            f0,
            f1,
            duration,
            sweep,
        })
    }

    /// The phase `φ(t)` (rad) of the sweep, `t` clamped to `[0, duration]`
    /// (NaN as 0).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::signal::{Chirp, Sweep};
    /// let c = Chirp::new(1.0, 1.0, 3.0, 2.0, Sweep::Linear)?;
    /// // 2 s at a mean of 2 Hz: 4 cycles.
    /// assert!((c.phase(2.0) - 8.0 * std::f64::consts::PI).abs() < 1e-12);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[must_use]
    pub fn phase(&self, t: f64) -> f64 {
        let t = self.within(t);
        let (f0, f1, big_t) = (self.f0, self.f1, self.duration);
        match self.sweep {
            Sweep::Linear => TAU * t * (f0 + (f1 - f0) * t / (2.0 * big_t)),
            Sweep::Logarithmic => {
                let k = f1 / f0;
                if k == 1.0 {
                    TAU * f0 * t
                } else if k.is_finite() && k > 0.0 {
                    // k^(t/T) − 1 through exp_m1, exact as k → 1.
                    let ln_k = k.ln();
                    TAU * f0 * big_t * (ln_k * t / big_t).exp_m1() / ln_k
                } else {
                    // f1 / f0 beyond f64 (1e-300 Hz to 1e10 Hz): the same
                    // phase, T (f(t) − f0) / ln k, from logarithms.
                    let ln_k = f1.ln() - f0.ln();
                    let x = ln_k * t / big_t;
                    let grown = if x.abs() < 1.0 {
                        f0 * x.exp_m1()
                    } else {
                        (f0.ln() + x).exp() - f0
                    };
                    TAU * big_t * grown / ln_k
                }
            }
        }
    }

    /// The instantaneous frequency `φ'(t) / 2π` (Hz) at `t` (s), `t`
    /// clamped to `[0, duration]` (NaN as 0).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::signal::{Chirp, Sweep};
    /// let c = Chirp::new(1.0, 1.0, 100.0, 10.0, Sweep::Logarithmic)?;
    /// assert!((c.frequency(5.0) - 10.0).abs() < 1e-12); // halfway in octaves
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[must_use]
    pub fn frequency(&self, t: f64) -> f64 {
        let t = self.within(t);
        let s = t / self.duration;
        match self.sweep {
            Sweep::Linear => self.f0 + (self.f1 - self.f0) * s,
            Sweep::Logarithmic => {
                let k = self.f1 / self.f0;
                if k.is_finite() && k > 0.0 {
                    self.f0 * k.powf(s)
                } else {
                    // f1 / f0 beyond f64: interpolate the logarithms.
                    (self.f0.ln() * (1.0 - s) + self.f1.ln() * s).exp()
                }
            }
        }
    }

    /// `t` clamped to the sweep, NaN as 0, s.
    fn within(&self, t: f64) -> f64 {
        if t.is_nan() {
            0.0
        } else {
            t.clamp(0.0, self.duration)
        }
    }

    /// The peak amplitude, in the input's unit.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::signal::{Chirp, Sweep};
    /// assert_eq!(Chirp::new(2.5, 1.0, 5.0, 1.0, Sweep::Linear)?.amplitude(), 2.5);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn amplitude(&self) -> f64 {
        self.amplitude
    }

    /// The sweep's duration, s.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::signal::{Chirp, Sweep};
    /// assert_eq!(Chirp::new(1.0, 1.0, 5.0, 4.0, Sweep::Linear)?.duration(), 4.0);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn duration(&self) -> f64 {
        self.duration
    }

    /// The band `(f0, f1)`, Hz, in sweep order.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::signal::{Chirp, Sweep};
    /// let c = Chirp::new(1.0, 8.0, 2.0, 4.0, Sweep::Logarithmic)?;
    /// assert_eq!(c.band(), (8.0, 2.0)); // a downward sweep
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn band(&self) -> (f64, f64) {
        (self.f0, self.f1)
    }

    /// The sweep law.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::signal::{Chirp, Sweep};
    /// assert_eq!(Chirp::new(1.0, 1.0, 5.0, 4.0, Sweep::Linear)?.sweep(), Sweep::Linear);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn sweep(&self) -> Sweep {
        self.sweep
    }
}

impl Signal for Chirp {
    #[inline]
    fn value(&self, t: f64) -> f64 {
        if !(0.0..=self.duration).contains(&t) {
            return 0.0;
        }
        self.amplitude * self.phase(t).sin()
    }
}
