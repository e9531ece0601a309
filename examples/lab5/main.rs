//! The whole of Lab 5 ("State feedback control" of the two-cart rig), end to
//! end, on the simulated rig through the full driver stack
//! (`lab::MassSpringRig` → `Pc104` → `SimulatedCard`) with a virtual clock:
//!
//! - Tables 1 and 2 in simulation (nominal model);
//! - the identification input's amplitude, chosen from two short probe runs
//!   so that neither cart is predicted past 60 % of its travel
//!   (`lab::ident_input`; `--ident-*` to choose the signal and amplitude);
//! - five identification runs on the rig (a run the rig halts is reported
//!   and left out), Tables 3 and 4 with averages, by
//!   the lab's formulas and the bias-free central scheme, and the identified
//!   state equations;
//! - Tables 5 and 6 run on the rig with the lab's gains;
//! - the answers the lab report asks for, stated from the numbers.
//!
//! With `--jitter SEED` the simulated rig runs on a virtual clock whose
//! ticks come late and stall as on a loaded machine (`hw::Jitter`, seeded
//! and reproducible; or `--jitter SEED,LATE_FRACTION,MAX_LATE_S,
//! STALL_FRACTION,STALL_S`): every section takes the late samples and the
//! gaps of skipped ticks, and the report counts them beside each section's
//! runs.
//!
//! With `--logs DIR` lab5 works offline on a student's own recordings
//! instead: Tables 1 and 2 in simulation, then Tables 3 and 4, the
//! identified model with its uncertainty, and the validation from every
//! `*.csv` in `DIR` (the rig sections need a rig and are skipped).
//!
//! Writes `report.md`, one SVG per table and every run's recording as CSV
//! (`runs/`) into `--out DIR` (default `target/lab5`). Ctrl-C halts the rig,
//! keeps the run's recording and the report so far; so do SIGTERM, a closed
//! terminal (SIGHUP), Ctrl-\\ (SIGQUIT) and Ctrl-Z (SIGTSTP), which stops the
//! run rather than suspending lab5 with the motor on.
//!
//! ```text
//! cargo run --release --example lab5
//! cargo run --release --example lab5 -- --out my_report      # elsewhere
//! cargo run --release --example lab5 -- --truth truth.toml   # another simulated rig
//! cargo run --release --example lab5 -- --logs my_runs        # Tables 3 and 4 from my CSV logs
//! cargo run --release --example lab5 -- --ident-signal prbs --ident-volts 6   # another input
//! cargo run --release --example lab5 -- --jitter 11          # late ticks and stalls, seeded
//! cargo run --release --example lab5 -- --real-time          # wall-clock loop (about two minutes)
//! cargo run --release --example lab5 -- --real-time --rt-priority 80   # with SCHED_FIFO
//! cargo run --release --example lab5 --features ppdev -- --port /dev/parport0 --card card.toml
//!                                                             # the real card, from its card file
//! ```
//!
//! One row at a time, as at the rig, is `examples/experiment` (`cargo run
//! --release --example experiment -- --cart 2 --kf 0,0,10,0.1 --setpoint
//! 30mm`): the same `lab::tables::Experiment` this program runs each row of
//! Tables 5 and 6 through, so it prints the batch's numbers.
//!
//! The program is the library's lab sections in order: each section runs
//! its experiments on the backend ([`backend`]), calls the library's
//! computation for it (`ctrlab::lab::tables`, `lab::ident::summarize`,
//! `lab::excitation`, `lab::validation`, `lab::frequency`, `lab::lqi`) and
//! returns a typed result, which the one renderer ([`report`]) turns into
//! Markdown and figures as soon as it is there. The command line is
//! [`cli::Args`]: every argument is checked before anything runs.
//!
//! The real card needs its card file (`--card`, a `ctrlab::lab::RigConfig`,
//! written by `cargo run --example probe --features ppdev -- --port
//! /dev/parport0`): lab5 prints what it will do, reads the card's ID (a
//! read only), and drives nothing unless the card answers with the ID the
//! file names. A card file saying `watchdog_timeout = "none"` is refused
//! unless it also says `no_watchdog_acknowledged = true`, or lab5 is given
//! `--no-watchdog-acknowledged`: then nothing on the card stops the motor
//! if lab5 stops driving it (the loop still halts after 25 periods without
//! a sample).

#[cfg(all(feature = "ppdev", target_os = "linux"))]
mod card;

mod backend;
mod cli;
mod design;
mod excitation;
mod frequency;
mod identification;
mod report;
mod rig_tables;

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use clap::Parser;
use ctrlab::data::CsvOptions;
use ctrlab::lab::SimulatedRig;
use ctrlab::lab::ident::SimulationModel;
use ctrlab::lab::tables::{RIG_TABLES, table1, table2};
use ctrlab::lab::validation::validate_models;

use backend::Backend;
use report::Report;

fn main() -> ExitCode {
    let args = cli::Args::parse();
    match lab(&args) {
        Ok(path) => {
            println!("report written to {}", path.display());
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("lab5: {e}");
            ExitCode::FAILURE
        }
    }
}

/// What lab5 works on.
enum Mode<'a> {
    /// The rig sections on a backend.
    Rig(Box<Backend>),
    /// A student's logs in a directory, with the encoders' calibration.
    Logs(&'a Path, Option<f64>),
}

fn lab(args: &cli::Args) -> Result<PathBuf, Box<dyn std::error::Error>> {
    let started = Instant::now();
    // The backend before anything is written: a bad truth or card file, or
    // a card that does not answer, stops here.
    let mode = match &args.logs {
        Some(dir) => Mode::Logs(dir, args.metres_per_count),
        None => Mode::Rig(Box::new(Backend::new(args)?)),
    };
    std::fs::create_dir_all(&args.out)?;
    let mut report = Report::new(&args.out);
    let result = match &mode {
        Mode::Rig(backend) => rig_sections(backend, &mut report),
        Mode::Logs(dir, metres_per_count) => offline_sections(dir, *metres_per_count, &mut report),
    };
    if let Err(e) = &result {
        // Keep what was measured: the report so far, with the reason.
        report.stopped_early(e.as_ref());
    }
    report.run_time(started.elapsed().as_secs_f64());
    let path = report.write()?;
    result.map(|()| path)
}

/// Every section on the rig: Tables 1 and 2 in simulation, the
/// identification, excitation, validation and frequency response, Tables 5
/// and 6, the design, and the answers.
fn rig_sections(backend: &Backend, report: &mut Report) -> Result<(), Box<dyn std::error::Error>> {
    report.title("cargo run --release --example lab5");
    report.table1(&table1()?)?;
    let table2 = table2()?;
    report.table2(&table2)?;
    let truth = backend.friction_truth();
    let (runs, source) = identification::rig_runs(backend)?;
    if let identification::Source::Rig { input, .. } = &source {
        report.identification_input(input, &runs);
    }
    let mut ident = identification::identify(runs, source)?;
    report.identification(Some(backend), &ident, truth.as_ref())?;
    let volts = ident.volts();
    ident.equal_springs = identification::equal_springs(backend, volts)?;
    if let Some(e) = &ident.equal_springs {
        report.equal_springs(e);
    }
    let excitation = excitation::section(backend, volts)?;
    report.excitation(excitation.volts, &excitation.inputs);
    let model = backend
        .sim()
        .map_or_else(SimulationModel::default, SimulatedRig::simulation_model);
    match &excitation.fresh {
        Some(fresh) => {
            let v = validate_models(
                &ident.summary,
                &ident.recordings(),
                fresh,
                truth.as_ref(),
                &model,
            )?;
            let first = ident.runs.first().ok_or("no identification run")?;
            report.validation(
                &v,
                (&first.name, excitation::FRESH_RUN),
                &model,
                truth.as_ref(),
            );
        }
        None => report.validation_not_possible(),
    }
    report.frequency(&frequency::section(backend, &ident)?)?;
    let mut rig = Vec::new();
    for table in RIG_TABLES {
        let t = rig_tables::run(backend, &ident.model(), table)?;
        report.rig_table(backend, &t)?;
        rig.push(t);
    }
    report.design(backend, &design::section(backend, &ident)?)?;
    report.answer_model(Some(backend), &ident);
    report.effects(&ident, &table2, &rig);
    Ok(())
}

/// `--logs DIR`: Tables 1 and 2 in simulation, then identification and
/// validation from the logs; no rig.
fn offline_sections(
    dir: &Path,
    metres_per_count: Option<f64>,
    report: &mut Report,
) -> Result<(), Box<dyn std::error::Error>> {
    report.title(&format!(
        "cargo run --release --example lab5 -- --logs {}",
        dir.display()
    ));
    report.table1(&table1()?)?;
    report.table2(&table2()?)?;
    let options = CsvOptions { metres_per_count };
    let (runs, source) = identification::log_runs(dir, &options)?;
    let ident = identification::identify(runs, source)?;
    report.identification(None, &ident, None)?;
    match (ident.runs.first(), ident.runs.get(1)) {
        (Some(first), Some(fresh)) => {
            let model = SimulationModel::default();
            let v = validate_models(
                &ident.summary,
                &ident.recordings(),
                &fresh.recording,
                None,
                &model,
            )?;
            report.validation(&v, (&first.name, &fresh.name), &model, None);
        }
        _ => report.validation_not_possible(),
    }
    report.answer_model(None, &ident);
    report.offline_answers();
    Ok(())
}
