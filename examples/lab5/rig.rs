//! The rig sections: identification runs (Tables 3 and 4) and state feedback
//! on the rig (Tables 5 and 6), through the full driver stack. Every run's
//! recording is saved as CSV next to the report.

use std::path::PathBuf;

use ctrlab::hw::{
    Clock, HwError, LoopConfig, LoopStats, RealTime, RunError, RunOutcome, StopSignal,
    VirtualClock, run,
};
use ctrlab::lab::ident::{
    MassSpringEstimate, Options, Scheme, SeparateSpringsEstimate, Spread, average, identify,
    identify_separate_springs_with,
};
use ctrlab::lab::{Cart, MassSpring, SimulatedRig};
use ctrlab::nalgebra::{SVector, vector};
use ctrlab::signal::{Signal, SquareWave};
use ctrlab::{
    Controller, Error, OpenLoop, Recording, StateFeedback, StepInfo, StepInfoOptions, step_info,
};

use crate::figures::{ParamPanel, RunCurve};
use crate::lab_tables::{self, fmt_kf, fmt_poles};
use crate::report::{Report, fmt_state_equations};

/// The loop period, s.
pub const PERIOD: f64 = 0.002;
/// Known masses (the lab weighs the carts), kg.
pub const M1: f64 = 1.3;
pub const M2: f64 = 0.7;
/// Identification input: ±8 V square wave (about ±9 N, ±18 mm on cart 2:
/// well clear of the friction, well inside the travel), 0.2 s half period,
/// 5 s.
pub const IDENT_VOLTS: f64 = 8.0;
pub const IDENT_HALF_PERIOD: f64 = 0.2;
pub const IDENT_DURATION: f64 = 5.0;
/// Length of each closed-loop rig run, s.
const STEP_DURATION: f64 = 3.0;
pub const RUNS: u64 = 5;

/// Where the rig sections run, and how.
pub struct Backend {
    pub kind: BackendKind,
    /// Real-time scheduling for the loop (`--rt-priority`).
    pub realtime: Option<RealTime>,
    /// Ctrl-C and SIGTERM stop the run in progress (the rig halts).
    pub stop: StopSignal,
    /// Where each run's CSV goes.
    pub out: PathBuf,
}

pub enum BackendKind {
    /// The register-level simulated card with `sim` inside (`--truth`),
    /// virtual or real time.
    Simulated {
        sim: Box<SimulatedRig>,
        real_time: bool,
    },
    /// The real PC104 card on a parallel port, with its card file's map
    /// and calibration.
    #[cfg(all(feature = "ppdev", target_os = "linux"))]
    Card {
        port: PathBuf,
        config: ctrlab::lab::RigConfig,
    },
}

impl Backend {
    pub fn describe(&self) -> String {
        match &self.kind {
            BackendKind::Simulated { sim, real_time } => {
                let t = sim.truth;
                format!(
                    "the simulated PC104 card ({} clock): m1 = {} kg, m2 = {} kg, k1 = {} N/m, k2 = {} N/m, b1 = {} N·s/m, b2 = {} N·s/m, K = {} N/V, Coulomb friction {} / {} N (breakaway {} / {} N), PWM delay {} ms, encoder noise σ = {} counts",
                    if *real_time { "real-time" } else { "virtual" },
                    t.m1,
                    t.m2,
                    t.k1,
                    t.k2,
                    t.b1,
                    t.b2,
                    t.gain,
                    sim.coulomb_friction[0],
                    sim.coulomb_friction[1],
                    sim.stiction[0],
                    sim.stiction[1],
                    sim.pwm_delay * 1e3,
                    sim.encoder_noise
                )
            }
            #[cfg(all(feature = "ppdev", target_os = "linux"))]
            BackendKind::Card { port, .. } => format!("the PC104 card on {}", port.display()),
        }
    }

    /// The simulated rig, when there is one.
    pub fn sim(&self) -> Option<&SimulatedRig> {
        match &self.kind {
            BackendKind::Simulated { sim, .. } => Some(sim),
            #[cfg(all(feature = "ppdev", target_os = "linux"))]
            BackendKind::Card { .. } => None,
        }
    }

    /// The truth behind a simulated rig, when there is one.
    pub fn truth(&self) -> Option<MassSpring> {
        self.sim().map(|s| s.truth)
    }

    /// The simulated card's Coulomb forces (cart 1, cart 2), N.
    pub fn coulomb_truth(&self) -> Option<[f64; 2]> {
        self.sim().map(|s| s.coulomb_friction)
    }

    fn real_time(&self) -> bool {
        match &self.kind {
            BackendKind::Simulated { real_time, .. } => *real_time,
            #[cfg(all(feature = "ppdev", target_os = "linux"))]
            BackendKind::Card { .. } => true,
        }
    }

    /// One experiment from rest: `controller` against the rig for
    /// `duration` s with reference `reference(t)`, its recording saved as
    /// `runs/{name}.csv`. The outer error is a set-up failure (or Ctrl-C),
    /// the inner one the run's own (with its recording).
    pub fn experiment(
        &self,
        name: &str,
        seed: u64,
        truth: Option<MassSpring>,
        controller: impl Controller<4, 1, 1>,
        reference: impl FnMut(f64) -> SVector<f64, 1>,
        duration: f64,
    ) -> Result<Result<RunOutcome, Box<RunError>>, Box<dyn std::error::Error>> {
        let loop_config = LoopConfig {
            duration,
            realtime: self.realtime,
            stop: Some(self.stop.clone()),
            ..LoopConfig::default()
        };
        let outcome = match &self.kind {
            BackendKind::Simulated { sim, real_time } => {
                let sim = SimulatedRig {
                    seed,
                    truth: truth.unwrap_or(sim.truth),
                    period: PERIOD,
                    ..(**sim).clone()
                };
                let clock = if *real_time {
                    Clock::RealTime
                } else {
                    Clock::Virtual(VirtualClock::new())
                };
                let rig = sim.rig(&clock)?;
                run(rig, controller, reference, &clock, &loop_config)
            }
            #[cfg(all(feature = "ppdev", target_os = "linux"))]
            BackendKind::Card { port, config } => {
                let _ = (truth, seed); // the real rig has its own
                // Let the carts come to rest, then make it the zero position.
                std::thread::sleep(std::time::Duration::from_secs(3));
                let rig = crate::card::rig(port, config, PERIOD)?;
                run(rig, controller, reference, &Clock::RealTime, &loop_config)
            }
        };
        let recording = match &outcome {
            Ok(out) => &out.recording,
            Err(e) => &e.recording,
        };
        let dir = self.out.join("runs");
        std::fs::create_dir_all(&dir)?;
        recording.write_csv(dir.join(format!("{name}.csv")))?;
        if let Err(e) = &outcome
            && let HwError::Interrupted { .. } = e.error
        {
            return Err(format!(
                "{e}; the run's recording is in {}",
                dir.join(format!("{name}.csv")).display()
            )
            .into());
        }
        Ok(outcome)
    }

    /// A sentence on the loop's timing, for real-time runs.
    fn timing(&self, stats: &[LoopStats]) -> Option<String> {
        if !self.real_time() || stats.is_empty() {
            return None;
        }
        let worst = |f: fn(&LoopStats) -> f64| stats.iter().map(f).fold(0.0, f64::max);
        let skipped: usize = stats.iter().map(|s| s.skipped).sum();
        let overruns: usize = stats.iter().map(|s| s.overruns).sum();
        Some(format!(
            "Loop timing over these runs ({}): worst p99 lateness {:.1} µs, worst max {:.1} µs, {overruns} overruns, {skipped} skipped ticks (they show as gaps in the recordings; identification splits at gaps), longest interval between samples {:.2} ms.\n",
            if self.realtime.is_some() {
                "SCHED_FIFO"
            } else {
                "normal scheduling"
            },
            worst(|s| s.lateness_p99) * 1e6,
            worst(|s| s.lateness_max) * 1e6,
            worst(|s| s.max_interval) * 1e3
        ))
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
    /// Separate springs with Coulomb friction (Central), one per run.
    pub separate: Vec<SeparateSpringsEstimate>,
    /// Run 1's recording.
    pub first_run: Recording,
    /// Lab and Central on one run of an equal-springs, frictionless truth
    /// (simulated rig only): the schemes' own bias, free of model error.
    pub equal_springs: Option<(MassSpring, MassSpringEstimate, MassSpringEstimate)>,
    /// The identified model: averages of the separate-springs estimates.
    pub model: MassSpring,
    /// The identified Coulomb forces, N (cart 1, cart 2).
    pub coulomb: [Spread; 2],
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
        "{RUNS} open-loop runs on {}: a ±{IDENT_VOLTS} V square wave, {IDENT_HALF_PERIOD} s half period, {IDENT_DURATION} s at T = {} ms, through `MassSpringRig` → `Pc104` → the card (recordings in `runs/ident_*.csv`). Masses known: m1 = {M1} kg, m2 = {M2} kg. **Lab** is equations (6)–(11) as the lab's MATLAB code; **Central** uses central-difference velocities, the input averaged over the hold and Numerov-weighted positions; **separate** identifies k1 ≠ k2 and each cart's Coulomb friction (Central, rows where the cart moves).\n",
        backend.describe(),
        PERIOD * 1e3
    ));
    let (mut lab, mut central, mut separate) = (Vec::new(), Vec::new(), Vec::new());
    let mut stats = Vec::new();
    let mut first = None;
    let wave = square();
    let options = Options {
        scheme: Scheme::Central,
        coulomb: true,
        ..Options::default()
    };
    for seed in 1..=RUNS {
        let out = backend
            .experiment(
                &format!("ident_{seed}"),
                seed,
                None,
                OpenLoop,
                |t| vector![wave.value(t)],
                IDENT_DURATION,
            )?
            .map_err(|e| format!("identification run {seed}: {e}"))?;
        let rec = out.recording;
        stats.push(out.stats);
        lab.push(identify(&rec, M1, M2, Scheme::Lab)?);
        central.push(identify(&rec, M1, M2, Scheme::Central)?);
        separate.push(identify_separate_springs_with(&rec, M1, M2, &options)?);
        if seed == 1 {
            first = Some(rec);
        }
    }
    if let Some(s) = backend.timing(&stats) {
        report.add(&s);
    }

    let truth = backend.truth();
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
    let sk1 = spread_of(separate.iter().map(|s| s.k1.value))?;
    let sk2 = spread_of(separate.iter().map(|s| s.k2.value))?;
    let sb1 = spread_of(separate.iter().map(|s| s.b1.value))?;
    let sg = spread_of(separate.iter().map(|s| s.gain.value))?;
    let sb2 = spread_of(separate.iter().map(|s| s.b2.value))?;
    let sf1 = spread_of(separate.iter().map(|s| coulomb(s, 0)))?;
    let sf2 = spread_of(separate.iter().map(|s| coulomb(s, 1)))?;
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
    if let (Some(t), Some(sim)) = (truth, backend.sim()) {
        rows3.push(vec![
            "truth (simulated card)".into(),
            format!("k1 {:.0}, k2 {:.0}", t.k1, t.k2),
            format!("{:.3}", t.b1),
            String::new(),
            String::new(),
            format!("{:.2}", t.k1),
            format!("{:.2}", t.k2),
            format!("{:.3}", t.b1),
            format!("{:.3}", sim.coulomb_friction[0]),
        ]);
        rows4.push(vec![
            "truth (simulated card)".into(),
            format!("{:.4}", t.gain),
            format!("{:.3}", t.b2),
            String::new(),
            String::new(),
            format!("{:.4}", t.gain),
            format!("{:.3}", t.b2),
            format!("{:.3}", sim.coulomb_friction[1]),
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
                truth: truth.map(|t| t.k1),
            },
            ParamPanel {
                name: "k2 (N/m)".into(),
                schemes: vec![
                    ("Lab k12".into(), values(&|i| lab[i].k12.value)),
                    ("Central k12".into(), values(&|i| central[i].k12.value)),
                    ("separate k2".into(), values(&|i| separate[i].k2.value)),
                ],
                truth: truth.map(|t| t.k2),
            },
            ParamPanel {
                name: "b1 (N·s/m)".into(),
                schemes: vec![
                    ("Lab".into(), values(&|i| lab[i].b1.value)),
                    ("Central".into(), values(&|i| central[i].b1.value)),
                    ("separate".into(), values(&|i| separate[i].b1.value)),
                ],
                truth: truth.map(|t| t.b1),
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
                truth: truth.map(|t| t.gain),
            },
            ParamPanel {
                name: "b2 (N·s/m)".into(),
                schemes: vec![
                    ("Lab".into(), values(&|i| lab[i].b2.value)),
                    ("Central".into(), values(&|i| central[i].b2.value)),
                    ("separate".into(), values(&|i| separate[i].b2.value)),
                ],
                truth: truth.map(|t| t.b2),
            },
        ],
    )?;
    let first = first.ok_or("no identification run")?;
    let mm = |v: &[f64]| v.iter().map(|x| x * 1e3).collect::<Vec<_>>();
    report.figure(
        "identification.svg",
        &format!("Identification run 1: positions under a ±{IDENT_VOLTS} V square wave"),
        "t (s)",
        "position (mm)",
        &[
            ("x1".into(), first.time().to_vec(), mm(first.channel("x1")?)),
            ("x2".into(), first.time().to_vec(), mm(first.channel("x2")?)),
        ],
    )?;

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
    report.add(&format!(
        "From the averages of the separate-springs estimates, equations (3)/(14), output cart 2; the Coulomb friction ({:.2} N and {:.2} N) is outside the linear model:\n",
        sf1.mean, sf2.mean
    ));
    let sys = model.state_space(Cart::Two)?;
    report.add(&fmt_state_equations(&sys));
    report.add(&format!("Open-loop poles: {}.\n", fmt_poles(&sys.poles()?)));
    // The lab's formulas assume k1 = k2 and no Coulomb friction. On a truth
    // where that holds, the only difference between the schemes is the
    // finite differences themselves.
    let equal_springs = match (backend.truth(), backend.sim()) {
        (Some(t), Some(sim)) => {
            let truth = MassSpring { k2: t.k1, ..t };
            let run_backend = Backend {
                kind: BackendKind::Simulated {
                    sim: Box::new(SimulatedRig {
                        coulomb_friction: [0.0; 2],
                        stiction: [0.0; 2],
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
    };
    Ok(Identification {
        lab,
        central,
        separate,
        first_run: first,
        equal_springs,
        model,
        coulomb: [sf1, sf2],
    })
}

/// How a closed-loop rig run ended.
pub enum RigRow {
    /// Settled inside the 2 % band: the metrics.
    Settled(StepInfo),
    /// Still moving towards the setpoint when the run ended.
    TooSlow { y_end_mm: f64 },
    /// A bounded oscillation that never settles: with the drive saturated
    /// most of the time (the drive chatters between ±24 V) or not.
    Oscillating {
        lo_mm: f64,
        hi_mm: f64,
        saturated: f64,
    },
    /// Halted by the rig (a travel limit, …) or the loop.
    Diverged { at: f64, why: String },
}

impl RigRow {
    pub fn is_settled(&self) -> bool {
        matches!(self, RigRow::Settled(_))
    }

    /// The outcome cell of the table.
    fn outcome(&self) -> String {
        match self {
            RigRow::Settled(_) => "settled".into(),
            RigRow::TooSlow { y_end_mm } => {
                format!("too slow for the {STEP_DURATION} s run (at {y_end_mm:.2} mm at the end)")
            }
            RigRow::Oscillating {
                lo_mm,
                hi_mm,
                saturated,
            } if *saturated > 0.2 => format!(
                "bounded oscillation under saturation: {lo_mm:.1} … {hi_mm:.1} mm, the drive at ±24 V {:.0} % of the time",
                saturated * 100.0
            ),
            RigRow::Oscillating { lo_mm, hi_mm, .. } => {
                format!("sustained oscillation: {lo_mm:.1} … {hi_mm:.1} mm")
            }
            RigRow::Diverged { at, why } => format!("diverged: halted at t = {at:.3} s, {why}"),
        }
    }
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

/// Classifies a completed run that did not settle.
fn unsettled(y_mm: &[f64], u: &[f64], full_scale: f64) -> RigRow {
    let tail = y_mm.len() * 3 / 4;
    let (y_tail, u_tail) = (&y_mm[tail..], &u[tail.min(u.len())..]);
    let lo = y_tail.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = y_tail.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let mean = y_tail.iter().sum::<f64>() / y_tail.len().max(1) as f64;
    let crossings = y_tail
        .windows(2)
        .filter(|w| (w[0] - mean) * (w[1] - mean) < 0.0)
        .count();
    let saturated = u_tail
        .iter()
        .filter(|v| v.abs() >= 0.99 * full_scale)
        .count() as f64
        / u_tail.len().max(1) as f64;
    if crossings >= 4 {
        RigRow::Oscillating {
            lo_mm: lo,
            hi_mm: hi,
            saturated,
        }
    } else {
        RigRow::TooSlow {
            y_end_mm: y_mm.last().copied().unwrap_or(f64::NAN),
        }
    }
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
        "u = Kf (G r − x_mm) in volts per mm, saturated at ±24 V, {STEP_DURATION} s per run on {}; metrics of the measured position (2 % band over the last 5 % of the run; y∞ = mean of that window, POT relative to y∞). The prediction is the identified linear model's closed loop sampled at 2 ms (ZOH, no saturation, no friction): stable when its spectral radius ρ = max |z| < 1; the continuous poles are shown for reference. Each run's recording is in `runs/`.\n",
        backend.describe()
    ));
    let sys = model.state_space(table.cart)?;
    // The rig samples every 2 ms: the loop that can be stable or not is the
    // sampled one, so predict with the ZOH-discretised model.
    let sampled = sys.discretize(PERIOD, ctrlab::Method::Zoh)?;
    let idx = table.cart.state_index();
    let channel = if idx == 0 { "x1" } else { "x2" };
    let setpoint = table.setpoint_mm / 1e3;
    let full_scale = 24.0;
    let mut rows = Vec::new();
    let mut curves = Vec::new();
    let mut results = Vec::new();
    let mut stats = Vec::new();
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
        let name = format!("{}_row{}", table.file.trim_end_matches(".svg"), i + 1);
        let outcome = backend.experiment(
            &name,
            100 + i as u64,
            None,
            ctrl,
            |_| vector![setpoint],
            STEP_DURATION,
        )?;
        let (rec, row): (&Recording, RigRow) = match &outcome {
            Ok(out) => {
                stats.push(out.stats.clone());
                let rec = &out.recording;
                let y: Vec<f64> = rec.channel(channel)?.iter().map(|v| v * 1e3).collect();
                let options = StepInfoOptions {
                    reference: Some(table.setpoint_mm),
                    ..Default::default()
                };
                let row = match step_info(rec.time(), &y, &options) {
                    Ok(info) => RigRow::Settled(info),
                    Err(Error::NotSettled { .. }) => unsettled(&y, rec.channel("u")?, full_scale),
                    Err(e) => RigRow::Diverged {
                        at: rec.time().last().copied().unwrap_or(0.0),
                        why: format!("no metrics: {e}"),
                    },
                };
                (rec, row)
            }
            Err(e) => {
                stats.push(e.stats.clone());
                let why = match &e.error {
                    HwError::TravelLimit {
                        axis,
                        position,
                        limit,
                    } => format!(
                        "cart {axis} at {:.1} mm beyond the ±{:.0} mm travel limit",
                        position * 1e3,
                        limit * 1e3
                    ),
                    other => other.to_string(),
                };
                let row = RigRow::Diverged {
                    at: e.recording.time().last().copied().unwrap_or(0.0),
                    why,
                };
                (&e.recording, row)
            }
        };
        curves.push(RunCurve {
            title: format!(
                "{}: {}",
                fmt_kf(kf),
                match &row {
                    RigRow::Settled(_) => "settled",
                    RigRow::TooSlow { .. } => "too slow",
                    RigRow::Oscillating { .. } => "oscillating",
                    RigRow::Diverged { .. } => "diverged",
                }
            ),
            t: rec.time().to_vec(),
            x_mm: rec.channel(channel)?.iter().map(|v| v * 1e3).collect(),
            u: rec.channel("u")?.to_vec(),
        });
        rows.push(match &row {
            RigRow::Settled(info) => vec![
                fmt_kf(kf),
                predicted.clone(),
                poles.clone(),
                row.outcome(),
                format!("{:.2}", info.steady_state_value),
                format!("{:.2}", info.peak),
                format!("{:.2}", info.overshoot),
                format!("{:.3}", info.settling_time),
                format!("{:.2}", info.steady_state_error.unwrap_or(f64::NAN)),
            ],
            _ => vec![
                fmt_kf(kf),
                predicted.clone(),
                poles.clone(),
                row.outcome(),
                "–".into(),
                "–".into(),
                "–".into(),
                "–".into(),
                "–".into(),
            ],
        });
        results.push(RigResult { row, radius });
    }
    report.table(
        &[
            "Kf (per mm)",
            "sampled loop, identified model",
            "continuous poles (1/s)",
            "outcome",
            "y∞ (mm)",
            "peak (mm)",
            "POT (%)",
            "settling time (s)",
            "steady-state error (mm)",
        ],
        &rows,
    );
    if let Some(s) = backend.timing(&stats) {
        report.add(&s);
    }
    report.runs(
        table.file,
        &format!(
            "{}: position (setpoint dashed) and applied voltage",
            table.name
        ),
        table.setpoint_mm,
        full_scale,
        &curves,
    )?;
    Ok(results)
}
