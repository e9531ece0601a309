//! Polishing (OSQP's, extended to soft rows): guess which rows bind from
//! an ADMM iterate, solve the equality-constrained problem those rows
//! define exactly, and keep the answer only if it satisfies every
//! optimality condition. An iterate that has found the active set is
//! thereby turned into the exact optimum, usually long before ADMM alone
//! would reach its tolerance; a wrong guess costs one linear solve.

use nalgebra::DMatrix;

use super::DenseQp;
use super::kernels::{SparseRows, lu_in_place, lu_solve};

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
const ACTIVE_SET_STEPS: usize = 2;

/// Marks a variable neither fixed nor yet placed.
const NONE: usize = usize::MAX;

/// The polishing workspace, allocated once with the solver.
#[derive(Debug, Clone)]
pub(super) struct Polish {
    pub(super) state: Vec<State>,
    /// Per row: the objective's curvature along it, `gᵀ P g / ‖g‖⁴`
    /// (scaled problem), which turns a multiplier into a distance.
    pub(super) curvature: Vec<f64>,
    /// Per variable: the row that fixes it, or [`NONE`].
    fixed_by: Vec<usize>,
    /// Per variable: its index among the reduced system's unknowns.
    position: Vec<usize>,
    /// The general equality rows.
    equalities: Vec<usize>,
    /// The rows that fixed a variable, in the order they did.
    fix_order: Vec<usize>,
    /// The reduced KKT matrix (column major, leading dimension `n + m`),
    /// its pivots, right-hand side and scratch.
    kkt: Vec<f64>,
    perm: Vec<usize>,
    rhs: Vec<f64>,
    work: Vec<f64>,
    /// The candidate solution, its `G x`, multipliers, and the gradient.
    pub(super) x: Vec<f64>,
    pub(super) gx: Vec<f64>,
    /// The active-set method's iterate, its `G x` and working set.
    pub(super) current: Vec<f64>,
    pub(super) current_gx: Vec<f64>,
    pub(super) working: Vec<State>,
    /// Rows the active-set method may not free at present.
    pub(super) tabu: Vec<bool>,
    pub(super) y: Vec<f64>,
    grad: Vec<f64>,
}

impl Polish {
    /// The workspace for `n` variables and the rows of `g` with the
    /// (scaled) Hessian `p`.
    pub(super) fn new(p: &DMatrix<f64>, g: &SparseRows) -> Self {
        let (n, m) = (p.nrows(), g.start.len() - 1);
        let k = n + m;
        let curvature = (0..m)
            .map(|i| {
                let (a, b) = (g.start[i], g.start[i + 1]);
                let norm2: f64 = g.values[a..b].iter().map(|v| v * v).sum();
                let mut along = 0.0;
                for s in a..b {
                    for t in a..b {
                        along += g.values[s] * p[(g.cols[s], g.cols[t])] * g.values[t];
                    }
                }
                let c = along / (norm2 * norm2);
                // A row the objective is flat along (or an empty row).
                if c > 0.0 && c.is_finite() { c } else { 1.0 }
            })
            .collect();
        Self {
            state: vec![State::Free; m],
            curvature,
            fixed_by: vec![NONE; n],
            position: vec![NONE; n],
            equalities: Vec::with_capacity(m),
            fix_order: Vec::with_capacity(n),
            kkt: vec![0.0; k * k],
            perm: vec![0; k],
            rhs: vec![0.0; k],
            work: vec![0.0; k],
            x: vec![0.0; n],
            gx: vec![0.0; m],
            current: vec![0.0; n],
            current_gx: vec![0.0; m],
            working: vec![State::Free; m],
            tabu: vec![false; m],
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
            if self.recover_multipliers() && self.optimal() {
                break;
            }
            // A wrong guess is corrected from the candidate itself (a
            // primal-dual active-set step), a few times at most.
            step += 1;
            if step > ACTIVE_SET_STEPS || !self.reclassify() {
                return false;
            }
        }
        self.accept_candidate();
        true
    }

    /// The candidate (`polisher.x`, its multipliers) becomes the iterate,
    /// with z the rows' values (inside the hard bounds to the tolerance,
    /// clamped) so the next warm start continues from it.
    pub(super) fn accept_candidate(&mut self) {
        let w = &self.polisher;
        self.x.as_mut_slice().copy_from_slice(&w.x);
        self.y.as_mut_slice().copy_from_slice(&w.y);
        for i in 0..self.z.len() {
            self.z[i] = match self.soft[i] {
                None => w.gx[i].clamp(self.l[i], self.u[i]),
                Some(_) => w.gx[i],
            };
        }
    }

    /// OSQP's rule on hard rows (`u − z < y`: upper binds), and the soft
    /// rows by where `z` lies.
    fn guess_active_set(&mut self) {
        let w = &mut self.polisher;
        for i in 0..self.z.len() {
            // The multiplier as a distance in the row's units, and a row
            // at its bound to rounding (a clipped warm start, whose
            // multipliers are not known, binds where it was clipped).
            let y = self.y[i] / w.curvature[i];
            let (z, l, u) = (self.z[i], self.l[i], self.u[i]);
            let tie = 1e-9 * (1.0 + z.abs());
            w.state[i] = match self.soft[i] {
                None if u.is_finite() && u - z <= y + tie => State::Upper,
                None if l.is_finite() && z - l <= -y + tie => State::Lower,
                None => State::Free,
                Some(_) if z > u + tie => State::PenaltyUpper,
                Some(_) if z < l - tie => State::PenaltyLower,
                Some(_) if y > 0.0 && u - z < y => State::Upper,
                Some(_) if y < 0.0 && z - l < -y => State::Lower,
                Some(_) => State::Free,
            };
        }
    }

    /// The primal-dual active-set step (Hintermüller, Ito and Kunisch's,
    /// for the proximal form): each row's state from where `g x + y / c`
    /// of the failed candidate falls against its bounds (and, for a soft
    /// row, its bounds widened by `linear / c`), `c` the objective's
    /// curvature along the row (so `y / c` is a distance in the row's
    /// units). False if nothing changes, a cycle that more steps would not
    /// break.
    fn reclassify(&mut self) -> bool {
        let w = &mut self.polisher;
        let mut changed = false;
        for i in 0..self.z.len() {
            let (l, u, c) = (self.l[i], self.u[i], w.curvature[i]);
            let v = w.gx[i] + w.y[i] / c;
            let state = match self.soft[i] {
                None if v > u => State::Upper,
                None if v < l => State::Lower,
                None => State::Free,
                Some((w1, _)) if v > u + w1 / c => State::PenaltyUpper,
                Some(_) if v > u => State::Upper,
                Some((w1, _)) if v < l - w1 / c => State::PenaltyLower,
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
    pub(super) fn solve_reduced(&mut self) -> bool {
        let (n, m) = (self.variables(), self.rows());
        let w = &mut self.polisher;
        w.fixed_by.fill(NONE);
        w.equalities.clear();
        w.fix_order.clear();
        // Binding rows are equalities; those with one unknown left fix it,
        // which may leave another row with one (a rate limit's chain from
        // the input last applied up to the input limit): propagate until
        // nothing changes. A binding row with no unknown left duplicates
        // others (degenerate: its multiplier is theirs) and is dropped,
        // checked feasible later; singular KKT systems are thereby avoided
        // in the input-and-rate structure of an MPC.
        for i in 0..m {
            if matches!(w.state[i], State::Upper | State::Lower) {
                w.equalities.push(i);
            }
        }
        loop {
            let mut changed = false;
            let mut e = 0;
            while e < w.equalities.len() {
                let i = w.equalities[e];
                let (a, b) = (self.g.start[i], self.g.start[i + 1]);
                let mut unknown = NONE;
                let mut count = 0;
                let mut rest = if w.state[i] == State::Upper {
                    self.u[i]
                } else {
                    self.l[i]
                };
                for t in a..b {
                    let j = self.g.cols[t];
                    if w.fixed_by[j] == NONE {
                        count += 1;
                        unknown = t;
                    } else {
                        rest -= self.g.values[t] * w.x[j];
                    }
                }
                match count {
                    0 => {
                        w.state[i] = State::Dropped;
                        w.equalities.swap_remove(e);
                        changed = true;
                    }
                    1 => {
                        let j = self.g.cols[unknown];
                        w.x[j] = rest / self.g.values[unknown];
                        w.fixed_by[j] = i;
                        w.fix_order.push(i);
                        w.equalities.swap_remove(e);
                        changed = true;
                    }
                    _ => e += 1,
                }
            }
            if !changed {
                break;
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
    pub(super) fn recover_multipliers(&mut self) -> bool {
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
        // The fixing rows last to first: a row fixed later may involve a
        // variable fixed earlier, never the other way round, so each
        // row's variable has every other multiplier in its gradient.
        for f in (0..w.fix_order.len()).rev() {
            let i = w.fix_order[f];
            let (a, b) = (self.g.start[i], self.g.start[i + 1]);
            // A fixing row fixed one of its own variables.
            let Some(t) = (a..b).find(|&t| w.fixed_by[self.g.cols[t]] == i) else {
                return false;
            };
            let j = self.g.cols[t];
            let yi = -w.grad[j] / self.g.values[t];
            w.y[i] = yi;
            for t in a..b {
                w.grad[self.g.cols[t]] += self.g.values[t] * yi;
            }
        }
        true
    }

    /// The candidate's optimality: stationarity (the free variables'
    /// gradient, to the dual tolerance), feasibility of every row, and
    /// each multiplier's sign and range for its row's state, in the
    /// problem's unscaled units.
    pub(super) fn optimal(&self) -> bool {
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
