//! Inner loops of simulation: the discrete step, a 5000-step closed loop
//! (against a plain hand-written nalgebra loop), one RK4 step, ZOH, and a
//! 40 001-sample step response (target < 1 ms: one discretisation).

use criterion::{Criterion, criterion_group, criterion_main};
use ctrlab::sim::{simulate_discrete_feedback, step_response};
use ctrlab::{Cart, Discretization, Integrator, MassSpring, Rk4};
use nalgebra::{SMatrix, SVector, vector};
use std::hint::black_box;

const STEPS: usize = 5000;

fn benches(c: &mut Criterion) {
    let sys = MassSpring::nominal().state_space(Cart::Two).unwrap();
    let d = sys.discretize(0.002, Discretization::Zoh).unwrap();
    // The lab's gain [0 0 10 0.1] per mm, in SI: u = K (G r - x).
    let k = SMatrix::<f64, 1, 4>::new(0.0, 0.0, 10_000.0, 100.0);
    let target = vector![0.0, 0.0, 0.030, 0.0];

    c.bench_function("discrete step (4 states)", |b| {
        let mut x = vector![0.001, 0.0, 0.002, 0.0];
        b.iter(|| {
            d.advance_mut(black_box(&mut x), black_box(&vector![1.0]));
        })
    });

    c.bench_function("closed loop, 5000 steps, ctrlab", |b| {
        b.iter(|| {
            let r = simulate_discrete_feedback(black_box(&d), SVector::zeros(), STEPS, |_k, x| {
                k * (target - x)
            })
            .unwrap();
            black_box(r)
        })
    });

    c.bench_function("closed loop, 5000 steps, hand-written nalgebra", |b| {
        let (a, bm, cm) = (*d.a(), *d.b(), *d.c());
        b.iter(|| {
            let mut t = Vec::with_capacity(STEPS);
            let mut xs = Vec::with_capacity(STEPS);
            let mut ys = Vec::with_capacity(STEPS);
            let mut x = SVector::<f64, 4>::zeros();
            for i in 0..STEPS {
                let u = k * (target - x);
                t.push(i as f64 * 0.002);
                xs.push(x);
                ys.push(cm * x);
                x = a * x + bm * u;
            }
            black_box((t, xs, ys))
        })
    });

    c.bench_function("RK4 step (4 states)", |b| {
        let mut x = vector![0.001, 0.0, 0.002, 0.0];
        b.iter(|| {
            Rk4.step_mut(
                black_box(&sys),
                0.0,
                0.002,
                black_box(&mut x),
                &vector![1.0],
            );
        })
    });

    c.bench_function("ZOH discretisation (4 states)", |b| {
        b.iter(|| black_box(&sys).discretize(black_box(0.002), Discretization::Zoh))
    });

    c.bench_function("step_response_40001", |b| {
        // 20 s at 0.5 ms: the grid of Table 2's fixture.
        b.iter(|| step_response(black_box(&sys), black_box(20.0), black_box(0.0005)))
    });
}

criterion_group!(sim, benches);
criterion_main!(sim);
