//! Do the identification's standard errors cover the truth? Seeded runs of
//! the simulated rig (Coulomb friction, stiction, PWM delay, encoder
//! quantisation and noise), identified with `Scheme::Central` and Coulomb
//! friction: classical against Newey–West standard errors (issue 12).
//!
//! The seed changes only the encoder noise, so the spread of the
//! estimates over the runs is the sampling spread the standard errors
//! estimate; what the plant has and the model lacks (the PWM delay, the
//! friction's stick–slip) is a bias common to every run, which no standard
//! error covers.

// Built on the two-cart lab (its plant, simulated rig or card).
#![cfg(feature = "lab")]

mod common;

use ctrlab::ident::Covariance;
use ctrlab::lab::ident::{
    Bootstrap, Estimate, Options, Scheme, SpringModel, bootstrap, identify_with, refine_with,
};
use ctrlab::lab::{CardSettings, SimulatedRig};
use ctrlab::signal::SquareWave;
use ctrlab::{MassSpring, Recording};

/// The default simulated rig with the seed, and with equal springs
/// (950 N/m) so that the equal-spring model's `k12` has one true value;
/// everything else a linear model lacks is kept.
fn equal_springs(seed: u64) -> SimulatedRig {
    let mut sim = SimulatedRig {
        card: CardSettings {
            seed,
            ..CardSettings::default()
        },
        // Off: the coverage of the standard errors on the model's own
        // structure (bounds measured without the unmodelled effects;
        // lab_identification checks the default rig with them).
        unmodelled: ctrlab::lab::Unmodelled::NONE,
        ..SimulatedRig::default()
    };
    sim.truth.k2 = sim.truth.k1;
    sim
}

/// lab5's identification run on `sim`: ±8 V square wave, 0.2 s half
/// period, 5 s at 2 ms.
fn record(sim: &SimulatedRig) -> Recording {
    common::open_loop(sim, &SquareWave::new(8.0, 0.2).unwrap(), 5.0)
}

fn options(coulomb: bool, covariance: Covariance) -> Options {
    Options {
        scheme: Scheme::Central,
        coulomb,
        covariance,
        ..Options::default()
    }
}

/// `[k12, K, b1, b2]` of the equal-spring identification, and the
/// bandwidths of its two stages.
fn equal(rec: &Recording, truth: &MassSpring, options: &Options) -> (Vec<Estimate>, [usize; 2]) {
    let e = identify_with(rec, truth.m1, truth.m2, options).unwrap();
    let lags = |c: Covariance| match c {
        Covariance::NeweyWest { lags: Some(l) } => l,
        _ => 0,
    };
    (
        vec![e.k12().unwrap(), e.gain, e.b1, e.b2],
        [
            lags(e.first.covariance_kind),
            lags(e.second.covariance_kind),
        ],
    )
}

/// Per parameter: the fraction of runs with `|θ̂ − θ| ≤ 1.96 se`, the
/// mean standard error over the standard deviation of `θ̂` over the runs,
/// and the mean's bias over that deviation.
#[derive(Debug)]
struct Coverage {
    coverage: Vec<f64>,
    se_over_spread: Vec<f64>,
    bias_over_spread: Vec<f64>,
}

fn coverage(runs: &[Vec<Estimate>], truth: &[f64]) -> Coverage {
    let n = runs.len() as f64;
    let mut out = Coverage {
        coverage: Vec::new(),
        se_over_spread: Vec::new(),
        bias_over_spread: Vec::new(),
    };
    for (i, &truth) in truth.iter().enumerate() {
        let values: Vec<f64> = runs.iter().map(|e| e[i].value).collect();
        let mean = values.iter().sum::<f64>() / n;
        let sd = (values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
        let se = runs.iter().map(|e| e[i].std_error).sum::<f64>() / n;
        let covered = runs
            .iter()
            .filter(|e| (e[i].value - truth).abs() <= 1.96 * e[i].std_error)
            .count();
        out.coverage.push(covered as f64 / n);
        out.se_over_spread.push(se / sd);
        out.bias_over_spread.push((mean - truth) / sd);
    }
    out
}

fn row(name: &str, c: &Coverage, lags: &str) {
    let f = |v: &[f64], d: usize| {
        v.iter()
            .map(|x| format!("{x:>6.d$}"))
            .collect::<Vec<_>>()
            .join(" ")
    };
    println!(
        "{name:<16} | {} | {} | {} | {lags}",
        f(&c.coverage, 3),
        f(&c.se_over_spread, 2),
        f(&c.bias_over_spread, 2)
    );
}

/// The covariances compared: classical, Newey–West with the automatic
/// bandwidth, and (`fixed`) with fixed ones.
fn kinds(fixed: bool) -> Vec<(String, Covariance)> {
    let mut kinds = vec![
        ("classical".to_string(), Covariance::Classical),
        (
            "Newey–West auto".into(),
            Covariance::NeweyWest { lags: None },
        ),
    ];
    if fixed {
        for lags in [0, 2, 8, 32, 128] {
            kinds.push((
                format!("Newey–West L={lags}"),
                Covariance::NeweyWest { lags: Some(lags) },
            ));
        }
    }
    kinds
}

/// The measurement behind the numbers in `Covariance`'s docs and the
/// README (about 15 s in release for 400 runs):
///
/// `RUNS=400 cargo test --release --test ident_coverage -- --ignored --nocapture`
#[test]
#[ignore = "the measurement for the docs: run in release"]
fn measure_coverage() {
    let runs: u64 = std::env::var("RUNS").map_or(400, |v| v.parse().unwrap());
    let started = std::time::Instant::now();
    let truth = equal_springs(0).truth;
    let recordings: Vec<Recording> = (1..=runs).map(|s| record(&equal_springs(s))).collect();
    println!("{runs} runs simulated in {:.1?}", started.elapsed());
    let header = |what: &str| {
        println!("\n{what}");
        println!(
            "{:<16} | coverage | se / spread | bias / spread | mean L stage 1, 2",
            ""
        );
    };
    for coulomb in [true, false] {
        header(&format!(
            "equal springs (950 N/m), Central, coulomb: {coulomb}: k12 K b1 b2"
        ));
        let want = [truth.k1, truth.gain, truth.b1, truth.b2];
        for (name, kind) in kinds(coulomb) {
            let fits: Vec<_> = recordings
                .iter()
                .map(|r| equal(r, &truth, &options(coulomb, kind)))
                .collect();
            let estimates: Vec<_> = fits.iter().map(|f| f.0.clone()).collect();
            let mean_lags =
                |s: usize| fits.iter().map(|f| f.1[s] as f64).sum::<f64>() / runs as f64;
            let lags = format!("{:.0}, {:.0}", mean_lags(0), mean_lags(1));
            row(&name, &coverage(&estimates, &want), &lags);
        }
    }
    // The default rig (k1 = 950, k2 = 1020 N/m), separate springs: lab5's
    // identification.
    let truth = SimulatedRig::default_truth();
    let recordings: Vec<Recording> = (1..=runs)
        .map(|seed| {
            record(&SimulatedRig {
                card: CardSettings {
                    seed,
                    ..CardSettings::default()
                },
                // Off: the coverage of the standard errors on the model's own
                // structure (bounds measured without the unmodelled effects;
                // lab_identification checks the default rig with them).
                unmodelled: ctrlab::lab::Unmodelled::NONE,
                ..SimulatedRig::default()
            })
        })
        .collect();
    header("default rig, separate springs, Central, coulomb: true: k1 k2 K b1 b2");
    let want = [truth.k1, truth.k2, truth.gain, truth.b1, truth.b2];
    for (name, kind) in kinds(false) {
        let estimates: Vec<_> = recordings
            .iter()
            .map(|r| {
                let options = Options {
                    springs: SpringModel::Separate,
                    ..options(true, kind)
                };
                let e = identify_with(r, truth.m1, truth.m2, &options).unwrap();
                vec![e.k1(), e.k2(), e.gain, e.b1, e.b2]
            })
            .collect();
        row(&name, &coverage(&estimates, &want), "");
    }
}

/// CI's share of the measurement: the first 20 seeds of
/// [`measure_coverage`]'s 400 (16 s in debug), equal springs, Central with
/// Coulomb friction. The bands are the 400-run numbers widened by about
/// three binomial (coverage: ±7 to ±11 points each) or sampling (the
/// standard deviation of 20 values: ±16 % each) standard deviations.
#[test]
fn newey_west_errors_match_the_spread_and_cover_all_but_the_bias() {
    const RUNS: u64 = 20;
    let truth = equal_springs(0).truth;
    let want = [truth.k1, truth.gain, truth.b1, truth.b2];
    let recordings: Vec<Recording> = (1..=RUNS).map(|s| record(&equal_springs(s))).collect();
    let run = |covariance| -> Vec<Vec<Estimate>> {
        recordings
            .iter()
            .map(|r| equal(r, &truth, &options(true, covariance)).0)
            .collect()
    };
    let (classical, hac) = (
        run(Covariance::Classical),
        run(Covariance::NeweyWest { lags: None }),
    );
    // Only the standard errors differ.
    for (c, h) in classical.iter().zip(&hac) {
        for (c, h) in c.iter().zip(h) {
            assert_eq!(c.value.to_bits(), h.value.to_bits());
        }
    }
    let (c, h) = (coverage(&classical, &want), coverage(&hac, &want));
    println!("classical {c:?}\nNewey–West {h:?}");
    let names = ["k12", "K", "b1", "b2"];
    for (i, name) in names.iter().enumerate() {
        // 400 runs: classical 3.7 to 9.8 times the spread, Newey–West
        // 1.06 to 1.22.
        assert!(c.se_over_spread[i] > 2.5, "{name}: {c:?}");
        assert!((0.6..1.8).contains(&h.se_over_spread[i]), "{name}: {h:?}");
    }
    // 400 runs: 89.0, 93.2 and 93.0 % for k12, b1, b2.
    for i in [0, 2, 3] {
        assert!(h.coverage[i] >= 0.7, "{}: {h:?}", names[i]);
    }
    // K is biased by 1.75 standard deviations (the PWM delay and the
    // stick–slip friction the model lacks): 62.3 % in 400 runs, and no
    // honest standard error does better.
    assert!((0.3..0.95).contains(&h.coverage[1]), "{h:?}");
    assert!(h.bias_over_spread[1] > 1.0, "{h:?}");
}

/// The refined model's parameters `[k1, k2, b1, b2, K, F1, F2]` for the
/// default rig with noise `seed`: lab5's identification run, least squares
/// with Coulomb friction, refined with the card's structure; with
/// `resamples`, their bootstrap standard errors (else 0).
fn refined_with_errors(seed: u64, resamples: Option<usize>) -> Vec<Estimate> {
    let sim = SimulatedRig {
        card: CardSettings {
            seed,
            ..CardSettings::default()
        },
        // Off: the coverage of the standard errors on the model's own
        // structure (bounds measured without the unmodelled effects;
        // lab_identification checks the default rig with them).
        unmodelled: ctrlab::lab::Unmodelled::NONE,
        ..SimulatedRig::default()
    };
    let rec = record(&sim);
    let identification = Options {
        springs: SpringModel::Separate,
        coulomb: true,
        ..Options::default()
    };
    let ls = identify_with(&rec, sim.truth.m1, sim.truth.m2, &identification).unwrap();
    let model = sim.simulation_model();
    let r = refine_with(&rec, &ls, &model).unwrap();
    let se = resamples.map(|resamples| {
        let options = Bootstrap {
            resamples,
            seed,
            ..Bootstrap::default()
        };
        bootstrap(&rec, &identification, &r, &model, &options)
            .unwrap()
            .to_array()
    });
    r.parameters()
        .into_iter()
        .enumerate()
        .map(|(i, value)| Estimate {
            value,
            std_error: se.map_or(0.0, |s| s[i]),
        })
        .collect()
}

fn refined(seed: u64) -> [f64; 7] {
    let e = refined_with_errors(seed, None);
    std::array::from_fn(|i| e[i].value)
}

/// The truth `[k1, k2, b1, b2, K, F1, F2]` of the default rig.
fn refined_truth() -> [f64; 7] {
    let (t, f) = (
        SimulatedRig::default_truth(),
        SimulatedRig::default().friction.coulomb,
    );
    [t.k1, t.k2, t.b1, t.b2, t.gain, f[0], f[1]]
}

/// The bootstrap's coverage of the refined parameters (the numbers in
/// `bootstrap`'s docs and the README):
///
/// `RUNS=100 RESAMPLES=30 cargo test --release --test ident_coverage -- --ignored --nocapture bootstrap`
#[test]
#[ignore = "the measurement for the docs: run in release"]
fn measure_bootstrap_coverage() {
    let runs: u64 = std::env::var("RUNS").map_or(100, |v| v.parse().unwrap());
    let resamples: usize = std::env::var("RESAMPLES").map_or(30, |v| v.parse().unwrap());
    let started = std::time::Instant::now();
    let estimates: Vec<Vec<Estimate>> = (1..=runs)
        .map(|seed| refined_with_errors(seed, Some(resamples)))
        .collect();
    println!(
        "{runs} runs refined and bootstrapped ({resamples} resamples) in {:.1?}",
        started.elapsed()
    );
    println!("refined, default rig: k1 k2 b1 b2 K F1 F2");
    println!("{:<16} | coverage | se / spread | bias / spread", "");
    row("bootstrap", &coverage(&estimates, &refined_truth()), "");
}

/// The refined parameters' bias and spread over seeded runs (the numbers
/// in `refine`'s docs and the README): the mean error and the standard
/// deviation over the runs, relative to the truth.
///
/// `RUNS=400 cargo test --release --test ident_coverage -- --ignored --nocapture refined`
#[test]
#[ignore = "the measurement for the docs: run in release"]
fn measure_refined_spread() {
    let runs: u64 = std::env::var("RUNS").map_or(400, |v| v.parse().unwrap());
    let started = std::time::Instant::now();
    let estimates: Vec<[f64; 7]> = (1..=runs).map(refined).collect();
    println!("{runs} runs refined in {:.1?}", started.elapsed());
    let truth = refined_truth();
    for (i, name) in ["k1", "k2", "b1", "b2", "K", "F1", "F2"].iter().enumerate() {
        let errors: Vec<f64> = estimates.iter().map(|e| e[i] / truth[i] - 1.0).collect();
        let n = errors.len() as f64;
        let mean = errors.iter().sum::<f64>() / n;
        let sd = (errors.iter().map(|e| (e - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
        let worst = errors.iter().fold(0.0f64, |w, e| w.max(e.abs()));
        println!(
            "{name:<3} mean error {:+.4} %, spread {:.4} %, worst {:.4} %",
            100.0 * mean,
            100.0 * sd,
            100.0 * worst
        );
    }
}
