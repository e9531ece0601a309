//! The warm start of each tick's QP and the fallback when it fails: the
//! last plan shifted and clipped to the hard limits, or the LQR law
//! rolled out; both clipped along the rate limit's chain.

use nalgebra::SVector;

use super::super::TickStatus;
use super::super::qp::QpStatus;
use super::Mpc;

impl<const N: usize, const M: usize, const Q: usize, const R: usize> Mpc<N, M, Q, R> {
    /// The previous plan shifted one step, relative to the new `u_s`, as
    /// the warm start, with its multipliers shifted alike.
    pub(super) fn warm_start(&mut self) {
        let (h, mh) = (self.problem.horizon, M * self.problem.horizon);
        // Shifted, and clipped along the chain from the input last applied
        // (which the drive rounded) to the input and rate limits: a start
        // that holds the hard rows, as the active-set method needs.
        let mut previous = self.u_prev;
        for k in 0..h {
            let from = (k + 1).min(h - 1);
            for i in 0..M {
                let u = self.clip_from(previous[i], i, self.plan[from * M + i]);
                previous[i] = u;
                self.shifted[k * M + i] = u - self.steady[N + i];
            }
        }
        // The multipliers' blocks (inputs, rates, outputs), each shifted.
        let y = self.qp.multipliers();
        let l = self.outputs.c.nrows();
        let blocks = [
            (0, M),
            (mh, if self.problem.rate_rows > 0 { M } else { 0 }),
            (mh + self.problem.rate_rows, l),
        ];
        for (start, width) in blocks {
            for k in 0..h {
                let from = (k + 1).min(h - 1);
                for i in 0..width {
                    self.shifted_y[start + k * width + i] = y[start + from * width + i];
                }
            }
        }
        // Finite by construction (a solved plan, finite targets).
        let _ = self
            .qp
            .warm_start(self.shifted.as_slice(), Some(self.shifted_y.as_slice()));
    }

    /// With no plan to shift (the first tick, or a plan run out): the LQR
    /// law clipped to the limits, rolled out over the horizon on the
    /// model, as the warm start. A saturated transient's plan is mostly
    /// this, so the first solve starts near its answer.
    pub(super) fn rollout_warm_start(&mut self) {
        self.roll_x.copy_from(&self.dx0);
        let mut previous = self.u_prev;
        for k in 0..self.problem.horizon {
            // u = u_s − K [δx; z], clipped.
            self.roll_u.gemv(-1.0, &self.lqr_gain, &self.roll_x, 0.0);
            for i in 0..M {
                let us = self.steady[N + i];
                let u = self.clip_from(previous[i], i, us + self.roll_u[i]);
                previous[i] = u;
                self.roll_u[i] = u - us;
                self.shifted[k * M + i] = u - us;
            }
            self.roll_next.gemv(1.0, &self.pa, &self.roll_x, 0.0);
            self.roll_next.gemv(1.0, &self.pb, &self.roll_u, 1.0);
            self.roll_x.copy_from(&self.roll_next);
        }
        if self.shifted.iter().all(|v| v.is_finite()) {
            let _ = self.qp.warm_start(self.shifted.as_slice(), None);
        }
    }

    /// `u` clipped to the input limits and the rate limit from `u_prev`.
    pub(super) fn clip(&self, mut u: SVector<f64, M>) -> SVector<f64, M> {
        for i in 0..M {
            u[i] = self.clip_from(self.u_prev[i], i, u[i]);
        }
        u
    }

    /// Input `i`'s value `u` clipped to its limits and to the rate limit
    /// from `previous`. An empty window (`previous` outside the limits by
    /// more than the rate) honours the input limits first.
    pub(super) fn clip_from(&self, previous: f64, i: usize, u: f64) -> f64 {
        let (lo, hi) = (
            (previous - self.rate_max[i]).max(self.input_min[i]),
            (previous + self.rate_max[i]).min(self.input_max[i]),
        );
        if lo <= hi {
            u.clamp(lo, hi)
        } else {
            u.clamp(self.input_min[i], self.input_max[i])
        }
    }

    /// The fallback input when the QP gave none: the plan shifted while
    /// it lasts, else the LQR law about the target.
    pub(super) fn fallback(&mut self, reason: QpStatus) -> SVector<f64, M> {
        let h = self.problem.horizon;
        let us = SVector::<f64, M>::from_fn(|i, _| self.steady[N + i]);
        let shifted = self.plan_age < h;
        let u = if shifted {
            let k = self.plan_age;
            self.plan_age += 1;
            SVector::<f64, M>::from_fn(|i, _| self.plan[k * M + i])
        } else {
            self.roll_u.gemv(-1.0, &self.lqr_gain, &self.dx0, 0.0);
            us + SVector::<f64, M>::from_fn(|i, _| self.roll_u[i])
        };
        self.last = TickStatus::Fallback {
            reason,
            shifted_plan: shifted,
        };
        if shifted {
            self.stats.fallback_shifted += 1;
        } else {
            self.stats.fallback_lqr += 1;
        }
        u
    }
}
