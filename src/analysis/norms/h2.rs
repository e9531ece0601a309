//! The H2 norm of a stable model from its controllability Gramian.

use nalgebra::DMatrix;

use super::super::{dlyap, lyapchol};
use crate::error::Error;
use crate::kernels::linalg::frobenius;
use crate::kernels::reduce::pow2_floor;

const OPERATION: &str = "H2 norm";

/// [`h2_norm`](super::h2_norm) of the stable `(a, b, c, d)` (period
/// `period`, `None` continuous).
pub(super) fn h2(
    a: &DMatrix<f64>,
    b: &DMatrix<f64>,
    c: &DMatrix<f64>,
    d: &DMatrix<f64>,
    period: Option<f64>,
) -> Result<f64, Error> {
    if period.is_none() && d.iter().any(|&v| v != 0.0) {
        return Err(Error::InvalidMatrix {
            matrix: "D",
            reason: "a continuous model with D ≠ 0 has an infinite H2 norm \
                     (python-control and MATLAB return inf)",
        });
    }
    // Exact scalings: G = β κ G' with B' = B / β, C' = C / κ.
    let (beta, kappa) = (pow2_floor(b.amax()), pow2_floor(c.amax()));
    let (b, c) = (b / beta, c / kappa);
    let scaled = if a.is_empty() || b.is_empty() || c.is_empty() {
        0.0
    } else if period.is_none() {
        // W_c = Rᵀ R: trace(C Rᵀ R Cᵀ) = ‖R Cᵀ‖_F².
        let r = lyapchol(a, &b)?.factor;
        frobenius(&(r * c.transpose()))
    } else {
        let w = dlyap(a, &(&b * b.transpose()))?.x;
        // C W Cᵀ is positive semidefinite; a rounded negative trace is 0.
        (c.clone() * w * c.transpose()).trace().max(0.0).sqrt()
    };
    let value = (scaled * beta * kappa).hypot(frobenius(d));
    if value.is_finite() {
        Ok(value)
    } else {
        Err(Error::Overflow {
            operation: OPERATION,
        })
    }
}
