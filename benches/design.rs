//! Design and control-update costs: the observer + LQI controller's
//! per-period update (the 2 ms loop's work), the full-state integral
//! controller's, and the design functions (`place` for 4 states and
//! 2 inputs, `dlqe`, `dlqi`), and the Riccati solvers: `lqr` on the lab
//! plant (N = 4), `lqr` on seeded random `DynStateSpace`s at
//! N = 20, 60, 100, and `care` on SciPy's CAREX 18 (N = 100). The same
//! problems against SciPy in one run: `scripts/riccati_vs_scipy.py`.

use criterion::{Criterion, criterion_group, criterion_main};
use ctrlab::design::{AntiWindup, IntegralFeedback, care, dlqe, dlqi, lqr, place};
use ctrlab::lab::{lqi, protocol::PERIOD};
use ctrlab::{Cart, Controller, DynStateSpace, MassSpring, StateSpace};
use nalgebra::{Complex, DMatrix, SMatrix, matrix, vector};
use std::hint::black_box;

fn benches(c: &mut Criterion) {
    // The tests' controller: LQI on cart 2, Kalman filter on both positions.
    let metres_per_count = 0.080 / 8192.0;
    let model = lqi::position_model(&MassSpring::nominal(), PERIOD).unwrap();
    let tracked = model
        .with_output(matrix![0.0, 1.0] * model.c(), matrix![0.0])
        .unwrap();
    let q = SMatrix::<f64, 5, 5>::from_diagonal(&vector![0.0, 0.0, 1e7, 0.0, 1e10]);
    let r = matrix![1.0];
    let lqi = dlqi(&tracked, &q, &r).unwrap();
    let rn = SMatrix::<f64, 2, 2>::identity() * (metres_per_count * metres_per_count / 12.0);
    let qn = matrix![10.0];
    let anti_windup = AntiWindup::BackCalculation {
        tracking: 0.01,
        deadband: 0.024,
    };

    c.bench_function(
        "observer + LQI update and applied (4 states, positions of 4 measurements)",
        |b| {
            let mut ctrl = lqi::positions_lqi(
                &model,
                Cart::Two,
                &lqi::weights(Cart::Two, 1e7),
                metres_per_count,
            )
            .unwrap()
            .controller;
            let y = vector![0.0101, 0.0, 0.0297, 0.0];
            let setpoint = vector![0.030];
            b.iter(|| {
                let u = ctrl.update(black_box(&y), black_box(&setpoint));
                ctrl.applied(black_box(&u));
                u
            })
        },
    );

    c.bench_function(
        "integral state feedback update and applied (4 states)",
        |b| {
            let mut ctrl = IntegralFeedback::new(&tracked, &lqi.gain, anti_windup).unwrap();
            let x = vector![0.0101, 0.01, 0.0297, -0.02];
            let setpoint = vector![0.030];
            b.iter(|| {
                let u = ctrl.update(black_box(&x), black_box(&setpoint));
                ctrl.applied(black_box(&u));
                u
            })
        },
    );

    // The two carts with a force on each: 4 states, 2 inputs, a complex
    // pair and a repeated pole.
    let (m1, m2, k1, k2) = (1.3, 0.7, 1000.0, 1000.0);
    let a = matrix![0.0, 1.0, 0.0, 0.0;
                    -(k1 + k2) / m1, 0.0, k2 / m1, 0.0;
                    0.0, 0.0, 0.0, 1.0;
                    k2 / m2, 0.0, -k2 / m2, 0.0];
    let b2 = matrix![0.0, 0.0; 1.0 / m1, 0.0; 0.0, 0.0; 0.0, 1.0 / m2];
    let two_inputs =
        StateSpace::continuous(a, b2, matrix![0.0, 0.0, 1.0, 0.0], matrix![0.0, 0.0]).unwrap();
    let targets = [
        Complex::new(-20.0, 20.0),
        Complex::new(-20.0, -20.0),
        Complex::new(-40.0, 0.0),
        Complex::new(-40.0, 0.0),
    ];
    c.bench_function("place (4 states, 2 inputs, pair + repeated pole)", |b| {
        b.iter(|| place(black_box(&two_inputs), black_box(&targets)).unwrap())
    });
    let distinct = [
        Complex::new(-10.0, 30.0),
        Complex::new(-10.0, -30.0),
        Complex::new(-15.0, 15.0),
        Complex::new(-15.0, -15.0),
    ];
    c.bench_function("place (4 states, 2 inputs, two pairs)", |b| {
        b.iter(|| place(black_box(&two_inputs), black_box(&distinct)).unwrap())
    });

    c.bench_function("dlqe (4 states, 2 positions)", |b| {
        b.iter(|| dlqe(black_box(&model), model.b(), &qn, &rn).unwrap())
    });
    c.bench_function("dlqi (4 states + 1 integrator)", |b| {
        b.iter(|| dlqi(black_box(&tracked), &q, &r).unwrap())
    });
}

/// A seeded stabilisable problem: `A` with uniform entries of variance
/// about 1/n plus 0.2 I (some modes unstable), `B` n × n/10, `Q = I`,
/// `R = I`. A small LCG keeps the bench free of a random-number crate.
fn random_problem(n: usize, seed: u64) -> (DynStateSpace, DMatrix<f64>, DMatrix<f64>) {
    let mut state = seed;
    let mut next = move || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (state >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    };
    let scale = (3.0 / n as f64).sqrt();
    let a = DMatrix::from_fn(n, n, |i, j| next() * scale + if i == j { 0.2 } else { 0.0 });
    let m = (n / 10).max(1);
    let b = DMatrix::from_fn(n, m, |_, _| next());
    let sys = DynStateSpace::continuous(a, b, DMatrix::zeros(0, n), DMatrix::zeros(0, m)).unwrap();
    (sys, DMatrix::identity(n, n), DMatrix::identity(m, m))
}

fn riccati(c: &mut Criterion) {
    let plant = MassSpring::nominal().state_space(Cart::Two).unwrap();
    let q = SMatrix::<f64, 4, 4>::from_diagonal(&vector![0.0, 0.0, 1e6, 0.0]);
    let r = matrix![1.0];
    c.bench_function("lqr (lab plant, 4 states)", |b| {
        b.iter(|| lqr(black_box(&plant), &q, &r).unwrap())
    });
    let mut group = c.benchmark_group("lqr, DynStateSpace (random, seeded)");
    group.sample_size(10);
    for n in [20, 60, 100] {
        let (sys, q, r) = random_problem(n, n as u64);
        group.bench_function(format!("n = {n}"), |b| {
            b.iter(|| lqr(&sys, black_box(&q), &r).unwrap())
        });
    }
    group.finish();

    let data: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/tests/data/riccati_fixtures.json"
        ))
        .unwrap(),
    )
    .unwrap();
    let case = &data["carex"][17];
    let m = |k: &str| {
        let rows: Vec<Vec<f64>> = serde_json::from_value(case[k]["re"].clone()).unwrap();
        DMatrix::from_fn(rows.len(), rows[0].len(), |i, j| rows[i][j])
    };
    let [a, b_, q, r] = ["a", "b", "q", "r"].map(m);
    let mut group = c.benchmark_group("care");
    group.sample_size(10);
    group.bench_function("CAREX 18 (n = 100)", |b| {
        b.iter(|| care(black_box(&a), &b_, &q, &r).unwrap())
    });
    group.finish();
}

criterion_group!(design, benches, riccati);
criterion_main!(design);
