//! Constrained linear model-predictive control: [`Mpc`], a
//! [`Controller`](crate::Controller) that plans the inputs over a horizon
//! every period under hard input and rate limits and soft or hard output
//! limits, tracks without offset by estimating an input disturbance, and
//! falls back safely when its solver runs out of iterations or time; and
//! [`DenseQp`], the quadratic-program solver under it (ADMM as OSQP runs
//! it, warm-started, allocation-free after construction).
//!
//! MATLAB's MPC Toolbox (`mpc`, `mpcmove`) and python-control's
//! `create_mpc_iosystem` are the peers; where python-control solves each
//! tick with SciPy's general optimiser, this one is a dense QP sized for
//! a hard real-time loop (the lab's 4-state rig at 2 ms with a 40-step
//! horizon: see the performance guide for the measured worst case).
//!
//! # Examples
//!
//! Design on the lab's plant, cart 2 to 45 mm with the drive's ±24 V and
//! both carts softly kept inside ±48 mm:
//!
//! ```
//! use ctrlab::{Controller, Cart, MassSpring, lab};
//! use ctrlab::design::mpc::{Estimation, Mpc, MpcDesign, OutputLimit, Row};
//! use ctrlab::nalgebra::{matrix, vector, SMatrix};
//!
//! let model = lab::lqi::position_model(&MassSpring::nominal(), 0.002)?;
//! let mut design = MpcDesign::new(
//!     30,
//!     SMatrix::<f64, 4, 4>::from_diagonal(&vector![1e4, 0.0, 1e6, 0.0]),
//!     matrix![1e-3],
//! );
//! design.input_min = vector![-24.0];
//! design.input_max = vector![24.0];
//! for row in [matrix![1.0, 0.0, 0.0, 0.0], matrix![0.0, 0.0, 1.0, 0.0]] {
//!     design.output_limits.push(OutputLimit {
//!         output: row, min: -0.048, max: 0.048, kind: Row::Soft { linear: 1e5, quadratic: 1e8 },
//!     });
//! }
//! let estimation = Estimation {
//!     input_noise: matrix![10.0],
//!     disturbance_noise: matrix![1e-2],
//!     output_disturbance_noise: 1e-12,
//!     measurement_noise: SMatrix::<f64, 2, 2>::identity() * 1e-11,
//! };
//! // Track x2, the second measurement.
//! let mut mpc = Mpc::new(&model, &matrix![0.0, 1.0], &design, &estimation)?;
//!
//! let mut x = vector![0.0, 0.0, 0.0, 0.0];
//! for _ in 0..1500 {
//!     let u = mpc.update(&(model.c() * x), &vector![0.045]);
//!     assert!(u[0].abs() <= 24.0);
//!     mpc.applied(&u);
//!     x = model.advance(&x, &u);
//!     assert!(x[2] < 0.050);
//! }
//! assert!((x[2] - 0.045).abs() < 1e-5);
//! # Ok::<(), ctrlab::Error>(())
//! ```

mod condensed;
mod controller;
mod qp;

use nalgebra::{DMatrix, DVector, RowSVector, SMatrix, SVector};

pub use controller::Mpc;
pub use qp::{DenseQp, QpReport, QpSettings, QpStatus, Row};

use crate::error::Error;
use condensed::OutputRows;

/// An [`MpcDesign`]'s solver settings unless changed: [`QpSettings`]'
/// defaults with at most 200 ADMM iterations per tick (the active-set
/// method's 50 solves and the polish before them settle almost every
/// tick; the bound is what a tick that needs ADMM may spend).
///
/// # Examples
///
/// ```
/// use ctrlab::design::mpc::{MPC_SOLVER, QpSettings};
/// assert_eq!(MPC_SOLVER.max_iterations, 200);
/// assert_eq!(MPC_SOLVER.active_set_steps, QpSettings::default().active_set_steps);
/// ```
pub const MPC_SOLVER: QpSettings = QpSettings {
    max_iterations: 200,
    ..QpSettings::DEFAULT
};

/// Inputs over the horizon at most (`M · horizon`): bounds the QP's size,
/// so the memory and the time of a tick.
///
/// # Examples
///
/// A single-input design may look 400 steps ahead, not 401:
///
/// ```
/// # use ctrlab::StateSpace;
/// # use ctrlab::design::mpc::{Estimation, Mpc, MpcDesign};
/// # use ctrlab::nalgebra::matrix;
/// use ctrlab::design::mpc::MAX_VARIABLES;
/// # let model = StateSpace::discrete(matrix![1.0, 0.1; 0.0, 1.0], matrix![0.005; 0.1],
/// #                                  matrix![1.0, 0.0], matrix![0.0], 0.1)?;
/// # let estimation = Estimation { input_noise: matrix![1e-2], disturbance_noise: matrix![1e-4],
/// #                               output_disturbance_noise: 0.0, measurement_noise: matrix![1e-6] };
/// let mut design = MpcDesign::new(MAX_VARIABLES + 1, matrix![1.0, 0.0; 0.0, 0.0], matrix![0.1]);
/// let err = Mpc::new(&model, &matrix![1.0], &design, &estimation).unwrap_err();
/// assert!(matches!(err, ctrlab::Error::InvalidParameter { name: "horizon", .. }));
/// design.horizon = MAX_VARIABLES;
/// assert!(Mpc::new(&model, &matrix![1.0], &design, &estimation).is_ok());
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub const MAX_VARIABLES: usize = 400;

/// A limit `min ≤ output · x ≤ max` on a combination of the states (the
/// rig's cart positions: a row picking `x1` or `x2`), kept at every
/// predicted step, hard or soft.
///
/// # Examples
///
/// ```
/// use ctrlab::design::mpc::{OutputLimit, Row};
/// use ctrlab::nalgebra::matrix;
/// let travel = OutputLimit { output: matrix![0.0, 0.0, 1.0, 0.0], min: -0.045, max: 0.045,
///                            kind: Row::Soft { linear: 1e5, quadratic: 0.0 } };
/// assert_eq!(travel.output[2], 1.0);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OutputLimit<const N: usize> {
    /// The combination of states limited (its units: m for a position).
    pub output: RowSVector<f64, N>,
    /// Lower limit, may be `−∞`.
    pub min: f64,
    /// Upper limit, may be `+∞`.
    pub max: f64,
    /// Hard, or soft with its penalty weights (per unit and per squared
    /// unit of violation, at each step).
    pub kind: Row,
}

/// An [`Mpc`]'s horizon, weights, limits and solver settings.
///
/// Units are the model's: for the rig, states in m and m/s, the input in
/// V; `state_weight` in 1/m² (positions), `input_weight` and `rate_weight`
/// in 1/V².
///
/// # Examples
///
/// ```
/// use ctrlab::design::mpc::MpcDesign;
/// use ctrlab::nalgebra::matrix;
/// let d = MpcDesign::<2, 1>::new(20, matrix![1.0, 0.0; 0.0, 0.0], matrix![0.01]);
/// assert_eq!(d.horizon, 20);
/// assert!(d.input_max[0].is_infinite() && d.rate_max[0].is_infinite());
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct MpcDesign<const N: usize, const M: usize> {
    /// Steps predicted, ≥ 1 (`M · horizon ≤` [`MAX_VARIABLES`]).
    pub horizon: usize,
    /// `Q`: weight on the state's deviation from its target, symmetric
    /// positive semidefinite.
    pub state_weight: SMatrix<f64, N, N>,
    /// `R`: weight on the input's deviation from its target, symmetric
    /// positive definite.
    pub input_weight: SMatrix<f64, M, M>,
    /// `S`: weight on each step's change of input, symmetric positive
    /// semidefinite (zero by default).
    pub rate_weight: SMatrix<f64, M, M>,
    /// Hard lower input limits (`−∞` by default).
    pub input_min: SVector<f64, M>,
    /// Hard upper input limits (`+∞` by default).
    pub input_max: SVector<f64, M>,
    /// Hard limit on each input's change per period, > 0 (`+∞` by
    /// default: none).
    pub rate_max: SVector<f64, M>,
    /// Limits on the predicted outputs (none by default).
    pub output_limits: Vec<OutputLimit<N>>,
    /// Integral action, 1/s (≥ 0; 0 by default: none): the target is
    /// computed for the reference shifted by this times each tracked
    /// output's integrated error (`r + k_i ∫(r − y) dt`), so what the
    /// disturbance estimate cannot remove, a cart held by its friction
    /// short of the setpoint, is walked off as an integrator does. The
    /// shifted target is a steady state of the model, so the plan is the
    /// same QP; keep `k_i` well below the closed loop's bandwidth.
    pub integral_gain: f64,
    /// The error integrates only while its magnitude is at most this, in
    /// the reference's units (> 0; `+∞` by default): integral separation,
    /// so a large step's transient winds nothing up.
    pub integral_zone: f64,
    /// The QP solver's settings; `max_iterations` and `active_set_steps`
    /// bound each tick's work ([`MPC_SOLVER`] by default).
    pub solver: QpSettings,
}

impl<const N: usize, const M: usize> MpcDesign<N, M> {
    /// A design with `horizon`, `Q` and `R`, no rate weight, no limits,
    /// and at most 200 solver iterations per tick.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::design::mpc::{MPC_SOLVER, MpcDesign};
    /// use ctrlab::nalgebra::matrix;
    ///
    /// let d = MpcDesign::<2, 1>::new(20, matrix![1.0, 0.0; 0.0, 0.0], matrix![0.01]);
    /// assert_eq!(d.rate_weight, matrix![0.0]);
    /// assert!(d.input_min[0] == f64::NEG_INFINITY && d.output_limits.is_empty());
    /// assert_eq!((d.integral_gain, d.solver), (0.0, MPC_SOLVER));
    /// ```
    pub fn new(
        horizon: usize,
        state_weight: SMatrix<f64, N, N>,
        input_weight: SMatrix<f64, M, M>,
    ) -> Self {
        Self {
            horizon,
            state_weight,
            input_weight,
            rate_weight: SMatrix::zeros(),
            input_min: SVector::repeat(f64::NEG_INFINITY),
            input_max: SVector::repeat(f64::INFINITY),
            rate_max: SVector::repeat(f64::INFINITY),
            output_limits: Vec::new(),
            integral_gain: 0.0,
            integral_zone: f64::INFINITY,
            solver: MPC_SOLVER,
        }
    }

    fn validate_limits(&self) -> Result<(), Error> {
        for i in 0..M {
            let (lo, hi) = (self.input_min[i], self.input_max[i]);
            if lo.is_nan() || hi.is_nan() || lo >= hi || lo == f64::INFINITY {
                return Err(Error::InvalidParameter {
                    name: "input_min",
                    value: lo,
                    reason: "input limits must satisfy input_min < input_max (not NaN)",
                });
            }
            if self.rate_max[i].is_nan() || self.rate_max[i] <= 0.0 {
                return Err(Error::InvalidParameter {
                    name: "rate_max",
                    value: self.rate_max[i],
                    reason: "a rate limit must be > 0 (+∞ for none)",
                });
            }
        }
        for limit in &self.output_limits {
            crate::error::check_finite("output_limits", &limit.output)?;
            if limit.min.is_nan() || limit.max.is_nan() || limit.min > limit.max {
                return Err(Error::InvalidParameter {
                    name: "output_limits",
                    value: limit.min,
                    reason: "an output limit must satisfy min ≤ max (not NaN)",
                });
            }
        }
        Ok(())
    }

    fn output_rows(&self) -> OutputRows {
        let l = self.output_limits.len();
        let mut c = DMatrix::zeros(l, N);
        for (i, limit) in self.output_limits.iter().enumerate() {
            for j in 0..N {
                c[(i, j)] = limit.output[j];
            }
        }
        OutputRows {
            c,
            lower: DVector::from_iterator(l, self.output_limits.iter().map(|o| o.min)),
            upper: DVector::from_iterator(l, self.output_limits.iter().map(|o| o.max)),
            kind: self.output_limits.iter().map(|o| o.kind).collect(),
        }
    }
}

/// The disturbance estimator's noise model: a steady-state Kalman filter on
/// the model augmented with a constant disturbance on each input and on
/// each direction of the measurements the tracked outputs do not see
/// (`x⁺ = A x + B (u + d_u + w)`, `d_u⁺ = d_u + v_u`, `y = C x + N d_y +
/// e`, `d_y⁺ = d_y + v_y`, `H N = 0`): as many disturbances as
/// measurements, so the tracked outputs settle without offset.
///
/// Larger disturbance noise against `measurement_noise` tracks a
/// changing disturbance (friction reversing) faster and filters the
/// measurements less.
///
/// # Examples
///
/// ```
/// use ctrlab::design::mpc::Estimation;
/// use ctrlab::nalgebra::{matrix, SMatrix};
/// let count = 9.765625e-6; // m, the rig's encoder count
/// let e = Estimation::<1, 2> { input_noise: matrix![10.0], disturbance_noise: matrix![1e-2],
///                              output_disturbance_noise: 1e-12,
///                              measurement_noise: SMatrix::identity() * (count * count / 12.0) };
/// assert!(e.measurement_noise[(0, 0)] > 0.0);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Estimation<const M: usize, const Q: usize> {
    /// Covariance of `w`, the noise on the inputs (input units², e.g. V²).
    pub input_noise: SMatrix<f64, M, M>,
    /// Covariance of `v_u`, the input disturbances' change per period
    /// (input units²).
    pub disturbance_noise: SMatrix<f64, M, M>,
    /// Variance of `v_y`, each output disturbance's change per period
    /// (the measurements' units², ≥ 0; unused when every measurement is
    /// tracked).
    pub output_disturbance_noise: f64,
    /// Covariance of `e`, the measurement noise (output units², e.g. m²),
    /// positive definite.
    pub measurement_noise: SMatrix<f64, Q, Q>,
}

/// How a tick's input was found ([`Mpc::last_status`]).
///
/// # Examples
///
/// ```
/// use ctrlab::design::mpc::{QpStatus, TickStatus};
/// let t = TickStatus::Fallback { reason: QpStatus::IterationLimit, shifted_plan: true };
/// assert!(!t.is_solved());
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TickStatus {
    /// No tick since construction or the last reset.
    NotStarted,
    /// The QP was solved in this many iterations; its first input applied.
    Solved {
        /// ADMM iterations.
        iterations: usize,
    },
    /// The QP was not solved; the input came from the previous plan
    /// (`shifted_plan`) or the LQR law, clipped to the limits.
    Fallback {
        /// Why: the iteration limit, or hard limits that cannot hold.
        reason: QpStatus,
        /// Whether the previous plan supplied it.
        shifted_plan: bool,
    },
    /// A non-finite measurement or reference: the last input was held.
    InvalidInput,
}

impl TickStatus {
    /// Whether the tick's QP was solved.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::design::mpc::{QpStatus, TickStatus};
    /// assert!(TickStatus::Solved { iterations: 12 }.is_solved());
    /// assert!(!TickStatus::NotStarted.is_solved());
    /// assert!(!TickStatus::Fallback { reason: QpStatus::TimeLimit, shifted_plan: false }.is_solved());
    /// ```
    pub fn is_solved(self) -> bool {
        matches!(self, Self::Solved { .. })
    }
}

/// What an [`Mpc`] did since its last reset (a run): ticks by kind, the
/// solver's iterations and the longest tick (wall clock).
///
/// # Examples
///
/// ```
/// use ctrlab::design::mpc::MpcStats;
/// let s = MpcStats::default();
/// assert_eq!((s.ticks, s.fallbacks()), (0, 0));
/// ```
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct MpcStats {
    /// Ticks (updates).
    pub ticks: usize,
    /// Ticks whose QP was solved.
    pub solved: usize,
    /// Solves that ran out of iterations.
    pub iteration_limit: usize,
    /// Solves that ran out of time ([`QpSettings::time_limit`]).
    pub time_limit: usize,
    /// Solves whose hard limits could not hold.
    pub infeasible: usize,
    /// Fallbacks served by the previous plan.
    pub fallback_shifted: usize,
    /// Fallbacks served by the LQR law.
    pub fallback_lqr: usize,
    /// Ticks with a non-finite measurement or reference (input held).
    pub invalid_inputs: usize,
    /// Ticks whose steady-state input lay outside the input limits (the
    /// reference cannot be held; the QP gets as close as the limits let).
    pub unreachable_targets: usize,
    /// Most iterations in one tick.
    pub iterations_max: usize,
    /// Iterations over all ticks.
    pub iterations_total: usize,
    /// Most active-set solves in one tick (see
    /// [`QpSettings::active_set_steps`]).
    pub active_set_steps_max: usize,
    /// Longest tick from measurement to input (estimate, target, solve),
    /// s, wall clock.
    pub solve_time_max: f64,
}

impl MpcStats {
    /// Ticks whose input came from a fallback.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::design::mpc::MpcStats;
    /// let s = MpcStats { ticks: 10, solved: 7, fallback_shifted: 2, fallback_lqr: 1,
    ///                    ..Default::default() };
    /// assert_eq!(s.fallbacks(), 3);
    /// assert_eq!(s.solved + s.fallbacks(), s.ticks);
    /// ```
    pub fn fallbacks(&self) -> usize {
        self.fallback_shifted + self.fallback_lqr
    }
}

impl std::fmt::Display for MpcStats {
    /// One line: ticks, solved, fallbacks and why, iterations, longest tick.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::design::mpc::MpcStats;
    /// let s = MpcStats { ticks: 10, solved: 10, iterations_max: 7, ..Default::default() };
    /// assert!(s.to_string().starts_with("ticks 10, solved 10"));
    /// ```
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "ticks {}, solved {}, fallbacks {} ({} shifted plan, {} LQR; {} at the iteration limit, {} at the time limit, {} infeasible), \
             unreachable targets {}, invalid inputs {}, iterations max {} mean {:.1}, active-set solves max {}, longest tick {:.1} µs",
            self.ticks,
            self.solved,
            self.fallbacks(),
            self.fallback_shifted,
            self.fallback_lqr,
            self.iteration_limit,
            self.time_limit,
            self.infeasible,
            self.unreachable_targets,
            self.invalid_inputs,
            self.iterations_max,
            self.iterations_total as f64 / self.ticks.max(1) as f64,
            self.active_set_steps_max,
            self.solve_time_max * 1e6
        )
    }
}
