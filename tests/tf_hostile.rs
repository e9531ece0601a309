//! Issue 28: hostile but representable models on which the transfer-function
//! numerics returned wrong answers (each test failed before its fix). Every
//! `Ok` holds finite numbers that are right; where a result cannot be
//! represented the call refuses with a typed error naming the operation.

use ctrlab::freq::{FrequencyDomain, TransferFunction, Zpk, bandwidth, stability_margins};
use ctrlab::{DynStateSpace, Error};
use nalgebra::{Complex, dmatrix};

/// `A = −1, B = C = 1e200`: `G = 1e400 / (s + 1)` is not representable
/// (its coefficient overflows); `ss2tf` returned `G ≡ 0` (the Markov
/// parameter `C B` overflowing to inf, then judged "zero to rounding"
/// against an infinite scale) and `ss2zpk` gain 0.
#[test]
fn ss2tf_of_an_overflowing_markov_parameter_refuses() {
    let sys = DynStateSpace::continuous(
        dmatrix![-1.0],
        dmatrix![1e200],
        dmatrix![1e200],
        dmatrix![0.0],
    )
    .unwrap();
    match TransferFunction::from_state_space(&sys) {
        Err(Error::Overflow { operation }) => assert!(operation.contains("ss2tf"), "{operation}"),
        other => panic!("ss2tf: {other:?}"),
    }
    assert!(matches!(
        Zpk::from_state_space(&sys),
        Err(Error::Overflow { .. })
    ));
    // 1e220 / s² (a double integrator): C A B = 0 exactly, C B² overflow.
    let sys = DynStateSpace::continuous(
        dmatrix![0.0, 0.0; 1.0, 0.0],
        dmatrix![1e220; 0.0],
        dmatrix![0.0, 1e220],
        dmatrix![0.0],
    )
    .unwrap();
    assert!(matches!(
        TransferFunction::from_state_space(&sys),
        Err(Error::Overflow { .. })
    ));
    assert!(matches!(
        Zpk::from_state_space(&sys),
        Err(Error::Overflow { .. })
    ));
    // The representable neighbour still converts: 1e300 / (s + 1).
    let sys = DynStateSpace::continuous(
        dmatrix![-1.0],
        dmatrix![1e150],
        dmatrix![1e150],
        dmatrix![0.0],
    )
    .unwrap();
    let g = TransferFunction::from_state_space(&sys).unwrap();
    assert!((g.num()[0] / 1e300 - 1.0).abs() < 1e-15, "{:?}", g.num());
}

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

/// `tf([1e300], [1e-300, 1])`: the gain `1e600` is not a float; the zpk
/// form must refuse, not return an infinite gain.
#[test]
fn tf2zpk_refuses_an_overflowing_gain() {
    let g = TransferFunction::continuous(&[1e300], &[1e-300, 1.0]).unwrap();
    match Zpk::from_transfer_function(&g) {
        Err(Error::Overflow { operation }) => assert!(operation.contains("tf2zpk"), "{operation}"),
        other => panic!("tf2zpk: {other:?}"),
    }
}

/// A discrete model with `dt = 1e-310` (subnormal): its Nyquist frequency
/// `π/dt` overflows; `bandwidth` returned `Ok(Some(inf))`.
#[test]
fn bandwidth_of_a_subnormal_period_is_finite_or_refused() {
    let g = TransferFunction::discrete(&[0.5], &[1.0, -0.5], 1e-310).unwrap();
    // The -3 dB crossing of 0.5/(z − 0.5) is at θ = 1.3 rad, ω = 1.3e310.
    match bandwidth(&g, -3.0) {
        Err(Error::Overflow { operation }) => assert!(operation.contains("θ / dt"), "{operation}"),
        other => panic!("bandwidth: {other:?}"),
    }
    // The margins of 2/z likewise: its phase crossing is at θ = π.
    let l = TransferFunction::discrete(&[2.0], &[1.0, 0.0], 1e-310).unwrap();
    assert!(matches!(stability_margins(&l), Err(Error::Overflow { .. })));
}

fn rel(got: f64, want: f64) -> f64 {
    (got - want).abs() / want.abs()
}

#[test]
fn ss2tf_keeps_widely_scaled_poles() {
    let sys = wide_model();
    let g = Zpk::from_state_space(&sys).unwrap();
    let mut poles: Vec<f64> = g.poles().iter().map(|p| p.re).collect();
    poles.sort_by(f64::total_cmp);
    assert_eq!(poles.len(), 2);
    assert!(
        rel(poles[0], -1e160) < 1e-15 && rel(poles[1], -1.0) < 1e-15,
        "{poles:?}"
    );
    let tf = TransferFunction::from_state_space(&sys).unwrap();
    let d = tf.den();
    assert_eq!(d.len(), 3);
    assert!(
        rel(d[1], 1e160) < 1e-15 && rel(d[2], 1e160) < 1e-15,
        "{d:?}"
    );
    assert!(rel(tf.dc_gain().unwrap(), 1.0) < 1e-15);
}

/// `A = diag(−1e8, −1e-9)`: the state-space DC gain is 1e9 (from the slow
/// state), but `ss2tf` snapped −1e-9 to 0 (within `n ε ‖A‖_F` = 4e-8)
/// and its `dc_gain` refused a "pole at s = 0".
#[test]
fn ss2tf_keeps_a_slow_pole_beside_a_fast_one() {
    let sys = DynStateSpace::continuous(
        dmatrix![-1e8, 0.0; 0.0, -1e-9],
        dmatrix![1.0; 1.0],
        dmatrix![0.0, 1.0],
        dmatrix![0.0],
    )
    .unwrap();
    let want = sys.dc_gain().unwrap()[(0, 0)];
    assert!(rel(want, 1e9) < 1e-15);
    let tf = TransferFunction::from_state_space(&sys).unwrap();
    assert!(rel(tf.den()[2], 1e-1) < 1e-15, "{:?}", tf.den());
    assert!(rel(tf.dc_gain().unwrap(), 1e9) < 1e-12);
    let zpk = Zpk::from_state_space(&sys).unwrap();
    assert!(rel(zpk.dc_gain().unwrap(), 1e9) < 1e-12);
    // An integrator stays an integrator: exact zeros in A still snap.
    let int = DynStateSpace::continuous(
        dmatrix![-1e8, 0.0; 1.0, 0.0],
        dmatrix![1.0; 0.0],
        dmatrix![0.0, 1.0],
        dmatrix![0.0],
    )
    .unwrap();
    assert!(
        TransferFunction::from_state_space(&int)
            .unwrap()
            .dc_gain()
            .is_err()
    );
}
