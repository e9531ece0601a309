//! Times ctrlab's continuous Riccati solver on problems read from a JSON
//! file, for `scripts/riccati_vs_scipy.py`, which times SciPy on the same
//! matrices in the same run and prints the two side by side.
//!
//! ```text
//! cargo run --release --example riccati_bench -- problems.json
//! ```
//!
//! The file is `{"cases": [{"name", "a", "b", "q", "r", "repeats"}]}` with
//! matrices as lists of rows. For each case one line of JSON is printed:
//! the name, `n`, the median and minimum wall time of `repeats` solves in
//! seconds, the relative residual, and the largest entry of the absolute
//! residual `X A + Aᵀ X − X B R⁻¹ Bᵀ X + Q`. For the case named
//! `lab plant n=4`, the line also has `fixed_lqr_median_s`: the fixed-size
//! [`lqr`](ctrlab::design::lqr) on `MassSpring::nominal()`'s cart-2 model
//! (checked to be the case's matrices), the function a lab program calls.

use std::time::Instant;

use ctrlab::design::{care, lqr};
use ctrlab::{Cart, MassSpring};
use nalgebra::{DMatrix, SMatrix};
use serde_json::{Value, json};

fn matrix(v: &Value) -> DMatrix<f64> {
    let rows: Vec<Vec<f64>> = serde_json::from_value(v.clone()).expect("a list of rows");
    let (n, m) = (rows.len(), rows.first().map_or(0, Vec::len));
    DMatrix::from_fn(n, m, |i, j| rows[i][j])
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = std::env::args()
        .nth(1)
        .ok_or("usage: riccati_bench problems.json")?;
    let data: Value = serde_json::from_str(&std::fs::read_to_string(path)?)?;
    for case in data["cases"].as_array().ok_or("no \"cases\"")? {
        let [a, b, q, r] = ["a", "b", "q", "r"].map(|k| matrix(&case[k]));
        let repeats = case["repeats"].as_u64().unwrap_or(5).max(1);
        let mut times = Vec::new();
        let mut solution = None;
        for _ in 0..repeats {
            let start = Instant::now();
            let sol = care(&a, &b, &q, &r)?;
            times.push(start.elapsed().as_secs_f64());
            solution = Some(sol);
        }
        let sol = solution.ok_or("no solve")?;
        times.sort_by(f64::total_cmp);
        let x = &sol.riccati;
        let xb = x * &b;
        let r_inv = r.clone().try_inverse().ok_or("R singular")?;
        let res = x * &a + a.transpose() * x + &q - &xb * r_inv * xb.transpose();
        let mut line = json!({
            "name": case["name"],
            "n": a.nrows(),
            "median_s": times[times.len() / 2],
            "min_s": times[0],
            "relative_residual": sol.residual,
            "max_abs_residual": res.amax(),
        });
        if case["name"] == "lab plant n=4" {
            line["fixed_lqr_median_s"] = json!(fixed_lab_lqr(&a, &b, &q, &r, repeats)?);
        }
        println!("{line}");
    }
    Ok(())
}

/// The median time of the fixed-size `lqr` on the lab plant, after checking
/// that the plant and weights are the case's (to 1e-12 relative).
fn fixed_lab_lqr(
    a: &DMatrix<f64>,
    b: &DMatrix<f64>,
    q: &DMatrix<f64>,
    r: &DMatrix<f64>,
    repeats: u64,
) -> Result<f64, Box<dyn std::error::Error>> {
    let plant = MassSpring::nominal().state_space(Cart::Two)?;
    let qs = SMatrix::<f64, 4, 4>::from_column_slice(q.as_slice());
    let rs = SMatrix::<f64, 1, 1>::from_column_slice(r.as_slice());
    let same = |x: &[f64], y: &[f64]| {
        let scale = x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        x.iter().zip(y).all(|(u, v)| (u - v).abs() <= 1e-12 * scale)
    };
    if !(same(plant.a().as_slice(), a.as_slice()) && same(plant.b().as_slice(), b.as_slice())) {
        return Err("the lab plant case is not MassSpring::nominal()'s cart-2 model".into());
    }
    let mut times = Vec::new();
    for _ in 0..repeats {
        let start = Instant::now();
        std::hint::black_box(lqr(&plant, &qs, &rs)?);
        times.push(start.elapsed().as_secs_f64());
    }
    times.sort_by(f64::total_cmp);
    Ok(times[times.len() / 2])
}
