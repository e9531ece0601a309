//! [`DenseQp`]: a convex quadratic program solved again and again with new
//! data, as a model-predictive controller solves one every tick.
//!
//! The alternating-direction method of multipliers as OSQP (Stellato et
//! al., 2020) runs it: the problem is equilibrated (Ruiz) once, the
//! reduced KKT matrix `P + σI + ρ GᵀG` is factored once (and again only
//! when `ρ` adapts, at most once per solve, in place), and each iteration
//! is two triangular solves and two products with `G`, kept in compressed
//! rows so the identity and difference rows of an MPC's input limits cost
//! what they hold. Soft rows need no slack variables: their penalty's
//! proximal operator replaces the projection. Nothing is allocated after
//! [`DenseQp::new`].

mod active_set;
mod admm;
mod kernels;
mod polish;
mod settings;

use std::time::Instant;

use nalgebra::{DMatrix, DVector};

use crate::error::{Error, check_finite_dyn, check_shape};
pub use settings::{QpReport, QpSettings, QpStatus, Row};

/// Iterations between convergence checks.
const CHECK_INTERVAL: usize = 5;
/// Iterations between polishing attempts and step-size adaptations (a
/// multiple of [`CHECK_INTERVAL`]).
const POLISH_INTERVAL: usize = 10;
use kernels::{
    SparseRows, equilibrate, invalid, semidefinite, validate_problem, validate_settings,
};
use polish::Polish;

/// A convex quadratic program with fixed `P` and `G` and data that change
/// between solves,
///
/// ```text
/// minimise   ½ xᵀ P x + qᵀ x + Σ_soft penaltyᵢ(gᵢᵀ x)
/// subject to l ≤ G x ≤ u   (the hard rows)
/// ```
///
/// solved by ADMM (OSQP's iteration) with a dense factorisation, for the
/// small problems a controller solves every period (tens of variables,
/// a few hundred rows). `P` is symmetric positive semidefinite (`n × n`),
/// `G` is `m × n`, each row [`Row::Hard`] or [`Row::Soft`]; bounds may be
/// infinite. Each [`solve`](Self::solve) starts from the previous solution
/// and multipliers (a warm start), or from what
/// [`warm_start`](Self::warm_start) sets, and allocates nothing.
///
/// The answer is what OSQP's would be, to its tolerance: `tests/qp.rs`
/// checks it against OSQP's (itself checked against Clarabel and quadprog)
/// on random problems and random MPCs of the lab's size, solved with
/// explicit slack variables.
///
/// # Examples
///
/// Two variables, a hard box and one soft row:
///
/// ```
/// use ctrlab::design::mpc::{DenseQp, QpSettings, Row};
/// use ctrlab::nalgebra::{DMatrix, dmatrix};
///
/// let p = dmatrix![2.0, 0.0; 0.0, 2.0];
/// // |x₀| ≤ 1 and |x₁| ≤ 1 (hard), x₀ + x₁ ≤ 0 (soft, exact penalty).
/// let g = dmatrix![1.0, 0.0; 0.0, 1.0; 1.0, 1.0];
/// let rows = [Row::Hard, Row::Hard, Row::Soft { linear: 100.0, quadratic: 0.0 }];
/// let mut qp = DenseQp::new(&p, &g, &rows, QpSettings::default())?;
/// // Unconstrained, x = (2, 1). The soft row's penalty (100 per unit)
/// // is dearer than its slope at the boundary: the optimum lies on
/// // x₀ + x₁ = 0, at (0.5, −0.5), with the row's multiplier 3 ∈ [0, 100].
/// let report = qp.solve(&[-4.0, -2.0], &[-1.0, -1.0, f64::NEG_INFINITY], &[1.0, 1.0, 0.0])?;
/// assert!(report.status.is_solved());
/// let (x, y) = (qp.solution(), qp.multipliers());
/// assert!((x[0] - 0.5).abs() < 1e-9 && (x[1] + 0.5).abs() < 1e-9);
/// assert!((y[2] - 3.0).abs() < 1e-9 && (report.objective + 0.5).abs() < 1e-9);
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct DenseQp {
    settings: QpSettings,
    /// Scaled `P` (`c D P D`), and `GᵀG` scaled (`D Gᵀ E² G D`).
    p: DMatrix<f64>,
    gtg: DMatrix<f64>,
    g: SparseRows,
    /// Variable scaling `D`, row scaling `E`, cost scaling `c`.
    d: DVector<f64>,
    e: DVector<f64>,
    c: f64,
    /// Scaled soft penalties per row: `(linear, quadratic)`, `None` hard.
    soft: Vec<Option<(f64, f64)>>,
    rho: f64,
    /// Lower Cholesky factor of `P + σI + ρ GᵀG` (scaled).
    chol: DMatrix<f64>,
    // Iterates (scaled): x, z, y and the previous y.
    x: DVector<f64>,
    z: DVector<f64>,
    y: DVector<f64>,
    y_prev: DVector<f64>,
    // Work: scaled q, l, u; the x̃ and z̃ steps; buffers.
    q: DVector<f64>,
    l: DVector<f64>,
    u: DVector<f64>,
    xt: DVector<f64>,
    zt: DVector<f64>,
    work_n: DVector<f64>,
    work_m: DVector<f64>,
    /// The unscaled solution and multipliers.
    x_out: DVector<f64>,
    y_out: DVector<f64>,
    polisher: Polish,
    /// The active-set method's solves in the current solve.
    active_set_steps: usize,
}

impl DenseQp {
    /// The problem's fixed part: `p` (`n × n`, symmetric positive
    /// semidefinite), `g` (`m × n`) and each row's kind (`m` of them), with
    /// the solver's `settings`. Equilibrates and factors.
    ///
    /// # Errors
    ///
    /// [`Error::DimensionMismatch`] (`"P"`, `"G"`), [`Error::LengthMismatch`]
    /// (`"rows"`), [`Error::NonFinite`], [`Error::InvalidMatrix`] (`"P"` not
    /// symmetric or not positive semidefinite),
    /// [`Error::InvalidParameter`] for a setting out of its range or a
    /// negative or non-finite soft weight (`"linear"`, `"quadratic"`).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::design::mpc::{DenseQp, QpSettings, Row};
    /// use ctrlab::nalgebra::{DMatrix, dmatrix};
    /// let bad = DenseQp::new(&dmatrix![1.0, 2.0; 0.0, 1.0], &DMatrix::zeros(0, 2), &[],
    ///                        QpSettings::default());
    /// assert!(bad.is_err()); // P is not symmetric
    /// ```
    pub fn new(
        p: &DMatrix<f64>,
        g: &DMatrix<f64>,
        rows: &[Row],
        settings: QpSettings,
    ) -> Result<Self, Error> {
        let n = p.nrows();
        check_shape("P", p, n, n)?;
        check_shape("G", g, g.nrows(), n)?;
        let m = g.nrows();
        crate::error::check_len("rows", m, rows.len())?;
        check_finite_dyn("P", p)?;
        check_finite_dyn("G", g)?;
        validate_settings(&settings)?;
        validate_problem(p, rows)?;

        let (mut ps, mut gs) = (p.clone(), g.clone());
        let (d, e, c) = equilibrate(&mut ps, &mut gs);
        let soft = rows
            .iter()
            .zip(e.iter())
            .map(|(row, &ei)| match *row {
                Row::Hard => None,
                Row::Soft { linear, quadratic } => {
                    Some((c * linear / ei, c * quadratic / (ei * ei)))
                }
            })
            .collect();
        let gtg = gs.transpose() * &gs;
        if !gtg.iter().chain(ps.iter()).all(|v| v.is_finite()) {
            return Err(Error::Overflow {
                operation: "QP equilibration",
            });
        }
        let g_sparse = SparseRows::of(&gs);
        let polisher = Polish::new(&ps, &g_sparse);
        let mut qp = Self {
            settings,
            p: ps,
            gtg,
            g: g_sparse,
            d,
            e,
            c,
            soft,
            rho: settings.rho,
            chol: DMatrix::zeros(n, n),
            x: DVector::zeros(n),
            z: DVector::zeros(m),
            y: DVector::zeros(m),
            y_prev: DVector::zeros(m),
            q: DVector::zeros(n),
            l: DVector::zeros(m),
            u: DVector::zeros(m),
            xt: DVector::zeros(n),
            zt: DVector::zeros(m),
            work_n: DVector::zeros(n),
            work_m: DVector::zeros(m),
            x_out: DVector::zeros(n),
            y_out: DVector::zeros(m),
            polisher,
            active_set_steps: 0,
        };
        // P itself must be semidefinite: ρ GᵀG in the ADMM matrix can hide
        // an indefinite P (a nonconvex problem) from its factorisation.
        if !semidefinite(&qp.p, &mut qp.chol) || !qp.factor() {
            return Err(Error::InvalidMatrix {
                matrix: "P",
                reason: "must be positive semidefinite",
            });
        }
        Ok(qp)
    }

    /// Number of variables `n`.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::design::mpc::{DenseQp, QpSettings, Row};
    /// use ctrlab::nalgebra::{DMatrix, dmatrix};
    /// // Two variables under three rows (G is 3 × 2).
    /// let g = dmatrix![1.0, 0.0; 0.0, 1.0; 1.0, 1.0];
    /// let qp = DenseQp::new(&DMatrix::identity(2, 2), &g, &[Row::Hard; 3], QpSettings::default())?;
    /// assert_eq!(qp.variables(), 2);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn variables(&self) -> usize {
        self.x.len()
    }

    /// Number of rows `m`.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::design::mpc::{DenseQp, QpSettings, Row};
    /// use ctrlab::nalgebra::{DMatrix, dmatrix};
    /// let g = dmatrix![1.0, 0.0; 0.0, 1.0; 1.0, 1.0];
    /// let qp = DenseQp::new(&DMatrix::identity(2, 2), &g, &[Row::Hard; 3], QpSettings::default())?;
    /// assert_eq!(qp.rows(), g.nrows());
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn rows(&self) -> usize {
        self.z.len()
    }

    /// Solves with the linear cost `q` (`n`) and bounds `lower`, `upper`
    /// (`m` each, `lower ≤ upper`, `±∞` allowed), from the previous solve's
    /// solution and multipliers. Allocates nothing.
    ///
    /// # Errors
    ///
    /// [`Error::LengthMismatch`] (`"q"`, `"lower"`, `"upper"`),
    /// [`Error::InvalidData`] for a NaN, an infinite `q`, `lower > upper`,
    /// or a bound infinite on the wrong side (`lower = +∞`, `upper = −∞`;
    /// named by index); [`Error::Overflow`] if the answer would leave f64's
    /// range (the next solve then starts cold). An unsolved problem is not
    /// an error: the report's [`QpStatus`] says what happened.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::design::mpc::{DenseQp, QpSettings, QpStatus, Row};
    /// use ctrlab::nalgebra::DMatrix;
    /// let mut qp = DenseQp::new(&DMatrix::identity(1, 1), &DMatrix::identity(1, 1),
    ///                           &[Row::Hard], QpSettings::default())?;
    /// assert!(qp.solve(&[0.0], &[1.0], &[0.0]).is_err()); // l > u
    /// // Infeasible hard rows: x ≥ 1 and x ≤ −1 in one problem.
    /// let g = DMatrix::from_column_slice(2, 1, &[1.0, 1.0]);
    /// let mut qp = DenseQp::new(&DMatrix::identity(1, 1), &g, &[Row::Hard, Row::Hard],
    ///                           QpSettings::default())?;
    /// let report = qp.solve(&[0.0], &[1.0, f64::NEG_INFINITY], &[f64::INFINITY, -1.0])?;
    /// assert_eq!(report.status, QpStatus::PrimalInfeasible);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn solve(&mut self, q: &[f64], lower: &[f64], upper: &[f64]) -> Result<QpReport, Error> {
        let started = Instant::now();
        let (n, m) = (self.variables(), self.rows());
        crate::error::check_len("q", n, q.len())?;
        crate::error::check_len("lower", m, lower.len())?;
        crate::error::check_len("upper", m, upper.len())?;
        if let Some(index) = q.iter().position(|v| !v.is_finite()) {
            return Err(invalid("q", index, "must be finite"));
        }
        for i in 0..m {
            if lower[i].is_nan() || upper[i].is_nan() {
                return Err(invalid("bounds", i, "NaN bound"));
            }
            if lower[i] > upper[i] {
                return Err(invalid("bounds", i, "lower bound above the upper"));
            }
            // Two equal infinities pass `lower ≤ upper` but bound nothing.
            if lower[i] == f64::INFINITY || upper[i] == f64::NEG_INFINITY {
                return Err(invalid("bounds", i, "an infinite bound on the wrong side"));
            }
        }
        for (j, qj) in q.iter().enumerate() {
            self.q[j] = self.c * self.d[j] * qj;
        }
        for i in 0..m {
            self.l[i] = self.e[i] * lower[i];
            self.u[i] = self.e[i] * upper[i];
        }
        // A warm start's z projected onto the new bounds keeps the
        // iteration's invariant (z inside the set of the hard rows).
        self.g.mul(&self.x, &mut self.z);
        for i in 0..m {
            if self.soft[i].is_none() {
                self.z[i] = self.z[i].clamp(self.l[i], self.u[i]);
            }
        }

        let s = self.settings;
        let deadline = s.time_limit.map(|t| started + t);
        let mut status = QpStatus::IterationLimit;
        let mut iterations = 0;
        // A warm start whose binding rows are still the right ones is
        // optimal after one polish.
        self.active_set_steps = 0;
        let mut polished = s.polish && self.polish();
        // Else the active-set method from the warm start, when it holds
        // the hard rows.
        if !polished && s.active_set_steps > 0 {
            polished = self.active_set(s.active_set_steps, deadline);
        }
        if polished {
            status = QpStatus::Solved;
        }
        while !polished && iterations < s.max_iterations {
            if deadline.is_some_and(|d| Instant::now() >= d) {
                status = QpStatus::TimeLimit;
                break;
            }
            iterations += 1;
            self.y_prev.copy_from(&self.y);
            self.iterate();
            // The residuals cost as much as an iteration: checked every
            // few, and at the last.
            if iterations % CHECK_INTERVAL != 0 && iterations != s.max_iterations {
                continue;
            }
            let r = self.residuals();
            if r.prim <= s.eps_abs + s.eps_rel * r.prim_scale
                && r.dual <= s.eps_abs + s.eps_rel * r.dual_scale
            {
                status = QpStatus::Solved;
                // Exact on the active set if the polish holds.
                polished = s.polish && self.polish();
                break;
            }
            if self.infeasible() {
                status = QpStatus::PrimalInfeasible;
                break;
            }
            if iterations % POLISH_INTERVAL == 0 {
                // A polish costs several iterations: only with time left.
                if deadline.is_some_and(|d| Instant::now() >= d) {
                    status = QpStatus::TimeLimit;
                    break;
                }
                if s.polish && self.polish() {
                    status = QpStatus::Solved;
                    polished = true;
                    break;
                }
                if s.adaptive_rho {
                    self.adapt_rho(&r);
                }
            }
        }
        let r = self.residuals();
        self.unscale();
        let objective = self.objective(q, lower, upper);
        let finite = [r.prim, r.dual, objective].iter().all(|v| v.is_finite())
            && self
                .x_out
                .iter()
                .chain(self.y_out.iter())
                .all(|v| v.is_finite());
        if !finite {
            // Finite data far beyond what the scaling brings to order one
            // (an optimum beyond f64's range) is no answer; the next solve
            // starts afresh.
            self.cold_start();
            self.x_out.fill(0.0);
            self.y_out.fill(0.0);
            return Err(Error::Overflow {
                operation: "QP solve",
            });
        }
        Ok(QpReport {
            status,
            iterations,
            primal_residual: r.prim,
            dual_residual: r.dual,
            objective,
            rho: self.rho,
            polished,
            active_set_steps: self.active_set_steps,
        })
    }

    /// The solution of the last solve (`n`, the problem's units).
    ///
    /// # Examples
    ///
    /// min ½ x² − 2 x subject to x ≤ 1: the bound holds the optimum at 1.
    ///
    /// ```
    /// use ctrlab::design::mpc::{DenseQp, QpSettings, Row};
    /// use ctrlab::nalgebra::DMatrix;
    /// let one = DMatrix::identity(1, 1);
    /// let mut qp = DenseQp::new(&one, &one, &[Row::Hard], QpSettings::default())?;
    /// qp.solve(&[-2.0], &[f64::NEG_INFINITY], &[1.0])?;
    /// assert!((qp.solution()[0] - 1.0).abs() < 1e-9);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn solution(&self) -> &[f64] {
        self.x_out.as_slice()
    }

    /// The multipliers of the rows at the last solve (`m`): positive where
    /// an upper bound binds, negative where a lower one does.
    ///
    /// # Examples
    ///
    /// min ½ x² − 2 x subject to x ≤ 1: the upper bound binds, and its
    /// multiplier is the cost's slope there, `P x + q + y = 0`, so `y = 1`.
    ///
    /// ```
    /// use ctrlab::design::mpc::{DenseQp, QpSettings, Row};
    /// use ctrlab::nalgebra::DMatrix;
    /// let one = DMatrix::identity(1, 1);
    /// let mut qp = DenseQp::new(&one, &one, &[Row::Hard], QpSettings::default())?;
    /// qp.solve(&[-2.0], &[f64::NEG_INFINITY], &[1.0])?;
    /// assert!((qp.multipliers()[0] - 1.0).abs() < 1e-9);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn multipliers(&self) -> &[f64] {
        self.y_out.as_slice()
    }

    /// Starts the next solve from `x` (`n`) with the multipliers `y` (`m`),
    /// or zero multipliers if `None` (an MPC's shifted plan).
    ///
    /// # Errors
    ///
    /// [`Error::LengthMismatch`]; [`Error::InvalidData`] for a non-finite
    /// entry.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::design::mpc::{DenseQp, QpSettings, Row};
    /// use ctrlab::nalgebra::DMatrix;
    /// let mut qp = DenseQp::new(&DMatrix::identity(1, 1), &DMatrix::identity(1, 1),
    ///                           &[Row::Hard], QpSettings::default())?;
    /// qp.warm_start(&[0.3], None)?;
    /// let cold = qp.solve(&[-0.3], &[-1.0], &[1.0])?; // x = 0.3 is optimal already
    /// assert!(cold.iterations <= 3);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn warm_start(&mut self, x: &[f64], y: Option<&[f64]>) -> Result<(), Error> {
        crate::error::check_len("x", self.variables(), x.len())?;
        if let Some(index) = x.iter().position(|v| !v.is_finite()) {
            return Err(invalid("x", index, "must be finite"));
        }
        if let Some(y) = y {
            crate::error::check_len("y", self.rows(), y.len())?;
            if let Some(index) = y.iter().position(|v| !v.is_finite()) {
                return Err(invalid("y", index, "must be finite"));
            }
        }
        for (j, xj) in x.iter().enumerate() {
            self.x[j] = xj / self.d[j];
        }
        for i in 0..self.rows() {
            self.y[i] = y.map_or(0.0, |y| y[i] / self.e[i] * self.c);
        }
        Ok(())
    }

    /// Forgets the last solution: the next solve starts from zero.
    ///
    /// # Examples
    ///
    /// The start changes the work, not the answer:
    ///
    /// ```
    /// use ctrlab::design::mpc::{DenseQp, QpSettings, Row};
    /// use ctrlab::nalgebra::DMatrix;
    /// let one = DMatrix::identity(1, 1);
    /// let mut qp = DenseQp::new(&one, &one, &[Row::Hard], QpSettings::default())?;
    /// qp.solve(&[-2.0], &[f64::NEG_INFINITY], &[1.0])?;
    /// let warm = qp.solution()[0];
    /// qp.cold_start();
    /// assert!(qp.solve(&[-2.0], &[f64::NEG_INFINITY], &[1.0])?.status.is_solved());
    /// assert!((qp.solution()[0] - warm).abs() < 1e-9);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn cold_start(&mut self) {
        self.x.fill(0.0);
        self.y.fill(0.0);
    }
}
