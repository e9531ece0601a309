//! The DC gain, written once over nalgebra's dimensions: both model types'
//! `dc_gain` (a fixed-size model's on stack matrices, without allocating).

use nalgebra::{DefaultAllocator, Dim, OMatrix, allocator::Allocator};

use crate::error::Error;
use crate::kernels::linalg::Lu;
use crate::kernels::reduce::pow2_floor;

/// The steady-state gain of `(A, B, C, D)`: `−C A⁻¹ B + D` in continuous
/// time (`period = None`), `C (I − A)⁻¹ B + D` in discrete time.
pub(crate) fn dc_gain<N: Dim, M: Dim, P: Dim>(
    a: &OMatrix<f64, N, N>,
    b: &OMatrix<f64, N, M>,
    c: &OMatrix<f64, P, N>,
    d: &OMatrix<f64, P, M>,
    period: Option<f64>,
) -> Result<OMatrix<f64, P, M>, Error>
where
    DefaultAllocator:
        Allocator<N, N> + Allocator<N, M> + Allocator<P, N> + Allocator<P, M> + Allocator<N>,
{
    let g = match period {
        None => {
            let x = gain_solve(a.clone(), b.clone(), "DC gain (pole at s = 0)")?;
            d - c * x
        }
        Some(_) => {
            let (n, _) = a.shape_generic();
            let i_minus_a = OMatrix::<f64, N, N>::identity_generic(n, n) - a;
            let x = gain_solve(i_minus_a, b.clone(), "DC gain (pole at z = 1)")?;
            c * x + d
        }
    };
    if g.iter().all(|v| v.is_finite()) {
        Ok(g)
    } else {
        Err(Error::Overflow {
            operation: "DC gain",
        })
    }
}

/// Solves `m x = b` for a DC gain, refusing an `m` so ill-conditioned that
/// the gain would have fewer than about four correct digits: a pole at
/// s = 0 / z = 1 that rounding moved slightly off it must be reported, not
/// turned into a huge, meaningless number. The equations are first scaled
/// by powers of two (each row's largest entry in [1, 2)), and the test is
/// the Skeel condition number `‖ |m⁻¹| |m| ‖∞`, which no such scaling
/// changes: `diag(−1, −1e12)` is perfectly conditioned.
fn gain_solve<N: Dim, M: Dim>(
    mut m: OMatrix<f64, N, N>,
    mut b: OMatrix<f64, N, M>,
    operation: &'static str,
) -> Result<OMatrix<f64, N, M>, Error>
where
    DefaultAllocator: Allocator<N, N> + Allocator<N, M> + Allocator<N>,
{
    let (dim, _) = m.shape_generic();
    for i in 0..dim.value() {
        let f = 1.0 / pow2_floor(m.row(i).amax());
        m.row_mut(i).scale_mut(f);
        b.row_mut(i).scale_mut(f);
    }
    let lu = Lu::new(&m, operation)?;
    let skeel = (lu
        .solve(&OMatrix::<f64, N, N>::identity_generic(dim, dim))
        .abs()
        * m.abs())
    .row_iter()
    .map(|r| r.sum())
    .fold(0.0, f64::max);
    if !skeel.is_finite() || skeel * f64::EPSILON > 1e-4 {
        return Err(Error::Singular { operation });
    }
    Ok(lu.solve(&b))
}
