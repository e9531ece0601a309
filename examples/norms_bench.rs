//! Times ctrlab's `hinf_norm` and `h2_norm` on models read from a JSON
//! file, for `scripts/norms_vs_python.py`, which times python-control's
//! `norm(sys, 'inf')` and `norm(sys, 2)` (its SciPy path) on the same
//! matrices in the same run.
//!
//! ```text
//! cargo run --release --example norms_bench -- models.json
//! ```
//!
//! The file is `{"cases": [{"name", "a", "b", "c", "d", "repeats"}]}`
//! (continuous models, matrices as lists of rows); for each case one line
//! of JSON is printed: the name, `n`, the median wall time of `repeats`
//! calls of each function in seconds, and the values (`hinf`, `peak`, `h2`;
//! `h2` is null when `D ≠ 0`).

use std::time::Instant;

use ctrlab::DynStateSpace;
use ctrlab::analysis::{h2_norm, hinf_norm};
use nalgebra::DMatrix;
use serde_json::{Value, json};

fn matrix(v: &Value) -> DMatrix<f64> {
    let rows: Vec<Vec<f64>> = serde_json::from_value(v.clone()).expect("a list of rows");
    let (n, m) = (rows.len(), rows.first().map_or(0, Vec::len));
    DMatrix::from_fn(n, m, |i, j| rows[i][j])
}

/// The median wall time of `repeats` calls of `f`, and its last result.
fn median<T>(repeats: u64, mut f: impl FnMut() -> T) -> (f64, T) {
    let mut times = Vec::new();
    let mut last = None;
    for _ in 0..repeats {
        let start = Instant::now();
        last = Some(f());
        times.push(start.elapsed().as_secs_f64());
    }
    times.sort_by(f64::total_cmp);
    (times[times.len() / 2], last.expect("repeats ≥ 1"))
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = std::env::args()
        .nth(1)
        .ok_or("usage: norms_bench models.json")?;
    let data: Value = serde_json::from_str(&std::fs::read_to_string(path)?)?;
    for case in data["cases"].as_array().ok_or("no \"cases\"")? {
        let [a, b, c, d] = ["a", "b", "c", "d"].map(|k| matrix(&case[k]));
        let n = a.nrows();
        let sys = DynStateSpace::continuous(a, b, c, d)?;
        let repeats = case["repeats"].as_u64().unwrap_or(5).max(1);
        let (t_inf, h) = median(repeats, || hinf_norm(&sys));
        let h = h?;
        let (t_2, h2) = median(repeats, || h2_norm(&sys));
        println!(
            "{}",
            json!({
                "name": case["name"],
                "n": n,
                "hinf_median_s": t_inf,
                "h2_median_s": t_2,
                "hinf": h.value,
                "peak": h.peak_frequency,
                "h2": h2.ok(),
            })
        );
    }
    Ok(())
}
