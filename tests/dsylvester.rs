//! The discrete Sylvester (Stein) equation `analysis::dsylvester`,
//! `A X B − X + C = 0`, against a dense Kronecker solve in NumPy (the
//! `stein` cases of `tests/data/d2c_fixtures.json`, from
//! `tests/data/gen_d2c_fixtures.py`), closed forms, refusals, and its
//! residual by proptest.

mod common;

use ctrlab::Error;
use ctrlab::analysis::dsylvester;
use ctrlab::signal::Rng;
use nalgebra::{DMatrix, SMatrix, dmatrix, matrix};
use proptest::prelude::*;

use common::{dmatrix as dm, rel_max as rel};

#[test]
fn stein_matches_a_kronecker_solve() {
    let data = common::fixture("d2c_fixtures.json");
    let mut worst: f64 = 0.0;
    for case in data["stein"].as_array().unwrap() {
        let (a, b, c, x) = (
            dm(&case["a"]),
            dm(&case["b"]),
            dm(&case["c"]),
            dm(&case["x"]),
        );
        let sol = dsylvester(&a, &b, &c).unwrap();
        let e = rel(&sol.x, &x);
        assert!(e < 1e-11, "{}: {e:e}", case["name"]);
        assert!(
            sol.residual < 1e-14,
            "{}: residual {:e}",
            case["name"],
            sol.residual
        );
        worst = worst.max(e);
        if (a.nrows(), b.nrows()) == (2, 3) {
            let f = dsylvester(
                &SMatrix::<f64, 2, 2>::from_column_slice(a.as_slice()),
                &SMatrix::<f64, 3, 3>::from_column_slice(b.as_slice()),
                &SMatrix::<f64, 2, 3>::from_column_slice(c.as_slice()),
            )
            .unwrap();
            assert_eq!(f.x.as_slice(), sol.x.as_slice());
        }
    }
    println!("stein: worst {worst:e}");
}

#[test]
fn scalar_closed_form_and_overflow() {
    // x = c / (1 − a b).
    let s = dsylvester(&matrix![3.0], &matrix![0.2], &matrix![1.0]).unwrap();
    assert!((s.x[(0, 0)] - 1.0 / (1.0 - 0.6)).abs() <= 2.0 * f64::EPSILON * 2.5);
    // Stein whose solution overflows: c = 1e300 over 1 − a b = 1e-10.
    let r = dsylvester(&matrix![1.0 - 1e-10], &matrix![1.0], &matrix![1e300]);
    assert!(matches!(r, Err(Error::Overflow { .. })), "{r:?}");
}

#[test]
fn stein_refusals_and_extremes() {
    // λ μ = 1: 2 · 0.5, and −1 · −1.
    match dsylvester(
        &matrix![2.0, 0.0; 0.0, 0.3],
        &matrix![0.5],
        &matrix![1.0; 1.0],
    ) {
        Err(Error::SingularEquation {
            lambda_re,
            mu_re,
            condition,
            ..
        }) => {
            assert_eq!((lambda_re, mu_re, condition), (2.0, 0.5, "λ μ = 1"));
        }
        other => panic!("{other:?}"),
    }
    assert!(matches!(
        dsylvester(&dmatrix![-1.0], &dmatrix![-1.0], &dmatrix![1.0]),
        Err(Error::SingularEquation { .. })
    ));
    assert!(matches!(
        dsylvester(&dmatrix![f64::NAN], &dmatrix![0.5], &dmatrix![1.0]),
        Err(Error::NonFinite { matrix: "A", .. })
    ));
    assert!(matches!(
        dsylvester(&dmatrix![0.5], &dmatrix![0.5], &dmatrix![f64::INFINITY]),
        Err(Error::NonFinite { matrix: "C", .. })
    ));
    assert!(matches!(
        dsylvester(&dmatrix![0.5], &DMatrix::zeros(2, 2), &dmatrix![1.0]),
        Err(Error::DimensionMismatch { matrix: "C", .. })
    ));
    assert!(matches!(
        dsylvester(&DMatrix::zeros(2, 3), &dmatrix![0.5], &dmatrix![1.0; 1.0]),
        Err(Error::DimensionMismatch { matrix: "A", .. })
    ));
    assert_eq!(
        dsylvester(&DMatrix::zeros(0, 0), &dmatrix![0.5], &DMatrix::zeros(0, 1))
            .unwrap()
            .x
            .shape(),
        (0, 1)
    );
    // A 1e300 against B 1e-300: balanced, x = c / (1 − a b) = 2.
    let s = dsylvester(
        &dmatrix![1e300, 0.0; 0.0, 2e300],
        &dmatrix![-1e-300],
        &dmatrix![2.0; 3.0],
    )
    .unwrap();
    assert!(
        (s.x[(0, 0)] - 1.0).abs() < 1e-15 && (s.x[(1, 0)] - 1.0).abs() < 1e-15,
        "{}",
        s.x
    );
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 200, ..ProptestConfig::default() })]

    /// The Stein residual is small relative to the data when the
    /// spectral radii keep λ μ away from 1.
    #[test]
    fn stein_residual_is_small(
        seed in any::<u64>(),
        m in 1usize..=7,
        n in 1usize..=7,
        ra in 0.05..3.0f64,
        rb in 0.05..0.3f64,
    ) {
        let mut rng = Rng::new(seed);
        let mut square = |k: usize, radius: f64| {
            let g = DMatrix::from_fn(k, k, |_, _| rng.gaussian());
            let inf = g.row_iter().map(|r| r.abs().sum()).fold(1e-300, f64::max);
            g * (radius / inf)
        };
        // ∞-norms bound the spectral radii: ρ(A) ρ(B) ≤ ‖A‖∞ ‖B‖∞ ≤ 0.9,
        // with ‖A‖∞ up to 3 (A itself may be unstable).
        let a = square(m, ra);
        let b = square(n, rb.min(0.9 / ra));
        let c = DMatrix::from_fn(m, n, |_, _| rng.gaussian());
        let s = dsylvester(&a, &b, &c).unwrap();
        let r = (&a * &s.x * &b - &s.x + &c).norm()
            / (a.norm() * s.x.norm() * b.norm() + s.x.norm() + c.norm());
        prop_assert!(r < 1e-14 && s.residual < 1e-14, "{r:e} {:e}", s.residual);
    }
}
