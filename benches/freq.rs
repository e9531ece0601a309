//! Frequency-response cost: a 1000-point Bode evaluation of the lab plant
//! (4 states, one input and output), through the fixed-size and the
//! run-time-sized model, and the complex response alone.

use criterion::{Criterion, criterion_group, criterion_main};
use ctrlab::freq::{FrequencyDomain, TransferFunction, bode, logspace, stability_margins};
use ctrlab::{Cart, DynStateSpace, MassSpring};
use std::hint::black_box;

fn benches(c: &mut Criterion) {
    let plant = MassSpring::nominal().state_space(Cart::Two).unwrap();
    let dynamic = DynStateSpace::from(&plant);
    let w = logspace(0.0, 3.0, 1000).unwrap();

    c.bench_function("bode, lab plant, 1000 points (StateSpace)", |b| {
        b.iter(|| bode(black_box(&plant), black_box(&w)).unwrap())
    });
    c.bench_function("bode, lab plant, 1000 points (DynStateSpace)", |b| {
        b.iter(|| bode(black_box(&dynamic), black_box(&w)).unwrap())
    });
    c.bench_function("frequency_response, lab plant, 1000 points", |b| {
        b.iter(|| {
            black_box(&dynamic)
                .frequency_response(black_box(&w))
                .unwrap()
        })
    });
    let g = TransferFunction::try_from(&plant).unwrap();
    let l = TransferFunction::continuous(
        &g.num().iter().map(|c| 2000.0 * c).collect::<Vec<_>>(),
        g.den(),
    )
    .unwrap();
    c.bench_function("stability_margins, lab plant under P control", |b| {
        b.iter(|| stability_margins(black_box(&l)).unwrap())
    });
}

criterion_group!(freq, benches);
criterion_main!(freq);
