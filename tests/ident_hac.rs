//! `Covariance::NeweyWest` against statsmodels (`tests/data/hac_fixtures.json`),
//! against a direct evaluation of its lag sums, and in its limits.

use ctrlab::ident::{Covariance, LeastSquares, newey_west_lags};
use nalgebra::{DMatrix, DVector};
use proptest::prelude::*;
use serde_json::Value;

fn fixtures() -> Value {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/hac_fixtures.json");
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

fn numbers(v: &Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

fn rows(v: &Value) -> Vec<Vec<f64>> {
    v.as_array().unwrap().iter().map(numbers).collect()
}

/// The problem `X θ ≈ y` with segments starting at `starts`.
fn problem(x: &[Vec<f64>], y: &[f64], starts: &[usize], covariance: Covariance) -> LeastSquares {
    let mut ls = LeastSquares::new(x[0].len()).with_covariance(covariance);
    for (k, (row, &y)) in x.iter().zip(y).enumerate() {
        if starts.contains(&k) {
            ls.start_segment();
        }
        ls.push_row(row, y).unwrap();
    }
    ls
}

#[test]
fn newey_west_matches_statsmodels() {
    let fixtures = fixtures();
    let cases = fixtures["cases"].as_array().unwrap();
    assert_eq!(cases.len(), 14);
    for case in cases {
        let name = case["name"].as_str().unwrap();
        let (x, y) = (rows(&case["X"]), numbers(&case["y"]));
        let starts: Vec<usize> = numbers(&case["segment_starts"])
            .iter()
            .map(|&s| s as usize)
            .collect();
        let lags = case["lags"].as_u64().unwrap() as usize;
        let rule = case["rule_of_thumb"].as_u64().unwrap() as usize;
        assert_eq!(newey_west_lags(y.len()), rule, "{name}");
        let covariance = if case["automatic"].as_bool().unwrap() {
            Covariance::NeweyWest { lags: None }
        } else {
            Covariance::NeweyWest { lags: Some(lags) }
        };
        let fit = problem(&x, &y, &starts, covariance).solve().unwrap();
        assert_eq!(
            fit.covariance_kind,
            Covariance::NeweyWest { lags: Some(lags) },
            "{name}"
        );
        let theta = numbers(&case["theta"]);
        let cov = rows(&case["cov"]);
        let se = numbers(&case["std_errors"]);
        for i in 0..theta.len() {
            let scale = theta[i].abs().max(se[i]);
            assert!(
                (fit.theta[i] - theta[i]).abs() <= 1e-9 * scale,
                "{name} θ{i}: {} vs {}",
                fit.theta[i],
                theta[i]
            );
            assert!(
                (fit.std_errors[i] / se[i] - 1.0).abs() <= 1e-9,
                "{name} se{i}: {} vs {}",
                fit.std_errors[i],
                se[i]
            );
            for j in 0..theta.len() {
                let bound = 1e-9 * (cov[i][i] * cov[j][j]).sqrt();
                assert!(
                    (fit.covariance[(i, j)] - cov[i][j]).abs() <= bound,
                    "{name} cov({i}, {j}): {} vs {}",
                    fit.covariance[(i, j)],
                    cov[i][j]
                );
            }
        }
        // The classical covariance of the same problem, for reference.
        let classical = problem(&x, &y, &starts, Covariance::Classical)
            .solve()
            .unwrap();
        let want = rows(&case["classical_cov"]);
        for (i, row) in want.iter().enumerate() {
            assert!((classical.covariance[(i, i)] / row[i] - 1.0).abs() < 1e-9);
        }
    }
}

/// Deterministic pseudo-random numbers in [-0.5, 0.5) (xorshift64*).
fn noise(seed: u64) -> impl FnMut() -> f64 {
    let mut s = seed.max(1);
    move || {
        s ^= s >> 12;
        s ^= s << 25;
        s ^= s >> 27;
        (s.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    }
}

/// The textbook Newey–West covariance, by the normal equations and the
/// lag sums `Γ_l` pair by pair within each segment (O(rows · L · p²)).
fn textbook(x: &[Vec<f64>], y: &[f64], starts: &[usize], lags: usize) -> DMatrix<f64> {
    let (m, p) = (x.len(), x[0].len());
    let phi = DMatrix::from_fn(m, p, |i, j| x[i][j]);
    let lambda = DVector::from_column_slice(y);
    let xtx_inv = (phi.transpose() * &phi).try_inverse().unwrap();
    let theta = &xtx_inv * phi.transpose() * &lambda;
    let e = &lambda - &phi * theta;
    let segment = |k: usize| starts.iter().filter(|&&s| s <= k).count();
    let mut s = DMatrix::zeros(p, p);
    for l in 0..=lags {
        let w = 1.0 - l as f64 / (lags + 1) as f64;
        for t in l..m {
            if segment(t) != segment(t - l) {
                continue;
            }
            let a = phi.row(t).transpose() * e[t];
            let b = phi.row(t - l).transpose() * e[t - l];
            let g = &a * b.transpose();
            if l == 0 {
                s += g;
            } else {
                s += (&g + g.transpose()) * w;
            }
        }
    }
    &xtx_inv * s * &xtx_inv * (m as f64 / (m - p) as f64)
}

#[test]
fn newey_west_equals_its_lag_sums_with_many_segments() {
    // Segments of 1, 2, 3, … rows, some shorter than the bandwidth, some
    // longer: the moving-sum evaluation against the pairs one by one.
    let mut r = noise(5);
    let (mut x, mut y, mut starts) = (Vec::new(), Vec::new(), Vec::new());
    let mut len = 1;
    while x.len() < 300 {
        if !x.is_empty() {
            starts.push(x.len());
        }
        for _ in 0..len {
            let row = vec![1.0, r(), 3.0 * r() + 0.2];
            y.push(row[0] * 0.5 - row[1] + 2.0 * row[2] + r() * r());
            x.push(row);
        }
        len = len % 17 + 1;
    }
    for lags in [0, 1, 3, 8, 20, 75] {
        let fit = problem(&x, &y, &starts, Covariance::NeweyWest { lags: Some(lags) })
            .solve()
            .unwrap();
        let want = textbook(&x, &y, &starts, lags);
        for i in 0..3 {
            for j in 0..3 {
                let bound = 1e-10 * (want[(i, i)] * want[(j, j)]).sqrt();
                assert!(
                    (fit.covariance[(i, j)] - want[(i, j)]).abs() <= bound,
                    "L = {lags}, ({i}, {j}): {} vs {}",
                    fit.covariance[(i, j)],
                    want[(i, j)]
                );
            }
        }
    }
}

#[test]
fn without_lags_and_with_a_constant_regressor_it_is_the_classical_covariance() {
    // L = 0 is White's estimator; with the factor n/(n − p) and φ = 1 it is
    // Σ e² / (n (n − 1)) = σ̂² / n, the classical variance of a mean.
    let mut r = noise(9);
    let y: Vec<f64> = (0..57).map(|_| 3.0 + r()).collect();
    let ones = vec![1.0; y.len()];
    let solve = |covariance| {
        let mut ls = LeastSquares::new(1).with_covariance(covariance);
        ls.push_columns(&[&ones], &y).unwrap();
        ls.solve().unwrap()
    };
    let classical = solve(Covariance::Classical);
    let white = solve(Covariance::NeweyWest { lags: Some(0) });
    assert_eq!(classical.theta, white.theta);
    let rel = (white.covariance[(0, 0)] / classical.covariance[(0, 0)] - 1.0).abs();
    assert!(rel < 1e-13, "{rel}");
    assert_eq!(
        white.covariance_kind,
        Covariance::NeweyWest { lags: Some(0) }
    );
}

#[test]
fn segments_change_nothing_but_the_newey_west_covariance() {
    let mut r = noise(3);
    let x: Vec<Vec<f64>> = (0..120).map(|_| vec![1.0, r()]).collect();
    let y: Vec<f64> = x.iter().map(|row| row[1] + 0.1 * r()).collect();
    let classical = |starts: &[usize]| {
        problem(&x, &y, starts, Covariance::Classical)
            .solve()
            .unwrap()
    };
    assert_eq!(classical(&[]), classical(&[40, 80]));
    let nw = Covariance::NeweyWest { lags: Some(5) };
    let one = problem(&x, &y, &[], nw).solve().unwrap();
    let three = problem(&x, &y, &[40, 80], nw).solve().unwrap();
    assert_eq!(one.theta, three.theta);
    assert_ne!(one.covariance, three.covariance);
    // The order of whole segments does not matter.
    let order = [80..120, 0..40, 40..80];
    let (mut x2, mut y2) = (Vec::new(), Vec::new());
    for range in order {
        x2.extend_from_slice(&x[range.clone()]);
        y2.extend_from_slice(&y[range]);
    }
    let swapped = problem(&x2, &y2, &[40, 80], nw).solve().unwrap();
    for (a, b) in swapped.covariance.iter().zip(three.covariance.iter()) {
        assert!(
            (a - b).abs() <= 1e-12 * three.covariance.amax(),
            "{a} vs {b}"
        );
    }
}

#[test]
fn the_workspace_is_reused_and_clear_forgets_the_segments() {
    let nw = Covariance::NeweyWest { lags: Some(2) };
    let mut ls = LeastSquares::new(1).with_covariance(nw);
    let y = [1.0, 2.0, 0.5, 1.5, 3.0, 2.5, 1.0, 2.0];
    ls.push_columns(&[&[1.0; 4]], &y[..4]).unwrap();
    ls.start_segment();
    ls.push_columns(&[&[1.0; 4]], &y[4..]).unwrap();
    let split = ls.solve().unwrap();
    assert_eq!(split, ls.solve().unwrap(), "a second solve is the same");
    ls.clear();
    assert_eq!(ls.segments(), 0);
    ls.push_columns(&[&[1.0; 8]], &y).unwrap();
    let whole = ls.solve().unwrap();
    let mut fresh = LeastSquares::new(1).with_covariance(nw);
    fresh.push_columns(&[&[1.0; 8]], &y).unwrap();
    assert_eq!(whole, fresh.solve().unwrap());
    assert_ne!(whole.covariance, split.covariance);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    /// Whatever the data, the bandwidth and the segments, an `Ok` holds
    /// finite, non-negative standard errors and a finite covariance.
    #[test]
    fn ok_holds_finite_standard_errors(
        seed in 1u64..u64::MAX,
        m in 3usize..80,
        p in 1usize..4,
        lags in proptest::option::of(0usize..2000),
        exponent in -300i32..300,
        marks in proptest::collection::vec(0usize..80, 0..6),
    ) {
        let mut r = noise(seed);
        let scale = 10f64.powi(exponent);
        let mut ls = LeastSquares::new(p).with_covariance(Covariance::NeweyWest { lags });
        for k in 0..m {
            if marks.contains(&k) {
                ls.start_segment();
            }
            let row: Vec<f64> = (0..p).map(|j| if j == 0 { scale } else { r() * scale.sqrt() }).collect();
            ls.push_row(&row, r() / scale).unwrap();
        }
        if let Ok(fit) = ls.solve() {
            prop_assert!(fit.std_errors.iter().all(|s| s.is_finite() && *s >= 0.0), "{:?}", fit.std_errors);
            prop_assert!(fit.covariance.iter().all(|c| c.is_finite()));
            prop_assert!(fit.theta.iter().all(|t| t.is_finite()));
            let Covariance::NeweyWest { lags: Some(used) } = fit.covariance_kind else {
                panic!("{:?}", fit.covariance_kind);
            };
            prop_assert!(used <= m / 4);
        }
    }
}
