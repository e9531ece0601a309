//! `analysis::dlyapchol` (the discrete Hammarling factor) against SciPy
//! 1.17.1's `solve_discrete_lyapunov` (`tests/data/gram_fixtures.json`,
//! from `tests/data/gen_gram_fixtures.py`), closed forms and refusals.
//! Run with `--nocapture` for each case's measured difference.

mod common;

use common::{dmatrix as dm, rel_max as rel_diff};
use ctrlab::Error;
use ctrlab::analysis::{dlyap, dlyapchol};
use ctrlab::nalgebra::{DMatrix, dmatrix, matrix};

/// `dlyapchol`'s `Rᵀ R` against SciPy's `solve_discrete_lyapunov` `X`,
/// relative to `max |X|`; measured at most 6.9e-12 (the case with
/// spectral radius 0.999; the others below 1e-13), bounded here at 1e-10.
#[test]
fn dlyapchol_agrees_with_scipy() {
    let data = common::fixture("gram_fixtures.json");
    let mut worst: f64 = 0.0;
    for (k, case) in data["dlyapchol"].as_array().unwrap().iter().enumerate() {
        let (a, b, x) = (dm(&case["a"]), dm(&case["b"]), dm(&case["x"]));
        let r = dlyapchol(&a, &b).unwrap_or_else(|e| panic!("case {k}: {e}"));
        let f = &r.factor;
        let diff = rel_diff(&(f.transpose() * f), &x);
        println!(
            "dlyapchol case {k} (n = {}): {diff:.1e}, residual {:.1e}",
            a.nrows(),
            r.residual
        );
        assert!(diff < 1e-10, "case {k}: {diff:e}");
        assert!(r.residual < 1e-13, "case {k}: {:e}", r.residual);
        assert_eq!(f.upper_triangle(), *f, "case {k}: not upper triangular");
        assert!(f.diagonal().iter().all(|&d| d >= 0.0), "case {k}: {f}");
        worst = worst.max(diff);
    }
    println!("dlyapchol: largest difference from SciPy {worst:.1e}");
}

#[test]
fn dlyapchol_closed_forms_and_refusals() {
    // a² x − x + b² = 0: r = |b| / √(1 − a²), fixed size and run time.
    let r = dlyapchol(&matrix![-0.6], &matrix![2.0]).unwrap();
    assert!((r.factor[(0, 0)] - 2.5).abs() < 1e-15);
    let r = dlyapchol(&dmatrix![0.6], &dmatrix![-2.0]).unwrap();
    assert!((r.factor[(0, 0)] - 2.5).abs() < 1e-15);
    // A complex pair and two inputs, fixed size: against dlyap.
    let a = matrix![0.5, 0.6, 0.1; -0.6, 0.5, 0.0; 0.0, 0.0, -0.9];
    let b = matrix![1.0, 0.0; 0.0, 2.0; 1.0, 1.0];
    let r = dlyapchol(&a, &b).unwrap();
    let x = dlyap(&a, &(b * b.transpose())).unwrap().x;
    assert!((r.factor.transpose() * r.factor - x).amax() < 1e-13 * x.amax());
    // A nearly uncontrollable direction (z = 0.5, 0.25 driven 1e-10 as
    // hard, rotated): the factor keeps it to rounding relative to it
    // (smallest singular value of R ≈ 1e-10 · 0.2; measured relative
    // error 2.1e-6, about ε ‖R‖ / σ_min = 6e-6; bounded at 1e-4).
    let rot = matrix![0.6, -0.8; 0.8, 0.6];
    let a = rot * matrix![0.5, 0.0; 0.0, 0.25] * rot.transpose();
    let b = rot * matrix![1.0; 1e-10];
    let sv = dlyapchol(&a, &b).unwrap().factor.singular_values();
    let exact = (1.0f64 - 0.25).recip().sqrt();
    assert!((sv.max() - exact).abs() < 1e-14);
    // Smallest: the Gramian of (A, b) in the rotated basis is 2 × 2 with
    // det = 1e-20 · (1/(1−.25) · 1/(1−.0625) − 1/(1−.125)²); √(det) / σ_max.
    let (w11, w22, w12): (f64, f64, f64) = (1.0 / 0.75, 1.0 / 0.9375, 1.0 / 0.875);
    let smallest = 1e-10 * (w11 * w22 - w12 * w12).sqrt() / w11.sqrt();
    println!(
        "dlyapchol: smallest direction off by {:.1e} relative",
        (sv.min() - smallest).abs() / smallest
    );
    assert!(
        (sv.min() - smallest).abs() < 1e-4 * smallest,
        "{} {smallest}",
        sv.min()
    );
    // No input: R = 0; 0 × 0: empty.
    assert_eq!(
        dlyapchol(&DMatrix::identity(2, 2).scale(0.5), &DMatrix::zeros(2, 0))
            .unwrap()
            .factor,
        DMatrix::zeros(2, 2)
    );
    assert_eq!(
        dlyapchol(&DMatrix::<f64>::zeros(0, 0), &DMatrix::zeros(0, 1))
            .unwrap()
            .factor
            .nrows(),
        0
    );
    // Refusals by name.
    assert!(
        matches!(dlyapchol(&matrix![1.0, 0.0; 0.0, 0.5], &matrix![1.0; 1.0]),
                     Err(Error::Unstable { re, .. }) if re == 1.0)
    );
    assert!(matches!(
        dlyapchol(&matrix![0.0, -1.0; 1.0, 0.0], &matrix![1.0; 0.0]),
        Err(Error::Unstable { .. })
    ));
    assert!(
        matches!(dlyapchol(&matrix![-1.5], &matrix![1.0]), Err(Error::Unstable { re, .. }) if re == -1.5)
    );
    assert!(matches!(
        dlyapchol(&dmatrix![0.5, f64::NAN; 0.0, 0.5], &dmatrix![1.0; 1.0]),
        Err(Error::NonFinite { matrix: "A", .. })
    ));
    assert!(matches!(
        dlyapchol(&dmatrix![0.5], &dmatrix![f64::INFINITY]),
        Err(Error::NonFinite { matrix: "B", .. })
    ));
    assert!(matches!(
        dlyapchol(&DMatrix::identity(2, 2), &DMatrix::zeros(3, 1)),
        Err(Error::DimensionMismatch { matrix: "B", .. })
    ));
    assert!(matches!(
        dlyapchol(&DMatrix::zeros(2, 3), &DMatrix::zeros(2, 1)),
        Err(Error::DimensionMismatch { matrix: "A", .. })
    ));
    // 1e300 in B: B is scaled by a power of two, R = 1e300 / √0.75 fits.
    let r = dlyapchol(&matrix![0.5], &matrix![1e300]).unwrap().factor[(0, 0)];
    assert!((r / (1e300 / 0.75f64.sqrt()) - 1.0).abs() < 1e-15);
}
