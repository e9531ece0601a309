//! Lyapunov and Sylvester equations (`analysis::{lyap, dlyap, sylvester}`)
//! against SciPy 1.17.1 and python-control 0.10.2, closed forms,
//! refusals, and invariants by proptest.
//!
//! Fixtures: `tests/data/lyapunov_fixtures.json`, from
//! `tests/data/gen_lyapunov_fixtures.py` (see `tests/data/README.md`).
//! Tolerance: SciPy's own test criterion for these solvers
//! (`scipy/linalg/tests/test_solvers.py`, `TestSolveLyapunov.check_continuous_case`,
//! `check_discrete_case`, `TestSolveSylvester.check_case`:
//! `assert_array_almost_equal(lhs, rhs)` at its default `decimal=6`, i.e.
//! every entry of the absolute residual below `1.5e-6`), stored in the
//! fixture as `scipy_residual_atol`. On top of it, ctrlab's `X` is compared
//! with SciPy's entry by entry relative to SciPy's largest entry
//! (`X_AGREEMENT`, about 50 times the largest difference measured: 2.2e-11,
//! on the pair of eigenvalues 1e-6 from the imaginary axis; run with
//! `--nocapture` to see each case's).

mod common;

use ctrlab::Error;
use ctrlab::analysis::{dlyap, lyap, lyapchol, sylvester};
use ctrlab::signal::Rng;
use nalgebra::{DMatrix, SMatrix, dmatrix, matrix};
use proptest::prelude::*;

/// `max |X − X_SciPy| / max |X_SciPy|` allowed, per family; SciPy's `X`
/// comes from LAPACK's Schur and `dtrsyl` (the discrete one for `n > 10`
/// from a bilinear map to a continuous equation), so the two differ by
/// the conditioning of each case times ε.
const X_AGREEMENT: f64 = 1e-9;

use common::{dmatrix as dm, rel_max as rel_diff};

/// The fixed-size solution of a fixture case of `N` states, on the heap.
fn fixed_lyap<const N: usize>(a: &DMatrix<f64>, q: &DMatrix<f64>, discrete: bool) -> DMatrix<f64> {
    let (a, q) = (
        SMatrix::<f64, N, N>::from_column_slice(a.as_slice()),
        SMatrix::<f64, N, N>::from_column_slice(q.as_slice()),
    );
    let x = if discrete {
        dlyap(&a, &q)
    } else {
        lyap(&a, &q)
    }
    .unwrap()
    .x;
    DMatrix::from_column_slice(N, N, x.as_slice())
}

fn fixed_if_small(a: &DMatrix<f64>, q: &DMatrix<f64>, discrete: bool) -> Option<DMatrix<f64>> {
    Some(match a.nrows() {
        1 => fixed_lyap::<1>(a, q, discrete),
        2 => fixed_lyap::<2>(a, q, discrete),
        3 => fixed_lyap::<3>(a, q, discrete),
        4 => fixed_lyap::<4>(a, q, discrete),
        5 => fixed_lyap::<5>(a, q, discrete),
        _ => return None,
    })
}

fn lyapunov_family(kind: &str) -> f64 {
    let data = common::fixture("lyapunov_fixtures.json");
    let atol = data["scipy_residual_atol"].as_f64().unwrap();
    let discrete = kind == "dlyap";
    let mut worst: f64 = 0.0;
    for case in data[kind].as_array().unwrap() {
        let name = case["name"].as_str().unwrap();
        let (a, q, scipy_x) = (dm(&case["a"]), dm(&case["q"]), dm(&case["x"]));
        let sol = if discrete {
            dlyap(&a, &q)
        } else {
            lyap(&a, &q)
        }
        .unwrap_or_else(|e| panic!("{kind} {name}: {e}"));
        let x = &sol.x;
        let residual = if discrete {
            &a * x * a.transpose() - x + &q
        } else {
            &a * x + x * a.transpose() + &q
        };
        let diff = rel_diff(x, &scipy_x);
        println!(
            "{kind} {name} (n = {}): max |residual| {:.1e}, relative residual {:.1e}, \
             X vs SciPy {diff:.1e}",
            a.nrows(),
            residual.amax(),
            sol.residual
        );
        assert!(residual.amax() < atol, "{kind} {name}: SciPy's criterion");
        assert!(
            diff < X_AGREEMENT,
            "{kind} {name}: X differs from SciPy's by {diff:e}"
        );
        assert!(
            sol.residual < 1e-13,
            "{kind} {name}: residual {:e}",
            sol.residual
        );
        if let Some(fixed) = fixed_if_small(&a, &q, discrete) {
            assert_eq!(fixed.as_slice(), x.as_slice(), "{kind} {name}: fixed size");
        }
        worst = worst.max(diff);
    }
    worst
}

#[test]
fn lyap_agrees_with_scipy_and_python_control() {
    let worst = lyapunov_family("lyap");
    println!("lyap: largest difference from SciPy {worst:.1e}");
}

#[test]
fn dlyap_agrees_with_scipy_and_python_control() {
    let worst = lyapunov_family("dlyap");
    println!("dlyap: largest difference from SciPy {worst:.1e}");
}

#[test]
fn sylvester_agrees_with_scipy() {
    let data = common::fixture("lyapunov_fixtures.json");
    let atol = data["scipy_residual_atol"].as_f64().unwrap();
    let mut worst: f64 = 0.0;
    for case in data["sylvester"].as_array().unwrap() {
        let name = case["name"].as_str().unwrap();
        let (a, b, c, scipy_x) = (
            dm(&case["a"]),
            dm(&case["b"]),
            dm(&case["c"]),
            dm(&case["x"]),
        );
        let sol = sylvester(&a, &b, &c).unwrap_or_else(|e| panic!("sylvester {name}: {e}"));
        let residual = &a * &sol.x + &sol.x * &b - &c;
        let diff = rel_diff(&sol.x, &scipy_x);
        println!(
            "sylvester {name}: max |residual| {:.1e}, relative residual {:.1e}, X vs SciPy {diff:.1e}",
            residual.amax(),
            sol.residual
        );
        assert!(
            residual.amax() < atol,
            "sylvester {name}: SciPy's criterion"
        );
        assert!(diff < X_AGREEMENT, "sylvester {name}: {diff:e}");
        assert!(
            sol.residual < 1e-13,
            "sylvester {name}: residual {:e}",
            sol.residual
        );
        worst = worst.max(diff);
    }
    println!("sylvester: largest difference from SciPy {worst:.1e}");
}

/// `B` with `B Bᵀ = Q` for a symmetric positive semidefinite `Q`.
fn square_root(q: &DMatrix<f64>) -> DMatrix<f64> {
    let e = q.clone().symmetric_eigen();
    let d = e.eigenvalues.map(|l| l.max(0.0).sqrt());
    &e.eigenvectors * DMatrix::from_diagonal(&d)
}

/// Hammarling's factor against SciPy's `X` on every stable case whose `Q`
/// is semidefinite (all but SciPy's own cases): `Rᵀ R` to `X_AGREEMENT`.
#[test]
fn lyapchol_agrees_with_scipy() {
    let data = common::fixture("lyapunov_fixtures.json");
    let mut worst: f64 = 0.0;
    for case in data["lyap"].as_array().unwrap() {
        let name = case["name"].as_str().unwrap();
        if name.starts_with("scipy_") {
            continue;
        }
        let (a, q, scipy_x) = (dm(&case["a"]), dm(&case["q"]), dm(&case["x"]));
        let b = square_root(&q);
        let r = lyapchol(&a, &b).unwrap_or_else(|e| panic!("lyapchol {name}: {e}"));
        let f = &r.factor;
        let diff = rel_diff(&(f.transpose() * f), &scipy_x);
        println!(
            "lyapchol {name}: RᵀR vs SciPy's X {diff:.1e}, residual {:.1e}",
            r.residual
        );
        assert!(diff < X_AGREEMENT, "lyapchol {name}: {diff:e}");
        assert!(r.residual < 1e-13, "lyapchol {name}: {:e}", r.residual);
        for j in 0..f.ncols() {
            assert!(f[(j, j)] >= 0.0);
            for i in j + 1..f.nrows() {
                assert_eq!(f[(i, j)], 0.0, "{name}: not upper triangular");
            }
        }
        worst = worst.max(diff);
    }
    println!("lyapchol: largest difference from SciPy {worst:.1e}");
}

/// A nearly uncontrollable model: modes at −1 and −2 rad/s, the second
/// driven 1e-10 as hard, seen through a rotation. The Gramian's smallest
/// eigenvalue is 1e-20 / 36 (its square root 1e-10 / 6), far below the
/// rounding errors of `X` (about ε ‖X‖ = 1e-16), so no factor of a
/// computed `X` can hold it; Hammarling's `R` does, to its own rounding
/// errors relative to the direction (ε ‖R‖ / σ_min ≈ 7e-6; measured
/// 3.3e-6).
#[test]
fn lyapchol_keeps_a_nearly_uncontrollable_direction() {
    let (c, s) = (0.6, 0.8);
    let rot = matrix![c, -s; s, c];
    let a = rot * matrix![-1.0, 0.0; 0.0, -2.0] * rot.transpose();
    let b = rot * matrix![1.0; 1e-10];
    let r = lyapchol(&a, &b).unwrap().factor;
    let sv = r.singular_values();
    let smallest = sv.min();
    assert!(
        (smallest - 1e-10 / 6.0).abs() < 3e-5 * 1e-10 / 6.0,
        "{smallest:e}"
    );
    assert!((sv.max() - 0.5f64.sqrt()).abs() < 1e-14);
}

#[test]
fn lyapchol_closed_forms_and_refusals() {
    // a x + x a + b² = 0: x = −b² / (2a), r = |b| / √(−2a).
    let r = lyapchol(&matrix![-2.0], &matrix![3.0]).unwrap();
    assert!((r.factor[(0, 0)] - 1.5).abs() < 1e-15);
    // Two inputs, fixed size: B is 2 × 3.
    let a = matrix![-1.0, 0.5; 0.0, -3.0];
    let b = matrix![1.0, 0.0, 2.0; 0.5, 1.0, 0.0];
    let r = lyapchol(&a, &b).unwrap();
    let x = lyap(&a, &(b * b.transpose())).unwrap().x;
    assert!((r.factor.transpose() * r.factor - x).amax() < 1e-14);
    // No input: X = 0.
    let none = lyapchol(&(-DMatrix::identity(2, 2)), &DMatrix::zeros(2, 0)).unwrap();
    assert_eq!(none.factor, DMatrix::zeros(2, 2));
    // Unstable, and on the imaginary axis: refused.
    assert!(matches!(
        lyapchol(&matrix![0.5, 0.0; 0.0, -1.0], &matrix![1.0; 1.0]),
        Err(Error::Unstable { re, .. }) if re == 0.5
    ));
    assert!(matches!(
        lyapchol(&matrix![0.0, 1.0; -4.0, 0.0], &matrix![0.0; 1.0]),
        Err(Error::Unstable { .. })
    ));
    assert!(matches!(
        lyapchol(&DMatrix::identity(2, 2), &DMatrix::zeros(3, 1)),
        Err(Error::DimensionMismatch { matrix: "B", .. })
    ));
}

#[test]
fn the_fixtures_come_from_the_stated_versions() {
    let data = common::fixture("lyapunov_fixtures.json");
    assert_eq!(data["versions"]["scipy"], "1.17.1");
    assert_eq!(data["versions"]["control"], "0.10.2");
    // python-control (without slycot) calls SciPy: the same numbers.
    assert_eq!(data["control_vs_scipy_max_rel_diff"]["lyap"], 0.0);
    assert_eq!(data["control_vs_scipy_max_rel_diff"]["dlyap"], 0.0);
}

fn diag(d: &[f64]) -> DMatrix<f64> {
    DMatrix::from_diagonal(&nalgebra::DVector::from_column_slice(d))
}

#[test]
fn closed_forms() {
    // First-order Gramian: a x + x a + q = 0, x = −q / (2a).
    for (a, q) in [(-2.0, 9.0), (-1e-3, 1.0), (-1e4, 3.0), (5.0, 1.0)] {
        let x = lyap(&matrix![a], &matrix![q]).unwrap().x[(0, 0)];
        assert!((x + q / (2.0 * a)).abs() <= 1e-15 * x.abs(), "{a} {q}: {x}");
        // a x a − x + q = 0, x = q / (1 − a²).
        let ad = 1.0 / (1.0 - a);
        let x = dlyap(&matrix![ad], &matrix![q]).unwrap().x[(0, 0)];
        assert!(
            (x - q / (1.0 - ad * ad)).abs() <= 1e-14 * x.abs(),
            "{ad} {q}: {x}"
        );
    }
    // Diagonal A: X_ij = −Q_ij / (a_i + a_j), X_ij = Q_ij / (1 − a_i a_j).
    let d = [-1.0, -2.5, -10.0];
    let dz = [0.5, -0.9, 0.1];
    let q = dmatrix![4.0, 1.0, 0.5; 1.0, 3.0, -1.0; 0.5, -1.0, 2.0];
    let x = lyap(&diag(&d), &q).unwrap().x;
    let xd = dlyap(&diag(&dz), &q).unwrap().x;
    let c = dmatrix![1.0, 2.0; 3.0, 4.0; 5.0, 6.0];
    let b = [3.0, 7.0];
    let xs = sylvester(&diag(&d), &diag(&b), &c).unwrap().x;
    for i in 0..3 {
        for j in 0..3 {
            let exact = -q[(i, j)] / (d[i] + d[j]);
            assert!((x[(i, j)] - exact).abs() <= 1e-15 * exact.abs().max(1.0));
            let exact = q[(i, j)] / (1.0 - dz[i] * dz[j]);
            assert!((xd[(i, j)] - exact).abs() <= 1e-15 * exact.abs().max(1.0));
        }
        for j in 0..2 {
            let exact = c[(i, j)] / (d[i] + b[j]);
            assert!((xs[(i, j)] - exact).abs() <= 1e-15 * exact.abs().max(1.0));
        }
    }
}

#[test]
fn a_second_order_gramian() {
    // ẍ + 2ζωn ẋ + ωn² x = u: the controllability Gramian is
    // diag(1 / (4ζωn³), 1 / (4ζωn)).
    let (zeta, wn) = (0.3, 10.0);
    let a = matrix![0.0, 1.0; -wn * wn, -2.0 * zeta * wn];
    let b = matrix![0.0; 1.0];
    let sol = lyap(&a, &(b * b.transpose())).unwrap();
    let exact = matrix![1.0 / (4.0 * zeta * wn.powi(3)), 0.0; 0.0, 1.0 / (4.0 * zeta * wn)];
    assert!((sol.x - exact).amax() < 1e-15, "{}", sol.x);
    assert_eq!(sol.x, sol.x.transpose());
}

fn singular(result: Result<impl std::fmt::Debug, Error>) -> (f64, f64, f64, f64, &'static str) {
    match result {
        Err(Error::SingularEquation {
            lambda_re,
            lambda_im,
            mu_re,
            mu_im,
            condition,
            ..
        }) => (lambda_re, lambda_im, mu_re, mu_im, condition),
        other => panic!("expected SingularEquation, got {other:?}"),
    }
}

/// Repeated, non-defective eigenvalues under a rotation
/// (`Q diag(−1, −2, −1, …) Qᵀ`), and a rotated Jordan chain: nalgebra's
/// Schur iteration stalls on some of the former (seed 4, n = 9, and seed
/// 21, n = 26, even with 200 iterations per dimension), and the EISPACK
/// iteration with exceptional shifts takes over.
#[test]
fn repeated_eigenvalues_are_solved() {
    for seed in 0..25u64 {
        let mut rng = Rng::new(seed);
        let n = 5 + (seed as usize % 40);
        let g = DMatrix::from_fn(n, n, |_, _| rng.gaussian());
        let rotation = g.qr().q();
        let d = DMatrix::from_fn(n, n, |i, j| match (i == j, i % 2) {
            (true, 0) => -1.0,
            (true, _) => -2.0,
            _ => 0.0,
        });
        let mut chain = DMatrix::from_fn(n, n, |i, j| f64::from(u8::from(j == i + 1)));
        chain.fill_diagonal(-1.0);
        let q = DMatrix::identity(n, n);
        for a in [
            &rotation * d * rotation.transpose(),
            &rotation * chain * rotation.transpose(),
        ] {
            let sol = lyap(&a, &q).unwrap_or_else(|e| panic!("seed {seed}, n = {n}: {e}"));
            assert!(sol.residual < 1e-12, "seed {seed}: {:e}", sol.residual);
            let sol = dlyap(&(&a * 0.4), &q).unwrap_or_else(|e| panic!("seed {seed}: {e}"));
            assert!(sol.residual < 1e-12, "seed {seed}: {:e}", sol.residual);
        }
    }
}

#[test]
fn singular_spectra_are_refused_by_name() {
    let eye = SMatrix::<f64, 2, 2>::identity();
    // An integrator (eigenvalue 0).
    let (lr, li, mr, mi, cond) = singular(lyap(&matrix![0.0, 1.0; 0.0, -1.0], &eye));
    assert_eq!((lr, li, mr, mi, cond), (0.0, 0.0, 0.0, 0.0, "λ + μ = 0"));
    // An undamped oscillator at 3 rad/s: ±3i.
    let (lr, li, mr, mi, _) = singular(lyap(&matrix![0.0, 1.0; -9.0, 0.0], &eye));
    assert!(lr.abs() < 1e-12 && mr.abs() < 1e-12);
    assert!((li.abs() - 3.0).abs() < 1e-12 && (li + mi).abs() < 1e-12);
    // λ and −λ (a saddle).
    let (lr, _, mr, _, _) = singular(lyap(
        &dmatrix![2.0, 0.0; 1.0, -2.0],
        &dmatrix![1.0, 0.0; 0.0, 1.0],
    ));
    assert!((lr + mr).abs() < 1e-12 && (lr.abs() - 2.0).abs() < 1e-12);
    // The message names the equation and both eigenvalues.
    let e = lyap(&matrix![0.0], &matrix![1.0]).unwrap_err();
    assert!(e.to_string().contains("continuous Lyapunov"), "{e}");
    assert_eq!(e.kind(), ctrlab::ErrorKind::Numerical);

    // Discrete: z = 1, z = −1, a rotation by 0.5 rad, λ and 1/λ.
    for a in [matrix![1.0, 0.3; 0.0, 0.5], matrix![-1.0, 0.0; 2.0, 0.2]] {
        let (lr, li, mr, mi, cond) = singular(dlyap(&a, &eye));
        assert_eq!(cond, "λ μ = 1");
        assert!((lr * mr - li * mi - 1.0).abs() < 1e-12 && lr.abs() == 1.0);
    }
    let (c, s) = (0.5f64.cos(), 0.5f64.sin());
    let (lr, li, mr, mi, _) = singular(dlyap(&matrix![c, -s; s, c], &eye));
    assert!((lr * mr - li * mi - 1.0).abs() < 1e-12 && (lr * mi + li * mr).abs() < 1e-12);
    let (lr, _, mr, _, _) = singular(dlyap(&matrix![4.0, 1.0; 0.0, 0.25], &eye));
    assert!((lr * mr - 1.0).abs() < 1e-12);
    // Sylvester: λ(A) = −μ(B).
    let (lr, _, mr, _, _) = singular(sylvester(
        &matrix![1.0, 5.0; 0.0, 2.0],
        &matrix![-2.0],
        &matrix![1.0; 1.0],
    ));
    assert_eq!((lr, mr), (2.0, -2.0));
    // Near the singularity but not on it: solved (eigenvalues −1e-9 ± i).
    let near = lyap(&matrix![-1e-9, 1.0; -1.0, -1e-9], &eye).unwrap();
    assert!((near.x[(0, 0)] - 0.5e9).abs() < 1e-6 * 0.5e9);
}

#[test]
fn bad_arguments_are_named() {
    let sq = DMatrix::<f64>::identity(3, 3);
    let tall = DMatrix::<f64>::zeros(3, 2);
    assert!(matches!(
        lyap(&tall, &sq),
        Err(Error::DimensionMismatch { matrix: "A", .. })
    ));
    assert!(matches!(
        dlyap(&sq, &DMatrix::identity(2, 2)),
        Err(Error::DimensionMismatch { matrix: "Q", .. })
    ));
    assert!(matches!(
        sylvester(&sq, &DMatrix::identity(2, 2), &sq),
        Err(Error::DimensionMismatch { matrix: "C", .. })
    ));
    let mut nan = -sq.clone();
    nan[(1, 2)] = f64::NAN;
    assert!(matches!(
        lyap(&nan, &sq),
        Err(Error::NonFinite {
            matrix: "A",
            row: 1,
            col: 2,
            ..
        })
    ));
    assert!(matches!(
        dlyap(&(&sq * 0.5), &nan),
        Err(Error::NonFinite { matrix: "Q", .. })
    ));
    // Empty problems have empty solutions, as SciPy's.
    let empty = DMatrix::<f64>::zeros(0, 0);
    assert_eq!(lyap(&empty, &empty).unwrap().x.shape(), (0, 0));
    let s = sylvester(&empty, &DMatrix::identity(2, 2), &DMatrix::zeros(0, 2)).unwrap();
    assert_eq!(s.x.shape(), (0, 2));
}

/// An `n × n` matrix with entries in [−1, 1] shifted by its largest
/// absolute row sum plus `margin` (Gershgorin: every eigenvalue has real
/// part at most −margin).
fn stable(v: &[f64], n: usize, margin: f64) -> DMatrix<f64> {
    let m = DMatrix::from_column_slice(n, n, &v[..n * n]);
    let shift = (0..n)
        .map(|i| m.row(i).iter().map(|x| x.abs()).sum::<f64>())
        .fold(0.0, f64::max);
    m - DMatrix::identity(n, n) * (shift + margin)
}

fn symmetric(v: &[f64], n: usize) -> DMatrix<f64> {
    let g = DMatrix::from_column_slice(n, n, &v[..n * n]);
    &g * g.transpose()
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 200, ..ProptestConfig::default() })]

    #[test]
    fn residuals_are_small_relative_to_the_data(
        n in 1usize..=8,
        v in proptest::collection::vec(-1.0..1.0f64, 64),
        w in proptest::collection::vec(-1.0..1.0f64, 64),
        margin in 0.01..2.0f64,
        radius in 0.05..0.99f64,
    ) {
        let a = stable(&v, n, margin);
        let q = symmetric(&w, n);
        let x = lyap(&a, &q).unwrap();
        let r = (&a * &x.x + &x.x * a.transpose() + &q).norm()
            / (2.0 * a.norm() * x.x.norm() + q.norm()).max(f64::MIN_POSITIVE);
        prop_assert!(r < 1e-10 && x.residual < 1e-10, "{r:e} {:e}", x.residual);
        prop_assert_eq!(&x.x, &x.x.transpose());
        // Hammarling's factor of the same X (Q = G Gᵀ).
        let g = DMatrix::from_column_slice(n, n, &w[..n * n]);
        let f = lyapchol(&a, &g).unwrap();
        prop_assert!(f.residual < 1e-10, "{:e}", f.residual);
        let xf = f.factor.transpose() * &f.factor;
        prop_assert!((&xf - &x.x).amax() <= 1e-10 * x.x.amax(), "{xf} {}", x.x);

        // Spectral radius below `radius` (the ∞-norm bounds it).
        let m = DMatrix::from_column_slice(n, n, &v[..n * n]);
        let ad = &m * (radius / m.row_iter().map(|r| r.abs().sum()).fold(1e-300, f64::max));
        let xd = dlyap(&ad, &q).unwrap();
        let r = (&ad * &xd.x * ad.transpose() - &xd.x + &q).norm()
            / ((ad.norm().powi(2) + 1.0) * xd.x.norm() + q.norm()).max(f64::MIN_POSITIVE);
        prop_assert!(r < 1e-10 && xd.residual < 1e-10, "{r:e} {:e}", xd.residual);
        prop_assert_eq!(&xd.x, &xd.x.transpose());

        // Sylvester: A and B stable, so λ + μ ≤ −2 margin.
        let b = stable(&w, n.max(2) - 1, margin);
        let c = DMatrix::from_column_slice(n, b.nrows(), &w[..n * b.nrows()]);
        let xs = sylvester(&a, &b, &c).unwrap();
        let r = (&a * &xs.x + &xs.x * &b - &c).norm()
            / ((a.norm() + b.norm()) * xs.x.norm() + c.norm()).max(f64::MIN_POSITIVE);
        prop_assert!(r < 1e-10 && xs.residual < 1e-10, "{r:e} {:e}", xs.residual);
    }

    #[test]
    fn fixed_and_run_time_sizes_give_the_same_x(
        v in proptest::collection::vec(-1.0..1.0f64, 49),
        w in proptest::collection::vec(-1.0..1.0f64, 49),
        margin in 0.01..2.0f64,
    ) {
        let (a, q) = (stable(&v, 7, margin), symmetric(&w, 7));
        let (fa, fq) = (
            SMatrix::<f64, 7, 7>::from_column_slice(a.as_slice()),
            SMatrix::<f64, 7, 7>::from_column_slice(q.as_slice()),
        );
        let (f, d) = (lyap(&fa, &fq).unwrap(), lyap(&a, &q).unwrap());
        prop_assert_eq!(f.x.as_slice(), d.x.as_slice());
        prop_assert_eq!(f.residual, d.residual);
        let (f, d) = (lyapchol(&fa, &fq).unwrap(), lyapchol(&a, &q).unwrap());
        prop_assert_eq!(f.factor.as_slice(), d.factor.as_slice());
        let (f, d) = (dlyap(&(fa * 0.1), &fq).unwrap(), dlyap(&(&a * 0.1), &q).unwrap());
        prop_assert_eq!(f.x.as_slice(), d.x.as_slice());
        let c = SMatrix::<f64, 7, 3>::from_column_slice(&w[..21]);
        let fb = SMatrix::<f64, 3, 3>::identity() * 2.0 + SMatrix::<f64, 3, 3>::from_column_slice(&v[..9]) * 0.1;
        let f = sylvester(&fa, &fb, &c).unwrap();
        let d = sylvester(&a, &DMatrix::from_column_slice(3, 3, fb.as_slice()),
                          &DMatrix::from_column_slice(7, 3, c.as_slice())).unwrap();
        prop_assert_eq!(f.x.as_slice(), d.x.as_slice());
    }

    #[test]
    fn no_panic_on_extreme_input(
        n in 1usize..=4,
        v in proptest::collection::vec(prop_oneof![
            4 => -10.0..10.0f64,
            1 => proptest::num::f64::ANY,
            1 => prop_oneof![Just(f64::MAX), Just(-1e308), Just(1e-308), Just(0.0)],
        ], 32),
    ) {
        let a = DMatrix::from_column_slice(n, n, &v[..n * n]);
        let q = DMatrix::from_column_slice(n, n, &v[16..16 + n * n]);
        let results = [lyap(&a, &q), dlyap(&a, &q), sylvester(&a, &q, &a)];
        for sol in results.into_iter().flatten() {
            prop_assert!(sol.x.iter().all(|x| x.is_finite()));
        }
    }
}
