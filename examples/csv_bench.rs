//! Times `Recording::read_csv` on logs named in a JSON file, for
//! `scripts/ahead_csv.py`, which times pandas' `read_csv` on the same files
//! in the same run.
//!
//! ```text
//! cargo run --release --example csv_bench -- payload.json
//! ```
//!
//! The file is `{"cases": [{"name", "path", "repeats"}]}`; for each case
//! one line of JSON is printed: the name, the rows read, and the minimum
//! and median wall time of `repeats` reads in seconds.

use std::time::Instant;

use ctrlab::Recording;
use serde_json::{Value, json};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = std::env::args()
        .nth(1)
        .ok_or("usage: csv_bench payload.json")?;
    let data: Value = serde_json::from_str(&std::fs::read_to_string(path)?)?;
    for case in data["cases"].as_array().ok_or("no \"cases\"")? {
        let file = case["path"].as_str().ok_or("no \"path\"")?;
        let repeats = case["repeats"].as_u64().unwrap_or(5).max(1);
        let mut times = Vec::new();
        let mut rows = 0;
        for _ in 0..repeats {
            let start = Instant::now();
            let rec = Recording::read_csv(file)?;
            times.push(start.elapsed().as_secs_f64());
            rows = rec.len();
            drop(std::hint::black_box(rec));
        }
        times.sort_by(f64::total_cmp);
        println!(
            "{}",
            json!({
                "name": case["name"],
                "rows": rows,
                "min_s": times[0],
                "median_s": times[times.len() / 2],
            })
        );
    }
    Ok(())
}
