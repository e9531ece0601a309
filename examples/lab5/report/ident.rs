//! The identification: its runs, Tables 3 and 4, the identified state
//! equations and the model's uncertainty, the equal-springs run, and the
//! answer on the state equations.

use ctrlab::lab::ident::{EqualSprings, MassSpringEstimate, Parameter, Spread, Summary};
use ctrlab::lab::ident_input::{IdentInput, IdentSignal, PROBE_DURATION, Reason, peaks};
use ctrlab::lab::protocol::{IDENT_DURATION, IDENT_RUNS, M1, M2, PERIOD};
use ctrlab::lab::tables::poles_display;
use ctrlab::lab::{Cart, FrictionPlant, Unmodelled};

use super::{ParamPanel, Report, describe, mm, pct, timing_text};
use crate::backend::Backend;
use crate::identification::{Identification, RigInput, Run, Source};

/// `mean ± sd` to `digits` decimals.
fn pm(s: &Spread, digits: usize) -> String {
    format!("{:.*} ± {:.*}", digits, s.mean, digits, s.std_dev)
}

/// A separate-springs estimate's Coulomb force on `cart` (0 or 1), N.
fn coulomb(e: &MassSpringEstimate, cart: usize) -> f64 {
    e.coulomb.map_or(f64::NAN, |c| c[cart].value)
}

/// The decimals a parameter of the separate-springs model is shown with.
pub(super) fn digits(p: Parameter) -> usize {
    match p {
        Parameter::K1 | Parameter::K2 => 1,
        Parameter::B1 | Parameter::B2 | Parameter::F1 | Parameter::F2 => 3,
        Parameter::Gain => 4,
    }
}

/// A parameter's column header: `k1 (N/m)`.
pub(super) fn header(p: Parameter) -> String {
    format!("{} ({})", p.symbol(), p.unit())
}

/// The identification input in words: `a ±8 V square wave, 0.2 s half
/// period`.
fn signal_text(input: &IdentInput, volts: f64) -> String {
    match input.signal {
        IdentSignal::Square => format!(
            "a ±{volts:.2} V square wave, {} s half period",
            input.half_period
        ),
        IdentSignal::Prbs => format!("a ±{volts:.2} V PRBS (a new bit every 40 ms, 127 bits)"),
        IdentSignal::Multisine => {
            format!("a multisine of {volts:.2} V peak (50 lines, 0.2 to 10 Hz, Schroeder phases)")
        }
    }
}

/// mm to two decimals.
fn mm2(x: f64) -> String {
    format!("{:.2}", x * 1e3)
}

impl Report {
    /// The identification input: what was asked, the probe runs, the
    /// amplitude chosen and why, and every identification run's peak
    /// excursion or why the rig halted it.
    pub fn identification_input(&mut self, input: &RigInput, runs: &[Run]) {
        let choice = &input.choice;
        let allowed = choice.allowed();
        self.heading(2, "Identification input");
        let mut text = format!(
            "Asked for: {}. Travel limits ±{:.1} / ±{:.1} mm; a run should keep each cart within {:.1} / {:.1} mm (60 %).",
            signal_text(&input.input, choice.asked),
            choice.limits[0] * 1e3,
            choice.limits[1] * 1e3,
            allowed[0] * 1e3,
            allowed[1] * 1e3,
        );
        if choice.reason != Reason::Fixed {
            text += &format!(
                " Two probe runs of {PROBE_DURATION} s came first (`runs/ident_probe*.csv`), at a quarter and half of it (the second lowered if the first said so). Each cart's peak at a higher amplitude is predicted as the larger of the line through the two probes' peaks (friction takes a fixed force off the small one) and the line through the origin and the larger probe (`lab::ident_input::predict`)."
            );
        }
        text += &format!(" **Chosen: {:.2} V**, {}.", choice.volts, choice.reason);
        if let Some(at_asked) = choice.predicted_asked
            && choice.volts < choice.asked
        {
            text += &format!(
                " At {:.2} V the peaks would have been {} / {} mm.",
                choice.asked,
                mm2(at_asked[0]),
                mm2(at_asked[1])
            );
        }
        self.add(&format!("{text}\n"));
        let mut rows = Vec::new();
        for (n, p) in choice.probes.iter().enumerate() {
            rows.push(vec![
                format!("probe {}", n + 1),
                format!("{:.2}", p.volts),
                mm2(p.peaks[0]),
                mm2(p.peaks[1]),
                "probe".into(),
            ]);
        }
        if let Some(p) = choice.halted {
            rows.push(vec![
                format!("probe {}", choice.probes.len() + 1),
                format!("{:.2}", p.volts),
                mm2(p.peaks[0]),
                mm2(p.peaks[1]),
                "probe halted at a travel limit (peaks cut short)".into(),
            ]);
        }
        if let Some(p) = choice.predicted {
            rows.push(vec![
                "prediction".into(),
                format!("{:.2}", choice.volts),
                mm2(p[0]),
                mm2(p[1]),
                "predicted".into(),
            ]);
        }
        for run in runs {
            let [x1, x2] = peaks(&run.recording).unwrap_or([f64::NAN; 2]);
            rows.push(vec![
                format!("`{}`", run.name),
                format!("{:.2}", choice.volts),
                mm2(x1),
                mm2(x2),
                "completed".into(),
            ]);
        }
        for f in &input.failed {
            rows.push(vec![
                format!("`{}`", f.name),
                format!("{:.2}", choice.volts),
                mm2(f.peaks[0]),
                mm2(f.peaks[1]),
                format!("halted after {:.3} s", f.ran),
            ]);
        }
        self.table(
            &[
                "run",
                "peak input (V)",
                "cart 1 peak (mm)",
                "cart 2 peak (mm)",
                "outcome",
            ],
            &rows,
        );
        if !input.failed.is_empty() {
            let halted: Vec<String> = input
                .failed
                .iter()
                .map(|f| format!("`{}` after {:.3} s ({})", f.name, f.ran, f.error))
                .collect();
            self.add(&format!(
                "The rig halted {} of the {} identification runs: {}. They are left out: the identification uses the {} that completed.\n",
                input.failed.len(),
                input.failed.len() + runs.len(),
                halted.join("; "),
                runs.len()
            ));
        }
    }

    /// The identification runs, Tables 3 and 4 with their figures, the
    /// identified state equations and the model's uncertainty.
    pub fn identification(
        &mut self,
        backend: Option<&Backend>,
        ident: &Identification,
        truth: Option<&FrictionPlant>,
    ) -> Result<(), Box<dyn std::error::Error>> {
        self.heading(2, "Identification runs");
        let intro = match (&ident.source, backend) {
            (Source::Rig { timing, input }, Some(backend)) => {
                let mut intro = format!(
                    "{IDENT_RUNS} open-loop runs on {}: {}, {IDENT_DURATION} s at T = {} ms, through `MassSpringRig` → `Pc104` → the card (recordings in `runs/ident_{}_{:.2}V_seed*.csv`).",
                    describe(backend),
                    signal_text(&input.input, input.choice.volts),
                    PERIOD * 1e3,
                    input.input.signal.name(),
                    input.choice.volts
                );
                if !input.failed.is_empty() {
                    intro += &format!(
                        " {} of them completed and are identified below; the rig halted {} (see above).",
                        ident.runs.len(),
                        input.failed.len()
                    );
                }
                if let Some(t) = timing {
                    intro += &format!(" {}", timing_text(t));
                }
                intro
            }
            (
                Source::Logs {
                    dir,
                    metres_per_count,
                },
                _,
            ) => {
                let names: Vec<String> =
                    ident.runs.iter().map(|r| format!("`{}`", r.name)).collect();
                format!(
                    "{} logs read from `{}` ({}), as recorded: separators, decimal commas, comments and units as their headers say{}; each split at any gap in its time stamps.",
                    ident.runs.len(),
                    dir.display(),
                    names.join(", "),
                    metres_per_count.map_or(String::new(), |m| format!(
                        ", encoder counts at {m:e} m each"
                    ))
                )
            }
            (Source::Rig { .. }, None) => String::new(),
        };
        self.add(&format!(
            "{intro} Masses known: m1 = {M1} kg, m2 = {M2} kg. **Lab** is equations (6)–(11) as the lab's MATLAB code; **Central** uses central-difference velocities, the input averaged over the hold and Numerov-weighted positions; **separate** identifies k1 ≠ k2 and each cart's Coulomb friction (Central, rows where the cart moves).\n"
        ));
        let s = &ident.summary;
        self.tables_3_and_4(s, truth)?;
        let first = ident.runs.first().ok_or("no identification run")?;
        let rec = &first.recording;
        let file = "identification.svg";
        let title = format!("Identification run {}: positions and input", first.name);
        super::figures::ident_svg(
            &self.out.join(file),
            &title,
            rec.time(),
            [&mm(rec.channel("x1")?), &mm(rec.channel("x2")?)],
            (
                rec.channel("u")?,
                backend.map(|b| b.calibration().volts_full_scale),
            ),
        )?;
        self.link(file, &title);
        let [sf1, sf2] = s.coulomb;
        self.heading(3, "Identified state equations");
        self.add(&format!(
            "From the averages of the separate-springs estimates, equations (3)/(14), output cart 2; the Coulomb friction ({:.2} N and {:.2} N) is outside the linear model:\n",
            sf1.mean, sf2.mean
        ));
        let sys = ident.model().state_space(Cart::Two)?;
        self.add(&format!(
            "```text\nx = [x1 (m), x1' (m/s), x2 (m), x2' (m/s)],   u in V\n{sys:.4}```\n"
        ));
        self.add(&format!(
            "Open-loop poles: {}.\n",
            poles_display(&sys.poles()?)
        ));
        self.model_csv(s, truth)?;
        self.uncertainty(s, truth);
        Ok(())
    }

    /// Tables 3 and 4: per run, mean ± sd, the truth; and their figures.
    fn tables_3_and_4(
        &mut self,
        s: &Summary,
        truth: Option<&FrictionPlant>,
    ) -> Result<(), Box<dyn std::error::Error>> {
        let mut rows3 = Vec::new();
        let mut rows4 = Vec::new();
        for (i, ((l, c), e)) in s.lab.iter().zip(&s.central).zip(&s.separate).enumerate() {
            rows3.push(vec![
                format!("{}", i + 1),
                format!("{:.2}", l.k1().value),
                format!("{:.3}", l.b1.value),
                format!("{:.2}", c.k1().value),
                format!("{:.3}", c.b1.value),
                format!("{:.2}", e.k1().value),
                format!("{:.2}", e.k2().value),
                format!("{:.3}", e.b1.value),
                format!("{:.3}", coulomb(e, 0)),
            ]);
            rows4.push(vec![
                format!("{}", i + 1),
                format!("{:.4}", l.gain.value),
                format!("{:.3}", l.b2.value),
                format!("{:.4}", c.gain.value),
                format!("{:.3}", c.b2.value),
                format!("{:.4}", e.gain.value),
                format!("{:.3}", e.b2.value),
                format!("{:.3}", coulomb(e, 1)),
            ]);
        }
        let (al, ac, a) = (&s.lab_average, &s.central_average, &s.average);
        let [sf1, sf2] = s.coulomb;
        rows3.push(vec![
            "**mean ± sd**".into(),
            pm(&al.k1(), 2),
            pm(&al.b1, 3),
            pm(&ac.k1(), 2),
            pm(&ac.b1, 3),
            pm(&a.k1(), 2),
            pm(&a.k2(), 2),
            pm(&a.b1, 3),
            pm(&sf1, 3),
        ]);
        rows4.push(vec![
            "**mean ± sd**".into(),
            pm(&al.gain, 4),
            pm(&al.b2, 3),
            pm(&ac.gain, 4),
            pm(&ac.b2, 3),
            pm(&a.gain, 4),
            pm(&a.b2, 3),
            pm(&sf2, 3),
        ]);
        if let Some(plant) = truth {
            let (t, forces) = (plant.truth(), plant.friction());
            rows3.push(vec![
                "truth (simulated card)".into(),
                format!("k1 {:.0}, k2 {:.0}", t.k1, t.k2),
                format!("{:.3}", t.b1),
                String::new(),
                String::new(),
                format!("{:.2}", t.k1),
                format!("{:.2}", t.k2),
                format!("{:.3}", t.b1),
                format!("{:.3}", forces[0]),
            ]);
            rows4.push(vec![
                "truth (simulated card)".into(),
                format!("{:.4}", t.gain),
                format!("{:.3}", t.b2),
                String::new(),
                String::new(),
                format!("{:.4}", t.gain),
                format!("{:.3}", t.b2),
                format!("{:.3}", forces[1]),
            ]);
        }
        let t = truth.map(FrictionPlant::truth);
        self.table3_csv(s, truth)?;
        self.heading(3, "Table 3: springs and friction of cart 1");
        self.table(
            &[
                "run",
                "k12 Lab (N/m)",
                "b1 Lab (N·s/m)",
                "k12 Central (N/m)",
                "b1 Central (N·s/m)",
                "k1 separate (N/m)",
                "k2 separate (N/m)",
                "b1 separate (N·s/m)",
                "Coulomb 1 separate (N)",
            ],
            &rows3,
        );
        let lab = |f: fn(&MassSpringEstimate) -> f64| s.lab.iter().map(f).collect::<Vec<f64>>();
        let central =
            |f: fn(&MassSpringEstimate) -> f64| s.central.iter().map(f).collect::<Vec<f64>>();
        let separate =
            |f: fn(&MassSpringEstimate) -> f64| s.separate.iter().map(f).collect::<Vec<f64>>();
        self.estimates(
            "table3.svg",
            "Table 3: estimates per run",
            &[
                ParamPanel {
                    name: "k1, k12 (N/m)".into(),
                    schemes: vec![
                        ("Lab k12".into(), lab(|e| e.k1().value)),
                        ("Central k12".into(), central(|e| e.k1().value)),
                        ("separate k1".into(), separate(|e| e.k1().value)),
                    ],
                    truth: t.map(|t| t.k1),
                },
                ParamPanel {
                    name: "k2 (N/m)".into(),
                    schemes: vec![
                        ("Lab k12".into(), lab(|e| e.k1().value)),
                        ("Central k12".into(), central(|e| e.k1().value)),
                        ("separate k2".into(), separate(|e| e.k2().value)),
                    ],
                    truth: t.map(|t| t.k2),
                },
                ParamPanel {
                    name: "b1 (N·s/m)".into(),
                    schemes: vec![
                        ("Lab".into(), lab(|e| e.b1.value)),
                        ("Central".into(), central(|e| e.b1.value)),
                        ("separate".into(), separate(|e| e.b1.value)),
                    ],
                    truth: t.map(|t| t.b1),
                },
            ],
        )?;
        self.table4_csv(s, truth)?;
        self.heading(3, "Table 4: motor gain and friction of cart 2");
        self.table(
            &[
                "run",
                "K Lab (N/V)",
                "b2 Lab (N·s/m)",
                "K Central (N/V)",
                "b2 Central (N·s/m)",
                "K separate (N/V)",
                "b2 separate (N·s/m)",
                "Coulomb 2 separate (N)",
            ],
            &rows4,
        );
        self.estimates(
            "table4.svg",
            "Table 4: estimates per run",
            &[
                ParamPanel {
                    name: "K (N/V)".into(),
                    schemes: vec![
                        ("Lab".into(), lab(|e| e.gain.value)),
                        ("Central".into(), central(|e| e.gain.value)),
                        ("separate".into(), separate(|e| e.gain.value)),
                    ],
                    truth: t.map(|t| t.gain),
                },
                ParamPanel {
                    name: "b2 (N·s/m)".into(),
                    schemes: vec![
                        ("Lab".into(), lab(|e| e.b2.value)),
                        ("Central".into(), central(|e| e.b2.value)),
                        ("separate".into(), separate(|e| e.b2.value)),
                    ],
                    truth: t.map(|t| t.b2),
                },
            ],
        )
    }

    /// The separate-springs model's parameters with their uncertainty: the
    /// spread over the runs beside the runs' own standard errors.
    fn uncertainty(&mut self, s: &Summary, truth: Option<&FrictionPlant>) {
        self.heading(3, "The identified model and its uncertainty");
        let rows = s.uncertainty(truth);
        let mut table = Vec::new();
        for u in &rows {
            let digits = digits(u.parameter);
            let Spread { mean, std_dev: sd } = u.spread;
            let mut row = vec![
                header(u.parameter),
                format!("{mean:.digits$}"),
                format!("{sd:.digits$}"),
                format!("{:.digits$}", u.std_error),
                format!("{:.1}", u.ratio()),
                format!("{:.digits$}", u.std_error_of_mean()),
            ];
            if let (Some(want), Some(bias)) = (u.truth, u.bias()) {
                row.push(format!("{want:.digits$}"));
                row.push(format!("{bias:+.1}"));
            }
            table.push(row);
        }
        let mut header = vec![
            "parameter",
            "mean",
            "sd over runs",
            "standard error of one run",
            "se / sd",
            "se of the mean (sd/√n)",
        ];
        if truth.is_some() {
            header.extend(["truth", "(mean − truth) / se of the mean"]);
        }
        self.add(&format!(
            "The separate-springs estimates over the {} runs (the model above is their mean). Each run's **standard error** is Newey–West's (HAC, bandwidth chosen from the data): the equation errors of differenced, quantised positions are coloured, and the classical formula, which assumes them white, is several times too wide on the rig; stage 2's errors carry stage 1's error in k2. Over repeated runs a standard error should match the **spread** (se / sd near 1). Where the mean is off the truth by more than a few of its own standard errors, the difference is bias (model error: the PWM delay, stiction above the Coulomb force), which no standard error covers.\n",
            s.average.runs
        ));
        self.table(&header, &table);
        let (lo, hi) = rows
            .iter()
            .map(|u| u.ratio())
            .fold((f64::INFINITY, 0.0f64), |(lo, hi), r| {
                (lo.min(r), hi.max(r))
            });
        self.add(&format!(
            "The standard errors are {lo:.1} to {hi:.1} times the run-to-run spread; with {} runs the spread itself is uncertain by about ±{:.0} %.\n",
            s.average.runs,
            100.0 * s.spread_uncertainty()
        ));
    }

    /// The equal-springs run: the schemes' own bias.
    pub fn equal_springs(&mut self, e: &EqualSprings) {
        let (truth, l, c) = (&e.truth, &e.lab, &e.central);
        self.add(&format!(
            "One more run on a card whose springs are equal (k1 = k2 = {:.0} N/m) and without Coulomb friction, where the lab's model is exact, isolates the schemes' own bias: Lab k12 {}, b1 {}, K {}, b2 {}; Central k12 {}, b1 {}, K {}, b2 {}.\n",
            truth.k1,
            pct(l.k1().value, truth.k1),
            pct(l.b1.value, truth.b1),
            pct(l.gain.value, truth.gain),
            pct(l.b2.value, truth.b2),
            pct(c.k1().value, truth.k1),
            pct(c.b1.value, truth.b1),
            pct(c.gain.value, truth.gain),
            pct(c.b2.value, truth.b2),
        ));
    }

    /// The answers' heading and question 1: the state equations with the
    /// identified parameters (and, on a simulated rig, against its truth).
    pub fn answer_model(&mut self, backend: Option<&Backend>, ident: &Identification) {
        self.heading(2, "Answers to the report's questions");
        self.heading(3, "1. The state equations with the identified parameters");
        let m = ident.model();
        let [f1, f2] = ident.coulomb();
        let mut s = format!(
            "With m1 = {} kg and m2 = {} kg known: k1 = {:.1} N/m, k2 = {:.1} N/m, b1 = {:.3} N·s/m, b2 = {:.3} N·s/m, K = {:.4} N/V, and Coulomb friction {:.2} N on cart 1 and {:.2} N on cart 2 (averages of {} runs); the matrices are in the section above.",
            m.m1, m.m2, m.k1, m.k2, m.b1, m.b2, m.gain, f1, f2, ident.summary.average.runs
        );
        if let Some(sim) = backend.and_then(Backend::sim) {
            let drawn = if sim.unmodelled.friction_variation > 0.0 {
                format!(
                    " (nominal: each run's is drawn with σ = {:.0} %)",
                    100.0 * sim.unmodelled.friction_variation
                )
            } else {
                String::new()
            };
            s += &format!(
                " The card's Coulomb friction is {} N and {} N{drawn}: identified {} and {}.",
                sim.friction.coulomb[0],
                sim.friction.coulomb[1],
                pct(f1, sim.friction.coulomb[0]),
                pct(f2, sim.friction.coulomb[1]),
            );
            let t = sim.truth;
            let lab_k = ident.summary.lab_average.gain.mean;
            let cen_k = ident.summary.central_average.gain.mean;
            s += &format!(
                " Against the simulated card's truth: k1 {}, k2 {}, b1 {}, b2 {}, K {}. The card's springs differ (k1 = {:.0}, k2 = {:.0} N/m) and its carts have Coulomb friction, so the lab's model is wrong for it whatever the differences: its K is off by {} (Lab) and {} (Central), while identifying k1, k2 and the friction separately gives K within {}{}.",
                pct(m.k1, t.k1),
                pct(m.k2, t.k2),
                pct(m.b1, t.b1),
                pct(m.b2, t.b2),
                pct(m.gain, t.gain),
                t.k1,
                t.k2,
                pct(lab_k, t.gain),
                pct(cen_k, t.gain),
                pct(m.gain, t.gain),
                if sim.unmodelled == Unmodelled::NONE {
                    ""
                } else {
                    " (the rest is what the model lacks: see \"What the identification does not recover\")"
                },
            );
        }
        if let Some(e) = &ident.equal_springs {
            let (truth, l, c) = (&e.truth, &e.lab, &e.central);
            s += &format!(
                " Where the model is right (the equal-springs run), the lab's formulas are still biased, K {} and b2 {}, by the half-sample-late velocity and the held input; the central scheme gives K {} and b2 {}.",
                pct(l.gain.value, truth.gain),
                pct(l.b2.value, truth.b2),
                pct(c.gain.value, truth.gain),
                pct(c.b2.value, truth.b2),
            );
        }
        self.add(&format!("{s}\n"));
    }

    /// What the offline report leaves to the rig.
    pub fn offline_answers(&mut self) {
        self.add("Tables 5 and 6 and the design on the rig need the rig: run lab5 without `--logs` (on the simulated rig, or the card with `--port`).\n");
    }
}
