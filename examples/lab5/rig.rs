//! The rig sections: identification runs (Tables 3 and 4) and state feedback
//! on the rig (Tables 5 and 6), through the full driver stack.

use ctrlab::hw::{Clock, HwError, LoopConfig, RunError, RunOutcome, VirtualClock, run};
use ctrlab::lab::ident::{
    MassSpringEstimate, Scheme, Spread, average, identify, identify_separate_springs,
};
use ctrlab::lab::{Cart, MassSpring, SimulatedRig};
use ctrlab::nalgebra::{SVector, vector};
use ctrlab::signal::{Signal, SquareWave};
use ctrlab::{Controller, Error, OpenLoop, StateFeedback, StepInfo, StepInfoOptions, step_info};

use crate::lab_tables::{self, fmt_kf, fmt_poles};
use crate::report::{Report, fmt_state_equations};

/// The loop period, s.
pub const PERIOD: f64 = 0.002;
/// Known masses (the lab weighs the carts), kg.
pub const M1: f64 = 1.3;
pub const M2: f64 = 0.7;
/// Encoder noise on the simulated card, counts (σ); each run has its seed.
const NOISE_COUNTS: f64 = 0.5;
/// Identification input: ±2 V square wave, 0.2 s half period, 5 s.
const IDENT_VOLTS: f64 = 2.0;
const IDENT_HALF_PERIOD: f64 = 0.2;
const IDENT_DURATION: f64 = 5.0;
/// Length of each closed-loop rig run, s.
const STEP_DURATION: f64 = 3.0;
pub const RUNS: u64 = 5;

/// Where the rig sections run.
pub enum Backend {
    /// The register-level simulated card (default truth, see
    /// `SimulatedRig::default_truth`), virtual or real time.
    Simulated { real_time: bool },
    /// The real PC104 card on a parallel port.
    #[cfg(all(feature = "ppdev", target_os = "linux"))]
    Card(std::path::PathBuf),
}

impl Backend {
    pub fn describe(&self) -> String {
        match self {
            Backend::Simulated { real_time } => {
                let t = SimulatedRig::default_truth();
                format!(
                    "simulated PC104 card ({} clock), truth m1 = {} kg, m2 = {} kg, k1 = {} N/m, k2 = {} N/m, b1 = {} N·s/m, b2 = {} N·s/m, K = {} N/V, encoder noise σ = {NOISE_COUNTS} counts",
                    if *real_time { "real-time" } else { "virtual" },
                    t.m1,
                    t.m2,
                    t.k1,
                    t.k2,
                    t.b1,
                    t.b2,
                    t.gain
                )
            }
            #[cfg(all(feature = "ppdev", target_os = "linux"))]
            Backend::Card(path) => format!("the PC104 card on {}", path.display()),
        }
    }

    /// The truth behind a simulated rig, when there is one.
    pub fn truth(&self) -> Option<MassSpring> {
        match self {
            Backend::Simulated { .. } => Some(SimulatedRig::default_truth()),
            #[cfg(all(feature = "ppdev", target_os = "linux"))]
            Backend::Card(_) => None,
        }
    }

    /// One experiment from rest: `controller` against the rig for
    /// `duration` s with reference `reference(t)`. The outer error is a
    /// set-up failure, the inner one the run's own (with its recording).
    pub fn experiment(
        &self,
        seed: u64,
        truth: Option<MassSpring>,
        controller: impl Controller<4, 1, 1>,
        reference: impl FnMut(f64) -> SVector<f64, 1>,
        duration: f64,
    ) -> Result<Result<RunOutcome, Box<RunError>>, HwError> {
        let loop_config = LoopConfig {
            duration,
            ..LoopConfig::default()
        };
        match self {
            Backend::Simulated { real_time } => {
                let sim = SimulatedRig {
                    encoder_noise: NOISE_COUNTS,
                    seed,
                    truth: truth.unwrap_or_else(SimulatedRig::default_truth),
                    period: PERIOD,
                    ..Default::default()
                };
                let clock = if *real_time {
                    Clock::RealTime
                } else {
                    Clock::Virtual(VirtualClock::new())
                };
                let rig = sim.rig(&clock)?;
                Ok(run(rig, controller, reference, &clock, &loop_config))
            }
            #[cfg(all(feature = "ppdev", target_os = "linux"))]
            Backend::Card(path) => {
                let _ = truth; // the real rig has its own
                // Let the carts come to rest, then make it the zero position.
                std::thread::sleep(std::time::Duration::from_secs(3));
                let mut card = ctrlab::hw::Pc104::new(ctrlab::hw::Ppdev::open(path)?);
                card.clear_counters()?;
                let rig = ctrlab::lab::MassSpringRig::new(
                    card,
                    ctrlab::lab::Calibration::default(),
                    PERIOD,
                )?;
                Ok(run(
                    rig,
                    controller,
                    reference,
                    &Clock::RealTime,
                    &loop_config,
                ))
            }
        }
    }
}

/// The identification input: the lab's square wave, V.
fn square() -> SquareWave {
    SquareWave::new(IDENT_VOLTS, IDENT_HALF_PERIOD).expect("valid constants")
}

/// All estimates of the identification runs.
pub struct Identification {
    pub lab: Vec<MassSpringEstimate>,
    pub central: Vec<MassSpringEstimate>,
    /// Lab and Central on one run of an equal-springs truth (simulated rig
    /// only): the schemes' own bias, free of the k1 ≠ k2 model error.
    pub equal_springs: Option<(MassSpring, MassSpringEstimate, MassSpringEstimate)>,
    /// The identified model: averages of the separate-springs central
    /// estimates.
    pub model: MassSpring,
}

/// Relative error in percent, signed.
pub fn pct(got: f64, want: f64) -> String {
    format!("{:+.2} %", (got / want - 1.0) * 100.0)
}

fn pm(s: &Spread, digits: usize) -> String {
    format!("{:.*} ± {:.*}", digits, s.mean, digits, s.std_dev)
}

fn spread_of(values: impl Iterator<Item = f64>) -> Result<Spread, Error> {
    Spread::of(&values.collect::<Vec<_>>())
}

/// Five open-loop runs, identified by both schemes; Tables 3 and 4.
pub fn identification(
    backend: &Backend,
    report: &mut Report,
) -> Result<Identification, Box<dyn std::error::Error>> {
    report.heading(2, "Identification runs (rig)");
    report.add(&format!(
        "{RUNS} open-loop runs on {}: a ±{IDENT_VOLTS} V square wave, {IDENT_HALF_PERIOD} s half period, {IDENT_DURATION} s at T = {} ms, through `MassSpringRig` → `Pc104` → the card. Masses known: m1 = {M1} kg, m2 = {M2} kg. **Lab** is equations (6)–(11) as the lab's MATLAB code; **Central** uses central-difference velocities, the input averaged over the hold and Numerov-weighted positions; **separate** identifies k1 ≠ k2 (Central).\n",
        backend.describe(),
        PERIOD * 1e3
    ));
    let (mut lab, mut central, mut separate) = (Vec::new(), Vec::new(), Vec::new());
    let mut first = None;
    let wave = square();
    for seed in 1..=RUNS {
        let out = backend
            .experiment(
                seed,
                None,
                OpenLoop,
                |t| vector![wave.value(t)],
                IDENT_DURATION,
            )?
            .map_err(|e| format!("identification run {seed}: {e}"))?;
        let rec = out.recording;
        lab.push(identify(&rec, M1, M2, Scheme::Lab)?);
        central.push(identify(&rec, M1, M2, Scheme::Central)?);
        separate.push(identify_separate_springs(&rec, M1, M2, Scheme::Central)?);
        if seed == 1 {
            first = Some(rec);
        }
    }

    let truth = backend.truth();
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
        ]);
        rows4.push(vec![
            format!("{}", i + 1),
            format!("{:.4}", l.gain.value),
            format!("{:.3}", l.b2.value),
            format!("{:.4}", c.gain.value),
            format!("{:.3}", c.b2.value),
            format!("{:.4}", s.gain.value),
            format!("{:.3}", s.b2.value),
        ]);
    }
    let (al, ac) = (average(&lab)?, average(&central)?);
    let sk1 = spread_of(separate.iter().map(|s| s.k1.value))?;
    let sk2 = spread_of(separate.iter().map(|s| s.k2.value))?;
    let sb1 = spread_of(separate.iter().map(|s| s.b1.value))?;
    let sg = spread_of(separate.iter().map(|s| s.gain.value))?;
    let sb2 = spread_of(separate.iter().map(|s| s.b2.value))?;
    rows3.push(vec![
        "**mean ± sd**".into(),
        pm(&al.k12, 2),
        pm(&al.b1, 3),
        pm(&ac.k12, 2),
        pm(&ac.b1, 3),
        pm(&sk1, 2),
        pm(&sk2, 2),
        pm(&sb1, 3),
    ]);
    rows4.push(vec![
        "**mean ± sd**".into(),
        pm(&al.gain, 4),
        pm(&al.b2, 3),
        pm(&ac.gain, 4),
        pm(&ac.b2, 3),
        pm(&sg, 4),
        pm(&sb2, 3),
    ]);
    if let Some(t) = truth {
        rows3.push(vec![
            "truth (simulated card)".into(),
            format!("k1 {:.0}, k2 {:.0}", t.k1, t.k2),
            format!("{:.3}", t.b1),
            String::new(),
            String::new(),
            format!("{:.2}", t.k1),
            format!("{:.2}", t.k2),
            format!("{:.3}", t.b1),
        ]);
        rows4.push(vec![
            "truth (simulated card)".into(),
            format!("{:.4}", t.gain),
            format!("{:.3}", t.b2),
            String::new(),
            String::new(),
            format!("{:.4}", t.gain),
            format!("{:.3}", t.b2),
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
        ],
        &rows3,
    );
    let run_axis: Vec<f64> = (1..=lab.len()).map(|r| r as f64).collect();
    let per_run = |label: &str, values: Vec<f64>| (label.to_string(), run_axis.clone(), values);
    report.figure(
        "table3.svg",
        "Table 3: spring estimates per run",
        "run",
        "spring (N/m)",
        &[
            per_run("k12 Lab", lab.iter().map(|e| e.k12.value).collect()),
            per_run("k12 Central", central.iter().map(|e| e.k12.value).collect()),
            per_run("k1 separate", separate.iter().map(|e| e.k1.value).collect()),
            per_run("k2 separate", separate.iter().map(|e| e.k2.value).collect()),
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
        ],
        &rows4,
    );
    report.figure(
        "table4.svg",
        "Table 4: motor gain estimates per run",
        "run",
        "K (N/V)",
        &[
            per_run("K Lab", lab.iter().map(|e| e.gain.value).collect()),
            per_run("K Central", central.iter().map(|e| e.gain.value).collect()),
            per_run(
                "K separate",
                separate.iter().map(|e| e.gain.value).collect(),
            ),
        ],
    )?;
    if let Some(rec) = first {
        let mm = |v: &[f64]| v.iter().map(|x| x * 1e3).collect::<Vec<_>>();
        report.figure(
            "identification.svg",
            "Identification run 1: positions under a ±2 V square wave",
            "t (s)",
            "position (mm)",
            &[
                ("x1".into(), rec.time().to_vec(), mm(rec.channel("x1")?)),
                ("x2".into(), rec.time().to_vec(), mm(rec.channel("x2")?)),
            ],
        )?;
    }

    let model = MassSpring {
        m1: M1,
        m2: M2,
        k1: sk1.mean,
        k2: sk2.mean,
        b1: sb1.mean,
        b2: sb2.mean,
        gain: sg.mean,
    };
    report.heading(3, "Identified state equations");
    report.add(
        "From the averages of the separate-springs (Central) estimates, equations (3)/(14):\n",
    );
    let sys = model.state_space(Cart::Two)?;
    report.add(&fmt_state_equations(&sys));
    report.add(&format!("Open-loop poles: {}.\n", fmt_poles(&sys.poles()?)));
    // The lab's formulas assume k1 = k2. On an equal-springs truth the only
    // difference between the schemes is the finite differences themselves.
    let equal_springs = match backend.truth() {
        Some(t) => {
            let truth = MassSpring { k2: t.k1, ..t };
            let out = backend
                .experiment(
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
                "One more run on a card whose springs are equal (k1 = k2 = {:.0} N/m), where the lab's model is exact, isolates the schemes' own bias: Lab k12 {}, b1 {}, K {}, b2 {}; Central k12 {}, b1 {}, K {}, b2 {}.\n",
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
        None => None,
    };
    Ok(Identification {
        lab,
        central,
        equal_springs,
        model,
    })
}

/// A closed-loop rig run's outcome.
pub enum RigRow {
    Measured(StepInfo),
    /// The run ended early (a travel limit, …) or never settled.
    Failed(String),
}

/// A rig row with what the identified model predicted for it.
pub struct RigResult {
    pub row: RigRow,
    /// The sampled identified loop's spectral radius (< 1: stable).
    pub radius: f64,
}

/// One table of rig runs.
pub struct RigTable {
    pub name: &'static str,
    pub file: &'static str,
    pub cart: Cart,
    pub setpoint_mm: f64,
    pub rows: Vec<[f64; 4]>,
}

pub fn rig_tables() -> [RigTable; 2] {
    [
        RigTable {
            name: "Table 5: cart 2, setpoint 30 mm (rig)",
            file: "table5.svg",
            cart: Cart::Two,
            setpoint_mm: 30.0,
            rows: lab_tables::table5(),
        },
        RigTable {
            name: "Table 6: cart 1, setpoint 15 mm (rig)",
            file: "table6.svg",
            cart: Cart::One,
            setpoint_mm: 15.0,
            rows: lab_tables::table6(),
        },
    ]
}

/// Runs every row of `table` on the rig; the identified model's closed-loop
/// poles say what to expect.
pub fn rig_table(
    backend: &Backend,
    model: &MassSpring,
    table: &RigTable,
    report: &mut Report,
) -> Result<Vec<RigResult>, Box<dyn std::error::Error>> {
    report.heading(2, table.name);
    report.add(&format!(
        "u = Kf (G r − x_mm) in volts per mm, saturated at ±24 V, {STEP_DURATION} s per run on {}; metrics of the measured position (2 % band over the last 5 % of the run; steady state = mean of that window). The prediction is the identified model's closed loop sampled at 2 ms (ZOH, no saturation): stable when its spectral radius ρ = max |z| < 1; the continuous poles are shown for reference.\n",
        backend.describe()
    ));
    let sys = model.state_space(table.cart)?;
    // The rig samples every 2 ms: the loop that can be stable or not is the
    // sampled one, so predict with the ZOH-discretised model.
    let sampled = sys.discretize(PERIOD, ctrlab::Method::Zoh)?;
    let idx = table.cart.state_index();
    let setpoint = table.setpoint_mm / 1e3;
    let mut rows = Vec::new();
    let mut curves = Vec::new();
    let mut results = Vec::new();
    for (i, kf) in table.rows.iter().enumerate() {
        let ctrl = StateFeedback::from_lab_gains(*kf, table.cart)?;
        let poles = fmt_poles(&ctrl.closed_loop(&sys)?.poles()?);
        let radius = ctrl
            .closed_loop(&sampled)?
            .poles()?
            .iter()
            .map(|z| z.norm())
            .fold(0.0, f64::max);
        let predicted = format!(
            "{} (ρ = {radius:.3})",
            if radius < 1.0 { "stable" } else { "unstable" }
        );
        let outcome = backend.experiment(
            100 + i as u64,
            None,
            ctrl,
            |_| vector![setpoint],
            STEP_DURATION,
        )?;
        let row = match outcome {
            Ok(out) => {
                let rec = out.recording;
                let x = rec.channel(if idx == 0 { "x1" } else { "x2" })?;
                let y: Vec<f64> = x.iter().map(|v| v * 1e3).collect();
                let options = StepInfoOptions {
                    reference: Some(table.setpoint_mm),
                    ..Default::default()
                };
                let row = match step_info(rec.time(), &y, &options) {
                    Ok(info) => RigRow::Measured(info),
                    Err(Error::NotSettled { .. }) => {
                        let tail = &y[y.len() * 3 / 4..];
                        let lo = tail.iter().copied().fold(f64::INFINITY, f64::min);
                        let hi = tail.iter().copied().fold(f64::NEG_INFINITY, f64::max);
                        RigRow::Failed(format!(
                            "unstable/not settled: the last quarter spans {lo:.1} … {hi:.1} mm"
                        ))
                    }
                    Err(e) => RigRow::Failed(format!("no metrics: {e}")),
                };
                curves.push((format!("Kf = {}", fmt_kf(kf)), rec.time().to_vec(), y));
                row
            }
            Err(e) => {
                let rec = &e.recording;
                let x = rec.channel(if idx == 0 { "x1" } else { "x2" })?;
                curves.push((
                    format!("Kf = {} (halted)", fmt_kf(kf)),
                    rec.time().to_vec(),
                    x.iter().map(|v| v * 1e3).collect(),
                ));
                RigRow::Failed(format!(
                    "unstable/halted at t = {:.3} s: {}",
                    rec.time().last().copied().unwrap_or(0.0),
                    e.error
                ))
            }
        };
        rows.push(match &row {
            RigRow::Measured(info) => vec![
                fmt_kf(kf),
                predicted.clone(),
                poles.clone(),
                format!("{:.2}", info.overshoot),
                format!("{:.4}", info.settling_time),
                format!("{:.4}", info.steady_state_error.unwrap_or(f64::NAN)),
            ],
            RigRow::Failed(why) => vec![
                fmt_kf(kf),
                predicted.clone(),
                poles.clone(),
                why.clone(),
                String::new(),
                String::new(),
            ],
        });
        results.push(RigResult { row, radius });
    }
    report.table(
        &[
            "Kf (per mm)",
            "sampled loop, identified model",
            "continuous poles (1/s)",
            "POT (%)",
            "settling time (s)",
            "steady-state error (mm)",
        ],
        &rows,
    );
    report.figure(
        table.file,
        table.name,
        "t (s)",
        if idx == 0 { "x1 (mm)" } else { "x2 (mm)" },
        &curves,
    )?;
    Ok(results)
}
