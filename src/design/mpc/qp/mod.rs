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

use nalgebra::{DMatrix, DVector};

use crate::error::{Error, check_finite_dyn, check_shape};
/// Iterations between convergence checks.
const CHECK_INTERVAL: usize = 5;
/// Iterations between polishing attempts and step-size adaptations (a
/// multiple of [`CHECK_INTERVAL`]).
const POLISH_INTERVAL: usize = 10;
use kernels::{SparseRows, equilibrate, validate_settings};
use polish::Polish;

/// How a row `lᵢ ≤ gᵢᵀ x ≤ uᵢ` of the constraints binds.
///
/// # Examples
///
/// ```
/// use ctrlab::design::mpc::Row;
/// let travel = Row::Soft { linear: 1e4, quadratic: 1e6 };
/// assert_ne!(travel, Row::Hard);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Row {
    /// Must hold (to the solver's tolerance).
    Hard,
    /// May be violated at a cost added to the objective:
    /// `linear · d + quadratic · d² / 2`, where `d` is the distance of
    /// `gᵢᵀ x` from `[lᵢ, uᵢ]` (in the row's units). A linear weight above
    /// the row's Lagrange multiplier makes the penalty exact: the row then
    /// holds whenever it can.
    Soft {
        /// Cost per unit of violation, ≥ 0.
        linear: f64,
        /// Cost per squared unit of violation (times ½), ≥ 0.
        quadratic: f64,
    },
}

/// The solver's settings. The defaults are OSQP's, but for a tighter
/// tolerance and a convergence check every iteration (the problems are
/// small, so the check is cheap against a wasted iteration).
///
/// # Examples
///
/// ```
/// use ctrlab::design::mpc::QpSettings;
/// let s = QpSettings { max_iterations: 50, ..QpSettings::default() };
/// assert_eq!((s.max_iterations, s.alpha), (50, 1.6));
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct QpSettings {
    /// Iterations per solve at most (a hard bound on its time), ≥ 1.
    pub max_iterations: usize,
    /// Absolute tolerance on the primal and dual residuals (the problem's
    /// units), > 0.
    pub eps_abs: f64,
    /// Relative tolerance on the residuals, ≥ 0.
    pub eps_rel: f64,
    /// Tolerance of the primal-infeasibility certificate, > 0.
    pub eps_infeasible: f64,
    /// The initial step size `ρ`, > 0.
    pub rho: f64,
    /// The proximal weight `σ` that keeps `P + σI` definite, > 0.
    pub sigma: f64,
    /// Over-relaxation, in (0, 2).
    pub alpha: f64,
    /// Whether `ρ` adapts to the ratio of the residuals (OSQP's rule,
    /// checked every 10 iterations; a refactorisation of the `n × n` KKT
    /// matrix, only when `ρ` would change fivefold).
    pub adaptive_rho: bool,
    /// Whether to polish: from the warm start and every 10 iterations,
    /// guess the binding rows, solve the equality-constrained problem
    /// they define exactly, and stop there if it passes every optimality
    /// check (a solve of at most `n + m` unknowns each time).
    pub polish: bool,
    /// Linear solves the primal active-set method may take from a warm
    /// start that holds the hard rows, before ADMM (0: none). Each changes
    /// the working set by one row, so a warm start a few rows from the
    /// optimum (a plan shifted by a period, even after a step of the
    /// reference) is solved exactly in that many.
    pub active_set_steps: usize,
}

impl Default for QpSettings {
    fn default() -> Self {
        Self {
            max_iterations: 4000,
            eps_abs: 1e-6,
            eps_rel: 1e-6,
            eps_infeasible: 1e-6,
            rho: 0.1,
            sigma: 1e-6,
            alpha: 1.6,
            adaptive_rho: true,
            polish: true,
            active_set_steps: 50,
        }
    }
}

/// How a solve ended.
///
/// # Examples
///
/// ```
/// use ctrlab::design::mpc::QpStatus;
/// assert!(QpStatus::Solved.is_solved());
/// assert!(!QpStatus::IterationLimit.is_solved());
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum QpStatus {
    /// Both residuals met the tolerance.
    Solved,
    /// [`QpSettings::max_iterations`] ran out first; the iterate is the
    /// last one (usually close, never certified).
    IterationLimit,
    /// The hard rows cannot all hold: a certificate (a direction of the
    /// multipliers, OSQP's test) proves it.
    PrimalInfeasible,
}

impl QpStatus {
    /// Whether the solve met its tolerance.
    pub fn is_solved(self) -> bool {
        self == Self::Solved
    }
}

/// What a solve reports besides its solution ([`DenseQp::solution`]).
///
/// # Examples
///
/// ```
/// use ctrlab::design::mpc::{DenseQp, QpSettings, Row};
/// use ctrlab::nalgebra::DMatrix;
/// // min ½ x² − x subject to x ≤ 0.5: the bound is active.
/// let mut qp = DenseQp::new(&DMatrix::from_element(1, 1, 1.0), &DMatrix::from_element(1, 1, 1.0),
///                           &[Row::Hard], QpSettings::default())?;
/// let report = qp.solve(&[-1.0], &[f64::NEG_INFINITY], &[0.5])?;
/// assert!(report.status.is_solved());
/// assert!((qp.solution()[0] - 0.5).abs() < 1e-5);
/// assert!((report.objective - (0.125 - 0.5)).abs() < 1e-5);
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct QpReport {
    /// How it ended.
    pub status: QpStatus,
    /// Iterations spent.
    pub iterations: usize,
    /// `‖G x − z‖∞` at the end, the problem's units.
    pub primal_residual: f64,
    /// `‖P x + q + Gᵀ y‖∞` at the end.
    pub dual_residual: f64,
    /// `½ xᵀ P x + qᵀ x` plus the soft rows' penalties at the solution.
    pub objective: f64,
    /// The step size `ρ` at the end (adapted), in the equilibrated
    /// problem's units.
    pub rho: f64,
    /// Whether the solution is a polished one (exact to rounding on its
    /// active set) rather than an ADMM iterate within the tolerances.
    pub polished: bool,
    /// Linear solves the active-set method took (0 if the polish from the
    /// warm start already held, or it did not run).
    pub active_set_steps: usize,
}

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
/// The answer is what OSQP's would be, to its tolerance: the tests check it
/// against an interior-point solution of the same problems with explicit
/// slack variables.
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
    /// symmetric or not positive semidefinite: the factorisation fails),
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
        for row in rows {
            if let Row::Soft { linear, quadratic } = *row {
                for (name, value) in [("linear", linear), ("quadratic", quadratic)] {
                    if !(value.is_finite() && value >= 0.0) {
                        return Err(Error::InvalidParameter {
                            name,
                            value,
                            reason: "a soft row's weight must be finite and ≥ 0",
                        });
                    }
                }
            }
        }
        let tol = 1e-12 * p.amax().max(f64::MIN_POSITIVE);
        if (0..n).any(|i| (0..i).any(|j| (p[(i, j)] - p[(j, i)]).abs() > tol)) {
            return Err(Error::InvalidMatrix {
                matrix: "P",
                reason: "must be symmetric",
            });
        }

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
        if !qp.factor() {
            return Err(Error::InvalidMatrix {
                matrix: "P",
                reason: "must be positive semidefinite",
            });
        }
        Ok(qp)
    }

    /// Number of variables `n`.
    pub fn variables(&self) -> usize {
        self.x.len()
    }

    /// Number of rows `m`.
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
    /// [`Error::InvalidData`] for a NaN, an infinite `q`, or `lower > upper`
    /// (named by index). An unsolved problem is not an error: the report's
    /// [`QpStatus`] says what happened.
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
        let mut status = QpStatus::IterationLimit;
        let mut iterations = 0;
        // A warm start whose binding rows are still the right ones is
        // optimal after one polish.
        self.active_set_steps = 0;
        let mut polished = s.polish && self.polish();
        // Else the active-set method from the warm start, when it holds
        // the hard rows.
        if !polished && s.active_set_steps > 0 {
            polished = self.active_set(s.active_set_steps);
        }
        if polished {
            status = QpStatus::Solved;
        }
        while !polished && iterations < s.max_iterations {
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
        Ok(QpReport {
            status,
            iterations,
            primal_residual: r.prim,
            dual_residual: r.dual,
            objective: self.objective(q, lower, upper),
            rho: self.rho,
            polished,
            active_set_steps: self.active_set_steps,
        })
    }

    /// The solution of the last solve (`n`, the problem's units).
    pub fn solution(&self) -> &[f64] {
        self.x_out.as_slice()
    }

    /// The multipliers of the rows at the last solve (`m`): positive where
    /// an upper bound binds, negative where a lower one does.
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
    pub fn cold_start(&mut self) {
        self.x.fill(0.0);
        self.y.fill(0.0);
    }
}

fn invalid(what: &'static str, index: usize, reason: &'static str) -> Error {
    Error::InvalidData {
        what,
        index,
        reason,
    }
}
