//! The solver's settings, rows and what a solve reports.

use std::time::Duration;

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
    /// A wall-clock budget for a solve (OSQP's `time_limit`, qpOASES's
    /// `cputime`), `None` for none. Checked before each active-set solve and
    /// each ADMM iteration and polish, so a solve ends within one of them
    /// after it (at most a few tens of µs for the lab's MPC); it then
    /// reports [`QpStatus::TimeLimit`]. The polish of the warm start comes
    /// first whatever the limit: it is what solves a typical tick. With a limit
    /// the outcome depends on the machine's speed and load: leave it `None`
    /// where runs must reproduce (simulations on virtual time), and set it
    /// on the wall clock of a real loop. Must be > 0.
    pub time_limit: Option<Duration>,
}

impl QpSettings {
    /// The defaults ([`Default::default`]) as a constant, for other
    /// constants to start from.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::design::mpc::QpSettings;
    /// assert_eq!(QpSettings::DEFAULT, QpSettings::default());
    /// assert_eq!(QpSettings::DEFAULT.max_iterations, 4000);
    /// ```
    pub const DEFAULT: Self = Self {
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
        time_limit: None,
    };
}

impl Default for QpSettings {
    fn default() -> Self {
        Self::DEFAULT
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
    /// [`QpSettings::time_limit`] ran out first; the iterate is the last
    /// one (never certified).
    TimeLimit,
    /// The hard rows cannot all hold: a certificate (a direction of the
    /// multipliers, OSQP's test) proves it.
    PrimalInfeasible,
}

impl QpStatus {
    /// Whether the solve met its tolerance.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::design::mpc::{DenseQp, QpSettings, QpStatus, Row};
    /// use ctrlab::nalgebra::DMatrix;
    /// let one = DMatrix::identity(1, 1);
    /// let mut qp = DenseQp::new(&one, &one, &[Row::Hard], QpSettings::default())?;
    /// assert!(qp.solve(&[-2.0], &[f64::NEG_INFINITY], &[1.0])?.status.is_solved());
    /// assert!(!QpStatus::PrimalInfeasible.is_solved() && !QpStatus::TimeLimit.is_solved());
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn is_solved(self) -> bool {
        self == Self::Solved
    }
}

/// What a solve reports besides its solution ([`DenseQp::solution`](super::DenseQp::solution)).
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
