//! The lab's state-feedback tables (LAB.md Tables 2, 5 and 6) and how the
//! examples print gains and poles; shared by the `state_feedback` and `lab5`
//! examples (`#[path]`-included, so each stays a single `cargo run`).

use nalgebra::Complex;

/// Gains `Kf = [Kf1 Kf2 Kf3 Kf4]` per millimetre for cart 2 (`Kf3`, `Kf4`).
fn cart2(kf3: f64, kf4: f64) -> [f64; 4] {
    [0.0, 0.0, kf3, kf4]
}

/// Gains for cart 1 (`Kf1`, `Kf2`, `Kf4`).
fn cart1(kf1: f64, kf2: f64, kf4: f64) -> [f64; 4] {
    [kf1, kf2, 0.0, kf4]
}

/// Table 2 (simulation): cart 2, setpoint 30 mm.
pub fn table2() -> Vec<[f64; 4]> {
    vec![
        cart2(0.1, 0.0),
        cart2(1.0, 0.0),
        cart2(10.0, 0.0),
        cart2(10.0, 0.1),
        cart2(10.0, 0.3),
        cart2(10.0, 0.5),
    ]
}

/// Table 5 (rig): cart 2, setpoint 30 mm; Kf3 alone, then Kf4 with Kf3 = 10.
pub fn table5() -> Vec<[f64; 4]> {
    [0.1, 0.5, 1.0, 5.0, 10.0]
        .map(|k| cart2(k, 0.0))
        .into_iter()
        .chain([0.02, 0.05, 0.1, 0.2].map(|k| cart2(10.0, k)))
        .collect()
}

/// Table 6 (rig): cart 1, setpoint 15 mm; Kf1 alone, then Kf2, then Kf4,
/// each with Kf1 = 1.
pub fn table6() -> Vec<[f64; 4]> {
    [0.2, 0.5, 1.0, 1.5, 2.0]
        .map(|k| cart1(k, 0.0, 0.0))
        .into_iter()
        .chain([0.001, 0.002, 0.005, 0.008, 0.01].map(|k| cart1(1.0, k, 0.0)))
        .chain([0.01, 0.02, 0.05, 0.1, 0.2].map(|k| cart1(1.0, 0.0, k)))
        .collect()
}

/// Poles as `a ± bj` pairs and real values.
pub fn fmt_poles(poles: &[Complex<f64>]) -> String {
    poles
        .iter()
        .filter(|p| p.im >= 0.0)
        .map(|p| {
            if p.im > 0.0 {
                format!("{:.2} ± {:.2}j", p.re, p.im)
            } else {
                format!("{:.2}", p.re)
            }
        })
        .collect::<Vec<_>>()
        .join(", ")
}

/// `[Kf1 Kf2 Kf3 Kf4]` as the lab writes it.
pub fn fmt_kf(kf: &[f64; 4]) -> String {
    format!("[{} {} {} {}]", kf[0], kf[1], kf[2], kf[3])
}
