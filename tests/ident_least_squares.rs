//! `LeastSquares` and `Rls` against known solutions.

use ctrlab::Error;
use ctrlab::ident::{LeastSquares, Rls};
use nalgebra::{DMatrix, DVector, SVector, vector};
use proptest::prelude::*;

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

#[test]
fn exact_data_gives_the_exact_solution() {
    let theta = [1.5, -2.0, 0.25];
    let mut ls = LeastSquares::new(3);
    let mut r = noise(7);
    for _ in 0..50 {
        let phi = [r(), r(), r()];
        let y: f64 = phi.iter().zip(theta).map(|(p, t)| p * t).sum();
        ls.push_row(&phi, y).unwrap();
    }
    let fit = ls.solve().unwrap();
    for (got, want) in fit.theta.iter().zip(theta) {
        assert!((got - want).abs() < 1e-13, "{got} vs {want}");
    }
    assert!(fit.residual_rms < 1e-14);
    assert!((fit.r_squared - 1.0).abs() < 1e-12 && fit.fit_percent > 99.9999);
    assert!(fit.condition >= 1.0 && fit.condition < 10.0);
    assert_eq!(fit.rows, 50);
}

#[test]
fn statistics_match_the_textbook_formulas() {
    // Straight line through noisy points; compare with closed-form
    // simple-regression formulas computed independently here.
    let xs: Vec<f64> = (0..20).map(|k| k as f64 * 0.5).collect();
    let mut r = noise(3);
    let ys: Vec<f64> = xs.iter().map(|x| 1.0 + 2.0 * x + r()).collect();
    let ones = vec![1.0; xs.len()];
    let mut ls = LeastSquares::new(2);
    ls.push_columns(&[&ones, &xs], &ys).unwrap();
    let fit = ls.solve().unwrap();

    let n = xs.len() as f64;
    let (mx, my) = (xs.iter().sum::<f64>() / n, ys.iter().sum::<f64>() / n);
    let sxx: f64 = xs.iter().map(|x| (x - mx).powi(2)).sum();
    let sxy: f64 = xs.iter().zip(&ys).map(|(x, y)| (x - mx) * (y - my)).sum();
    let slope = sxy / sxx;
    let icpt = my - slope * mx;
    let ssr: f64 = xs
        .iter()
        .zip(&ys)
        .map(|(x, y)| (y - icpt - slope * x).powi(2))
        .sum();
    let sst: f64 = ys.iter().map(|y| (y - my).powi(2)).sum();
    let s2 = ssr / (n - 2.0);
    assert!((fit.theta[1] - slope).abs() < 1e-12 && (fit.theta[0] - icpt).abs() < 1e-12);
    assert!((fit.std_errors[1] - (s2 / sxx).sqrt()).abs() < 1e-12);
    assert!((fit.std_errors[0] - (s2 * (1.0 / n + mx * mx / sxx)).sqrt()).abs() < 1e-12);
    assert!((fit.covariance[(0, 1)] - (-mx * s2 / sxx)).abs() < 1e-12);
    assert!((fit.residual_rms - (ssr / n).sqrt()).abs() < 1e-12);
    assert!((fit.r_squared - (1.0 - ssr / sst)).abs() < 1e-12);
    assert!((fit.fit_percent - 100.0 * (1.0 - (ssr / sst).sqrt())).abs() < 1e-9);
}

#[test]
fn ill_conditioned_qr_keeps_digits_the_normal_equations_lose() {
    // Two nearly parallel columns: cond(Φ) ≈ 2·10⁷, so the normal equations
    // (cond² ≈ 4·10¹⁴) lose almost every digit while QR keeps ~8.
    let m = 200;
    let mut r = noise(11);
    let c0: Vec<f64> = (0..m).map(|_| 1.0 + r()).collect();
    let c1: Vec<f64> = c0.iter().map(|v| v + 1e-7 * r()).collect();
    let theta = [1.0, 1.0];
    let y: Vec<f64> = c0
        .iter()
        .zip(&c1)
        .map(|(a, b)| a * theta[0] + b * theta[1])
        .collect();

    let mut ls = LeastSquares::new(2);
    ls.push_columns(&[&c0, &c1], &y).unwrap();
    let fit = ls.solve().unwrap();
    let qr_err = (0..2)
        .map(|i| (fit.theta[i] - theta[i]).abs())
        .fold(0.0, f64::max);

    let phi = DMatrix::from_fn(m, 2, |i, j| if j == 0 { c0[i] } else { c1[i] });
    let lam = DVector::from_vec(y);
    let ne = (phi.transpose() * &phi)
        .lu()
        .solve(&(phi.transpose() * lam))
        .expect("normal equations solve");
    let ne_err = (0..2).map(|i| (ne[i] - theta[i]).abs()).fold(0.0, f64::max);

    println!(
        "condition {:e}: QR error {qr_err:e}, normal equations error {ne_err:e}",
        fit.condition
    );
    assert!(fit.condition > 1e6);
    assert!(qr_err < 1e-6, "QR error {qr_err:e}");
    assert!(
        ne_err > 1e3 * qr_err,
        "normal equations should lose digits: {ne_err:e} vs {qr_err:e}"
    );
}

#[test]
fn rank_deficiency_is_an_error() {
    // Collinear columns.
    let mut ls = LeastSquares::new(3);
    let mut r = noise(5);
    for _ in 0..30 {
        let (a, b) = (r(), r());
        ls.push_row(&[a, b, 2.0 * a - b], r()).unwrap();
    }
    match ls.solve() {
        Err(Error::RankDeficient { rank, condition }) => {
            assert_eq!(rank, 2);
            assert!(condition > 1e10);
        }
        other => panic!("expected RankDeficient, got {other:?}"),
    }
    // A zero column (no excitation).
    let mut ls = LeastSquares::new(2);
    ls.push_columns(&[&[1.0, 2.0, 3.0], &[0.0; 3]], &[1.0, 2.0, 3.0])
        .unwrap();
    assert_eq!(
        ls.solve(),
        Err(Error::RankDeficient {
            rank: 1,
            condition: f64::INFINITY
        })
    );
}

#[test]
fn bad_shapes_and_values_are_errors() {
    let mut ls = LeastSquares::new(2);
    assert!(matches!(
        ls.solve(),
        Err(Error::TooFewSamples {
            needed: 3,
            got: 0,
            ..
        })
    ));
    ls.push_row(&[1.0, 2.0], 1.0).unwrap();
    ls.push_row(&[1.0, 3.0], 1.0).unwrap();
    assert!(matches!(
        ls.solve(),
        Err(Error::TooFewSamples { got: 2, .. })
    ));
    assert!(ls.push_row(&[1.0, 2.0, 3.0], 1.0).is_err());
    assert!(ls.push_columns(&[&[1.0]], &[1.0]).is_err());
    assert!(ls.push_columns(&[&[1.0], &[1.0, 2.0]], &[1.0]).is_err());
    assert_eq!(ls.rows(), 2);
    ls.push_row(&[1.0, f64::NAN], 1.0).unwrap();
    assert!(matches!(
        ls.solve(),
        Err(Error::NonFinite {
            matrix: "regressor",
            row: 2,
            col: 1,
            ..
        })
    ));
    let mut zero = LeastSquares::new(0);
    assert!(matches!(zero.solve(), Err(Error::TooFewSamples { .. })));
}

#[test]
fn rls_with_forgetting_tracks_a_parameter_change() {
    let mut rls = Rls::<2>::new(0.98, 1e4).unwrap();
    let mut r = noise(9);
    for k in 0..2000 {
        let theta = if k < 1000 { [1.0, 2.0] } else { [3.0, -1.0] };
        let phi = vector![r(), r()];
        rls.update(&phi, phi[0] * theta[0] + phi[1] * theta[1])
            .unwrap();
    }
    assert!((rls.theta() - vector![3.0, -1.0]).norm() < 1e-6);
    assert_eq!(rls.updates(), 2000);
}

proptest! {
    #[test]
    fn rls_without_forgetting_agrees_with_batch(seed in 1u64..u64::MAX, n in 20usize..300) {
        let mut r = noise(seed);
        let mut ls = LeastSquares::new(3);
        // P₀ = δ I: RLS minimises ‖Φθ − λ‖² + ‖θ‖²/δ, within ~‖θ‖/(δ σ²_min) of batch.
        let mut rls = Rls::<3>::new(1.0, 1e10).unwrap();
        for _ in 0..n {
            let phi = [r(), r(), r()];
            let y = 0.3 * phi[0] - 1.2 * phi[1] + 2.0 * phi[2] + 0.1 * r();
            ls.push_row(&phi, y).unwrap();
            rls.update(&SVector::from(phi), y).unwrap();
        }
        let fit = ls.solve().unwrap();
        for i in 0..3 {
            prop_assert!((rls.theta()[i] - fit.theta[i]).abs() < 1e-6, "{} vs {}", rls.theta()[i], fit.theta[i]);
        }
    }

    #[test]
    fn exact_problems_are_solved_exactly(
        theta in prop::array::uniform3(-1e3f64..1e3), scales in prop::array::uniform3(-6i32..6), seed in 1u64..u64::MAX,
    ) {
        // Columns scaled over 12 decades: the equilibration makes it irrelevant.
        let mut r = noise(seed);
        let mut ls = LeastSquares::with_capacity(3, 40);
        for _ in 0..40 {
            let phi: [f64; 3] = std::array::from_fn(|j| r() * 10f64.powi(scales[j]));
            let y = (0..3).map(|j| phi[j] * theta[j]).sum();
            ls.push_row(&phi, y).unwrap();
        }
        let fit = ls.solve().unwrap();
        // Each column's contribution φ_j θ_j is recovered to 1e-10 of the
        // largest contribution (θ_j of a tiny column is known only that well).
        let size = |j: usize| 10f64.powi(scales[j]);
        let signal = (0..3).map(|j| theta[j].abs() * size(j)).fold(1e-300, f64::max);
        for (j, (got, want)) in fit.theta.iter().zip(theta).enumerate() {
            let err = (got - want).abs() * size(j) / signal;
            prop_assert!(err < 1e-10, "theta[{}] {} vs {} (err {:e})", j, got, want, err);
        }
    }
}
