//! The identification sections: Tables 3 and 4 with their averages, the
//! identified model and its uncertainty, from runs on the rig or from a
//! student's own logs (`--logs DIR`).

use std::path::Path;

use ctrlab::data::CsvOptions;
use ctrlab::hw::LoopStats;
use ctrlab::lab::ident::{
    Estimate, MassSpringEstimate, Options, Scheme, SeparateSpringsAverage, SeparateSpringsEstimate,
    Spread, average, average_separate_springs, identify, identify_separate_springs_with,
};
use ctrlab::lab::{Cart, Friction, MassSpring, SimulatedRig};
use ctrlab::nalgebra::vector;
use ctrlab::signal::{Signal, SquareWave};
use ctrlab::{OpenLoop, Recording};

use crate::figures::ParamPanel;
use crate::lab_tables::fmt_poles;
use crate::report::{Report, fmt_state_equations};
use crate::rig::{
    Backend, BackendKind, IDENT_DURATION, IDENT_HALF_PERIOD, IDENT_VOLTS, M1, M2, PERIOD, RUNS, pct,
};

/// The separate-springs identification: Central, with each cart's Coulomb
/// friction.
pub const SEPARATE: Options = Options {
    scheme: Scheme::Central,
    coulomb: true,
    ..Options::DEFAULT
};

/// The identification input: the lab's square wave, V.
fn square() -> SquareWave {
    SquareWave::new(IDENT_VOLTS, IDENT_HALF_PERIOD).expect("valid constants")
}

/// `mean ± sd` to `digits` decimals.
fn pm(s: &Spread, digits: usize) -> String {
    format!("{:.*} ± {:.*}", digits, s.mean, digits, s.std_dev)
}

/// One identification run: its name (the CSV file's stem) and recording.
pub struct Run {
    pub name: String,
    pub recording: Recording,
}

/// The equal-springs truth and its Lab and Central estimates.
pub type EqualSprings = (MassSpring, MassSpringEstimate, MassSpringEstimate);

/// All estimates of the identification runs.
pub struct Identification {
    pub lab: Vec<MassSpringEstimate>,
    pub central: Vec<MassSpringEstimate>,
    /// Separate springs with Coulomb friction (Central), one per run.
    pub separate: Vec<SeparateSpringsEstimate>,
    /// The runs, in order.
    pub runs: Vec<Run>,
    /// Lab and Central on one run of an equal-springs, frictionless truth
    /// (simulated rig only): the schemes' own bias, free of model error.
    pub equal_springs: Option<EqualSprings>,
    /// The separate-springs estimates averaged over the runs.
    pub average: SeparateSpringsAverage,
    /// The identified model: the averages' linear part.
    pub model: MassSpring,
}

impl Identification {
    /// The identified Coulomb forces, N (cart 1, cart 2): the averages.
    pub fn coulomb(&self) -> [f64; 2] {
        self.average.coulomb.map_or([0.0; 2], |c| c.map(|s| s.mean))
    }
}

/// The lab's identification runs on the rig: {RUNS} runs of the square
/// wave, each saved as `runs/ident_{seed}.csv`; the intro paragraph with
/// the loop's timing.
pub fn rig_runs(backend: &Backend) -> Result<(Vec<Run>, String), Box<dyn std::error::Error>> {
    let wave = square();
    let mut runs = Vec::new();
    let mut stats: Vec<LoopStats> = Vec::new();
    for seed in 1..=RUNS {
        let name = format!("ident_{seed}");
        let out = backend
            .experiment(
                &name,
                seed,
                None,
                OpenLoop,
                |t| vector![wave.value(t)],
                IDENT_DURATION,
            )?
            .map_err(|e| format!("identification run {seed}: {e}"))?;
        stats.push(out.stats);
        runs.push(Run {
            name,
            recording: out.recording,
        });
    }
    let mut intro = format!(
        "{RUNS} open-loop runs on {}: a ±{IDENT_VOLTS} V square wave, {IDENT_HALF_PERIOD} s half period, {IDENT_DURATION} s at T = {} ms, through `MassSpringRig` → `Pc104` → the card (recordings in `runs/ident_*.csv`).",
        backend.describe(),
        PERIOD * 1e3
    );
    if let Some(s) = backend.timing(&stats) {
        intro += &format!(" {s}");
    }
    Ok((runs, intro))
}

/// Every `*.csv` file in `dir`, in file-name order, read with `options`;
/// the intro paragraph.
pub fn log_runs(
    dir: &Path,
    options: &CsvOptions,
) -> Result<(Vec<Run>, String), Box<dyn std::error::Error>> {
    let mut paths = Vec::new();
    for entry in std::fs::read_dir(dir).map_err(|e| format!("--logs {}: {e}", dir.display()))? {
        let path = entry?.path();
        if path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("csv"))
        {
            paths.push(path);
        }
    }
    paths.sort();
    if paths.len() < 2 {
        return Err(format!(
            "--logs {}: found {} CSV file(s); the averages and the validation on a fresh run need at least two",
            dir.display(),
            paths.len()
        )
        .into());
    }
    let mut runs = Vec::new();
    for path in &paths {
        let recording = Recording::read_csv_with(path, options)
            .map_err(|e| format!("{}: {e}", path.display()))?;
        let name = path
            .file_stem()
            .map_or_else(String::new, |s| s.to_string_lossy().into_owned());
        runs.push(Run { name, recording });
    }
    let names: Vec<String> = runs.iter().map(|r| format!("`{}`", r.name)).collect();
    let intro = format!(
        "{} logs read from `{}` ({}), as recorded: separators, decimal commas, comments and units as their headers say{}; each split at any gap in its time stamps.",
        runs.len(),
        dir.display(),
        names.join(", "),
        options.metres_per_count.map_or(String::new(), |m| format!(
            ", encoder counts at {m:e} m each"
        ))
    );
    Ok((runs, intro))
}

/// Tables 3 and 4 (Lab, Central and separate springs with Coulomb
/// friction, per run, averaged), the identified model and its uncertainty.
/// `truth`: the simulated card's plant and Coulomb forces.
pub fn identification(
    runs: Vec<Run>,
    intro: &str,
    truth: Option<(MassSpring, [f64; 2])>,
    report: &mut Report,
) -> Result<Identification, Box<dyn std::error::Error>> {
    report.heading(2, "Identification runs");
    report.add(&format!(
        "{intro} Masses known: m1 = {M1} kg, m2 = {M2} kg. **Lab** is equations (6)–(11) as the lab's MATLAB code; **Central** uses central-difference velocities, the input averaged over the hold and Numerov-weighted positions; **separate** identifies k1 ≠ k2 and each cart's Coulomb friction (Central, rows where the cart moves).\n"
    ));
    let (mut lab, mut central, mut separate) = (Vec::new(), Vec::new(), Vec::new());
    let options = SEPARATE;
    for run in &runs {
        let rec = &run.recording;
        let context = |e: ctrlab::Error| format!("run {}: {e}", run.name);
        lab.push(identify(rec, M1, M2, Scheme::Lab).map_err(context)?);
        central.push(identify(rec, M1, M2, Scheme::Central).map_err(context)?);
        separate.push(identify_separate_springs_with(rec, M1, M2, &options).map_err(context)?);
    }
    let coulomb =
        |e: &SeparateSpringsEstimate, cart: usize| e.coulomb.map_or(f64::NAN, |c| c[cart].value);
    let mut rows3 = Vec::new();
    let mut rows4 = Vec::new();
    for i in 0..lab.len() {
        let (l, c, s) = (&lab[i], &central[i], &separate[i]);
        rows3.push(vec![
            format!("{}", i + 1),
            format!("{:.2}", l.k12.value),
            format!("{:.3}", l.b1.value),
            format!("{:.2}", c.k12.value),
            format!("{:.3}", c.b1.value),
            format!("{:.2}", s.k1.value),
            format!("{:.2}", s.k2.value),
            format!("{:.3}", s.b1.value),
            format!("{:.3}", coulomb(s, 0)),
        ]);
        rows4.push(vec![
            format!("{}", i + 1),
            format!("{:.4}", l.gain.value),
            format!("{:.3}", l.b2.value),
            format!("{:.4}", c.gain.value),
            format!("{:.3}", c.b2.value),
            format!("{:.4}", s.gain.value),
            format!("{:.3}", s.b2.value),
            format!("{:.3}", coulomb(s, 1)),
        ]);
    }
    let (al, ac) = (average(&lab)?, average(&central)?);
    let average = average_separate_springs(&separate)?;
    let [sf1, sf2] = average
        .coulomb
        .ok_or("the separate-springs fit has no Coulomb forces")?;
    let (sk1, sk2, sb1, sg, sb2) = (average.k1, average.k2, average.b1, average.gain, average.b2);
    rows3.push(vec![
        "**mean ± sd**".into(),
        pm(&al.k12, 2),
        pm(&al.b1, 3),
        pm(&ac.k12, 2),
        pm(&ac.b1, 3),
        pm(&sk1, 2),
        pm(&sk2, 2),
        pm(&sb1, 3),
        pm(&sf1, 3),
    ]);
    rows4.push(vec![
        "**mean ± sd**".into(),
        pm(&al.gain, 4),
        pm(&al.b2, 3),
        pm(&ac.gain, 4),
        pm(&ac.b2, 3),
        pm(&sg, 4),
        pm(&sb2, 3),
        pm(&sf2, 3),
    ]);
    if let Some((t, forces)) = truth {
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
    report.heading(3, "Table 3: springs and friction of cart 1");
    report.table(
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
    let values = |f: &dyn Fn(usize) -> f64| (0..lab.len()).map(f).collect::<Vec<f64>>();
    report.estimates(
        "table3.svg",
        "Table 3: estimates per run",
        &[
            ParamPanel {
                name: "k1, k12 (N/m)".into(),
                schemes: vec![
                    ("Lab k12".into(), values(&|i| lab[i].k12.value)),
                    ("Central k12".into(), values(&|i| central[i].k12.value)),
                    ("separate k1".into(), values(&|i| separate[i].k1.value)),
                ],
                truth: truth.map(|(t, _)| t.k1),
            },
            ParamPanel {
                name: "k2 (N/m)".into(),
                schemes: vec![
                    ("Lab k12".into(), values(&|i| lab[i].k12.value)),
                    ("Central k12".into(), values(&|i| central[i].k12.value)),
                    ("separate k2".into(), values(&|i| separate[i].k2.value)),
                ],
                truth: truth.map(|(t, _)| t.k2),
            },
            ParamPanel {
                name: "b1 (N·s/m)".into(),
                schemes: vec![
                    ("Lab".into(), values(&|i| lab[i].b1.value)),
                    ("Central".into(), values(&|i| central[i].b1.value)),
                    ("separate".into(), values(&|i| separate[i].b1.value)),
                ],
                truth: truth.map(|(t, _)| t.b1),
            },
        ],
    )?;
    report.heading(3, "Table 4: motor gain and friction of cart 2");
    report.table(
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
    report.estimates(
        "table4.svg",
        "Table 4: estimates per run",
        &[
            ParamPanel {
                name: "K (N/V)".into(),
                schemes: vec![
                    ("Lab".into(), values(&|i| lab[i].gain.value)),
                    ("Central".into(), values(&|i| central[i].gain.value)),
                    ("separate".into(), values(&|i| separate[i].gain.value)),
                ],
                truth: truth.map(|(t, _)| t.gain),
            },
            ParamPanel {
                name: "b2 (N·s/m)".into(),
                schemes: vec![
                    ("Lab".into(), values(&|i| lab[i].b2.value)),
                    ("Central".into(), values(&|i| central[i].b2.value)),
                    ("separate".into(), values(&|i| separate[i].b2.value)),
                ],
                truth: truth.map(|(t, _)| t.b2),
            },
        ],
    )?;
    let first = runs.first().ok_or("no identification run")?;
    let rec = &first.recording;
    let mm = |v: &[f64]| v.iter().map(|x| x * 1e3).collect::<Vec<_>>();
    report.figure(
        "identification.svg",
        &format!("Identification run {}: positions", first.name),
        "t (s)",
        "position (mm)",
        &[
            ("x1".into(), rec.time().to_vec(), mm(rec.channel("x1")?)),
            ("x2".into(), rec.time().to_vec(), mm(rec.channel("x2")?)),
        ],
    )?;
    let model = average.plant();
    report.heading(3, "Identified state equations");
    report.add(&format!(
        "From the averages of the separate-springs estimates, equations (3)/(14), output cart 2; the Coulomb friction ({:.2} N and {:.2} N) is outside the linear model:\n",
        sf1.mean, sf2.mean
    ));
    let sys = model.state_space(Cart::Two)?;
    report.add(&fmt_state_equations(&sys));
    report.add(&format!("Open-loop poles: {}.\n", fmt_poles(&sys.poles()?)));
    uncertainty(&separate, &average, truth, report);
    Ok(Identification {
        lab,
        central,
        separate,
        runs,
        equal_springs: None,
        average,
        model,
    })
}

/// The separate-springs model's parameters with their uncertainty: the
/// spread over the runs beside the runs' own standard errors.
fn uncertainty(
    separate: &[SeparateSpringsEstimate],
    average: &SeparateSpringsAverage,
    truth: Option<(MassSpring, [f64; 2])>,
    report: &mut Report,
) {
    report.heading(3, "The identified model and its uncertainty");
    type Pick = fn(&SeparateSpringsEstimate) -> Option<Estimate>;
    /// Name, estimate, spread over the runs, truth, decimals.
    type Row = (&'static str, Pick, Option<Spread>, Option<f64>, usize);
    let forces = average.coulomb.map(|[f1, f2]| (f1, f2));
    // Each parameter's spread over the runs is the average's own.
    let rows: [Row; 7] = [
        (
            "k1 (N/m)",
            |e| Some(e.k1),
            Some(average.k1),
            truth.map(|(t, _)| t.k1),
            1,
        ),
        (
            "k2 (N/m)",
            |e| Some(e.k2),
            Some(average.k2),
            truth.map(|(t, _)| t.k2),
            1,
        ),
        (
            "b1 (N·s/m)",
            |e| Some(e.b1),
            Some(average.b1),
            truth.map(|(t, _)| t.b1),
            3,
        ),
        (
            "b2 (N·s/m)",
            |e| Some(e.b2),
            Some(average.b2),
            truth.map(|(t, _)| t.b2),
            3,
        ),
        (
            "K (N/V)",
            |e| Some(e.gain),
            Some(average.gain),
            truth.map(|(t, _)| t.gain),
            4,
        ),
        (
            "F1 (N)",
            |e| Some(e.coulomb?[0]),
            forces.map(|f| f.0),
            truth.map(|(_, f)| f[0]),
            3,
        ),
        (
            "F2 (N)",
            |e| Some(e.coulomb?[1]),
            forces.map(|f| f.1),
            truth.map(|(_, f)| f[1]),
            3,
        ),
    ];
    let n = separate.len() as f64;
    let mut table = Vec::new();
    let mut ratios = Vec::new();
    for (name, pick, spread, want, digits) in rows {
        let Some(Spread { mean, std_dev: sd }) = spread else {
            continue;
        };
        let estimates: Vec<Estimate> = separate.iter().filter_map(pick).collect();
        let se = (estimates.iter().map(|e| e.std_error.powi(2)).sum::<f64>() / n).sqrt();
        ratios.push(se / sd);
        let mut row = vec![
            name.to_string(),
            format!("{mean:.digits$}"),
            format!("{sd:.digits$}"),
            format!("{se:.digits$}"),
            format!("{:.1}", se / sd),
            format!("{:.digits$}", sd / n.sqrt()),
        ];
        if let Some(want) = want {
            row.push(format!("{want:.digits$}"));
            row.push(format!("{:+.1}", (mean - want) / (sd / n.sqrt())));
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
    report.add(&format!(
        "The separate-springs estimates over the {} runs (the model above is their mean). Each run's **standard error** is Newey–West's (HAC, bandwidth chosen from the data): the equation errors of differenced, quantised positions are coloured, and the classical formula, which assumes them white, is several times too wide on the rig; stage 2's errors carry stage 1's error in k2. Over repeated runs a standard error should match the **spread** (se / sd near 1). Where the mean is off the truth by more than a few of its own standard errors, the difference is bias (model error: the PWM delay, stiction above the Coulomb force), which no standard error covers.\n",
        average.runs
    ));
    let header: Vec<&str> = header.into_iter().collect();
    report.table(&header, &table);
    let (lo, hi) = ratios.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), r| {
        (lo.min(*r), hi.max(*r))
    });
    report.add(&format!(
        "The standard errors are {lo:.1} to {hi:.1} times the run-to-run spread; with {} runs the spread itself is uncertain by about ±{:.0} %.\n",
        average.runs,
        100.0 / (2.0 * (n - 1.0)).sqrt()
    ));
}

/// One more run on a card whose springs are equal and without Coulomb
/// friction (simulated rig only), where the lab's model is exact: the
/// schemes' own bias.
pub fn equal_springs(
    backend: &Backend,
    report: &mut Report,
) -> Result<Option<EqualSprings>, Box<dyn std::error::Error>> {
    // The lab's formulas assume k1 = k2 and no Coulomb friction. On a truth
    // where that holds, the only difference between the schemes is the
    // finite differences themselves.
    Ok(match (backend.truth(), backend.sim()) {
        (Some(t), Some(sim)) => {
            let truth = MassSpring { k2: t.k1, ..t };
            let run_backend = Backend {
                kind: BackendKind::Simulated {
                    sim: Box::new(SimulatedRig {
                        friction: Friction {
                            coulomb: [0.0; 2],
                            stiction: [0.0; 2],
                        },
                        ..sim.clone()
                    }),
                    real_time: backend.real_time(),
                },
                realtime: backend.realtime,
                stop: backend.stop.clone(),
                out: backend.out.clone(),
            };
            let out = run_backend
                .experiment(
                    "ident_equal_springs",
                    99,
                    Some(truth),
                    OpenLoop,
                    |t| vector![square().value(t)],
                    IDENT_DURATION,
                )?
                .map_err(|e| format!("equal-springs run: {e}"))?;
            let rec = out.recording;
            let (l, c) = (
                identify(&rec, M1, M2, Scheme::Lab)?,
                identify(&rec, M1, M2, Scheme::Central)?,
            );
            report.add(&format!(
                "One more run on a card whose springs are equal (k1 = k2 = {:.0} N/m) and without Coulomb friction, where the lab's model is exact, isolates the schemes' own bias: Lab k12 {}, b1 {}, K {}, b2 {}; Central k12 {}, b1 {}, K {}, b2 {}.\n",
                truth.k1,
                pct(l.k12.value, truth.k1),
                pct(l.b1.value, truth.b1),
                pct(l.gain.value, truth.gain),
                pct(l.b2.value, truth.b2),
                pct(c.k12.value, truth.k1),
                pct(c.b1.value, truth.b1),
                pct(c.gain.value, truth.gain),
                pct(c.b2.value, truth.b2),
            ));
            Some((truth, l, c))
        }
        _ => None,
    })
}
