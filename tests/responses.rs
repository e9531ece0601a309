//! `step_response`, `impulse_response` and `initial_response` against
//! python-control 0.10.2 (tests/data/response_fixtures.json, made by
//! tests/data/gen_response_fixtures.py) and against closed forms, in both
//! time domains; bad input is an error.
//!
//! Tolerance against python-control: both sides compute these responses
//! exactly up to rounding (matrix exponentials and a recursion), so each
//! series must agree to 1e-9 of its largest value (python-control's own
//! tests ask for four decimals, `assert_array_almost_equal(decimal=4)`,
//! on the hand-written arrays that `timeresp_test.py` records; the
//! `siso_ss1` case checks those too).

mod common;

use common::matrix;
use ctrlab::sim::{impulse_response, initial_response, step_response};
use ctrlab::{Discretization, Domain, Error, Response, StateSpace};
use nalgebra::{Const, SVector, matrix, vector};
use serde_json::Value;

fn series(v: &Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

/// `got` against `want` to 1e-9 of `want`'s largest magnitude (at least 1).
fn assert_series(what: &str, got: &[f64], want: &[f64]) {
    assert_eq!(got.len(), want.len(), "{what}: length");
    let scale = want.iter().fold(1.0f64, |m, v| m.max(v.abs()));
    for (k, (g, w)) in got.iter().zip(want).enumerate() {
        assert!(
            (g - w).abs() <= 1e-9 * scale,
            "{what}[{k}]: {g} vs python-control {w}"
        );
    }
}

fn check_outputs<const N: usize, const P: usize>(
    what: &str,
    r: &Response<Const<N>, Const<P>>,
    want: &Value,
) {
    for i in 0..P {
        assert_series(
            &format!("{what}, output {i}"),
            &r.output(i).unwrap(),
            &series(&want[i]),
        );
    }
}

fn check_case<const N: usize, const M: usize, const P: usize, D: Domain>(
    sys: &StateSpace<N, M, P, D>,
    case: &Value,
) {
    let name = case["name"].as_str().unwrap();
    let (t_end, dt) = (
        case["t_end"].as_f64().unwrap(),
        case["grid_dt"].as_f64().unwrap(),
    );
    let x0 = SVector::<f64, N>::from_iterator(series(&case["x0"]));
    for j in 0..M {
        let one = sys.select_input(j).unwrap();
        let r = step_response(&one, t_end, dt).unwrap();
        let t = series(&case["step"][j][0]);
        assert_eq!(r.len(), t.len(), "{name}: samples");
        check_outputs(&format!("{name} step, input {j}"), &r, &case["step"][j]);
        let r = impulse_response(&one, t_end, dt).unwrap();
        check_outputs(
            &format!("{name} impulse, input {j}"),
            &r,
            &case["impulse"][j],
        );
    }
    let r = initial_response(sys, t_end, dt, x0).unwrap();
    check_outputs(&format!("{name} initial"), &r, &case["initial"]);
}

fn run_case<const N: usize, const M: usize, const P: usize>(name: &str) {
    let all = common::fixture("response_fixtures.json");
    let case = all["cases"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["name"] == name)
        .unwrap_or_else(|| panic!("no case {name}"));
    let (a, b, c, d) = (
        matrix::<N, N>(&case["a"]),
        matrix::<N, M>(&case["b"]),
        matrix::<P, N>(&case["c"]),
        matrix::<P, M>(&case["d"]),
    );
    match case["dt"].as_f64() {
        None => check_case(&StateSpace::continuous(a, b, c, d).unwrap(), case),
        Some(dt) => check_case(&StateSpace::discrete(a, b, c, d, dt).unwrap(), case),
    }
}

#[test]
fn python_control_test_system_with_and_without_feedthrough() {
    run_case::<2, 1, 1>("siso_ss1");
    run_case::<2, 1, 1>("siso_ss2");
}

#[test]
fn python_control_second_order_continuous_and_sampled() {
    run_case::<2, 1, 1>("second_order");
    run_case::<2, 1, 1>("sampled_second_order");
}

#[test]
fn python_control_mimo_continuous_and_discrete() {
    run_case::<3, 2, 2>("mimo_continuous");
    run_case::<2, 2, 2>("matlab_mimo_discrete");
}

#[test]
fn python_control_hand_written_arrays() {
    // control/tests/timeresp_test.py (python-control 0.10.2), fixtures
    // siso_ss1 / siso_ss2 on linspace(0, 1, 10), checked there to four
    // decimals (assert_array_almost_equal, decimal=4: |Δ| < 1.5e-4).
    let (a, b, c) = (
        matrix![1.0, -2.0; 3.0, -4.0],
        matrix![5.0; 7.0],
        matrix![6.0, 8.0],
    );
    let ss1 = StateSpace::continuous(a, b, c, matrix![9.0]).unwrap();
    let ss2 = StateSpace::continuous(a, b, c, matrix![0.0]).unwrap();
    let ystep = [
        9., 17.6457, 24.7072, 30.4855, 35.2234, 39.1165, 42.3227, 44.9694, 47.1599, 48.9776,
    ];
    let yinitial = [
        11., 8.1494, 5.9361, 4.2258, 2.9118, 1.9092, 1.1508, 0.5833, 0.1645, -0.1391,
    ];
    let yimpulse = [
        86., 70.1808, 57.3753, 46.9975, 38.5766, 31.7344, 26.1668, 21.6292, 17.9245, 14.8945,
    ];
    let close = |what: &str, got: Vec<f64>, want: &[f64]| {
        for (k, (g, w)) in got.iter().zip(want).enumerate() {
            assert!((g - w).abs() < 1.5e-4, "{what}[{k}]: {g} vs {w}");
        }
    };
    let dt = 1.0 / 9.0;
    close(
        "ystep",
        step_response(&ss1, 1.0, dt).unwrap().output(0).unwrap(),
        &ystep,
    );
    close(
        "yinitial",
        initial_response(&ss1, 1.0, dt, vector![0.5, 1.0])
            .unwrap()
            .output(0)
            .unwrap(),
        &yinitial,
    );
    close(
        "yimpulse",
        impulse_response(&ss2, 1.0, dt).unwrap().output(0).unwrap(),
        &yimpulse,
    );
}

#[test]
fn first_order_responses_are_analytic() {
    // τ ẏ = −y + u: step 1 − e^{−t/τ}, impulse e^{−t/τ}/τ, free y0 e^{−t/τ}.
    let tau = 0.25;
    let sys = common::lag(tau, 1.0);
    let (t_end, dt) = (2.0, 0.01);
    let step = step_response(&sys, t_end, dt).unwrap();
    let impulse = impulse_response(&sys, t_end, dt).unwrap();
    let free = initial_response(&sys, t_end, dt, vector![3.0]).unwrap();
    for k in 0..step.len() {
        let t = step.t[k];
        let e = (-t / tau).exp();
        assert!((step.y[k][0] - (1.0 - e)).abs() < 1e-13, "step at {t}");
        assert!((impulse.y[k][0] - e / tau).abs() < 1e-12, "impulse at {t}");
        assert!((free.y[k][0] - 3.0 * e).abs() < 1e-13, "initial at {t}");
    }

    // Its exact discretisation: y[k] = C A^(k−1) B / dt for the impulse,
    // and the continuous step and free responses at the samples.
    let h = 0.05;
    let d = sys.discretize(h, Discretization::Zoh).unwrap();
    let (ad, bd) = (d.a()[(0, 0)], d.b()[(0, 0)]);
    let step = step_response(&d, t_end, h).unwrap();
    let impulse = impulse_response(&d, t_end, h).unwrap();
    let free = initial_response(&d, t_end, h, vector![3.0]).unwrap();
    assert_eq!(impulse.y[0][0], 0.0);
    for k in 0..step.len() {
        let e = (-step.t[k] / tau).exp();
        assert!((step.y[k][0] - (1.0 - e)).abs() < 1e-13);
        assert!((free.y[k][0] - 3.0 * e).abs() < 1e-13);
        if k > 0 {
            let want = ad.powi(k as i32 - 1) * bd / h;
            assert!((impulse.y[k][0] - want).abs() < 1e-12 * want.abs().max(1.0));
        }
    }
}

#[test]
fn second_order_impulse_and_free_response_are_analytic() {
    // ωn² / (s² + 2ζωn s + ωn²): impulse (ωn/√(1−ζ²)) e^{−ζωn t} sin ωd t;
    // from x = (1, 0) with no input, e^{−ζωn t}(cos ωd t + ζ/√(1−ζ²) sin ωd t).
    let (zeta, wn) = (0.2, 5.0);
    let sys = common::second_order(zeta, wn);
    let root = (1.0 - zeta * zeta).sqrt();
    let wd = wn * root;
    let impulse = impulse_response(&sys, 4.0, 0.001).unwrap();
    let free = initial_response(&sys, 4.0, 0.001, vector![1.0, 0.0]).unwrap();
    for k in 0..impulse.len() {
        let t = impulse.t[k];
        let decay = (-zeta * wn * t).exp();
        let g = wn / root * decay * (wd * t).sin();
        let x = decay * ((wd * t).cos() + zeta / root * (wd * t).sin());
        assert!((impulse.y[k][0] - g).abs() < 1e-11, "impulse at {t}");
        assert!((free.y[k][0] - x).abs() < 1e-12, "initial at {t}");
    }
}

#[test]
fn bad_input_is_an_error() {
    let sys =
        StateSpace::continuous(matrix![-1.0], matrix![1.0], matrix![1.0], matrix![0.0]).unwrap();
    let d =
        StateSpace::discrete(matrix![0.5], matrix![1.0], matrix![1.0], matrix![0.0], 0.1).unwrap();
    // A discrete model's grid is its period.
    for dt in [0.05, 0.2, f64::NAN, 0.1 * (1.0 + 1e-6)] {
        assert!(matches!(
            impulse_response(&d, 1.0, dt),
            Err(Error::InvalidParameter { name: "dt", .. })
        ));
    }
    assert_eq!(impulse_response(&d, 1.0, 0.1).unwrap().len(), 11);
    for (t_end, dt) in [(1.0, 0.0), (1.0, -0.1), (f64::INFINITY, 0.1), (0.01, 0.1)] {
        assert!(impulse_response(&sys, t_end, dt).is_err());
        assert!(initial_response(&sys, t_end, dt, vector![1.0]).is_err());
    }
    assert!(matches!(
        initial_response(&sys, 1.0, 0.1, vector![f64::NAN]),
        Err(Error::NonFinite { matrix: "x0", .. })
    ));
    assert!(matches!(
        initial_response(&d, 1.0, 0.1, vector![f64::INFINITY]),
        Err(Error::NonFinite { matrix: "x0", .. })
    ));
    // A diverging discrete response is an error, not infinities.
    let wild =
        StateSpace::discrete(matrix![1e10], matrix![1.0], matrix![1.0], matrix![0.0], 0.1).unwrap();
    assert!(matches!(
        initial_response(&wild, 10.0, 0.1, vector![1e300]),
        Err(Error::Overflow { .. })
    ));
    // A period so short that the unit-area pulse 1/dt overflows.
    let tiny = StateSpace::discrete(
        matrix![0.5],
        matrix![1.0],
        matrix![1.0],
        matrix![0.0],
        1e-310,
    )
    .unwrap();
    assert!(matches!(
        impulse_response(&tiny, 2e-310, 1e-310),
        Err(Error::Overflow { .. })
    ));
    assert!(matches!(
        sys.select_input(1),
        Err(Error::OutOfRange { what: "input", .. })
    ));
}
