//! Root loci (`freq::root_locus`, `freq::root_locus_at`): the closed-loop
//! poles against python-control 0.10.2's `root_locus_map(sys, gains)`
//! (`tests/data/rlocus_fixtures.json`, from
//! `tests/data/gen_rlocus_fixtures.py`), closed forms worked by hand, the
//! refusals, and invariants of every reported pole.

use ctrlab::freq::{
    PoleZeroMap, RootLocus, TransferFunction, Zpk, pole_zero_map, root_locus, root_locus_at,
};
use ctrlab::{DynStateSpace, Error};
use nalgebra::Complex;
use proptest::prelude::*;
use serde_json::Value;

mod common;

use common::{complexes, dmatrix as matrix, floats, two_inputs, worst_match};

fn fixtures() -> Value {
    common::fixture("rlocus_fixtures.json")
}

/// Runs `$body` with `$m` bound to the case's open loop: its transfer
/// function or state-space model, continuous or discrete.
macro_rules! with_model {
    ($case:expr, $m:ident => $body:expr) => {{
        let case = $case;
        let dt = case["dt"].as_f64();
        if case["kind"] == "tf" {
            let (num, den) = (floats(&case["num"]), floats(&case["den"]));
            match dt {
                None => {
                    let $m = TransferFunction::continuous(&num, &den).unwrap();
                    $body
                }
                Some(dt) => {
                    let $m = TransferFunction::discrete(&num, &den, dt).unwrap();
                    $body
                }
            }
        } else {
            let m = |key: &str| matrix(&case[key]);
            let (a, b, c, d) = (m("a"), m("b"), m("c"), m("d"));
            match dt {
                None => {
                    let $m = DynStateSpace::continuous(a, b, c, d).unwrap();
                    $body
                }
                Some(dt) => {
                    let $m = DynStateSpace::discrete(a, b, c, d, dt).unwrap();
                    $body
                }
            }
        }
    }};
}

/// Every case's locus at the fixture's gains, by `root_locus_at`.
fn loci_of(case: &Value) -> RootLocus {
    let gains = floats(&case["gains"]);
    with_model!(case, l => root_locus_at(&l, &gains).unwrap())
}

#[test]
fn closed_loop_poles_match_python_control_at_its_gains() {
    let f = fixtures();
    for case in f["cases"].as_array().unwrap() {
        let name = case["name"].as_str().unwrap();
        let locus = loci_of(case);
        let want: Vec<Value> = case["loci"].as_array().unwrap().clone();
        assert_eq!(locus.gains.len(), want.len(), "{name}");
        let mut worst: f64 = 0.0;
        for (j, w) in want.iter().enumerate() {
            worst = worst.max(worst_match(&locus.poles_at(j), &complexes(w)));
        }
        // Measured: 3.6e-12 for the lab's ZOH loop (poles clustered near
        // z = 1, ill-conditioned roots), at most 3.2e-15 for the others.
        assert!(
            worst <= 1e-10,
            "{name}: worst pole off by {worst:e} (relative)"
        );
        // Open-loop poles and zeros: python-control's pole_zero_map.
        assert!(
            worst_match(&locus.poles, &complexes(&case["poles"])) <= 1e-9,
            "{name}"
        );
        assert!(
            worst_match(&locus.zeros, &complexes(&case["zeros"])) <= 1e-7,
            "{name}"
        );
    }
}

/// Every case's pole-zero map, from its own model (tf or state space).
fn pzmap_of(case: &Value) -> PoleZeroMap {
    with_model!(case, m => pole_zero_map(&m).unwrap())
}

#[test]
fn pole_zero_maps_match_python_control() {
    let f = fixtures();
    for case in f["cases"].as_array().unwrap() {
        let name = case["name"].as_str().unwrap();
        let pz = pzmap_of(case);
        assert_eq!(pz.period, case["dt"].as_f64(), "{name}");
        let poles = worst_match(&pz.poles, &complexes(&case["poles"]));
        let zeros = worst_match(&pz.zeros, &complexes(&case["zeros"]));
        // Measured: poles at most 2.1e-15, zeros 8.8e-16 (relative).
        assert!(
            poles <= 1e-13 && zeros <= 1e-13,
            "{name}: {poles:e} {zeros:e}"
        );
        // Sorted by real, then imaginary part.
        for v in [&pz.poles, &pz.zeros] {
            assert!(
                v.windows(2)
                    .all(|w| (w[0].re, w[0].im) <= (w[1].re, w[1].im)),
                "{name}"
            );
        }
    }
    // A zpk is its own map; a non-square state-space model is refused.
    let z = Zpk::continuous(&[Complex::new(-3.0, 0.0)], &[Complex::new(-1.0, 0.0)], 2.0).unwrap();
    assert_eq!(pole_zero_map(&z).unwrap().zeros, [Complex::new(-3.0, 0.0)]);
    let wide = two_inputs();
    assert!(matches!(
        pole_zero_map(&wide),
        Err(Error::InvalidMatrix { matrix: "D", .. })
    ));
}

#[test]
fn the_closed_forms_in_the_fixtures_hold() {
    let f = fixtures();
    for case in f["cases"].as_array().unwrap() {
        let locus = loci_of(case);
        let name = case["name"].as_str().unwrap();
        if case["dt"].is_number() {
            // The discrete closed form: `discrete_crossing_on_the_unit_circle`.
            if let Some(c) = case.get("crossing") {
                let gain = c[0].as_f64().unwrap();
                assert_eq!(locus.crossings.len(), 1, "{name}");
                assert!(
                    (locus.crossings[0].gain - gain).abs() < 1e-10 * gain,
                    "{name}"
                );
            }
            continue;
        }
        if let Some(b) = case.get("breakaway") {
            let [point, gain] = [b[0].as_f64().unwrap(), b[1].as_f64().unwrap()];
            let got = root_locus(&tf_of(case)).unwrap().breakaways;
            assert_eq!(got.len(), 1, "{name}: {got:?}");
            assert!(
                (got[0].point - Complex::new(point, 0.0)).norm() < 1e-12,
                "{name}"
            );
            assert!((got[0].gain - gain).abs() < 1e-12, "{name}");
        }
        if let Some(c) = case.get("crossing") {
            let [gain, w] = [c[0].as_f64().unwrap(), c[1].as_f64().unwrap()];
            let got = root_locus(&tf_of(case)).unwrap().crossings;
            assert_eq!(got.len(), 1, "{name}: {got:?}");
            assert!((got[0].gain - gain).abs() < 1e-9 * gain, "{name}: {got:?}");
            assert!((got[0].frequency - w).abs() < 1e-9 * w, "{name}: {got:?}");
            assert!(got[0].destabilising, "{name}");
            // At root_locus_at's gains the crossing is inside their range.
            assert_eq!(locus.crossings.len(), 1, "{name}");
        }
    }
}

fn tf_of(case: &Value) -> TransferFunction<ctrlab::Continuous> {
    TransferFunction::continuous(&floats(&case["num"]), &floats(&case["den"])).unwrap()
}

#[test]
fn breakaway_of_a_double_integrator_with_lag() {
    // 1 / (s (s + 2)): breakaway at −1 with k = 1, asymptotes ±90° from −1.
    let l = TransferFunction::continuous(&[1.0], &[1.0, 2.0, 0.0]).unwrap();
    let locus = root_locus(&l).unwrap();
    assert_eq!(locus.breakaways.len(), 1);
    assert!((locus.breakaways[0].point.re + 1.0).abs() < 1e-12);
    assert!((locus.breakaways[0].gain - 1.0).abs() < 1e-12);
    let a = locus.asymptotes.as_ref().unwrap();
    assert_eq!(a.centroid, -1.0);
    assert!(locus.crossings.is_empty());
    // The breakaway gain is on the grid, and both poles are at −1 there.
    let j = locus
        .gains
        .iter()
        .position(|&k| k == locus.breakaways[0].gain)
        .unwrap();
    for p in locus.poles_at(j) {
        assert!((p - Complex::new(-1.0, 0.0)).norm() < 1e-7, "{p}");
    }
}

#[test]
fn third_order_lag_crosses_at_root_11_for_gain_60() {
    let l = TransferFunction::continuous(&[1.0], &[1.0, 6.0, 11.0, 6.0]).unwrap();
    let locus = root_locus(&l).unwrap();
    assert_eq!(locus.crossings.len(), 1);
    let c = locus.crossings[0];
    assert!((c.gain - 60.0).abs() < 1e-10, "{c:?}");
    assert!((c.frequency - 11f64.sqrt()).abs() < 1e-12, "{c:?}");
    assert!(c.destabilising);
    // One real breakaway between −1 and −2: 3 s² + 12 s + 11 = 0.
    assert_eq!(locus.breakaways.len(), 1);
    let want = -2.0 + 1.0 / 3f64.sqrt();
    assert!((locus.breakaways[0].point.re - want).abs() < 1e-12);
    // The range reaches past the crossing.
    assert!(*locus.gains.last().unwrap() >= 90.0);
}

#[test]
fn discrete_crossing_on_the_unit_circle() {
    // (z − 1)(z − 0.5) + 0.25 k: |z|² = 0.5 + 0.25 k = 1 at k = 2.
    let l = TransferFunction::discrete(&[0.25], &[1.0, -1.5, 0.5], 0.1).unwrap();
    let locus = root_locus(&l).unwrap();
    assert_eq!(locus.period, Some(0.1));
    assert_eq!(locus.crossings.len(), 1, "{:?}", locus.crossings);
    let c = locus.crossings[0];
    assert!((c.gain - 2.0).abs() < 1e-10, "{c:?}");
    assert!((c.point - Complex::new(0.75, 7f64.sqrt() / 4.0)).norm() < 1e-10);
    assert!((c.frequency - 0.75f64.acos() / 0.1).abs() < 1e-9);
    assert!(c.destabilising);
    // Breakaway: 2 z − 1.5 = 0 at z = 0.75, k = −D(0.75)/0.25 = 0.25.
    assert!((locus.breakaways[0].point.re - 0.75).abs() < 1e-12);
    assert!((locus.breakaways[0].gain - 0.25).abs() < 1e-12);
}

#[cfg(feature = "lab")]
#[test]
fn the_lab_plant_and_its_transfer_function_give_one_locus() {
    // Fixed-size state space, run-time sized, and its tf: the same locus.
    let plant = ctrlab::MassSpring::nominal()
        .state_space(ctrlab::Cart::Two)
        .unwrap();
    let gains = [0.0, 1e3, 1e4];
    let a = root_locus_at(&plant, &gains).unwrap();
    let b = root_locus_at(&DynStateSpace::from(&plant), &gains).unwrap();
    let c = root_locus_at(&TransferFunction::try_from(&plant).unwrap(), &gains).unwrap();
    for j in 0..3 {
        assert_eq!(a.poles_at(j), b.poles_at(j));
        assert!(worst_match(&a.poles_at(j), &c.poles_at(j)) < 1e-12);
    }
}

#[test]
fn extreme_input_is_refused_by_name() {
    let zero = TransferFunction::continuous(&[0.0], &[1.0, 1.0]).unwrap();
    assert!(matches!(
        root_locus(&zero),
        Err(Error::InvalidData { what: "num", .. })
    ));
    let improper = TransferFunction::continuous(&[1.0, 0.0, 0.0], &[1.0, 1.0]).unwrap();
    assert!(matches!(
        root_locus(&improper),
        Err(Error::InvalidData { what: "num", .. })
    ));
    let stat = TransferFunction::continuous(&[2.0], &[1.0]).unwrap();
    assert!(matches!(
        root_locus(&stat),
        Err(Error::InvalidData { what: "den", .. })
    ));
    let l = TransferFunction::continuous(&[1.0], &[1.0, 1.0]).unwrap();
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        let r = root_locus_at(&l, &[0.0, bad]);
        assert!(
            matches!(
                r,
                Err(Error::InvalidData {
                    what: "gains",
                    index: 1,
                    ..
                })
            ),
            "{r:?}"
        );
    }
    assert!(matches!(
        root_locus_at(&l, &[]),
        Err(Error::InvalidData { what: "gains", .. })
    ));
    // A biproper loop whose branch passes through infinity at k = 1.
    let through = TransferFunction::continuous(&[1.0, 2.0], &[-1.0, 1.0]).unwrap();
    assert!(matches!(
        root_locus_at(&through, &[1.0]),
        Err(Error::Singular { .. })
    ));
    // ...which the automatic grid steps over.
    let locus = root_locus(&through).unwrap();
    assert!(locus.branches[0].iter().all(|p| p.re.is_finite()));
    // Not SISO.
    let mimo = two_inputs();
    assert!(matches!(
        root_locus(&mimo),
        Err(Error::DimensionMismatch { .. })
    ));
    // Huge and tiny coefficients and gains: finite answers.
    let huge = TransferFunction::continuous(&[1e300], &[1.0, 1e-300, 1e-300]).unwrap();
    let locus = root_locus(&huge).unwrap();
    assert!(
        locus
            .branches
            .iter()
            .flatten()
            .all(|p| p.re.is_finite() && p.im.is_finite())
    );
    let r = root_locus_at(&l, &[1e300, -1e300, 0.0]).unwrap();
    assert!(r.branches.iter().flatten().all(|p| p.re.is_finite()));
}

/// `|D(p) + k N(p)|` relative to the size of its terms
/// (`Σ|dᵢ||p|ⁱ + |k| Σ|nᵢ||p|ⁱ`): the backward error of the pole.
fn residual(num: &[f64], den: &[f64], k: f64, p: Complex<f64>) -> f64 {
    let eval = |c: &[f64]| c.iter().fold(Complex::new(0.0, 0.0), |acc, &x| acc * p + x);
    let size = |c: &[f64]| c.iter().fold(0.0, |acc, &x| acc * p.norm() + x.abs());
    let (d, n) = (eval(den), eval(num));
    // Above |k| = 1 the polynomial is D / k + N: the same scaled.
    let (value, scale) = if k.abs() <= 1.0 {
        ((d + n * k).norm(), size(den) + k.abs() * size(num))
    } else {
        ((d / k + n).norm(), size(den) / k.abs() + size(num))
    };
    value / scale
}

fn poly_strategy(len: std::ops::RangeInclusive<usize>) -> impl Strategy<Value = Vec<f64>> {
    prop::collection::vec(prop_oneof![(-10.0f64..10.0), (0.1f64..5.0)], len)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    /// Every reported pole solves 1 + k L = 0 to rounding, there are as
    /// many branches as the order, and consecutive points of a branch are
    /// close compared with the region the locus spans.
    #[test]
    fn every_point_is_a_closed_loop_pole(
        den in poly_strategy(3..=6),
        num in poly_strategy(1..=3),
        lead in 0.5f64..3.0,
    ) {
        let mut den = den;
        den[0] = lead;
        prop_assume!(num[0].abs() > 1e-3);
        let l = TransferFunction::continuous(&num, &den).unwrap();
        let locus = root_locus(&l).unwrap();
        prop_assert_eq!(locus.branches.len(), den.len() - 1);
        for b in &locus.branches {
            prop_assert_eq!(b.len(), locus.gains.len());
            for (k, p) in locus.gains.iter().zip(b) {
                let r = residual(&num, &den, *k, *p);
                // Measured: at most 7.8e-15 over these cases.
                prop_assert!(r <= 1e-12, "k = {k}, p = {p}, residual {r:e}");
            }
        }
        prop_assert!(locus.gains.windows(2).all(|w| w[0] < w[1]));
        // Continuity: in the region the refinement works in (the poles,
        // zeros and special points), no branch jumps by more than a
        // quarter of the open-loop pattern's size between gains unless the
        // grid reached its narrowest interval there.
        let mut pts: Vec<Complex<f64>> = locus.poles.clone();
        pts.extend(&locus.zeros);
        let lo = pts.iter().map(|p| p.re).fold(f64::INFINITY, f64::min);
        let hi = pts.iter().map(|p| p.re).fold(f64::NEG_INFINITY, f64::max);
        let top = pts.iter().map(|p| p.im.abs()).fold(0.0, f64::max);
        let size = (hi - lo).max(top).max(1e-3);
        for b in &locus.branches {
            for j in 1..b.len() {
                let inside = |p: Complex<f64>| p.re >= lo && p.re <= hi && p.im.abs() <= top;
                if inside(b[j - 1]) && inside(b[j]) {
                    let (k0, k1) = (locus.gains[j - 1], locus.gains[j]);
                    let jump = (b[j] - b[j - 1]).norm();
                    prop_assert!(
                        jump <= 0.25 * size || k1 - k0 <= 1e-9 * k1,
                        "jump {jump} of {size} between k = {k0} and {k1}"
                    );
                }
            }
        }
    }
}

#[cfg(feature = "plot")]
#[test]
fn figures_name_what_a_student_reads_and_refuse_bad_input() {
    use ctrlab::freq::{pole_zero_svg, root_locus_svg, root_locus_zoomed_svg};
    use ctrlab::plot::PlotError;

    let dir = std::env::temp_dir().join("ctrlab_rlocus_figures");
    std::fs::create_dir_all(&dir).unwrap();
    let l = TransferFunction::continuous(&[1.0], &[1.0, 6.0, 11.0, 6.0]).unwrap();
    let locus = root_locus(&l).unwrap();
    let path = dir.join("third.svg");
    root_locus_svg(&path, "third order", &locus, &[("k = 20", 20.0)]).unwrap();
    let svg = std::fs::read_to_string(&path).unwrap();
    for text in [
        "k = 60.0, ω = 3.32 rad/s",
        "k = 0.385",
        "k = 20",
        "Re s (rad/s)",
        "asymptotes",
    ] {
        assert!(svg.contains(text), "{text} missing");
    }
    let bad = root_locus_svg(dir.join("nan.svg"), "t", &locus, &[("nan", f64::NAN)]);
    assert!(matches!(
        bad,
        Err(PlotError::Data(Error::InvalidParameter { name: "k", .. }))
    ));
    for (x, y) in [((1.0, 0.0), (0.0, 1.0)), ((0.0, 1.0), (f64::NAN, 1.0))] {
        let r = root_locus_zoomed_svg(dir.join("view.svg"), "t", &locus, &[], x, y);
        assert!(
            matches!(r, Err(PlotError::Data(Error::InvalidParameter { .. }))),
            "{r:?}"
        );
    }
    let d = TransferFunction::discrete(&[0.25], &[1.0, -1.5, 0.5], 0.1).unwrap();
    let path = dir.join("discrete.svg");
    root_locus_svg(&path, "discrete", &root_locus(&d).unwrap(), &[]).unwrap();
    let svg = std::fs::read_to_string(&path).unwrap();
    assert!(svg.contains("crosses the unit circle") && svg.contains("k = 2.00"));
    let pz = pole_zero_map(&d).unwrap();
    pole_zero_svg(dir.join("pz.svg"), "pz", &[("L", &pz)]).unwrap();
    assert!(matches!(
        pole_zero_svg(dir.join("none.svg"), "pz", &[]),
        Err(PlotError::Data(Error::InvalidData { what: "maps", .. }))
    ));
}
