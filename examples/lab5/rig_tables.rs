//! Tables 5 and 6 on the rig: every row of `lab::tables::TABLE5` and
//! `TABLE6` run, with what the identified model predicted for it.

use ctrlab::Recording;
use ctrlab::lab::MassSpring;
use ctrlab::lab::protocol::PERIOD;
use ctrlab::lab::tables::{GainTable, Prediction, RigRun};

use crate::backend::{Backend, LoopTiming, RunId};

/// One table's runs.
pub struct RigTable {
    pub table: GainTable,
    /// The drive's full scale the runs saturate at, V.
    pub volts_full_scale: f64,
    /// The rows, each with its recording (to the halt, if it halted).
    pub runs: Vec<(RigRun, Recording)>,
    /// Each row's recording's name, `runs/{name}.csv`.
    pub names: Vec<String>,
    pub timing: Option<LoopTiming>,
}

impl RigTable {
    /// The rows' outcomes in order.
    pub fn outcomes(&self) -> Vec<ctrlab::lab::tables::RigOutcome> {
        self.runs.iter().map(|(r, _)| r.outcome.clone()).collect()
    }
}

/// Runs every row of `table` on the rig, seeds 100 + i; the identified
/// `model` says what to expect. Each row is the library's `Experiment`
/// (its controller, reference and metrics), the same path as `cargo run
/// --example experiment` running it alone, and its recording is named as
/// that program names it, after the table:
/// `runs/table5_cart2_kf_0_0_10_0.1_to_30mm.csv`.
pub fn run(
    backend: &Backend,
    model: &MassSpring,
    table: GainTable,
) -> Result<RigTable, Box<dyn std::error::Error>> {
    let volts_full_scale = backend.calibration().volts_full_scale;
    let mut runs = Vec::new();
    let mut stats = Vec::new();
    let mut names = Vec::new();
    for (i, kf) in table.rows().into_iter().enumerate() {
        let experiment = table
            .experiment(i)
            .ok_or("a table row without its experiment")?;
        let prediction = Prediction::of(model, kf, table.cart, PERIOD)?;
        let id = RunId::keyed(
            format!("table{}_{experiment}", table.number),
            format!("table{}_row{}", table.number, i + 1),
        );
        let run = experiment.measure(
            backend.experiment(
                &id,
                table.row_seed(i),
                experiment.controller()?,
                experiment.reference(),
                experiment.duration,
            )?,
            volts_full_scale,
        )?;
        stats.push(run.stats);
        names.push(id.file);
        runs.push((
            RigRun {
                kf,
                prediction,
                outcome: run.outcome,
            },
            run.recording,
        ));
    }
    Ok(RigTable {
        table,
        volts_full_scale,
        runs,
        names,
        timing: backend.timing(&stats),
    })
}
