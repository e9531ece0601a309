//! The lab's per-millimetre gains and back: `LabGains::state_feedback` and
//! `LabGains::from_state_feedback` are inverses.

// Built on the two-cart lab (its plant, simulated rig or card).
#![cfg(feature = "lab")]

use ctrlab::lab::LabGains;
use ctrlab::{Cart, Controller, Error, MassSpring, StateFeedback, lqr};
use nalgebra::{SMatrix, matrix, vector};
use proptest::prelude::*;

/// Relative agreement to a couple of ulps: ×1000 then ÷1000 need not
/// return the same double.
fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 4.0 * f64::EPSILON * a.abs().max(b.abs())
}

#[test]
fn the_lab_tables_round_trip_exactly() {
    // Every row of Tables 2, 5 and 6.
    let rows = [
        ([0.0, 0.0, 0.1, 0.0], Cart::Two),
        ([0.0, 0.0, 10.0, 0.5], Cart::Two),
        ([0.0, 0.0, 10.0, 0.02], Cart::Two),
        ([1.0, 0.005, 0.0, 0.0], Cart::One),
        ([1.0, 0.0, 0.0, 0.2], Cart::One),
    ];
    for (kf, cart) in rows {
        let law = LabGains::new(kf, cart).state_feedback().unwrap();
        let lab = LabGains::from_state_feedback(&law, cart).unwrap();
        for (got, want) in lab.kf.iter().zip(kf) {
            assert!(close(*got, want), "{kf:?}: {got} vs {want}");
        }
        let mut g = [0.0; 4];
        g[cart.state_index()] = 1.0;
        assert_eq!(lab.g, g, "G selects the cart");
        assert_eq!(lab.state_feedback().unwrap(), law);
        // Bit for bit the law `StateFeedback::from_lab_gains` built:
        // K = 1000 Kf, N = K on the cart's position.
        let k = kf.map(|kf| kf * 1000.0);
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(law.gain().as_slice()), bits(&k));
        assert_eq!(
            bits(law.reference_gain().as_slice()),
            bits(&[k[cart.state_index()]])
        );
    }
}

#[test]
fn an_lqr_law_reaches_the_lab_units_and_acts_the_same() {
    let plant = MassSpring::nominal().state_space(Cart::Two).unwrap();
    let q = SMatrix::<f64, 4, 4>::from_diagonal(&vector![1e4, 0.0, 1e6, 10.0]);
    let k = lqr(&plant, &q, &matrix![1.0]).unwrap().gain;
    let mut law = StateFeedback::with_prefilter(&plant, k).unwrap();
    let lab = LabGains::from_state_feedback(&law, Cart::Two).unwrap();
    // The lab's formula, evaluated in millimetres by hand, gives the SI
    // law's input.
    let (x, r) = (vector![0.004, -0.02, 0.011, 0.05], 0.030);
    let by_hand: f64 = (0..4)
        .map(|i| lab.kf[i] * (lab.g[i] * r * 1000.0 - x[i] * 1000.0))
        .sum();
    let si = law.update(&x, &vector![r])[0];
    assert!(
        (by_hand - si).abs() <= 1e-12 * si.abs(),
        "{by_hand} vs {si}"
    );
    // The closed loop still has unit DC gain, so G is not the selection.
    assert!(lab.g[2] != 1.0);
}

#[test]
fn a_law_without_gain_on_the_cart_has_no_lab_form_for_it() {
    let law = StateFeedback::new(matrix![1.0, 0.0, 0.0, 0.0], vector![2.0]).unwrap();
    let err = LabGains::from_state_feedback(&law, Cart::Two).unwrap_err();
    assert!(
        matches!(err, Error::InvalidParameter { name: "K", .. }),
        "{err:?}"
    );
    // With no reference gain either, G = 0 reproduces it.
    let regulator = StateFeedback::new(matrix![1.0, 0.0, 0.0, 0.0], vector![0.0]).unwrap();
    assert_eq!(
        LabGains::from_state_feedback(&regulator, Cart::Two)
            .unwrap()
            .g,
        [0.0; 4]
    );
}

#[test]
fn a_non_finite_lab_gain_is_named() {
    let lab = LabGains {
        kf: [0.0, f64::INFINITY, 1.0, 0.0],
        g: [0.0, 0.0, 1.0, 0.0],
    };
    assert!(matches!(
        lab.state_feedback(),
        Err(Error::NonFinite {
            matrix: "K",
            col: 1,
            ..
        })
    ));
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn lab_to_si_to_lab_is_the_identity(
        kf in proptest::array::uniform4(-50.0..50.0f64),
        two in any::<bool>(),
    ) {
        let cart = if two { Cart::Two } else { Cart::One };
        prop_assume!(kf[cart.state_index()] != 0.0);
        let lab = LabGains::from_state_feedback(&LabGains::new(kf, cart).state_feedback().unwrap(), cart)
            .unwrap();
        for (got, want) in lab.kf.iter().zip(kf) {
            prop_assert!(close(*got, want), "{} vs {}", got, want);
        }
        prop_assert_eq!(lab.g[cart.state_index()], 1.0);
    }

    #[test]
    fn si_to_lab_to_si_is_the_identity(
        k in proptest::array::uniform4(-1e5..1e5f64),
        n in -1e5..1e5f64,
        two in any::<bool>(),
    ) {
        let cart = if two { Cart::Two } else { Cart::One };
        prop_assume!(k[cart.state_index()].abs() > 1e-3);
        let law = StateFeedback::new(SMatrix::<f64, 1, 4>::from_row_slice(&k), vector![n]).unwrap();
        let back = LabGains::from_state_feedback(&law, cart).unwrap().state_feedback().unwrap();
        for (got, want) in back.gain().iter().zip(k) {
            prop_assert!(close(*got, want));
        }
        let n_back = back.reference_gain()[0];
        prop_assert!((n_back - n).abs() <= 8.0 * f64::EPSILON * n.abs(), "{} vs {}", n_back, n);
    }
}
