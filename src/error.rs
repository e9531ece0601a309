//! The crate's error type.
//!
//! One enum for everything numeric (models, discretisation, simulation, and the
//! modules built on them). Every variant carries the context needed to act on it:
//! which parameter, which matrix entry, which operation.

use crate::readable::Readable;

/// Everything that can go wrong in `ctrlab`'s numeric code.
///
/// The enum is `#[non_exhaustive]`: later releases add variants without a
/// breaking change, so match with a wildcard arm.
///
/// # Examples
///
/// ```
/// use ctrlab::{Error, MassSpring};
///
/// let mut plant = MassSpring::nominal();
/// plant.m1 = -1.0;
/// let err = plant.validate().unwrap_err();
/// assert!(matches!(err, Error::InvalidParameter { name: "m1", .. }));
/// assert!(err.to_string().contains("m1"));
/// ```
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A scalar parameter is out of its valid range (a non-positive mass, a
    /// negative spring, a non-positive time step, …).
    #[error("invalid parameter `{name}` = {}: {reason}", Readable(*.value))]
    InvalidParameter {
        /// The parameter's name as it appears in the API (`"m1"`, `"dt"`, …).
        name: &'static str,
        /// The offending value.
        value: f64,
        /// What the value must satisfy.
        reason: &'static str,
    },
    /// A matrix handed to a constructor has a NaN or infinite entry.
    #[error("matrix {matrix} has a non-finite entry {} at row {row}, column {col}", Readable(*.value))]
    NonFinite {
        /// Which matrix (`"A"`, `"B"`, `"C"`, `"D"`).
        matrix: &'static str,
        /// Zero-based row of the first bad entry.
        row: usize,
        /// Zero-based column of the first bad entry.
        col: usize,
        /// The entry itself.
        value: f64,
    },
    /// A matrix that has to be inverted is singular (or numerically so).
    #[error("singular matrix in {operation}")]
    Singular {
        /// The operation that needed the inverse (`"Tustin discretisation"`, …).
        operation: &'static str,
    },
    /// A Lyapunov, Stein (discrete Lyapunov) or Sylvester equation has no
    /// unique solution: two eigenvalues of its coefficients satisfy the
    /// equation's singularity condition to working precision (`λ + μ = 0`
    /// for `A X + X B = C` and the continuous Lyapunov equation, an
    /// eigenvalue of `A` on the imaginary axis for instance; `λ μ = 1` for
    /// the discrete one, an eigenvalue on the unit circle).
    #[error(
        "{equation} has no unique solution: eigenvalues {lambda_re} + {lambda_im}i and \
         {mu_re} + {mu_im}i give {condition}"
    )]
    SingularEquation {
        /// The equation (`"continuous Lyapunov equation"`, …).
        equation: &'static str,
        /// Real part of the first eigenvalue `λ` (of `A`).
        lambda_re: f64,
        /// Imaginary part of `λ`.
        lambda_im: f64,
        /// Real part of the second eigenvalue `μ` (of `Aᵀ`, or of `B`).
        mu_re: f64,
        /// Imaginary part of `μ`.
        mu_im: f64,
        /// The condition they meet (`"λ + μ = 0"` or `"λ μ = 1"`).
        condition: &'static str,
    },
    /// A computation produced a non-finite result from finite input (overflow,
    /// typically a time step far too large for the model's dynamics).
    #[error("{operation} overflowed to a non-finite result")]
    Overflow {
        /// The operation that overflowed.
        operation: &'static str,
    },
    /// A response did not settle inside its band before the end of the
    /// record, so its step metrics are not defined; `cause` says whether it
    /// diverges, oscillates, or was still converging (the message adds a
    /// hint for each).
    #[error(
        "response not settled ({cause}): it is outside the settling band at t = {} s, \
         after the start of the final window at t = {} s; {}",
        Short(*last_outside),
        Short(*window_start),
        cause.hint()
    )]
    NotSettled {
        /// Time (s, from the first sample) at which the response last enters
        /// the band, or the last sample time if it ends outside.
        last_outside: f64,
        /// Start (s, from the first sample) of the final window the response
        /// has to stay inside the band for.
        window_start: f64,
        /// What the final window looks like.
        cause: SettleFailure,
    },
    /// A model is unstable where a stable one is needed (step metrics of a
    /// model, a Riccati solution that does not stabilise).
    #[error("{operation}: unstable pole {} + {}i", Readable(*.re), Readable(*.im))]
    Unstable {
        /// The operation that needed stability.
        operation: &'static str,
        /// Real part of the first offending pole (continuous: ≥ 0).
        re: f64,
        /// Imaginary part of that pole.
        im: f64,
    },
    /// The pair (A, B) is not controllable to working precision.
    #[error("uncontrollable: controllability matrix has rank {rank} of {states}")]
    Uncontrollable {
        /// Numerical rank of the controllability matrix.
        rank: usize,
        /// Number of states (the full rank).
        states: usize,
    },
    /// The pair (A, C) is not observable to working precision (an observer
    /// cannot place its poles, or a Kalman filter has no stabilising
    /// solution).
    #[error("unobservable: observability matrix has rank {rank} of {states}")]
    Unobservable {
        /// Numerical rank of the observability matrix.
        rank: usize,
        /// Number of states (the full rank).
        states: usize,
    },
    /// Pole placement computed a gain whose closed-loop pole is not where it
    /// was asked for (beyond the documented tolerance): the target set is
    /// too ill-conditioned to assign in floating point.
    #[error(
        "pole placement: target pole {target_re} + {target_im}i was placed at \
         {achieved_re} + {achieved_im}i"
    )]
    PoleNotPlaced {
        /// Real part of the target.
        target_re: f64,
        /// Imaginary part of the target.
        target_im: f64,
        /// Real part of the nearest achieved pole.
        achieved_re: f64,
        /// Imaginary part of the nearest achieved pole.
        achieved_im: f64,
    },
    /// Data handed to an algorithm are malformed: non-finite samples, a
    /// non-increasing time axis, too few samples.
    #[error("invalid data `{what}` at index {index}: {reason}")]
    InvalidData {
        /// Which input (`"t"`, `"y"`, …).
        what: &'static str,
        /// Zero-based index of the first bad sample (or the length, when
        /// there are too few).
        index: usize,
        /// What is wrong.
        reason: &'static str,
    },
    /// Two inputs that must have one entry per sample have different lengths.
    #[error("length mismatch: `{what}` has {found} entries, expected {expected}")]
    LengthMismatch {
        /// Which input has the wrong length.
        what: &'static str,
        /// The length it should have.
        expected: usize,
        /// The length it has.
        found: usize,
    },
    /// A matrix argument violates a structural requirement (symmetric,
    /// positive definite, …).
    #[error("invalid matrix {matrix}: {reason}")]
    InvalidMatrix {
        /// Which matrix (`"Q"`, `"R"`, …).
        matrix: &'static str,
        /// What it must satisfy.
        reason: &'static str,
    },
    /// A matrix of a run-time-sized model or problem has the wrong shape.
    #[error(
        "matrix {matrix} is {found_rows}×{found_cols}, expected {expected_rows}×{expected_cols}"
    )]
    DimensionMismatch {
        /// Which matrix (`"A"`, `"B"`, `"Q"`, …).
        matrix: &'static str,
        /// The rows it must have.
        expected_rows: usize,
        /// The columns it must have.
        expected_cols: usize,
        /// The rows it has.
        found_rows: usize,
        /// The columns it has.
        found_cols: usize,
    },
    /// An iterative algorithm did not converge.
    #[error("{operation} did not converge after {iterations} iterations")]
    NoConvergence {
        /// The algorithm (`"Schur decomposition"`, `"Riccati doubling"`, …).
        operation: &'static str,
        /// Iterations spent.
        iterations: usize,
    },
    /// A least-squares regressor does not determine every parameter: its
    /// column-equilibrated condition number exceeds the solver's limit
    /// (typically a run with no excitation, or two collinear regressors).
    #[error("rank-deficient regressor: numerical rank {rank}, condition number {condition:e}")]
    RankDeficient {
        /// Number of singular values above the tolerance.
        rank: usize,
        /// Ratio of largest to smallest singular value of the
        /// column-equilibrated regressor (`inf` when a column is zero).
        condition: f64,
    },
    /// Too few samples (or regression rows) for the requested computation.
    #[error("{what}: need at least {needed} samples, got {got}")]
    TooFewSamples {
        /// What needed them (`"least squares"`, `"mass-spring identification"`, …).
        what: &'static str,
        /// Minimum number required.
        needed: usize,
        /// Number supplied.
        got: usize,
    },
    /// An in-memory recording is inconsistent: columns of different lengths,
    /// a non-finite value, or a time column that is not strictly increasing
    /// and uniformly sampled.
    #[error("invalid recording at sample {index}: {reason}")]
    InvalidRecording {
        /// Zero-based sample index at fault.
        index: usize,
        /// What is wrong.
        reason: String,
    },
    /// A recording has no channel of that name, or a channel's name or unit
    /// cannot be used (empty, duplicated, or with characters a CSV header
    /// cannot hold).
    #[error("channel `{name}`: {reason}")]
    Channel {
        /// The channel's name as asked for or given.
        name: String,
        /// What is wrong; for a missing channel, the channels there are.
        reason: String,
    },
    /// An index is past the end of what it indexes (an output channel of a
    /// response, …).
    #[error("{what} index {index} is out of range: there are {len}")]
    OutOfRange {
        /// What was indexed (`"output"`, …).
        what: &'static str,
        /// The index asked for.
        index: usize,
        /// How many there are (valid indices are `0..len`).
        len: usize,
    },
    /// A result was computed but fails the accuracy check the operation
    /// applies to it: the problem is too ill-conditioned for double
    /// precision (a pole placement whose poles land elsewhere, a matrix
    /// exponential whose rounding errors grow past the result).
    #[error(
        "{operation}: too ill-conditioned for double precision \
         (estimated relative error {error:.1e}, limit {limit:.0e})"
    )]
    IllConditioned {
        /// The operation (`"Ackermann pole placement"`, …).
        operation: &'static str,
        /// The relative error found or estimated.
        error: f64,
        /// The largest relative error the operation accepts.
        limit: f64,
    },
    /// A matrix has an eigenvalue where the operation is undefined: a
    /// discrete model's pole on the closed negative real axis has no
    /// continuous counterpart under ZOH (no real principal logarithm), one
    /// at `z = −1` none under Tustin.
    #[error("{operation}: eigenvalue {} + {}i {reason}", Readable(*.re), Readable(*.im))]
    EigenvalueOutOfDomain {
        /// The operation (`"ZOH d2c …"`, `"matrix logarithm"`, …).
        operation: &'static str,
        /// Real part of the eigenvalue.
        re: f64,
        /// Imaginary part of the eigenvalue.
        im: f64,
        /// Where it lies and why that is refused.
        reason: &'static str,
    },
    /// A target pole handed to a pole-placement routine is unusable.
    #[error("target pole {index} ({re} + {im}i): {reason}")]
    InvalidPole {
        /// Zero-based index of the pole in the targets.
        index: usize,
        /// Its real part.
        re: f64,
        /// Its imaginary part.
        im: f64,
        /// What is wrong with it.
        reason: &'static str,
    },
}

/// The category of an [`Error`], for callers that branch on what happened
/// rather than on the details (as embedded-hal's error kinds).
///
/// `#[non_exhaustive]`: match with a wildcard arm.
///
/// # Examples
///
/// ```
/// use ctrlab::{Error, ErrorKind};
///
/// let e = Error::InvalidParameter { name: "dt", value: -1.0, reason: "must be > 0" };
/// assert_eq!(e.kind(), ErrorKind::InvalidInput);
/// assert_eq!(Error::Singular { operation: "Tustin" }.kind(), ErrorKind::Numerical);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum ErrorKind {
    /// An argument is out of its domain: a parameter, a matrix's entries or
    /// shape, data, a pole, an index, too few samples.
    InvalidInput,
    /// The computation cannot be done to working precision: a singular or
    /// ill-conditioned matrix, an overflow, an iteration that did not
    /// converge, a rank-deficient regressor, a pole placed elsewhere.
    Numerical,
    /// The model lacks a property the operation needs: stability,
    /// controllability, observability, or a response that settles.
    System,
}

impl Error {
    /// What kind of failure this is.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{Error, ErrorKind};
    /// assert_eq!(Error::Uncontrollable { rank: 3, states: 4 }.kind(), ErrorKind::System);
    /// ```
    pub fn kind(&self) -> ErrorKind {
        match self {
            Error::InvalidParameter { .. }
            | Error::NonFinite { .. }
            | Error::InvalidData { .. }
            | Error::LengthMismatch { .. }
            | Error::InvalidMatrix { .. }
            | Error::DimensionMismatch { .. }
            | Error::TooFewSamples { .. }
            | Error::InvalidRecording { .. }
            | Error::Channel { .. }
            | Error::OutOfRange { .. }
            | Error::InvalidPole { .. } => ErrorKind::InvalidInput,
            Error::Singular { .. }
            | Error::SingularEquation { .. }
            | Error::Overflow { .. }
            | Error::PoleNotPlaced { .. }
            | Error::NoConvergence { .. }
            | Error::RankDeficient { .. }
            | Error::IllConditioned { .. } => ErrorKind::Numerical,
            Error::NotSettled { .. }
            | Error::Unstable { .. }
            | Error::EigenvalueOutOfDomain { .. }
            | Error::Uncontrollable { .. }
            | Error::Unobservable { .. } => ErrorKind::System,
        }
    }
}

/// Why a response did not settle ([`Error::NotSettled`]), judged from its
/// final window: a hint at what to change, not a proof.
///
/// # Examples
///
/// ```
/// use ctrlab::{Error, StepInfoOptions, metrics::{SettleFailure, step_info}};
///
/// let t: Vec<f64> = (0..=100).map(|k| k as f64 * 0.01).collect();
/// let growing: Vec<f64> = t.iter().map(|t| (4.0 * t).exp() - 1.0).collect();
/// match step_info(&t, &growing, &StepInfoOptions::default()) {
///     Err(Error::NotSettled { cause, .. }) => assert_eq!(cause, SettleFailure::Diverging),
///     other => panic!("{other:?}"),
/// }
/// assert!(SettleFailure::TooShort.hint().contains("longer"));
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum SettleFailure {
    /// The deviation from the final value keeps growing (an unstable loop,
    /// a ramp).
    Diverging,
    /// The response keeps crossing the final value without decaying (an
    /// undamped or barely damped oscillation).
    Oscillating,
    /// The response is still converging when the record ends.
    TooShort,
}

impl SettleFailure {
    /// What to check or change, in a few words.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::metrics::SettleFailure;
    /// assert!(SettleFailure::Diverging.hint().contains("unstable"));
    /// ```
    pub fn hint(self) -> &'static str {
        match self {
            SettleFailure::Diverging => {
                "the deviation keeps growing: is the loop unstable (check its poles)?"
            }
            SettleFailure::Oscillating => {
                "it keeps oscillating about the final value: the loop is undamped or \
                 barely damped (check the damping of its poles)"
            }
            SettleFailure::TooShort => {
                "it is still converging: use a longer record (a larger t_end) or a wider \
                 settling band"
            }
        }
    }
}

impl std::fmt::Display for SettleFailure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            SettleFailure::Diverging => "diverging",
            SettleFailure::Oscillating => "oscillating",
            SettleFailure::TooShort => "record too short",
        })
    }
}

/// A time printed to six significant digits, without the float noise of
/// the shortest round-trip form (`0.475`, not `0.47500000000000003`).
struct Short(f64);

impl std::fmt::Display for Short {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let v = self.0;
        if v == 0.0 || !v.is_finite() {
            return write!(f, "{v}");
        }
        let digits = 5 - v.abs().log10().floor() as i32;
        let p = 10f64.powi(digits.abs());
        let rounded = if digits >= 0 {
            (v * p).round() / p
        } else {
            (v / p).round() * p
        };
        // Fall back to the value itself where the scaling over- or underflows.
        write!(f, "{}", if rounded.is_finite() { rounded } else { v })
    }
}

/// Checks a matrix's entries as [`check_finite`] does, for any size
/// (run-time sized, or fixed inside code written over nalgebra's `Dim`).
pub(crate) fn check_finite_dyn<R: nalgebra::Dim, C: nalgebra::Dim, S>(
    matrix: &'static str,
    m: &nalgebra::Matrix<f64, R, C, S>,
) -> Result<(), Error>
where
    S: nalgebra::RawStorage<f64, R, C>,
{
    match m.iter().position(|v| !v.is_finite()) {
        None => Ok(()),
        Some(i) => Err(Error::NonFinite {
            matrix,
            row: i % m.nrows(),
            col: i / m.nrows(),
            value: m[i],
        }),
    }
}

/// Checks a matrix's shape (a run-time-sized one's; a fixed-size one's
/// always holds).
pub(crate) fn check_shape<R: nalgebra::Dim, C: nalgebra::Dim, S>(
    matrix: &'static str,
    m: &nalgebra::Matrix<f64, R, C, S>,
    rows: usize,
    cols: usize,
) -> Result<(), Error>
where
    S: nalgebra::RawStorage<f64, R, C>,
{
    if m.shape() == (rows, cols) {
        Ok(())
    } else {
        Err(Error::DimensionMismatch {
            matrix,
            expected_rows: rows,
            expected_cols: cols,
            found_rows: m.nrows(),
            found_cols: m.ncols(),
        })
    }
}

/// [`Error::LengthMismatch`] named `what` unless `found == expected`.
pub(crate) fn check_len(what: &'static str, expected: usize, found: usize) -> Result<(), Error> {
    if found == expected {
        Ok(())
    } else {
        Err(Error::LengthMismatch {
            what,
            expected,
            found,
        })
    }
}

/// Checks that every entry of a matrix is finite; names the first bad one.
pub(crate) fn check_finite<const R: usize, const C: usize>(
    matrix: &'static str,
    m: &nalgebra::SMatrix<f64, R, C>,
) -> Result<(), Error> {
    for c in 0..C {
        for r in 0..R {
            let value = m[(r, c)];
            if !value.is_finite() {
                return Err(Error::NonFinite {
                    matrix,
                    row: r,
                    col: c,
                    value,
                });
            }
        }
    }
    Ok(())
}

/// Checks a time step: finite and strictly positive.
pub(crate) fn check_dt(dt: f64) -> Result<(), Error> {
    if dt.is_finite() && dt > 0.0 {
        Ok(())
    } else {
        Err(Error::InvalidParameter {
            name: "dt",
            value: dt,
            reason: "time step must be finite and > 0 s",
        })
    }
}
