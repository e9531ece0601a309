//! The rig sections: identification runs (Tables 3 and 4) and state feedback
//! on the rig (Tables 5 and 6), through the full driver stack. Every run's
//! recording is saved as CSV next to the report.

use std::path::PathBuf;

use ctrlab::hw::{
    Clock, LoopConfig, LoopFault, LoopStats, RealTime, RigError, RunError, RunOutcome, StopSignal,
    VirtualClock, run,
};
use ctrlab::lab::{CardSettings, Cart, LabGains, MassSpring, SimulatedRig};
use ctrlab::nalgebra::{SVector, vector};
use ctrlab::{Controller, Error, Recording, StepInfo, StepInfoOptions, step_info};

use crate::figures::RunCurve;
use crate::lab_tables::{self, fmt_kf, fmt_poles};
use crate::report::Report;

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
                    sim.friction.coulomb[0],
                    sim.friction.coulomb[1],
                    sim.friction.stiction[0],
                    sim.friction.stiction[1],
                    sim.card.pwm_delay * 1e3,
                    sim.card.encoder_noise
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
        self.sim().map(|s| s.friction.coulomb)
    }

    pub fn real_time(&self) -> bool {
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
                    truth: truth.unwrap_or(sim.truth),
                    period: PERIOD,
                    card: CardSettings { seed, ..sim.card },
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
            && let RigError::Fault(LoopFault::Interrupted { .. }) = e.error
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
    pub fn timing(&self, stats: &[LoopStats]) -> Option<String> {
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

/// Relative error in percent, signed.
pub fn pct(got: f64, want: f64) -> String {
    format!("{:+.2} %", (got / want - 1.0) * 100.0)
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
        let ctrl = LabGains::new(*kf, table.cart).state_feedback()?;
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
                    RigError::Fault(LoopFault::TravelLimit {
                        axis,
                        position,
                        limit,
                    }) => format!(
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
