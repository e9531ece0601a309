//! lab5 itself on jittered and stalled clocks (`--jitter`, the clock double
//! `hw::Jitter`), end to end: every run completes (no bus fault, no
//! refusal), the report counts the late and skipped ticks beside each
//! section's runs, the identification lands within the bounds of the
//! ideal-clock tests, the frequency section finds the modes, and the report
//! is written. tests/late_ticks.rs checks the library's analyses on such
//! recordings one by one; this checks lab5's pipeline over all of them.
//!
//! It runs the lab5 binary (`LAB5`, or the one next to this test's profile:
//! `cargo build --release --example lab5` first), so it is ignored by
//! default; `.ci/run` builds lab5 and runs it with `--ignored`. About 40 s
//! in release (eleven lab5 runs of 3.5 s).

// Built on the two-cart lab (its plant, simulated rig or card).
#![cfg(feature = "lab")]

#[path = "common/example.rs"]
mod example;

use std::path::PathBuf;
use std::process::Command;

/// The lab5 binary: `$LAB5`, else this test's profile's.
fn lab5_binary() -> PathBuf {
    example::example_binary("lab5", "LAB5", "cargo build --release --example lab5")
}

/// Runs lab5 with `--jitter jitter` (on the ideal virtual clock when
/// `jitter` is empty); its report.
fn lab5(jitter: &str) -> String {
    let name = if jitter.is_empty() { "ideal" } else { jitter };
    let out = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join("lab5-jitter")
        .join(name.replace(',', "_"));
    let mut command = Command::new(lab5_binary());
    if !jitter.is_empty() {
        command.args(["--jitter", jitter]);
    }
    let run = command
        .arg("--out")
        .arg(&out)
        .output()
        .expect("lab5 starts");
    assert!(
        run.status.success(),
        "lab5 --jitter {jitter}: {}\n{}",
        run.status,
        String::from_utf8_lossy(&run.stderr)
    );
    let report = std::fs::read_to_string(out.join("report.md")).expect("lab5 wrote its report");
    assert!(!report.contains("The lab stopped early"), "{report}");
    assert!(!report.contains("NaN"), "{report}");
    report
}

/// The cells of the table rows under the heading that starts with
/// `heading` (its header row included).
fn rows(report: &str, heading: &str) -> Vec<Vec<String>> {
    let mut on = false;
    let mut out = Vec::new();
    for line in report.lines() {
        if line.starts_with('#') {
            on = line.trim_start_matches('#').trim().starts_with(heading);
        } else if on && line.starts_with('|') && !line.starts_with("|---") {
            out.push(
                line.trim_matches('|')
                    .split(" | ")
                    .map(|c| c.trim().to_owned())
                    .collect(),
            );
        }
    }
    assert!(!out.is_empty(), "no table under `{heading}`");
    out
}

/// A cell's leading number (`949.9 ± 0.1`).
fn number(cell: &str) -> f64 {
    let first = cell.split_whitespace().next().unwrap_or_default();
    first
        .parse()
        .unwrap_or_else(|_| panic!("`{cell}` is not a number"))
}

/// The identified model's error against the simulated card's truth, %,
/// by parameter (`k1`, `k2`, `b1`, `b2`, `K`, `F1`, `F2`).
fn identification_errors(report: &str) -> Vec<(String, f64)> {
    rows(report, "The identified model and its uncertainty")
        .iter()
        .skip(1)
        .map(|r| {
            let name = r[0].split_whitespace().next().unwrap().to_owned();
            (name, (number(&r[1]) / number(&r[6]) - 1.0) * 100.0)
        })
        .collect()
}

/// The loop's timing sentences on the jittered clock: (overruns, skipped,
/// late) of each section that reports one.
fn timing(report: &str) -> Vec<[usize; 3]> {
    let count = |line: &str, what: &str| -> usize {
        let before = &line[..line.find(what).unwrap_or_else(|| panic!("{what}: {line}"))];
        before.split_whitespace().last().unwrap().parse().unwrap()
    };
    report
        .lines()
        .filter_map(|l| {
            l.find("Loop timing over these runs (the jittered virtual clock)")
                .map(|i| &l[i..])
        })
        .map(|l| {
            [
                count(l, " overruns"),
                count(l, " skipped ticks"),
                count(l, " late ticks"),
            ]
        })
        .collect()
}

/// What the jittered runs are held to beside the ideal clock's run of the
/// same lab5 (the same rig, the same per-run seeds): its refined fit,
/// bootstrap k1, measured modes and identification errors.
struct Ideal {
    fit: [f64; 2],
    k1: f64,
    modes: Vec<f64>,
    errors: Vec<(String, f64)>,
}

impl Ideal {
    fn run() -> Self {
        let report = lab5("");
        let (fit, k1) = refinement(&report);
        Self {
            fit,
            k1,
            modes: measured_modes(&report),
            errors: identification_errors(&report),
        }
    }
}

/// The refined model's fit on both carts (%) and the bootstrap's k1 (N/m).
fn refinement(report: &str) -> ([f64; 2], f64) {
    let validation = rows(report, "Validation");
    let refined = validation
        .iter()
        .find(|r| r[0] == "refined by output error")
        .expect("the refined row");
    let bootstrap = rows(report, "The refined parameters over every run");
    let first = bootstrap
        .iter()
        .find(|r| r[0].contains("bootstrap"))
        .expect("the bootstrap row");
    (
        [number(&refined[8]), number(&refined[9])],
        number(&first[1]),
    )
}

/// The frequency section's measured gain peaks, Hz.
fn measured_modes(report: &str) -> Vec<f64> {
    rows(report, "Frequency response")
        .iter()
        .skip(1)
        .map(|m| number(&m[3]))
        .collect()
}

/// Everything lab5 reports on a jittered run but the identification's
/// bounds: each section ran, counted its late and skipped ticks, and the
/// refinement, the bootstrap and the frequency section agree with the
/// ideal clock's run.
fn check_sections(report: &str, jitter: &str, ideal: &Ideal) {
    // The identification runs, Table 5 and Table 6 say how the loop ran.
    let timing = timing(report);
    assert_eq!(timing.len(), 3, "--jitter {jitter}: {timing:?}");
    for [overruns, skipped, late] in timing {
        assert_eq!(overruns, 0, "--jitter {jitter}");
        assert!(
            skipped > 0 && late > 0,
            "--jitter {jitter}: {skipped} {late}"
        );
    }
    // Validation and refinement against the ideal clock's: measured, the
    // ideal run's refined model fits 96.31 / 95.30 % (the card has what the
    // model lacks: the truth itself reaches about 96 %) and its bootstrap
    // k1 is 929.3 N/m; twenty jittered runs (both schedules, seeds 1–10)
    // fit 96.15–96.44 / 95.15–95.48 % with k1 928.9–929.7 N/m. Bounds:
    // 0.5 points of fit, 0.2 % of k1.
    let (fit, k1) = refinement(report);
    for (got, want) in fit.iter().zip(ideal.fit) {
        assert!((got - want).abs() < 0.5, "--jitter {jitter}: fit {fit:?}");
    }
    assert!(
        (k1 / ideal.k1 - 1.0).abs() < 0.002,
        "--jitter {jitter}: k1 {k1}"
    );
    // The frequency section: each measured gain peak within 0.2 Hz of the
    // ideal clock's (2.71 and 7.92 Hz; the twenty runs measured 2.68–2.77
    // and 7.92–8.01 Hz; before the section resampled gaps, `--jitter 11`
    // measured 2.33 and 3.02 Hz).
    let modes = measured_modes(report);
    assert_eq!(modes.len(), ideal.modes.len(), "--jitter {jitter}");
    for (got, want) in modes.iter().zip(&ideal.modes) {
        assert!((got - want).abs() < 0.2, "--jitter {jitter}: {modes:?}");
    }
    for heading in [
        "Table 5",
        "Table 6",
        "Predicted against measured",
        "Answers",
    ] {
        assert!(report.contains(heading), "--jitter {jitter}: no {heading}");
    }
}

/// The usual bounds of lab5's identification against the card's truth,
/// those of tests/lab_identification.rs (the default rig with its
/// unmodelled effects on, measured there over six sets of five runs):
/// springs within 0.3 %, K −3.2 to −1.7 %, b2 +3.0 to +5.5 %, the Coulomb
/// forces within 10 % of their nominal values; b1 unbounded.
fn assert_usual_bounds(errors: &[(String, f64)], what: &str) {
    for (name, e) in errors {
        let ok = match name.as_str() {
            "k1" | "k2" => e.abs() < 0.3,
            "K" => (-3.2..-1.7).contains(e),
            "b2" => (3.0..5.5).contains(e),
            "F1" | "F2" => e.abs() < 10.0,
            _ => true,
        };
        assert!(ok, "{what}: {name} {e:+.2} %");
    }
}

/// Each jittered run's identification error minus the ideal clock's,
/// percentage points, within `bounds` (k1/k2, K, b2, F1/F2).
fn assert_near_ideal(errors: &[(String, f64)], ideal: &Ideal, bounds: [f64; 4], what: &str) {
    assert_eq!(errors.len(), ideal.errors.len(), "{what}: {errors:?}");
    for ((name, e), (_, i)) in errors.iter().zip(&ideal.errors) {
        let bound = match name.as_str() {
            "k1" | "k2" => bounds[0],
            "K" => bounds[1],
            "b2" => bounds[2],
            "F1" | "F2" => bounds[3],
            _ => f64::INFINITY,
        };
        assert!(
            (e - i).abs() < bound,
            "{what}: {name} {e:+.2} % against the ideal clock's {i:+.2} %"
        );
    }
}

/// The schedule of tests/late_ticks.rs's identification test: 3 % of ticks
/// late by up to 6 ms (three periods), one in 500 stalled for 8–16 ms.
const MILD: &str = "0.03,0.006,0.002,0.016";

// Measured (% error of the five-run mean against the card's truth;
// `cargo build --release --example lab5`, then `lab5` for the ideal clock
// and `lab5 --jitter SEED[,0.03,0.006,0.002,0.016]`, seeds 1–10), on the
// default rig with its unmodelled effects on:
//
//                       k1     k2     b1     b2     K      F1     F2
//   ideal             +0.01  -0.08  -0.57  +4.07  -2.58  +6.80  +0.15
//   mild, mean        +0.04  -0.04  -0.33  +3.98  -2.50  +5.94  +0.80
//   mild, worst       +0.17  -0.18  -1.65  +2.73  -2.37  +10.4  +1.60
//   default, mean     +0.01  -0.13  -0.84  +4.42  -2.58  +7.24  +0.38
//   default, worst    -0.15  -0.36  -3.22  +2.35  -3.13  +15.1  +2.50
//
// Against the ideal run, a jittered one differs by at most (percentage
// points) k 0.16, K 0.21, b2 1.34, F 6.9 (mild) and k 0.39, K 0.67,
// b2 2.58, F 8.3 (default). The identification splits each recording at
// every late sample and stall and fits fewer rows (tests/late_ticks.rs):
// the spread grows, not the bias, so a single jittered run can leave the
// usual bounds (b2 +2.73 % on mild seed 1) while the mean of ten is inside
// them.

#[test]
#[ignore = "runs the lab5 binary: cargo build --release --example lab5, then --ignored"]
fn lab5_on_jittered_and_stalled_clocks_identifies_within_the_ideal_clocks_bounds() {
    let ideal = Ideal::run();
    assert_usual_bounds(&ideal.errors, "the ideal clock");
    let mut sums = vec![0.0; ideal.errors.len()];
    for seed in 1..=10 {
        let jitter = format!("{seed},{MILD}");
        let report = lab5(&jitter);
        check_sections(&report, &jitter, &ideal);
        let errors = identification_errors(&report);
        println!("--jitter {jitter}: {errors:.2?} %");
        // Measured at most 0.16, 0.21, 1.34 and 6.9 points (above).
        assert_near_ideal(&errors, &ideal, [0.3, 0.5, 2.0, 8.0], &jitter);
        for (sum, (_, e)) in sums.iter_mut().zip(&errors) {
            *sum += e / 10.0;
        }
    }
    let mean: Vec<(String, f64)> = ideal
        .errors
        .iter()
        .zip(sums)
        .map(|((name, _), m)| (name.clone(), m))
        .collect();
    println!("mean of ten: {mean:.2?} %");
    assert_usual_bounds(&mean, "the mean of ten jittered runs");
}

#[test]
#[ignore = "runs the lab5 binary: cargo build --release --example lab5, then --ignored"]
fn lab5_on_the_default_jitter_schedule_completes_every_section() {
    // `--jitter 11`: 10 % of ticks late by up to 6 ms, one in 200 stalled
    // for 8–16 ms; about 10 % of the ticks skipped. The bounds against the
    // ideal run are the default schedule's worst over seeds 1–10 (above:
    // k 0.39, K 0.67, b2 2.58, F 8.3 points), rounded up.
    let ideal = Ideal::run();
    let report = lab5("11");
    check_sections(&report, "11", &ideal);
    let errors = identification_errors(&report);
    println!("--jitter 11: {errors:.2?} %");
    assert_near_ideal(&errors, &ideal, [0.5, 1.0, 3.0, 10.0], "--jitter 11");
}
