//! Batch linear least squares by Householder QR (faer inside).

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::qr::no_pivoting::factor::{qr_in_place, qr_in_place_scratch};
use faer::{MatMut, Par};
use nalgebra::{DMatrix, DVector};

use crate::error::Error;
use crate::kernels::reduce::{first_non_finite, max_abs, pow2_floor, sum_by};

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
    /// Regressor columns, each one `Vec` of rows.
    columns: Vec<Vec<f64>>,
    /// Right-hand side.
    rhs: Vec<f64>,
    max_condition: f64,
    /// Column-major `[Φ D⁻¹ | λ]`, overwritten by the QR factors.
    work: Vec<f64>,
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
    /// Estimated covariance of `θ̂`: `σ̂² (ΦᵀΦ)⁻¹` with
    /// `σ̂² = ‖r‖² / (rows − parameters)` (computed from R, not from `ΦᵀΦ`).
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
        Self {
            columns: (0..parameters).map(|_| Vec::with_capacity(rows)).collect(),
            rhs: Vec::with_capacity(rows),
            max_condition: DEFAULT_MAX_CONDITION,
            work: Vec::new(),
        }
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
        self.columns.len()
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

    /// Removes every row, keeping the allocations.
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
        if phi.len() != self.columns.len() {
            return Err(Error::InvalidParameter {
                name: "phi",
                value: phi.len() as f64,
                reason: "regressor row length must equal the number of parameters",
            });
        }
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
        if columns.len() != self.columns.len() {
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
        self.work.clear();
        self.work.reserve(m * (p + 1));
        for col in &self.columns {
            self.work.extend_from_slice(col);
        }
        self.work.extend_from_slice(&self.rhs);
        solve_augmented(&mut self.work, m, p, self.max_condition)
    }
}

/// Solves `Φ θ ≈ λ` by QR, given column-major `a = [Φ | λ]` (`m` rows, `p + 1`
/// columns), destroying `a`.
pub(crate) fn solve_augmented(
    a: &mut [f64],
    m: usize,
    p: usize,
    max_condition: f64,
) -> Result<LeastSquaresFit, Error> {
    debug_assert_eq!(a.len(), m * (p + 1));
    if p == 0 || m <= p {
        return Err(Error::TooFewSamples {
            what: "least squares (more rows than parameters)",
            needed: p.max(1) + 1,
            got: m,
        });
    }
    // Equilibrate every column (λ too) by a power of two, so that its
    // largest entry is in [1, 2): exact, and then no norm, product or
    // square in the QR or the statistics below can overflow or underflow,
    // whatever the units (a column of 1e308, another of 1e-200). The
    // results are unscaled at the end.
    let mut exponents = vec![0i32; p + 1];
    for (j, (col, e)) in a.chunks_exact_mut(m).zip(exponents.iter_mut()).enumerate() {
        if let Some(i) = first_non_finite(col) {
            return Err(Error::NonFinite {
                matrix: "regressor",
                row: i,
                col: j,
                value: col[i],
            });
        }
        *e = binary_exponent(max_abs(col));
        if *e != 0 {
            let f = pow2(-*e);
            col.iter_mut().for_each(|v| *v *= f);
        }
    }
    let e_lambda = exponents[p];
    // Spread of λ about its mean, before QR overwrites it.
    let lam = &a[p * m..];
    let mean = sum_by(lam, |v| v) / m as f64;
    let sst = sum_by(lam, |v| (v - mean) * (v - mean));

    let n = p + 1;
    // Tall and narrow (a handful of columns): blocking buys nothing and
    // costs about half the time at 5000 × 3.
    let bs = 1;
    let mut h = vec![0.0; bs * n];
    let mut mem = MemBuffer::new(qr_in_place_scratch::<f64>(
        m,
        n,
        bs,
        Par::Seq,
        Default::default(),
    ));
    qr_in_place(
        MatMut::from_column_major_slice_mut(a, m, n),
        MatMut::from_column_major_slice_mut(&mut h, bs, n),
        Par::Seq,
        MemStack::new(&mut mem),
        Default::default(),
    );
    // The upper triangle of `a` now holds R_aug = [R z; 0 ρ], |ρ| = ‖r‖.
    let r = |i: usize, j: usize| a[j * m + i];

    // Householder QR commutes with column scaling, so the equilibrated
    // regressor Φ D⁻¹ (unit columns) has the triangular factor R D⁻¹, with
    // ‖Φ_j‖ = ‖R_j‖: its singular values give a unit-free condition number.
    let mut rmat = DMatrix::from_fn(p, p, |i, j| if i <= j { r(i, j) } else { 0.0 });
    for j in 0..p {
        let norm = rmat.column(j).norm();
        if norm > 0.0 {
            rmat.column_mut(j).unscale_mut(norm);
        }
    }
    let iterations = 200 * p;
    let sv = rmat
        .try_svd_unordered(false, false, f64::EPSILON, iterations)
        .ok_or(Error::NoConvergence {
            operation: "least squares (singular values of R)",
            iterations,
        })?
        .singular_values;
    let smax = sv.max();
    let smin = sv.min();
    let condition = if smin > 0.0 {
        smax / smin
    } else {
        f64::INFINITY
    };
    if condition.is_nan() || condition > max_condition {
        let rank = sv.iter().filter(|&&s| s * max_condition > smax).count();
        return Err(Error::RankDeficient { rank, condition });
    }

    // Back substitution R θ' = z, then undo the scaling.
    let mut theta = DVector::zeros(p);
    for i in (0..p).rev() {
        let mut s = r(i, p);
        for j in i + 1..p {
            s -= r(i, j) * theta[j];
        }
        theta[i] = s / r(i, i);
    }
    // R⁻¹ by back substitution, column by column.
    let mut rinv = DMatrix::zeros(p, p);
    for c in 0..p {
        for i in (0..=c).rev() {
            let mut s = if i == c { 1.0 } else { 0.0 };
            for j in i + 1..=c {
                s -= r(i, j) * rinv[(j, c)];
            }
            rinv[(i, c)] = s / r(i, i);
        }
    }
    let ssr = r(p, p) * r(p, p);
    let sigma2 = ssr / (m - p) as f64;
    let mut covariance = &rinv * rinv.transpose() * sigma2;
    let mut std_errors = covariance.diagonal().map(f64::sqrt);
    let (r_squared, fit_percent) = if sst > 0.0 {
        (1.0 - ssr / sst, (1.0 - (ssr / sst).sqrt()) * 100.0)
    } else if ssr == 0.0 {
        (1.0, 100.0)
    } else {
        (f64::NEG_INFINITY, f64::NEG_INFINITY)
    };
    // Undo the equilibration: θ_j and its standard error in λ's units per
    // column j's, the covariance in their products.
    for j in 0..p {
        let d = e_lambda - exponents[j];
        theta[j] = scale_pow2(theta[j], d);
        std_errors[j] = scale_pow2(std_errors[j], d);
        for i in 0..p {
            covariance[(i, j)] =
                scale_pow2(scale_pow2(covariance[(i, j)], d), e_lambda - exponents[i]);
        }
    }
    let residual_rms = scale_pow2((ssr / m as f64).sqrt(), e_lambda);
    let finite = |v: &[f64]| v.iter().all(|v| v.is_finite());
    if !(finite(theta.as_slice())
        && finite(std_errors.as_slice())
        && finite(covariance.as_slice())
        && residual_rms.is_finite())
    {
        return Err(Error::Overflow {
            operation: "least squares (the estimate or its covariance exceeds f64::MAX)",
        });
    }
    Ok(LeastSquaresFit {
        theta,
        covariance,
        std_errors,
        residual_rms,
        r_squared,
        fit_percent,
        condition,
        rows: m,
    })
}

/// `e` with `2^e ≤ x < 2^(e+1)` for a finite `x > 0` (0 for `x = 0`).
fn binary_exponent(x: f64) -> i32 {
    pow2_floor(x).log2() as i32
}

/// `2^e` for `|e| ≤ 1022`, exactly.
fn pow2(e: i32) -> f64 {
    2f64.powi(e)
}

/// `v · 2^d` for `|d| ≤ 2046`, in two exact halves: no intermediate
/// overflows unless the result does.
fn scale_pow2(v: f64, d: i32) -> f64 {
    let half = d / 2;
    v * pow2(half) * pow2(d - half)
}
