//! `place`, `lqe`, `dlqe` and `lqi`/`dlqi` against python-control
//! (tests/data/design_fixtures.json, made by tests/data/gen_design_fixtures.py).
//!
//! Tolerances are python-control's own: its `place` and `lqr` tests use
//! `assert_array_almost_equal` (six decimals), its `lqe`/`dlqe` tests
//! `assert_almost_equal` (seven decimals), i.e. `|got − want| < 1.5 · 10⁻ᵈ`.
//! For the lab's matrices, whose entries run to 10⁴, the same bound is
//! taken relative to the largest entry (poles: to `max(1, |pole|)`).

mod common;

use common::matrix;
use ctrlab::design::{augment_integral, dlqe, dlqi, lqe, lqi, place};
use ctrlab::{Discrete, Error, StateSpace};
use nalgebra::{Complex, SMatrix};
use serde_json::Value;

fn fixtures() -> Value {
    common::fixture("design_fixtures.json")
}

fn case<'a>(all: &'a Value, kind: &str, name: &str) -> &'a Value {
    all[kind]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["name"] == name)
        .unwrap_or_else(|| panic!("no {kind} case {name}"))
}

fn complex_list(v: &Value) -> Vec<Complex<f64>> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|p| Complex::new(p[0].as_f64().unwrap(), p[1].as_f64().unwrap()))
        .collect()
}

/// numpy's `assert_almost_equal(got, want, decimal)`, relative to the
/// matrix's largest entry when that exceeds 1 (the lab's gains mix entries
/// of 10⁴ and 10⁻²; python-control's own solution of those is accurate to
/// about 1e-10 of the largest, checked against a 60-digit Newton solution).
fn assert_almost<const R: usize, const C: usize>(
    what: &str,
    got: &SMatrix<f64, R, C>,
    want: &SMatrix<f64, R, C>,
    decimal: i32,
) {
    let bound = 1.5 * 10f64.powi(-decimal) * want.amax().max(1.0);
    for (g, w) in got.iter().zip(want.iter()) {
        assert!(
            (g - w).abs() < bound,
            "{what}: {g} vs python-control {w}\ngot {got}want {want}"
        );
    }
}

/// Both pole lists sorted as python-control sorts them, compared entry by
/// entry to `decimal` places (relative for large poles).
fn assert_poles(what: &str, got: &[Complex<f64>], want: &[Complex<f64>], decimal: i32) {
    let sort = |v: &[Complex<f64>]| {
        let mut v = v.to_vec();
        v.sort_by(|a, b| a.re.total_cmp(&b.re).then(a.im.total_cmp(&b.im)));
        v
    };
    let (got, want) = (sort(got), sort(want));
    assert_eq!(got.len(), want.len());
    let bound = 1.5 * 10f64.powi(-decimal);
    for (g, w) in got.iter().zip(&want) {
        assert!(
            (g - w).norm() < bound * w.norm().max(1.0),
            "{what}: pole {g} vs python-control {w}\ngot {got:?}\nwant {want:?}"
        );
    }
}

// ---- place ---------------------------------------------------------------------

fn check_place<const N: usize, const M: usize>(name: &str, domain_dt: Option<f64>) {
    let all = fixtures();
    let c = case(&all, "place", name);
    let (a, b) = (matrix::<N, N>(&c["a"]), matrix::<N, M>(&c["b"]));
    assert_eq!(c["discrete"].as_bool().unwrap(), domain_dt.is_some());
    let targets: [Complex<f64>; N] = complex_list(&c["poles"]).try_into().unwrap();
    let k = match domain_dt {
        None => place(
            &StateSpace::continuous(a, b, SMatrix::<f64, 1, N>::zeros(), SMatrix::zeros()).unwrap(),
            &targets,
        ),
        Some(dt) => place(
            &StateSpace::discrete(a, b, SMatrix::<f64, 1, N>::zeros(), SMatrix::zeros(), dt)
                .unwrap(),
            &targets,
        ),
    }
    .unwrap();
    let achieved = eigenvalues(&(a - b * k));
    // python-control's checkPlaced: six decimals against the targets; and
    // the same against what python-control achieved.
    assert_poles(name, &achieved, &targets, 6);
    assert_poles(name, &achieved, &complex_list(&c["achieved"]), 6);
    // A robust placement: the gain is no larger than python-control's
    // (Tits–Yang) by more than a small factor.
    let ratio = k.norm() / c["gain_norm"].as_f64().unwrap();
    println!("{name}: ‖K‖ / ‖K_python-control‖ = {ratio:.4}");
    assert!(ratio < 1.5, "{name}: gain {ratio} times python-control's");
}

fn eigenvalues<const N: usize>(m: &SMatrix<f64, N, N>) -> Vec<Complex<f64>> {
    StateSpace::continuous(
        *m,
        SMatrix::<f64, N, 1>::zeros(),
        SMatrix::<f64, 1, N>::zeros(),
        SMatrix::zeros(),
    )
    .unwrap()
    .poles()
    .unwrap()
    .to_vec()
}

#[test]
fn place_matches_python_control_on_scipy_example() {
    check_place::<4, 2>("scipy_example", None);
}

#[test]
fn place_matches_python_control_with_a_repeated_pole_and_a_complex_pair() {
    check_place::<4, 2>("repeated_and_complex", None);
}

#[test]
fn place_matches_python_control_on_the_two_carts_with_two_forces() {
    check_place::<4, 2>("two_carts_two_forces", None);
    check_place::<4, 2>("two_carts_two_pairs", None);
}

#[test]
fn place_matches_python_control_on_a_discrete_model() {
    check_place::<4, 2>("two_carts_discrete", Some(0.002));
}

#[test]
fn place_matches_python_control_with_a_pole_repeated_three_times_and_three_inputs() {
    check_place::<5, 3>("random_5x3_triple", None);
}

#[test]
fn place_refuses_a_pole_repeated_more_often_than_there_are_inputs() {
    // python-control's testPlace: rank(B) = 2, three poles at −0.5.
    let all = fixtures();
    let c = case(&all, "place", "scipy_example");
    let sys = StateSpace::continuous(
        matrix::<4, 4>(&c["a"]),
        matrix::<4, 2>(&c["b"]),
        SMatrix::<f64, 1, 4>::zeros(),
        SMatrix::zeros(),
    )
    .unwrap();
    let repeated = [-0.5, -0.5, -0.5, -8.6659].map(|re| Complex::new(re, 0.0));
    let err = place(&sys, repeated).unwrap_err();
    assert!(
        matches!(err, Error::InvalidParameter { name: "poles", .. }),
        "{err:?}"
    );
}

// ---- lqe / dlqe ----------------------------------------------------------------

/// An `lqe` case (`dt = None`) or a `dlqe` case at period `dt`; python-control's
/// discrete gain is the predictor's, the current estimator's was computed
/// from its `P` by NumPy.
fn check_lqe<const N: usize, const W: usize, const P: usize>(name: &str, dt: Option<f64>) {
    let all = fixtures();
    let c = case(&all, if dt.is_some() { "dlqe" } else { "lqe" }, name);
    let (a, cm) = (matrix::<N, N>(&c["a"]), matrix::<P, N>(&c["c"]));
    let (g, qn, rn) = (
        matrix::<N, W>(&c["g"]),
        matrix::<W, W>(&c["qn"]),
        matrix::<P, P>(&c["rn"]),
    );
    let b = SMatrix::<f64, N, 1>::zeros();
    let kf = match dt {
        None => lqe(
            &StateSpace::continuous(a, b, cm, SMatrix::zeros()).unwrap(),
            &g,
            &qn,
            &rn,
        ),
        Some(dt) => dlqe(
            &StateSpace::discrete(a, b, cm, SMatrix::zeros(), dt).unwrap(),
            &g,
            &qn,
            &rn,
        ),
    }
    .unwrap();
    assert_almost(name, &kf.gain, &matrix(&c["gain"]), 7);
    match kf.current_gain {
        Some(m) => assert_almost(name, &m, &matrix(&c["current_gain"]), 7),
        None => assert!(dt.is_none()),
    }
    assert_almost(name, &kf.covariance, &matrix(&c["covariance"]), 7);
    assert_poles(name, kf.poles.as_slice(), &complex_list(&c["poles"]), 7);
    assert!(kf.residual < 1e-9, "{name}: residual {}", kf.residual);
}

#[test]
fn lqe_matches_python_control() {
    check_lqe::<1, 1, 1>("python_control_scalar", None);
    check_lqe::<3, 2, 2>("three_states_two_outputs", None);
    check_lqe::<4, 1, 2>("lab_positions", None);
}

#[test]
fn dlqe_matches_python_control() {
    check_lqe::<3, 2, 2>("three_states_two_outputs", Some(0.1));
    check_lqe::<4, 1, 2>("lab_positions", Some(0.002));
    check_lqe::<4, 1, 2>("lab_positions_noisy_force", Some(0.002));
}

#[test]
fn lqe_names_the_noise_covariances_in_its_errors() {
    let sys = StateSpace::continuous(
        SMatrix::<f64, 1, 1>::new(-1.0),
        SMatrix::<f64, 1, 1>::new(1.0),
        SMatrix::<f64, 1, 1>::new(1.0),
        SMatrix::<f64, 1, 1>::zeros(),
    )
    .unwrap();
    let one = SMatrix::<f64, 1, 1>::new(1.0);
    let err = lqe(&sys, &one, &nalgebra::matrix![-1.0], &one).unwrap_err();
    assert!(
        matches!(err, Error::InvalidMatrix { matrix: "QN", .. }),
        "{err:?}"
    );
    let err = lqe(&sys, &one, &one, &nalgebra::matrix![0.0]).unwrap_err();
    assert!(
        matches!(err, Error::InvalidMatrix { matrix: "RN", .. }),
        "{err:?}"
    );
    let err = lqe(&sys, &nalgebra::matrix![f64::NAN], &one, &one).unwrap_err();
    assert!(
        matches!(err, Error::NonFinite { matrix: "G", .. }),
        "{err:?}"
    );
}

// ---- lqi / dlqi ----------------------------------------------------------------

/// python-control's augmented state `[x; ζ]` with `ζ = ∫ C_i x` (or
/// `Σ C_i x`) is ctrlab's `[x; z]` with `z = s ζ` (`s = −1`, or `−T` in
/// discrete time): `S = diag(I, s I)`, `Q = S⁻ᵀ Q_pc S⁻¹`, `K = K_pc S⁻¹`,
/// `X = S⁻ᵀ X_pc S⁻¹`.
fn scaling<const NA: usize>(n: usize, s: f64) -> SMatrix<f64, NA, NA> {
    SMatrix::from_fn(|i, j| match (i == j, i < n) {
        (true, true) => 1.0,
        (true, false) => 1.0 / s,
        _ => 0.0,
    })
}

fn check_lqi<const N: usize, const M: usize, const I: usize, const NA: usize>(name: &str) {
    let all = fixtures();
    let c = case(&all, "lqi", name);
    let (a, b, ci) = (
        matrix::<N, N>(&c["a"]),
        matrix::<N, M>(&c["b"]),
        matrix::<I, N>(&c["ci"]),
    );
    let r = matrix::<M, M>(&c["r"]);
    let dt = c["dt"].as_f64();
    // S⁻¹.
    let s_inv = scaling::<NA>(N, dt.map_or(-1.0, |t| -t));
    let q = s_inv.transpose() * matrix::<NA, NA>(&c["q_pc"]) * s_inv;
    let q = (q + q.transpose()) * 0.5;
    let sol = match dt {
        None => {
            let sys = StateSpace::continuous(a, b, ci, SMatrix::zeros()).unwrap();
            lqi(&sys, &q, &r).unwrap()
        }
        Some(t) => {
            let sys = StateSpace::discrete(a, b, ci, SMatrix::zeros(), t).unwrap();
            dlqi(&sys, &q, &r).unwrap()
        }
    };
    let want_k = matrix::<M, NA>(&c["gain_pc"]) * s_inv;
    let want_x = s_inv.transpose() * matrix::<NA, NA>(&c["riccati_pc"]) * s_inv;
    assert_almost(name, &sol.gain, &want_k, 6);
    assert_almost(name, &sol.riccati, &want_x, 6);
    assert_poles(name, sol.poles.as_slice(), &complex_list(&c["poles"]), 6);
    assert!(sol.residual < 1e-9, "{name}: residual {}", sol.residual);
}

#[test]
fn lqi_matches_python_control_integral_action_on_the_lab_plant() {
    check_lqi::<4, 1, 1, 5>("lab_cart2");
    check_lqi::<4, 1, 1, 5>("lab_cart2_discrete");
}

#[test]
fn lqi_matches_python_control_integral_action_with_two_integrators() {
    check_lqi::<4, 2, 2, 6>("mimo_two_integrators");
    check_lqi::<4, 2, 2, 6>("mimo_two_integrators_discrete");
}

#[test]
fn the_discrete_augmentation_is_forward_euler_at_the_models_period() {
    let sys = StateSpace::discrete(
        SMatrix::<f64, 1, 1>::new(0.5),
        SMatrix::<f64, 1, 1>::new(1.0),
        SMatrix::<f64, 1, 1>::new(2.0),
        SMatrix::<f64, 1, 1>::new(0.25),
        0.1,
    )
    .unwrap();
    let aug: StateSpace<2, 1, 1, Discrete> = augment_integral(&sys).unwrap();
    // z[k+1] = z[k] + T (r − 2 x − 0.25 u).
    assert_eq!(*aug.a(), nalgebra::matrix![0.5, 0.0; -0.2, 1.0]);
    assert_eq!(*aug.b(), nalgebra::matrix![1.0; -0.025]);
    assert_eq!(*aug.c(), nalgebra::matrix![2.0, 0.0]);
    assert_eq!(*aug.d(), nalgebra::matrix![0.25]);
    assert_eq!(aug.dt(), 0.1);
}
