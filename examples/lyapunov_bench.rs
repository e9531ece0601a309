//! Times ctrlab's `lyap` on problems read from a JSON file, for
//! `scripts/lyapunov_vs_scipy.py`, which times SciPy's
//! `solve_continuous_lyapunov` on the same matrices in the same run.
//!
//! ```text
//! cargo run --release --example lyapunov_bench -- problems.json
//! ```
//!
//! The file is `{"cases": [{"name", "a", "q", "repeats"}]}` with matrices
//! as lists of rows; for each case one line of JSON is printed: the name,
//! `n`, the median and minimum wall time of `repeats` solves in seconds,
//! the relative residual, and the largest entry of `A X + X Aᵀ + Q`.

use std::time::Instant;

use ctrlab::analysis::lyap;
use nalgebra::DMatrix;
use serde_json::{Value, json};

fn matrix(v: &Value) -> DMatrix<f64> {
    let rows: Vec<Vec<f64>> = serde_json::from_value(v.clone()).expect("a list of rows");
    let (n, m) = (rows.len(), rows.first().map_or(0, Vec::len));
    DMatrix::from_fn(n, m, |i, j| rows[i][j])
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = std::env::args()
        .nth(1)
        .ok_or("usage: lyapunov_bench problems.json")?;
    let data: Value = serde_json::from_str(&std::fs::read_to_string(path)?)?;
    for case in data["cases"].as_array().ok_or("no \"cases\"")? {
        let [a, q] = ["a", "q"].map(|k| matrix(&case[k]));
        let repeats = case["repeats"].as_u64().unwrap_or(5).max(1);
        let mut times = Vec::new();
        let mut solution = None;
        for _ in 0..repeats {
            let start = Instant::now();
            let sol = lyap(&a, &q)?;
            times.push(start.elapsed().as_secs_f64());
            solution = Some(sol);
        }
        let sol = solution.ok_or("no solve")?;
        times.sort_by(f64::total_cmp);
        let res = &a * &sol.x + &sol.x * a.transpose() + &q;
        println!(
            "{}",
            json!({
                "name": case["name"],
                "n": a.nrows(),
                "median_s": times[times.len() / 2],
                "min_s": times[0],
                "relative_residual": sol.residual,
                "max_abs_residual": res.amax(),
            })
        );
    }
    Ok(())
}
