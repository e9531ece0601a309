//! The sections that put the identified models to the test: Excitation
//! (which input identifies best), Validation (the models on a fresh run,
//! refined) and Frequency response (the measured response against the
//! model).

use ctrlab::freq::Bode;
use ctrlab::lab::FrictionPlant;
use ctrlab::lab::excitation::{CHIRP_BAND, Failure, Input, InputResult, MULTISINE_LINES, best};
use ctrlab::lab::frequency::{MS_PERIOD, PERIODS, SPA_WINDOW};
use ctrlab::lab::ident::{Parameter, SimulationModel, Validation};
use ctrlab::lab::protocol::{IDENT_DURATION, IDENT_RUNS, IDENT_VOLTS};
use ctrlab::lab::validation::{ModelCheck, ModelKind, Validated};

use super::Report;
use super::ident::{digits, header};
use crate::frequency::Frequency;

/// The excitation table's columns: k1, k2, K, b1, b2, F1, F2.
const EXCITATION_COLUMNS: [Parameter; 7] = [
    Parameter::K1,
    Parameter::K2,
    Parameter::Gain,
    Parameter::B1,
    Parameter::B2,
    Parameter::F1,
    Parameter::F2,
];

/// An input's name and settings.
fn input_name(input: &Input) -> (&'static str, String) {
    match input {
        Input::Square(s) => (
            "square wave (the lab's)",
            format!("±{} V, {} s half period", s.amplitude(), s.half_period()),
        ),
        Input::Prbs(p) => (
            "PRBS",
            format!(
                "±{} V, {} bits, {} ms clock",
                p.amplitude(),
                p.order(),
                p.clock() * 1e3
            ),
        ),
        Input::Multisine(m) => (
            "multisine",
            format!(
                "{:.2} V per line on {}–{} Hz ({} lines), Schroeder phases, crest {:.2}",
                m.amplitude(),
                f64::from(*MULTISINE_LINES.start()) / IDENT_DURATION,
                f64::from(*MULTISINE_LINES.end()) / IDENT_DURATION,
                m.harmonics().len(),
                m.crest_factor()
            ),
        ),
        Input::Chirp(c) => (
            "chirp",
            format!(
                "{} V, {} → {} Hz logarithmic",
                c.amplitude(),
                CHIRP_BAND.0,
                CHIRP_BAND.1
            ),
        ),
    }
}

/// A validated model's name in the table.
fn model_name(kind: ModelKind) -> &'static str {
    match kind {
        ModelKind::LabFormulas => "lab's formulas (equal springs, no Coulomb)",
        ModelKind::LeastSquares => "least squares (separate, Coulomb)",
        ModelKind::Refined => "refined by output error",
        ModelKind::Truth => "**the simulated card's truth**",
    }
}

/// A validated model's row.
fn model_row(m: &ModelCheck, v: &Validation) -> Vec<String> {
    let mut row = vec![model_name(m.kind).to_string()];
    row.extend(Parameter::ALL.map(|p| {
        let d = digits(p);
        format!("{:.d$}", p.of(&m.plant, m.coulomb))
    }));
    row.extend([
        format!("{:.2}", v.fit_percent[0]),
        format!("{:.2}", v.fit_percent[1]),
        format!("{:.3}", v.whiteness.max_correlation),
        format!("{:.3}", v.independence.max_correlation),
    ]);
    row
}

impl Report {
    /// The Excitation section: every input's estimates against the truth
    /// (simulated rig) or each other.
    pub fn excitation(&mut self, volts: f64, results: &[InputResult]) {
        self.heading(2, "Excitation: which input identifies best");
        self.add(&format!(
            "The same identification (separate springs, Coulomb friction, Central scheme) from four inputs of the same peak ({volts:.2} V, the identification's) and length ({IDENT_DURATION} s), {IDENT_RUNS} runs each (recordings in `runs/excite_{{square,prbs,multisine,chirp}}_{volts:.2}V_seed*.csv`). The square wave puts its power on a few odd harmonics of 2.5 Hz; the PRBS spreads it flat to 11 Hz; the multisine puts it exactly on 50 lines from 0.2 to 10 Hz; the chirp sweeps 0.2–10 Hz once, the same time per octave.\n"
        ));
        let mut rows = Vec::new();
        for r in results {
            let (name, what) = input_name(&r.input);
            let mut row = vec![format!("**{name}**<br>{what}"), format!("{:.2}", r.rms)];
            match &r.outcome {
                Err(f) => {
                    row.push(match f {
                        Failure::NotIdentified(e) => format!("not identified: {e}"),
                        Failure::Halted(why) => format!("run halted: {why}"),
                    });
                    row.extend(std::iter::repeat_n(String::new(), 6));
                }
                Ok(e) => {
                    let errors = e.errors_percent();
                    for p in EXCITATION_COLUMNS {
                        let i = Parameter::ALL.iter().position(|q| *q == p).unwrap_or(0);
                        row.push(match errors {
                            Some(err) => format!("{:.4} ({:+.1} %)", e.means[i], err[i]),
                            None => format!("{:.4}", e.means[i]),
                        });
                    }
                }
            }
            rows.push(row);
        }
        let mut columns = vec!["input".to_string(), "RMS (V)".to_string()];
        columns.extend(EXCITATION_COLUMNS.map(header));
        self.table(&columns, &rows);
        if let Some((best, e)) = best(results) {
            self.add(&format!(
                "Means over the runs, with the error against the simulated card's truth in brackets. Smallest worst-case error: the {} ({e:.1} %). At one peak voltage the input with the most RMS puts the most energy into the fit, and where its power lies in frequency decides which parameters it pins down: the viscous frictions need slow motion, the springs and the gain the band around the two modes.\n",
                input_name(&best.input).0
            ));
        } else {
            self.add("Means over the runs (the real rig's truth is unknown: compare the inputs with each other and with the square wave's Tables 3 and 4).\n");
        }
    }

    /// The Validation section's heading, and why it could not run.
    pub fn validation_not_possible(&mut self) {
        self.heading(2, VALIDATION);
        self.add("Not possible: the Excitation section's first PRBS run did not complete.\n");
    }

    /// The Validation section: the models on the fresh run, the lab's
    /// formulas against the refined model, every run refined.
    /// `first`: the first identification run's name; `fresh`: the fresh
    /// run's; `truth`: the simulated card's plant and friction (whose
    /// structure `model` then is).
    pub fn validation(
        &mut self,
        v: &Validated,
        (first, fresh): (&str, &str),
        model: &SimulationModel,
        truth: Option<&FrictionPlant>,
    ) {
        self.heading(2, VALIDATION);
        let r = &v.refined;
        self.add(&format!(
            "The first identification run (`{first}`) identified three ways, each model then simulated from the input of a run it has not seen (`{fresh}`), from rest. **Fit** is `100 (1 − ‖x − x̂‖ / ‖x − mean x‖)` of each cart's simulated position (MATLAB's `compare`). The refinement minimises both carts' simulation error on that run over k1, k2, b1, b2, K, F1, F2 by Levenberg–Marquardt ({} simulations; fit on `{first}` from {:.2} / {:.2} % to {:.2} / {:.2} %). **white** and **indep.** are the largest normalised auto- and cross-correlation (with the input) of cart 2's simulation error over 25 lags, against a 99 % bound of {:.3} for a white error independent of the input: an output-error model has no noise model, so its error is not white; a cross-correlation above the bound is dynamics the model misses. The simulation holds the previous input for {} ms after each sample (the drive's delay), integrates in sub-steps of at most {} ms and decides each cart's stick or slip between them, with breakaway at {:.2} / {:.2} × the Coulomb force{}.\n",
            r.evaluations,
            r.start.fit_percent[0],
            r.start.fit_percent[1],
            r.refined.fit_percent[0],
            r.refined.fit_percent[1],
            v.bound,
            model.input_delay * 1e3,
            model.max_substep * 1e3,
            model.stiction_ratio[0],
            model.stiction_ratio[1],
            if truth.is_some() {
                " (the simulated card's own structure)"
            } else {
                " (the defaults: this rig's delay and stiction are not known to the program)"
            },
        ));
        let mut header = vec!["model".to_string()];
        header.extend(Parameter::ALL.map(super::ident::header));
        header.extend(["fit x1 (%)", "fit x2 (%)", "white", "indep."].map(String::from));
        let rows: Vec<Vec<String>> = v
            .models
            .iter()
            .filter_map(|m| m.validation.as_ref().ok().map(|val| model_row(m, val)))
            .collect();
        self.table(&header, &rows);
        for m in &v.models {
            if let Err(e) = &m.validation {
                self.add(&format!("Not validated: {}: {e}.\n", model_name(m.kind)));
            }
        }
        if let Some(lab) = v.model(ModelKind::LabFormulas) {
            let (lab, p) = (&lab.plant, &r.plant);
            let bias = |got: f64, want: f64| format!("{:+.1} %", (got / want - 1.0) * 100.0);
            self.add(&format!(
                "Against the refined model, the lab's formulas on the same run give k1 {}, k2 {}, b1 {}, b2 {}, K {}: with dry friction left out, its viscous frictions absorb it.\n",
                bias(lab.k1, p.k1),
                bias(lab.k2, p.k2),
                bias(lab.b1, p.b1),
                bias(lab.b2, p.b2),
                bias(lab.gain, p.gain),
            ));
        }
        let Some(s) = &v.spread else {
            return;
        };
        let mut rows = Vec::new();
        let mut row = vec![format!("refined, mean ± spread over {} runs", s.runs)];
        row.extend(Parameter::ALL.iter().zip(&s.spread).map(|(p, sp)| {
            let d = digits(*p);
            format!("{:.d$} ± {:.d$}", sp.mean, sp.std_dev)
        }));
        rows.push(row);
        let mut row = vec![format!(
            "refined on `{first}` ± bootstrap standard error ({} resamples)",
            s.bootstrap.resamples
        )];
        row.extend(
            Parameter::ALL
                .iter()
                .zip(s.first.iter().zip(&s.std_errors))
                .map(|(p, (v, e))| {
                    let d = digits(*p);
                    format!("{v:.d$} ± {e:.d$}")
                }),
        );
        rows.push(row);
        if let Some(truth) = truth {
            let mut row = vec![model_name(ModelKind::Truth).to_string()];
            row.extend(Parameter::ALL.map(|p| {
                let d = digits(p);
                format!("{:.d$}", p.of(&truth.truth(), truth.friction()))
            }));
            rows.push(row);
        }
        self.heading(3, "The refined parameters over every run");
        self.add("Every identification run refined the same way: the parameters' mean ± spread over the runs. Beside it, the first run's refinement with standard errors from a moving-block bootstrap (`lab::ident::bootstrap`: the refined model's simulation plus its simulation error resampled in blocks of 100 samples, identified and refined again, 30 times). Derivative-based standard errors would be wrong here: the simulation decides stick and slip between sub-steps, as the card does, so its error jumps as the parameters move (at one run's optimum a 2e-5 relative change of K tripled it); on 100 seeded runs they came out 2–9× below the spread, the bootstrap's 0.9–1.6×.\n");
        let mut header = vec![String::new()];
        header.extend(Parameter::ALL.map(super::ident::header));
        self.table(&header, &rows);
    }

    /// The Frequency response section: the modes on model and rig, the
    /// distance between the curves, the Bode figure.
    pub fn frequency(&mut self, f: &Frequency) -> Result<(), Box<dyn std::error::Error>> {
        self.heading(
            2,
            "Frequency response: the identified model against the rig",
        );
        let r = match &f.response {
            Ok(r) => r,
            Err(why) => {
                self.add(&format!("The multisine run halted: {why}\n"));
                return Ok(());
            }
        };
        let truth = r.truth.is_some();
        let cell = |v: Option<f64>| v.map_or("–".to_string(), |v| format!("{v:.2}"));
        let rows: Vec<Vec<String>> = ["first (carts in phase)", "second (carts in opposition)"]
            .iter()
            .zip(&r.modes)
            .map(|(name, m)| {
                let mut row = vec![
                    name.to_string(),
                    cell(m.model_hz),
                    cell(m.simulated_hz),
                    cell(m.measured_hz),
                ];
                if truth {
                    row.push(cell(m.truth_hz));
                }
                row
            })
            .collect();
        let mut header = vec![
            "mode",
            "identified linear model ωn (Hz)",
            "gain peak, identified model with friction, simulated (Hz)",
            "gain peak, measured (Hz)",
        ];
        if truth {
            header.push("truth ωn (Hz)");
        }
        self.add(&format!(
            "A multisine of {} lines from 0.2 to 15 Hz (Schroeder phases, {IDENT_VOLTS} V peak), {PERIODS} periods of {MS_PERIOD} s (recording `runs/frequency_multisine.csv`). The response from the drive voltage to cart 2's position is estimated over the last {} periods, where the input is periodic and the transient has died out: the empirical transfer-function estimate (`ident::etfe`, one point per line) and its Blackman–Tukey smoothing (`ident::spa`, {SPA_WINDOW} s Hann lag window), whose peaks locate the modes. The identified model is the separate-springs average of the identification runs: its linear part's Bode plot (`freq::bode`), and the model with its Coulomb friction simulated on the same input through the same drive (`sim::run_sampled`) and estimated the same way.\n",
            f.multisine.harmonics().len(),
            PERIODS - 1
        ));
        self.table(&header, &rows);
        self.add(&format!(
            "Median distance of the measured (smoothed) magnitude from the linear model's: {:.1} %; from the identified model with friction, simulated: {:.1} %. At this drive level Coulomb friction is a large part of the force: it damps the first mode and lowers its peak frequency (the carts stick for part of each cycle), which the linear model cannot show and the model with friction does. The first mode's peak is where a design with the linear model is least to be trusted.\n",
            r.gap_linear * 100.0,
            r.gap_friction * 100.0,
        ));
        let measured = Bode::from_response(&r.measured.omega, &r.measured.response)?;
        let smoothed = Bode::from_response(&r.smoothed.omega, &r.smoothed.response)?;
        let simulated = Bode::from_response(&r.simulated.omega, &r.simulated.response)?;
        // Drawn in this order, widest first: the noisy raw estimate under
        // its smoothing, the models over the measurements, so each shows.
        let mut curves: Vec<(&str, &Bode)> = vec![
            ("measured (ETFE)", &measured),
            ("measured, smoothed (spa)", &smoothed),
            (
                "identified model with friction, simulated (spa)",
                &simulated,
            ),
            ("identified model, linear part", &r.model),
        ];
        if let Some(t) = &r.truth {
            curves.push(("truth's linear part (simulated rig)", t));
        }
        // The modes where the rig shows them (its gain peaks), else the
        // model's natural frequencies.
        let marks: Vec<(&str, f64)> = ["mode 1", "mode 2"]
            .into_iter()
            .zip(&r.modes)
            .filter_map(|(name, m)| {
                m.measured_hz
                    .or(m.model_hz)
                    .map(|hz| (name, hz * std::f64::consts::TAU))
            })
            .collect();
        self.bode(
            "bode.svg",
            "u (V) to cart 2 position (m): identified model and measured response",
            &curves,
            &marks,
        )
    }
}

/// The Validation section's heading.
const VALIDATION: &str = "Validation: the models on a fresh run, and refined by output error";
