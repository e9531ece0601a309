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
//! Writes into `--out DIR` (default `target/lab5`):
//!
//! - `report.md`: the title and a contents list; the student's part
//!   (Tables 1 and 2, the identification input and runs with Tables 3 and
//!   4, the identified state equations and their uncertainty, Tables 5
//!   and 6, the answers); then "Further sections" (what the identification
//!   does not recover, excitation, validation, frequency response, design,
//!   constrained MPC).
//!   The sections run in the order the computation needs (the
//!   identification first: Tables 5 and 6 predict from it); the report is
//!   collected in its two parts ([`report::Part`]) and written in this
//!   order, so the runs, their seeds and numbers are those of any order.
//!   `--tables-only` skips the further sections' runs and says so;
//! - one SVG per table and section, written as each section finishes;
//! - `tables/`: every table as CSV (`table1.csv` … `table6.csv`, and
//!   `model.csv`, the identified parameters), units in the headers, linked
//!   under each table;
//! - `runs/`: every run's recording as CSV, named for what ran:
//!   `ident_square_8.00V_seed1.csv` (signal, peak, seed),
//!   `ident_probe1_square_2.00V.csv`, `excite_prbs_8.00V_seed1.csv`,
//!   `table5_cart2_kf_0_0_10_0.1_to_30mm.csv` (the table and
//!   `lab::tables::Experiment`'s name, as `examples/experiment` saves it),
//!   `frequency_multisine.csv`, `design_cart1_rig.csv`, `mpc_cart2_rig.csv`.
//!
//! The terminal gets a line per section as it finishes and a short summary
//! at the end: Tables 5 and 6 by outcome, the identified parameters, and
//! where the report, figures, tables and recordings are. Ctrl-C halts the
//! rig, keeps the run's recording and the report so far (and says where);
//! so do SIGTERM, a closed terminal (SIGHUP), Ctrl-\\ (SIGQUIT) and Ctrl-Z
//! (SIGTSTP), which stops the run rather than suspending lab5 with the
//! motor on.
//!
//! ```text
//! cargo run --release --example lab5
//! cargo run --release --example lab5 -- --out my_report      # elsewhere
//! cargo run --release --example lab5 -- --tables-only        # Tables 1–6 and the answers only
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
//! `lab::excitation`, `lab::validation`, `lab::frequency`, `lab::lqi`,
//! `lab::mpc`) and
//! returns a typed result, which the one renderer ([`report`]) turns into
//! Markdown, figures and CSV tables as soon as it is there. The command line is
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
mod mpc;
mod paths;
mod report;
mod rig_tables;

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use clap::Parser;
use ctrlab::data::CsvOptions;
use ctrlab::lab::ident::SimulationModel;
use ctrlab::lab::tables::{RIG_TABLES, Table2, table1, table2};
use ctrlab::lab::validation::validate_models;
use ctrlab::lab::{FrictionPlant, SimulatedRig};

use backend::Backend;
use report::{Part, Report, terminal};

fn main() -> ExitCode {
    let args = cli::Args::parse();
    match lab(&args) {
        Ok(path) => {
            println!("report written to {}", path.display());
            ExitCode::SUCCESS
        }
        Err(Stopped { error, report }) => {
            eprintln!("lab5: {error}");
            // What was measured before the stop is kept: say where.
            if let Some(path) = report {
                println!(
                    "report written to {} (the lab stopped early)",
                    path.display()
                );
            }
            ExitCode::FAILURE
        }
    }
}

/// Why lab5 did not finish, and where the report so far is (if it could
/// be written).
struct Stopped {
    error: Box<dyn std::error::Error>,
    report: Option<PathBuf>,
}

impl<E: Into<Box<dyn std::error::Error>>> From<E> for Stopped {
    fn from(e: E) -> Self {
        Self {
            error: e.into(),
            report: None,
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

fn lab(args: &cli::Args) -> Result<PathBuf, Stopped> {
    let started = Instant::now();
    // The backend before anything is written: a bad truth or card file, or
    // a card that does not answer, stops here.
    let mode = match &args.logs {
        Some(dir) => Mode::Logs(dir, args.metres_per_count),
        None => Mode::Rig(Box::new(Backend::new(args)?)),
    };
    paths::prepare_out(&args.out, &["runs", "tables"], &["report.md"])?;
    let mut report = Report::new(&args.out);
    let result = match &mode {
        Mode::Rig(backend) => rig_sections(backend, args.tables_only, &mut report),
        Mode::Logs(dir, metres_per_count) => {
            offline_sections(dir, *metres_per_count, args.tables_only, &mut report)
        }
    };
    if let Err(e) = &result {
        // Keep what was measured: the report so far, with the reason.
        report.stopped_early(e.as_ref());
    }
    let seconds = started.elapsed().as_secs_f64();
    report.run_time(seconds);
    let written = report.write();
    if let Ok(path) = &written {
        let recordings = match &mode {
            Mode::Rig(backend) => Some(backend.recordings()),
            Mode::Logs(..) => None,
        };
        let state = if result.is_ok() {
            "finished"
        } else {
            "stopped early"
        };
        print!(
            "\nLab 5 {state} in {seconds:.1} s:\n{}",
            report.summary(path, recordings)
        );
    }
    match (result, written) {
        (Ok(()), Ok(path)) => Ok(path),
        (Ok(()), Err(e)) => Err(e.into()),
        (Err(error), written) => {
            if let Err(e) = &written {
                eprintln!("lab5: the report could not be written either: {e}");
            }
            Err(Stopped {
                error,
                report: written.ok(),
            })
        }
    }
}

/// Every section on the rig, in the order the computation needs: Tables 1
/// and 2 in simulation, the identification, excitation, validation and
/// frequency response, Tables 5 and 6 (on the identified model), the
/// design, and the answers. The report puts Tables 1–6 and the answers
/// first whatever this order ([`Part`]). With `tables_only` the further
/// sections' runs are skipped; the others keep their seeds, so their
/// numbers are the same.
fn rig_sections(
    backend: &Backend,
    tables_only: bool,
    report: &mut Report,
) -> Result<(), Box<dyn std::error::Error>> {
    report.title(&format!(
        "cargo run --release --example lab5{}",
        if tables_only { " -- --tables-only" } else { "" }
    ));
    let table2 = tables_1_and_2(report)?;
    let truth = backend.friction_truth();
    let (runs, source) = identification::rig_runs(backend)?;
    if let identification::Source::Rig { input, .. } = &source {
        report.identification_input(input, &runs);
        report.progress(&format!(
            "Identification input: {} at {:.2} V, {}",
            input.input.signal, input.choice.volts, input.choice.reason
        ));
    }
    let mut ident = identification::identify(runs, source)?;
    report.identification(Some(backend), &ident, truth.as_ref())?;
    report.result(terminal::model_line(&ident));
    let volts = ident.volts();
    // On a simulated card only (no run at the real rig); the answers use it.
    ident.equal_springs = identification::equal_springs(backend, volts)?;
    if let Some(e) = &ident.equal_springs {
        report.equal_springs(e);
    }
    report.part(Part::Further);
    report.unmodelled(backend, &ident)?;
    if tables_only {
        report.skipped(SKIPPED);
    } else {
        model_sections(backend, &ident, truth.as_ref(), report)?;
    }
    report.part(Part::Student);
    let mut rig = Vec::new();
    for table in RIG_TABLES {
        let t = rig_tables::run(backend, &ident.model(), table)?;
        report.rig_table_csv(&t)?;
        report.rig_table(backend, &t)?;
        report.result(terminal::rig_table_line(&t));
        rig.push(t);
    }
    if !tables_only {
        report.part(Part::Further);
        let design = design::section(backend, &ident)?;
        report.design(backend, &design)?;
        report.progress(&format!(
            "Design ({} cases): designed on the identified model, run and compared",
            design.cases.len()
        ));
        let mpc = mpc::section(backend, &ident)?;
        report.mpc(&mpc)?;
        report.progress(&format!(
            "Constrained MPC ({} cases): designed on the identified model, run and compared; {} fallbacks on the rig",
            mpc.cases.len(),
            mpc.cases.iter().map(|c| c.rig.stats.fallbacks()).sum::<usize>()
        ));
        report.part(Part::Student);
    }
    report.answer_model(Some(backend), &ident);
    report.effects(&ident, &table2, &rig);
    report.progress("Answers: written");
    Ok(())
}

/// What the report says `--tables-only` left out.
const SKIPPED: &str = "Skipped with `--tables-only`: the Excitation, Validation, Frequency response, Design and Constrained MPC sections and their runs (four inputs five times each, the multisine, the two designs, the two MPC cases). Run lab5 without `--tables-only` for them.";

/// Tables 1 and 2 in simulation, each with its CSV; Table 2 is kept for
/// the answers.
fn tables_1_and_2(report: &mut Report) -> Result<Table2, Box<dyn std::error::Error>> {
    let t1 = table1()?;
    report.table1_csv(&t1)?;
    report.table1(&t1)?;
    report.progress(&terminal::table1_line(&t1));
    let t2 = table2()?;
    report.table2_csv(&t2)?;
    report.table2(&t2)?;
    report.progress(&terminal::table2_line(&t2));
    Ok(t2)
}

/// The further sections on the identified models: excitation, validation
/// on the excitation's fresh run, frequency response.
fn model_sections(
    backend: &Backend,
    ident: &identification::Identification,
    truth: Option<&FrictionPlant>,
    report: &mut Report,
) -> Result<(), Box<dyn std::error::Error>> {
    let excitation = excitation::section(backend, ident.volts())?;
    report.excitation(excitation.volts, &excitation.inputs);
    report.progress(&format!(
        "Excitation ({} inputs at {:.2} V): {} identified",
        excitation.inputs.len(),
        excitation.volts,
        excitation
            .inputs
            .iter()
            .filter(|i| i.outcome.is_ok())
            .count()
    ));
    let model = backend
        .sim()
        .map_or_else(SimulationModel::default, SimulatedRig::simulation_model);
    match &excitation.fresh {
        Some((fresh, recording)) => {
            let v = validate_models(
                &ident.summary,
                &ident.recordings(),
                recording,
                truth,
                &model,
            )?;
            let first = ident.runs.first().ok_or("no identification run")?;
            report.validation(
                &v,
                (&first.name, &format!("runs/{fresh}.csv")),
                &model,
                truth,
            );
            report.progress(&format!("Validation: on the fresh run {fresh}"));
        }
        None => {
            report.validation_not_possible();
            report.progress("Validation: not possible (no fresh PRBS run)");
        }
    }
    let frequency = frequency::section(backend, ident)?;
    report.frequency(&frequency)?;
    report.progress(match &frequency.response {
        Ok(_) => "Frequency response (1 run): estimated",
        Err(_) => "Frequency response (1 run): the run halted",
    });
    Ok(())
}

/// `--logs DIR`: Tables 1 and 2 in simulation, then identification and
/// validation from the logs; no rig.
fn offline_sections(
    dir: &Path,
    metres_per_count: Option<f64>,
    tables_only: bool,
    report: &mut Report,
) -> Result<(), Box<dyn std::error::Error>> {
    report.title(&format!(
        "cargo run --release --example lab5 -- --logs {}{}",
        dir.display(),
        if tables_only { " --tables-only" } else { "" }
    ));
    tables_1_and_2(report)?;
    let options = CsvOptions { metres_per_count };
    let (runs, source) = identification::log_runs(dir, &options)?;
    let ident = identification::identify(runs, source)?;
    report.identification(None, &ident, None)?;
    report.result(terminal::model_line(&ident));
    report.part(Part::Further);
    if tables_only {
        report.skipped("Skipped with `--tables-only`: the Validation section. Run lab5 without `--tables-only` for it.");
    } else {
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
                report.progress(&format!("Validation: on the fresh run {}", fresh.name));
            }
            _ => report.validation_not_possible(),
        }
    }
    report.part(Part::Student);
    report.answer_model(None, &ident);
    report.offline_answers();
    report.progress("Answers: written");
    Ok(())
}
