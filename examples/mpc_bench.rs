//! Times ctrlab's MPC move on problems read from a JSON file, for
//! `scripts/mpc_vs_python.py`, which solves the same problems with
//! python-control's optimal-control MPC in the same run.
//!
//! ```text
//! cargo run --release --example mpc_bench -- problems.json
//! ```
//!
//! The file is `{"a", "b", "c", "dt", "q", "r", "umax", "xmax", "tracked",
//! "cases": [{"name", "horizon", "x0", "reference", "repeats"}]}`: a
//! discrete model (`c` its measured outputs, matrices as lists of rows),
//! weights, the input limited to ±`umax`, the measured outputs to
//! ±`xmax` (hard), `tracked` the index of the tracked measurement. For
//! each case one line of JSON is printed: the name, the median wall time
//! of `repeats` moves from `x0` (each by a controller fresh from its
//! design, as a step from rest has it: no earlier plan to start from), the
//! first input and the solver's counts.

use std::time::Instant;

use ctrlab::design::mpc::{Estimation, Mpc, MpcDesign, OutputLimit, Row};
use ctrlab::{Discrete, StateSpace};
use nalgebra::{SMatrix, SVector};
use serde_json::{Value, json};

fn matrix<const R: usize, const C: usize>(v: &Value) -> SMatrix<f64, R, C> {
    let rows: Vec<Vec<f64>> = serde_json::from_value(v.clone()).expect("a list of rows");
    SMatrix::from_fn(|i, j| rows[i][j])
}

fn number(v: &Value) -> f64 {
    v.as_f64().expect("a number")
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = std::env::args()
        .nth(1)
        .ok_or("usage: mpc_bench problems.json")?;
    let p: Value = serde_json::from_str(&std::fs::read_to_string(path)?)?;
    let model: StateSpace<4, 1, 2, Discrete> = StateSpace::discrete(
        matrix(&p["a"]),
        matrix(&p["b"]),
        matrix(&p["c"]),
        SMatrix::zeros(),
        number(&p["dt"]),
    )?;
    let (umax, xmax) = (number(&p["umax"]), number(&p["xmax"]));
    let mut tracked = SMatrix::<f64, 1, 2>::zeros();
    tracked[p["tracked"].as_u64().ok_or("tracked")? as usize] = 1.0;
    let estimation = Estimation {
        input_noise: SMatrix::identity(),
        disturbance_noise: SMatrix::zeros(),
        output_disturbance_noise: 0.0,
        measurement_noise: SMatrix::identity() * 1e-12,
    };
    for case in p["cases"].as_array().ok_or("cases")? {
        let horizon = case["horizon"].as_u64().ok_or("horizon")? as usize;
        let mut design = MpcDesign::new(horizon, matrix(&p["q"]), matrix(&p["r"]));
        design.input_min = SVector::repeat(-umax);
        design.input_max = SVector::repeat(umax);
        for i in 0..2 {
            design.output_limits.push(OutputLimit {
                output: model.c().row(i).into_owned(),
                min: -xmax,
                max: xmax,
                kind: Row::Hard,
            });
        }
        let fresh = Mpc::new(&model, &tracked, &design, &estimation)?;
        let x0: Vec<f64> = serde_json::from_value(case["x0"].clone())?;
        let x0 = SVector::<f64, 4>::from_column_slice(&x0);
        let r = SVector::<f64, 1>::new(number(&case["reference"]));
        let repeats = case["repeats"].as_u64().ok_or("repeats")?.max(1);
        let mut times = Vec::new();
        let mut last = None;
        for _ in 0..repeats {
            let mut mpc = fresh.clone();
            let start = Instant::now();
            let u = mpc.move_at(&x0, &r, &SVector::zeros())?;
            times.push(start.elapsed().as_secs_f64());
            last = Some((u[0], mpc.last_report(), mpc.last_status()));
        }
        times.sort_by(f64::total_cmp);
        let (u0, report, status) = last.ok_or("no repeat")?;
        println!(
            "{}",
            json!({
                "name": case["name"],
                "median": times[times.len() / 2],
                "max": times[times.len() - 1],
                "u0": u0,
                "solved": status.is_solved(),
                "active_set_steps": report.map(|r| r.active_set_steps),
                "iterations": report.map(|r| r.iterations),
            })
        );
    }
    Ok(())
}
