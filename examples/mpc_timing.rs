//! How long the lab's MPC takes per tick: each case of `lab::mpc` run on
//! the rig as the prediction knows it (virtual time), every `update`
//! timed on the wall clock; median, 99th percentile and the longest, with
//! the solver's iterations and fallbacks, for horizons 20, 30 and 40.
//!
//! `cargo run --release --example mpc_timing [-- runs]`

use std::time::Instant;

use ctrlab::Controller;
use ctrlab::lab::{Calibration, SimulatedRig, lqi, mpc};
use ctrlab::nalgebra::{SVector, vector};
use ctrlab::sim::run_sampled;

/// Times every `update` of the controller it wraps.
struct Timed<C> {
    inner: C,
    ticks: Vec<f64>,
}

impl<C: Controller<4, 1, 1>> Controller<4, 1, 1> for Timed<C> {
    fn update(&mut self, y: &SVector<f64, 4>, r: &SVector<f64, 1>) -> SVector<f64, 1> {
        let start = Instant::now();
        let u = self.inner.update(y, r);
        self.ticks.push(start.elapsed().as_secs_f64());
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

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let runs: usize = std::env::args().nth(1).map_or(Ok(5), |a| a.parse())?;
    let calibration = Calibration::default();
    let sim = SimulatedRig::default();
    let rig = lqi::predicted_rig(sim.truth, sim.friction.coulomb, &calibration, 0.002);
    let model = lqi::position_model(&rig.truth, rig.period)?;
    println!(
        "horizon | case | ticks | median µs | p99 µs | max µs | ADMM iterations max | active-set solves max | fallbacks"
    );
    for horizon in [20, 30, 40] {
        let tuning = mpc::Tuning {
            horizon,
            ..mpc::Tuning::LAB
        };
        for (cart, setpoint) in mpc::cases(&calibration) {
            let mut timed = Timed {
                inner: mpc::design_with(&model, cart, &calibration, &tuning)?,
                ticks: Vec::new(),
            };
            let (mut iterations, mut steps, mut fallbacks) = (0, 0, 0);
            for _ in 0..runs {
                run_sampled(
                    rig.plant(),
                    rig.sensor(),
                    &mut timed,
                    |_| vector![setpoint],
                    SVector::zeros(),
                    &rig.sampled_config(3.0),
                )?;
                let stats = timed.inner.inner().stats();
                iterations = iterations.max(stats.iterations_max);
                steps = steps.max(stats.active_set_steps_max);
                fallbacks += stats.fallbacks();
            }
            let mut t = timed.ticks.clone();
            t.sort_by(f64::total_cmp);
            let at = |q: f64| t[((t.len() - 1) as f64 * q).round() as usize] * 1e6;
            println!(
                "{horizon} | {cart:?} to {:.0} mm | {} | {:.1} | {:.1} | {:.1} | {iterations} | {steps} | {fallbacks}",
                setpoint * 1e3,
                t.len(),
                at(0.5),
                at(0.99),
                at(1.0)
            );
        }
    }
    Ok(())
}
