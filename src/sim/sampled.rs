//! The sampled-data simulator: a continuous plant under a discrete
//! [`Controller`], as the rig runs it.

use nalgebra::SVector;

use crate::data::{Recording, Schema};
use crate::design::Controller;
use crate::error::Error;
use crate::integrate::{Integrator, Rk4};
use crate::model::Dynamics;
use crate::signal::Rng;

use super::{MAX_RK4_STEPS, MAX_SAMPLES};

/// What a simulated plant's sensors report: the measurements `y` (`P`
/// values) at time `t` (s) from the true state `x`.
///
/// Closures `FnMut(&SVector<f64, N>) -> SVector<f64, P>` are sensors (a
/// linear `y = C x` is `|x| c * x`); a sensor with memory (an encoder whose
/// speed is differenced counts, as the lab's
/// [`EncoderSensor`](crate::lab::EncoderSensor)) implements the trait and
/// clears its memory in [`reset`](Self::reset).
///
/// # Examples
///
/// ```
/// use ctrlab::sim::Sensor;
/// use ctrlab::nalgebra::{SVector, matrix, vector};
///
/// let c = matrix![1.0, 0.0];
/// let mut position = |x: &SVector<f64, 2>| c * x;
/// assert_eq!(position.measure(0.0, &vector![0.3, 2.0]), vector![0.3]);
/// ```
pub trait Sensor<const N: usize, const P: usize> {
    /// The measurements at time `t` (s) of state `x`. Called once per
    /// sampling instant, in order; allocates nothing.
    fn measure(&mut self, t: f64, x: &SVector<f64, N>) -> SVector<f64, P>;

    /// Forgets earlier samples before a new run. The default does nothing.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::sim::Sensor;
    /// use ctrlab::nalgebra::{SVector, vector};
    /// let mut full = |x: &SVector<f64, 1>| *x;
    /// full.reset();
    /// assert_eq!(full.measure(0.0, &vector![1.0]), vector![1.0]);
    /// ```
    fn reset(&mut self) {}
}

impl<const N: usize, const P: usize, F> Sensor<N, P> for F
where
    F: FnMut(&SVector<f64, N>) -> SVector<f64, P>,
{
    #[inline]
    fn measure(&mut self, _t: f64, x: &SVector<f64, N>) -> SVector<f64, P> {
        self(x)
    }
}

/// Settings of a sampled-data simulation ([`run_sampled`]): the controller's
/// period, the run's length, and what stands between controller and plant.
///
/// [`new`](Self::new) sets the period and duration and leaves the rest
/// ideal: no delay, saturation, quantisation or noise; RK4 sub-steps of at
/// most an eighth of the period.
///
/// # Examples
///
/// ```
/// use ctrlab::sim::SampledConfig;
/// // The lab's drive: 2 ms, ±24 V in 24 mV steps, 0.15 ms latch-to-PWM delay.
/// let config = SampledConfig::<1, 4> {
///     saturation: [24.0],
///     input_quantisation: [0.024],
///     input_delay: 0.15e-3,
///     ..SampledConfig::new(0.002, 3.0)
/// };
/// assert_eq!(config.max_substep, 0.25e-3);
/// assert!(config.validate().is_ok());
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct SampledConfig<const M: usize, const P: usize> {
    /// The controller's sampling period `T`, s (> 0).
    pub period: f64,
    /// Length of the run, s: `round(duration / period)` samples (≥ 1).
    pub duration: f64,
    /// Largest RK4 sub-step, s (> 0); each hold interval is split into equal
    /// steps no longer than this.
    pub max_substep: f64,
    /// Delay from the sampling instant to the new input reaching the plant,
    /// s, `0 ≤ delay < period` (the old input is held until then): the
    /// computation and latch-to-PWM time of a real loop.
    pub input_delay: f64,
    /// Symmetric limit on each input, `|u_i| ≤ saturation[i]` (> 0;
    /// `f64::INFINITY` for none).
    pub saturation: [f64; M],
    /// Resolution of each input after saturation (a PWM duty step in
    /// volts), `u ← q round(u / q)` (≥ 0; 0 for none), kept within the
    /// saturation (to rounding): a step that rounds past it is taken back.
    pub input_quantisation: [f64; M],
    /// Resolution of each measurement, `y ← q round(y / q)` (≥ 0; 0 for
    /// none), applied after the noise.
    pub quantisation: [f64; P],
    /// Standard deviation of Gaussian noise added to each measurement, in
    /// its unit (≥ 0; 0 for none).
    pub noise: [f64; P],
    /// Seed of the noise (the crate's [`Rng`]): the same seed, the same run.
    pub seed: u64,
    /// Names and units of the recording's channels; `None` for
    /// [`Schema::numbered`].
    pub schema: Option<Schema>,
}

impl<const M: usize, const P: usize> SampledConfig<M, P> {
    /// An ideal sampled-data loop at `period` s for `duration` s: no delay,
    /// saturation, quantisation or noise, sub-steps of at most `period / 8`,
    /// numbered channels.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::sim::SampledConfig;
    /// let c = SampledConfig::<1, 1>::new(0.01, 1.0);
    /// assert_eq!((c.saturation, c.noise), ([f64::INFINITY], [0.0]));
    /// ```
    pub fn new(period: f64, duration: f64) -> Self {
        Self {
            period,
            duration,
            max_substep: period / 8.0,
            input_delay: 0.0,
            saturation: [f64::INFINITY; M],
            input_quantisation: [0.0; M],
            quantisation: [0.0; P],
            noise: [0.0; P],
            seed: 0x5eed,
            schema: None,
        }
    }

    /// Checks every field; returns the number of samples.
    ///
    /// # Errors
    ///
    /// [`Error::InvalidParameter`] naming the first bad field;
    /// [`Error::LengthMismatch`] for a schema with other than `M` inputs and
    /// `P` measurements.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::{Error, sim::SampledConfig};
    /// let c = SampledConfig::<1, 1> { input_delay: 0.02, ..SampledConfig::new(0.01, 1.0) };
    /// assert!(matches!(c.validate(), Err(Error::InvalidParameter { name: "input_delay", .. })));
    /// assert_eq!(SampledConfig::<1, 1>::new(0.01, 1.0).validate()?, 100);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn validate(&self) -> Result<usize, Error> {
        let bad = |name, value, reason| Error::InvalidParameter {
            name,
            value,
            reason,
        };
        if !(self.period.is_finite() && self.period > 0.0) {
            return Err(bad("period", self.period, "must be finite and > 0 s"));
        }
        let samples = (self.duration / self.period).round();
        if !(self.duration.is_finite() && samples >= 1.0) {
            return Err(bad(
                "duration",
                self.duration,
                "must be finite and at least one period, s",
            ));
        }
        if samples > MAX_SAMPLES as f64 {
            return Err(bad(
                "duration",
                self.duration,
                "more samples than sim::MAX_SAMPLES",
            ));
        }
        if !(self.max_substep.is_finite() && self.max_substep > 0.0) {
            return Err(bad(
                "max_substep",
                self.max_substep,
                "must be finite and > 0 s",
            ));
        }
        // A sub-step a million times shorter than the period is a unit slip,
        // and unbounded work besides.
        if self.period / self.max_substep > 1e6 {
            return Err(bad(
                "max_substep",
                self.max_substep,
                "more than 10^6 sub-steps per period",
            ));
        }
        // And a bound on the whole run's work, as for `simulate`.
        if samples * (self.period / self.max_substep).ceil() > MAX_RK4_STEPS as f64 {
            return Err(bad(
                "max_substep",
                self.max_substep,
                "more than sim::MAX_RK4_STEPS RK4 steps in all",
            ));
        }
        if !(self.input_delay.is_finite()
            && self.input_delay >= 0.0
            && self.input_delay < self.period)
        {
            return Err(bad(
                "input_delay",
                self.input_delay,
                "must be finite, >= 0 and < period, s",
            ));
        }
        for &s in &self.saturation {
            if s.is_nan() || s <= 0.0 {
                return Err(bad("saturation", s, "must be > 0 (infinity for none)"));
            }
        }
        for (name, values) in [
            ("input_quantisation", &self.input_quantisation[..]),
            ("quantisation", &self.quantisation[..]),
            ("noise", &self.noise[..]),
        ] {
            if let Some(&v) = values.iter().find(|v| !(v.is_finite() && **v >= 0.0)) {
                return Err(bad(name, v, "must be finite and >= 0"));
            }
        }
        if let Some(schema) = &self.schema {
            if schema.inputs().len() != M {
                return Err(Error::LengthMismatch {
                    what: "schema inputs",
                    expected: M,
                    found: schema.inputs().len(),
                });
            }
            if schema.measurements().len() != P {
                return Err(Error::LengthMismatch {
                    what: "schema measurements",
                    expected: P,
                    found: schema.measurements().len(),
                });
            }
        }
        Ok(samples as usize)
    }
}

/// Simulates a continuous plant under a discrete controller, as the rig
/// runs it, and records the run.
///
/// `plant` is any [`Dynamics`] (linear or not: Coulomb friction, a
/// saturating motor), integrated by RK4 with its
/// [`update_mode`](Dynamics::update_mode) called between steps; `sensor`
/// turns its state into measurements. Each sample `k`, at `t_k = k T`:
///
/// 1. measure `y_k` = `sensor(t_k, x(t_k))`, plus noise, quantised;
/// 2. `u_k = controller.update(y_k, reference(t_k))`, saturated and
///    quantised; the controller is told the result
///    ([`applied`](Controller::applied));
/// 3. record `(t_k, u_k, y_k)`;
/// 4. hold the previous input until `t_k + input_delay`, then `u_k` until
///    `t_{k+1}` (zero-order hold; the input before the first sample is 0).
///
/// The same controller object runs unchanged on the rig through
/// [`hw::run`](crate::hw::run), which follows the same order.
///
/// # Errors
///
/// Errors of [`SampledConfig::validate`]; [`Error::InvalidParameter`] named
/// `"x0"` for a non-finite initial state, `"period"` when the controller was
/// designed for another period ([`Controller::period`]), `"input"` for a
/// non-finite controller output or `"reference"` for a non-finite
/// reference, `"measurement"` for a non-finite measurement from the
/// sensor (with the value); [`Error::Overflow`] when the plant's state
/// stops being finite (it diverged).
///
/// # Examples
///
/// A first-order lag `x' = −x + u` under proportional control at 10 ms,
/// with the input limited to ±2:
///
/// ```
/// use ctrlab::{StateFeedback, StateSpace, sim::{SampledConfig, run_sampled}};
/// use ctrlab::nalgebra::{SVector, matrix, vector};
///
/// let plant = StateSpace::continuous(matrix![-1.0], matrix![1.0], matrix![1.0], matrix![0.0])?;
/// let control = StateFeedback::new(matrix![4.0], vector![5.0])?; // u = 5 r − 4 x
/// let config = SampledConfig { saturation: [2.0], ..SampledConfig::new(0.01, 5.0) };
/// let rec = run_sampled(plant, |x: &SVector<f64, 1>| *x, control, |_t| vector![1.0], vector![0.0], &config)?;
/// assert_eq!(rec.len(), 500);
/// assert_eq!(rec.channel("u")?[0], 2.0); // 5 asked, 2 applied
/// assert!((rec.channel("y")?[499] - 1.0).abs() < 1e-3); // settles at 5 / (1 + 4) = 1
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub fn run_sampled<const N: usize, const M: usize, const P: usize, const R: usize, D, S, C>(
    mut plant: D,
    mut sensor: S,
    mut controller: C,
    mut reference: impl FnMut(f64) -> SVector<f64, R>,
    x0: SVector<f64, N>,
    config: &SampledConfig<M, P>,
) -> Result<Recording, Error>
where
    D: Dynamics<N, M>,
    S: Sensor<N, P>,
    C: Controller<P, R, M>,
{
    let samples = config.validate()?;
    crate::error::check_finite("x0", &x0).map_err(|_| Error::InvalidParameter {
        name: "x0",
        value: x0
            .iter()
            .copied()
            .find(|v| !v.is_finite())
            .unwrap_or(f64::NAN),
        reason: "initial state must be finite",
    })?;
    let period = config.period;
    if let Some(p) = controller.period()
        && (p - period).abs() > 1e-9 * period
    {
        return Err(Error::InvalidParameter {
            name: "period",
            value: period,
            reason: "differs from the period the controller was designed for",
        });
    }
    let schema = config
        .schema
        .clone()
        .unwrap_or_else(Schema::numbered_const::<M, P>);
    let mut recording = Recording::with_capacity(schema, samples);
    let mut rng = Rng::new(config.seed);
    controller.reset();
    sensor.reset();

    let mut x = x0;
    let mut held = SVector::<f64, M>::zeros();
    for k in 0..samples {
        let t = k as f64 * period;
        let mut y = sensor.measure(t, &x);
        if let Some(&v) = y.iter().find(|v| !v.is_finite()) {
            return Err(Error::InvalidParameter {
                name: "measurement",
                value: v,
                reason: "the sensor's measurement must be finite",
            });
        }
        for i in 0..P {
            if config.noise[i] > 0.0 {
                y[i] += config.noise[i] * rng.gaussian();
            }
            y[i] = quantise(y[i], config.quantisation[i]);
        }
        let r = reference(t);
        if let Some(&v) = r.iter().find(|v| !v.is_finite()) {
            return Err(Error::InvalidParameter {
                name: "reference",
                value: v,
                reason: "the reference must be finite",
            });
        }
        let mut u = controller.update(&y, &r);
        for i in 0..M {
            if !u[i].is_finite() {
                return Err(Error::InvalidParameter {
                    name: "input",
                    value: u[i],
                    reason: "the controller's output must be finite",
                });
            }
            let limit = config.saturation[i];
            let q = config.input_quantisation[i];
            u[i] = quantise_within(u[i].clamp(-limit, limit), q, limit);
        }
        controller.applied(&u);
        recording.push_vectors(t, &u, &y)?;

        let delay = config.input_delay;
        integrate(&mut plant, &mut x, t, delay, &held, config.max_substep);
        held = u;
        integrate(
            &mut plant,
            &mut x,
            t + delay,
            period - delay,
            &held,
            config.max_substep,
        );
        if x.iter().any(|v| !v.is_finite()) {
            return Err(Error::Overflow {
                operation: "sampled-data simulation (the plant's state diverged)",
            });
        }
    }
    Ok(recording)
}

/// `v` on the grid of step `q` (`q round(v / q)`; `q = 0` for none). When
/// `v / q` overflows (a step of 1e-310) the grid is finer than f64 at `v`,
/// and `v` is on it.
fn quantise(v: f64, q: f64) -> f64 {
    let steps = (v / q).round();
    if q > 0.0 && steps.is_finite() {
        q * steps
    } else {
        v
    }
}

/// [`quantise`], one step back toward 0 when rounding steps past `limit`
/// (±1 in steps of 0.4 rounds 1 to 1.2, and applies 0.8). The product's own
/// rounding (0.1 × 3 = 0.30000000000000004 for a limit of 0.3) is not a step.
fn quantise_within(v: f64, q: f64, limit: f64) -> f64 {
    let steps = (v / q).round();
    if !(q > 0.0 && steps.is_finite()) {
        return v;
    }
    if (q * steps).abs() > limit * (1.0 + 1e-12) {
        q * (steps - steps.signum())
    } else {
        q * steps
    }
}

/// Integrates `plant` over `[t, t + span]` with the input `u` held, in equal
/// RK4 steps no longer than `max_step`, calling the mode hook first (the
/// plant sees the new input: a stuck cart may break away) and after each
/// step.
fn integrate<const N: usize, const M: usize, D: Dynamics<N, M>>(
    plant: &mut D,
    x: &mut SVector<f64, N>,
    t: f64,
    span: f64,
    u: &SVector<f64, M>,
    max_step: f64,
) {
    if span <= 0.0 {
        return;
    }
    // The tolerance keeps T / (T / 8) at 8 steps despite rounding.
    let steps = ((span / max_step) * (1.0 - 1e-12)).ceil().max(1.0) as usize;
    let h = span / steps as f64;
    plant.update_mode(t, x, u);
    for s in 0..steps {
        Rk4.step_mut(&*plant, t + s as f64 * h, h, x, u);
        plant.update_mode(t + (s + 1) as f64 * h, x, u);
    }
}
