//! Poles, stability, DC gain, damping and rank tests against the fixture and
//! closed-form values.

// Built on the two-cart lab (its plant, simulated rig or card).
#![cfg(feature = "lab")]

mod common;

use ctrlab::analysis::rank;
use ctrlab::{Cart, Discretization, Error, MassSpring, StateSpace, dlqr, lqr};
use nalgebra::{Complex, DMatrix, SMatrix, dmatrix, matrix};
use proptest::prelude::*;

#[test]
fn poles_match_the_fixture_sorted() {
    let fx = common::nominal_fixture();
    let sys = MassSpring::nominal().state_space(Cart::Two).unwrap();
    let got = sys.poles().unwrap();
    let mut want: Vec<Complex<f64>> = fx["poles"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| Complex::new(p[0].as_f64().unwrap(), p[1].as_f64().unwrap()))
        .collect();
    want.sort_by(|x, y| x.re.total_cmp(&y.re).then(x.im.total_cmp(&y.im)));
    for (g, w) in got.iter().zip(&want) {
        assert!((g - w).norm() <= 1e-9 * w.norm(), "{g} vs {w}");
    }
    // Sorted by real part, then imaginary part.
    for w in got.windows(2) {
        assert!(w[0].re < w[1].re || (w[0].re == w[1].re && w[0].im <= w[1].im));
    }
}

#[test]
fn dc_gain_is_the_static_deflection() {
    let plant = MassSpring::nominal();
    for (output, want) in [(Cart::One, 1.0 / 1000.0), (Cart::Two, 2.0 / 1000.0)] {
        let sys = plant.state_space(output).unwrap();
        let g = sys.dc_gain().unwrap()[(0, 0)];
        assert!((g - want).abs() <= 1e-14 * want, "{output:?}");
        // ZOH preserves the DC gain exactly (in exact arithmetic).
        let d = sys.discretize(0.002, Discretization::Zoh).unwrap();
        assert!((d.dc_gain().unwrap()[(0, 0)] - want).abs() <= 1e-10 * want);
    }
}

#[test]
fn dc_gain_with_a_pole_at_the_origin_is_singular() {
    let free_cart = StateSpace::continuous(
        matrix![0.0, 1.0; 0.0, -1.0],
        matrix![0.0; 1.0],
        matrix![1.0, 0.0],
        matrix![0.0],
    )
    .unwrap();
    assert!(matches!(free_cart.dc_gain(), Err(Error::Singular { .. })));
    let acc =
        StateSpace::discrete(matrix![1.0], matrix![1.0], matrix![1.0], matrix![0.0], 0.1).unwrap();
    assert!(matches!(acc.dc_gain(), Err(Error::Singular { .. })));
}

#[test]
fn dc_gain_includes_feedthrough() {
    let sys =
        StateSpace::continuous(matrix![-4.0], matrix![2.0], matrix![3.0], matrix![0.5]).unwrap();
    assert!((sys.dc_gain().unwrap()[(0, 0)] - (1.5 + 0.5)).abs() < 1e-15);
}

#[test]
fn stability_in_both_domains() {
    let plant = MassSpring::nominal().state_space(Cart::Two).unwrap();
    assert!(plant.is_stable().unwrap());
    assert!(
        plant
            .discretize(0.002, Discretization::Zoh)
            .unwrap()
            .is_stable()
            .unwrap()
    );
    let unstable = StateSpace::continuous(
        matrix![0.1, 1.0; -1.0, 0.1],
        matrix![0.0; 1.0],
        matrix![1.0, 0.0],
        matrix![0.0],
    )
    .unwrap();
    assert!(!unstable.is_stable().unwrap());
    assert!(
        !unstable
            .discretize(0.01, Discretization::Zoh)
            .unwrap()
            .is_stable()
            .unwrap()
    );
    let undamped = StateSpace::continuous(
        matrix![0.0, 1.0; -1.0, 0.0],
        matrix![0.0; 1.0],
        matrix![1.0, 0.0],
        matrix![0.0],
    )
    .unwrap();
    assert!(!undamped.is_stable().unwrap());
}

#[test]
fn damping_of_a_second_order_system_and_its_discretisation() {
    let (wn, zeta) = (12.0, 0.25);
    let sys = StateSpace::continuous(
        matrix![0.0, 1.0; -wn * wn, -2.0 * zeta * wn],
        matrix![0.0; 1.0],
        matrix![1.0, 0.0],
        matrix![0.0],
    )
    .unwrap();
    for d in sys.damping().unwrap() {
        assert!((d.natural_frequency - wn).abs() < 1e-12);
        assert!((d.damping_ratio - zeta).abs() < 1e-12);
        assert!((d.time_constant - 1.0 / (zeta * wn)).abs() < 1e-12);
    }
    // ZOH maps s to e^(s dt); damp maps it back.
    let d = sys.discretize(0.01, Discretization::Zoh).unwrap();
    for p in d.damping().unwrap() {
        assert!((p.natural_frequency - wn).abs() < 1e-9);
        assert!((p.damping_ratio - zeta).abs() < 1e-9);
    }
    let integrator =
        StateSpace::continuous(matrix![0.0], matrix![1.0], matrix![1.0], matrix![0.0]).unwrap();
    let d0 = integrator.damping().unwrap()[0];
    assert_eq!((d0.natural_frequency, d0.damping_ratio), (0.0, -1.0));
    assert_eq!(d0.time_constant, f64::INFINITY);
    let deadbeat =
        StateSpace::discrete(matrix![0.0], matrix![1.0], matrix![1.0], matrix![0.0], 0.1).unwrap();
    let z0 = deadbeat.damping().unwrap()[0];
    assert_eq!(
        (z0.natural_frequency, z0.damping_ratio, z0.time_constant),
        (f64::INFINITY, 1.0, 0.0)
    );
}

#[test]
fn controllability_and_observability_of_the_lab_plant() {
    let sys = MassSpring::nominal().state_space(Cart::Two).unwrap();
    let c = sys.controllability().unwrap();
    assert_eq!((c.nrows(), c.ncols()), (4, 4));
    // Column j is A^j B.
    let a = sys.a();
    let b = sys.b();
    for j in 0..4 {
        let col = a.pow(j as u32) * b;
        for i in 0..4 {
            assert_eq!(c[(i, j)], col[i]);
        }
    }
    assert!(sys.is_controllable().unwrap());
    assert!(sys.is_observable().unwrap());
    assert_eq!(rank(&sys.observability().unwrap(), None).unwrap(), 4);
    // A zero spring between the carts cuts cart 1 off from the motor and cart
    // 2's position off from cart 1.
    let cut = MassSpring {
        k2: 0.0,
        ..MassSpring::nominal()
    };
    let s = cut.state_space(Cart::Two).unwrap();
    assert!(!s.is_controllable().unwrap());
    assert!(!s.is_observable().unwrap());
    assert_eq!(rank(&s.controllability().unwrap(), None).unwrap(), 2);
}

#[test]
fn rank_is_relative_to_the_largest_singular_value() {
    // The same rank-1 matrix at wildly different scales.
    for scale in [1e-200, 1.0, 1e200] {
        let m = dmatrix![1.0, 2.0; 2.0, 4.0] * scale;
        assert_eq!(rank(&m, None).unwrap(), 1, "scale {scale}");
    }
    assert_eq!(rank(&DMatrix::<f64>::zeros(3, 2), None).unwrap(), 0);
    assert!(matches!(
        rank(&dmatrix![1.0], Some(-1.0)),
        Err(Error::InvalidParameter { name: "rtol", .. })
    ));
    assert!(matches!(
        rank(&dmatrix![f64::NAN], None),
        Err(Error::NonFinite { .. })
    ));
}

#[test]
fn huge_powers_overflow_into_an_error_not_nan() {
    let a = SMatrix::<f64, 4, 4>::from_element(1e120);
    let sys = StateSpace::continuous(
        a,
        matrix![1.0; 1.0; 1.0; 1.0],
        matrix![1.0, 0.0, 0.0, 0.0],
        matrix![0.0],
    )
    .unwrap();
    assert!(matches!(sys.controllability(), Err(Error::Overflow { .. })));
    assert!(matches!(sys.observability(), Err(Error::Overflow { .. })));
    // The rank tests scale the powers as they form them, so they answer:
    // A = 1e120 · ones has rank 1, and C A ∥ C A², so the rank is 2.
    assert!(!sys.is_observable().unwrap());
    assert!(!sys.is_controllable().unwrap());
}

proptest! {
    #[test]
    fn poles_of_a_block_diagonal_matrix_are_its_blocks(
        sigma in proptest::array::uniform2(-50.0..50.0f64),
        omega in proptest::array::uniform2(0.1..80.0f64),
    ) {
        // Rotation-scaling blocks [σ ω; −ω σ] have poles σ ± iω.
        let a = matrix![
            sigma[0], omega[0], 0.0, 0.0;
            -omega[0], sigma[0], 0.0, 0.0;
            0.0, 0.0, sigma[1], omega[1];
            0.0, 0.0, -omega[1], sigma[1]
        ];
        let sys = StateSpace::continuous(a, SMatrix::<f64, 4, 1>::zeros(), SMatrix::<f64, 1, 4>::zeros(), matrix![0.0]).unwrap();
        let got = sys.poles().unwrap();
        for (s, w) in sigma.iter().zip(&omega) {
            for sign in [1.0, -1.0] {
                let want = Complex::new(*s, sign * w);
                let err = got.iter().map(|g| (g - want).norm()).fold(f64::INFINITY, f64::min);
                prop_assert!(err <= 1e-12 * want.norm().max(1.0), "{} missed by {}", want, err);
            }
        }
        prop_assert_eq!(sys.is_stable().unwrap(), sigma.iter().all(|s| *s < 0.0));
    }
}

#[test]
fn a_rigid_body_mode_is_neither_stable_nor_given_a_dc_gain() {
    // k1 = 0: both carts can drift together. The pole at 0 (z = 1) comes
    // out of the arithmetic a few ε off the boundary; it must still count
    // as on it, before and after discretisation.
    for k2 in [1000.0, 777.7] {
        let plant = MassSpring {
            k1: 0.0,
            k2,
            ..MassSpring::nominal()
        };
        let sys = plant.state_space(Cart::Two).unwrap();
        assert!(!sys.is_stable().unwrap(), "k2 = {k2}");
        assert!(
            matches!(sys.dc_gain(), Err(Error::Singular { .. })),
            "k2 = {k2}"
        );
        let d = sys.discretize(0.002, Discretization::Zoh).unwrap();
        assert!(!d.is_stable().unwrap(), "k2 = {k2}");
        assert!(
            matches!(d.dc_gain(), Err(Error::Singular { .. })),
            "k2 = {k2}: {:?}",
            d.dc_gain()
        );
    }
    // A slow but genuine pole keeps its stability and its gain.
    let slow =
        StateSpace::continuous(matrix![-1e-6], matrix![1e-6], matrix![1.0], matrix![0.0]).unwrap();
    let d = slow.discretize(0.002, Discretization::Zoh).unwrap();
    assert!(slow.is_stable().unwrap() && d.is_stable().unwrap());
    assert!((slow.dc_gain().unwrap()[(0, 0)] - 1.0).abs() < 1e-12);
    assert!((d.dc_gain().unwrap()[(0, 0)] - 1.0).abs() < 1e-6);
}

#[test]
fn unstable_pole_is_the_first_pole_on_or_outside_the_boundary() {
    // Continuous: poles sorted by real part, then imaginary part; the first
    // with Re s ≥ 0 (to rounding) is returned.
    let two_unstable = StateSpace::continuous(
        matrix![-1.0, 0.0, 0.0; 0.0, 3.0, 0.0; 0.0, 0.0, 2.0],
        matrix![1.0; 1.0; 1.0],
        matrix![1.0, 1.0, 1.0],
        matrix![0.0],
    )
    .unwrap();
    assert_eq!(
        two_unstable.unstable_pole().unwrap(),
        Some(Complex::new(2.0, 0.0))
    );
    assert!(!two_unstable.is_stable().unwrap());
    // A growing oscillation 0.5 ± i next to a stable real pole: the pair's
    // lower half comes first.
    let spiral = StateSpace::continuous(
        matrix![0.5, 1.0, 0.0; -1.0, 0.5, 0.0; 0.0, 0.0, -3.0],
        matrix![0.0; 1.0; 1.0],
        matrix![1.0, 0.0, 1.0],
        matrix![0.0],
    )
    .unwrap();
    let p = spiral.unstable_pole().unwrap().unwrap();
    assert!((p - Complex::new(0.5, -1.0)).norm() < 1e-12, "{p}");
    // On the boundary counts: an integrator.
    let integrator =
        StateSpace::continuous(matrix![0.0], matrix![1.0], matrix![1.0], matrix![0.0]).unwrap();
    assert_eq!(
        integrator.unstable_pole().unwrap(),
        Some(Complex::new(0.0, 0.0))
    );
    // Stable models have none.
    let plant = MassSpring::nominal().state_space(Cart::Two).unwrap();
    assert_eq!(plant.unstable_pole().unwrap(), None);
    let lag =
        StateSpace::continuous(matrix![-1e-3], matrix![1.0], matrix![1.0], matrix![0.0]).unwrap();
    assert_eq!(lag.unstable_pole().unwrap(), None);

    // Discrete: the first pole with |z| ≥ 1 (to rounding), in the same order.
    let outside = StateSpace::discrete(
        matrix![0.5, 0.0, 0.0; 0.0, 1.1, 0.0; 0.0, 0.0, -1.2],
        matrix![1.0; 1.0; 1.0],
        matrix![1.0, 1.0, 1.0],
        matrix![0.0],
        0.1,
    )
    .unwrap();
    assert_eq!(
        outside.unstable_pole().unwrap(),
        Some(Complex::new(-1.2, 0.0))
    );
    assert!(!outside.is_stable().unwrap());
    // |z| = 1.2 > 1 although Re z = 0.6 < 1: the test is on the modulus.
    let rotating = StateSpace::discrete(
        matrix![0.6, 0.96; -0.96, 0.6],
        matrix![0.0; 1.0],
        matrix![1.0, 0.0],
        matrix![0.0],
        0.1,
    )
    .unwrap();
    let z = rotating.unstable_pole().unwrap().unwrap();
    assert!((z - Complex::new(0.6, -0.96)).norm() < 1e-12, "{z}");
    let accumulator =
        StateSpace::discrete(matrix![1.0], matrix![1.0], matrix![1.0], matrix![0.0], 0.1).unwrap();
    assert_eq!(
        accumulator.unstable_pole().unwrap(),
        Some(Complex::new(1.0, 0.0))
    );
    let d = plant.discretize(0.002, Discretization::Zoh).unwrap();
    assert_eq!(d.unstable_pole().unwrap(), None);
    let halving =
        StateSpace::discrete(matrix![-0.5], matrix![1.0], matrix![1.0], matrix![0.0], 0.1).unwrap();
    assert_eq!(halving.unstable_pole().unwrap(), None);
}

#[test]
fn lqr_and_dlqr_refuse_a_solution_that_does_not_stabilise() {
    // x' = x + u with Q = 0: the unstable mode costs nothing, the Riccati
    // solution found is X = 0, and its loop keeps the pole at s = 1.
    let sys =
        StateSpace::continuous(matrix![1.0], matrix![1.0], matrix![1.0], matrix![0.0]).unwrap();
    match lqr(&sys, &matrix![0.0], &matrix![1.0]) {
        Err(Error::Unstable { re, im, .. }) => assert_eq!((re, im), (1.0, 0.0)),
        other => panic!("expected Error::Unstable, got {other:?}"),
    }
    // The same in discrete time: x[k+1] = 2 x[k] + u[k] keeps z = 2.
    let d =
        StateSpace::discrete(matrix![2.0], matrix![1.0], matrix![1.0], matrix![0.0], 0.1).unwrap();
    match dlqr(&d, &matrix![0.0], &matrix![1.0]) {
        Err(Error::Unstable { re, im, .. }) => assert_eq!((re, im), (2.0, 0.0)),
        other => panic!("expected Error::Unstable, got {other:?}"),
    }
    // An unstable mode the input cannot reach (not stabilisable), in both
    // domains.
    let unreachable = StateSpace::continuous(
        matrix![1.0, 0.0; 0.0, -1.0],
        matrix![0.0; 1.0],
        matrix![1.0, 0.0],
        matrix![0.0],
    )
    .unwrap();
    let q = SMatrix::<f64, 2, 2>::identity();
    match lqr(&unreachable, &q, &matrix![1.0]) {
        Err(Error::Unstable { re, .. }) => assert!(re >= 0.0, "{re}"),
        other => panic!("expected Error::Unstable, got {other:?}"),
    }
    let unreachable_d = StateSpace::discrete(
        matrix![1.5, 0.0; 0.0, 0.5],
        matrix![0.0; 1.0],
        matrix![1.0, 0.0],
        matrix![0.0],
        0.1,
    )
    .unwrap();
    match dlqr(&unreachable_d, &q, &matrix![1.0]) {
        Err(Error::Unstable { re, im, .. }) => {
            assert!(Complex::new(re, im).norm() >= 1.0, "{re} + {im}i")
        }
        other => panic!("expected Error::Unstable, got {other:?}"),
    }
    // With Q > 0 the same plants are stabilised.
    assert!(lqr(&sys, &matrix![1.0], &matrix![1.0]).is_ok());
    assert!(dlqr(&d, &matrix![1.0], &matrix![1.0]).is_ok());
}
