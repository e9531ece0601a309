//! One iteration of the 2 ms control loop on the simulated card: latch and
//! kick, read both counters (with the rig's plausibility checks), the lab's
//! `StateFeedback` update, PWM write. Target: under 2 µs (a thousandth of
//! the period).

use criterion::{Criterion, criterion_group, criterion_main};
use ctrlab::hw::{Clock, SimulatedCard, VirtualClock};
use ctrlab::lab::{Calibration, FrictionPlant, LabGains, MassSpringRig, SimulatedRig};
use ctrlab::{Cart, Controller};
use nalgebra::vector;
use std::hint::black_box;

/// The lab's realistic rig (default truth, friction and stiction, PWM delay,
/// encoder noise), without the card's watchdog: the benchmark measures the
/// loop's own work.
fn rig(clock: &VirtualClock) -> MassSpringRig<SimulatedCard<FrictionPlant, 4>> {
    SimulatedRig {
        initial_state: [0.001, 0.0, 0.002, 0.0],
        calibration: Calibration {
            watchdog_timeout: None,
            ..Calibration::default()
        },
        ..Default::default()
    }
    .rig(&Clock::Virtual(clock.clone()))
    .unwrap()
}

fn benches(c: &mut Criterion) {
    // The lab's gain [0 0 10 0.1] per mm on cart 2, setpoint 30 mm.
    let mut ctrl = LabGains::new([0.0, 0.0, 10.0, 0.1], Cart::Two)
        .state_feedback()
        .unwrap();

    c.bench_function("loop iteration, simulated card, clock held", |b| {
        let clock = VirtualClock::new();
        let mut rig = rig(&clock);
        b.iter(|| {
            let x = rig.read_state().unwrap();
            let u = ctrl.update(&x, &black_box(vector![0.030]))[0];
            rig.apply_voltage(u).unwrap();
        })
    });

    c.bench_function("loop iteration, simulated card, plant advanced 2 ms", |b| {
        let clock = VirtualClock::new();
        let mut rig = rig(&clock);
        b.iter(|| {
            clock.advance_nanos(2_000_000);
            let x = rig.read_state().unwrap();
            let u = ctrl.update(&x, &black_box(vector![0.030]))[0];
            rig.apply_voltage(u).unwrap();
        })
    });
}

criterion_group!(hw, benches);
criterion_main!(hw);
