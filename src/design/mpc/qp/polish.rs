//! Polishing (OSQP's, extended to soft rows): guess which rows bind from
//! an ADMM iterate, solve the equality-constrained problem those rows
//! define exactly, and keep the answer only if it satisfies every
//! optimality condition. An iterate that has found the active set is
//! thereby turned into the exact optimum, usually long before ADMM alone
//! would reach its tolerance; a wrong guess costs one linear solve.

use super::DenseQp;
use super::kernels::{lu_in_place, lu_solve};

/// How a row binds in a polishing guess.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum State {
    /// Inside its bounds; multiplier 0.
    Free,
    /// At its upper bound (a hard row, or a soft one with a multiplier in
    /// `[0, linear]`).
    Upper,
    /// At its lower bound.
    Lower,
    /// A soft row beyond its upper bound: its penalty is in the objective.
    PenaltyUpper,
    /// A soft row beyond its lower bound.
    PenaltyLower,
    /// Binding, but on a variable another row already fixes (a duplicate):
    /// multiplier 0, checked feasible.
    Dropped,
}

/// Corrections of a polishing guess before it is given up (each one
/// linear solve).
const ACTIVE_SET_STEPS: usize = 6;

/// Marks a variable neither fixed nor yet placed.
const NONE: usize = usize::MAX;

/// The polishing workspace, allocated once with the solver.
#[derive(Debug, Clone)]
pub(super) struct Polish {
    state: Vec<State>,
    /// Per variable: the row that fixes it, or [`NONE`].
    fixed_by: Vec<usize>,
    /// Per variable: its index among the reduced system's unknowns.
    position: Vec<usize>,
    /// The general equality rows, in order.
    equalities: Vec<usize>,
    /// The reduced KKT matrix (column major, leading dimension `n + m`),
    /// its pivots, right-hand side and scratch.
    kkt: Vec<f64>,
    perm: Vec<usize>,
    rhs: Vec<f64>,
    work: Vec<f64>,
    /// The candidate solution, its `G x`, multipliers, and the gradient.
    x: Vec<f64>,
    gx: Vec<f64>,
    y: Vec<f64>,
    grad: Vec<f64>,
}

impl Polish {
    pub(super) fn new(n: usize, m: usize) -> Self {
        let k = n + m;
        Self {
            state: vec![State::Free; m],
            fixed_by: vec![NONE; n],
            position: vec![NONE; n],
            equalities: Vec::with_capacity(m),
            kkt: vec![0.0; k * k],
            perm: vec![0; k],
            rhs: vec![0.0; k],
            work: vec![0.0; k],
            x: vec![0.0; n],
            gx: vec![0.0; m],
            y: vec![0.0; m],
            grad: vec![0.0; n],
        }
    }
}

impl DenseQp {
    /// Polishes the current iterate (`x`, `z`, `y`, scaled): true, with the
    /// iterate replaced by the exact optimum, if the guessed active set
    /// passes every optimality check to the solver's tolerances.
    pub(super) fn polish(&mut self) -> bool {
        self.guess_active_set();
        let mut step = 0;
        loop {
            if !self.solve_reduced() {
                return false;
            }
            self.recover_multipliers();
            if self.optimal() {
                break;
            }
            // A wrong guess is corrected from the candidate itself (a
            // primal-dual active-set step), a few times at most.
            step += 1;
            if step > ACTIVE_SET_STEPS || !self.reclassify() {
                return false;
            }
        }
        // Accept: the iterate becomes the polished point, with z the rows'
        // values (inside the hard bounds to the tolerance, clamped) so the
        // next warm start continues from it.
        let w = &self.polisher;
        self.x.as_mut_slice().copy_from_slice(&w.x);
        self.y.as_mut_slice().copy_from_slice(&w.y);
        for i in 0..self.z.len() {
            self.z[i] = match self.soft[i] {
                None => w.gx[i].clamp(self.l[i], self.u[i]),
                Some(_) => w.gx[i],
            };
        }
        true
    }

    /// OSQP's rule on hard rows (`u − z < y`: upper binds), and the soft
    /// rows by where `z` lies.
    fn guess_active_set(&mut self) {
        let w = &mut self.polisher;
        for i in 0..self.z.len() {
            let (z, y, l, u) = (self.z[i], self.y[i], self.l[i], self.u[i]);
            w.state[i] = match self.soft[i] {
                None if u.is_finite() && u - z < y => State::Upper,
                None if l.is_finite() && z - l < -y => State::Lower,
                None => State::Free,
                Some(_) if z > u => State::PenaltyUpper,
                Some(_) if z < l => State::PenaltyLower,
                Some(_) if y > 0.0 && u - z < y => State::Upper,
                Some(_) if y < 0.0 && z - l < -y => State::Lower,
                Some(_) => State::Free,
            };
        }
    }

    /// The primal-dual active-set step (Hintermüller, Ito and Kunisch's,
    /// for the proximal form): each row's state from where `g x + y / ρ`
    /// of the failed candidate falls against its bounds (and, for a soft
    /// row, its bounds widened by `linear / ρ`). False if nothing changes,
    /// a cycle that more steps would not break.
    fn reclassify(&mut self) -> bool {
        let rho = self.rho;
        let w = &mut self.polisher;
        let mut changed = false;
        for i in 0..self.z.len() {
            let (l, u) = (self.l[i], self.u[i]);
            let v = w.gx[i] + w.y[i] / rho;
            let state = match self.soft[i] {
                None if v > u => State::Upper,
                None if v < l => State::Lower,
                None => State::Free,
                Some((w1, _)) if v > u + w1 / rho => State::PenaltyUpper,
                Some(_) if v > u => State::Upper,
                Some((w1, _)) if v < l - w1 / rho => State::PenaltyLower,
                Some(_) if v < l => State::Lower,
                Some(_) => State::Free,
            };
            // A dropped duplicate stays dropped while its twin binds.
            let same =
                state == w.state[i] || (w.state[i] == State::Dropped && state != State::Free);
            changed |= !same;
            w.state[i] = state;
        }
        changed
    }

    /// Solves the equality-constrained problem of the guess: binding rows
    /// with one entry fix their variable; the other binding rows are
    /// equalities; the penalised soft rows add their quadratic and linear
    /// terms. False if its KKT matrix is singular.
    fn solve_reduced(&mut self) -> bool {
        let (n, m) = (self.variables(), self.rows());
        let w = &mut self.polisher;
        w.fixed_by.fill(NONE);
        w.equalities.clear();
        for i in 0..m {
            let bound = match w.state[i] {
                State::Upper => self.u[i],
                State::Lower => self.l[i],
                _ => continue,
            };
            let (a, b) = (self.g.start[i], self.g.start[i + 1]);
            if b - a == 1 {
                let j = self.g.cols[a];
                if w.fixed_by[j] == NONE {
                    w.fixed_by[j] = i;
                    w.x[j] = bound / self.g.values[a];
                } else {
                    w.state[i] = State::Dropped;
                }
            } else {
                w.equalities.push(i);
            }
        }
        let mut k = 0;
        for j in 0..n {
            w.position[j] = if w.fixed_by[j] == NONE {
                k += 1;
                k - 1
            } else {
                NONE
            };
        }
        let free = k;
        let size = free + w.equalities.len();
        if size == 0 {
            return true;
        }
        let lda = n + m;
        // H = P + Σ_penalised w2 g gᵀ on the free variables; the linear
        // term and the fixed variables' contribution go to the right.
        for c in 0..size {
            for r in 0..size {
                w.kkt[r + c * lda] = 0.0;
            }
        }
        for j in 0..n {
            let pj = w.position[j];
            let mut rhs = -self.q[j];
            for jj in 0..n {
                let v = self.p[(j, jj)];
                match (pj, w.position[jj]) {
                    (NONE, _) => {}
                    (_, NONE) => rhs -= v * w.x[jj],
                    (a, b) => w.kkt[a + b * lda] += v,
                }
            }
            if pj != NONE {
                w.rhs[pj] = rhs;
            }
        }
        for i in 0..m {
            let (w1, w2) = match self.soft[i] {
                Some(weights) => weights,
                None => continue,
            };
            let (sign, bound) = match w.state[i] {
                State::PenaltyUpper => (1.0, self.u[i]),
                State::PenaltyLower => (-1.0, self.l[i]),
                _ => continue,
            };
            // Gradient of the penalty: w2 g gᵀ x + (±w1 − w2 bound) g.
            let (a, b) = (self.g.start[i], self.g.start[i + 1]);
            let linear = sign * w1 - w2 * bound;
            for e in a..b {
                let (j, gj) = (self.g.cols[e], self.g.values[e]);
                let pj = w.position[j];
                if pj == NONE {
                    continue;
                }
                w.rhs[pj] -= linear * gj;
                for f in a..b {
                    let (jj, gjj) = (self.g.cols[f], self.g.values[f]);
                    match w.position[jj] {
                        NONE => w.rhs[pj] -= w2 * gj * gjj * w.x[jj],
                        pjj => w.kkt[pj + pjj * lda] += w2 * gj * gjj,
                    }
                }
            }
        }
        // The equality rows: G_E,free x_free = bound − G_E,fixed x_fixed.
        for (e, &i) in w.equalities.iter().enumerate() {
            let r = free + e;
            let mut rhs = if w.state[i] == State::Upper {
                self.u[i]
            } else {
                self.l[i]
            };
            for t in self.g.start[i]..self.g.start[i + 1] {
                let (j, v) = (self.g.cols[t], self.g.values[t]);
                match w.position[j] {
                    NONE => rhs -= v * w.x[j],
                    pj => {
                        w.kkt[r + pj * lda] = v;
                        w.kkt[pj + r * lda] = v;
                    }
                }
            }
            w.rhs[r] = rhs;
        }
        if !lu_in_place(&mut w.kkt, lda, size, &mut w.perm) {
            return false;
        }
        lu_solve(&w.kkt, lda, size, &w.perm, &mut w.rhs, &mut w.work);
        for j in 0..n {
            if w.position[j] != NONE {
                w.x[j] = w.rhs[w.position[j]];
            }
        }
        w.rhs[..size].iter().all(|v| v.is_finite())
    }

    /// Every row's multiplier at the candidate: the equalities' from the
    /// solve, the fixing rows' from the stationarity of their variable,
    /// the penalised rows' from their penalty's slope, zero elsewhere.
    fn recover_multipliers(&mut self) {
        let (n, m) = (self.variables(), self.rows());
        let w = &mut self.polisher;
        let free = (0..n).filter(|&j| w.position[j] != NONE).count();
        w.y.fill(0.0);
        for (e, &i) in w.equalities.iter().enumerate() {
            w.y[i] = w.rhs[free + e];
        }
        // G x, and the penalised rows' multipliers ±(w1 + w2 d).
        for i in 0..m {
            let (a, b) = (self.g.start[i], self.g.start[i + 1]);
            w.gx[i] = (a..b).map(|t| self.g.values[t] * w.x[self.g.cols[t]]).sum();
            if let Some((w1, w2)) = self.soft[i] {
                match w.state[i] {
                    State::PenaltyUpper => w.y[i] = w1 + w2 * (w.gx[i] - self.u[i]),
                    State::PenaltyLower => w.y[i] = -(w1 + w2 * (self.l[i] - w.gx[i])),
                    _ => {}
                }
            }
        }
        // grad = P x + q + Gᵀ y over the rows with a multiplier so far;
        // a fixed variable's row takes up the rest.
        for j in 0..n {
            w.grad[j] = self.q[j] + (0..n).map(|jj| self.p[(j, jj)] * w.x[jj]).sum::<f64>();
        }
        for i in 0..m {
            let yi = w.y[i];
            if yi != 0.0 {
                for t in self.g.start[i]..self.g.start[i + 1] {
                    w.grad[self.g.cols[t]] += self.g.values[t] * yi;
                }
            }
        }
        for j in 0..n {
            let i = w.fixed_by[j];
            if i != NONE {
                let gij = self.g.values[self.g.start[i]];
                w.y[i] = -w.grad[j] / gij;
                w.grad[j] = 0.0;
            }
        }
    }

    /// The candidate's optimality: stationarity (the free variables'
    /// gradient, to the dual tolerance), feasibility of every row, and
    /// each multiplier's sign and range for its row's state, in the
    /// problem's unscaled units.
    fn optimal(&self) -> bool {
        let s = self.settings;
        let w = &self.polisher;
        let (n, m) = (self.variables(), self.rows());
        let mut dual_scale = 0.0f64;
        let mut dual = 0.0f64;
        for j in 0..n {
            let inv = 1.0 / (self.c * self.d[j]);
            dual = dual.max((w.grad[j] * inv).abs());
            dual_scale = dual_scale.max((self.q[j] * inv).abs());
        }
        let eps_dual = s.eps_abs + s.eps_rel * dual_scale;
        if dual.is_nan() || dual > eps_dual {
            return false;
        }
        for i in 0..m {
            // Unscaled: rows by E⁻¹, multipliers by E / c.
            let (inv, ys) = (1.0 / self.e[i], self.e[i] / self.c);
            let tol = s.eps_abs + s.eps_rel * (w.gx[i] * inv).abs();
            let above = (w.gx[i] - self.u[i]) * inv;
            let below = (self.l[i] - w.gx[i]) * inv;
            let y = w.y[i] * ys;
            let ytol = s.eps_abs + s.eps_rel * y.abs();
            let ok = match (w.state[i], self.soft[i]) {
                (State::Free | State::Dropped, _) => above <= tol && below <= tol,
                (State::Upper, None) => y >= -ytol && below <= tol,
                (State::Lower, None) => y <= ytol && above <= tol,
                (State::Upper, Some((w1, _))) => y >= -ytol && y <= w1 * ys + ytol,
                (State::Lower, Some((w1, _))) => y <= ytol && -y <= w1 * ys + ytol,
                (State::PenaltyUpper, _) => above >= -tol,
                (State::PenaltyLower, _) => below >= -tol,
            };
            if !ok || !y.is_finite() {
                return false;
            }
        }
        true
    }
}
