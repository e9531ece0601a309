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
use ctrlab::lab::{CardSettings, FrictionPlant, SimulatedRig, lqi};
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
/// on seeds 101 and 102, `lab::ident_input`): the 8 V asked for, which
/// keeps cart 2 within 60 % of its travel with the unmodelled effects on
/// (the deadband and the rotor; 7.64 V without them).
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

/// The card's truth as lab5's report judges the identification against
/// it: cart 2's effective mass (with the rotor) and the nominal friction,
/// the mean of the runs' draws.
fn truth_plant() -> FrictionPlant {
    let sim = SimulatedRig::default();
    FrictionPlant::new(sim.effective_truth(), sim.friction.coulomb)
        .with_stiction(sim.friction.stiction)
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
    // Separate springs with Coulomb friction, against the card's truth with
    // its unmodelled effects on (rotor 0.06 kg on cart 2 while m2 = 0.7 kg
    // is given, 0.3 V deadband, ±15 % friction along the rail, σ = 5 %
    // friction per run). Measured over six sets of five runs (seeds 1–5 to
    // 26–30, `lab_unmodelled::scan_identification_on_the_default_rig`, 8 V):
    // k1 −0.05 to +0.01 %, k2 −0.10 to 0.00 %: recovered (cart 1's
    // equation holds no rotor and no drive). K −2.62 to −2.27 % and b2
    // +3.71 to +4.84 %: biased by the deadband (K·0.3 V·sign(u) looks like
    // a smaller K at a constant |u| = 8 V, −3.75 %) and the rotor's mass the
    // fixed m2 leaves out. The bounds keep the springs at 0.3 % and put K
    // and b2 in bands about 0.5 % wider than the scan's.
    let m = s.model();
    for (got, want) in [(m.k1, truth.k1), (m.k2, truth.k2)] {
        assert!(rel(got, want) < 0.003, "{got} against {want}");
    }
    let k = 100.0 * (m.gain / truth.gain - 1.0);
    assert!((-3.2..-1.7).contains(&k), "K {k} %");
    let b2 = 100.0 * (m.b2 / truth.b2 - 1.0);
    assert!((3.0..5.5).contains(&b2), "b2 {b2} %");
    // The Coulomb forces against their nominal 1 N and 2 N: measured F1
    // −1.4 to +6.8 % (+6.8 % on seeds 1–5, whose draws average +1.8 %),
    // F2 −3.0 to +2.2 %: the per-run draw (σ = 5 %, 2.2 % on a mean of
    // five) and the friction along the rail. Bound 10 %.
    let [f1, f2] = s.coulomb();
    assert!(rel(f1, 1.0) < 0.1 && rel(f2, 2.0) < 0.1, "{f1} {f2}");
    // The lab's equal-springs model is wrong for this card: its K is off by
    // 20.4 to 21.2 % (Lab) and 18.1 to 18.7 % (Central) in the scan.
    assert!(rel(s.lab_average.gain.mean, truth.gain) > 0.1);
    assert!(rel(s.central_average.gain.mean, truth.gain) > 0.1);
}

#[test]
fn every_parameter_has_its_uncertainty_beside_the_spread() {
    let rows = summary().uncertainty(Some(&truth_plant()));
    let names: Vec<Parameter> = rows.iter().map(|u| u.parameter).collect();
    assert_eq!(names, Parameter::ALL);
    for u in &rows {
        // Measured 1.05 to 2.16 for k1, k2, b1, b2, K: Newey–West errors
        // match the spread; with five runs the spread itself is ±35 %. The
        // Coulomb forces vary from run to run (σ = 5 %), which no run's own
        // standard error sees: F2's spread is 0.109 N against a standard
        // error of 0.025 N, ratio 0.23 (F1 1.83 on these seeds). Their
        // lower bound is 0.1.
        let low = if matches!(u.parameter, Parameter::F1 | Parameter::F2) {
            0.1
        } else {
            0.3
        };
        assert!((low..3.5).contains(&u.ratio()), "{u:?}");
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
fn every_input_identifies_the_card_and_the_square_wave_best() {
    let truth = truth_plant();
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
        // Measured on seeds 1–5 with the unmodelled effects on (each
        // input's worst parameter against the truth, nominal friction):
        // square 6.8 % (F1; K −2.6 %), PRBS 14.8 % (b2; K −10.0 %),
        // multisine 21.0 % (b2; K −12.4 %), chirp 8.3 % (F1; K −5.3 %).
        // Without them it was 3.6 % at worst. The deadband's bias depends on
        // the input: a constant |u| (square wave) turns it into a smaller
        // K; inputs that dwell near zero (PRBS through the carts' lag,
        // multisine, chirp) lose more of their force to it, which the fit
        // spreads over K and b2. Not recovered; bound 25 %.
        let worst = e.worst_percent().unwrap();
        assert!(worst < 25.0, "{input:?}: {worst} %");
        assert!(input.peak(PERIOD, IDENT_DURATION) <= volts() + 1e-9);
        results.push(excitation::InputResult {
            rms: input.rms(PERIOD, IDENT_DURATION),
            input,
            outcome: Ok(e),
        });
    }
    // The square wave has the most power at one peak: RMS 8 V.
    assert!((results[0].rms - volts()).abs() < 1e-9);
    // The square wave is best: 6.8 % measured (F1 against its nominal
    // 1 N; seeds 1–5 draw +1.8 % on average), bound 8 %.
    let (best, worst) = excitation::best(&results).unwrap();
    assert!(worst < 8.0, "{best:?}: {worst}");
    assert!(matches!(best.input, Input::Square(_)), "{best:?}");
    assert!(!matches!(best.input, Input::Multisine(_)));
}

#[test]
fn the_refined_model_reproduces_a_fresh_run_and_the_truth() {
    let sim = SimulatedRig::default();
    let truth = truth_plant();
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
    // Measured on the fresh run (seed 6) with the unmodelled effects on:
    // the lab's formulas 83.0 / 83.9 %, least squares 93.1 / 93.4 %, the
    // refined model 96.3 / 95.3 %, the truth itself (simulated without the
    // deadband, ripple and per-run draw) 96.1 / 96.1 %: what the model
    // lacks caps every fit near 96 % (99.95 % before). Bounds 94.5 % and
    // 8 points over the lab's formulas (measured 11.4).
    assert!(
        fit(ModelKind::Refined)[1] > 94.5,
        "{:?}",
        fit(ModelKind::Refined)
    );
    assert!(fit(ModelKind::Refined)[1] > fit(ModelKind::LabFormulas)[1] + 8.0);
    assert!(fit(ModelKind::Refined)[0] > fit(ModelKind::LeastSquares)[0]);
    assert!((v.bound - 2.58 / 50.0).abs() < 1e-12); // 2500 samples
    // Every run refined. The refinement fits the output with m2 = 0.7 kg
    // given and no deadband, so its parameters move to make up for them:
    // measured means k1 −2.2 %, k2 −5.4 %, b1 −12.7 %, b2 +5.5 %,
    // K −8.0 %, F1 +41 %, F2 −19 % against the truth (before: within
    // 0.15 %). Not recovered: an equally good output fit with other
    // parameters. Bounds 15 % (linear) and 50 % (Coulomb), the first run
    // likewise; the bootstrap's errors stay below them.
    let spread = v.spread.expect("five runs refined");
    assert_eq!(spread.runs, 5);
    let want = Parameter::ALL.map(|p| p.of(&truth.truth(), truth.friction()));
    for (i, p) in Parameter::ALL.iter().enumerate() {
        let bound = if i < 5 { 0.15 } else { 0.5 };
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
    let truth = sim.effective_truth();
    let r = frequency::frequency_response(&rec, &model, Some(&truth), &ms).unwrap();
    // The default rig's modes are 3.18 and 7.89 Hz (3.25 and 8.05 without
    // the rotor); the measured gain peaks sit within a few lines of them
    // (friction lowers the first: 2.71 Hz measured), and the identified
    // model with friction puts its
    // peaks where the rig does.
    for (m, nominal) in r.modes.iter().zip([3.0, 8.0]) {
        let (model, measured, simulated) = (
            m.model_hz.unwrap(),
            m.measured_hz.unwrap(),
            m.simulated_hz.unwrap(),
        );
        assert!(rel(model, nominal) < 0.15, "{m:?}");
        assert!(rel(measured, model) < 0.25, "{m:?}");
        // The identified model (m2 = 0.7 kg given, the rotor's 0.06 kg left
        // out) puts the second mode at 8.45 Hz where the rig measures
        // 7.92 Hz (first mode 2.68 against 2.71 Hz); 0.25 Hz before the
        // unmodelled effects. Bound 0.75 Hz.
        assert!((simulated - measured).abs() <= 0.75, "{m:?}");
        // The truth's modes (cart 2 with the rotor, 0.76 kg) are 3.18 and
        // 7.89 Hz, the model's (0.7 kg given) 3.25 and 8.04 Hz: 2.1 % and
        // 1.9 % high, the rotor's mass not recovered (0.01 % before).
        // Bound 3 %.
        assert!(rel(m.truth_hz.unwrap(), model) < 0.03, "{m:?}");
    }
    // The model with friction within 5 % of the measured response at the
    // median frequency (measured 0.2 %), the linear model far off (22 %).
    assert!(r.gap_friction < 0.05, "{}", r.gap_friction);
    assert!(r.gap_linear > 2.0 * r.gap_friction);
    assert_eq!(r.smoothed.omega.len(), frequency::GRID_POINTS);
    assert!(r.truth.is_some() && !r.measured.omega.is_empty());
    assert!(ms.value(0.0).is_finite());
}
