//! Shared helpers for the integration tests: loading the reference fixtures.
#![allow(dead_code)]

use nalgebra::SMatrix;
use serde_json::Value;

/// The python-control / SciPy fixture for the nominal plant.
pub fn nominal_fixture() -> Value {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/mass_spring_nominal.json"
    ))
    .expect("fixture tests/data/mass_spring_nominal.json is readable");
    serde_json::from_str(&text).expect("fixture is valid JSON")
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

/// Relative Frobenius error ‖got − want‖ / ‖want‖.
pub fn rel_frobenius<const R: usize, const C: usize>(
    got: &SMatrix<f64, R, C>,
    want: &SMatrix<f64, R, C>,
) -> f64 {
    (got - want).norm() / want.norm()
}
