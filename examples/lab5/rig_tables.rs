//! Tables 5 and 6 on the rig: every row of `lab::tables::TABLE5` and
//! `TABLE6` run, with what the identified model predicted for it.

use ctrlab::Recording;
use ctrlab::lab::protocol::{PERIOD, STEP_DURATION};
use ctrlab::lab::tables::{GainTable, Prediction, RigOutcome, RigRun};
use ctrlab::lab::{LabGains, MassSpring};
use ctrlab::nalgebra::vector;

use crate::backend::{Backend, LoopTiming};

/// One table's runs.
pub struct RigTable {
    pub table: GainTable,
    /// The drive's full scale the runs saturate at, V.
    pub volts_full_scale: f64,
    /// The rows, each with its recording (to the halt, if it halted).
    pub runs: Vec<(RigRun, Recording)>,
    pub timing: Option<LoopTiming>,
}

impl RigTable {
    /// The rows' outcomes in order.
    pub fn outcomes(&self) -> Vec<ctrlab::lab::tables::RigOutcome> {
        self.runs.iter().map(|(r, _)| r.outcome.clone()).collect()
    }
}

/// Runs every row of `table` on the rig (`runs/table{n}_row{i}.csv`,
/// seeds 100 + i); the identified `model` says what to expect.
pub fn run(
    backend: &Backend,
    model: &MassSpring,
    table: GainTable,
) -> Result<RigTable, Box<dyn std::error::Error>> {
    let volts_full_scale = backend.calibration().volts_full_scale;
    let setpoint = table.setpoint_mm / 1e3;
    let mut runs = Vec::new();
    let mut stats = Vec::new();
    for (i, kf) in table.rows().into_iter().enumerate() {
        let prediction = Prediction::of(model, kf, table.cart, PERIOD)?;
        let name = format!("table{}_row{}", table.number, i + 1);
        let ctrl = LabGains::new(kf, table.cart).state_feedback()?;
        let (outcome, rec) = match backend.experiment(
            &name,
            100 + i as u64,
            ctrl,
            |_| vector![setpoint],
            STEP_DURATION,
        )? {
            Ok(out) => {
                stats.push(out.stats);
                let outcome = RigOutcome::classify(
                    &out.recording,
                    table.cart,
                    table.setpoint_mm,
                    volts_full_scale,
                )?;
                (outcome, out.recording)
            }
            Err(e) => {
                let e = *e;
                stats.push(e.stats);
                (RigOutcome::halted(&e.recording, &e.error), e.recording)
            }
        };
        runs.push((
            RigRun {
                kf,
                prediction,
                outcome,
            },
            rec,
        ));
    }
    Ok(RigTable {
        table,
        volts_full_scale,
        runs,
        timing: backend.timing(&stats),
    })
}
