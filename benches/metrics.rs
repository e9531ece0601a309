//! Design-time and measurement kernels: `step_info` over a 5000-sample record
//! (target under 20 µs; python-control takes about 50 µs from data) and over
//! the 40 001-sample second-order response of
//! `scripts/ahead_metrics_ident.py` (target: 5× python-control's `step_info`,
//! about 200 µs on a quiet machine, so under 40 µs), and
//! `acker` and `dlqr` on the lab's 4-state plant.

use criterion::{Criterion, criterion_group, criterion_main};
use ctrlab::lab::LabGains;
use ctrlab::sim::{Solver, simulate, time_grid};
use ctrlab::{Cart, Discretization, MassSpring, StepInfoOptions, acker, dlqr, step_info};
use nalgebra::{Complex, SMatrix, SVector, matrix, vector};
use std::hint::black_box;

fn benches(c: &mut Criterion) {
    let plant = MassSpring::nominal().state_space(Cart::Two).unwrap();

    // Table 2, row [0 0 10 0.1]: 5000 samples at 0.5 ms (2.5 s).
    let cl = LabGains::new([0.0, 0.0, 10.0, 0.1], Cart::Two)
        .state_feedback()
        .unwrap()
        .closed_loop(&plant)
        .unwrap();
    let t = time_grid(4999.0 * 0.0005, 0.0005).unwrap();
    assert_eq!(t.len(), 5000);
    let r = simulate(&cl, &t, SVector::zeros(), |_| vector![30.0], Solver::Zoh).unwrap();
    let y: Vec<f64> = r.y.iter().map(|y| y[0]).collect();
    let given = StepInfoOptions {
        final_value: Some(cl.dc_gain().unwrap()[(0, 0)] * 30.0),
        reference: Some(30.0),
        ..Default::default()
    };
    c.bench_function("step_info, 5000 samples, final value given", |b| {
        b.iter(|| step_info(black_box(&t), black_box(&y), black_box(&given)).unwrap())
    });
    let estimated = StepInfoOptions::default();
    c.bench_function("step_info, 5000 samples, final value estimated", |b| {
        b.iter(|| step_info(black_box(&t), black_box(&y), black_box(&estimated)).unwrap())
    });

    // ζ = 0.3, ωn = 2 rad/s, 0 … 20 s every 0.5 ms, as the script's.
    let (zeta, wn) = (0.3f64, 2.0f64);
    let wd = wn * (1.0 - zeta * zeta).sqrt();
    let t: Vec<f64> = (0..40_001).map(|k| k as f64 * 0.0005).collect();
    let y: Vec<f64> = t
        .iter()
        .map(|&t| {
            1.0 - (-zeta * wn * t).exp()
                * ((wd * t).cos() + zeta / (1.0 - zeta * zeta).sqrt() * (wd * t).sin())
        })
        .collect();
    c.bench_function("step_info, 40 001 samples, second order", |b| {
        b.iter(|| step_info(black_box(&t), black_box(&y), black_box(&estimated)).unwrap())
    });

    let targets = [
        Complex::new(-30.0, 30.0),
        Complex::new(-30.0, -30.0),
        Complex::new(-40.0, 0.0),
        Complex::new(-50.0, 0.0),
    ];
    c.bench_function("acker, 4 states", |b| {
        b.iter(|| acker(black_box(&plant), black_box(&targets)).unwrap())
    });

    let d = plant.discretize(0.002, Discretization::Zoh).unwrap();
    let q = SMatrix::<f64, 4, 4>::from_diagonal(&vector![1e4, 1.0, 1e6, 1.0]);
    let rw = matrix![1.0];
    c.bench_function("dlqr, 4 states (SDA)", |b| {
        b.iter(|| dlqr(black_box(&d), black_box(&q), black_box(&rw)).unwrap())
    });
}

criterion_group!(metrics, benches);
criterion_main!(metrics);
