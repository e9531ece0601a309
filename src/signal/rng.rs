//! [`Rng`]: the crate's seeded random generator.

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
