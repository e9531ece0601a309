//! The principal matrix logarithm, the inverse of [`expm`](super::expm):
//! inverse scaling and squaring (Kenney & Laub 1989; Cheng, Higham,
//! Kenney & Laub 2001). Square roots by the product form of the
//! Denman–Beavers iteration with determinant scaling bring the matrix
//! within `‖X − I‖₁ ≤ ¼` of the identity, where the degree-8 diagonal
//! Padé approximant of `log(I + X)`, in its partial-fraction form (the
//! Gauss–Legendre rule on `log(I + X) = ∫₀¹ X (I + t X)⁻¹ dt`), is exact
//! to rounding; the result is that approximant times `2^s` for `s` roots.

use nalgebra::{Complex, DMatrix, SMatrix};

use crate::analysis::eigenvalues_dyn;
use crate::error::{Error, check_finite, check_finite_dyn, check_shape};
use crate::kernels::linalg::{frobenius, norm1};

/// Largest estimated relative error of a matrix logarithm (and so of a ZOH
/// [`d2c`](crate::StateSpace::d2c)) that is returned; above it the result
/// is refused with [`Error::IllConditioned`].
///
/// The estimate is `ε κ`, with `κ = ‖L_log(M)‖ ‖M‖_F / ‖log M‖_F` the
/// relative condition number of the logarithm at `M`, its Fréchet
/// derivative's norm bounded below by the largest divided difference
/// `|(log λᵢ − log λⱼ)/(λᵢ − λⱼ)|` over the eigenvalues (`1/|λ|` for
/// `i = j`; exact for a normal `M`). It is large when an eigenvalue is
/// tiny against `‖M‖` (a mode that decayed past rounding within the
/// sampling period), when a complex pair nears the negative real axis
/// (a pole near the Nyquist frequency), or when `log M` is tiny against
/// `M` (a period so short that `M` stores `log M` in few digits). For a
/// ZOH [`d2c`](crate::StateSpace::d2c), `M` is `Ad`: the identity block
/// of `[[Ad, Bd], [0, I]]` is exact and `B` follows `Bd` linearly.
///
/// # Examples
///
/// ```
/// use ctrlab::{Error, discretize::{LOGM_MAX_ERROR, logm}};
/// use ctrlab::nalgebra::matrix;
///
/// // A mode 25 time constants fast next to a slow one: e^-25 ≈ 1.4e-11
/// // is known to a few digits only under the rounding of the other entry.
/// let m = matrix![1.0, 1.0; 0.0, (-25.0f64).exp()];
/// match logm(&m) {
///     Err(Error::IllConditioned { error, limit, .. }) => assert!(error > limit && limit == LOGM_MAX_ERROR),
///     other => panic!("{other:?}"),
/// }
/// ```
pub const LOGM_MAX_ERROR: f64 = 1e-8;

/// Gauss–Legendre nodes and weights on `[0, 1]`, 8 points: the
/// `[8/8]` Padé approximant of `log(1 + x)` as `Σ wⱼ x / (1 + tⱼ x)`.
/// Its relative error at `x = −¼`, the worst point of the disc the
/// square roots reach, is 3.6e-17 (measured with mpmath at 40 digits).
const GAUSS_LEGENDRE: [(f64, f64); 8] = [
    (0.019855071751231884, 0.05061426814518813),
    (0.10166676129318664, 0.11119051722668724),
    (0.2372337950418355, 0.15685332293894363),
    (0.4082826787521751, 0.181341891689181),
    (0.591717321247825, 0.181341891689181),
    (0.7627662049581645, 0.15685332293894363),
    (0.8983332387068134, 0.11119051722668724),
    (0.9801449282487681, 0.05061426814518813),
];

/// `‖X − I‖₁` at or below which the Padé approximant is applied.
const PADE_RADIUS: f64 = 0.25;

/// Square roots at most: each halves the logarithm, and a finite matrix
/// with eigenvalues off the refused set has `‖log M‖` far below `2^64`.
const MAX_ROOTS: usize = 64;

/// Denman–Beavers iterations at most per square root (quadratic once
/// close; the determinant scaling brings it close in a few).
const MAX_ITERATIONS: usize = 100;

/// Eigenvalues within this many `n ε ‖M‖_F` of the closed negative real
/// axis are taken to be on it.
const AXIS_FACTOR: f64 = 100.0;

/// The principal logarithm `L` of `exp(L) = A`, the inverse of
/// [`expm`](super::expm) (MATLAB's `logm`, SciPy's `scipy.linalg.logm`),
/// real for a real `A`: every eigenvalue of `L` has its imaginary part in
/// `(−π, π)`.
///
/// # Errors
///
/// [`Error::NonFinite`] for a NaN or infinite entry;
/// [`Error::EigenvalueOutOfDomain`] naming an eigenvalue on the closed
/// negative real axis (zero included), where no real principal logarithm
/// exists; [`Error::IllConditioned`] when the estimated relative error
/// exceeds [`LOGM_MAX_ERROR`] (see there); [`Error::NoConvergence`] if a
/// square-root iteration does not converge within its cap.
///
/// # Examples
///
/// ```
/// use ctrlab::discretize::{expm, logm};
/// use ctrlab::nalgebra::matrix;
///
/// // The rotation by θ < π has the principal logarithm [[0, −θ], [θ, 0]].
/// let theta = 2.5f64;
/// let r = matrix![theta.cos(), -theta.sin(); theta.sin(), theta.cos()];
/// let l = logm(&r)?;
/// assert!((l - matrix![0.0, -theta; theta, 0.0]).amax() < 1e-14);
/// assert!((expm(&logm(&matrix![2.0, 1.0; 0.0, 3.0])?)? - matrix![2.0, 1.0; 0.0, 3.0]).amax() < 1e-14);
/// // −1 has no real logarithm.
/// assert!(logm(&matrix![-1.0]).is_err());
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub fn logm<const N: usize>(a: &SMatrix<f64, N, N>) -> Result<SMatrix<f64, N, N>, Error> {
    check_finite("A", a)?;
    let l = principal_log(
        &DMatrix::from_column_slice(N, N, a.as_slice()),
        "matrix logarithm",
    )?;
    Ok(SMatrix::from_column_slice(l.as_slice()))
}

/// [`logm`] of a square run-time-sized matrix: the same algorithm, checks
/// and refusals.
///
/// # Errors
///
/// [`Error::DimensionMismatch`] named `"A"` unless `a` is square; as
/// [`logm`] otherwise.
///
/// # Examples
///
/// ```
/// use ctrlab::discretize::logm_dyn;
/// use ctrlab::nalgebra::{DMatrix, dmatrix};
///
/// // log of a Jordan block: log(λ) on the diagonal, 1/λ above it.
/// let l = logm_dyn(&dmatrix![2.0, 1.0; 0.0, 2.0])?;
/// assert!((l - dmatrix![2f64.ln(), 0.5; 0.0, 2f64.ln()]).amax() < 1e-15);
/// assert!(logm_dyn(&DMatrix::zeros(2, 3)).is_err());
/// assert!(logm_dyn(&dmatrix![0.0, 1.0; 0.0, 1.0]).is_err()); // singular
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[doc(alias = "logm")]
pub fn logm_dyn(a: &DMatrix<f64>) -> Result<DMatrix<f64>, Error> {
    check_shape("A", a, a.nrows(), a.nrows())?;
    check_finite_dyn("A", a)?;
    principal_log(a, "matrix logarithm")
}

/// The principal logarithm of a square, finite `m`, refused as [`logm`]
/// documents; `operation` names the caller in the errors.
pub(super) fn principal_log(
    m: &DMatrix<f64>,
    operation: &'static str,
) -> Result<DMatrix<f64>, Error> {
    let none = DMatrix::zeros(m.nrows(), 0);
    held_log(m, &none, operation).map(|(l, _)| l)
}

/// `(L, F)` with `[[L, F], [0, 0]] = log([[E, G], [0, I]])` (`E` square,
/// finite, `G` with as many rows), the inverse of ZOH's exponential, on
/// the blocks alone: each square root of `[[E, G], [0, I]]` is
/// `[[R, (R + I)⁻¹ G], [0, I]]` with `R = E^½`, and the Padé form of
/// `log(I + [[X, Y], [0, 0]])` is `[[Σ wⱼ X (I + tⱼ X)⁻¹, Σ wⱼ (I + tⱼ X)⁻¹ Y], [0, 0]]`.
/// The identity block is exact and `F` linear in `G`, so `E` alone is
/// judged: its eigenvalues against the negative real axis, and the error
/// estimate of [`LOGM_MAX_ERROR`] with `‖E‖_F` and `‖L‖_F`.
pub(super) fn held_log(
    e: &DMatrix<f64>,
    g: &DMatrix<f64>,
    operation: &'static str,
) -> Result<(DMatrix<f64>, DMatrix<f64>), Error> {
    let n = e.nrows();
    if n == 0 {
        return Ok((DMatrix::zeros(0, 0), DMatrix::zeros(0, g.ncols())));
    }
    let norm = frobenius(e);
    let eigenvalues = &eigenvalues_dyn(e)?;
    let on_axis = AXIS_FACTOR * n as f64 * f64::EPSILON * norm;
    if let Some(l) = eigenvalues
        .iter()
        .find(|l| l.norm() <= on_axis || (l.re < 0.0 && l.im.abs() <= on_axis))
    {
        return Err(Error::EigenvalueOutOfDomain {
            operation,
            re: l.re,
            im: l.im,
            reason: "lies on the closed negative real axis: no real principal logarithm",
        });
    }
    let slope = largest_divided_difference(eigenvalues);
    let ill = |error: f64| Error::IllConditioned {
        operation: "matrix logarithm (an eigenvalue tiny against the matrix, a complex \
                    pair near the negative real axis, or a logarithm tiny against the \
                    matrix)",
        error,
        limit: LOGM_MAX_ERROR,
    };
    let (l, f) = match inverse_scaling_squaring(e, g, operation) {
        Ok(lf) => lf,
        Err(failed) => {
            // The square roots broke down (a pair so near the negative
            // axis that `M + I`-like iterates are singular): judged with
            // the eigenvalues' logarithms for `‖log M‖_F`, which bound it
            // below, the error estimate says why.
            let size = eigenvalues
                .iter()
                .map(|l| l.ln().norm_sqr())
                .sum::<f64>()
                .sqrt();
            let error = f64::EPSILON * slope * norm / size;
            return Err(if error.is_nan() || error > LOGM_MAX_ERROR {
                ill(error)
            } else {
                failed
            });
        }
    };
    let size = l.norm();
    let error = if size > 0.0 {
        f64::EPSILON * slope * norm / size
    } else {
        0.0
    };
    if !error.is_finite() || error > LOGM_MAX_ERROR {
        return Err(ill(error));
    }
    if l.iter().chain(f.iter()).any(|v| !v.is_finite()) {
        return Err(Error::Overflow { operation });
    }
    Ok((l, f))
}

/// `max |(log λᵢ − log λⱼ)/(λᵢ − λⱼ)|` over the eigenvalues, `1/|λᵢ|` for
/// coincident ones: a lower bound on the norm of the logarithm's Fréchet
/// derivative (its eigenvalues).
fn largest_divided_difference(eigenvalues: &[Complex<f64>]) -> f64 {
    let mut largest = 0.0f64;
    for &li in eigenvalues {
        for &lj in eigenvalues {
            let z = (li - lj) / lj;
            let d = li.ln() - lj.ln();
            // Near each other across the negative real axis the principal
            // logarithms differ by about 2πi: no series there.
            let across = (d - (li / lj).ln()).norm() > 1.0;
            let g = if z.norm() < 1e-4 && !across {
                // log(1 + z) / (z λⱼ) by its series: no cancellation.
                (Complex::new(1.0, 0.0) - z / 2.0 + z * z / 3.0) / lj
            } else {
                d / (li - lj)
            };
            largest = largest.max(g.norm());
        }
    }
    largest
}

/// `(L, F)` of [`held_log`] (no eigenvalue of `e` on the closed negative
/// real axis) by inverse scaling and squaring.
fn inverse_scaling_squaring(
    e: &DMatrix<f64>,
    g: &DMatrix<f64>,
    operation: &'static str,
) -> Result<(DMatrix<f64>, DMatrix<f64>), Error> {
    let n = e.nrows();
    let id = DMatrix::<f64>::identity(n, n);
    let (mut x, mut y) = (e.clone(), g.clone());
    let mut roots = 0;
    while norm1(&(&x - &id)) > PADE_RADIUS {
        if roots == MAX_ROOTS {
            return Err(Error::NoConvergence {
                operation: "matrix logarithm (square roots)",
                iterations: roots,
            });
        }
        x = square_root(&x, operation)?;
        y = (&x + &id)
            .lu()
            .solve(&y)
            .ok_or(Error::Singular { operation })?;
        roots += 1;
    }
    let x = x - &id;
    let mut l = DMatrix::<f64>::zeros(n, n);
    let mut f = DMatrix::<f64>::zeros(n, g.ncols());
    for (t, w) in GAUSS_LEGENDRE {
        let lu = (&id + &x * t).lu();
        l += lu.solve(&x).ok_or(Error::Singular { operation })? * w;
        f += lu.solve(&y).ok_or(Error::Singular { operation })? * w;
    }
    let scale = 2f64.powi(roots as i32);
    Ok((l * scale, f * scale))
}

/// The principal square root of `a` by the product form of the
/// Denman–Beavers iteration with determinant scaling (Higham, *Functions
/// of Matrices*, 2008, eq. 6.29): `M ← ½ (I + (μ² M + μ⁻² M⁻¹)/2)`,
/// `X ← ½ μ X (I + μ⁻² M⁻¹)`, from `M = X = A`, `μ = |det M|^(−1/(2n))`
/// while `M` is far from `I`; `X → A^½`, `M → I`.
fn square_root(a: &DMatrix<f64>, operation: &'static str) -> Result<DMatrix<f64>, Error> {
    let n = a.nrows();
    let id = DMatrix::<f64>::identity(n, n);
    let (mut x, mut m) = (a.clone(), a.clone());
    let mut close = false;
    for _ in 0..MAX_ITERATIONS {
        let lu = m.clone().lu();
        let log_det: f64 = lu.u().diagonal().iter().map(|u| u.abs().ln()).sum();
        let inv = lu.try_inverse().ok_or(Error::Singular { operation })?;
        let mu = if close {
            1.0
        } else {
            (-log_det / (2 * n) as f64).exp()
        };
        if !mu.is_finite() || mu == 0.0 {
            return Err(Error::Overflow { operation });
        }
        let mu2 = mu * mu;
        x = &x * (&id + &inv / mu2) * (0.5 * mu);
        m = (&id + (&m * mu2 + &inv / mu2) * 0.5) * 0.5;
        if x.iter().chain(m.iter()).any(|v| !v.is_finite()) {
            return Err(Error::Overflow { operation });
        }
        let gap = norm1(&(&m - &id));
        if close && gap <= 1e-12 {
            // The step after `M` came within 1e-8 of `I` squared its
            // distance: converged to rounding.
            return Ok(x);
        }
        close = gap <= 1e-8;
    }
    Err(Error::NoConvergence {
        operation: "matrix square root (Denman–Beavers)",
        iterations: MAX_ITERATIONS,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::dmatrix;

    #[test]
    fn square_root_squares_back() {
        let a = dmatrix![4.0, 1.0, 0.0; 0.5, 3.0, -1.0; 0.0, 2.0, 5.0];
        let r = square_root(&a, "test").unwrap();
        assert!((&r * &r - &a).amax() < 1e-13 * a.amax());
    }

    #[test]
    fn pade_is_exact_to_rounding_on_its_radius() {
        for x in [-PADE_RADIUS, PADE_RADIUS, 1e-3] {
            let r: f64 = GAUSS_LEGENDRE
                .iter()
                .map(|(t, w)| w * x / (1.0 + t * x))
                .sum();
            assert!((r - x.ln_1p()).abs() <= 2.0 * f64::EPSILON * x.ln_1p().abs());
        }
    }
}
