//! lab5's command line: every argument parsed and checked before anything
//! runs (clap prints the error, naming the argument, and exits with 2).

use std::path::PathBuf;

use clap::Parser;
use ctrlab::hw::Jitter;
use ctrlab::lab::ident_input::{IdentInput, IdentSignal};
use ctrlab::lab::protocol::PERIOD;

use crate::paths::{existing_file, out_dir};

/// The whole of Lab 5 (state feedback control of the two-cart rig): every
/// table, the identification, validation, frequency response and design,
/// written to DIR/report.md with its figures and every run's recording.
///
/// Without --logs it runs on the built-in simulated rig (or --truth FILE,
/// or the real card with --port and --card). With --logs it works offline
/// on a student's recorded runs.
#[derive(Debug, Parser)]
#[command(
    name = "lab5",
    after_help = "Examples:
  cargo run --release --example lab5
  cargo run --release --example lab5 -- --out my_report
  cargo run --release --example lab5 -- --tables-only
  cargo run --release --example lab5 -- --truth truth.toml
  cargo run --release --example lab5 -- --logs my_runs --metres-per-count 0.000009765625
  cargo run --release --example lab5 -- --real-time --rt-priority 80
  cargo run --release --example lab5 -- --jitter 11
  cargo run --release --example lab5 -- --jitter 11,0.2,0.006,0.01,0.016
  cargo run --release --example lab5 -- --ident-signal prbs --ident-volts 6
  cargo run --release --example lab5 -- --ident-volts 12 --ident-fixed
  cargo run --release --example lab5 --features ppdev -- --port /dev/parport0 --card card.toml"
)]
pub struct Args {
    /// Where report.md, the SVGs, tables/*.csv and runs/*.csv go (created
    /// if missing)
    #[arg(long, value_name = "DIR", default_value = "target/lab5", value_parser = out_dir)]
    pub out: PathBuf,
    /// The simulated rig from a TOML file (see ctrlab::lab::SimulatedRig)
    #[arg(long, value_name = "FILE", value_parser = existing_file, conflicts_with = "port")]
    pub truth: Option<PathBuf>,
    /// Run the rig sections on the wall clock instead of virtual time
    #[arg(long)]
    pub real_time: bool,
    /// Simulated rig on a virtual clock whose ticks come late and stall as
    /// on a loaded machine (seeded, reproducible): SEED alone is 10 % of
    /// ticks late by up to 6 ms and 0.5 % stalled for 8–16 ms; or
    /// SEED,LATE_FRACTION,MAX_LATE_S,STALL_FRACTION,STALL_S. Skipped ticks
    /// never stop a run here; the report counts them
    #[arg(
        long,
        value_name = "SEED[,...]",
        value_parser = jitter,
        allow_hyphen_values = true,
        conflicts_with_all = ["real_time", "port"]
    )]
    pub jitter: Option<Jitter>,
    /// Run the loop with SCHED_FIFO priority N, memory locked (Linux)
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(i32).range(1..=99), allow_hyphen_values = true)]
    pub rt_priority: Option<i32>,
    /// Run the rig sections on the real PC104 card on this parallel port
    /// (feature `ppdev`); needs --card
    #[arg(long, value_name = "PATH")]
    pub port: Option<PathBuf>,
    /// The real card's register map and calibration (ctrlab::lab::RigConfig),
    /// written by the probe
    #[arg(long, value_name = "FILE", value_parser = existing_file, requires = "port")]
    pub card: Option<PathBuf>,
    /// Drive a card whose card file says `watchdog_timeout = "none"`: nothing
    /// on it stops the motor if this program stops driving it (as
    /// `no_watchdog_acknowledged = true` in the card file). Keep a hand on
    /// the emergency stop
    #[arg(long, requires = "card")]
    pub no_watchdog_acknowledged: bool,
    /// Offline: identify from every *.csv in DIR (two or more identification
    /// runs: columns t, u, x1, x2 with units, e.g. t_s;u_V;x1_mm;x2_mm)
    #[arg(
        long,
        value_name = "DIR",
        value_parser = existing_dir,
        conflicts_with_all = ["truth", "real_time", "rt_priority", "port", "card", "jitter"]
    )]
    pub logs: Option<PathBuf>,
    /// With --logs: the encoders' calibration, m per count, for positions
    /// logged in counts
    #[arg(long, value_name = "M", value_parser = positive_metres, allow_hyphen_values = true, requires = "logs")]
    pub metres_per_count: Option<f64>,
    /// The identification input's signal: square (the lab's), prbs or
    /// multisine [default: square, or the card or truth file's [ident] signal]
    #[arg(long, value_name = "SIGNAL", value_parser = ident_signal, conflicts_with = "logs")]
    pub ident_signal: Option<IdentSignal>,
    /// The identification input's peak voltage asked for, V: lowered to
    /// keep both carts within 60 % of their travel (from two short probe
    /// runs) unless --ident-fixed [default: 8, or the card or truth file's]
    #[arg(long, value_name = "V", value_parser = ident_volts, allow_hyphen_values = true, conflicts_with = "logs")]
    pub ident_volts: Option<f64>,
    /// The square wave's half period, s [default: 0.2, or the card or truth file's]
    #[arg(long, value_name = "S", value_parser = ident_half_period, allow_hyphen_values = true, conflicts_with = "logs")]
    pub ident_half_period: Option<f64>,
    /// Run the identification input at --ident-volts as is: no probe runs,
    /// no scaling to the travel (a run that hits a travel limit is
    /// reported and the lab goes on with the others)
    #[arg(long, conflicts_with = "logs")]
    pub ident_fixed: bool,
    /// Only Tables 1–6 and the answers: skip the further sections
    /// (excitation, validation, frequency response, design) and their runs,
    /// for less time at the rig. The runs kept give the same numbers
    #[arg(long)]
    pub tables_only: bool,
}

impl Args {
    /// The identification input: `base` (the card or truth file's, or the lab's
    /// default) with the command line's `--ident-*` on top.
    pub fn ident_input(&self, base: IdentInput) -> IdentInput {
        IdentInput {
            signal: self.ident_signal.unwrap_or(base.signal),
            volts: self.ident_volts.unwrap_or(base.volts),
            half_period: self.ident_half_period.unwrap_or(base.half_period),
            scale_to_travel: base.scale_to_travel && !self.ident_fixed,
        }
    }
}

/// `--ident-signal`: one of [`IdentSignal::ALL`].
fn ident_signal(s: &str) -> Result<IdentSignal, String> {
    s.parse().map_err(|_| {
        let names: Vec<&str> = IdentSignal::ALL.iter().map(|k| k.name()).collect();
        format!("`{s}` is not one of {}", names.join(", "))
    })
}

/// `--ident-volts`: checked as the card file's `ident.volts` is
/// ([`IdentInput::validate`]), with the same reason.
fn ident_volts(s: &str) -> Result<f64, String> {
    let volts: f64 = s.parse().map_err(|_| format!("`{s}` is not a number"))?;
    IdentInput {
        volts,
        ..IdentInput::default()
    }
    .validate()
    .map_err(|e| e.reason().to_owned())?;
    Ok(volts)
}

/// `--ident-half-period`: checked as the card file's `ident.half_period`.
fn ident_half_period(s: &str) -> Result<f64, String> {
    let half_period: f64 = s.parse().map_err(|_| format!("`{s}` is not a number"))?;
    IdentInput {
        half_period,
        ..IdentInput::default()
    }
    .validate()
    .map_err(|e| e.reason().to_owned())?;
    Ok(half_period)
}

/// `--jitter`: a seed alone (the default schedule: 10 % of ticks late by
/// up to three periods, 6 ms, and one in 200 stalled for 4 to 8 periods,
/// 8–16 ms, as tests/late_ticks.rs uses), or the seed and the schedule's
/// four numbers ([`Jitter`]'s fields, durations in s), checked by
/// [`Jitter::validate`] with its reason.
fn jitter(s: &str) -> Result<Jitter, String> {
    let mut fields = s.split(',').map(str::trim);
    let seed = fields.next().unwrap_or_default();
    let seed: u64 = seed
        .parse()
        .map_err(|_| format!("`{seed}` is not a seed (an integer >= 0)"))?;
    let rest: Vec<f64> = fields
        .map(|f| f.parse().map_err(|_| format!("`{f}` is not a number")))
        .collect::<Result<_, _>>()?;
    let jitter = match rest[..] {
        [] => Jitter {
            seed,
            late_fraction: 0.1,
            max_late: 3.0 * PERIOD,
            stall_fraction: 0.005,
            stall: 8.0 * PERIOD,
        },
        [late_fraction, max_late, stall_fraction, stall] => Jitter {
            seed,
            late_fraction,
            max_late,
            stall_fraction,
            stall,
        },
        _ => {
            return Err(format!(
                "`{s}` is SEED or SEED,LATE_FRACTION,MAX_LATE_S,STALL_FRACTION,STALL_S"
            ));
        }
    };
    jitter
        .validate()
        .map_err(|e| format!("{}: {}", e.key(), e.reason()))?;
    Ok(jitter)
}

/// A directory that exists.
fn existing_dir(s: &str) -> Result<PathBuf, String> {
    let path = PathBuf::from(s);
    if !path.is_dir() {
        return Err(format!("`{s}` is not a directory"));
    }
    Ok(path)
}

/// A length per count: finite and positive, m.
fn positive_metres(s: &str) -> Result<f64, String> {
    let m: f64 = s.parse().map_err(|_| format!("`{s}` is not a number"))?;
    if !(m.is_finite() && m > 0.0) {
        return Err(format!("`{s}` must be a finite length > 0, m"));
    }
    Ok(m)
}
