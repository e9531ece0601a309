//! [`Mpc`]: the constrained, offset-free linear MPC as a [`Controller`].

use std::time::Instant;

use nalgebra::{DMatrix, DVector, SMatrix, SVector};

mod estimator;
mod inspect;
mod requests;
mod warm;

use super::condensed::{Condensed, OutputRows, span_scale};
use super::qp::{DenseQp, QpReport, QpStatus};
use super::{Estimation, MAX_VARIABLES, MpcDesign, MpcStats, TickStatus};
use crate::design::{Controller, lqr};
use crate::error::{Error, check_finite};
use crate::model::{Discrete, StateSpace};
use estimator::{check_weight, estimator, target_map};

/// A linear model-predictive controller: every period it estimates the
/// state and an input disturbance from the measurements, finds the steady
/// state that puts the tracked outputs on the reference, and solves a
/// quadratic program for the inputs over the horizon under the design's
/// limits; it applies the first and keeps the rest as the next tick's
/// warm start and fallback.
///
/// ```text
/// estimate   [x̂; d̂] ← Kalman filter of x⁺ = A x + B (u + d), d⁺ = d, y = C x
/// target     x_s = A x_s + B (u_s + d̂),  T x_s = r          (least squares if not square)
/// minimise   Σ_{k=1}^{H−1} δx_kᵀ Q δx_k + δx_Hᵀ P δx_H + Σ_{k=0}^{H−1} δu_kᵀ R δu_k + Δu_kᵀ S Δu_k
///            + Σ soft-limit penalties
/// subject to u_min ≤ u_k ≤ u_max,  |Δu_k| ≤ Δu_max,  limits on the predicted outputs
/// ```
///
/// with `δx = x − x_s`, `δu = u − u_s`, `Δu_k = u_k − u_{k−1}` (`u_{−1}`
/// the input last applied) and `P` the discrete Riccati solution of
/// `(A, B, Q, R)`. The estimated disturbance `d̂` makes the tracking
/// offset-free: a constant force the model does not know (Coulomb
/// friction, a wrong motor gain) is estimated and countered, so the tracked
/// outputs settle on the reference, as integral action does.
///
/// Each tick's QP is solved by [`DenseQp`] with at most
/// [`QpSettings::max_iterations`](super::QpSettings::max_iterations)
/// iterations, warm-started from the previous plan shifted by one step.
/// When a solve does not converge or the hard limits cannot hold, the
/// controller falls back ([`TickStatus`]): to the last solved plan shifted,
/// while it lasts, else to the LQR law `u = u_s − K δx` of the same
/// weights; either is clipped to the input and rate limits, as every
/// output is. [`stats`](Self::stats) counts the ticks of each kind and
/// the longest solve. `update` and `applied` allocate nothing.
///
/// Its measurements are the model's outputs; on a loop that measures more
/// (the rig's speeds), wrap it in [`SelectOutputs`](crate::design::SelectOutputs).
///
/// # Examples
///
/// A double integrator at 0.1 s, position measured, driven to 1 with the
/// input limited to ±0.5 and the position softly kept below 1.05:
///
/// ```
/// use ctrlab::{Controller, StateSpace};
/// use ctrlab::design::mpc::{Estimation, Mpc, MpcDesign, OutputLimit, Row};
/// use ctrlab::nalgebra::{matrix, vector};
///
/// let model = StateSpace::discrete(matrix![1.0, 0.1; 0.0, 1.0], matrix![0.005; 0.1],
///                                  matrix![1.0, 0.0], matrix![0.0], 0.1)?;
/// let mut design = MpcDesign::new(20, matrix![10.0, 0.0; 0.0, 1.0], matrix![0.1]);
/// design.input_min = vector![-0.5];
/// design.input_max = vector![0.5];
/// design.output_limits.push(OutputLimit {
///     output: matrix![1.0, 0.0], min: -1.0, max: 1.05, kind: Row::Soft { linear: 1e3, quadratic: 1e4 },
/// });
/// let estimation = Estimation { input_noise: matrix![1e-2], disturbance_noise: matrix![1e-4],
///                               output_disturbance_noise: 0.0,
///                               measurement_noise: matrix![1e-6] };
/// let mut mpc = Mpc::new(&model, &matrix![1.0], &design, &estimation)?;
///
/// let (mut x, mut peak) = (vector![0.0, 0.0], 0.0f64);
/// for _ in 0..200 {
///     let u = mpc.update(&(model.c() * x), &vector![1.0]);
///     assert!(u[0].abs() <= 0.5);
///     mpc.applied(&u);
///     x = model.advance(&x, &u);
///     peak = peak.max(x[0]);
/// }
/// assert!((x[0] - 1.0).abs() < 1e-4 && peak < 1.05);
/// assert_eq!(mpc.stats().ticks, 200);
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct Mpc<const N: usize, const M: usize, const Q: usize, const R: usize> {
    dt: f64,
    problem: Condensed,
    qp: DenseQp,
    input_min: SVector<f64, M>,
    input_max: SVector<f64, M>,
    rate_max: SVector<f64, M>,
    outputs: OutputRows,
    /// The LQR gain of the fallback law (on `[δx; z]`), and the
    /// prediction model it rolls out on.
    lqr_gain: DMatrix<f64>,
    pa: DMatrix<f64>,
    pb: DMatrix<f64>,
    /// The tracked outputs' selection of the measurements, and their
    /// integrated error (`T` times, in the reference's units × s) when
    /// the design has integral action.
    tracked: DMatrix<f64>,
    integral: DVector<f64>,
    integral_gain: f64,
    /// Whether the estimator models input disturbances.
    input_disturbances: bool,
    integral_zone: f64,
    /// `[x_s; u_s] = target · [B d̂; r]`.
    target: DMatrix<f64>,
    b: DMatrix<f64>,
    // The augmented estimator on [x; d]: A_a, B_a, C_a and its
    // current-form gain.
    a_aug: DMatrix<f64>,
    b_aug: DMatrix<f64>,
    c_aug: DMatrix<f64>,
    gain: DMatrix<f64>,
    // State.
    prior: DVector<f64>,
    estimate: DVector<f64>,
    u_prev: SVector<f64, M>,
    plan: DVector<f64>,
    /// Ticks since `plan` was solved (`horizon` or more: none left).
    plan_age: usize,
    stats: MpcStats,
    last: TickStatus,
    report: Option<QpReport>,
    // Work.
    innovation: DVector<f64>,
    rhs: DVector<f64>,
    steady: DVector<f64>,
    dx0: DVector<f64>,
    roll_x: DVector<f64>,
    roll_next: DVector<f64>,
    roll_u: DVector<f64>,
    q: DVector<f64>,
    lower: DVector<f64>,
    upper: DVector<f64>,
    free: DVector<f64>,
    shifted: DVector<f64>,
    shifted_y: DVector<f64>,
}

impl<const N: usize, const M: usize, const Q: usize, const R: usize> Mpc<N, M, Q, R> {
    /// Designs the controller for `model` (discrete; its outputs are the
    /// measurements, `D = 0`), tracking `tracked · y` (`H`: `R` combinations
    /// of the measurements, usually a selection; the reference's units),
    /// under `design`'s horizon, weights and limits, with the disturbance
    /// estimator of `estimation`. Offset-free tracking needs `R = M` (as
    /// many tracked outputs as inputs).
    ///
    /// # Errors
    ///
    /// - [`Error::InvalidParameter`]: a horizon of 0 or one with more than
    ///   [`MAX_VARIABLES`] inputs in all (`"horizon"`), an input range
    ///   that is empty or NaN (`"input_min"`), a rate limit that is not
    ///   positive (`"rate_max"`), an output limit with `min > max` or NaN
    ///   (`"output_limits"`), as [`DenseQp::new`] for the solver settings
    ///   and soft weights;
    /// - [`Error::InvalidMatrix`]: `D ≠ 0`, weights not symmetric positive
    ///   (semi)definite as [`dlqr`](crate::design::dlqr) requires;
    /// - [`Error::NonFinite`] for a non-finite `tracked` or output row;
    /// - [`Error::Singular`]: no steady state puts the tracked outputs on
    ///   an arbitrary reference (a zero of the plant at `z = 1`);
    /// - as [`dlqr`](crate::design::dlqr) and
    ///   [`dlqe`](crate::design::dlqe): an uncontrollable plant or a state
    ///   and disturbance the measurements cannot tell apart.
    ///
    /// # Examples
    ///
    /// A double integrator sampled at 0.1 s (position in m measured and
    /// tracked, force in N), a 20-step horizon (2 s):
    ///
    /// ```
    /// use ctrlab::StateSpace;
    /// use ctrlab::design::mpc::{Estimation, Mpc, MpcDesign};
    /// use ctrlab::nalgebra::matrix;
    ///
    /// let model = StateSpace::discrete(matrix![1.0, 0.1; 0.0, 1.0], matrix![0.005; 0.1],
    ///                                  matrix![1.0, 0.0], matrix![0.0], 0.1)?;
    /// let mut design = MpcDesign::new(20, matrix![10.0, 0.0; 0.0, 1.0], matrix![0.1]);
    /// let estimation = Estimation { input_noise: matrix![1e-2], disturbance_noise: matrix![1e-4],
    ///                               output_disturbance_noise: 0.0, measurement_noise: matrix![1e-6] };
    /// let mpc = Mpc::new(&model, &matrix![1.0], &design, &estimation)?;
    /// assert_eq!(mpc.plan().len(), 20); // one input per step
    /// design.horizon = 0;
    /// assert!(Mpc::new(&model, &matrix![1.0], &design, &estimation).is_err());
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn new(
        model: &StateSpace<N, M, Q, Discrete>,
        tracked: &SMatrix<f64, R, Q>,
        design: &MpcDesign<N, M>,
        estimation: &Estimation<M, Q>,
    ) -> Result<Self, Error> {
        check_finite("H", tracked)?;
        if model.d().iter().any(|&v| v != 0.0) {
            return Err(Error::InvalidMatrix {
                matrix: "D",
                reason: "an MPC's measurements must not feed through (D = 0)",
            });
        }
        let horizon = design.horizon;
        if horizon == 0 || horizon.saturating_mul(M) > MAX_VARIABLES {
            return Err(Error::InvalidParameter {
                name: "horizon",
                value: horizon as f64,
                reason: "must be ≥ 1 with at most MAX_VARIABLES inputs over the horizon",
            });
        }
        design.validate_limits()?;
        let dt = model.dt();
        let (a, b) = (
            DMatrix::from_column_slice(N, N, model.a().as_slice()),
            DMatrix::from_column_slice(N, M, model.b().as_slice()),
        );
        let ki = design.integral_gain;
        if !(ki.is_finite() && ki >= 0.0) {
            return Err(Error::InvalidParameter {
                name: "integral_gain",
                value: ki,
                reason: "must be finite and ≥ 0 /s (0: no integral action)",
            });
        }
        if design.integral_zone.is_nan() || design.integral_zone <= 0.0 {
            return Err(Error::InvalidParameter {
                name: "integral_zone",
                value: design.integral_zone,
                reason: "must be > 0 (+∞: everywhere)",
            });
        }
        let tracked_states = tracked * model.c();
        let nx = N;
        let pa = a.clone();
        let pb = b.clone();
        let q = DMatrix::from_column_slice(N, N, design.state_weight.as_slice());
        let r = DMatrix::from_column_slice(M, M, design.input_weight.as_slice());
        let s = DMatrix::from_column_slice(M, M, design.rate_weight.as_slice());
        check_weight("S", &s)?;
        let lqr = lqr::regulator(&pa, &pb, &q, &r, Some(dt))?;
        let outputs = design.output_rows();
        let input_scale: Vec<f64> = (0..M)
            .map(|i| span_scale(design.input_min[i], design.input_max[i]))
            .collect();
        let rate_scale: Vec<f64> = (0..M)
            .map(|i| span_scale(-design.rate_max[i], design.rate_max[i]))
            .collect();
        let rate_limited = design.rate_max.iter().any(|v| v.is_finite());
        let problem = Condensed::new(
            &pa,
            &pb,
            &q,
            &r,
            &s,
            &lqr.riccati,
            horizon,
            &input_scale,
            rate_limited.then_some(rate_scale.as_slice()),
            &outputs,
        );
        let qp = DenseQp::new(&problem.hessian, &problem.g, &problem.kinds, design.solver)?;

        let target = target_map(&a, &b, &tracked_states)?;
        let (a_aug, b_aug, c_aug, gain) = estimator(&a, &b, model, tracked, estimation)?;
        let na = a_aug.nrows();
        let h_tracked = DMatrix::from_column_slice(R, Q, tracked.as_slice());
        let (rows, mh, lh) = (qp.rows(), M * horizon, outputs.c.nrows() * horizon);
        Ok(Self {
            dt,
            problem,
            qp,
            input_min: design.input_min,
            input_max: design.input_max,
            rate_max: design.rate_max,
            outputs,
            lqr_gain: lqr.gain,
            pa,
            pb,
            tracked: h_tracked,
            integral: DVector::zeros(R),
            integral_gain: ki,
            input_disturbances: estimation.disturbance_noise.iter().any(|&v| v != 0.0),
            integral_zone: design.integral_zone,
            roll_x: DVector::zeros(nx),
            roll_next: DVector::zeros(nx),
            roll_u: DVector::zeros(M),
            target,
            b,
            a_aug,
            b_aug,
            c_aug,
            gain,
            prior: DVector::zeros(na),
            estimate: DVector::zeros(na),
            u_prev: SVector::zeros(),
            plan: DVector::zeros(mh),
            plan_age: horizon,
            stats: MpcStats::default(),
            last: TickStatus::NotStarted,
            report: None,
            innovation: DVector::zeros(Q),
            rhs: DVector::zeros(N + R),
            steady: DVector::zeros(N + M),
            dx0: DVector::zeros(nx),
            q: DVector::zeros(mh),
            lower: DVector::zeros(rows),
            upper: DVector::zeros(rows),
            free: DVector::zeros(lh),
            shifted: DVector::zeros(mh),
            shifted_y: DVector::zeros(rows),
        })
    }

    /// One tick from the current estimate: target, QP data, warm start,
    /// solve or fallback, clip; the counts. Allocates nothing.
    fn tick(&mut self, r: &SVector<f64, R>) -> SVector<f64, M> {
        let started = Instant::now();
        self.steady_state(r);
        for i in 0..N {
            self.dx0[i] = self.estimate[i] - self.steady[i];
        }
        if !self.reachable() {
            self.stats.unreachable_targets += 1;
        }
        self.problem_data();
        if self.plan_age < self.problem.horizon {
            self.warm_start();
        } else {
            self.rollout_warm_start();
        }
        let report = self.qp.solve(
            self.q.as_slice(),
            self.lower.as_slice(),
            self.upper.as_slice(),
        );
        self.report = report.as_ref().ok().copied();
        if let Some(r) = self.report {
            self.stats.active_set_steps_max =
                self.stats.active_set_steps_max.max(r.active_set_steps);
        }
        let u = match report {
            Ok(report) if report.status.is_solved() => {
                self.stats.solved += 1;
                self.stats.iterations_total += report.iterations;
                self.stats.iterations_max = self.stats.iterations_max.max(report.iterations);
                let x = self.qp.solution();
                for k in 0..self.problem.horizon {
                    for i in 0..M {
                        self.plan[k * M + i] = self.steady[N + i] + x[k * M + i];
                    }
                }
                self.plan_age = 1;
                self.last = TickStatus::Solved {
                    iterations: report.iterations,
                };
                SVector::<f64, M>::from_fn(|i, _| self.plan[i])
            }
            Ok(report) => {
                self.stats.iterations_total += report.iterations;
                self.stats.iterations_max = self.stats.iterations_max.max(report.iterations);
                match report.status {
                    QpStatus::PrimalInfeasible => self.stats.infeasible += 1,
                    QpStatus::TimeLimit => self.stats.time_limit += 1,
                    _ => self.stats.iteration_limit += 1,
                }
                self.fallback(report.status)
            }
            // Finite data of the right lengths by construction; were it
            // refused, the fallback is still safe.
            Err(_) => {
                self.stats.iteration_limit += 1;
                self.fallback(QpStatus::IterationLimit)
            }
        };
        let u = self.clip(u);
        let elapsed = started.elapsed().as_secs_f64();
        self.stats.solve_time_max = self.stats.solve_time_max.max(elapsed);
        if u.iter().all(|v| v.is_finite()) {
            u
        } else {
            self.clip(self.u_prev)
        }
    }

    /// Whether the target's inputs lie within the input limits.
    fn reachable(&self) -> bool {
        (0..M).all(|i| {
            let us = self.steady[N + i];
            us >= self.input_min[i] && us <= self.input_max[i]
        })
    }

    /// Whether an input is at its limit.
    fn limited(&self, u: &SVector<f64, M>) -> bool {
        (0..M).any(|i| u[i] <= self.input_min[i] || u[i] >= self.input_max[i])
    }

    /// The measurement update of the estimator: `[x̂; d̂]` from the prior.
    fn correct(&mut self, y: &SVector<f64, Q>) {
        self.innovation.copy_from_slice(y.as_slice());
        self.innovation.gemv(-1.0, &self.c_aug, &self.prior, 1.0);
        self.estimate.copy_from(&self.prior);
        self.estimate.gemv(1.0, &self.gain, &self.innovation, 1.0);
    }

    /// `[x_s; u_s]` into `steady` for reference `r` and the disturbance.
    fn steady_state(&mut self, r: &SVector<f64, R>) {
        if self.input_disturbances {
            let d = self.estimate.rows(N, M);
            self.rhs.rows_mut(0, N).gemv(1.0, &self.b, &d, 0.0);
        } else {
            self.rhs.rows_mut(0, N).fill(0.0);
        }
        for i in 0..R {
            self.rhs[N + i] = r[i] + self.integral_gain * self.integral[i];
        }
        self.steady.gemv(1.0, &self.target, &self.rhs, 0.0);
    }

    /// The QP's linear cost and bounds for this tick, from `steady`,
    /// `dx0` and `u_prev`.
    fn problem_data(&mut self) {
        let (h, l) = (self.problem.horizon, self.outputs.c.nrows());
        let us = SVector::<f64, M>::from_fn(|i, _| self.steady[N + i]);
        // q = Fx δx₀ + Fu (u_s − u_prev)
        let du = us - self.u_prev;
        self.q.gemv(1.0, &self.problem.fx, &self.dx0, 0.0);
        for i in 0..M {
            let (col, scale) = (self.problem.fu.column(i), du[i]);
            self.q.axpy(scale, &col, 1.0);
        }
        for k in 0..h {
            for i in 0..M {
                self.lower[k * M + i] = self.input_min[i] - us[i];
                self.upper[k * M + i] = self.input_max[i] - us[i];
            }
        }
        let mut row = M * h;
        if self.problem.rate_rows > 0 {
            for k in 0..h {
                for i in 0..M {
                    let (lo, hi) = if k == 0 {
                        let base = self.u_prev[i] - us[i];
                        (base - self.rate_max[i], base + self.rate_max[i])
                    } else {
                        (-self.rate_max[i], self.rate_max[i])
                    };
                    self.lower[row] = lo;
                    self.upper[row] = hi;
                    row += 1;
                }
            }
        }
        // Outputs: lower − C_c x_s − C_c Φ_k δx₀ ≤ C_c Γ_k δU ≤ upper − …
        self.free
            .gemv(1.0, &self.problem.output_free, &self.dx0, 0.0);
        for j in 0..l {
            let at_steady: f64 = (0..N)
                .map(|c| self.outputs.c[(j, c)] * self.steady[c])
                .sum();
            for k in 0..h {
                let i = k * l + j;
                let offset = at_steady + self.free[i];
                self.lower[row + i] = self.outputs.lower[j] - offset;
                self.upper[row + i] = self.outputs.upper[j] - offset;
            }
        }
        self.lower.component_mul_assign(&self.problem.row_scale);
        self.upper.component_mul_assign(&self.problem.row_scale);
    }
}

impl<const N: usize, const M: usize, const Q: usize, const R: usize> Controller<Q, R, M>
    for Mpc<N, M, Q, R>
{
    fn update(&mut self, y: &SVector<f64, Q>, r: &SVector<f64, R>) -> SVector<f64, M> {
        self.stats.ticks += 1;
        if !(y.iter().all(|v| v.is_finite()) && r.iter().all(|v| v.is_finite())) {
            // Nothing to estimate or aim at: hold the input, within limits.
            self.stats.invalid_inputs += 1;
            self.last = TickStatus::InvalidInput;
            return self.clip(self.u_prev);
        }
        self.correct(y);
        let u = self.tick(r);
        // The integrated error, z += T (r − H y), frozen while an input
        // is at its limit or the target cannot be held (conditional
        // integration: no windup to unwind afterwards).
        if self.integral_gain > 0.0 && !self.limited(&u) && self.reachable() {
            for i in 0..R {
                let measured: f64 = (0..Q).map(|j| self.tracked[(i, j)] * y[j]).sum();
                let error = r[i] - measured;
                if error.abs() <= self.integral_zone {
                    self.integral[i] += self.dt * error;
                }
            }
        }
        u
    }

    fn applied(&mut self, u: &SVector<f64, M>) {
        if !u.iter().all(|v| v.is_finite()) {
            return;
        }
        self.u_prev = *u;
        // x̂⁺ = A_a [x̂; d̂] + B_a u
        self.prior.gemv(1.0, &self.a_aug, &self.estimate, 0.0);
        for i in 0..M {
            let col = self.b_aug.column(i);
            self.prior.axpy(self.u_prev[i], &col, 1.0);
        }
    }

    fn reset(&mut self) {
        self.prior.fill(0.0);
        self.estimate.fill(0.0);
        self.u_prev = SVector::zeros();
        self.plan.fill(0.0);
        self.integral.fill(0.0);
        self.plan_age = self.problem.horizon;
        self.qp.cold_start();
        self.stats = MpcStats::default();
        self.last = TickStatus::NotStarted;
        self.report = None;
    }

    fn period(&self) -> Option<f64> {
        Some(self.dt)
    }
}
