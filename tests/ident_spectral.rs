//! `etfe` and `spa` against frequency responses computed independently here
//! (`C (zI − A)⁻¹ B + D` at `z = e^{jω dt}` by a complex LU), on data
//! simulated sample by sample.

use ctrlab::Error;
use ctrlab::ident::{etfe, spa};
use ctrlab::signal::{Multisine, Phases, Prbs, Rng, Signal};
use nalgebra::{Complex, DMatrix};

/// A lightly damped discrete two-state system (poles 0.97 e^{±0.2j}) with a
/// one-state lag: resonant like the rig's modes.
fn system() -> (DMatrix<f64>, DMatrix<f64>, DMatrix<f64>, f64) {
    let (r, th) = (0.97f64, 0.2f64);
    let a = DMatrix::from_row_slice(
        3,
        3,
        &[
            r * th.cos(),
            -r * th.sin(),
            0.0, //
            r * th.sin(),
            r * th.cos(),
            0.0, //
            0.0,
            0.3,
            0.6,
        ],
    );
    let b = DMatrix::from_row_slice(3, 1, &[1.0, 0.0, 0.0]);
    let c = DMatrix::from_row_slice(1, 3, &[0.2, 0.5, 1.0]);
    (a, b, c, 0.25)
}

/// `C (e^{jω dt} I − A)⁻¹ B + D`.
fn truth(w: f64, dt: f64) -> Complex<f64> {
    let (a, b, c, d) = system();
    let z = Complex::from_polar(1.0, w * dt);
    let m = DMatrix::from_fn(3, 3, |i, j| {
        Complex::new(if i == j { 1.0 } else { 0.0 }, 0.0) * z - Complex::new(a[(i, j)], 0.0)
    });
    let x = m.lu().solve(&b.map(|v| Complex::new(v, 0.0))).unwrap();
    (c.map(|v| Complex::new(v, 0.0)) * x)[(0, 0)] + d
}

fn simulate(u: &[f64]) -> Vec<f64> {
    let (a, b, c, d) = system();
    let mut x = DMatrix::zeros(3, 1);
    u.iter()
        .map(|&u| {
            let y = (&c * &x)[(0, 0)] + d * u;
            x = &a * &x + &b * u;
            y
        })
        .collect()
}

#[test]
fn etfe_of_a_periodic_multisine_in_steady_state_is_exact() {
    let dt = 0.002;
    let n = 1000; // one period, 2 s
    let ms = Multisine::new(1.0, n as f64 * dt, (1..200).step_by(3), Phases::Schroeder).unwrap();
    let u: Vec<f64> = (0..4 * n).map(|k| ms.value(k as f64 * dt)).collect();
    let y = simulate(&u);
    // The transient (0.97^3000 ≈ 1e-40) is gone after three periods.
    let g = etfe(&u[3 * n..], &y[3 * n..], dt).unwrap();
    assert_eq!(g.omega.len(), ms.harmonics().len());
    for (w, (k, est)) in g.omega.iter().zip(ms.harmonics().iter().zip(&g.response)) {
        assert!((w - std::f64::consts::TAU * f64::from(*k) / (n as f64 * dt)).abs() < 1e-9);
        let t = truth(*w, dt);
        assert!((est - t).norm() < 1e-10 * t.norm(), "ω = {w}: {est} vs {t}");
    }
}

#[test]
fn etfe_of_a_full_period_prbs_is_exact_where_it_has_power() {
    let dt = 0.002;
    let prbs = Prbs::new(1.0, dt, 9, 3).unwrap();
    let n = prbs.len(); // 511 samples per period
    let u: Vec<f64> = (0..3 * n).map(|k| prbs.value(k as f64 * dt)).collect();
    let y = simulate(&u);
    let g = etfe(&u[2 * n..], &y[2 * n..], dt).unwrap();
    // A maximum-length sequence has equal power at every non-zero bin.
    assert_eq!(g.omega.len(), n / 2);
    let worst = g
        .omega
        .iter()
        .zip(&g.response)
        .map(|(w, est)| (est - truth(*w, dt)).norm() / truth(*w, dt).norm())
        .fold(0.0, f64::max);
    assert!(worst < 1e-10, "worst relative error {worst:e}");
}

#[test]
fn spa_follows_the_resonance_with_a_wide_enough_lag_window() {
    let dt = 0.002;
    let mut rng = Rng::new(11);
    let u: Vec<f64> = (0..200_000).map(|_| rng.gaussian()).collect();
    let y = simulate(&u);
    // The resonance at 0.2 rad/sample = 100 rad/s decays as 0.97^k: a lag
    // window of 400 samples holds its impulse response (0.97^400 ≈ 5e-6).
    let omega: Vec<f64> = (1..=60).map(|k| k as f64 * 5.0).collect();
    let g = spa(&u, &y, dt, Some(400), &omega).unwrap();
    let mut worst: f64 = 0.0;
    for (w, est) in omega.iter().zip(&g.response) {
        let t = truth(*w, dt);
        worst = worst.max((est - t).norm() / t.norm());
    }
    // Statistical error of the Blackman–Tukey estimate, relative:
    // ≈ √(0.75 M / N) ≈ 0.04 for M = 400, N = 2e5 (Ljung, Table 6.1); the
    // Hann window's bias at the peak is below that for this decay.
    assert!(worst < 0.08, "worst relative error {worst}");
    // MATLAB's default window (30 lags) is far too short for this
    // resonance: the smoothed peak is well below the true one.
    let peak = spa(&u, &y, dt, None, &[100.0]).unwrap().response[0].norm();
    assert!(peak < 0.7 * truth(100.0, dt).norm());
}

#[test]
fn bad_data_is_refused_with_what_is_wrong() {
    let u = vec![1.0, -1.0, 1.0, -1.0, 1.0, -1.0];
    let y = u.clone();
    assert!(matches!(
        etfe(&u, &y[..5], 0.01),
        Err(Error::LengthMismatch { .. })
    ));
    assert!(matches!(
        etfe(&u[..3], &y[..3], 0.01),
        Err(Error::TooFewSamples { .. })
    ));
    assert!(matches!(
        etfe(&u, &y, 0.0),
        Err(Error::InvalidParameter { name: "dt", .. })
    ));
    let mut bad = y.clone();
    bad[4] = f64::NAN;
    assert!(matches!(
        etfe(&u, &bad, 0.01),
        Err(Error::InvalidData {
            what: "y",
            index: 4,
            ..
        })
    ));
    let zeros = vec![0.0; 6];
    assert!(matches!(
        etfe(&zeros, &y, 0.01),
        Err(Error::InvalidData { what: "u", .. })
    ));
    assert!(matches!(
        spa(&zeros, &y, 0.01, Some(2), &[1.0]),
        Err(Error::InvalidData { what: "u", .. })
    ));
    assert!(matches!(
        spa(&u, &y, 0.01, Some(6), &[1.0]),
        Err(Error::InvalidParameter { name: "lag", .. })
    ));
    assert!(matches!(
        spa(&u, &y, 0.01, Some(0), &[1.0]),
        Err(Error::InvalidParameter { name: "lag", .. })
    ));
    assert!(matches!(
        spa(&u, &y, 0.01, Some(2), &[f64::NAN]),
        Err(Error::InvalidParameter { name: "omega", .. })
    ));
    // Huge but finite samples: an error or finite numbers, never NaN in Ok.
    let huge: Vec<f64> = u.iter().map(|v| v * 1e308).collect();
    if let Ok(g) = etfe(&huge, &huge, 0.01) {
        assert!(
            g.response
                .iter()
                .all(|g| g.re.is_finite() && g.im.is_finite())
        );
    }
    if let Ok(g) = spa(&huge, &huge, 0.01, Some(2), &[1.0]) {
        assert!(
            g.response
                .iter()
                .all(|g| g.re.is_finite() && g.im.is_finite())
        );
    }
}
