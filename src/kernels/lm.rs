//! Levenberg–Marquardt for nonlinear least squares, `min ½‖f(x)‖²`: the
//! algorithm of MINPACK's `lmder` (Moré, "The Levenberg–Marquardt
//! algorithm: implementation and theory", 1978; Moré, Garbow and
//! Hillstrom, MINPACK-1, 1980), written here on nalgebra.
//!
//! Each iteration factors the Jacobian by Householder QR with column
//! pivoting (`qrfac`), chooses the Levenberg–Marquardt parameter that puts
//! the scaled step `‖D p‖` on the trust-region radius `Δ` by a safeguarded
//! Newton iteration (`lmpar`), solving each damped system from the QR
//! factors with Givens rotations (`qrsolv`), and accepts the step when the
//! actual reduction of the cost is at least 1e-4 of the predicted one. The
//! scaling `D` starts at the Jacobian's column norms and keeps the largest
//! seen; `Δ` starts at `factor · ‖D x₀‖`. It stops on MINPACK's tests:
//! relative reduction of the cost (`ftol`), relative size of the step
//! (`xtol`), cosine between the residuals and the Jacobian's columns
//! (`gtol`), or `patience · (n + 1)` residual evaluations.
//!
//! Why here: `lab::ident::refine` used the `levenberg-marquardt` crate
//! (itself a port of MINPACK), whose latest release is built on nalgebra
//! 0.34, a second nalgebra (with simba, wide and safe_arch) beside the
//! crate's 0.35. This kernel keeps one nalgebra in the tree. It differs
//! from MINPACK only where MINPACK would compute with non-finite numbers or
//! divide by a zero cost: it stops with [`Termination::NonFinite`] on
//! non-finite residuals at the start, a non-finite Jacobian or step, treats
//! a non-finite trial cost as a failed step, and stops at once when the
//! residuals' norm falls below the smallest normal number. `enorm`'s
//! thresholds are those of IEEE doubles rather than MINPACK's constants.

use nalgebra::{DMatrix, DVector};

/// A least-squares problem: `m` residuals of `n` parameters.
pub(crate) trait LeastSquaresProblem {
    /// `m`, the number of residuals (at least the number of parameters).
    fn residual_count(&self) -> usize;
    /// Writes the residuals at `x` to `out` (`m` rows); `false` stops the
    /// optimiser ([`Termination::Aborted`]).
    fn residuals(&mut self, x: &DVector<f64>, out: &mut DVector<f64>) -> bool;
    /// Writes the Jacobian at `x` to `out` (`m × n`, zeroed on entry);
    /// `false` stops the optimiser. It is only asked for at the point of
    /// the latest [`residuals`](Self::residuals) call.
    fn jacobian(&mut self, x: &DVector<f64>, out: &mut DMatrix<f64>) -> bool;
}

/// The optimiser's tolerances and limits: it stops when the actual and
/// predicted relative reductions of the cost are both at most `ftol`, when
/// the trust region's radius is at most `xtol · ‖D x‖`, when the cosine
/// between the residuals and every column of the Jacobian is at most
/// `gtol`, or after `patience · (n + 1)` residual evaluations (MINPACK's
/// `maxfev`, the start's included). The first radius is `factor · ‖D x₀‖`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Settings {
    pub ftol: f64,
    pub xtol: f64,
    pub gtol: f64,
    pub factor: f64,
    pub patience: usize,
}

impl Settings {
    fn valid(&self) -> bool {
        let tolerances = [self.ftol, self.xtol, self.gtol];
        tolerances.iter().all(|t| *t >= 0.0)
            && self.factor > 0.0
            && self.factor.is_finite()
            && self.patience > 0
    }
}

impl Default for Settings {
    /// MINPACK's `lmder1`: `ftol = xtol = √ε`, `gtol = 0`, `factor = 100`,
    /// `maxfev = 100 (n + 1)`.
    fn default() -> Self {
        Settings {
            ftol: f64::EPSILON.sqrt(),
            xtol: f64::EPSILON.sqrt(),
            gtol: 0.0,
            factor: 100.0,
            patience: 100,
        }
    }
}

/// Why the optimiser stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Termination {
    /// The `ftol` or `xtol` test passed (MINPACK's `info` 1, 2, 3).
    Converged { ftol: bool, xtol: bool },
    /// The residuals are orthogonal to the Jacobian's columns to within
    /// `gtol` (`info` 4).
    Orthogonal,
    /// The residuals are zero.
    ResidualsZero,
    /// `patience · (n + 1)` residual evaluations (`info` 5).
    LostPatience,
    /// The `"ftol"`, `"xtol"` or `"gtol"` test passed at machine precision
    /// (`info` 6, 7, 8): the tolerance is too small.
    NoImprovementPossible(&'static str),
    /// Non-finite residuals at the start, Jacobian, step or factors.
    NonFinite(&'static str),
    /// The problem returned `false`.
    Aborted(&'static str),
    /// No parameters, fewer residuals than them, a non-finite start,
    /// settings out of range, or residuals or a Jacobian of the wrong size.
    InvalidInput(&'static str),
}

impl Termination {
    /// The result is not one to use: the problem or the settings are at
    /// fault (as the `levenberg-marquardt` crate's `was_usage_issue`, with
    /// non-finite numbers and aborts added).
    pub(crate) fn was_usage_issue(&self) -> bool {
        matches!(
            self,
            Termination::NoImprovementPossible(_)
                | Termination::NonFinite(_)
                | Termination::Aborted(_)
                | Termination::InvalidInput(_)
        )
    }
}

/// The result of [`minimize`].
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Report {
    pub termination: Termination,
    /// Residual evaluations, the starting point's included.
    pub evaluations: usize,
    /// The best point found (the start when no step was accepted).
    pub x: DVector<f64>,
    /// `½‖f(x)‖²` there (NaN when the start's residuals were not finite).
    #[cfg_attr(
        not(test),
        allow(dead_code, reason = "refine validates its result instead")
    )]
    pub objective: f64,
}

pub(super) const EPSMCH: f64 = f64::EPSILON;
pub(super) const DWARF: f64 = f64::MIN_POSITIVE;

/// Minimises `½‖f(x)‖²` from `x0`. The work is bounded: at most
/// `patience · (n + 1)` residual evaluations and one Jacobian per
/// accepted step; never panics on any problem or settings.
pub(crate) fn minimize<P: LeastSquaresProblem + ?Sized>(
    problem: &mut P,
    x0: &DVector<f64>,
    settings: &Settings,
) -> Report {
    let n = x0.len();
    let m = problem.residual_count();
    let mut report = Report {
        termination: Termination::ResidualsZero,
        evaluations: 0,
        x: x0.clone(),
        objective: f64::NAN,
    };
    let s = settings;
    let invalid = [
        (n == 0, "no parameters"),
        (m < n, "fewer residuals than parameters"),
        (x0.iter().any(|v| !v.is_finite()), "a non-finite start"),
        (!settings.valid(), "settings out of range"),
    ];
    if let Some((_, reason)) = invalid.iter().find(|(bad, _)| *bad) {
        return report.ending(Termination::InvalidInput(reason));
    }
    let max_evaluations = s.patience.saturating_mul(n + 1);

    let mut fvec = DVector::zeros(m);
    report.evaluations = 1;
    if !problem.residuals(&report.x, &mut fvec) {
        return report.ending(Termination::Aborted("residuals"));
    }
    if fvec.len() != m {
        return report.ending(Termination::InvalidInput("residuals of another length"));
    }
    let mut fnorm = enorm(fvec.as_slice());
    if !fnorm.is_finite() {
        return report.ending(Termination::NonFinite("residuals at the start"));
    }
    report.objective = 0.5 * fnorm * fnorm;
    if fnorm <= DWARF {
        return report;
    }

    let mut w = Work::new(m, n);
    let mut trial = DVector::zeros(n);
    let mut ftrial = DVector::zeros(m);
    let (mut par, mut delta, mut xnorm) = (0.0, 0.0, 0.0);
    // MINPACK's `iter == 1`: no step accepted yet.
    let mut first = true;
    loop {
        w.jac.fill(0.0);
        if !problem.jacobian(&report.x, &mut w.jac) {
            return report.ending(Termination::Aborted("jacobian"));
        }
        if w.jac.shape() != (m, n) {
            return report.ending(Termination::InvalidInput("a Jacobian of another shape"));
        }
        if w.jac.iter().any(|v| !v.is_finite()) {
            return report.ending(Termination::NonFinite("jacobian"));
        }
        w.factor(fvec.as_slice());
        if first {
            for (d, a) in w.diag.iter_mut().zip(&w.acnorm) {
                *d = if *a != 0.0 { *a } else { 1.0 };
            }
            xnorm = scaled_norm(&w.diag, report.x.as_slice(), &mut w.wa3);
            delta = s.factor * xnorm;
            if delta == 0.0 {
                delta = s.factor;
            }
        }
        // The largest cosine between the residuals and a column.
        let mut gnorm: f64 = 0.0;
        for j in 0..n {
            let l = w.ipvt[j];
            if w.acnorm[l] != 0.0 {
                let sum: f64 = (0..=j).map(|i| w.r[(i, j)] * (w.qtf[i] / fnorm)).sum();
                gnorm = gnorm.max((sum / w.acnorm[l]).abs());
            }
        }
        let factors = [gnorm, xnorm].into_iter().chain(w.rdiag.iter().copied());
        if factors.chain(w.qtf.iter().copied()).any(|v| !v.is_finite()) {
            return report.ending(Termination::NonFinite("QR factors"));
        }
        if gnorm <= s.gtol {
            return report.ending(Termination::Orthogonal);
        }
        for (d, a) in w.diag.iter_mut().zip(&w.acnorm) {
            *d = d.max(*a);
        }

        loop {
            par = w.lmpar(delta, par);
            // The step p = −wa1, the trial point x + p, and ‖D p‖.
            for j in 0..n {
                w.wa1[j] = -w.wa1[j];
                trial[j] = report.x[j] + w.wa1[j];
            }
            let pnorm = scaled_norm(&w.diag, &w.wa1, &mut w.wa3);
            if !(pnorm.is_finite() && par.is_finite()) {
                return report.ending(Termination::NonFinite("trust-region step"));
            }
            if first {
                delta = delta.min(pnorm);
            }
            report.evaluations += 1;
            if !problem.residuals(&trial, &mut ftrial) {
                return report.ending(Termination::Aborted("residuals"));
            }
            if ftrial.len() != m {
                return report.ending(Termination::InvalidInput("residuals of another length"));
            }
            // A non-finite trial cost fails as an infinite one would.
            let fnorm1 = enorm(ftrial.as_slice());
            let worse = fnorm1.is_nan() || 0.1 * fnorm1 >= fnorm;
            let actred = if worse {
                -1.0
            } else {
                1.0 - (fnorm1 / fnorm).powi(2)
            };
            // Predicted reduction and directional derivative from R Pᵀ p.
            for j in 0..n {
                w.wa3[j] = 0.0;
                let temp = w.wa1[w.ipvt[j]];
                for i in 0..=j {
                    w.wa3[i] += w.r[(i, j)] * temp;
                }
            }
            let temp1 = enorm(&w.wa3) / fnorm;
            let temp2 = (par.sqrt() * pnorm) / fnorm;
            let prered = temp1 * temp1 + temp2 * temp2 / 0.5;
            let dirder = -(temp1 * temp1 + temp2 * temp2);
            let ratio = if prered != 0.0 { actred / prered } else { 0.0 };

            if ratio <= 0.25 {
                let mut temp = if actred >= 0.0 {
                    0.5
                } else {
                    0.5 * dirder / (dirder + 0.5 * actred)
                };
                if worse || temp < 0.1 {
                    temp = 0.1;
                }
                delta = temp * delta.min(pnorm / 0.1);
                par /= temp;
            } else if par == 0.0 || ratio >= 0.75 {
                delta = pnorm / 0.5;
                par *= 0.5;
            }

            let accepted = ratio >= 1e-4;
            if accepted {
                report.x.copy_from(&trial);
                fvec.copy_from(&ftrial);
                xnorm = scaled_norm(&w.diag, report.x.as_slice(), &mut w.wa3);
                fnorm = fnorm1;
                report.objective = 0.5 * fnorm * fnorm;
                first = false;
                if !xnorm.is_finite() {
                    return report.ending(Termination::NonFinite("parameters"));
                }
                if fnorm <= DWARF {
                    return report.ending(Termination::ResidualsZero);
                }
            }

            let ftol = actred.abs() <= s.ftol && prered <= s.ftol && 0.5 * ratio <= 1.0;
            let xtol = delta <= s.xtol * xnorm;
            if ftol || xtol {
                return report.ending(Termination::Converged { ftol, xtol });
            }
            // MINPACK's order: a later test overrides an earlier one.
            let stop = if gnorm <= EPSMCH {
                Termination::NoImprovementPossible("gtol")
            } else if delta <= EPSMCH * xnorm {
                Termination::NoImprovementPossible("xtol")
            } else if actred.abs() <= EPSMCH && prered <= EPSMCH && 0.5 * ratio <= 1.0 {
                Termination::NoImprovementPossible("ftol")
            } else if report.evaluations >= max_evaluations {
                Termination::LostPatience
            } else if accepted {
                break;
            } else {
                continue;
            };
            return report.ending(stop);
        }
    }
}

impl Report {
    fn ending(mut self, termination: Termination) -> Report {
        self.termination = termination;
        self
    }
}

/// `‖D v‖`, with `out` as scratch.
pub(super) fn scaled_norm(diag: &[f64], v: &[f64], out: &mut [f64]) -> f64 {
    for ((o, d), v) in out.iter_mut().zip(diag).zip(v) {
        *o = d * v;
    }
    enorm(out)
}

/// The Euclidean norm without overflow or destructive underflow: MINPACK's
/// `enorm`, which sums the squares of small, intermediate and large
/// components separately (the bounds `√(smallest normal)` and
/// `√(largest) / len` for IEEE doubles).
pub(crate) fn enorm(v: &[f64]) -> f64 {
    let rdwarf = DWARF.sqrt();
    let agiant = f64::MAX.sqrt() / v.len() as f64;
    let (mut s1, mut s2, mut s3) = (0.0f64, 0.0f64, 0.0f64);
    let (mut x1max, mut x3max) = (0.0f64, 0.0f64);
    for &x in v {
        let xabs = x.abs();
        if xabs > rdwarf && xabs < agiant {
            s2 += xabs * xabs;
        } else if xabs <= rdwarf {
            if xabs > x3max {
                s3 = 1.0 + s3 * (x3max / xabs).powi(2);
                x3max = xabs;
            } else if xabs != 0.0 {
                s3 += (xabs / x3max).powi(2);
            }
        } else if xabs > x1max {
            s1 = 1.0 + s1 * (x1max / xabs).powi(2);
            x1max = xabs;
        } else {
            // Also NaN, which then propagates.
            s1 += (xabs / x1max).powi(2);
        }
    }
    if s1 != 0.0 {
        x1max * (s1 + (s2 / x1max) / x1max).sqrt()
    } else if s2 != 0.0 {
        if s2 >= x3max {
            (s2 * (1.0 + (x3max / s2) * (x3max * s3))).sqrt()
        } else {
            (x3max * ((s2 / x3max) + (x3max * s3))).sqrt()
        }
    } else {
        x3max * s3.sqrt()
    }
}

mod work;
use work::Work;

#[cfg(test)]
mod tests;
