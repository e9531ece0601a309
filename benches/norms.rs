//! System norms: `hinf_norm` and `h2_norm` on the lab's two-cart plant (4
//! states, fixed size, `MassSpring::nominal()`, force on cart 2 to its
//! position) and on random
//! stable SISO models of 20 and 100 states (run-time sized; issue 29's
//! target: H∞ at N = 100 at most twice python-control's `norm(sys, 'inf')`,
//! timed on the same models by `scripts/norms_vs_python.py`).

use criterion::{Criterion, criterion_group, criterion_main};
use ctrlab::analysis::{h2_norm, hinf_norm};
use ctrlab::signal::Rng;
use ctrlab::{Cart, DynStateSpace, MassSpring};
use nalgebra::DMatrix;
use std::hint::black_box;

/// `A = G / √n − 1.5 I` with `G` N(0, 1) (seeded), so it is stable; `B`,
/// `C` N(0, 1); `D = 0`.
fn random(n: usize, seed: u64) -> DynStateSpace {
    let mut rng = Rng::new(seed);
    let scale = 1.0 / (n as f64).sqrt();
    let a = DMatrix::from_fn(n, n, |_, _| rng.gaussian() * scale) - DMatrix::identity(n, n) * 1.5;
    let b = DMatrix::from_fn(n, 1, |_, _| rng.gaussian());
    let c = DMatrix::from_fn(1, n, |_, _| rng.gaussian());
    DynStateSpace::continuous(a, b, c, DMatrix::zeros(1, 1)).unwrap()
}

fn benches(c: &mut Criterion) {
    // The lab plant: force on cart 2 to its position.
    let plant = MassSpring::nominal().state_space(Cart::Two).unwrap();
    c.bench_function("hinf_norm, lab plant (4 states, fixed size)", |bench| {
        bench.iter(|| hinf_norm(black_box(&plant)).unwrap())
    });
    c.bench_function("h2_norm, lab plant (4 states, fixed size)", |bench| {
        bench.iter(|| h2_norm(black_box(&plant)).unwrap())
    });
    for n in [20, 100] {
        let sys = random(n, n as u64);
        c.bench_function(
            &format!("hinf_norm, {n} states (run-time sized)"),
            |bench| bench.iter(|| hinf_norm(black_box(&sys)).unwrap()),
        );
    }
    let sys = random(100, 100);
    c.bench_function("h2_norm, 100 states (run-time sized)", |bench| {
        bench.iter(|| h2_norm(black_box(&sys)).unwrap())
    });
}

criterion_group!(norms, benches);
criterion_main!(norms);
