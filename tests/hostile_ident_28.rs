//! Issue 28's bad input that got a wrong answer from identification: a
//! position of 1e200 m is a poor fit, not a NaN one; a mass that is not a
//! mass is named; spectra of ±1e308 are scaled, not declared powerless.

use ctrlab::Error;
use ctrlab::ident::{etfe, spa};

#[cfg(feature = "lab")]
mod lab {
    use ctrlab::lab::SimulatedRig;
    use ctrlab::lab::ident::{
        AverageError, Options, SimulationModel, SpringModel, average, identify_with, refine_with,
        validate_with,
    };
    use ctrlab::{Error, Recording};

    fn recording() -> Recording {
        Recording::read_csv(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/tests/data/ident_square_wave.csv"
        ))
        .unwrap()
    }

    #[test]
    fn a_wild_position_gives_a_finite_fit() {
        let mut rec = recording();
        rec.channel_mut("x2").unwrap()[100] = 1e200;
        let truth = SimulatedRig::default().truth;
        let model = SimulationModel::default();
        // Was fit NaN (1e400 / 1e400).
        let v = validate_with(&rec, &truth, [0.0; 2], &model).unwrap();
        for cart in 0..2 {
            assert!(v.fit_percent[cart].is_finite(), "{v:?}");
            assert!(v.rms_error[cart].is_finite(), "{v:?}");
        }
        // One sample of 1e200 in n: the fit is 1 − √(n / (n − 1))·… ≈ 0 %.
        assert!(v.fit_percent[1].abs() < 1.0, "{v:?}");
        assert!((v.rms_error[1] / (1e200 / (rec.len() as f64).sqrt()) - 1.0).abs() < 1e-6);
        assert!(v.whiteness.max_correlation.is_finite());
        assert!(v.independence.max_correlation.is_finite());
        let options = Options {
            springs: SpringModel::Separate,
            ..Options::default()
        };
        let start = identify_with(&recording(), 1.3, 0.7, &options).unwrap();
        if let Ok(r) = refine_with(&rec, &start, &model) {
            for v in [r.start, r.refined] {
                assert!(v.fit_percent.iter().all(|f| f.is_finite()), "{v:?}");
                assert!(v.rms_error.iter().all(|f| f.is_finite()), "{v:?}");
            }
        }
    }

    #[test]
    fn averaging_names_a_mass_that_is_not_a_mass() {
        let options = Options {
            springs: SpringModel::Separate,
            ..Options::default()
        };
        let est = identify_with(&recording(), 1.3, 0.7, &options).unwrap();
        for bad in [f64::INFINITY, f64::NAN] {
            let mut runs = [est.clone(), est.clone()];
            runs[0].m1 = bad;
            runs[1].m1 = bad;
            // Was Ok(m1: inf), or (NaN) "identified with different masses".
            let err = average(&runs).unwrap_err();
            let AverageError::Data(Error::InvalidParameter { name, .. }) = &err else {
                panic!("{bad}: {err:?}");
            };
            assert_eq!(*name, "m1");
            let message = err.to_string();
            assert!(
                message.contains(&format!(
                    "`m1` = {}",
                    if bad.is_nan() { "NaN" } else { "inf" }
                )),
                "{message}"
            );
        }
    }
}

fn wave(n: usize, amplitude: f64) -> (Vec<f64>, Vec<f64>) {
    // A pseudo-random binary sequence (power at every frequency)…
    let mut state = 0x2545_f491_u32;
    let u: Vec<f64> = (0..n)
        .map(|_| {
            state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            if state >> 31 == 1 {
                amplitude
            } else {
                -amplitude
            }
        })
        .collect();
    // …and y[k] = u[k − 1] / 2, a delayed half.
    let y: Vec<f64> = (0..n)
        .map(|k| if k == 0 { 0.0 } else { u[k - 1] / 2.0 })
        .collect();
    (u, y)
}

#[test]
fn etfe_of_huge_signals_is_the_etfe_of_unit_ones() {
    let (u1, y1) = wave(64, 1.0);
    let (u, y) = wave(64, 1e308);
    // Was "the input has no power at any non-zero frequency".
    let big = etfe(&u, &y, 0.01).unwrap();
    let unit = etfe(&u1, &y1, 0.01).unwrap();
    assert_eq!(big.omega, unit.omega);
    for (g, h) in big.response.iter().zip(&unit.response) {
        assert!((g - h).norm() <= 1e-15 * h.norm().max(1.0), "{g} vs {h}");
    }
    // And a tiny output against a huge input: G ≈ 1e-300.
    let tiny: Vec<f64> = y1.iter().map(|v| v * 1e-150).collect();
    let (u2, _) = wave(64, 1e150);
    let g = etfe(&u2, &tiny, 0.01).unwrap();
    for (g, h) in g.response.iter().zip(&unit.response) {
        assert!((g * 1e300 - h).norm() <= 1e-14 * h.norm().max(1.0), "{g}");
    }
}

#[test]
fn spa_of_huge_signals_and_frequencies() {
    let (u1, y1) = wave(256, 1.0);
    let (u, y) = wave(256, 1e200);
    let omega = [1.0, 10.0, 50.0];
    let unit = spa(&u1, &y1, 0.01, None, &omega).unwrap();
    // Covariances of 1e200 overflowed.
    let big = spa(&u, &y, 0.01, None, &omega).unwrap();
    for (g, h) in big.response.iter().zip(&unit.response) {
        assert!((g - h).norm() <= 1e-14 * h.norm(), "{g} vs {h}");
    }
    // ω·dt·M = 1e308 · 10 · 25 overflowing was "smoothed spectrum is not
    // positive".
    let err = spa(&u1, &y1, 10.0, None, &[1e308]).unwrap_err();
    assert!(
        matches!(err, Error::InvalidParameter { name: "omega", value, .. } if value == 1e308),
        "{err:?}"
    );
}
