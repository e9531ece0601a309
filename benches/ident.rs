//! Identification inner loops: the lab's two-stage identification over
//! 5000 samples (target < 50 µs; NumPy's `lstsq` alone takes about 56 µs
//! for one 5000×2 solve), with its default Newey–West standard errors and
//! with the classical ones, one `Rls` update for P = 2 (target < 30 ns), and
//! the output-error refinement of a 5000-sample run (target < 50 ms): ideal
//! sampled data at one step per sample, and the simulated card's run with
//! its own structure (delay, stiction, 0.25 ms sub-steps). Also the
//! two-stage identification over 500 000 samples, classical and Newey–West
//! (issue 30: targets 6× NumPy's `lstsq`, about 3.5 ms on a quiet machine,
//! and Newey–West within 2× of classical; `scripts/ahead_metrics_ident.py`
//! times NumPy on the same kind of run).

use criterion::{Criterion, criterion_group, criterion_main};
use ctrlab::data::{Channel, Schema};
use ctrlab::hw::{self, Clock, LoopConfig, VirtualClock};
use ctrlab::ident::Covariance;
use ctrlab::lab::SimulatedRig;
use ctrlab::lab::ident::{
    MassSpringEstimate, Options, Scheme, SimulationModel, SpringModel, identify, identify_with,
    refine_with,
};
use ctrlab::signal::{Signal, SquareWave};
use ctrlab::sim::{Solver, simulate, time_grid};
use ctrlab::{Cart, MassSpring, OpenLoop, Recording, Rls};
use nalgebra::{SVector, vector};
use std::hint::black_box;

const SAMPLES: usize = 5000;

/// A square-wave run of the fixture's plant, `samples` at 2 ms (10 s at
/// 5000), quantised like the rig's encoders (102 400 counts/m), with the
/// channels of the lab's logs (`u`, `x1`, `x2`).
fn recording(samples: usize) -> Recording {
    let plant = MassSpring {
        k1: 950.0,
        k2: 950.0,
        b1: 12.3,
        b2: 6.1,
        gain: 8.5,
        ..MassSpring::nominal()
    };
    let sys = plant.state_space(Cart::Two).unwrap();
    let t = time_grid((samples - 1) as f64 * 0.002, 0.002).unwrap();
    // ±2 V every 0.2 s (for t ≥ 0 the same values as the hand-written
    // `⌊t / 0.2⌋` even/odd wave this bench used before).
    let wave = SquareWave::new(2.0, 0.2).unwrap();
    let square = |t: f64| wave.value(t);
    let r = simulate(
        &sys,
        &t,
        SVector::zeros(),
        |t| vector![square(t)],
        Solver::Zoh,
    )
    .unwrap();
    let q = |x: f64| (x * 102_400.0).round() / 102_400.0;
    let schema = Schema::new(
        vec![Channel::new("u", "V")],
        vec![Channel::new("x1", "m"), Channel::new("x2", "m")],
    )
    .unwrap();
    let mut rec = Recording::with_capacity(schema, t.len());
    for (k, &tk) in t.iter().enumerate() {
        rec.push(tk, &[square(tk)], &[q(r.x[k][0]), q(r.x[k][2])])
            .unwrap();
    }
    assert_eq!(rec.len(), samples);
    rec
}

/// A 10 s square-wave run (5000 samples) of the default simulated card
/// (Coulomb friction, stiction, PWM delay, encoder noise), its
/// least-squares start with Coulomb friction, and the card's structure.
fn simulated_card_run() -> (Recording, MassSpringEstimate, SimulationModel) {
    let sim = SimulatedRig::default();
    let clock = VirtualClock::new();
    let wave = SquareWave::new(8.0, 0.2).unwrap();
    let config = LoopConfig {
        duration: (SAMPLES as f64 - 0.5) * sim.period,
        ..LoopConfig::default()
    };
    let rig = sim.rig(&Clock::Virtual(clock.clone())).unwrap();
    let rec = hw::run(
        rig,
        OpenLoop,
        |t| vector![wave.value(t)],
        &Clock::Virtual(clock),
        &config,
    )
    .unwrap()
    .recording;
    assert_eq!(rec.len(), SAMPLES);
    let options = Options {
        springs: SpringModel::Separate,
        coulomb: true,
        ..Options::default()
    };
    let start = identify_with(&rec, 1.3, 0.7, &options).unwrap();
    (rec, start, sim.simulation_model())
}

fn benches(c: &mut Criterion) {
    let rec = recording(SAMPLES);
    c.bench_function("identify, Scheme::Lab, 5000 samples (two stages)", |b| {
        b.iter(|| identify(black_box(&rec), 1.3, 0.7, Scheme::Lab).unwrap())
    });
    c.bench_function(
        "identify, Scheme::Central, 5000 samples (two stages)",
        |b| b.iter(|| identify(black_box(&rec), 1.3, 0.7, Scheme::Central).unwrap()),
    );
    for scheme in [Scheme::Lab, Scheme::Central] {
        let options = Options {
            scheme,
            covariance: Covariance::Classical,
            ..Options::default()
        };
        c.bench_function(
            &format!("identify, Scheme::{scheme:?}, classical standard errors, 5000 samples"),
            |b| b.iter(|| identify_with(black_box(&rec), 1.3, 0.7, &options).unwrap()),
        );
    }
    let separate = Options {
        springs: SpringModel::Separate,
        ..Options::default()
    };
    let start = identify_with(&rec, 1.3, 0.7, &separate).unwrap();
    let mut slow = c.benchmark_group("refine");
    slow.sample_size(10);
    // The run is ideal sampled data (ZOH, no friction, no delay): one
    // exact step per sample is its structure.
    let ideal = SimulationModel {
        max_substep: 0.002,
        ..SimulationModel::default()
    };
    slow.bench_function(
        "output-error refinement, ideal sampled data, 5000 samples",
        |b| b.iter(|| refine_with(black_box(&rec), &start, &ideal).unwrap()),
    );
    let (card_run, card_start, model) = simulated_card_run();
    slow.bench_function(
        "output-error refinement, simulated card's structure, 5000 samples",
        |b| b.iter(|| refine_with(black_box(&card_run), &card_start, &model).unwrap()),
    );
    let long = recording(500_000);
    for covariance in [Covariance::Classical, Options::default().covariance] {
        let options = Options {
            covariance,
            ..Options::default()
        };
        let errors = match covariance {
            Covariance::Classical => "classical",
            _ => "Newey–West",
        };
        slow.bench_function(
            format!("identify, Scheme::Central, {errors} standard errors, 500 000 samples"),
            |b| b.iter(|| identify_with(black_box(&long), 1.3, 0.7, &options).unwrap()),
        );
    }
    slow.finish();
    c.bench_function("Rls<2> update", |b| {
        let mut rls = Rls::<2>::new(0.999, 1e3).unwrap();
        let mut k = 0u32;
        b.iter(|| {
            k = k.wrapping_add(1);
            let x = f64::from(k % 1000) * 1e-3;
            black_box(rls.update(black_box(&vector![1.0, x]), black_box(2.0 + 3.0 * x)))
        })
    });
}

criterion_group!(ident, benches);
criterion_main!(ident);
