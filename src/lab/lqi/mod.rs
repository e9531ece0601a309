//! LQI with a Kalman filter on the rig's two measured positions, designed
//! to a stated step-response spec on an identified model: the controller
//! ([`positions_lqi`], [`PositionsLqi`]), the rig as the prediction knows it
//! ([`predicted_rig`]) and the prediction ([`predict`]), the spec and a
//! run's figures against it ([`Spec`], [`Metrics`]), the bounded search over
//! one weight that picks the design ([`design_search`]), and what tells a
//! prediction from the rig's run ([`Comparison`]).
//!
//! The design the lab's Design section makes and its tests check: cart 2 to
//! Table 5's 30 mm and cart 1 to Table 6's 15 mm ([`CASES`]).
//!
//! # Examples
//!
//! The tests' and benches' controller: LQI on cart 2 of the nominal plant.
//!
//! ```
//! use ctrlab::Controller;
//! use ctrlab::lab::{Cart, MassSpring, lqi};
//! use ctrlab::nalgebra::vector;
//!
//! let model = lqi::position_model(&MassSpring::nominal(), 0.002)?;
//! let design = lqi::positions_lqi(&model, Cart::Two, &lqi::weights(Cart::Two, 1e7), 9.765625e-6)?;
//! assert!(design.poles.iter().all(|z| z.norm() < 1.0));
//! let mut ctrl = design.controller;
//! // Held at rest 30 mm short of the setpoint: the integrator drives cart 2
//! // forward.
//! let mut u = vector![0.0];
//! for _ in 0..10 {
//!     u = ctrl.update(&vector![0.0, 0.0, 0.0, 0.0], &vector![0.030]);
//!     ctrl.applied(&u);
//! }
//! assert!(u[0] > 0.0);
//! # Ok::<(), ctrlab::Error>(())
//! ```

mod compare;
mod search;
mod spec;

use crate::nalgebra::{Complex, SMatrix, SVector, matrix, vector};

use crate::data::Recording;
use crate::design::{
    AntiWindup, Controller, EstimatorForm, Observer, ObserverController, SelectOutputs, dlqe, dlqi,
};
use crate::discretize::Discretization;
use crate::error::Error;
use crate::lab::{
    self, Calibration, CardSettings, Cart, Friction, MassSpring, SimulatedRig, Unmodelled,
};
use crate::model::{Discrete, StateSpace};
use crate::sim::run_sampled;

pub use compare::{
    Comparison, IDENT_TOLERANCE, IntegratorWalk, KnownDifferences, REST_TAIL, Rest, RestKind,
    Transient,
};
pub use search::{Candidate, Choice, Design, design_search, rho_grid};
pub use spec::{Item, Metrics, Spec, Step, Verdict};

/// The controller on the rig's `[x1, v1, x2, v2]`: positions only.
///
/// # Examples
///
/// ```
/// use ctrlab::Controller;
/// use ctrlab::lab::{Cart, MassSpring, lqi};
/// use ctrlab::nalgebra::vector;
/// # let model = lqi::position_model(&MassSpring::nominal(), 0.002)?;
/// let mut a: lqi::PositionsLqi = lqi::positions_lqi(&model, Cart::Two, &lqi::weights(Cart::Two, 1e7), 1e-5)?.controller;
/// let mut b = a.clone();
/// // The speeds it is handed are ignored: its filter estimates them.
/// let ua = a.update(&vector![0.001, 0.0, 0.002, 0.0], &vector![0.030]);
/// let ub = b.update(&vector![0.001, 9.0, 0.002, -9.0], &vector![0.030]);
/// assert_eq!(ua, ub);
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub type PositionsLqi = SelectOutputs<ObserverController<4, 1, 2, 1>, 4, 2>;

/// A designed controller with its LQI gain and the closed loop's poles.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::{Cart, MassSpring, lqi};
/// let model = lqi::position_model(&MassSpring::nominal(), 0.002)?;
/// let design: lqi::Lqi = lqi::positions_lqi(&model, Cart::Two, &lqi::weights(Cart::Two, 1e7), 1e-5)?;
/// assert!(design.poles.iter().all(|z| z.norm() < 1.0)); // stable on the model
/// // Cart 2 ahead of its setpoint is pushed back: a positive gain on x2, V/m.
/// assert!(design.gain[(0, 2)] > 0.0);
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct Lqi {
    /// The controller, ready for `hw::run` or the sampled-data simulator.
    pub controller: PositionsLqi,
    /// `[K_x K_z]` on `[x1, v1, x2, v2, z]`: V/m, V·s/m, V/m, V·s/m,
    /// V/(m·s).
    pub gain: SMatrix<f64, 1, 5>,
    /// The closed loop's poles on the model (z-plane).
    pub poles: SVector<Complex<f64>, 5>,
}

/// The Kalman filter's process noise: a force on cart 2 through the
/// input, variance in V².
///
/// # Examples
///
/// ```
/// use ctrlab::lab::{Calibration, lqi::INPUT_NOISE, mpc::Tuning};
/// // About 3.2 V RMS of unknown push, well inside the ±24 V drive.
/// assert!(INPUT_NOISE.sqrt() < Calibration::default().volts_full_scale / 5.0);
/// assert_eq!(Tuning::LAB.input_noise, INPUT_NOISE); // the MPC's estimator too
/// ```
pub const INPUT_NOISE: f64 = 10.0;
/// Back-calculation past the drive's 24 mV step (see `AntiWindup`).
///
/// # Examples
///
/// ```
/// use ctrlab::design::AntiWindup;
/// use ctrlab::lab::{Calibration, lqi::ANTI_WINDUP};
/// let AntiWindup::BackCalculation { deadband, .. } = ANTI_WINDUP else { panic!() };
/// // The drive's step: 0.1 % of its ±24 V full scale.
/// assert!((deadband - 0.001 * Calibration::default().volts_full_scale).abs() < 1e-15);
/// ```
pub const ANTI_WINDUP: AntiWindup = AntiWindup::BackCalculation {
    tracking: 0.01,
    deadband: 0.024,
};
/// Weight on the integrated error relative to the tracked position,
/// 1/s² (an integral time of about 32 ms).
///
/// # Examples
///
/// ```
/// use ctrlab::lab::{Cart, lqi};
/// assert!((1.0 / lqi::INTEGRAL_RATIO.sqrt() - 0.032).abs() < 0.001); // s
/// assert_eq!(lqi::weights(Cart::Two, 1e7)[(4, 4)], 1e7 * lqi::INTEGRAL_RATIO);
/// ```
pub const INTEGRAL_RATIO: f64 = 1e3;
/// The drive's latch-to-PWM delay, s: its data sheet, not identified.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::{Calibration, MassSpring, lqi, protocol::PERIOD};
/// assert!((lqi::DRIVE_DELAY / PERIOD - 0.075).abs() < 1e-12); // 7.5 % of a period
/// let rig = lqi::predicted_rig(MassSpring::nominal(), [0.0; 2], &Calibration::default(), PERIOD);
/// assert_eq!(rig.card.pwm_delay, lqi::DRIVE_DELAY);
/// ```
pub const DRIVE_DELAY: f64 = 0.15e-3;
/// Length of each predicted and measured step, s.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::{lqi::DURATION, protocol::{PERIOD, STEP_DURATION}};
/// assert_eq!(DURATION, STEP_DURATION); // as long as a row of Tables 5 and 6
/// assert!((DURATION / PERIOD - 1500.0).abs() < 1e-9);
/// ```
pub const DURATION: f64 = 3.0;
/// The lab's design cases: cart 2 to Table 5's 30 mm, cart 1 to Table 6's
/// 15 mm (m).
///
/// # Examples
///
/// ```
/// use ctrlab::lab::{lqi::CASES, tables::{TABLE5, TABLE6}};
/// for ((cart, setpoint), table) in CASES.into_iter().zip([TABLE5, TABLE6]) {
///     assert_eq!(cart, table.cart);
///     assert!((setpoint * 1e3 - table.setpoint_mm).abs() < 1e-12); // m against mm
/// }
/// ```
pub const CASES: [(Cart, f64); 2] = [(Cart::Two, 0.030), (Cart::One, 0.015)];
/// The larger cart-1 setpoint the choice of 15 mm is weighed against, m.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::{Calibration, ident_input::TRAVEL_FRACTION, lqi::{CART1_ALTERNATIVE, CASES}};
/// assert!(CART1_ALTERNATIVE > CASES[1].1); // 20 mm against 15 mm
/// // Still a setpoint the lab accepts: within 60 % of cart 1's travel.
/// assert!(CART1_ALTERNATIVE <= TRAVEL_FRACTION * Calibration::default().travel_limits[0]);
/// ```
pub const CART1_ALTERNATIVE: f64 = 0.020;

/// The model the loop sees every `period` s (ZOH), outputs both positions
/// `[x1, x2]` (m).
///
/// # Errors
///
/// An invalid plant or period.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::{MassSpring, lqi};
/// let model = lqi::position_model(&MassSpring::nominal(), 0.002)?;
/// assert_eq!(model.c()[(1, 2)], 1.0);
/// assert!(lqi::position_model(&MassSpring::nominal(), -1.0).is_err());
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub fn position_model(
    plant: &MassSpring,
    period: f64,
) -> Result<StateSpace<4, 1, 2, Discrete>, Error> {
    plant
        .state_space(Cart::Two)?
        .with_output(lab::position_output_matrix(), matrix![0.0; 0.0])?
        .discretize(period, Discretization::Zoh)
}

/// The LQI weights for `cart`: `rho` on its position (1/m²), `rho ·`
/// [`INTEGRAL_RATIO`] on the integrated error (1/(m·s)²), nothing on the
/// rest; R = 1/V².
///
/// # Examples
///
/// ```
/// use ctrlab::lab::{Cart, lqi};
/// let q = lqi::weights(Cart::One, 1e6);
/// assert_eq!((q[(0, 0)], q[(4, 4)], q[(2, 2)]), (1e6, 1e9, 0.0));
/// ```
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
///
/// # Errors
///
/// As `dlqi` and `dlqe` (weights that are not positive semidefinite, a
/// non-positive `metres_per_count`: `R` not positive definite).
///
/// # Examples
///
/// ```
/// use ctrlab::lab::{Cart, MassSpring, lqi};
/// let model = lqi::position_model(&MassSpring::nominal(), 0.002)?;
/// let q = lqi::weights(Cart::Two, 1e7);
/// assert!(lqi::positions_lqi(&model, Cart::Two, &q, 1e-5).is_ok());
/// assert!(lqi::positions_lqi(&model, Cart::Two, &q, 0.0).is_err());
/// # Ok::<(), ctrlab::Error>(())
/// ```
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
        poles: lqi.poles,
    })
}

/// The rig as the prediction knows it: the identified plant `model` and
/// Coulomb friction `coulomb` (N; no stiction beyond it), the drive's
/// data-sheet delay [`DRIVE_DELAY`], the encoders' counts without noise;
/// the drive (±full scale in 0.1 % steps), encoder resolution and travel
/// limits are `calibration`'s, known without identifying anything, and the
/// loop runs every `period` s.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::{Calibration, MassSpring, lqi};
/// let rig = lqi::predicted_rig(MassSpring::nominal(), [1.0, 2.0], &Calibration::default(), 0.002);
/// assert_eq!((rig.friction.stiction, rig.card.encoder_noise), ([1.0, 2.0], 0.0));
/// assert_eq!(rig.calibration, Calibration::default());
/// ```
pub fn predicted_rig(
    model: MassSpring,
    coulomb: [f64; 2],
    calibration: &Calibration,
    period: f64,
) -> SimulatedRig {
    let defaults = SimulatedRig::default();
    SimulatedRig {
        truth: model,
        friction: Friction::coulomb(coulomb),
        // The model's prediction: nothing the model lacks.
        unmodelled: Unmodelled::NONE,
        card: CardSettings {
            pwm_delay: DRIVE_DELAY,
            encoder_noise: 0.0,
            ..defaults.card
        },
        calibration: *calibration,
        period,
        ..defaults
    }
}

/// `controller` to `setpoint` (m) from rest for `duration` s on `rig`'s
/// sampled-data simulation: its plant, sensor and drive.
///
/// # Errors
///
/// As [`run_sampled`]: an invalid rig, period or duration, a diverging
/// simulation.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::LabGains;
/// use ctrlab::lab::{Cart, SimulatedRig, lqi};
/// let law = LabGains::new([0.0, 0.0, 1.0, 0.0], Cart::Two).state_feedback()?;
/// let rec = lqi::predict(&SimulatedRig::default(), law, 0.030, 1.0)?;
/// assert_eq!(rec.len(), 500);
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub fn predict<C: Controller<4, 1, 1>>(
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

/// What holding cart 1 at a setpoint takes on a model at rest: the force
/// `k1 r` through the spring `k2`, so cart 2 sits at `r (1 + k1 / k2)`.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::{MassSpring, lqi::Hold};
/// let h = Hold::of(&MassSpring::nominal(), 0.015);
/// assert!((h.volts - 15.0).abs() < 1e-12 && (h.x2 - 0.030).abs() < 1e-15);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hold {
    /// The drive it takes, `k1 r / K`, V.
    pub volts: f64,
    /// Where cart 2 sits, m.
    pub x2: f64,
}

impl Hold {
    /// Cart 1 held at `r` (m) on `model`.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::{MassSpring, lqi::Hold};
    /// // The fixture's identified rig: k1 = k2 = 950 N/m, K = 8.5 N/V.
    /// let rig = MassSpring { k1: 950.0, k2: 950.0, gain: 8.5, ..MassSpring::nominal() };
    /// let h = Hold::of(&rig, 0.015);
    /// assert!((h.volts - 950.0 * 0.015 / 8.5).abs() < 1e-12); // about 1.7 V
    /// assert!((h.x2 - 0.030).abs() < 1e-15); // equal springs: twice cart 1's 15 mm
    /// ```
    pub fn of(model: &MassSpring, r: f64) -> Self {
        Self {
            volts: model.k1 * r / model.gain,
            x2: r * (1.0 + model.k1 / model.k2),
        }
    }
}
