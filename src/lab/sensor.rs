//! [`EncoderSensor`]: what the rig measures, for the sampled-data simulator.

use nalgebra::SVector;

use crate::signal::Rng;
use crate::sim::Sensor;

/// The rig's measurement of the state `[x1, v1, x2, v2]`, as
/// [`MassSpringRig`](super::MassSpringRig) makes it: each position counted
/// by an encoder (`round(x / metres_per_count + noise)` counts), each speed
/// the difference of two counts over the period (the first sample reports
/// zero speed). With it, [`sim::run_sampled`](crate::sim::run_sampled)
/// measures what the rig would.
///
/// The noise has the card's statistics (Gaussian, σ in counts) but not its
/// exact draws.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::EncoderSensor;
/// use ctrlab::sim::Sensor;
/// use ctrlab::nalgebra::vector;
///
/// let mut enc = EncoderSensor::new(0.080 / 8192.0, 0.002, 0.0, 1);
/// let y0 = enc.measure(0.0, &vector![0.0, 0.0, 0.0, 0.0]);
/// let y1 = enc.measure(0.002, &vector![0.0, 0.0, 0.001, 0.5]);
/// assert_eq!(y0[3], 0.0);
/// // 0.001 m is 102.4 counts: 102 counts, 0.99609375 mm, over 2 ms.
/// assert_eq!(y1[2], 102.0 * 0.080 / 8192.0);
/// assert_eq!(y1[3], y1[2] / 0.002);
/// ```
#[derive(Debug, Clone)]
pub struct EncoderSensor {
    metres_per_count: f64,
    period: f64,
    noise: f64,
    rng: Rng,
    seed: u64,
    previous: Option<[f64; 2]>,
}

impl EncoderSensor {
    /// Encoders of `metres_per_count` m per count (> 0), sampled every
    /// `period` s (> 0), with Gaussian count noise of σ = `noise` counts
    /// (≥ 0) drawn from `seed`. Invalid values are replaced by the nearest
    /// valid ones' behaviour: a non-positive resolution or period gives an
    /// unquantised position and zero speed; a negative or non-finite noise
    /// none.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::lab::EncoderSensor;
    /// let enc = EncoderSensor::new(1e-5, 0.002, 0.5, 7);
    /// assert_eq!(enc.metres_per_count(), 1e-5);
    /// ```
    pub fn new(metres_per_count: f64, period: f64, noise: f64, seed: u64) -> Self {
        Self {
            metres_per_count,
            period,
            noise: if noise.is_finite() && noise > 0.0 {
                noise
            } else {
                0.0
            },
            rng: Rng::new(seed),
            seed,
            previous: None,
        }
    }

    /// Travel per count, m.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::lab::EncoderSensor;
    /// assert_eq!(EncoderSensor::new(2e-5, 0.002, 0.0, 0).metres_per_count(), 2e-5);
    /// ```
    pub fn metres_per_count(&self) -> f64 {
        self.metres_per_count
    }

    fn count(&mut self, x: f64) -> f64 {
        let q = self.metres_per_count;
        if !(q.is_finite() && q > 0.0) {
            return x;
        }
        let noise = if self.noise > 0.0 {
            self.noise * self.rng.gaussian()
        } else {
            0.0
        };
        (x / q + noise).round() * q
    }
}

impl Sensor<4, 4> for EncoderSensor {
    fn measure(&mut self, _t: f64, x: &SVector<f64, 4>) -> SVector<f64, 4> {
        let positions = [self.count(x[0]), self.count(x[2])];
        let previous = self.previous.replace(positions).unwrap_or(positions);
        let speed = |now: f64, before: f64| {
            if self.period.is_finite() && self.period > 0.0 {
                (now - before) / self.period
            } else {
                0.0
            }
        };
        SVector::<f64, 4>::new(
            positions[0],
            speed(positions[0], previous[0]),
            positions[1],
            speed(positions[1], previous[1]),
        )
    }

    fn reset(&mut self) {
        self.previous = None;
        self.rng = Rng::new(self.seed);
    }
}
