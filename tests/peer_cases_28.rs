//! Issue 28's peer disagreements: python-control's own test cases on which
//! ctrlab answered differently, checked against python-control 0.10.2 /
//! SciPy 1.17.1 (`tests/data/peer_cases_28.json`, from
//! `tests/data/gen_peer_cases_28.py`) at the tolerances of python-control's
//! own tests, quoted at each check.

use ctrlab::freq::{BodeOptions, TransferFunction, WrapPhase, bode, bode_with, stability_margins};
use ctrlab::{Discretization, DynStateSpace};
use nalgebra::{Complex, DMatrix};
use serde_json::Value;

fn fixtures() -> Value {
    serde_json::from_str(include_str!("data/peer_cases_28.json")).unwrap()
}

fn floats(v: &Value) -> Vec<f64> {
    serde_json::from_value(v.clone()).unwrap()
}

fn complexes(v: &Value) -> Vec<Complex<f64>> {
    let pairs: Vec<[f64; 2]> = serde_json::from_value(v.clone()).unwrap();
    pairs.iter().map(|p| Complex::new(p[0], p[1])).collect()
}

fn matrix(v: &Value) -> DMatrix<f64> {
    let rows: Vec<Vec<f64>> = serde_json::from_value(v.clone()).unwrap();
    let (r, c) = (rows.len(), rows.first().map_or(0, Vec::len));
    DMatrix::from_fn(r, c, |i, j| rows[i][j])
}

fn rel(got: f64, want: f64) -> f64 {
    (got - want).abs() / want.abs()
}

/// `test_stability_margins_discrete`, case gh-523 b: python-control's
/// `assert_allclose(out, ref, rtol=1e-5)` on (gm, pm, wpc, wgc); ctrlab
/// has no stability margin `sm` (nor its frequency `wms`).
#[test]
fn discrete_margins_gh523b() {
    let f = &fixtures()["margins_gh523b"];
    let rtol = f["test_rtol"].as_f64().unwrap();
    assert_eq!(rtol, 1e-5);
    let dt = f["dt"].as_f64().unwrap();
    // ctrlab's own ZOH sampling of the continuous loop, and python-control's
    // sampled transfer function.
    let cont = TransferFunction::continuous(&floats(&f["cnum"]), &floats(&f["cden"])).unwrap();
    let sampled = cont
        .to_state_space()
        .unwrap()
        .discretize(dt, Discretization::Zoh)
        .unwrap();
    let ours = TransferFunction::from_state_space(&sampled).unwrap();
    let theirs = TransferFunction::discrete(&floats(&f["num"]), &floats(&f["den"]), dt).unwrap();
    for (route, l) in [("ctrlab c2d", ours), ("python-control sample", theirs)] {
        let m = stability_margins(&l).unwrap();
        let (gain, phase, delay) = (m.gain.unwrap(), m.phase.unwrap(), m.delay.unwrap());
        let got = [
            ("gm", gain.margin),
            ("pm", phase.margin),
            ("wpc", gain.frequency),
            ("wgc", phase.frequency),
        ];
        for (what, value) in got {
            let want = f["test_ref"][what].as_f64().unwrap();
            let e = rel(value, want);
            assert!(
                e <= rtol,
                "{route}: {what} {value} vs the test's {want} ({e:e})"
            );
            let pc = f["python_control"][what].as_f64().unwrap();
            assert!(
                rel(value, pc) <= rtol,
                "{route}: {what} {value} vs python-control's {pc}"
            );
        }
        // The crossing is one: |L| = 1 there, to the ~1e-9 to which this
        // ill-conditioned tf can be evaluated (it was 0.865).
        let at = l
            .evaluate(Complex::from_polar(1.0, phase.frequency * dt))
            .unwrap();
        assert!(
            (at.norm() - 1.0).abs() < 1e-8,
            "{route}: |L(wgc)| = {}",
            at.norm()
        );
        // The delay margin inherits the crossing (python-control has none:
        // pm / wgc from its crossing).
        let dm = f["python_control"]["dm"].as_f64().unwrap();
        assert!(
            rel(delay.margin, dm) <= rtol,
            "{route}: dm {} vs {dm}",
            delay.margin
        );
        println!("{route}: {m:?}");
    }
}

/// `test_tf2ss_unstable` (python-control issue #935): the poles of the
/// 16-state realisation against the transfer function's,
/// `assert_allclose(tf_poles, ss_poles, rtol=1e-4)` after sorting.
#[test]
fn tf2ss_unstable_poles() {
    let f = &fixtures()["tf2ss_unstable"];
    let rtol = f["rtol"].as_f64().unwrap();
    assert_eq!(rtol, 1e-4);
    let g = TransferFunction::continuous(&floats(&f["num"]), &floats(&f["den"])).unwrap();
    let sys = g.to_state_space().unwrap();
    assert_eq!(sys.states(), 16);
    // ctrlab's realisation is SciPy's.
    for (ours, key) in [
        (sys.a(), "a"),
        (sys.b(), "b"),
        (sys.c(), "c"),
        (sys.d(), "d"),
    ] {
        let want = matrix(&f[key]);
        let scale = want.amax().max(f64::MIN_POSITIVE);
        assert!((ours - &want).amax() <= 1e-15 * scale, "{key}");
    }
    // A model built from SciPy's matrices: the same poles.
    let scipy_sys = DynStateSpace::continuous(
        matrix(&f["a"]),
        matrix(&f["b"]),
        matrix(&f["c"]),
        matrix(&f["d"]),
    )
    .unwrap();
    let tf_poles = complexes(&f["tf_poles"]);
    let ss_poles = complexes(&f["ss_poles"]);
    for (what, got) in [
        // The transfer function's own: its companion matrix is as badly
        // scaled.
        ("tf poles", g.poles().unwrap()),
        ("ss poles", sys.poles().unwrap()),
        ("SciPy's ss poles", scipy_sys.poles().unwrap()),
    ] {
        assert!(got.iter().all(|p| p.re < 0.0), "{what}: {got:?}");
        for (want_name, want) in [("tf poles", &tf_poles), ("NumPy's ss poles", &ss_poles)] {
            // NumPy's sort: by real part, then imaginary.
            assert_eq!(got.len(), want.len());
            for (g, w) in got.iter().zip(want.iter()) {
                // assert_allclose: |actual - desired| <= rtol |desired|.
                assert!(
                    (g - w).norm() <= rtol * w.norm(),
                    "{what} vs {want_name}: {g} vs {w}"
                );
            }
        }
    }
}

fn options(case: &Value) -> BodeOptions {
    BodeOptions {
        initial_phase: case["initial_phase"].as_f64(),
        wrap_phase: match &case["wrap_phase"] {
            Value::Null => WrapPhase::Unwrap,
            Value::Bool(false) => WrapPhase::Unwrap,
            Value::Bool(true) => WrapPhase::Wrap,
            v => WrapPhase::AtLeast(v.as_f64().unwrap()),
        },
    }
}

/// `test_initial_phase` (`abs(phase[0] - expected) < 0.1`), `test_phase_wrap`
/// and `test_phase_wrap_multiple_systems` (`min(phase) >= min_phase`,
/// `max(phase) <= max_phase`), and python-control's phases themselves.
#[test]
fn bode_phase_conventions() {
    let f = &fixtures()["phase"];
    let omega = floats(&f["omega"]);
    let tol = f["initial_phase_tolerance"].as_f64().unwrap();
    for case in f["cases"].as_array().unwrap() {
        let name = case["name"].as_str().unwrap();
        let g = TransferFunction::continuous(&floats(&case["num"]), &floats(&case["den"])).unwrap();
        let b = bode_with(&g, &omega, &options(case)).unwrap();
        if let Some(expected) = case["expected"].as_f64() {
            assert!(
                (b.phase[0] - expected).abs() < tol,
                "{name}: {}",
                b.phase[0]
            );
        }
        if let (Some(lo), Some(hi)) = (case["min_phase"].as_f64(), case["max_phase"].as_f64()) {
            assert!(
                b.phase.iter().all(|&p| p >= lo && p <= hi),
                "{name}: {:?}",
                b.phase
            );
        }
        let want = floats(&case["phase"]);
        for (p, w) in b.phase.iter().zip(&want) {
            assert!(
                (p - w).abs() <= 1e-12 * w.abs().max(1.0),
                "{name}: {p} vs {w}"
            );
        }
    }
}

/// The crate's `bode` keeps its own start (the principal value at the
/// first frequency): 1/s³ at +90°, where python-control starts at −270°.
#[test]
fn bode_keeps_its_principal_value_start() {
    let g = TransferFunction::continuous(&[1.0], &[1.0, 0.0, 0.0, 0.0]).unwrap();
    let b = bode(&g, &[0.1, 1.0]).unwrap();
    assert!((b.phase[0] - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
    let d = bode_with(&g, &[0.1, 1.0], &BodeOptions::default()).unwrap();
    assert!((d.phase[0] + 1.5 * std::f64::consts::PI).abs() < 1e-12);
}

/// A static gain: no state, as python-control's `tf2ss`; SciPy's `tf2ss`
/// adds one (A = B = C = [[0]]), which the docs state.
#[test]
fn static_gain_realisation() {
    let f = &fixtures()["static_gain"];
    let g = TransferFunction::continuous(&floats(&f["num"]), &floats(&f["den"])).unwrap();
    let sys = g.to_state_space().unwrap();
    let pc = &f["python_control"];
    assert_eq!(sys.states() as u64, pc["states"].as_u64().unwrap());
    assert_eq!(sys.d(), &matrix(&pc["d"]));
    let scipy = &f["scipy"];
    assert_eq!(matrix(&scipy["a"]), DMatrix::zeros(1, 1));
    assert_eq!(sys.d(), &matrix(&scipy["d"]));
}
