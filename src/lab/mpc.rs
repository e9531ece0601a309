//! Constrained model-predictive control on the two-cart rig: a controller
//! that knows the drive's ±24 V, how fast it lets the drive change, and
//! where the travel limits are, designed on an identified model.
//!
//! [`design`] builds an [`Mpc`] on the carts' two measured positions
//! ([`lqi::position_model`]) with [`Tuning::LAB`]: the drive's range as a
//! hard limit, a hard rate limit of [`RATE_LIMIT`] per period, both carts
//! softly kept inside their travel limits, offset-free by integral action
//! (the carts' friction, a wrong motor gain), a 30-step plan. [`cases`] are the lab's: cart 2
//! to [`SETPOINT_MARGIN`] inside its travel limit (where a fixed gain
//! either crawls or overshoots into the stop), cart 1 to Table 6's 15 mm.
//! [`Figures`] are what a run shows against the limits; the step's own
//! figures and the prediction's agreement are [`lqi`]'s ([`lqi::Metrics`],
//! [`lqi::Comparison`]).
//!
//! # Examples
//!
//! Cart 2 to 5 mm inside its travel on the rig as the prediction knows it
//! (the nominal plant with Coulomb friction, the drive's 24 mV steps and
//! the encoders' counts):
//!
//! ```
//! use ctrlab::lab::{Calibration, Cart, MassSpring, lqi, mpc};
//! let calibration = Calibration::default();
//! let rig = lqi::predicted_rig(MassSpring::nominal(), [1.0, 2.0], &calibration, 0.002);
//! let model = lqi::position_model(&rig.truth, rig.period)?;
//! let (cart, setpoint) = mpc::cases(&calibration)[0];
//! assert!(cart == Cart::Two && (setpoint - 0.045).abs() < 1e-15);
//! let mut controller = mpc::design(&model, cart, &calibration)?;
//! let rec = lqi::predict(&rig, &mut controller, setpoint, 2.0)?;
//! let figures = mpc::Figures::of(&rec, &calibration)?;
//! assert!(figures.clearance[1] > 0.0); // never touched the limit
//! // The drive's 24 mV steps round the rate limit by half a step at most.
//! assert!(figures.peak_u <= 24.0 && figures.max_step_u <= mpc::RATE_LIMIT + 0.012 + 1e-9);
//! assert_eq!(controller.inner().stats().fallbacks(), 0);
//! # Ok::<(), ctrlab::Error>(())
//! ```

use std::time::Duration;

use crate::data::Recording;
use crate::design::SelectOutputs;
use crate::design::mpc::{Estimation, MPC_SOLVER, Mpc, MpcDesign, OutputLimit, QpSettings, Row};
use crate::error::Error;
use crate::lab::{self, Calibration, Cart, lqi, position_channel};
use crate::model::{Discrete, StateSpace};
use crate::nalgebra::{SMatrix, matrix, vector};

/// The controller on the rig's `[x1, v1, x2, v2]`: positions only.
///
/// # Examples
///
/// ```
/// use ctrlab::Controller;
/// use ctrlab::lab::{Calibration, Cart, MassSpring, lqi, mpc, protocol};
/// use ctrlab::nalgebra::vector;
/// # let model = lqi::position_model(&MassSpring::nominal(), protocol::PERIOD)?;
/// let mut c: mpc::PositionsMpc = mpc::design(&model, Cart::Two, &Calibration::default())?;
/// // Fed all four states, it reads only the positions: at rest on its
/// // setpoint it does not push, however fast the readings say the carts move.
/// let u = c.update(&vector![0.0, 5.0, 0.0, -5.0], &vector![0.0]);
/// assert!(u[0].abs() < 1e-6);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub type PositionsMpc = SelectOutputs<Mpc<4, 1, 2, 1>, 4, 2>;

/// Cart 2's case: its setpoint lies this far inside its travel limit, m.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::{Calibration, mpc::SETPOINT_MARGIN};
/// // With the default ±50 mm travel, cart 2 goes to 45 mm.
/// let limit = Calibration::default().travel_limits[1];
/// assert!((limit - SETPOINT_MARGIN - 0.045).abs() < 1e-15);
/// ```
pub const SETPOINT_MARGIN: f64 = 0.005;
/// Cart 1's case: Table 6's setpoint, m.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::{Calibration, mpc::{CART1_SETPOINT, Tuning}};
/// // 15 mm: inside cart 1's soft travel limit, which the MPC keeps 2 mm in.
/// let soft = Calibration::default().travel_limits[0] - Tuning::LAB.travel_margin;
/// assert!(CART1_SETPOINT == 0.015 && CART1_SETPOINT < soft);
/// ```
pub const CART1_SETPOINT: f64 = 0.015;
/// Largest change of drive from one period to the next, V (1 kV/s).
///
/// # Examples
///
/// ```
/// use ctrlab::lab::{mpc::RATE_LIMIT, protocol::PERIOD};
/// assert!((RATE_LIMIT / PERIOD - 1000.0).abs() < 1e-9); // V/s
/// // The full ±24 V swing takes 24 periods, 48 ms.
/// assert_eq!(48.0 / RATE_LIMIT, 24.0);
/// ```
pub const RATE_LIMIT: f64 = 2.0;

/// The lab MPC's horizon, weights, limits and estimator: [`Tuning::LAB`]
/// is what [`design`] uses; [`design_with`] takes another.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::mpc::Tuning;
/// let slower = Tuning { input_weight: 0.1, ..Tuning::LAB };
/// assert_eq!(slower.horizon, Tuning::LAB.horizon);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tuning {
    /// Steps planned.
    pub horizon: usize,
    /// Weight on the tracked cart's position error, 1/m².
    pub tracked_weight: f64,
    /// Weight on the other cart's deviation from where it rests at the
    /// target, 1/m²: damps the spring between them.
    pub other_weight: f64,
    /// Weight on the drive's deviation from what holds the target, 1/V².
    pub input_weight: f64,
    /// Weight on the drive's change per period, 1/V².
    pub rate_weight: f64,
    /// Integral action on the tracked position, 1/s: what walks a cart
    /// held by friction to its setpoint.
    pub integral_gain: f64,
    /// The error integrates only within this of the setpoint, m.
    pub integral_zone: f64,
    /// Largest change of drive per period, V.
    pub rate_limit: f64,
    /// The soft travel limits lie this far inside the calibration's, m.
    pub travel_margin: f64,
    /// Cost of a violated soft travel limit: per metre and per square
    /// metre (times ½) at each predicted step.
    pub travel_penalty: Row,
    /// Force noise on the input, V².
    pub input_noise: f64,
    /// The input disturbance's change per period, V²: how fast the
    /// estimate follows friction.
    pub disturbance_noise: f64,
    /// The other cart's reading's offset from the model, its change per
    /// period, m².
    pub output_disturbance_noise: f64,
    /// The QP solver's settings, which bound each tick's work
    /// ([`MPC_SOLVER`]: at most 200 ADMM iterations and 50 active-set
    /// solves).
    pub solver: QpSettings,
}

impl Tuning {
    /// The lab's: a 60 ms plan (longer than half the carts' slower mode's
    /// period, so a plan sees the overshoot it would cause), the tracked
    /// position weighted 10⁸ times the drive, the soft travel limits 2 mm
    /// inside the calibration's with a penalty far above what reaching the
    /// setpoint is worth, and the LQI's input noise. Offset-free by
    /// integral action (3 /s within 5 mm of the setpoint), not by
    /// disturbance estimates: a cart held by Coulomb friction is
    /// explained by a disturbance estimate as well as by a push that has
    /// not yet broken it free, so the estimate would stop the walk the
    /// integral makes (on the simulated rig with Coulomb friction, estimates
    /// left cart 1 3 counts short; integral action reaches the count).
    pub const LAB: Self = Self {
        horizon: 30,
        tracked_weight: 1e6,
        other_weight: 1e4,
        input_weight: 0.01,
        rate_weight: 0.01,
        integral_gain: 3.0,
        integral_zone: 0.005,
        rate_limit: RATE_LIMIT,
        travel_margin: 0.002,
        travel_penalty: Row::Soft {
            linear: 1e5,
            quadratic: 1e9,
        },
        input_noise: lqi::INPUT_NOISE,
        disturbance_noise: 0.0,
        output_disturbance_noise: 0.0,
        solver: MPC_SOLVER,
    };

    /// [`Tuning::LAB`] for a loop on the wall clock (the real card,
    /// `lab5 --real-time`): each solve also stops at [`TICK_TIME_LIMIT`], so
    /// no tick overruns the 2 ms period whatever the state (the iteration
    /// bounds alone allow 2 ms at horizon 40); a tick stopped there falls
    /// back as one out of iterations does, counted in
    /// [`MpcStats::time_limit`].
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::mpc::{TICK_TIME_LIMIT, Tuning};
    /// assert_eq!(Tuning::REAL_TIME.solver.time_limit, Some(TICK_TIME_LIMIT));
    /// assert_eq!(Tuning::LAB.solver.time_limit, None);
    /// ```
    ///
    /// [`MpcStats::time_limit`]: crate::design::mpc::MpcStats::time_limit
    pub const REAL_TIME: Self = Self {
        solver: QpSettings {
            time_limit: Some(TICK_TIME_LIMIT),
            ..MPC_SOLVER
        },
        ..Self::LAB
    };
}

/// The solver's wall-clock budget per tick on the real loop, 1 ms: half
/// the 2 ms period, so a tick never overruns it, and far above what the
/// lab's ticks need (at most about 0.1 ms at horizon 30 on a small
/// machine: the performance guide). A budget near what ticks need is
/// spent by preemption instead: under normal scheduling beside a build,
/// 100 µs made 230 of 317 ticks fall back. The clock is the wall clock,
/// so under SCHED_FIFO (`--rt-priority`) the budget is the tick's work.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::{mpc::TICK_TIME_LIMIT, protocol::PERIOD};
/// assert_eq!(2.0 * TICK_TIME_LIMIT.as_secs_f64(), PERIOD); // half a period
/// ```
pub const TICK_TIME_LIMIT: Duration = Duration::from_millis(1);

/// The lab's cases for `calibration`: cart 2 to [`SETPOINT_MARGIN`] inside
/// its travel limit, cart 1 to [`CART1_SETPOINT`] (m).
///
/// # Examples
///
/// ```
/// use ctrlab::lab::{Calibration, Cart, mpc};
/// let c = Calibration { travel_limits: [0.04, 0.03], ..Calibration::default() };
/// let [(cart2, two), (cart1, one)] = mpc::cases(&c);
/// assert_eq!((cart2, cart1, one), (Cart::Two, Cart::One, 0.015));
/// assert!((two - 0.025).abs() < 1e-15);
/// ```
pub fn cases(calibration: &Calibration) -> [(Cart, f64); 2] {
    [
        (Cart::Two, calibration.travel_limits[1] - SETPOINT_MARGIN),
        (Cart::One, CART1_SETPOINT),
    ]
}

/// The MPC for `cart` on `model` (the rig's positions model, discrete at
/// the loop's period), with `calibration`'s drive range, encoder count and
/// travel limits.
///
/// # Errors
///
/// As [`Mpc::new`]: a model the design cannot use (uncontrollable, a zero
/// at `z = 1`), a calibration whose travel limits leave no room inside
/// the tuning's margin ([`Error::InvalidParameter`] `"travel_limits"`).
///
/// # Examples
///
/// ```
/// use ctrlab::Controller;
/// use ctrlab::lab::{Calibration, Cart, MassSpring, lqi, mpc, protocol};
/// use ctrlab::nalgebra::vector;
/// let model = lqi::position_model(&MassSpring::nominal(), protocol::PERIOD)?;
/// let mut c = mpc::design(&model, Cart::Two, &Calibration::default())?;
/// // From rest toward 45 mm, the first tick's drive is rate-limited.
/// let u = c.update(&vector![0.0, 0.0, 0.0, 0.0], &vector![0.045]);
/// assert!(u[0] > 0.0 && u[0] <= mpc::RATE_LIMIT + 1e-9);
/// // Travel limits inside the 2 mm margin leave the MPC no room.
/// let tight = Calibration { travel_limits: [0.001, 0.05], ..Calibration::default() };
/// assert!(mpc::design(&model, Cart::Two, &tight).is_err());
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn design(
    model: &StateSpace<4, 1, 2, Discrete>,
    cart: Cart,
    calibration: &Calibration,
) -> Result<PositionsMpc, Error> {
    design_with(model, cart, calibration, &Tuning::LAB)
}

/// [`design`] with another [`Tuning`].
///
/// # Errors
///
/// As [`design`].
///
/// # Examples
///
/// ```
/// use ctrlab::Controller;
/// use ctrlab::lab::{Calibration, Cart, MassSpring, lqi, mpc, protocol};
/// use ctrlab::nalgebra::vector;
/// # let model = lqi::position_model(&MassSpring::nominal(), protocol::PERIOD)?;
/// let gentle = mpc::Tuning { rate_limit: 0.5, ..mpc::Tuning::LAB };
/// let mut c = mpc::design_with(&model, Cart::Two, &Calibration::default(), &gentle)?;
/// let u = c.update(&vector![0.0, 0.0, 0.0, 0.0], &vector![0.045]);
/// assert!(u[0] > 0.0 && u[0] <= 0.5 + 1e-9); // V per period
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn design_with(
    model: &StateSpace<4, 1, 2, Discrete>,
    cart: Cart,
    calibration: &Calibration,
    tuning: &Tuning,
) -> Result<PositionsMpc, Error> {
    let t = tuning;
    let (tracked, other) = (cart.state_index(), 2 - cart.state_index());
    let mut q = SMatrix::<f64, 4, 4>::zeros();
    q[(tracked, tracked)] = t.tracked_weight;
    q[(other, other)] = t.other_weight;
    let volts = calibration.volts_full_scale;
    let mut d = MpcDesign::new(t.horizon, q, matrix![t.input_weight]);
    d.rate_weight = matrix![t.rate_weight];
    d.integral_gain = t.integral_gain;
    d.integral_zone = t.integral_zone;
    d.input_min = vector![-volts];
    d.input_max = vector![volts];
    d.rate_max = vector![t.rate_limit];
    d.solver = t.solver;
    for (i, limit) in calibration.travel_limits.iter().enumerate() {
        let soft = limit - t.travel_margin;
        if soft.is_nan() || soft <= 0.0 {
            return Err(Error::InvalidParameter {
                name: "travel_limits",
                value: *limit,
                reason: "the MPC keeps the carts its travel margin inside their travel limits",
            });
        }
        let mut output = SMatrix::<f64, 1, 4>::zeros();
        output[2 * i] = 1.0;
        d.output_limits.push(OutputLimit {
            output,
            min: -soft,
            max: soft,
            kind: t.travel_penalty,
        });
    }
    let count = calibration.metres_per_count;
    let estimation = Estimation {
        input_noise: matrix![t.input_noise],
        disturbance_noise: matrix![t.disturbance_noise],
        output_disturbance_noise: t.output_disturbance_noise,
        measurement_noise: SMatrix::<f64, 2, 2>::identity() * (count * count / 12.0),
    };
    // The tracked cart's position among the two measured.
    let selection = cart.selection() * lab::position_output_matrix().transpose();
    let mpc = Mpc::new(model, &selection, &d, &estimation)?;
    SelectOutputs::new(mpc, lab::position_output_matrix())
}

/// What a run shows against the rig's limits.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::{Calibration, mpc::Figures};
/// use ctrlab::{Recording, lab};
/// let mut rec = Recording::new(lab::schema());
/// rec.push(0.000, &[0.0], &[0.0, 0.0, 0.0, 0.0])?;
/// rec.push(0.002, &[2.0], &[0.001, 0.0, 0.046, 0.0])?;
/// let f = Figures::of(&rec, &Calibration::default())?;
/// assert!((f.clearance[1] - 0.004).abs() < 1e-12); // 46 mm of ±50 mm
/// assert_eq!((f.peak_u, f.max_step_u, f.at_limit), (2.0, 2.0, 0));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Figures {
    /// Each cart's closest approach to its travel limit, m (negative:
    /// past it).
    pub clearance: [f64; 2],
    /// Largest |u|, V.
    pub peak_u: f64,
    /// Largest change of the applied drive between samples, V.
    pub max_step_u: f64,
    /// Samples with the drive at its full scale.
    pub at_limit: usize,
}

impl Figures {
    /// The figures of `rec` (the lab's schema) against `calibration`.
    ///
    /// # Errors
    ///
    /// [`Error::Channel`] for a channel missing from `rec`.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::{Calibration, mpc::Figures};
    /// use ctrlab::{Recording, lab};
    /// let mut rec = Recording::new(lab::schema());
    /// rec.push(0.000, &[24.0], &[0.0, 0.0, 0.0, 0.0])?;
    /// rec.push(0.002, &[24.0], &[0.0, 0.0, -0.052, 0.0])?;
    /// let f = Figures::of(&rec, &Calibration::default())?;
    /// assert!((f.clearance[1] + 0.002).abs() < 1e-12); // 2 mm past cart 2's limit
    /// assert_eq!((f.at_limit, f.max_step_u), (2, 0.0)); // held at full scale
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn of(rec: &Recording, calibration: &Calibration) -> Result<Self, Error> {
        let mut clearance = [f64::INFINITY; 2];
        for (i, cart) in [Cart::One, Cart::Two].into_iter().enumerate() {
            let peak = rec
                .channel(position_channel(cart))?
                .iter()
                .fold(0.0f64, |m, x| m.max(x.abs()));
            clearance[i] = calibration.travel_limits[i] - peak;
        }
        let u = rec.channel("u")?;
        let volts = calibration.volts_full_scale;
        Ok(Self {
            clearance,
            peak_u: u.iter().fold(0.0, |m: f64, v| m.max(v.abs())),
            max_step_u: u
                .windows(2)
                .fold(0.0, |m: f64, w| m.max((w[1] - w[0]).abs())),
            at_limit: u.iter().filter(|v| v.abs() >= volts).count(),
        })
    }
}
