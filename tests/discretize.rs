//! Discretisation against SciPy's `cont2discrete` and analytic invariants.

// Built on the two-cart lab (its plant, simulated rig or card).
#![cfg(feature = "lab")]

mod common;

use ctrlab::discretize::expm;
use ctrlab::{Cart, Discretization, Error, MassSpring, StateSpace};
use nalgebra::{SMatrix, matrix};
use proptest::prelude::*;

const DT: f64 = 0.002;

#[test]
fn all_four_methods_match_scipy_to_1e10() {
    let fx = common::nominal_fixture();
    let sys = MassSpring::nominal().state_space(Cart::Two).unwrap();
    let table = &fx["discretised_dt_0_002"];
    for (key, method) in [
        ("zoh", Discretization::Zoh),
        ("bilinear", Discretization::Tustin),
        ("euler", Discretization::ForwardEuler),
        ("backward_diff", Discretization::BackwardEuler),
    ] {
        let d = sys.discretize(DT, method).unwrap();
        let ad = common::matrix::<4, 4>(&table[key]["ad"]);
        let bd = common::matrix::<4, 1>(&table[key]["bd"]);
        let ea = common::rel_frobenius(d.a(), &ad);
        let eb = common::rel_frobenius(d.b(), &bd);
        assert!(ea < 1e-10, "{key}: Ad relative error {ea:e}");
        assert!(eb < 1e-10, "{key}: Bd relative error {eb:e}");
        assert_eq!(d.dt(), DT);
    }
}

#[test]
fn zoh_of_a_double_integrator_is_analytic() {
    // x'' = u: Ad = [[1, h], [0, 1]], Bd = [h²/2, h]; A is singular, so this
    // also checks that ZOH never inverts A.
    let sys = StateSpace::continuous(
        matrix![0.0, 1.0; 0.0, 0.0],
        matrix![0.0; 1.0],
        matrix![1.0, 0.0],
        matrix![0.0],
    )
    .unwrap();
    let h = 0.37;
    let d = sys.discretize(h, Discretization::Zoh).unwrap();
    assert!((d.a() - matrix![1.0, h; 0.0, 1.0]).norm() < 1e-15);
    assert!((d.b() - matrix![h * h / 2.0; h]).norm() < 1e-15);
}

#[test]
fn zoh_handles_large_steps_by_scaling_and_squaring() {
    // ‖A h‖ ≈ 15: exercises several squarings; compare with the analytic
    // rotation-with-decay exponential.
    let (sigma, omega, h) = (-0.5, 3.0, 5.0);
    let a = matrix![sigma, -omega; omega, sigma];
    let e = expm(&(a * h)).unwrap();
    let (s, c) = (omega * h).sin_cos();
    let want = matrix![c, -s; s, c] * (sigma * h).exp();
    assert!(common::rel_frobenius(&e, &want) < 1e-13, "{e} vs {want}");
}

#[test]
fn tustin_and_backward_euler_refuse_a_singular_inverse() {
    // Pole at 2/h makes I - A h/2 singular for Tustin; at 1/h for backward Euler.
    let h = 0.1;
    let tustin =
        StateSpace::continuous(matrix![2.0 / h], matrix![1.0], matrix![1.0], matrix![0.0]).unwrap();
    assert!(matches!(
        tustin.discretize(h, Discretization::Tustin),
        Err(Error::Singular { .. })
    ));
    let backward =
        StateSpace::continuous(matrix![1.0 / h], matrix![1.0], matrix![1.0], matrix![0.0]).unwrap();
    assert!(matches!(
        backward.discretize(h, Discretization::BackwardEuler),
        Err(Error::Singular { .. })
    ));
    // Forward Euler inverts nothing.
    assert!(backward.discretize(h, Discretization::ForwardEuler).is_ok());
}

#[test]
fn bad_time_steps_and_overflow_are_errors() {
    let sys = MassSpring::nominal().state_space(Cart::One).unwrap();
    for dt in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        for method in [
            Discretization::Zoh,
            Discretization::Tustin,
            Discretization::ForwardEuler,
            Discretization::BackwardEuler,
        ] {
            assert!(
                matches!(
                    sys.discretize(dt, method),
                    Err(Error::InvalidParameter { name: "dt", .. })
                ),
                "{method:?} dt = {dt}"
            );
        }
    }
    // An unstable pole with a huge step: e^(1000 · 1e6) is not representable.
    let unstable =
        StateSpace::continuous(matrix![1000.0], matrix![1.0], matrix![1.0], matrix![0.0]).unwrap();
    assert!(matches!(
        unstable.discretize(1e6, Discretization::Zoh),
        Err(Error::Overflow { .. })
    ));
    assert!(matches!(
        expm(&matrix![f64::NAN]),
        Err(Error::NonFinite { matrix: "A", .. })
    ));
}

#[test]
fn tustin_and_backward_euler_transform_c_and_d_like_scipy() {
    // SciPy gbt: Cd = C (I - αhA)^-1, Dd = D + α C Bd. Check the identities
    // directly on the nominal plant.
    let sys = MassSpring::nominal().state_space(Cart::Two).unwrap();
    for (method, alpha) in [
        (Discretization::Tustin, 0.5),
        (Discretization::BackwardEuler, 1.0),
    ] {
        let d = sys.discretize(DT, method).unwrap();
        let ima = SMatrix::<f64, 4, 4>::identity() - sys.a() * (alpha * DT);
        assert!((d.c() * ima - sys.c()).norm() < 1e-14);
        assert!((d.d() - (sys.d() + sys.c() * d.b() * alpha)).norm() < 1e-18);
    }
}

fn spectral_radius(m: &SMatrix<f64, 4, 4>) -> f64 {
    m.complex_eigenvalues()
        .iter()
        .map(|z| z.norm())
        .fold(0.0, f64::max)
}

proptest! {
    #[test]
    fn zoh_of_diagonal_stable_a_is_elementwise_exp(
        poles in proptest::array::uniform3(-1e3..-1e-3f64),
        // |λ dt| ≤ 700 keeps e^(λ dt) ≥ 1e-304, a normal number: a subnormal
        // result has too few bits left for any relative tolerance.
        dt in 1e-4..0.7f64,
    ) {
        let a = SMatrix::<f64, 3, 3>::from_diagonal(&poles.into());
        let b = matrix![1.0; 1.0; 1.0];
        let sys = StateSpace::continuous(a, b, matrix![1.0, 1.0, 1.0], matrix![0.0]).unwrap();
        let d = sys.discretize(dt, Discretization::Zoh).unwrap();
        // exp is conditioned by ‖A dt‖: rounding λ·dt alone moves e^(λ dt) by
        // a relative |λ dt|·ε, and scaling and squaring runs s ≈ log2(4‖A dt‖)
        // squarings on every entry, each of which can double its relative
        // error. So the bar is a small multiple of ‖A dt‖·ε per entry (up to
        // 700·ε here), not ε; the worst measured is about 8 ‖A dt‖ ε.
        let norm = poles.iter().map(|p| (p * dt).abs()).fold(1.0, f64::max);
        let tol = 32.0 * f64::EPSILON * norm;
        for (i, &pole) in poles.iter().enumerate() {
            let x = pole * dt;
            let want = x.exp();
            prop_assert!((d.a()[(i, i)] - want).abs() <= tol * want,
                "a[{i}] = {} vs {want}", d.a()[(i, i)]);
            // ∫ e^(λ s) ds = (e^(λ h) - 1) / λ
            let bw = x.exp_m1() / pole;
            prop_assert!((d.b()[(i, 0)] - bw).abs() <= tol * bw, "b[{i}]");
            for j in 0..3 {
                if i != j { prop_assert_eq!(d.a()[(i, j)], 0.0); }
            }
        }
    }

    #[test]
    fn tustin_maps_stable_models_into_the_unit_disc(
        entries in proptest::array::uniform16(-50.0..50.0f64),
        shift in 0.1..20.0f64,
        dt in 1e-4..0.5f64,
    ) {
        // Make A stable by shifting its spectrum left of -shift.
        let m = SMatrix::<f64, 4, 4>::from_row_slice(&entries);
        let abscissa = m.complex_eigenvalues().iter().map(|z| z.re).fold(f64::MIN, f64::max);
        let a = m - SMatrix::<f64, 4, 4>::identity() * (abscissa + shift);
        let sys = StateSpace::continuous(a, matrix![0.0; 0.0; 0.0; 1.0], matrix![1.0, 0.0, 0.0, 0.0], matrix![0.0]).unwrap();
        let d = sys.discretize(dt, Discretization::Tustin).unwrap();
        let rho = spectral_radius(d.a());
        prop_assert!(rho < 1.0, "spectral radius {rho}");
    }
}
