//! Issue 28: hostile but representable models on which the transfer-function
//! numerics returned wrong answers (each test failed before its fix). Every
//! `Ok` holds finite numbers that are right; where a result cannot be
//! represented the call refuses with a typed error naming the operation.

use ctrlab::DynStateSpace;
use ctrlab::freq::FrequencyDomain;
use nalgebra::{Complex, dmatrix};

/// `A = diag(−1e160, −1)`, `B = [1; 0]`, `C = [1e160, 1]`:
/// `G = 1e160 / (s + 1e160)`, `G(j) ≈ 1`.
fn wide_model() -> DynStateSpace {
    DynStateSpace::continuous(
        dmatrix![-1e160, 0.0; 0.0, -1.0],
        dmatrix![1.0; 0.0],
        dmatrix![1e160, 1.0],
        dmatrix![0.0],
    )
    .unwrap()
}

#[test]
fn frequency_response_of_a_widely_scaled_model() {
    let sys = wide_model();
    let r = sys.frequency_response(&[1.0, 0.0]).unwrap();
    let g = r.response(0, 0).unwrap();
    for (k, want) in [(0, Complex::new(1.0, -1e-160)), (1, Complex::new(1.0, 0.0))] {
        assert!(
            (g[k] - want).norm() < 1e-15,
            "G at {k}: {} (want {want})",
            g[k]
        );
    }
    let e = sys.evaluate(Complex::new(0.0, 1.0)).unwrap();
    assert!(
        (e[(0, 0)] - Complex::new(1.0, 0.0)).norm() < 1e-15,
        "evaluate: {e}"
    );
}
