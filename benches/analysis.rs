//! Analysis of models sized at run time: `poles` of a 100-state model
//! (issue target: under 5 ms) and of the lab plant, the lab plant's
//! `dc_gain`, and a 30-state `is_controllable`.

use criterion::{Criterion, criterion_group, criterion_main};
use ctrlab::signal::Rng;
use ctrlab::{Cart, DynStateSpace, MassSpring};
use nalgebra::DMatrix;
use std::hint::black_box;

/// A random `n`-state model with `m` inputs (entries N(0, 1), seeded).
fn random(n: usize, m: usize, seed: u64) -> DynStateSpace {
    let mut rng = Rng::new(seed);
    let mut g = |r, c| DMatrix::from_fn(r, c, |_, _| rng.gaussian());
    let (a, b, c) = (g(n, n), g(n, m), g(1, n));
    DynStateSpace::continuous(a, b, c, DMatrix::zeros(1, m)).unwrap()
}

fn benches(c: &mut Criterion) {
    let big = random(100, 10, 1);
    c.bench_function("poles, 100 states (run-time sized)", |b| {
        b.iter(|| black_box(&big).poles().unwrap())
    });
    let lab = MassSpring::nominal().state_space(Cart::Two).unwrap();
    c.bench_function("poles, lab plant (4 states, fixed size)", |b| {
        b.iter(|| black_box(&lab).poles().unwrap())
    });
    c.bench_function("dc_gain, lab plant (4 states, fixed size)", |b| {
        b.iter(|| black_box(&lab).dc_gain().unwrap())
    });
    let mid = random(30, 2, 2);
    c.bench_function("is_controllable, 30 states (run-time sized)", |b| {
        b.iter(|| black_box(&mid).is_controllable().unwrap())
    });
}

criterion_group!(analysis, benches);
criterion_main!(analysis);
