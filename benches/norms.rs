//! System norms: `hinf_norm` and `h2_norm` on the lab's two-cart plant (4
//! states, fixed size, force on cart 2 to its position) and on random
//! stable SISO models of 20 and 100 states (run-time sized; issue 29's
//! target: H∞ at N = 100 at most twice python-control's `norm(sys, 'inf')`,
//! timed on the same models by `scripts/norms_vs_python.py`).

use criterion::{Criterion, criterion_group, criterion_main};
use ctrlab::analysis::{h2_norm, hinf_norm};
use ctrlab::signal::Rng;
use ctrlab::{DynStateSpace, StateSpace};
use nalgebra::{DMatrix, matrix};
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
    // tests/calling_style.rs `two_carts()`: the lab plant, force on cart 2.
    let (m1, m2, k1, k2, c1, c2) = (1.3, 0.7, 1000.0, 1000.0, 2.0, 1.0);
    let plant = StateSpace::continuous(
        matrix![0.0, 1.0, 0.0, 0.0;
                -(k1 + k2) / m1, -c1 / m1, k2 / m1, 0.0;
                0.0, 0.0, 0.0, 1.0;
                k2 / m2, 0.0, -k2 / m2, -c2 / m2],
        matrix![0.0; 0.0; 0.0; 1.0 / m2],
        matrix![0.0, 0.0, 1.0, 0.0],
        matrix![0.0],
    )
    .unwrap();
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
