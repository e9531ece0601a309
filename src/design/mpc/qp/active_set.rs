//! A primal active-set method for the same problem (Nocedal and Wright's
//! Algorithm 16.3, with the soft rows' breakpoints as constraints that
//! block a step): from a warm start that satisfies the hard rows, each
//! step solves the equality-constrained problem of the working set, moves
//! toward its solution until a row blocks, and frees the row whose
//! multiplier is most wrong once a full step lands. Every step lowers the
//! objective or changes the working set by one row, so it ends at the
//! optimum in a number of steps that is the number of rows that change —
//! few from a plan shifted by a period, where ADMM needs hundreds of
//! iterations after a step of the reference.

use super::DenseQp;
use super::polish::State;

/// A row's state in the working set: binding ones are the equalities of
/// the next step.
fn binding(state: State) -> bool {
    matches!(state, State::Upper | State::Lower)
}

impl DenseQp {
    /// Runs the active-set method from the current iterate `x` (scaled) for
    /// at most `steps` linear solves; true with the iterate replaced by the
    /// optimum, false (iterate untouched) if `x` violates a hard row or the
    /// steps run out.
    pub(super) fn active_set(&mut self, steps: usize) -> bool {
        self.active_set_steps = 0;
        let m = self.rows();
        let tol = self.settings.eps_abs;
        // Where the start is: G x, its working set, and feasibility.
        self.g.mul(&self.x, &mut self.work_m);
        let w = &mut self.polisher;
        w.current.copy_from_slice(self.x.as_slice());
        for i in 0..m {
            let (v, l, u) = (self.work_m[i], self.l[i], self.u[i]);
            let tie = 1e-9 * (1.0 + v.abs());
            let hard = self.soft[i].is_none();
            if hard && (v > u + tol || v < l - tol) {
                return false;
            }
            w.current_gx[i] = v;
            w.working[i] = match () {
                _ if (v - u).abs() <= tie => State::Upper,
                _ if (v - l).abs() <= tie => State::Lower,
                _ if !hard && v > u => State::PenaltyUpper,
                _ if !hard && v < l => State::PenaltyLower,
                _ => State::Free,
            };
        }
        // The row freed last: blocked by it again at once, its multiplier
        // was one of many at a degenerate vertex (a rate limit's chain
        // meeting the input limit), so it goes back and is not freed again
        // until a step makes progress; another row is freed instead.
        let mut freed = usize::MAX;
        self.polisher.tabu.fill(false);
        for _ in 0..steps {
            self.active_set_steps += 1;
            let w = &mut self.polisher;
            w.state.copy_from_slice(&w.working);
            if !self.solve_reduced() || !self.recover_multipliers() {
                return false;
            }
            // A binding row the others already determine (a duplicate the
            // solve dropped) leaves the working set: the rows kept are
            // independent, so their multipliers are unique and a wrong
            // sign means what it says.
            let w = &mut self.polisher;
            for i in 0..m {
                if w.state[i] == State::Dropped {
                    w.working[i] = State::Free;
                }
            }
            // The largest step toward the candidate that no row blocks.
            let (mut alpha, mut block) = (1.0f64, None);
            for i in 0..m {
                let (from, to) = (w.current_gx[i], w.gx[i]);
                let d = to - from;
                // A row the step leaves where it is to rounding does not
                // block (a dependent one, in exact arithmetic, never does).
                if d.abs() <= 1e-12 * (1.0 + from.abs()) || binding(w.working[i]) {
                    continue;
                }
                let (l, u) = (self.l[i], self.u[i]);
                // The bound the row would cross, and the state it takes.
                let crossing = match w.working[i] {
                    State::Free if d > 0.0 && u.is_finite() => Some((u, State::Upper)),
                    State::Free if d < 0.0 && l.is_finite() => Some((l, State::Lower)),
                    State::PenaltyUpper if d < 0.0 => Some((u, State::Upper)),
                    State::PenaltyLower if d > 0.0 => Some((l, State::Lower)),
                    _ => None,
                };
                if let Some((bound, state)) = crossing {
                    let t = ((bound - from) / d).max(0.0);
                    if t < alpha {
                        alpha = t;
                        block = Some((i, state));
                    }
                }
            }
            for j in 0..w.current.len() {
                w.current[j] += alpha * (w.x[j] - w.current[j]);
            }
            // A step that moves no row by more than rounding makes no
            // progress (a full step to where the iterate already is).
            let mut moved = 0.0f64;
            for i in 0..m {
                let step = alpha * (w.gx[i] - w.current_gx[i]);
                moved = moved.max(step.abs() / (1.0 + w.current_gx[i].abs()));
                w.current_gx[i] += step;
            }
            let progress = moved > 1e-9;
            if progress {
                w.tabu.fill(false);
            }
            if let Some((i, state)) = block {
                if i == freed && !progress {
                    w.tabu[i] = true;
                }
                w.working[i] = state;
                continue;
            }
            // A full step: the candidate is the minimiser on the working
            // set. Free the row whose multiplier is most wrong, or stop.
            let mut worst: Option<(usize, State, f64)> = None;
            for i in 0..m {
                let y = w.y[i];
                let change = match (w.working[i], self.soft[i]) {
                    (State::Upper, None) if y < 0.0 => Some((State::Free, -y)),
                    (State::Lower, None) if y > 0.0 => Some((State::Free, y)),
                    (State::Upper, Some(_)) if y < 0.0 => Some((State::Free, -y)),
                    (State::Upper, Some((w1, _))) if y > w1 => Some((State::PenaltyUpper, y - w1)),
                    (State::Lower, Some(_)) if y > 0.0 => Some((State::Free, y)),
                    (State::Lower, Some((w1, _))) if -y > w1 => {
                        Some((State::PenaltyLower, -y - w1))
                    }
                    _ => None,
                };
                if let Some((state, by)) = change.filter(|_| !w.tabu[i]) {
                    // In the row's units, as the polish compares them.
                    let by = by / w.curvature[i];
                    if worst.is_none_or(|(_, _, b)| by > b) {
                        worst = Some((i, state, by));
                    }
                }
            }
            match worst {
                Some((i, state, by)) if by > tol => {
                    w.working[i] = state;
                    freed = i;
                }
                _ => {
                    if self.optimal() {
                        self.accept_candidate();
                        return true;
                    }
                    return false;
                }
            }
        }
        false
    }
}
