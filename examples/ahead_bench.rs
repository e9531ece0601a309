//! Times ctrlab's `step_info` and the lab's two-stage identification on
//! data read from files, for `scripts/ahead_metrics_ident.py`, which times
//! python-control's `step_info` and NumPy's `lstsq` on the same data in the
//! same run.
//!
//! ```text
//! cargo run --release --example ahead_bench -- cases.json
//! ```
//!
//! The file is `{"cases": [...]}`; each case has a `"name"`, a `"kind"`,
//! `"repeats"` and `"rounds"`, and names raw little-endian `f64` files
//! (written by NumPy's `tofile`, so that both sides read the same bits):
//!
//! - `"step_info"`: `"t"`, `"y"` — `step_info(t, y)` with the default
//!   options;
//! - `"ident"`: `"t"`, `"u"`, `"x1"`, `"x2"` (a recording with the lab's
//!   channels), `"m1"`, `"m2"`, `"covariance"` (`"classical"` or
//!   `"newey_west"`) — `identify_with` with the default options otherwise
//!   (central differences, equal springs), building the recording outside
//!   the timed calls.
//!
//! For each case one line of JSON: the name, the minimum wall time over
//! `rounds × repeats` calls (s), and the figures (to compare with the
//! peer's).

use std::time::Instant;

use ctrlab::data::{Channel, Schema};
use ctrlab::ident::Covariance;
use ctrlab::lab::ident::{Options, identify_with};
use ctrlab::{Recording, StepInfoOptions, step_info};
use serde_json::{Value, json};

fn read_f64(path: &Value) -> Result<Vec<f64>, Box<dyn std::error::Error>> {
    let bytes = std::fs::read(path.as_str().ok_or("a file name")?)?;
    Ok(bytes
        .chunks_exact(8)
        .map(|b| f64::from_le_bytes(b.try_into().unwrap_or_default()))
        .collect())
}

/// The minimum time of `rounds × repeats` calls of `f`, and its last value.
fn time<T>(rounds: u64, repeats: u64, mut f: impl FnMut() -> T) -> (f64, T) {
    let mut best = f64::INFINITY;
    let mut last = f();
    for _ in 0..rounds * repeats {
        let start = Instant::now();
        last = std::hint::black_box(f());
        best = best.min(start.elapsed().as_secs_f64());
    }
    (best, last)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = std::env::args()
        .nth(1)
        .ok_or("usage: ahead_bench cases.json")?;
    let data: Value = serde_json::from_str(&std::fs::read_to_string(path)?)?;
    for case in data["cases"].as_array().ok_or("no \"cases\"")? {
        let repeats = case["repeats"].as_u64().unwrap_or(5).max(1);
        let rounds = case["rounds"].as_u64().unwrap_or(3).max(1);
        let t = read_f64(&case["t"])?;
        match case["kind"].as_str() {
            Some("step_info") => {
                let y = read_f64(&case["y"])?;
                let options = StepInfoOptions::default();
                let (s, info) = time(rounds, repeats, || step_info(&t, &y, &options));
                let info = info?;
                println!(
                    "{}",
                    json!({
                        "name": case["name"],
                        "min_s": s,
                        "rise_time": info.rise_time,
                        "settling_time": info.settling_time,
                        "overshoot": info.overshoot,
                        "peak": info.peak,
                    })
                );
            }
            Some("ident") => {
                let [u, x1, x2] = ["u", "x1", "x2"].map(|k| read_f64(&case[k]));
                let (u, x1, x2) = (u?, x1?, x2?);
                let schema = Schema::new(
                    vec![Channel::new("u", "V")],
                    vec![Channel::new("x1", "m"), Channel::new("x2", "m")],
                )?;
                let mut rec = Recording::with_capacity(schema, t.len());
                for k in 0..t.len() {
                    rec.push(t[k], &[u[k]], &[x1[k], x2[k]])?;
                }
                let covariance = match case["covariance"].as_str() {
                    Some("classical") => Covariance::Classical,
                    _ => Options::default().covariance,
                };
                let options = Options {
                    covariance,
                    ..Options::default()
                };
                let (m1, m2) = (
                    case["m1"].as_f64().ok_or("m1")?,
                    case["m2"].as_f64().ok_or("m2")?,
                );
                let (s, est) = time(rounds, repeats, || identify_with(&rec, m1, m2, &options));
                let est = est?;
                println!(
                    "{}",
                    json!({
                        "name": case["name"],
                        "min_s": s,
                        "k12": est.k2().value,
                        "b1": est.b1.value,
                        "gain": est.gain.value,
                        "b2": est.b2.value,
                    })
                );
            }
            other => return Err(format!("unknown kind {other:?}").into()),
        }
    }
    Ok(())
}
