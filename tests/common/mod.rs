//! Shared helpers for the integration tests: loading the reference fixtures.
#![allow(dead_code)]

use ctrlab::StateSpace;
use nalgebra::{DMatrix, SMatrix, matrix};
use serde_json::Value;

/// A JSON fixture from `tests/data/`.
pub fn fixture(file: &str) -> Value {
    let path = format!("{}/tests/data/{file}", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("fixture {path} is readable: {e}"));
    serde_json::from_str(&text).expect("fixture is valid JSON")
}

/// The python-control / SciPy fixture for the nominal plant.
pub fn nominal_fixture() -> Value {
    fixture("mass_spring_nominal.json")
}

/// The lag `gain / (τ s + 1)`: `τ ẏ = −y + gain · u`.
pub fn lag(tau: f64, gain: f64) -> StateSpace<1, 1, 1> {
    StateSpace::continuous(
        matrix![-1.0 / tau],
        matrix![gain / tau],
        matrix![1.0],
        matrix![0.0],
    )
    .expect("a finite lag")
}

/// `ωn² / (s² + 2ζωn s + ωn²)` with the position as the output.
pub fn second_order(zeta: f64, wn: f64) -> StateSpace<2, 1, 1> {
    StateSpace::continuous(
        matrix![0.0, 1.0; -wn * wn, -2.0 * zeta * wn],
        matrix![0.0; wn * wn],
        matrix![1.0, 0.0],
        matrix![0.0],
    )
    .expect("a finite second-order model")
}

/// A fixed-size matrix from a JSON array of rows.
pub fn matrix<const R: usize, const C: usize>(v: &Value) -> SMatrix<f64, R, C> {
    let rows = v.as_array().expect("matrix is an array of rows");
    assert_eq!(rows.len(), R, "row count");
    SMatrix::from_fn(|r, c| {
        let row = rows[r].as_array().expect("row is an array");
        assert_eq!(row.len(), C, "column count");
        row[c].as_f64().expect("entry is a number")
    })
}

/// A run-time-sized matrix from a JSON array of rows (empty: 0 × 0).
pub fn dmatrix(v: &Value) -> DMatrix<f64> {
    let rows: Vec<Vec<f64>> = serde_json::from_value(v.clone()).expect("an array of rows");
    let (n, m) = (rows.len(), rows.first().map_or(0, Vec::len));
    DMatrix::from_fn(n, m, |i, j| rows[i][j])
}

/// `max |got − want| / max |want|`.
pub fn rel_max(got: &DMatrix<f64>, want: &DMatrix<f64>) -> f64 {
    (got - want).amax() / want.amax().max(f64::MIN_POSITIVE)
}

/// Relative Frobenius error ‖got − want‖ / ‖want‖.
pub fn rel_frobenius<const R: usize, const C: usize>(
    got: &SMatrix<f64, R, C>,
    want: &SMatrix<f64, R, C>,
) -> f64 {
    (got - want).norm() / want.norm()
}

// Helpers on the two-cart lab's plant, simulated rig and LQI design.
#[cfg(feature = "lab")]
mod lab;
#[cfg(feature = "lab")]
#[allow(unused_imports)] // each test binary uses some of them
pub use lab::*;

/// A list of numbers from a JSON array.
pub fn floats(v: &Value) -> Vec<f64> {
    serde_json::from_value(v.clone()).expect("an array of numbers")
}

/// Complex numbers from a JSON array of `[re, im]` pairs.
pub fn complexes(v: &Value) -> Vec<nalgebra::Complex<f64>> {
    let pairs: Vec<[f64; 2]> = serde_json::from_value(v.clone()).expect("[re, im] pairs");
    pairs
        .into_iter()
        .map(|[re, im]| nalgebra::Complex::new(re, im))
        .collect()
}

/// `ẋ = −x + u₁ + u₂`, `y = x`: one output, two inputs (not SISO, not
/// square).
pub fn two_inputs() -> ctrlab::DynStateSpace {
    ctrlab::DynStateSpace::continuous(
        nalgebra::DMatrix::from_element(1, 1, -1.0),
        nalgebra::DMatrix::from_element(1, 2, 1.0),
        nalgebra::DMatrix::from_element(1, 1, 1.0),
        nalgebra::DMatrix::zeros(1, 2),
    )
    .expect("a finite model")
}

/// The largest distance from a wanted pole to its match (each got pole
/// used once, nearest first), relative to `max(|w|, 1)`; the counts must
/// agree.
pub fn worst_match(got: &[nalgebra::Complex<f64>], want: &[nalgebra::Complex<f64>]) -> f64 {
    assert_eq!(got.len(), want.len(), "{got:?} vs {want:?}");
    let mut left = got.to_vec();
    let mut worst: f64 = 0.0;
    for w in want {
        let (i, d) = left
            .iter()
            .enumerate()
            .map(|(i, g)| (i, (g - w).norm()))
            .min_by(|x, y| x.1.total_cmp(&y.1))
            .expect("a pole left to match");
        worst = worst.max(d / w.norm().max(1.0));
        left.remove(i);
    }
    worst
}

// Quadratic programs for `DenseQp`'s tests: the OSQP fixtures and the KKT
// certificate.
pub mod qp;
