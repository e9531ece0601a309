//! The typed model and the lab's plant against the python-control fixture.

// Built on the two-cart lab (its plant, simulated rig or card).
#![cfg(feature = "lab")]

mod common;

use ctrlab::{Cart, Error, MassSpring, StateSpace};
use nalgebra::{SMatrix, matrix};
use proptest::prelude::*;

#[test]
fn nominal_a_and_b_equal_the_fixture_exactly() {
    let fx = common::nominal_fixture();
    let sys = MassSpring::nominal().state_space(Cart::Two).unwrap();
    assert_eq!(*sys.a(), common::matrix::<4, 4>(&fx["a"]));
    assert_eq!(*sys.b(), common::matrix::<4, 1>(&fx["b"]));
    assert_eq!(*sys.c(), matrix![0.0, 0.0, 1.0, 0.0]);
    assert_eq!(*sys.d(), matrix![0.0]);
    let cart1 = MassSpring::nominal().state_space(Cart::One).unwrap();
    assert_eq!(*cart1.c(), matrix![1.0, 0.0, 0.0, 0.0]);
    assert_eq!(cart1.a(), sys.a());
}

#[test]
fn open_loop_poles_match_the_fixture() {
    let fx = common::nominal_fixture();
    let sys = MassSpring::nominal().state_space(Cart::Two).unwrap();
    let mut got: Vec<(f64, f64)> = sys
        .a()
        .complex_eigenvalues()
        .iter()
        .map(|z| (z.re, z.im))
        .collect();
    let mut want: Vec<(f64, f64)> = fx["poles"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| (p[0].as_f64().unwrap(), p[1].as_f64().unwrap()))
        .collect();
    let key = |p: &(f64, f64)| (p.0, p.1);
    got.sort_by(|a, b| key(a).partial_cmp(&key(b)).unwrap());
    want.sort_by(|a, b| key(a).partial_cmp(&key(b)).unwrap());
    for (g, w) in got.iter().zip(&want) {
        let scale = w.0.hypot(w.1);
        assert!(
            (g.0 - w.0).hypot(g.1 - w.1) <= 1e-9 * scale,
            "pole {g:?} vs {w:?}"
        );
    }
}

#[test]
fn static_deflection_matches_the_fixture() {
    let fx = common::nominal_fixture();
    for (force, xs) in fx["static_mm"].as_object().unwrap() {
        let f: f64 = force.parse().unwrap();
        let (x1, x2) = MassSpring::nominal().static_deflection(f).unwrap();
        let want1 = xs[0].as_f64().unwrap();
        let want2 = xs[1].as_f64().unwrap();
        assert!((x1 * 1e3 - want1).abs() < 1e-12 * want1, "x1 at {f} N");
        assert!((x2 * 1e3 - want2).abs() < 1e-12 * want2, "x2 at {f} N");
    }
}

#[test]
fn every_bad_parameter_is_named() {
    let base = MassSpring::nominal();
    let cases: [(MassSpring, &str); 12] = [
        (MassSpring { m1: 0.0, ..base }, "m1"),
        (MassSpring { m1: -1.3, ..base }, "m1"),
        (
            MassSpring {
                m2: f64::NAN,
                ..base
            },
            "m2",
        ),
        (MassSpring { m2: 0.0, ..base }, "m2"),
        (MassSpring { k1: -1.0, ..base }, "k1"),
        (
            MassSpring {
                k2: f64::INFINITY,
                ..base
            },
            "k2",
        ),
        (MassSpring { b1: -0.1, ..base }, "b1"),
        (
            MassSpring {
                b2: f64::NAN,
                ..base
            },
            "b2",
        ),
        (MassSpring { gain: -1.0, ..base }, "gain"),
        (
            MassSpring {
                gain: f64::NEG_INFINITY,
                ..base
            },
            "gain",
        ),
        (
            MassSpring {
                m1: f64::INFINITY,
                ..base
            },
            "m1",
        ),
        (
            MassSpring {
                k1: f64::NAN,
                ..base
            },
            "k1",
        ),
    ];
    for (plant, field) in cases {
        for err in [
            plant.validate().unwrap_err(),
            plant.state_space(Cart::One).unwrap_err(),
            plant.static_deflection(1.0).unwrap_err(),
        ] {
            match err {
                Error::InvalidParameter { name, .. } => assert_eq!(name, field),
                other => panic!("{field}: expected InvalidParameter, got {other:?}"),
            }
        }
    }
}

#[test]
fn zero_spring_has_no_static_deflection_but_is_a_valid_model() {
    let plant = MassSpring {
        k1: 0.0,
        ..MassSpring::nominal()
    };
    assert!(plant.state_space(Cart::Two).is_ok());
    assert!(matches!(
        plant.static_deflection(10.0),
        Err(Error::InvalidParameter { name: "k1", .. })
    ));
    assert!(matches!(
        MassSpring::nominal().static_deflection(f64::NAN),
        Err(Error::InvalidParameter { name: "force", .. })
    ));
}

#[test]
fn constructors_name_the_non_finite_entry() {
    let a = matrix![-1.0, 0.0; 0.0, -2.0];
    let b = matrix![1.0; 1.0];
    let c = matrix![1.0, 0.0];
    let d = matrix![0.0];
    let mut bad_c = c;
    bad_c[(0, 1)] = f64::NAN;
    assert!(matches!(
        StateSpace::continuous(a, b, bad_c, d),
        Err(Error::NonFinite {
            matrix: "C",
            row: 0,
            col: 1,
            ..
        })
    ));
    let mut bad_a = a;
    bad_a[(1, 0)] = f64::INFINITY;
    assert!(matches!(
        StateSpace::discrete(bad_a, b, c, d, 0.1),
        Err(Error::NonFinite {
            matrix: "A",
            row: 1,
            col: 0,
            ..
        })
    ));
    assert!(matches!(
        StateSpace::continuous(a, b, c, matrix![f64::NEG_INFINITY]),
        Err(Error::NonFinite { matrix: "D", .. })
    ));
    for dt in [0.0, -0.002, f64::NAN, f64::INFINITY] {
        assert!(
            matches!(
                StateSpace::discrete(a, b, c, d, dt),
                Err(Error::InvalidParameter { name: "dt", .. })
            ),
            "dt = {dt}"
        );
    }
}

fn any_f64() -> impl Strategy<Value = f64> {
    prop_oneof![
        any::<f64>(),
        Just(f64::NAN),
        Just(f64::INFINITY),
        Just(f64::NEG_INFINITY),
        Just(f64::MAX),
        Just(-f64::MAX),
        Just(f64::MIN_POSITIVE),
        Just(0.0),
        -1e3..1e3f64,
    ]
}

proptest! {
    #[test]
    fn constructors_never_panic(
        e in proptest::collection::vec(any_f64(), 9),
        dt in any_f64(),
    ) {
        let a = SMatrix::<f64, 2, 2>::from_iterator(e[0..4].iter().copied());
        let b = SMatrix::<f64, 2, 1>::from_iterator(e[4..6].iter().copied());
        let c = SMatrix::<f64, 1, 2>::from_iterator(e[6..8].iter().copied());
        let d = SMatrix::<f64, 1, 1>::new(e[8]);
        let all_finite = e.iter().all(|v| v.is_finite());
        let cont = StateSpace::continuous(a, b, c, d);
        prop_assert_eq!(cont.is_ok(), all_finite);
        let disc = StateSpace::discrete(a, b, c, d, dt);
        prop_assert_eq!(disc.is_ok(), all_finite && dt.is_finite() && dt > 0.0);
        // Discretising whatever was accepted must not panic either.
        if let Ok(sys) = cont {
            for method in [ctrlab::Discretization::Zoh, ctrlab::Discretization::Tustin,
                           ctrlab::Discretization::ForwardEuler, ctrlab::Discretization::BackwardEuler] {
                if let Ok(d) = sys.discretize(dt, method) {
                    prop_assert!(d.a().iter().all(|v| v.is_finite()));
                }
            }
        }
    }

    #[test]
    fn mass_spring_never_panics(p in proptest::collection::vec(any_f64(), 7)) {
        let plant = MassSpring { m1: p[0], m2: p[1], k1: p[2], k2: p[3], b1: p[4], b2: p[5], gain: p[6] };
        let valid = p[0].is_finite() && p[0] > 0.0 && p[1].is_finite() && p[1] > 0.0
            && p[2..].iter().all(|v| v.is_finite() && *v >= 0.0);
        prop_assert_eq!(plant.validate().is_ok(), valid);
        // Valid but extreme parameters may still overflow A (e.g. k / tiny m):
        // that must be an error, not a panic or a NaN-filled model.
        if let Ok(sys) = plant.state_space(Cart::One) {
            prop_assert!(sys.a().iter().all(|v| v.is_finite()));
        }
    }
}
