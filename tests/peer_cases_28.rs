//! Issue 28's peer disagreements: python-control's own test cases on which
//! ctrlab answered differently, checked against python-control 0.10.2 /
//! SciPy 1.17.1 (`tests/data/peer_cases_28.json`, from
//! `tests/data/gen_peer_cases_28.py`) at the tolerances of python-control's
//! own tests, quoted at each check.

use ctrlab::Discretization;
use ctrlab::freq::{TransferFunction, stability_margins};
use nalgebra::Complex;
use serde_json::Value;

fn fixtures() -> Value {
    serde_json::from_str(include_str!("data/peer_cases_28.json")).unwrap()
}

fn floats(v: &Value) -> Vec<f64> {
    serde_json::from_value(v.clone()).unwrap()
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
