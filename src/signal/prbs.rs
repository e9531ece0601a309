//! [`Prbs`]: maximum-length pseudo-random binary sequences.

use std::fmt;

use super::{Signal, check_amplitude};
use crate::error::Error;

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
