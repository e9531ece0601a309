//! LQI with a Kalman filter on the rig's two measured positions, designed
//! to a stated step-response spec on a model: the controller, the spec and
//! its checks, the prediction (the sampled-data simulator with the rig's
//! drive, delay, encoders and Coulomb friction) and the bounded search over
//! one weight that picks the design. Shared by `lab5`'s Design section and
//! the tests (`#[path]`-included, so each stays a single `cargo run`).
#![allow(dead_code)]

use ctrlab::design::{
    AntiWindup, EstimatorForm, Observer, ObserverController, SelectOutputs, dlqe, dlqi,
};
use ctrlab::lab::{self, Cart, MassSpring, SimulatedRig};
use ctrlab::nalgebra::{SMatrix, SVector, matrix, vector};
use ctrlab::sim::run_sampled;
use ctrlab::{Discrete, Discretization, Error, Recording, StateSpace, StepInfoOptions, step_info};

/// The controller on the rig's `[x1, v1, x2, v2]`: positions only.
pub type PositionsLqi = SelectOutputs<ObserverController<4, 1, 2, 1>, 4, 2>;

/// A designed controller with its LQI gain `[K_x K_z]` (V/m, V·s/m, V/(m·s))
/// and the closed loop's poles on the model (z-plane).
pub struct Lqi {
    pub controller: PositionsLqi,
    pub gain: SMatrix<f64, 1, 5>,
    pub poles: [ctrlab::nalgebra::Complex<f64>; 5],
}

/// The Kalman filter's process noise: a force on cart 2 through the
/// input, variance in V².
pub const INPUT_NOISE: f64 = 10.0;
/// Back-calculation past the drive's 24 mV step (see `AntiWindup`).
pub const ANTI_WINDUP: AntiWindup = AntiWindup::BackCalculation {
    tracking: 0.01,
    deadband: 0.024,
};
/// Weight on the integrated error relative to the tracked position,
/// 1/s² (an integral time of about 32 ms).
pub const INTEGRAL_RATIO: f64 = 1e3;
/// The drive's latch-to-PWM delay, s: its data sheet, not identified.
pub const DRIVE_DELAY: f64 = 0.15e-3;
/// Length of each predicted and measured step, s.
pub const DURATION: f64 = 3.0;

/// The model the 2 ms loop sees, outputs both positions `[x1, x2]`.
pub fn position_model(
    plant: &MassSpring,
    period: f64,
) -> Result<StateSpace<4, 1, 2, Discrete>, Error> {
    plant
        .state_space(Cart::Two)?
        .with_output(lab::position_output_matrix(), matrix![0.0; 0.0])?
        .discretize(period, Discretization::Zoh)
}

/// The LQI weights for `cart`: `rho` on its position (1/m²), `rho ·
/// INTEGRAL_RATIO` on the integrated error, nothing on the rest; R = 1/V².
pub fn weights(cart: Cart, rho: f64) -> SMatrix<f64, 5, 5> {
    let mut q = SMatrix::<f64, 5, 5>::zeros();
    q[(cart.state_index(), cart.state_index())] = rho;
    q[(4, 4)] = rho * INTEGRAL_RATIO;
    q
}

/// LQI on `cart`'s measured position with weights `q` (R = 1), a
/// current-form Kalman filter on both positions (force noise
/// [`INPUT_NOISE`], each position read to a count of `metres_per_count`),
/// [`ANTI_WINDUP`]; it uses only `[x1, x2]` of the rig's measurements.
pub fn positions_lqi(
    model: &StateSpace<4, 1, 2, Discrete>,
    cart: Cart,
    q: &SMatrix<f64, 5, 5>,
    metres_per_count: f64,
) -> Result<Lqi, Error> {
    // Integrate the tracked cart's position, one of the two measured.
    let h = cart.selection() * lab::position_output_matrix().transpose();
    let tracked = model.with_output(h * model.c(), matrix![0.0])?;
    let lqi = dlqi(&tracked, q, &matrix![1.0])?;
    let rn = SMatrix::<f64, 2, 2>::identity() * (metres_per_count * metres_per_count / 12.0);
    let kf = dlqe(model, model.b(), &matrix![INPUT_NOISE], &rn)?;
    let observer = Observer::new(model, kf.gain, EstimatorForm::Current)?;
    let controller = ObserverController::new(observer, &lqi.gain, h, ANTI_WINDUP)?;
    Ok(Lqi {
        controller: SelectOutputs::new(controller, lab::position_output_matrix())?,
        gain: lqi.gain,
        poles: lqi.poles.into(),
    })
}

/// The rig as the prediction knows it: the identified plant and Coulomb
/// friction (no stiction beyond it), the drive's data-sheet delay
/// [`DRIVE_DELAY`], the encoders' counts without noise; the drive (±supply
/// in 0.1 % steps), encoder resolution and period are `calibration`'s,
/// known without identifying anything.
pub fn predicted_rig(
    model: MassSpring,
    coulomb: [f64; 2],
    calibration: &SimulatedRig,
) -> SimulatedRig {
    SimulatedRig {
        truth: model,
        coulomb_friction: coulomb,
        stiction: coulomb,
        pwm_delay: DRIVE_DELAY,
        encoder_noise: 0.0,
        ..calibration.clone()
    }
}

/// `controller` to `setpoint` (m) from rest for `duration` s on `rig`'s
/// sampled-data simulation: its plant, sensor and drive.
pub fn predict<C: ctrlab::Controller<4, 1, 1>>(
    rig: &SimulatedRig,
    controller: C,
    setpoint: f64,
    duration: f64,
) -> Result<Recording, Error> {
    run_sampled(
        rig.plant(),
        rig.sensor(),
        controller,
        |_| vector![setpoint],
        SVector::zeros(),
        &rig.sampled_config(duration),
    )
}

/// The spec of a step: overshoot, 2 % settling time, steady-state error
/// and drive voltage.
#[derive(Debug, Clone, Copy)]
pub struct Spec {
    pub cart: Cart,
    /// m.
    pub setpoint: f64,
    /// %.
    pub overshoot: f64,
    /// s.
    pub settling: f64,
    /// Encoder counts.
    pub error_counts: f64,
    /// V: the drive's range, never clipped.
    pub volts: f64,
}

impl Spec {
    /// The spec for `cart` to `setpoint` (m): overshoot ≤ 5 %,
    /// settling ≤ 0.5 s, within a count, |u| ≤ 24 V.
    pub fn new(cart: Cart, setpoint: f64) -> Self {
        Self {
            cart,
            setpoint,
            overshoot: 5.0,
            settling: 0.5,
            error_counts: 1.0,
            volts: 24.0,
        }
    }
}

/// A step's figures, from [`step_info`] (2 % band, 10–90 % rise, y∞ the
/// mean of the last 5 %).
#[derive(Debug, Clone, Copy)]
pub struct Step {
    /// 10–90 % rise time, s.
    pub rise: f64,
    /// %, relative to y∞.
    pub overshoot: f64,
    /// 2 % band, s.
    pub settling: f64,
    /// setpoint − y∞, mm.
    pub error_mm: f64,
    /// The same in encoder counts.
    pub error_counts: f64,
}

/// A run's figures against the spec.
#[derive(Debug, Clone)]
pub struct Metrics {
    /// The step's figures, or why there are none (not settled, …).
    pub step: Result<Step, String>,
    /// Largest |u|, V.
    pub peak_u: f64,
    /// Samples with the drive at its limit.
    pub clipped: usize,
}

/// Each spec item, passed or not: overshoot, settling, error, voltage.
pub type Verdict = [bool; 4];

impl Metrics {
    /// The figures of `rec` for `spec`, counts of `metres_per_count`.
    ///
    /// # Errors
    ///
    /// A channel missing from `rec`.
    pub fn of(rec: &Recording, spec: &Spec, metres_per_count: f64) -> Result<Self, Error> {
        let y: Vec<f64> = rec
            .channel(tracked(spec.cart))?
            .iter()
            .map(|v| v * 1e3)
            .collect();
        let options = StepInfoOptions {
            reference: Some(spec.setpoint * 1e3),
            ..Default::default()
        };
        let step = step_info(rec.time(), &y, &options)
            .map(|info| {
                let error_mm = info.steady_state_error.unwrap_or(f64::NAN);
                Step {
                    rise: info.rise_time,
                    overshoot: info.overshoot,
                    settling: info.settling_time,
                    error_mm,
                    error_counts: error_mm * 1e-3 / metres_per_count,
                }
            })
            .map_err(|e| match e {
                Error::NotSettled { .. } => "not settled".to_string(),
                other => other.to_string(),
            });
        let u = rec.channel("u")?;
        Ok(Self {
            step,
            peak_u: u.iter().fold(0.0, |m: f64, v| m.max(v.abs())),
            clipped: u.iter().filter(|v| v.abs() >= spec.volts).count(),
        })
    }

    pub fn verdict(&self, spec: &Spec) -> Verdict {
        let volts = self.clipped == 0 && self.peak_u <= spec.volts;
        match &self.step {
            Ok(s) => [
                s.overshoot <= spec.overshoot,
                s.settling <= spec.settling,
                s.error_counts.abs() <= spec.error_counts,
                volts,
            ],
            Err(_) => [false, false, false, volts],
        }
    }

    pub fn passes(&self, spec: &Spec) -> bool {
        self.verdict(spec).iter().all(|&ok| ok)
    }

    /// The smallest relative margin to the spec of each item (negative:
    /// out of spec; −∞ without step figures): `1 − figure / limit`.
    pub fn margin(&self, spec: &Spec) -> f64 {
        self.step.as_ref().map_or(f64::NEG_INFINITY, |s| {
            (1.0 - s.overshoot / spec.overshoot)
                .min(1.0 - s.settling / spec.settling)
                .min(1.0 - s.error_counts.abs() / spec.error_counts)
                .min(1.0 - self.peak_u / spec.volts)
        })
    }
}

/// The recording's channel of `cart`'s position.
pub fn tracked(cart: Cart) -> &'static str {
    match cart {
        Cart::One => "x1",
        Cart::Two => "x2",
    }
}

/// The weights searched: ρ = 10^4 … 10^10 in quarter decades.
pub fn rho_grid() -> impl Iterator<Item = f64> {
    (0..=24).map(|k| 10f64.powf(4.0 + 0.25 * f64::from(k)))
}

/// One weight of the search and its predicted step (`None`: no design, or
/// the prediction diverged).
pub struct Candidate {
    pub rho: f64,
    pub metrics: Option<Metrics>,
}

impl Candidate {
    pub fn passes(&self, spec: &Spec) -> bool {
        self.metrics.as_ref().is_some_and(|m| m.passes(spec))
    }
}

/// How the weight was chosen.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Choice {
    /// Its prediction and both neighbours' on the grid meet the spec.
    Robust,
    /// Its prediction meets the spec, a neighbour's does not.
    Isolated,
    /// No weight's prediction meets the spec: the best margin.
    NoneMeets,
}

/// The design for a spec on an identified model: the chosen weight and
/// controller, its predicted step, and the whole search.
pub struct Design {
    pub spec: Spec,
    pub rho: f64,
    pub q: SMatrix<f64, 5, 5>,
    pub lqi: Lqi,
    pub choice: Choice,
    pub predicted: Recording,
    pub metrics: Metrics,
    pub candidates: Vec<Candidate>,
}

/// Designs LQI + Kalman filter for `spec` on `model` (with Coulomb friction
/// `coulomb`, N) by a bounded search over ρ ([`rho_grid`], [`weights`]):
/// each weight's step is predicted on [`predicted_rig`]; the choice is the
/// largest [`Metrics::margin`] among the weights whose prediction meets
/// the spec and whose grid neighbours' do too (friction makes the response
/// jump with the weight, so a lone pass may be luck, and a neighbour is
/// what a 1.8-fold error in the identified gain would give); failing
/// those, among the weights that meet it; failing those, among all.
pub fn design(
    model: &MassSpring,
    coulomb: [f64; 2],
    calibration: &SimulatedRig,
    spec: Spec,
) -> Result<Design, Error> {
    let rig = predicted_rig(*model, coulomb, calibration);
    let discrete = position_model(model, rig.period)?;
    let count = rig.metres_per_count();
    let candidates: Vec<Candidate> = rho_grid()
        .map(|rho| Candidate {
            rho,
            metrics: positions_lqi(&discrete, spec.cart, &weights(spec.cart, rho), count)
                .and_then(|lqi| predict(&rig, lqi.controller, spec.setpoint, DURATION))
                .and_then(|rec| Metrics::of(&rec, &spec, count))
                .ok(),
        })
        .collect();
    let passes = |i: usize| candidates.get(i).is_some_and(|c| c.passes(&spec));
    let margin = |i: &usize| {
        candidates[*i]
            .metrics
            .as_ref()
            .map_or(f64::NEG_INFINITY, |m| m.margin(&spec))
    };
    let best = |filter: &dyn Fn(usize) -> bool| {
        (0..candidates.len())
            .filter(|&i| filter(i) && margin(&i) > f64::NEG_INFINITY)
            .max_by(|a, b| margin(a).total_cmp(&margin(b)))
    };
    let (chosen, choice) = match best(&|i| i > 0 && passes(i - 1) && passes(i) && passes(i + 1)) {
        Some(i) => (i, Choice::Robust),
        None => match best(&passes) {
            Some(i) => (i, Choice::Isolated),
            None => (
                best(&|_| true).ok_or(Error::NoConvergence {
                    operation: "LQI design: no weight gives a settled prediction",
                    iterations: candidates.len(),
                })?,
                Choice::NoneMeets,
            ),
        },
    };
    let rho = candidates[chosen].rho;
    let q = weights(spec.cart, rho);
    let lqi = positions_lqi(&discrete, spec.cart, &q, count)?;
    let predicted = predict(&rig, lqi.controller, spec.setpoint, DURATION)?;
    let metrics = Metrics::of(&predicted, &spec, count)?;
    Ok(Design {
        spec,
        rho,
        q,
        lqi,
        choice,
        predicted,
        metrics,
        candidates,
    })
}
