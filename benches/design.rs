//! Design and control-update costs: the observer + LQI controller's
//! per-period update (the 2 ms loop's work), the full-state integral
//! controller's, and the design functions (`place` for 4 states and
//! 2 inputs, `dlqe`, `dlqi`).

#[path = "../tests/common/mod.rs"]
mod common;

use criterion::{Criterion, criterion_group, criterion_main};
use ctrlab::design::{AntiWindup, IntegralFeedback, dlqe, dlqi, place};
use ctrlab::{Controller, StateSpace};
use nalgebra::{Complex, SMatrix, matrix, vector};
use std::hint::black_box;

fn benches(c: &mut Criterion) {
    // The tests' controller: LQI on cart 2, Kalman filter on both positions.
    let metres_per_count = 0.080 / 8192.0;
    let model = common::position_model();
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
            let mut ctrl = common::positions_lqi(metres_per_count);
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

criterion_group!(design, benches);
criterion_main!(design);
