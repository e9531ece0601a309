//! `ctrlab::freq` against python-control 0.10.2 / SciPy 1.17.1
//! (`tests/data/freq_fixtures.json`, from `gen_freq_fixtures.py`), and its
//! answers to bad input.

// Built on the two-cart lab (its plant, simulated rig or card).
#![cfg(feature = "lab")]

use ctrlab::freq::{
    FrequencyDomain, TransferFunction, TransferMatrix, Zpk, bandwidth, bode, logspace, nyquist,
    stability_margins,
};
use ctrlab::{Cart, Discrete, DynStateSpace, Error, MassSpring};
use nalgebra::{Complex, DMatrix};
use serde_json::Value;

mod common;

fn fixtures() -> Value {
    serde_json::from_str(include_str!("data/freq_fixtures.json")).unwrap()
}

fn matrix(v: &Value) -> DMatrix<f64> {
    let rows: Vec<Vec<f64>> = serde_json::from_value(v.clone()).unwrap();
    let (r, c) = (rows.len(), rows.first().map_or(0, Vec::len));
    DMatrix::from_fn(r, c, |i, j| rows[i][j])
}

fn floats(v: &Value) -> Vec<f64> {
    serde_json::from_value(v.clone()).unwrap()
}

fn complexes(v: &Value) -> Vec<Complex<f64>> {
    let pairs: Vec<[f64; 2]> = serde_json::from_value(v.clone()).unwrap();
    pairs.iter().map(|p| Complex::new(p[0], p[1])).collect()
}

/// A fixture's model, continuous or discrete.
enum Model {
    C(DynStateSpace),
    D(DynStateSpace<Discrete>),
}

fn model(case: &Value) -> Model {
    let (a, b, c, d) = (
        matrix(&case["a"]),
        matrix(&case["b"]),
        matrix(&case["c"]),
        matrix(&case["d"]),
    );
    match case["dt"].as_f64() {
        None => Model::C(DynStateSpace::continuous(a, b, c, d).unwrap()),
        Some(dt) => Model::D(DynStateSpace::discrete(a, b, c, d, dt).unwrap()),
    }
}

/// Largest distance from each wanted root to the nearest found one, over
/// the wanted roots' scale; the counts must match.
fn root_error(found: &[Complex<f64>], want: &[Complex<f64>]) -> f64 {
    assert_eq!(found.len(), want.len(), "{found:?} vs {want:?}");
    want.iter()
        .map(|w| {
            let d = found
                .iter()
                .map(|f| (f - w).norm())
                .fold(f64::INFINITY, f64::min);
            d / w.norm().max(1.0)
        })
        .fold(0.0, f64::max)
}

/// Relative error of `got` against `want`, both polynomials normalised by
/// the denominator's leading coefficient, aligned at the constant term,
/// over the largest coefficient.
fn poly_error(got: &[f64], got_lead: f64, want: &[f64], want_lead: f64) -> f64 {
    let n = got.len().max(want.len());
    let at = |p: &[f64], lead: f64, k: usize| {
        if k < p.len() {
            p[p.len() - 1 - k] / lead
        } else {
            0.0
        }
    };
    let scale = (0..n)
        .map(|k| at(want, want_lead, k).abs())
        .fold(0.0, f64::max);
    (0..n)
        .map(|k| (at(got, got_lead, k) - at(want, want_lead, k)).abs())
        .fold(0.0, f64::max)
        / scale
}

fn rel(got: f64, want: f64) -> f64 {
    (got - want).abs() / want.abs().max(1e-300)
}

#[test]
fn frequency_responses_match_python_control() {
    for case in fixtures()["cases"].as_array().unwrap() {
        let omega = floats(&case["omega"]);
        let r = match model(case) {
            Model::C(sys) => sys.frequency_response(&omega).unwrap(),
            Model::D(sys) => sys.frequency_response(&omega).unwrap(),
        };
        let mut worst: f64 = 0.0;
        for i in 0..r.outputs() {
            for j in 0..r.inputs() {
                let (re, im) = (floats(&case["re"][i][j]), floats(&case["im"][i][j]));
                for (k, g) in r.response(i, j).unwrap().iter().enumerate() {
                    let want = Complex::new(re[k], im[k]);
                    worst = worst.max((g - want).norm() / want.norm());
                }
            }
        }
        println!(
            "{}: frequency response, max relative error {worst:.1e}",
            case["name"]
        );
        // Both sides are exact up to rounding; the lab plant's resonances
        // (ζ ≈ 0.05) amplify it by about 1/ζ.
        assert!(worst < 1e-11, "{}: {worst:e}", case["name"]);
    }
}

#[test]
fn transfer_functions_zeros_and_zpk_match_python_control() {
    for case in fixtures()["cases"].as_array().unwrap() {
        let name = case["name"].as_str().unwrap();
        let (tf_err, pole_err, zpk) = match model(case) {
            Model::C(sys) if sys.inputs() == 1 => {
                let g = TransferFunction::from_state_space(&sys).unwrap();
                let z = Zpk::from_state_space(&sys).unwrap();
                let num = (g.num().to_vec(), g.den()[0]);
                (
                    num,
                    root_error(&g.poles().unwrap(), &complexes(&case["poles"])),
                    z.gain(),
                )
            }
            Model::D(sys) => {
                let g = TransferFunction::from_state_space(&sys).unwrap();
                let z = Zpk::from_state_space(&sys).unwrap();
                assert_eq!(g.dt(), sys.dt());
                let num = (g.num().to_vec(), g.den()[0]);
                (
                    num,
                    root_error(&g.poles().unwrap(), &complexes(&case["poles"])),
                    z.gain(),
                )
            }
            Model::C(sys) => {
                // MIMO: zeros only (square), poles of A.
                let z = sys.zeros().unwrap();
                let e = root_error(&z, &complexes(&case["zeros"]));
                println!("{name}: zeros {e:.1e}");
                assert!(e < 1e-12, "{name}: zeros {e:e}");
                let g = TransferMatrix::from_state_space(&sys).unwrap();
                let r = g.frequency_response(&floats(&case["omega"])).unwrap();
                let want = Complex::new(
                    case["re"][1][0][30].as_f64().unwrap(),
                    case["im"][1][0][30].as_f64().unwrap(),
                );
                assert!((r.response(1, 0).unwrap()[30] - want).norm() < 1e-12 * want.norm());
                continue;
            }
        };
        let (num, lead) = tf_err;
        let num_err = poly_error(&num, lead, &floats(&case["num"]), floats(&case["den"])[0]);
        let zeros = match model(case) {
            Model::C(sys) => sys.zeros().unwrap(),
            Model::D(sys) => sys.zeros().unwrap(),
        };
        let zero_err = root_error(&zeros, &complexes(&case["zeros"]));
        let gain_err = rel(zpk, case["zpk_gain"].as_f64().unwrap());
        println!(
            "{name}: numerator {num_err:.1e}, poles {pole_err:.1e}, zeros {zero_err:.1e}, zpk gain {gain_err:.1e}"
        );
        // SciPy's ss2tf forms det(A − B C) − det(A): its coefficients carry
        // rounding of the size of the largest term (1e-12 relative on the
        // lab plant); ctrlab's come from the zeros and are not worse.
        assert!(num_err < 1e-11, "{name}: numerator {num_err:e}");
        // The discrete case has a triple pole (ZOH of 2/(s + 1)³): a root
        // of multiplicity 3 moves by ε^(1/3) ≈ 6e-6 under rounding.
        let pole_tol = if name == "discrete" { 1e-5 } else { 1e-12 };
        assert!(pole_err < pole_tol, "{name}: poles {pole_err:e}");
        assert!(zero_err < 1e-10, "{name}: zeros {zero_err:e}");
        // SciPy's ZOH numerator (coefficients ~3e-4) is a difference of
        // determinants of size 1: its leading coefficient carries 3e-12
        // relative rounding, the bound the numerator check uses too.
        assert!(gain_err < 1e-11, "{name}: gain {gain_err:e}");
    }
}

#[test]
fn margins_and_bandwidth_match_python_control() {
    for case in fixtures()["cases"].as_array().unwrap() {
        let Some(m) = case.get("margins") else {
            continue;
        };
        let name = case["name"].as_str().unwrap();
        let k = m["loop_gain"].as_f64().unwrap();
        let scaled = |g_num: &[f64]| g_num.iter().map(|c| k * c).collect::<Vec<_>>();
        let (margins, bw) = match model(case) {
            Model::C(sys) => {
                let g = TransferFunction::from_state_space(&sys).unwrap();
                let l = TransferFunction::continuous(&scaled(g.num()), g.den()).unwrap();
                let bw = match bandwidth(&g, -3.0) {
                    Ok(bw) => bw,
                    // python-control: nan for an infinite DC gain.
                    Err(Error::Singular { .. }) => None,
                    Err(e) => panic!("{name}: {e}"),
                };
                (stability_margins(&l).unwrap(), Some(bw))
            }
            Model::D(sys) => {
                let g = TransferFunction::from_state_space(&sys).unwrap();
                let l = TransferFunction::discrete(&scaled(g.num()), g.den(), g.dt()).unwrap();
                (stability_margins(&l).unwrap(), None)
            }
        };
        // Against python-control's own values: its crossings are np.roots
        // of the crossing polynomials, whose roots near |z| = 1 carry
        // ~1e-9 relative (its "poly" and "frd" methods differ by 1.2e-9 on
        // the discrete case); hence 1e-8 there. Against the crossings
        // polished on the state-space loop ("refined"): 1e-12.
        let check =
            |what: &str, got: Option<f64>, want: &Value, tol: f64| match (got, want.as_f64()) {
                (None, None) => 0.0,
                (Some(g), Some(w)) => {
                    let e = rel(g, w);
                    assert!(e < tol, "{name}: {what} {g} vs {w} ({e:e})");
                    e
                }
                (g, w) => panic!("{name}: {what} {g:?} vs {w:?}"),
            };
        let got = [
            ("gm", margins.gain.map(|g| g.margin)),
            ("wpc", margins.gain.map(|g| g.frequency)),
            ("pm", margins.phase.map(|p| p.margin)),
            ("wgc", margins.phase.map(|p| p.frequency)),
            ("dm", margins.delay.map(|d| d.margin)),
        ];
        let mut worst = 0.0f64;
        let mut worst_refined = 0.0f64;
        for (what, value) in got {
            worst = worst.max(check(what, value, &m[what], 1e-8));
            let refined = &m["refined"][what];
            worst_refined = worst_refined.max(check(what, value, refined, 1e-12));
        }
        let bw_err = match (bw, case.get("bandwidth")) {
            (Some(got), Some(want)) => check("bandwidth", got, want, 1e-9),
            _ => 0.0,
        };
        println!(
            "{name}: margins max relative error {worst:.1e} (python-control), \
             {worst_refined:.1e} (refined), bandwidth {bw_err:.1e}"
        );
    }
}

#[test]
fn tf2ss_is_scipys_controllable_canonical_form() {
    let f = &fixtures()["tf2ss"];
    let g = TransferFunction::continuous(&floats(&f["num"]), &floats(&f["den"])).unwrap();
    let sys = g.to_state_space().unwrap();
    for (got, want) in [
        (sys.a(), "a"),
        (sys.b(), "b"),
        (sys.c(), "c"),
        (sys.d(), "d"),
    ] {
        let want = matrix(&f[want]);
        assert!((got - &want).amax() < 1e-15, "{got} vs {want}");
    }
}

#[test]
fn the_state_space_and_transfer_function_responses_agree_on_the_lab_plant() {
    let plant = MassSpring::nominal().state_space(Cart::Two).unwrap();
    let w = logspace(0.0, 3.0, 200).unwrap();
    let a = bode(&plant, &w).unwrap();
    let g = TransferFunction::try_from(&plant).unwrap();
    let b = bode(&g, &w).unwrap();
    let z = bode(&Zpk::try_from(&plant).unwrap(), &w).unwrap();
    let back = bode(&g.to_state_space().unwrap(), &w).unwrap();
    for k in 0..w.len() {
        for other in [&b, &z, &back] {
            assert!(rel(other.magnitude[k], a.magnitude[k]) < 1e-9, "{k}");
            assert!((other.phase[k] - a.phase[k]).abs() < 1e-9, "{k}");
        }
    }
    // Resonance (−180°), anti-resonance (back to 0°), resonance: the phase
    // ends near −180° (relative degree 2) with no wrapping jump on the way.
    let p = a.phase_deg();
    assert!(
        (p.last().unwrap() + 180.0).abs() < 10.0,
        "{}",
        p.last().unwrap()
    );
    assert!(p.windows(2).all(|w| (w[1] - w[0]).abs() < 90.0));
}

#[test]
fn bad_input_gives_typed_errors() {
    let g = TransferFunction::continuous(&[1.0], &[1.0, 1.0]).unwrap();
    assert!(matches!(
        g.frequency_response(&[1.0, f64::NAN]),
        Err(Error::InvalidData {
            what: "omega",
            index: 1,
            ..
        })
    ));
    assert!(matches!(
        g.frequency_response(&[f64::INFINITY]),
        Err(Error::InvalidData { what: "omega", .. })
    ));
    assert!(matches!(
        TransferFunction::continuous(&[], &[1.0]),
        Err(Error::InvalidData { what: "num", .. })
    ));
    assert!(matches!(
        TransferFunction::continuous(&[1.0], &[]),
        Err(Error::InvalidData { what: "den", .. })
    ));
    assert!(matches!(
        TransferFunction::continuous(&[1.0], &[0.0, 0.0, 0.0]),
        Err(Error::InvalidData { what: "den", .. })
    ));
    assert!(matches!(
        TransferFunction::continuous(&[1.0], &[1.0, f64::INFINITY]),
        Err(Error::InvalidData {
            what: "den",
            index: 1,
            ..
        })
    ));
    // Leading zeros are dropped, not taken as degree.
    let lz = TransferFunction::continuous(&[0.0, 0.0, 1.0], &[0.0, 1.0, 2.0]).unwrap();
    assert_eq!((lz.num(), lz.den()), (&[1.0][..], &[1.0, 2.0][..]));
    assert_eq!(lz.to_state_space().unwrap().states(), 1);
    // Improper: evaluable, no realisation, no discrete margins trouble.
    let improper = TransferFunction::continuous(&[1.0, 0.0, 0.0], &[1.0, 1.0]).unwrap();
    assert!(improper.evaluate(Complex::new(0.0, 1.0)).is_ok());
    assert!(matches!(
        improper.to_state_space(),
        Err(Error::InvalidData { what: "num", .. })
    ));
    assert!(stability_margins(&improper).is_ok());
    // A static gain: a 0-state realisation, no crossings for |G| ≠ 1.
    let k = TransferFunction::continuous(&[2.0], &[1.0]).unwrap();
    assert_eq!(k.to_state_space().unwrap().states(), 0);
    let m = stability_margins(&k).unwrap();
    assert!(m.gain.is_none() && m.phase.is_none());
    let one = TransferFunction::continuous(&[1.0], &[1.0]).unwrap();
    assert!(stability_margins(&one).unwrap().phase.is_none());
    // A pole exactly on the grid.
    let integrator = TransferFunction::continuous(&[1.0], &[1.0, 0.0]).unwrap();
    assert!(matches!(
        integrator.frequency_response(&[0.0]),
        Err(Error::Singular { .. })
    ));
    let ss = integrator.to_state_space().unwrap();
    assert!(matches!(
        ss.frequency_response(&[0.0]),
        Err(Error::Singular { .. })
    ));
    assert!(matches!(
        bandwidth(&integrator, -3.0),
        Err(Error::Singular { .. })
    ));
    assert!(bandwidth(&g, f64::NAN).is_err());
    // Channels and shapes.
    let r = g.frequency_response(&[1.0]).unwrap();
    assert!(matches!(
        r.bode(0, 1),
        Err(Error::OutOfRange { what: "input", .. })
    ));
    let mimo = common::two_inputs();
    assert!(matches!(
        bode(&mimo, &[1.0]),
        Err(Error::DimensionMismatch { .. })
    ));
    assert!(matches!(
        nyquist(&mimo, &[1.0]),
        Err(Error::DimensionMismatch { .. })
    ));
    assert!(matches!(
        mimo.zeros(),
        Err(Error::InvalidMatrix { matrix: "D", .. })
    ));
    assert!(matches!(
        TransferFunction::from_state_space(&mimo),
        Err(Error::DimensionMismatch { .. })
    ));
    assert!(TransferMatrix::from_state_space(&mimo).is_ok());
    // Roots.
    assert!(Zpk::continuous(&[Complex::new(f64::NAN, 0.0)], &[], 1.0).is_err());
    assert!(Zpk::continuous(&[], &[], f64::INFINITY).is_err());
    assert!(g.evaluate(Complex::new(f64::NAN, 0.0)).is_err());
    assert!(logspace(400.0, 1.0, 3).is_err());
    assert_eq!(logspace(0.0, 1.0, 0).unwrap(), Vec::<f64>::new());
    // Huge but finite: Ok only with finite numbers.
    let huge = TransferFunction::continuous(&[1e300], &[1e-300, 1.0]).unwrap();
    match huge.frequency_response(&logspace(-3.0, 3.0, 7).unwrap()) {
        Ok(r) => assert!(
            r.response(0, 0)
                .unwrap()
                .iter()
                .all(|g| g.re.is_finite() && g.im.is_finite())
        ),
        Err(e) => assert!(matches!(e, Error::Overflow { .. }), "{e}"),
    }
}

#[test]
fn a_discrete_phase_crossover_at_the_nyquist_frequency_counts() {
    // L = 0.5 / (z − 1), dt = 0.01 s: real and negative only at z = −1,
    // where L = −0.25 (python-control drops z = −1 and reports no margin).
    let l = TransferFunction::discrete(&[0.5], &[1.0, -1.0], 0.01).unwrap();
    let gm = stability_margins(&l).unwrap().gain.unwrap();
    assert!((gm.margin - 4.0).abs() < 1e-12, "{gm:?}");
    assert!(
        (gm.frequency - std::f64::consts::PI / 0.01).abs() < 1e-9,
        "{gm:?}"
    );
}
