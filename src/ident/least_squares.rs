//! Batch linear least squares by Householder QR (faer inside).

use nalgebra::{DMatrix, DVector};

use super::Covariance;
use super::solve::{SolveOptions, Workspace, solve_augmented};
use crate::error::Error;

/// Default limit on the column-equilibrated condition number (10¹⁰, i.e.
/// more than ten of the sixteen significant digits lost): above it a
/// regressor counts as rank deficient.
///
/// # Examples
///
/// ```
/// # use ctrlab::{Error, ident::{LeastSquares, DEFAULT_MAX_CONDITION}};
/// // Columns 1e-12 apart in angle: condition ≈ 10¹², beyond the default.
/// let mut ls = LeastSquares::new(2);
/// ls.push_columns(&[&[1.0, 1.0, 1.0], &[1.0, 1.0, 1.0 + 2e-12]], &[1.0, 2.0, 3.0])?;
/// match ls.solve() {
///     Err(Error::RankDeficient { condition, .. }) => assert!(condition > DEFAULT_MAX_CONDITION),
///     other => panic!("{other:?}"),
/// }
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub const DEFAULT_MAX_CONDITION: f64 = 1e10;

/// Linear least squares `Φ θ ≈ λ`: rows `φ(k)ᵀ θ = λ(k)` are pushed one at a
/// time or as columns, and [`solve`](Self::solve) returns the estimate with
/// its statistics.
///
/// The solver is Householder QR of the augmented matrix `[Φ | λ] = Q R`:
/// the last column of `R` holds `Qᵀλ` and the residual norm, so one
/// factorisation gives the estimate, its covariance and the fit. The normal
/// equations `ΦᵀΦ` are never formed (they square the condition number).
/// The rank test uses the condition number of `Φ` with its columns scaled
/// to unit norm, so it does not depend on the parameters' units. The
/// workspace is kept between solves.
///
/// The covariance is [`Covariance::Classical`] unless
/// [`with_covariance`](Self::with_covariance) asks for Newey–West; rows
/// from separate runs or segments are marked by
/// [`start_segment`](Self::start_segment), so that its sums never pair
/// rows across them.
///
/// # Examples
///
/// ```
/// use ctrlab::ident::LeastSquares;
///
/// // y = 2 + 3 x, exactly.
/// let mut ls = LeastSquares::new(2);
/// for x in [0.0, 1.0, 2.0, 3.0] {
///     ls.push_row(&[1.0, x], 2.0 + 3.0 * x)?;
/// }
/// let fit = ls.solve()?;
/// assert!((fit.theta[0] - 2.0).abs() < 1e-12 && (fit.theta[1] - 3.0).abs() < 1e-12);
/// assert!(fit.fit_percent > 99.999_999);
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct LeastSquares {
    /// The number of parameters, `θ`'s length.
    parameters: usize,
    /// The rows each column has room for when it is made.
    capacity: usize,
    /// Regressor columns, each one `Vec` of rows: `parameters` of them, or
    /// none until the first row when the allocator refused them up front.
    columns: Vec<Vec<f64>>,
    /// Right-hand side.
    rhs: Vec<f64>,
    max_condition: f64,
    covariance: Covariance,
    /// Rows where a segment starts (increasing, each > 0).
    segment_starts: Vec<usize>,
    /// Column-major `[Φ D⁻¹ | λ]`, overwritten by the QR factors.
    work: Vec<f64>,
    /// A copy of `work` before QR and the sums' buffer, for the
    /// Newey–West covariance.
    hac: Workspace,
}

/// The result of a least-squares solve. All vectors are indexed like the
/// regressor's columns.
///
/// # Examples
///
/// ```
/// # use ctrlab::ident::LeastSquares;
/// let mut ls = LeastSquares::new(1);
/// ls.push_columns(&[&[1.0, 2.0, 3.0]], &[1.1, 1.9, 3.0])?;
/// let fit = ls.solve()?;
/// assert_eq!(fit.rows, 3);
/// assert!(fit.std_errors[0] > 0.0 && fit.r_squared < 1.0);
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct LeastSquaresFit {
    /// The estimate `θ̂`.
    pub theta: DVector<f64>,
    /// Estimated covariance of `θ̂`, as [`covariance_kind`](Self::covariance_kind)
    /// says: classically `σ̂² (ΦᵀΦ)⁻¹` with
    /// `σ̂² = ‖r‖² / (rows − parameters)`, or the Newey–West sandwich
    /// (computed from R, never from `ΦᵀΦ`). In the products of the
    /// parameters' units.
    pub covariance: DMatrix<f64>,
    /// Standard errors, the square roots of the covariance's diagonal.
    pub std_errors: DVector<f64>,
    /// Root mean square of the residual `r = λ − Φ θ̂`, in the unit of `λ`.
    pub residual_rms: f64,
    /// Coefficient of determination `1 − ‖r‖² / ‖λ − mean λ‖²`. When `λ` is
    /// constant it is 1 for a zero residual and −∞ otherwise.
    pub r_squared: f64,
    /// Fit in percent, `(1 − ‖r‖ / ‖λ − mean λ‖) · 100` (MATLAB's
    /// `compare` NRMSE fit); same convention as `r_squared` for constant `λ`.
    pub fit_percent: f64,
    /// Condition number of the column-equilibrated regressor `Φ D⁻¹` (`D`
    /// scales every column to unit norm): the ratio of its extreme singular
    /// values, independent of the parameters' units.
    pub condition: f64,
    /// Number of rows used.
    pub rows: usize,
    /// How `covariance` was estimated; for Newey–West with the bandwidth
    /// actually used (`lags: Some(L)`, after the automatic rule and the cap).
    pub covariance_kind: Covariance,
}

impl LeastSquares {
    /// An empty problem with `parameters` unknowns and the default
    /// [`DEFAULT_MAX_CONDITION`].
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::ident::LeastSquares;
    /// let ls = LeastSquares::new(3);
    /// assert_eq!((ls.parameters(), ls.rows()), (3, 0));
    /// ```
    pub fn new(parameters: usize) -> Self {
        Self::with_capacity(parameters, 0)
    }

    /// An empty problem with room for `rows` rows without reallocating.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::ident::LeastSquares;
    /// let ls = LeastSquares::with_capacity(2, 5000);
    /// assert_eq!(ls.parameters(), 2);
    /// ```
    pub fn with_capacity(parameters: usize, rows: usize) -> Self {
        let mut rhs = Vec::new();
        // Hints: room the allocator refuses (usize::MAX rows or
        // parameters) is not reserved, instead of a capacity-overflow panic.
        let _ = rhs.try_reserve_exact(rows);
        let mut ls = Self {
            parameters,
            capacity: rows,
            columns: Vec::new(),
            rhs,
            max_condition: DEFAULT_MAX_CONDITION,
            covariance: Covariance::Classical,
            segment_starts: Vec::new(),
            work: Vec::new(),
            hac: Workspace::default(),
        };
        ls.make_columns();
        ls
    }

    /// Makes the `parameters` columns, each with room for `capacity` rows,
    /// unless they exist or the allocator refuses them.
    fn make_columns(&mut self) {
        if self.columns.len() == self.parameters
            || self.columns.try_reserve_exact(self.parameters).is_err()
        {
            return;
        }
        let capacity = self.capacity;
        self.columns.extend((0..self.parameters).map(|_| {
            let mut column = Vec::new();
            let _ = column.try_reserve_exact(capacity);
            column
        }));
    }

    /// Sets how the covariance of `θ̂` is estimated (default
    /// [`Covariance::Classical`]); the estimate itself does not change.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::ident::{Covariance, LeastSquares};
    ///
    /// let nw = Covariance::NeweyWest { lags: None };
    /// let mut ls = LeastSquares::new(1).with_covariance(nw);
    /// assert_eq!(ls.covariance(), nw);
    /// ls.push_columns(&[&[1.0; 8]], &[1.0, 2.0, 1.5, 0.5, 1.0, 2.0, 1.5, 0.5])?;
    /// let fit = ls.solve()?;
    /// assert_eq!(fit.covariance_kind, Covariance::NeweyWest { lags: Some(2) });
    /// assert!(fit.std_errors[0].is_finite());
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[must_use]
    pub fn with_covariance(mut self, covariance: Covariance) -> Self {
        self.covariance = covariance;
        self
    }

    /// How the covariance is estimated.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::ident::{Covariance, LeastSquares};
    /// assert_eq!(LeastSquares::new(2).covariance(), Covariance::Classical);
    /// ```
    pub fn covariance(&self) -> Covariance {
        self.covariance
    }

    /// Marks the next row pushed as the first of a new segment (another
    /// run, or the part of a recording after a gap): the Newey–West sums
    /// pair no row with one across the mark. Nothing happens before the
    /// first row, or twice at the same row. The estimate and the classical
    /// covariance do not depend on segments.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::ident::{Covariance, LeastSquares};
    ///
    /// let nw = Covariance::NeweyWest { lags: Some(1) };
    /// let (mut one, mut two) = (LeastSquares::new(1).with_covariance(nw), LeastSquares::new(1).with_covariance(nw));
    /// let y = [1.0, 2.0, 0.5, 1.5, 3.0, 2.5, 1.0, 2.0];
    /// one.push_columns(&[&[1.0; 8]], &y)?;
    /// two.push_columns(&[&[1.0; 4]], &y[..4])?;
    /// two.start_segment();
    /// two.push_columns(&[&[1.0; 4]], &y[4..])?;
    /// assert_eq!(two.segments(), 2);
    /// let (a, b) = (one.solve()?, two.solve()?);
    /// assert_eq!(a.theta, b.theta);
    /// assert_ne!(a.std_errors, b.std_errors); // rows 3 and 4 are not paired
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn start_segment(&mut self) {
        let row = self.rows();
        if row > 0 && self.segment_starts.last() != Some(&row) {
            self.segment_starts.push(row);
        }
    }

    /// Number of segments ([`start_segment`](Self::start_segment)): 1 with
    /// rows and no mark, 0 without rows.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::ident::LeastSquares;
    /// let mut ls = LeastSquares::new(1);
    /// assert_eq!(ls.segments(), 0);
    /// ls.push_row(&[1.0], 1.0)?;
    /// ls.start_segment();
    /// assert_eq!(ls.segments(), 1); // nothing after the mark yet
    /// ls.push_row(&[1.0], 2.0)?;
    /// assert_eq!(ls.segments(), 2);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn segments(&self) -> usize {
        let rows = self.rows();
        if rows == 0 {
            return 0;
        }
        1 + self.segment_starts.iter().filter(|&&s| s < rows).count()
    }

    /// Sets the largest accepted condition number of the column-equilibrated
    /// regressor (default [`DEFAULT_MAX_CONDITION`]); values ≤ 1 or NaN are
    /// replaced by the default.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::{Error, ident::LeastSquares};
    /// let mut ls = LeastSquares::new(2).with_max_condition(10.0);
    /// // Two nearly parallel columns: condition about 400.
    /// ls.push_columns(&[&[1.0, 1.0, 1.0], &[1.0, 1.0, 1.01]], &[1.0, 2.0, 3.0])?;
    /// assert!(matches!(ls.solve(), Err(Error::RankDeficient { rank: 1, .. })));
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn with_max_condition(mut self, max_condition: f64) -> Self {
        self.max_condition = if max_condition > 1.0 {
            max_condition
        } else {
            DEFAULT_MAX_CONDITION
        };
        self
    }

    /// Number of unknowns.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::ident::LeastSquares;
    /// assert_eq!(LeastSquares::new(4).parameters(), 4);
    /// ```
    pub fn parameters(&self) -> usize {
        self.parameters
    }

    /// Number of rows pushed so far.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::ident::LeastSquares;
    /// let mut ls = LeastSquares::new(1);
    /// ls.push_row(&[1.0], 2.0)?;
    /// assert_eq!(ls.rows(), 1);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn rows(&self) -> usize {
        self.rhs.len()
    }

    /// Removes every row and segment mark, keeping the allocations.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::ident::LeastSquares;
    /// let mut ls = LeastSquares::new(1);
    /// ls.push_row(&[1.0], 2.0)?;
    /// ls.clear();
    /// assert_eq!(ls.rows(), 0);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn clear(&mut self) {
        self.columns.iter_mut().for_each(Vec::clear);
        self.rhs.clear();
        self.segment_starts.clear();
    }

    /// Appends one row `φᵀ θ = λ`. Allocation-free while capacity lasts.
    ///
    /// # Errors
    ///
    /// [`Error::InvalidParameter`] when `phi` has the wrong length (the row
    /// is not added).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::ident::LeastSquares;
    /// let mut ls = LeastSquares::new(2);
    /// ls.push_row(&[1.0, 0.5], 3.0)?;
    /// assert!(ls.push_row(&[1.0], 3.0).is_err());
    /// assert_eq!(ls.rows(), 1);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn push_row(&mut self, phi: &[f64], lambda: f64) -> Result<(), Error> {
        if phi.len() != self.parameters {
            return Err(Error::InvalidParameter {
                name: "phi",
                value: phi.len() as f64,
                reason: "regressor row length must equal the number of parameters",
            });
        }
        self.make_columns();
        for (col, &v) in self.columns.iter_mut().zip(phi) {
            col.push(v);
        }
        self.rhs.push(lambda);
        Ok(())
    }

    /// Appends many rows given as columns: `columns[j][k]` is entry `j` of
    /// row `k`, `lambda[k]` its right-hand side.
    ///
    /// # Errors
    ///
    /// [`Error::InvalidParameter`] when the number of columns is not the
    /// number of parameters or the columns' lengths differ from `lambda`'s
    /// (nothing is added).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::ident::LeastSquares;
    /// let mut ls = LeastSquares::new(2);
    /// ls.push_columns(&[&[1.0, 1.0, 1.0], &[0.0, 1.0, 2.0]], &[1.0, 3.0, 5.0])?;
    /// let fit = ls.solve()?;
    /// assert!((fit.theta[1] - 2.0).abs() < 1e-12);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn push_columns(&mut self, columns: &[&[f64]], lambda: &[f64]) -> Result<(), Error> {
        if columns.len() != self.parameters {
            return Err(Error::InvalidParameter {
                name: "columns",
                value: columns.len() as f64,
                reason: "number of columns must equal the number of parameters",
            });
        }
        if let Some(bad) = columns.iter().find(|c| c.len() != lambda.len()) {
            return Err(Error::InvalidParameter {
                name: "columns",
                value: bad.len() as f64,
                reason: "every column must be as long as lambda",
            });
        }
        self.make_columns();
        for (col, new) in self.columns.iter_mut().zip(columns) {
            col.extend_from_slice(new);
        }
        self.rhs.extend_from_slice(lambda);
        Ok(())
    }

    /// Solves the problem by QR.
    ///
    /// # Errors
    ///
    /// - [`Error::TooFewSamples`] unless there are more rows than parameters
    ///   (the residual variance needs a degree of freedom), or with zero
    ///   parameters;
    /// - [`Error::NonFinite`] (`matrix: "regressor"`, column `parameters`
    ///   for `λ`) naming the first NaN or infinite entry;
    /// - [`Error::RankDeficient`] when the column-equilibrated condition
    ///   number exceeds the limit (a zero column gives `condition = inf`).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::{Error, ident::LeastSquares};
    /// let mut ls = LeastSquares::new(2);
    /// // The second regressor is twice the first: no unique solution.
    /// ls.push_columns(&[&[1.0, 2.0, 3.0], &[2.0, 4.0, 6.0]], &[1.0, 2.0, 3.0])?;
    /// assert!(matches!(ls.solve(), Err(Error::RankDeficient { rank: 1, .. })));
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn solve(&mut self) -> Result<LeastSquaresFit, Error> {
        let (m, p) = (self.rows(), self.parameters());
        // Before sizing anything by `p`: a problem with no more rows than
        // parameters has no solution to give (and `m (p + 1)` may overflow).
        if m <= p || p == 0 {
            return Err(Error::TooFewSamples {
                what: "least squares (more rows than parameters)",
                needed: p.saturating_add(1).max(2),
                got: m,
            });
        }
        self.work.clear();
        self.work.reserve(m * (p + 1));
        for col in &self.columns {
            self.work.extend_from_slice(col);
        }
        self.work.extend_from_slice(&self.rhs);
        let options = SolveOptions {
            max_condition: self.max_condition,
            covariance: self.covariance,
            segment_starts: &self.segment_starts,
        };
        solve_augmented(&mut self.work, m, p, &options, &mut self.hac)
    }
}
