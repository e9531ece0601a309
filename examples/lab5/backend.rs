//! Where the rig sections run, through the full driver stack: the
//! register-level simulated card (virtual or real time) or the real PC104
//! card. One experiment at a time, each run's recording saved as CSV next
//! to the report.

use std::path::PathBuf;

use ctrlab::hw::{
    Clock, Jitter, LoopConfig, LoopFault, LoopStats, RealTime, RigError, RunError, RunOutcome,
    StopSignal, VirtualClock, run,
};
use ctrlab::lab::ident_input::IdentInput;
use ctrlab::lab::protocol::PERIOD;
use ctrlab::lab::{Calibration, CardSettings, FrictionPlant, MassSpring, SimulatedRig};
use ctrlab::nalgebra::SVector;
use ctrlab::{Controller, Recording};

use crate::cli::Args;

/// Where the rig sections run, and how.
pub struct Backend {
    pub kind: BackendKind,
    /// Real-time scheduling for the loop (`--rt-priority`).
    pub realtime: Option<RealTime>,
    /// Ctrl-C, SIGTERM, SIGHUP, SIGQUIT and Ctrl-Z stop the run in
    /// progress (the rig halts).
    pub stop: StopSignal,
    /// Where each run's CSV goes (`runs/` under it).
    pub out: PathBuf,
    /// How many recordings this lab wrote, for the closing summary.
    saved: std::rc::Rc<std::cell::Cell<usize>>,
    /// The identification input asked for: the card file's `[ident]` (or
    /// the lab's default) with `--ident-*` on top.
    pub ident: IdentInput,
}

pub enum BackendKind {
    /// The register-level simulated card with `sim` inside (`--truth`),
    /// virtual or real time; on a virtual clock, its ticks late and
    /// stalled by `jitter` (`--jitter`).
    Simulated {
        sim: Box<SimulatedRig>,
        real_time: bool,
        jitter: Option<Jitter>,
    },
    /// The real PC104 card on a parallel port, with its card file's map
    /// and calibration.
    #[cfg(all(feature = "ppdev", target_os = "linux"))]
    Card {
        port: PathBuf,
        config: Box<ctrlab::lab::RigConfig>,
    },
}

/// A run's names: its recording's file stem (`runs/{file}.csv`), which
/// says what ran, and the key its jittered clock's schedule is drawn from
/// (`--jitter`). The key is the run's name from before the recordings were
/// named for what ran, so that the same `--jitter` still gives the same
/// report.
pub struct RunId {
    pub file: String,
    pub schedule: String,
}

impl RunId {
    /// A run whose file stem is its schedule's key.
    pub fn new(file: impl Into<String>) -> Self {
        let file = file.into();
        Self {
            schedule: file.clone(),
            file,
        }
    }

    /// A run saved as `file` whose schedule is keyed by `schedule`.
    pub fn keyed(file: impl Into<String>, schedule: impl Into<String>) -> Self {
        Self {
            file: file.into(),
            schedule: schedule.into(),
        }
    }
}

/// The loop's timing over a section's runs (real-time or jittered runs).
pub struct LoopTiming {
    /// How the loop was scheduled, in words: SCHED_FIFO (`--rt-priority`),
    /// normal scheduling, or the jittered virtual clock (`--jitter`).
    pub clock: &'static str,
    /// Worst 99th percentile of the tick's lateness, s.
    pub lateness_p99: f64,
    /// Worst lateness, s.
    pub lateness_max: f64,
    /// Overruns, summed over the runs.
    pub overruns: usize,
    /// Skipped ticks, summed.
    pub skipped: usize,
    /// Late ticks (sampled after their deadline), summed.
    pub late: usize,
    /// Longest interval between samples, s.
    pub max_interval: f64,
}

impl Backend {
    /// The backend the arguments ask for: the simulated rig (its truth file
    /// read and checked) or, after printing what it will do and checking
    /// the card's ID, the real card. Then Ctrl-C halts the rig.
    pub fn new(args: &Args) -> Result<Self, Box<dyn std::error::Error>> {
        let realtime = args.rt_priority.map(|priority| RealTime {
            priority,
            ..RealTime::default()
        });
        // First the backend: before Ctrl-C is caught, so that it still ends
        // the process during the real card's countdown, before anything is
        // driven.
        let kind = kind(args)?;
        let base = match &kind {
            BackendKind::Simulated { sim, .. } => sim.ident,
            #[cfg(all(feature = "ppdev", target_os = "linux"))]
            BackendKind::Card { config, .. } => config.ident,
        };
        let ident = args.ident_input(base);
        ident.validate()?;
        // --ident-volts above the drive's range: refused, named, before
        // anything runs (the card file's [ident] was checked on reading).
        let full_scale = match &kind {
            BackendKind::Simulated { sim, .. } => sim.calibration.volts_full_scale,
            #[cfg(all(feature = "ppdev", target_os = "linux"))]
            BackendKind::Card { config, .. } => config.calibration.volts_full_scale,
        };
        ident
            .check_drive(full_scale)
            .map_err(|e| format!("--ident-volts (or the card file's ident.volts): {e}"))?;
        // Then Ctrl-C halts the rig and ends the run with its recording,
        // instead of killing the process with the motor at its last duty.
        let stop = StopSignal::on_interrupt()?;
        Ok(Self {
            kind,
            realtime,
            stop,
            out: args.out.clone(),
            saved: std::rc::Rc::default(),
            ident,
        })
    }

    /// The simulated rig, when there is one.
    pub fn sim(&self) -> Option<&SimulatedRig> {
        match &self.kind {
            BackendKind::Simulated { sim, .. } => Some(sim),
            #[cfg(all(feature = "ppdev", target_os = "linux"))]
            BackendKind::Card { .. } => None,
        }
    }

    /// The plant behind a simulated rig, when there is one.
    pub fn truth(&self) -> Option<MassSpring> {
        // Cart 2 with the rotor: the linear plant the carts really are.
        self.sim().map(SimulatedRig::effective_truth)
    }

    /// The plant and Coulomb friction behind a simulated rig, as the
    /// identification is judged against: cart 2's effective mass (with the
    /// rotor) and the nominal friction, the mean of the runs' draws
    /// (`Unmodelled::draw_friction`).
    pub fn friction_truth(&self) -> Option<FrictionPlant> {
        self.sim().map(|s| {
            FrictionPlant::new(s.effective_truth(), s.friction.coulomb)
                .with_stiction(s.friction.stiction)
        })
    }

    /// The card's calibration: the simulated card's, or the real card's
    /// from its card file (its encoders, drive full scale, travel limits).
    pub fn calibration(&self) -> Calibration {
        match &self.kind {
            BackendKind::Simulated { sim, .. } => sim.calibration,
            #[cfg(all(feature = "ppdev", target_os = "linux"))]
            BackendKind::Card { config, .. } => config.calibration,
        }
    }

    pub fn real_time(&self) -> bool {
        match &self.kind {
            BackendKind::Simulated { real_time, .. } => *real_time,
            #[cfg(all(feature = "ppdev", target_os = "linux"))]
            BackendKind::Card { .. } => true,
        }
    }

    /// The virtual clock's schedule of late ticks and stalls (`--jitter`).
    pub fn jitter(&self) -> Option<Jitter> {
        match &self.kind {
            BackendKind::Simulated { jitter, .. } => *jitter,
            #[cfg(all(feature = "ppdev", target_os = "linux"))]
            BackendKind::Card { .. } => None,
        }
    }

    /// The same backend on another simulated card (the equal-springs run).
    pub fn with_sim(&self, sim: SimulatedRig) -> Self {
        Self {
            kind: BackendKind::Simulated {
                sim: Box::new(sim),
                real_time: self.real_time(),
                jitter: self.jitter(),
            },
            realtime: self.realtime,
            stop: self.stop.clone(),
            out: self.out.clone(),
            saved: self.saved.clone(),
            ident: self.ident,
        }
    }

    /// One experiment from rest: `controller` against the rig for
    /// `duration` s with reference `reference(t)`, its recording saved as
    /// `runs/{id.file}.csv`. The outer error is a set-up failure (or
    /// Ctrl-C), the inner one the run's own (with its recording).
    pub fn experiment(
        &self,
        id: &RunId,
        seed: u64,
        controller: impl Controller<4, 1, 1>,
        reference: impl FnMut(f64) -> SVector<f64, 1>,
        duration: f64,
    ) -> Result<Result<RunOutcome, Box<RunError>>, Box<dyn std::error::Error>> {
        let mut loop_config = LoopConfig {
            duration,
            realtime: self.realtime,
            stop: Some(self.stop.clone()),
            ..LoopConfig::default()
        };
        if self.jitter().is_some() {
            // The clock double's skipped deadlines are what is under test
            // (the default schedule skips about 25 per 0.5 s, the default
            // limit): the analyses must take them, so they never stop a
            // run. A stall still stops it past the gap limit (50 ms).
            loop_config.max_timing_faults = usize::MAX;
        }
        let outcome = match &self.kind {
            BackendKind::Simulated {
                sim,
                real_time,
                jitter,
            } => {
                let sim = SimulatedRig {
                    card: CardSettings { seed, ..sim.card },
                    period: PERIOD,
                    ..(**sim).clone()
                };
                let clock = match (real_time, jitter) {
                    (true, _) => Clock::RealTime,
                    (false, None) => Clock::Virtual(VirtualClock::new()),
                    (false, Some(j)) => Clock::Virtual(
                        VirtualClock::new().with_jitter(run_schedule(j, &id.schedule))?,
                    ),
                };
                let rig = sim.rig(&clock)?;
                run(rig, controller, reference, &clock, &loop_config)
            }
            #[cfg(all(feature = "ppdev", target_os = "linux"))]
            BackendKind::Card { port, config } => {
                let _ = seed; // the real rig has its own noise
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
        let path = self.save(&id.file, recording)?;
        if let Err(e) = &outcome
            && let RigError::Fault(LoopFault::Interrupted { .. }) = e.error
        {
            return Err(format!("{e}; the run's recording is in {}", path.display()).into());
        }
        Ok(outcome)
    }

    /// Saves `recording` as `runs/{name}.csv`; returns the path.
    pub fn save(
        &self,
        name: &str,
        recording: &Recording,
    ) -> Result<PathBuf, Box<dyn std::error::Error>> {
        let dir = self.out.join("runs");
        std::fs::create_dir_all(&dir)?;
        let path = dir.join(format!("{name}.csv"));
        recording.write_csv(&path)?;
        self.saved.set(self.saved.get() + 1);
        Ok(path)
    }

    /// How many recordings this backend wrote.
    pub fn recordings(&self) -> usize {
        self.saved.get()
    }

    /// The loop's timing over `stats`, for real-time or jittered runs (on
    /// the ideal virtual clock every tick is on time).
    pub fn timing(&self, stats: &[LoopStats]) -> Option<LoopTiming> {
        if !(self.real_time() || self.jitter().is_some()) || stats.is_empty() {
            return None;
        }
        let worst = |f: fn(&LoopStats) -> f64| stats.iter().map(f).fold(0.0, f64::max);
        Some(LoopTiming {
            clock: match (self.jitter(), self.realtime) {
                (Some(_), _) => "the jittered virtual clock",
                (None, Some(_)) => "SCHED_FIFO",
                (None, None) => "normal scheduling",
            },
            lateness_p99: worst(|s| s.lateness_p99),
            lateness_max: worst(|s| s.lateness_max),
            overruns: stats.iter().map(|s| s.overruns).sum(),
            skipped: stats.iter().map(|s| s.skipped).sum(),
            late: stats.iter().map(|s| s.late).sum(),
            max_interval: worst(|s| s.max_interval),
        })
    }
}

fn kind(args: &Args) -> Result<BackendKind, Box<dyn std::error::Error>> {
    match &args.port {
        None => {
            let sim = match &args.truth {
                Some(path) => SimulatedRig::read_toml(path)?,
                None => SimulatedRig::default(),
            };
            sim.validate()?;
            Ok(BackendKind::Simulated {
                sim: Box::new(sim),
                real_time: args.real_time,
                jitter: args.jitter,
            })
        }
        #[cfg(all(feature = "ppdev", target_os = "linux"))]
        Some(port) => {
            let (file, config) =
                crate::card::load(port, args.card.as_deref(), args.no_watchdog_acknowledged)?;
            println!(
                "{}",
                card_plan(
                    port,
                    file,
                    &config,
                    &args.ident_input(config.ident),
                    args.tables_only
                )
            );
            let id = crate::card::check_id(port, &config)?;
            println!(
                "The card answers {id:#04x} at register {:#04x}, as the card file says.\n\
                 Keep a hand on the emergency stop. Starting in 10 s (Ctrl-C to abort).",
                config.map.id
            );
            std::thread::sleep(std::time::Duration::from_secs(10));
            Ok(BackendKind::Card {
                port: port.clone(),
                config: Box::new(config),
            })
        }
        #[cfg(not(all(feature = "ppdev", target_os = "linux")))]
        Some(_) => Err(
            "--port needs the `ppdev` feature on Linux: cargo run --release \
                        --example lab5 --features ppdev -- --port /dev/parport0 --card card.toml"
                .into(),
        ),
    }
}

#[cfg(all(feature = "ppdev", target_os = "linux"))]
/// What the run will do, for the person at the rig to check before the
/// first register access.
fn card_plan(
    port: &std::path::Path,
    card: &std::path::Path,
    config: &ctrlab::lab::RigConfig,
    ident: &IdentInput,
    tables_only: bool,
) -> String {
    use ctrlab::lab::ident_input::{PROBE_DURATION, PROBE_FRACTIONS, TRAVEL_FRACTION};
    let cal = &config.calibration;
    let what = config
        .to_string()
        .lines()
        .map(|line| format!("  {line}\n"))
        .collect::<String>();
    format!(
        "About to run the rig sections on the REAL card.\n\
         port: {port}\n\
         card file: {card}\n\
         {what}\
         runs: {probes}5 open-loop runs of 5 s with a {signal} of {ident_volts}, {further}\
         saturated at ±{full} V, 3 s pauses between runs; each run \
         halts the motor at the first fault (travel limit, bus fault, stall, a dead cart-2 encoder, \
         the drive held at its limit, timing, Ctrl-C and the other stop signals).\n\
         Nothing has been written to the card. Next: open the port and read the ID register \
         {id:#04x} (a read only).",
        port = port.display(),
        card = card.display(),
        full = cal.volts_full_scale,
        id = config.map.id,
        signal = ident.signal,
        further = if tables_only {
            "then 24 closed-loop runs of 3 s for Tables 5 and 6 (--tables-only: no excitation, \
             frequency response or design runs)"
        } else {
            "20 more of 5 s comparing inputs of the same peak (square wave, PRBS, multisine, \
             chirp), a multisine for the frequency response, then 26 closed-loop runs of 3 s \
             (24 for Tables 5 and 6, 2 for the Design section's LQI)"
        },
        probes = if ident.scale_to_travel {
            format!(
                "2 probe runs of {PROBE_DURATION} s at {} and {} V, ",
                PROBE_FRACTIONS[0] * ident.volts,
                PROBE_FRACTIONS[1] * ident.volts
            )
        } else {
            String::new()
        },
        ident_volts = if ident.scale_to_travel {
            format!(
                "at most ±{} V (lowered to keep both carts within {:.0} % of their travel)",
                ident.volts,
                TRAVEL_FRACTION * 100.0
            )
        } else {
            format!("±{} V (fixed)", ident.volts)
        },
    )
}

/// Run `name`'s own schedule from `jitter`: its seed mixed with the run's
/// name (FNV-1a), so that no two runs are late on the same ticks and the
/// same `--jitter` still gives the same report.
fn run_schedule(jitter: &Jitter, name: &str) -> Jitter {
    let hash = name.bytes().fold(0xcbf2_9ce4_8422_2325_u64, |h, b| {
        (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
    });
    Jitter {
        seed: jitter.seed ^ hash,
        ..*jitter
    }
}
