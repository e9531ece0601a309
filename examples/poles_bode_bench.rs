//! Times `poles()` on a run-time-sized matrix read from a JSON file and a
//! 1000-point Bode evaluation of the lab plant, for
//! `scripts/poles_bode_vs_python.py`, which times NumPy's `eigvals` and
//! python-control's frequency response on the same data in the same run.
//!
//! ```text
//! cargo run --release --example poles_bode_bench -- problem.json
//! ```
//!
//! The file is `{"a": [[...], ...], "repeats": k}`. One line of JSON is
//! printed: the median wall time in seconds of `k` pole computations of
//! `a` and of `10 k` Bode evaluations (ω = 10⁰ … 10³ rad/s, 1000 points
//! log-spaced), and the largest pole's real part (a check that both sides
//! solved the same matrix), and the lab plant's output row `C`.

use std::time::Instant;

use ctrlab::freq::{bode, logspace};
use ctrlab::{Cart, DynStateSpace, MassSpring};
use nalgebra::DMatrix;
use serde_json::{Value, json};

fn median(mut times: Vec<f64>) -> f64 {
    times.sort_by(f64::total_cmp);
    times[times.len() / 2]
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = std::env::args()
        .nth(1)
        .ok_or("usage: poles_bode_bench problem.json")?;
    let data: Value = serde_json::from_str(&std::fs::read_to_string(path)?)?;
    let rows: Vec<Vec<f64>> = serde_json::from_value(data["a"].clone())?;
    let n = rows.len();
    let a = DMatrix::from_fn(n, n, |i, j| rows[i][j]);
    let sys = DynStateSpace::continuous(
        a,
        DMatrix::zeros(n, 1),
        DMatrix::zeros(1, n),
        DMatrix::zeros(1, 1),
    )?;
    let repeats = data["repeats"].as_u64().unwrap_or(20).max(1);

    let mut times = Vec::new();
    let mut largest = f64::NAN;
    for _ in 0..repeats {
        let start = Instant::now();
        let poles = sys.poles()?;
        times.push(start.elapsed().as_secs_f64());
        largest = poles.last().map_or(f64::NAN, |p| p.re);
    }
    let poles_s = median(times);

    let plant = MassSpring::nominal().state_space(Cart::Two)?;
    let w = logspace(0.0, 3.0, 1000)?;
    let mut times = Vec::new();
    for _ in 0..10 * repeats {
        let start = Instant::now();
        std::hint::black_box(bode(&plant, &w)?);
        times.push(start.elapsed().as_secs_f64());
    }
    println!(
        "{}",
        json!({
            "n": n,
            "poles_median_s": poles_s,
            "largest_pole_re": largest,
            "bode_median_s": median(times),
            "plant_c": plant.c().as_slice(),
        })
    );
    Ok(())
}
