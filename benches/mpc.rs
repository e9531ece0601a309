//! The lab's MPC per tick (issue 31: at most 200 µs in the worst case on
//! the lab's problem, 4 states, horizon 20–40): `lab::mpc::design` on the
//! nominal plant, cart 2 to 45 mm, at horizons 20, 30 and 40.
//!
//! - *hold*: a tick at rest on the setpoint (the warm start is the plan:
//!   the common case);
//! - *step*: the first tick of the 45 mm step from rest (no plan yet);
//! - *worst*: the tick of a 3 s closed-loop step (on the rig as the
//!   prediction knows it: Coulomb friction, the drive's steps, the
//!   encoders' counts) that took the most active-set solves, replayed from
//!   a copy of the controller taken just before it.
//!
//! - *budget spent*: the step's first tick with tolerances no iterate
//!   meets, so it runs every bound out (a polish, 50 active-set solves,
//!   200 ADMM iterations with a polish every 10) and falls back: the most
//!   work any tick can do, whatever the state; and the same with the
//!   a wall-clock budget of 100 µs (`QpSettings::time_limit`), the most
//!   time a tick can take when its solve is limited to a tenth of that of
//!   the lab's `TICK_TIME_LIMIT`.
//!
//! The step, worst and budget ticks run on a fresh copy each time (its memory
//! just written, so they include the cache misses a copy brings).
//!
//! `scripts/mpc_vs_python.py` times python-control's MPC on the same
//! plant in one run.

use criterion::{BatchSize, Criterion, criterion_group, criterion_main};
use ctrlab::Controller;
use ctrlab::design::mpc::{MPC_SOLVER, QpSettings};
use ctrlab::lab::{Calibration, Cart, MassSpring, lqi, mpc};
use ctrlab::nalgebra::{SVector, vector};
use ctrlab::sim::run_sampled;
use std::hint::black_box;

/// Keeps a copy of the controller (and its inputs) from before the tick
/// with the most active-set solves.
struct Worst {
    inner: mpc::PositionsMpc,
    worst: Option<(usize, mpc::PositionsMpc, SVector<f64, 4>)>,
}

impl Controller<4, 1, 1> for Worst {
    fn update(&mut self, y: &SVector<f64, 4>, r: &SVector<f64, 1>) -> SVector<f64, 1> {
        let before = self.inner.clone();
        let u = self.inner.update(y, r);
        let steps = self
            .inner
            .inner()
            .last_report()
            .map_or(0, |r| r.active_set_steps);
        if self.worst.as_ref().is_none_or(|(s, _, _)| steps > *s) {
            self.worst = Some((steps, before, *y));
        }
        u
    }
    fn applied(&mut self, u: &SVector<f64, 1>) {
        self.inner.applied(u)
    }
    fn reset(&mut self) {
        self.inner.reset()
    }
    fn period(&self) -> Option<f64> {
        self.inner.period()
    }
}

fn benches(c: &mut Criterion) {
    let cal = Calibration::default();
    let nominal = MassSpring::nominal();
    let model = lqi::position_model(&nominal, 0.002).unwrap();
    let rig = lqi::predicted_rig(nominal, [1.0, 2.0], &cal, 0.002);
    let setpoint = vector![0.045];
    for horizon in [20, 30, 40] {
        let tuning = mpc::Tuning {
            horizon,
            ..mpc::Tuning::LAB
        };
        let fresh = mpc::design_with(&model, Cart::Two, &cal, &tuning).unwrap();

        // Settled at the setpoint: run the model there first.
        let mut holding = fresh.clone();
        let mut x = SVector::<f64, 4>::zeros();
        for _ in 0..1500 {
            let u = holding.update(&x, &setpoint);
            holding.applied(&u);
            x = model.a() * x + model.b() * u;
        }
        // Tick after tick at rest, as the loop runs it (warm caches).
        c.bench_function(
            &format!("MPC tick, holding 45 mm, horizon {horizon}"),
            |b| b.iter(|| holding.update(black_box(&x), black_box(&setpoint))),
        );
        c.bench_function(
            &format!("MPC tick, step from rest, horizon {horizon}"),
            |b| {
                b.iter_batched_ref(
                    || fresh.clone(),
                    |ctrl| ctrl.update(black_box(&SVector::zeros()), black_box(&setpoint)),
                    BatchSize::SmallInput,
                )
            },
        );
        let mut watch = Worst {
            inner: fresh.clone(),
            worst: None,
        };
        run_sampled(
            rig.plant(),
            rig.sensor(),
            &mut watch,
            |_| setpoint,
            SVector::zeros(),
            &rig.sampled_config(3.0),
        )
        .unwrap();
        let (steps, before, y) = watch.worst.expect("ticks ran");
        // Tolerances no iterate meets: every bound runs out. Without a time
        // limit that is the most work a tick can do; with a wall-clock one
        // the most time.
        for (what, time_limit) in [
            ("", None),
            (
                ", 100 µs time limit",
                Some(std::time::Duration::from_micros(100)),
            ),
        ] {
            let unmet = QpSettings {
                eps_abs: f64::MIN_POSITIVE,
                eps_rel: 0.0,
                time_limit,
                ..MPC_SOLVER
            };
            let spent = mpc::design_with(
                &model,
                Cart::Two,
                &cal,
                &mpc::Tuning {
                    solver: unmet,
                    ..tuning
                },
            )
            .unwrap();
            let mut trial = spent.clone();
            trial.update(&SVector::zeros(), &setpoint);
            let report = trial.inner().last_report().expect("a solve ran");
            let counts = format!(
                "{} active-set solves, {} ADMM iterations, {:?}",
                report.active_set_steps, report.iterations, report.status
            );
            c.bench_function(
                &format!("MPC tick, budget spent{what} ({counts}), horizon {horizon}"),
                |b| {
                    b.iter_batched_ref(
                        || spent.clone(),
                        |ctrl| ctrl.update(black_box(&SVector::zeros()), black_box(&setpoint)),
                        BatchSize::SmallInput,
                    )
                },
            );
        }
        c.bench_function(
            &format!("MPC tick, worst of a step ({steps} active-set solves), horizon {horizon}"),
            |b| {
                b.iter_batched_ref(
                    || before.clone(),
                    |ctrl| ctrl.update(black_box(&y), black_box(&setpoint)),
                    BatchSize::SmallInput,
                )
            },
        );
    }
}

criterion_group!(mpc_benches, benches);
criterion_main!(mpc_benches);
