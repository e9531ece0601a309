//! The crate's one stability test, on run-time-sized matrices, with a
//! fixed-size entry point for the design code.

use nalgebra::{Complex, DMatrix, SMatrix};

use super::ITERATIONS_PER_DIM;
use crate::error::Error;
use crate::kernels::linalg::boundary_tolerance;
use crate::model::{Domain, DynStateSpace, period_of};

/// [`first_unstable_dyn`] for a fixed-size `a` (the LQR and observer
/// checks).
pub(crate) fn first_unstable<const N: usize>(
    poles: &[Complex<f64>; N],
    a: &SMatrix<f64, N, N>,
    period: Option<f64>,
) -> Option<Complex<f64>> {
    first_unstable_dyn(
        poles,
        &DMatrix::from_column_slice(N, N, a.as_slice()),
        period,
    )
}

/// The crate's one stability test: the first of `poles` (eigenvalues of `a`)
/// on or outside the stability boundary of the domain with sampling period
/// `period` (`None`: continuous), within rounding of `a`.
///
/// A pole is on the boundary when it is within its own rounding error of
/// it: the smaller of the normwise bound `100 N ε max(1, ‖A‖₁)` and the
/// componentwise one `100 N ε |y|ᵀ|A||x| / |yᴴx|` (`x`, `y` its right and
/// left eigenvectors), which is what the pole's error is when `A`'s entries
/// are known to a relative ε. The componentwise bound does not change under
/// a diagonal change of state units (it is the bound of the balanced
/// matrix), so `diag(−1e−3, −1e12)` is stable, while a rigid-body mode
/// computed from physical parameters stays on the boundary. It is computed
/// only for poles the normwise bound leaves in doubt.
pub(crate) fn first_unstable_dyn(
    poles: &[Complex<f64>],
    a: &DMatrix<f64>,
    period: Option<f64>,
) -> Option<Complex<f64>> {
    let normwise = boundary_tolerance(a);
    let outside = |p: &Complex<f64>, tol: f64| match period {
        None => p.re >= -tol,
        Some(_) => p.norm() >= 1.0 - tol,
    };
    let strictly_inside = |p: &Complex<f64>| match period {
        None => p.re < 0.0,
        Some(_) => p.norm() < 1.0,
    };
    poles.iter().copied().find(|p| {
        outside(p, normwise)
            && !(strictly_inside(p)
                && componentwise_tolerance(a, *p).is_some_and(|tol| !outside(p, tol)))
    })
}

/// `100 N ε |y|ᵀ|A||x| / |yᴴx|`, the rounding error of the eigenvalue `p`
/// of `a` under relative perturbations of its entries, with `x`, `y` the
/// right and left singular vectors of `A − p I` for its smallest singular
/// value (its eigenvectors). `None` when the SVD fails.
fn componentwise_tolerance(a: &DMatrix<f64>, p: Complex<f64>) -> Option<f64> {
    let n = a.nrows();
    let shifted = DMatrix::from_fn(n, n, |i, j| {
        Complex::new(a[(i, j)], 0.0) - if i == j { p } else { Complex::new(0.0, 0.0) }
    });
    let iterations = ITERATIONS_PER_DIM * n;
    let svd = shifted.try_svd_unordered(true, true, f64::EPSILON, iterations)?;
    if svd.singular_values.iter().any(|s| !s.is_finite()) {
        return None;
    }
    let (u, v_t) = (svd.u?, svd.v_t?);
    let k = svd.singular_values.imin();
    let x = v_t.row(k).adjoint();
    let y = u.column(k);
    let mut weighted = 0.0;
    for i in 0..n {
        for j in 0..n {
            weighted += y[i].norm() * a[(i, j)].abs() * x[j].norm();
        }
    }
    let overlap = y.dotc(&x).norm();
    let tol = 100.0 * n as f64 * f64::EPSILON * weighted / overlap;
    tol.is_finite().then_some(tol)
}

/// The poles of `sys`, or [`Error::Unstable`] of `operation` naming the
/// first on or outside the stability boundary by the crate's one test
/// ([`StateSpace::unstable_pole`](crate::StateSpace::unstable_pole)):
/// what the Gramians and the system norms require.
pub(crate) fn stable_poles<D: Domain>(
    sys: &DynStateSpace<D>,
    operation: &'static str,
) -> Result<Vec<Complex<f64>>, Error> {
    let poles = sys.poles()?;
    match first_unstable_dyn(&poles, sys.a(), period_of(&sys.domain())) {
        Some(p) => Err(Error::Unstable {
            operation,
            re: p.re,
            im: p.im,
        }),
        None => Ok(poles),
    }
}
