//! One iteration of the 2 ms control loop on the simulated card: latch and
//! kick, read both counters, a state-feedback update `u = -k·x` with constant
//! gains, PWM write. Target: under 2 µs (a thousandth of the period).

use criterion::{Criterion, criterion_group, criterion_main};
use ctrlab::MassSpring;
use ctrlab::hw::{
    Calibration, MassSpringRig, Pc104, Rig, SimulatedCard, SimulatedCardConfig, VirtualClock,
};
use nalgebra::SMatrix;
use std::hint::black_box;

fn rig(clock: &VirtualClock) -> MassSpringRig<SimulatedCard> {
    let config = SimulatedCardConfig {
        truth: MassSpring::nominal(),
        watchdog_timeout: None,
        initial_state: nalgebra::vector![0.001, 0.0, 0.002, 0.0],
        ..Default::default()
    };
    let card = SimulatedCard::virtual_time(config, clock).unwrap();
    MassSpringRig::new(Pc104::new(card), Calibration::default(), 0.002).unwrap()
}

fn benches(c: &mut Criterion) {
    // The lab's gain [0 0 10 0.1] per mm, in SI (V per m, V per m/s).
    let k = SMatrix::<f64, 1, 4>::new(0.0, 0.0, 10_000.0, 100.0);

    c.bench_function("loop iteration, simulated card, clock held", |b| {
        let clock = VirtualClock::new();
        let mut rig = rig(&clock);
        b.iter(|| {
            let x = rig.read_state().unwrap();
            let u = -(k * x)[0];
            rig.apply_voltage(black_box(u)).unwrap();
        })
    });

    c.bench_function("loop iteration, simulated card, plant advanced 2 ms", |b| {
        let clock = VirtualClock::new();
        let mut rig = rig(&clock);
        b.iter(|| {
            clock.advance_nanos(2_000_000);
            let x = rig.read_state().unwrap();
            let u = -(k * x)[0];
            rig.apply_voltage(black_box(u)).unwrap();
        })
    });
}

criterion_group!(hw, benches);
criterion_main!(hw);
