//! Test inputs: steps, square waves, pseudo-random binary sequences, and the
//! crate's seeded random generator.
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

use std::fmt;

use crate::error::Error;

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
fn check_amplitude(amplitude: f64) -> Result<(), Error> {
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

/// Smallest accepted [`Prbs`] order (bits).
const PRBS_MIN_ORDER: u32 = 2;
/// Largest accepted [`Prbs`] order (bits): 2²⁰ − 1 bits, 128 KiB of bitset.
const PRBS_MAX_ORDER: u32 = 20;

/// Feedback taps of a maximal-length Fibonacci LFSR for each order 2..=20,
/// as exponents of a primitive polynomial `x^n + … + 1` (the standard table,
/// e.g. Wikipedia's "Linear-feedback shift register" article). The tests
/// check every row for maximal length.
const PRBS_TAPS: [&[u32]; (PRBS_MAX_ORDER - PRBS_MIN_ORDER + 1) as usize] = [
    &[2, 1],
    &[3, 2],
    &[4, 3],
    &[5, 3],
    &[6, 5],
    &[7, 6],
    &[8, 6, 5, 4],
    &[9, 5],
    &[10, 7],
    &[11, 9],
    &[12, 11, 10, 4],
    &[13, 12, 11, 8],
    &[14, 13, 12, 2],
    &[15, 14],
    &[16, 15, 13, 4],
    &[17, 14],
    &[18, 11],
    &[19, 18, 17, 14],
    &[20, 17],
];

/// A maximum-length pseudo-random binary sequence (m-sequence): `±amplitude`,
/// holding each bit for [`clock`](Prbs::clock) seconds.
///
/// The bits come from a Fibonacci linear-feedback shift register of
/// [`order`](Prbs::order) `n` bits (2 ≤ `n` ≤ 20) with a primitive feedback
/// polynomial, so the register visits all 2ⁿ − 1 nonzero states and the
/// sequence repeats after [`len`](Prbs::len) = 2ⁿ − 1 bits, a
/// [`period`](Prbs::period) of (2ⁿ − 1)·clock seconds. The register starts
/// at the seed, and the first `n` bits of the sequence are the seed's low
/// `n` bits, least significant first (1 → `+amplitude`, 0 → `−amplitude`).
///
/// Bit `k` is held on `[k·clock, (k + 1)·clock)`: `value(t)` is the bit
/// `⌊t / clock⌋ mod (2ⁿ − 1)`, a pure function of `t` (the sequence is
/// computed once, at construction). Times before 0, and NaN, give the first
/// bit. The edges sit where the computed quotient `t / clock` crosses an
/// integer, so a time computed as `k·clock` can round into bit `k − 1`;
/// read bit `k` mid-bit, at `(k + ½)·clock`. Beyond 2⁵³ clock periods `f64`
/// no longer resolves single bits.
///
/// # Properties
///
/// - **Balance**: each period has 2ⁿ⁻¹ bits at `+amplitude` and 2ⁿ⁻¹ − 1 at
///   `−amplitude`, so the mean is `amplitude / (2ⁿ − 1)`.
/// - **Autocorrelation**: the circular autocorrelation of one period is
///   `amplitude²` at lag 0 and `−amplitude² / (2ⁿ − 1)` at every other lag
///   (in whole bits): nearly white.
/// - **Spectrum**: a line spectrum with lines every `1 / period` Hz. Apart
///   from the DC line (power `(amplitude / (2ⁿ − 1))²`) the line powers follow
///   the envelope `amplitude²·(2ⁿ / (2ⁿ − 1)²)·sinc²(f·clock)`, with
///   `sinc(x) = sin(πx) / (πx)`: flat to within 3 dB up to about
///   `0.44 / clock` Hz, zero at multiples of `1 / clock`. Choose `clock` so
///   that `0.44 / clock` covers the band to identify, and the period longer
///   than the plant's settling time.
///
/// # Examples
///
/// ```
/// use ctrlab::signal::{Prbs, Signal};
///
/// // ±1 V, a new bit every 20 ms, 2¹⁰ − 1 = 1023 bits per period.
/// let prbs = Prbs::new(1.0, 0.02, 10, 0x2a5)?;
/// let one_period = prbs.sample(0.01, 0.02, prbs.len()); // mid-bit samples
/// let ones = one_period.iter().filter(|&&v| v == 1.0).count();
/// assert_eq!(ones, 512); // and 511 at −1 V
/// assert!((one_period.iter().sum::<f64>() / 1023.0 - 1.0 / 1023.0).abs() < 1e-15);
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Clone, PartialEq)]
pub struct Prbs {
    amplitude: f64,
    clock: f64,
    order: u32,
    /// The register's initial state: the seed masked to `order` bits.
    seed: u64,
    /// One period of the sequence, bit `k` at `bits[k / 64] >> (k % 64)`.
    bits: Vec<u64>,
}

impl Prbs {
    /// A PRBS of `±amplitude` (input unit), a new bit every `clock` seconds,
    /// from an LFSR of `order` bits (2..=20) started at `seed`.
    ///
    /// Only the low `order` bits of `seed` are used (the register's initial
    /// state; see [`seed`](Prbs::seed)); they must not all be zero, since
    /// the all-zero state is the one an LFSR never leaves. Different seeds
    /// give circular shifts of the same sequence. Construction computes the
    /// whole period: 2ⁿ − 1 register steps and (2ⁿ − 1) / 8 bytes.
    ///
    /// # Errors
    ///
    /// [`Error::InvalidParameter`] naming
    ///
    /// - `"amplitude"` when it is not finite,
    /// - `"clock"` when it is not finite and > 0 s, or the period
    ///   (2ⁿ − 1)·clock overflows,
    /// - `"order"` when it is outside 2..=20,
    /// - `"seed"` when its low `order` bits are all zero.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{Error, signal::{Prbs, Signal}};
    ///
    /// // The first `order` bits are the seed's, least significant first.
    /// let prbs = Prbs::new(2.0, 0.1, 4, 0b0110)?;
    /// assert_eq!(prbs.sample(0.05, 0.1, 4), [-2.0, 2.0, 2.0, -2.0]);
    ///
    /// // 0x100 has no bit among the low 8: refused.
    /// assert!(matches!(
    ///     Prbs::new(1.0, 0.1, 8, 0x100),
    ///     Err(Error::InvalidParameter { name: "seed", .. })
    /// ));
    /// assert!(matches!(
    ///     Prbs::new(1.0, 0.1, 21, 1),
    ///     Err(Error::InvalidParameter { name: "order", .. })
    /// ));
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn new(amplitude: f64, clock: f64, order: u32, seed: u64) -> Result<Self, Error> {
        check_amplitude(amplitude)?;
        if !(PRBS_MIN_ORDER..=PRBS_MAX_ORDER).contains(&order) {
            return Err(Error::InvalidParameter {
                name: "order",
                value: f64::from(order),
                reason: "PRBS order must be in 2..=20 bits",
            });
        }
        let len = (1usize << order) - 1;
        if !(clock.is_finite() && clock > 0.0 && (len as f64 * clock).is_finite()) {
            return Err(Error::InvalidParameter {
                name: "clock",
                value: clock,
                reason: "PRBS clock period must be finite and > 0 s, with a finite period",
            });
        }
        let mask = (1u64 << order) - 1;
        let seed_bits = seed & mask;
        if seed_bits == 0 {
            return Err(Error::InvalidParameter {
                name: "seed",
                // Exact up to 2^53; a larger seed is named approximately.
                value: seed as f64,
                reason: "PRBS seed must have a nonzero bit among its low `order` bits",
            });
        }

        // Tap at exponent p reads register bit n − p (the bit n − p shifts
        // before it is output), so exponent n is bit 0, the output bit.
        let taps = PRBS_TAPS[(order - PRBS_MIN_ORDER) as usize]
            .iter()
            .fold(0u64, |m, &p| m | (1 << (order - p)));
        let mut state = seed_bits;
        let mut bits = vec![0u64; len.div_ceil(64)];
        for k in 0..len {
            bits[k / 64] |= (state & 1) << (k % 64);
            let feedback = u64::from((state & taps).count_ones() & 1);
            state = (state >> 1) | (feedback << (order - 1));
        }
        Ok(Prbs {
            amplitude,
            clock,
            order,
            seed: seed_bits,
            bits,
        })
    }

    /// The amplitude (input unit): bits are `+amplitude` (1) or
    /// `−amplitude` (0).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::signal::Prbs;
    /// assert_eq!(Prbs::new(0.5, 0.01, 6, 1)?.amplitude(), 0.5);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[must_use]
    pub fn amplitude(&self) -> f64 {
        self.amplitude
    }

    /// Time each bit is held (s).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::signal::Prbs;
    /// assert_eq!(Prbs::new(0.5, 0.01, 6, 1)?.clock(), 0.01);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[must_use]
    pub fn clock(&self) -> f64 {
        self.clock
    }

    /// The shift register's length `n` (bits).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::signal::Prbs;
    /// assert_eq!(Prbs::new(0.5, 0.01, 6, 1)?.order(), 6);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[must_use]
    pub fn order(&self) -> u32 {
        self.order
    }

    /// The register's initial state: the seed passed to
    /// [`new`](Prbs::new), masked to its low [`order`](Prbs::order) bits.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::signal::Prbs;
    /// assert_eq!(Prbs::new(0.5, 0.01, 6, 0xff)?.seed(), 0x3f);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[must_use]
    pub fn seed(&self) -> u64 {
        self.seed
    }

    /// Bits per period, 2ⁿ − 1 (never 0: at least 3).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::signal::Prbs;
    /// assert_eq!(Prbs::new(0.5, 0.01, 6, 1)?.len(), 63);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[must_use]
    #[expect(
        clippy::len_without_is_empty,
        reason = "a PRBS always has at least 3 bits"
    )]
    pub fn len(&self) -> usize {
        (1usize << self.order) - 1
    }

    /// The sequence's period, (2ⁿ − 1)·clock (s).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::signal::{Prbs, Signal};
    /// let prbs = Prbs::new(0.5, 0.01, 6, 1)?;
    /// assert!((prbs.period() - 0.63).abs() < 1e-12);
    /// assert_eq!(prbs.value(0.123), prbs.value(0.123 + prbs.period()));
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[must_use]
    pub fn period(&self) -> f64 {
        self.len() as f64 * self.clock
    }
}

impl Signal for Prbs {
    #[inline]
    fn value(&self, t: f64) -> f64 {
        // `as` truncates toward zero and saturates: t < 0 and NaN give 0
        // (the first bit), t / clock beyond u64::MAX gives u64::MAX. `len`
        // is at least 3, so the remainder never divides by zero.
        let k = ((t / self.clock) as u64 % self.len() as u64) as usize;
        if (self.bits[k / 64] >> (k % 64)) & 1 == 1 {
            self.amplitude
        } else {
            -self.amplitude
        }
    }
}

/// The sequence itself is left out: up to 16 384 words.
impl fmt::Debug for Prbs {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Prbs")
            .field("amplitude", &self.amplitude)
            .field("clock", &self.clock)
            .field("order", &self.order)
            .field("seed", &self.seed)
            .field("len", &self.len())
            .finish_non_exhaustive()
    }
}

/// The crate's seeded random generator: splitmix64, with Box–Muller normal
/// samples.
///
/// Small (one `u64` of state), fast, allocation-free and reproducible: the
/// same seed gives the same stream on every platform and in every release,
/// since the simulated card's measurement noise, and therefore recorded
/// simulation runs, depend on it. splitmix64 is Steele, Lea and Flood's
/// generator as in Vigna's reference implementation (seed 0 starts
/// `0xe220a8397b1dcdaf`). Not for cryptography.
///
/// `Rng` is deliberately not `Copy`, so a stream cannot be duplicated by
/// accident; [`Clone`] it to replay one.
///
/// # Examples
///
/// ```
/// use ctrlab::signal::Rng;
///
/// let mut rng = Rng::new(0);
/// assert_eq!(rng.next_u64(), 0xe220_a839_7b1d_cdaf);
///
/// // Reproducible noise: a clone replays the stream.
/// let mut a = Rng::new(42);
/// let mut b = a.clone();
/// assert_eq!(a.gaussian(), b.gaussian());
/// ```
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Rng {
    state: u64,
}

impl Rng {
    /// A generator started from `seed`; every `u64`, 0 included, is a good
    /// seed.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::signal::Rng;
    /// assert_eq!(Rng::new(7), Rng::new(7));
    /// assert_ne!(Rng::new(7).next_u64(), Rng::new(8).next_u64());
    /// ```
    #[must_use]
    pub fn new(seed: u64) -> Self {
        Rng { state: seed }
    }

    /// The next 64 uniformly distributed bits (splitmix64).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::signal::Rng;
    /// let mut rng = Rng::new(0);
    /// assert_eq!(rng.next_u64(), 0xe220_a839_7b1d_cdaf);
    /// assert_eq!(rng.next_u64(), 0x6e78_9e6a_a1b9_65f4);
    /// ```
    pub fn next_u64(&mut self) -> u64 {
        self.state = self.state.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.state;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// A uniform sample in `[0, 1)`: the top 53 bits of
    /// [`next_u64`](Rng::next_u64) scaled by 2⁻⁵³, so every multiple of
    /// 2⁻⁵³ in the interval is equally likely.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::signal::Rng;
    /// let mut rng = Rng::new(1);
    /// let mean = (0..10_000).map(|_| rng.uniform()).sum::<f64>() / 10_000.0;
    /// assert!((mean - 0.5).abs() < 0.02);
    /// ```
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// A standard normal sample (mean 0, standard deviation 1) by the
    /// Box–Muller transform of two [`next_u64`](Rng::next_u64) draws; scale
    /// it by the noise's standard deviation. Always finite (|x| < 8.6).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::signal::Rng;
    /// let mut rng = Rng::new(2);
    /// let x: Vec<f64> = (0..10_000).map(|_| rng.gaussian()).collect();
    /// let mean = x.iter().sum::<f64>() / 1e4;
    /// let var = x.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / 1e4;
    /// assert!(mean.abs() < 0.05 && (var - 1.0).abs() < 0.05);
    /// ```
    pub fn gaussian(&mut self) -> f64 {
        // Uniform in (0, 1]: never 0, so the logarithm is finite.
        let u1 = ((self.next_u64() >> 11) + 1) as f64 / (1u64 << 53) as f64;
        let u2 = (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
        (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
    }
}
