//! Lyapunov equations: `lyap` on the lab's two-cart plant (4 states, fixed
//! size, Q = B Bᵀ) and on random stable models of 20 and 100 states (run
//! time sized; issue 29's target: at N = 100 at most twice SciPy's
//! `solve_continuous_lyapunov`, timed on the same models by
//! `scripts/lyapunov_vs_scipy.py`), and `dlyap` at 100 states.

use criterion::{Criterion, criterion_group, criterion_main};
use ctrlab::analysis::{dlyap, lyap};
use ctrlab::signal::Rng;
use nalgebra::{DMatrix, matrix};
use std::hint::black_box;

/// `G / √n − 1.5 I` with `G` N(0, 1) (seeded): its eigenvalues lie near
/// the disc of radius 1 about −1.5, so it is stable; and `Q = H Hᵀ`.
fn random(n: usize, seed: u64) -> (DMatrix<f64>, DMatrix<f64>) {
    let mut rng = Rng::new(seed);
    let scale = 1.0 / (n as f64).sqrt();
    let a = DMatrix::from_fn(n, n, |_, _| rng.gaussian() * scale) - DMatrix::identity(n, n) * 1.5;
    let h = DMatrix::from_fn(n, n, |_, _| rng.gaussian());
    let q = &h * h.transpose();
    (a, q)
}

fn benches(c: &mut Criterion) {
    // tests/calling_style.rs `two_carts()`: the lab plant, force on cart 2.
    let (m1, m2, k1, k2, c1, c2) = (1.3, 0.7, 1000.0, 1000.0, 2.0, 1.0);
    let a = matrix![0.0, 1.0, 0.0, 0.0;
                    -(k1 + k2) / m1, -c1 / m1, k2 / m1, 0.0;
                    0.0, 0.0, 0.0, 1.0;
                    k2 / m2, 0.0, -k2 / m2, -c2 / m2];
    let b = matrix![0.0; 0.0; 0.0; 1.0 / m2];
    let q = b * b.transpose();
    c.bench_function("lyap, lab plant (4 states, fixed size)", |bench| {
        bench.iter(|| lyap(black_box(&a), black_box(&q)).unwrap())
    });
    for n in [20, 100] {
        let (a, q) = random(n, n as u64);
        c.bench_function(&format!("lyap, {n} states (run-time sized)"), |bench| {
            bench.iter(|| lyap(black_box(&a), black_box(&q)).unwrap())
        });
    }
    let (a, q) = random(100, 100);
    let a = a * (1.0 / 3.0);
    c.bench_function("dlyap, 100 states (run-time sized)", |bench| {
        bench.iter(|| dlyap(black_box(&a), black_box(&q)).unwrap())
    });
}

criterion_group!(lyapunov, benches);
criterion_main!(lyapunov);
