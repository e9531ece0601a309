//! The ADMM iteration (OSQP's Algorithm 1) on the equilibrated problem,
//! its residuals, the primal-infeasibility certificate and the adaptive
//! step size.

use super::DenseQp;
use super::kernels::cholesky_in_place;

/// `ρ` stays within these (OSQP's), and changes only by a factor of 5.
pub(super) const RHO_MIN: f64 = 1e-6;
pub(super) const RHO_MAX: f64 = 1e6;
pub(super) const RHO_TRIGGER: f64 = 5.0;

/// Residuals of an iterate and the norms they are relative to.
pub(super) struct Residuals {
    pub(super) prim: f64,
    pub(super) dual: f64,
    pub(super) prim_scale: f64,
    pub(super) dual_scale: f64,
}

impl DenseQp {
    /// One ADMM iteration on the scaled problem (OSQP's Algorithm 1).
    pub(super) fn iterate(&mut self) {
        let (s, rho) = (self.settings, self.rho);
        // rhs = σ x − q + Gᵀ (ρ z − y)
        for i in 0..self.rows() {
            self.work_m[i] = rho * self.z[i] - self.y[i];
        }
        for j in 0..self.variables() {
            self.xt[j] = s.sigma * self.x[j] - self.q[j];
        }
        self.g.add_tr_mul(&self.work_m, &mut self.xt);
        // x̃ = (P + σI + ρ GᵀG)⁻¹ rhs
        self.chol.solve_lower_triangular_mut(&mut self.xt);
        self.chol.tr_solve_lower_triangular_mut(&mut self.xt);
        self.g.mul(&self.xt, &mut self.zt);
        let a = s.alpha;
        for j in 0..self.variables() {
            self.x[j] = a * self.xt[j] + (1.0 - a) * self.x[j];
        }
        for i in 0..self.rows() {
            let relaxed = a * self.zt[i] + (1.0 - a) * self.z[i];
            let v = relaxed + self.y[i] / rho;
            let z = match self.soft[i] {
                None => v.clamp(self.l[i], self.u[i]),
                Some((w1, w2)) => soft_prox(v, self.l[i], self.u[i], w1, w2, rho),
            };
            self.y[i] += rho * (relaxed - z);
            self.z[i] = z;
        }
    }

    /// The residuals in the unscaled problem's units.
    pub(super) fn residuals(&mut self) -> Residuals {
        // Primal: G x − z, row by row unscaled by E⁻¹.
        self.g.mul(&self.x, &mut self.work_m);
        let (mut prim, mut gx, mut zn) = (0.0f64, 0.0f64, 0.0f64);
        for i in 0..self.rows() {
            let inv = 1.0 / self.e[i];
            prim = prim.max(((self.work_m[i] - self.z[i]) * inv).abs());
            gx = gx.max((self.work_m[i] * inv).abs());
            zn = zn.max((self.z[i] * inv).abs());
        }
        // Dual: P x + q + Gᵀ y, unscaled by D⁻¹ / c; Gᵀ y into x̃'s
        // buffer (x̃ is spent) for its own norm.
        self.work_n.gemv(1.0, &self.p, &self.x, 0.0);
        self.xt.fill(0.0);
        self.g.add_tr_mul(&self.y, &mut self.xt);
        let (mut dual, mut px, mut gy, mut qn) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
        for j in 0..self.variables() {
            let inv = 1.0 / (self.c * self.d[j]);
            px = px.max((self.work_n[j] * inv).abs());
            qn = qn.max((self.q[j] * inv).abs());
            gy = gy.max((self.xt[j] * inv).abs());
            dual = dual.max(((self.work_n[j] + self.q[j] + self.xt[j]) * inv).abs());
        }
        Residuals {
            prim,
            dual,
            prim_scale: gx.max(zn),
            dual_scale: px.max(gy).max(qn),
        }
    }

    /// OSQP's primal-infeasibility certificate on `δy = y − y_prev`: over
    /// the hard rows (a soft row's multiplier is bounded by its penalty,
    /// so it takes no part), `‖Gᵀ δy‖ ≈ 0` while `uᵀ δy₊ + lᵀ δy₋ < 0`.
    pub(super) fn infeasible(&mut self) -> bool {
        let eps = self.settings.eps_infeasible;
        let mut norm = 0.0f64;
        for i in 0..self.rows() {
            let mut dy = self.y[i] - self.y_prev[i];
            if self.soft[i].is_some()
                || (dy > 0.0 && self.u[i] == f64::INFINITY)
                || (dy < 0.0 && self.l[i] == f64::NEG_INFINITY)
            {
                dy = 0.0;
            }
            self.work_m[i] = dy;
            norm = norm.max((dy * self.e[i]).abs());
        }
        if norm <= f64::MIN_POSITIVE {
            return false;
        }
        let mut support = 0.0;
        for i in 0..self.rows() {
            let dy = self.work_m[i];
            if dy > 0.0 {
                support += self.u[i] * dy;
            } else if dy < 0.0 {
                support += self.l[i] * dy;
            }
        }
        if support >= -eps * norm {
            return false;
        }
        self.work_n.fill(0.0);
        self.g.add_tr_mul(&self.work_m, &mut self.work_n);
        let gty = self
            .work_n
            .iter()
            .zip(self.d.iter())
            .fold(0.0f64, |a, (v, d)| a.max((v / d).abs()));
        gty <= eps * norm
    }

    /// OSQP's step-size rule, `ρ ← ρ √(r̂_prim / r̂_dual)` in residuals
    /// relative to their scales, refactoring only on a fivefold change.
    pub(super) fn adapt_rho(&mut self, r: &Residuals) {
        let tiny = 1e-30;
        let ratio = (r.prim / (r.prim_scale + tiny)) / (r.dual / (r.dual_scale + tiny)).max(tiny);
        if !ratio.is_finite() || ratio <= 0.0 {
            return;
        }
        let proposed = (self.rho * ratio.sqrt()).clamp(RHO_MIN, RHO_MAX);
        if proposed > self.rho * RHO_TRIGGER || proposed < self.rho / RHO_TRIGGER {
            let old = self.rho;
            self.rho = proposed;
            if !self.factor() {
                // Cannot happen for a matrix that factored before with a
                // positive ρ; keep the old step if it does.
                self.rho = old;
                let _ = self.factor();
            }
        }
    }

    /// Factors `P + σI + ρ GᵀG` in place into `chol` (lower); false if it
    /// is not positive definite.
    pub(super) fn factor(&mut self) -> bool {
        let n = self.variables();
        let (sigma, rho) = (self.settings.sigma, self.rho);
        for j in 0..n {
            for i in j..n {
                let mut v = self.p[(i, j)] + rho * self.gtg[(i, j)];
                if i == j {
                    v += sigma;
                }
                self.chol[(i, j)] = v;
            }
        }
        cholesky_in_place(&mut self.chol)
    }

    pub(super) fn unscale(&mut self) {
        for j in 0..self.variables() {
            self.x_out[j] = self.d[j] * self.x[j];
        }
        for i in 0..self.rows() {
            self.y_out[i] = self.e[i] * self.y[i] / self.c;
        }
    }

    /// `½ xᵀ P x + qᵀ x` + the soft penalties, at the unscaled solution.
    pub(super) fn objective(&mut self, q: &[f64], lower: &[f64], upper: &[f64]) -> f64 {
        // P x (scaled P, scaled x) is c D P x.
        self.work_n.gemv(1.0, &self.p, &self.x, 0.0);
        let mut f = 0.0;
        for (j, qj) in q.iter().enumerate() {
            f += 0.5 * self.x[j] * self.work_n[j] / self.c + qj * self.x_out[j];
        }
        self.g.mul(&self.x, &mut self.work_m);
        for i in 0..self.rows() {
            if let Some((w1, w2)) = self.soft[i] {
                let v = self.work_m[i] / self.e[i];
                let d = (lower[i] - v).max(v - upper[i]).max(0.0);
                // Unscale the weights: w1 = c linear / e, w2 = c quad / e².
                let (linear, quadratic) =
                    (w1 * self.e[i] / self.c, w2 * self.e[i].powi(2) / self.c);
                f += linear * d + 0.5 * quadratic * d * d;
            }
        }
        f
    }
}

/// The proximal operator of `w1 d + w2 d² / 2` (`d` the distance from
/// `[l, u]`) with step `1/ρ`, at `v`.
pub(super) fn soft_prox(v: f64, l: f64, u: f64, w1: f64, w2: f64, rho: f64) -> f64 {
    if v > u {
        u + (rho * (v - u) - w1).max(0.0) / (rho + w2)
    } else if v < l {
        l - (rho * (l - v) - w1).max(0.0) / (rho + w2)
    } else {
        v
    }
}
