//! lab5's identification sections on the default simulated rig, run as
//! lab5 runs them and asserted on the library's typed results: Tables 3
//! and 4 and the model's uncertainty (`lab::ident::summarize`), the
//! equal-springs run (`EqualSprings`), the inputs compared
//! (`lab::excitation`), the models on a fresh run and refined
//! (`lab::validation`), and the frequency response (`lab::frequency`).

// Built on the two-cart lab (its plant, simulated rig or card).
#![cfg(feature = "lab")]

mod common;

use std::sync::OnceLock;

use common::open_loop;
use ctrlab::Recording;
use ctrlab::lab::excitation::{self, Estimates, Input};
use ctrlab::lab::frequency::{self, DURATION};
use ctrlab::lab::ident::{
    EqualSprings, Parameter, SEPARATE_SPRINGS, Summary, identify_with, summarize,
};
use ctrlab::lab::ident_input::{AmplitudeSearch, IdentInput, PROBE_DURATION, ProbeFault, peaks};
use ctrlab::lab::protocol::{
    IDENT_DURATION, IDENT_HALF_PERIOD, IDENT_RUNS, IDENT_VOLTS, M1, M2, PERIOD,
};
use ctrlab::lab::validation::{ModelKind, validate_models};
use ctrlab::lab::{CardSettings, SimulatedRig, lqi};
use ctrlab::signal::{Signal, SquareWave};

/// The default simulated rig with noise `seed`, at the lab's period.
fn rig(seed: u64) -> SimulatedRig {
    SimulatedRig {
        card: CardSettings {
            seed,
            ..CardSettings::default()
        },
        period: PERIOD,
        ..SimulatedRig::default()
    }
}

/// The identification amplitude lab5 chooses on the default rig (probes
/// on seeds 101 and 102, `lab::ident_input`): 7.64 V, not the 8 V asked
/// for, which would take cart 2 past 60 % of its travel.
fn volts() -> f64 {
    static VOLTS: OnceLock<f64> = OnceLock::new();
    *VOLTS.get_or_init(|| {
        let ident = IdentInput::default();
        let mut n = 0;
        AmplitudeSearch::new(
            ident.volts,
            SimulatedRig::default().calibration.travel_limits,
        )
        .unwrap()
        .run(|v| {
            n += 1;
            let input = ident.input(v, IDENT_DURATION).unwrap();
            Ok::<_, ProbeFault>(peaks(&open_loop(&rig(100 + n), &input, PROBE_DURATION)).unwrap())
        })
        .unwrap()
        .volts
    })
}

/// lab5's identification square wave, at [`volts`].
fn ident_square_wave() -> Result<SquareWave, ctrlab::Error> {
    SquareWave::new(volts(), IDENT_HALF_PERIOD)
}

/// lab5's identification runs: the square wave on seeds 1 to 5.
fn runs() -> &'static [Recording] {
    static RUNS: OnceLock<Vec<Recording>> = OnceLock::new();
    RUNS.get_or_init(|| {
        let wave = ident_square_wave().unwrap();
        (1..=IDENT_RUNS)
            .map(|seed| open_loop(&rig(seed), &wave, IDENT_DURATION))
            .collect()
    })
}

fn summary() -> &'static Summary {
    static SUMMARY: OnceLock<Summary> = OnceLock::new();
    SUMMARY.get_or_init(|| summarize(runs(), M1, M2).unwrap())
}

/// Relative error.
fn rel(got: f64, want: f64) -> f64 {
    (got / want - 1.0).abs()
}

#[test]
fn tables_3_and_4_identify_the_simulated_card() {
    let s = summary();
    let truth = SimulatedRig::default_truth();
    assert_eq!((s.lab.len(), s.central.len(), s.separate.len()), (5, 5, 5));
    assert_eq!(s.average.runs, 5);
    // Separate springs with Coulomb friction: measured within 0.25 % (K
    // +0.23 %, the PWM delay's bias; F2 +1.3 %).
    let m = s.model();
    for (got, want) in [
        (m.k1, truth.k1),
        (m.k2, truth.k2),
        (m.gain, truth.gain),
        (m.b2, truth.b2),
    ] {
        assert!(rel(got, want) < 0.005, "{got} against {want}");
    }
    let [f1, f2] = s.coulomb();
    assert!(rel(f1, 1.0) < 0.05 && rel(f2, 2.0) < 0.05, "{f1} {f2}");
    // The lab's equal-springs model is wrong for this card: its K is off by
    // 17 % (Lab) and 15 % (Central).
    assert!(rel(s.lab_average.gain.mean, truth.gain) > 0.1);
    assert!(rel(s.central_average.gain.mean, truth.gain) > 0.1);
}

#[test]
fn every_parameter_has_its_uncertainty_beside_the_spread() {
    let sim = SimulatedRig::default();
    let rows = summary().uncertainty(Some(&sim.plant()));
    let names: Vec<Parameter> = rows.iter().map(|u| u.parameter).collect();
    assert_eq!(names, Parameter::ALL);
    for u in &rows {
        // Measured 0.7 to 1.7: Newey–West errors match the spread; with
        // five runs the spread itself is ±35 %.
        assert!((0.3..3.5).contains(&u.ratio()), "{u:?}");
        assert!(u.std_error_of_mean() > 0.0 && u.bias().is_some_and(f64::is_finite));
    }
    assert!((summary().spread_uncertainty() - 0.3536).abs() < 1e-4);
}

#[test]
fn the_equal_springs_run_isolates_the_schemes_own_bias() {
    let card = EqualSprings::card(&rig(99));
    let rec = open_loop(&card, &ident_square_wave().unwrap(), IDENT_DURATION);
    let e = EqualSprings::identify(&rec, card.truth, M1, M2).unwrap();
    // Measured: Lab K −1.8 %, Central +0.1 %.
    assert!(
        rel(e.lab.gain.value, e.truth.gain) > 0.01,
        "{:?}",
        e.lab.gain
    );
    assert!(
        rel(e.central.gain.value, e.truth.gain) < 0.005,
        "{:?}",
        e.central.gain
    );
    assert!(rel(e.central.k1().value, e.truth.k1) < 0.005);
}

/// The first PRBS run: the Validation section's fresh run.
fn fresh() -> &'static Recording {
    static FRESH: OnceLock<Recording> = OnceLock::new();
    FRESH.get_or_init(|| {
        let [_, prbs, ..] = excitation::inputs(volts(), IDENT_DURATION, IDENT_HALF_PERIOD).unwrap();
        open_loop(&rig(1), &prbs, IDENT_DURATION)
    })
}

#[test]
fn every_input_identifies_the_card_within_5_percent() {
    let sim = SimulatedRig::default();
    let truth = sim.plant();
    let inputs = excitation::inputs(volts(), IDENT_DURATION, IDENT_HALF_PERIOD).unwrap();
    let mut results = Vec::new();
    for input in inputs {
        let estimates: Vec<_> = (1..=IDENT_RUNS)
            .map(|seed| {
                let rec = open_loop(&rig(seed), &input, IDENT_DURATION);
                identify_with(&rec, M1, M2, &SEPARATE_SPRINGS).unwrap()
            })
            .collect();
        let e = Estimates::of(&estimates, Some(&truth)).unwrap();
        // Measured: worst 3.6 % (the multisine's b2: the least power at
        // low frequency).
        let worst = e.worst_percent().unwrap();
        assert!(worst < 5.0, "{input:?}: {worst} %");
        assert!(input.peak(PERIOD, IDENT_DURATION) <= volts() + 1e-9);
        results.push(excitation::InputResult {
            rms: input.rms(PERIOD, IDENT_DURATION),
            input,
            outcome: Ok(e),
        });
    }
    // The square wave has the most power at one peak: RMS 8 V.
    assert!((results[0].rms - volts()).abs() < 1e-9);
    let (best, worst) = excitation::best(&results).unwrap();
    assert!(worst < 2.0, "{best:?}: {worst}");
    assert!(!matches!(best.input, Input::Multisine(_)));
}

#[test]
fn the_refined_model_reproduces_a_fresh_run_and_the_truth() {
    let sim = SimulatedRig::default();
    let truth = sim.plant();
    let runs: Vec<&Recording> = runs().iter().collect();
    let v = validate_models(
        summary(),
        &runs,
        fresh(),
        Some(&truth),
        &sim.simulation_model(),
    )
    .unwrap();
    let kinds: Vec<ModelKind> = v.models.iter().map(|m| m.kind).collect();
    assert_eq!(
        kinds,
        [
            ModelKind::LabFormulas,
            ModelKind::LeastSquares,
            ModelKind::Refined,
            ModelKind::Truth
        ]
    );
    let fit = |k| v.model(k).unwrap().validation.as_ref().unwrap().fit_percent;
    // Measured: the lab's formulas 83.5 / 84.5 %, the refined model
    // 99.95 / 99.97 %, as the truth.
    assert!(
        fit(ModelKind::Refined)[1] > 99.5,
        "{:?}",
        fit(ModelKind::Refined)
    );
    assert!(fit(ModelKind::Refined)[1] > fit(ModelKind::LabFormulas)[1] + 10.0);
    assert!(fit(ModelKind::Refined)[0] > fit(ModelKind::LeastSquares)[0]);
    assert!((v.bound - 2.58 / 50.0).abs() < 1e-12); // 2500 samples
    // Every run refined: means within 0.15 % of the truth, the bootstrap's
    // errors as the spread (0.0005 N/V on K).
    let spread = v.spread.expect("five runs refined");
    assert_eq!(spread.runs, 5);
    let want = Parameter::ALL.map(|p| p.of(&truth.truth(), truth.friction()));
    for (i, p) in Parameter::ALL.iter().enumerate() {
        let bound = if i < 5 { 0.01 } else { 0.1 };
        assert!(
            rel(spread.spread[i].mean, want[i]) < bound,
            "{p:?}: {spread:?}"
        );
        assert!(rel(spread.first[i], want[i]) < bound, "{p:?}: {spread:?}");
        let se = spread.std_errors[i];
        assert!(se > 0.0 && se < bound * want[i], "{p:?}: {se}");
    }
}

#[test]
fn the_frequency_response_shows_both_modes_on_model_and_rig() {
    let sim = SimulatedRig::default();
    let ms = frequency::multisine(IDENT_VOLTS).unwrap();
    let rec = open_loop(&rig(1), &ms, DURATION);
    let s = summary();
    let model = lqi::predicted_rig(s.model(), s.coulomb(), &sim.calibration, PERIOD);
    let r = frequency::frequency_response(&rec, &model, Some(&sim.truth), &ms).unwrap();
    // The default rig's modes are 3.25 and 8.05 Hz; the measured gain
    // peaks sit within a few lines of them (friction lowers the first:
    // 2.68 Hz measured), and the identified model with friction puts its
    // peaks where the rig does.
    for (m, nominal) in r.modes.iter().zip([3.0, 8.0]) {
        let (model, measured, simulated) = (
            m.model_hz.unwrap(),
            m.measured_hz.unwrap(),
            m.simulated_hz.unwrap(),
        );
        assert!(rel(model, nominal) < 0.15, "{m:?}");
        assert!(rel(measured, model) < 0.25, "{m:?}");
        assert!((simulated - measured).abs() <= 0.25, "{m:?}");
        assert!(rel(m.truth_hz.unwrap(), model) < 0.01, "{m:?}");
    }
    // The model with friction within 5 % of the measured response at the
    // median frequency (measured 0.2 %), the linear model far off (22 %).
    assert!(r.gap_friction < 0.05, "{}", r.gap_friction);
    assert!(r.gap_linear > 2.0 * r.gap_friction);
    assert_eq!(r.smoothed.omega.len(), frequency::GRID_POINTS);
    assert!(r.truth.is_some() && !r.measured.omega.is_empty());
    assert!(ms.value(0.0).is_finite());
}
