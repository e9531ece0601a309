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

use std::path::PathBuf;
use std::process::Command;

/// The lab5 binary: `$LAB5`, else `examples/lab5` of this test's profile
/// (`target/release/deps/lab5_jitter-…` → `target/release/examples/lab5`).
fn lab5_binary() -> PathBuf {
    if let Some(path) = std::env::var_os("LAB5") {
        return path.into();
    }
    let exe = std::env::current_exe().expect("the test's own path");
    let profile = exe.ancestors().nth(2).expect("target/<profile>/deps/…");
    let bin = profile
        .join("examples")
        .join(format!("lab5{}", std::env::consts::EXE_SUFFIX));
    assert!(
        bin.is_file(),
        "{} is missing: cargo build --release --example lab5 (or set LAB5)",
        bin.display()
    );
    bin
}

/// Runs lab5 with `--jitter jitter`; its report.
fn lab5(jitter: &str) -> String {
    let out = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join("lab5-jitter")
        .join(jitter.replace(',', "_"));
    let run = Command::new(lab5_binary())
        .args(["--jitter", jitter, "--out"])
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

/// Everything lab5 reports on a jittered run but the identification's
/// bounds: each section ran, counted its late and skipped ticks, and the
/// frequency section found both modes.
fn check_sections(report: &str, jitter: &str) {
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
    // Validation and refinement: the refined model simulates both carts
    // within 1 % (fit ≥ 99 %; 99.95 % on the ideal clock, 99.93 % on
    // `--jitter 11`), and the bootstrap gives k1 with its standard error.
    let validation = rows(report, "Validation");
    let refined = validation
        .iter()
        .find(|r| r[0] == "refined by output error")
        .expect("the refined row");
    assert!(
        number(&refined[8]) >= 99.0 && number(&refined[9]) >= 99.0,
        "{refined:?}"
    );
    let bootstrap = rows(report, "The refined parameters over every run");
    let first = bootstrap
        .iter()
        .find(|r| r[0].contains("bootstrap"))
        .expect("the bootstrap row");
    assert!((number(&first[1]) / 950.0 - 1.0).abs() < 0.005, "{first:?}");
    // The frequency section: each measured gain peak within 0.5 Hz of the
    // identified model's with friction, simulated (2.68 and 8.45 Hz; the
    // ideal clock measures exactly those; the ten schedules of the scan
    // below were off by at most 0.44 Hz, the second mode at 8.01 Hz).
    for mode in rows(report, "Frequency response").iter().skip(1) {
        let (simulated, measured) = (number(&mode[2]), number(&mode[3]));
        assert!(
            (measured - simulated).abs() < 0.5,
            "--jitter {jitter}: {mode:?}"
        );
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

/// The schedule of tests/late_ticks.rs's identification test: 3 % of ticks
/// late by up to 6 ms (three periods), one in 500 stalled for 8–16 ms.
const MILD: &str = "0.03,0.006,0.002,0.016";

#[test]
#[ignore = "runs the lab5 binary: cargo build --release --example lab5, then --ignored"]
fn lab5_on_jittered_and_stalled_clocks_identifies_within_the_ideal_clocks_bounds() {
    // The bounds of tests/lab_identification.rs (lab5's identification on
    // the ideal clock, the same rig): k1, k2, K and b2 within 0.5 % of the
    // truth, F1 and F2 within 5 %. Here on each of ten jittered schedules
    // the mean over lab5's five runs is within 1 % (5 % for F1, F2), and
    // the mean over the ten within the ideal bounds.
    //
    // Measured (% error of the five-run mean; `cargo build --release
    // --example lab5`, then `lab5 --jitter SEED,0.03,0.006,0.002,0.016`,
    // seeds 1–10, and `lab5` for the ideal clock):
    //
    //             k1     k2     b1     b2     K      F1     F2
    //   ideal   +0.04  -0.02  -0.41  -0.18  +0.19  +1.6   +1.35
    //   mean    +0.05  +0.04  -0.02  -0.14  +0.29  +0.22  +1.54
    //   worst   +0.12  +0.24  +0.92  -0.89  +0.57  -3.6   +2.5
    //
    // So a single jittered lab5 is not always within the ideal 0.5 % (b2
    // -0.89 % on seed 1, K +0.57 % on seed 5): as tests/late_ticks.rs
    // found, the identification splits each recording at every late
    // sample and stall and fits fewer rows, so its spread grows, not its
    // bias. The default `--jitter SEED` schedule (10 % late, one in 200
    // stalled), seeds 1–10: mean k1 +0.04, k2 +0.12, b1 +0.67, b2 -0.17,
    // K +0.39, F1 -1.32, F2 +1.85 %; worst b1 +2.95, b2 +1.78, K +1.20,
    // F1 -7.6 %.
    let mut sums = [0.0; 7];
    for seed in 1..=10 {
        let jitter = format!("{seed},{MILD}");
        let report = lab5(&jitter);
        check_sections(&report, &jitter);
        let errors = identification_errors(&report);
        println!("--jitter {jitter}: {errors:.2?} %");
        assert_eq!(errors.len(), 7, "{errors:?}");
        for (i, (name, e)) in errors.iter().enumerate() {
            let bound = if name.starts_with('F') { 5.0 } else { 1.0 };
            if name != "b1" {
                assert!(e.abs() < bound, "--jitter {jitter}: {name} {e:+.2} %");
            }
            sums[i] += e / 10.0;
        }
    }
    println!("mean of ten: {sums:.2?} %");
    let names = ["k1", "k2", "b1", "b2", "K", "F1", "F2"];
    for (name, mean) in names.iter().zip(sums) {
        let bound = match *name {
            "F1" | "F2" => 5.0,
            "b1" => 1.0, // not bounded on the ideal clock either (-0.41 %)
            _ => 0.5,
        };
        assert!(mean.abs() < bound, "mean {name} {mean:+.2} %");
    }
}

#[test]
#[ignore = "runs the lab5 binary: cargo build --release --example lab5, then --ignored"]
fn lab5_on_the_default_jitter_schedule_completes_every_section() {
    // `--jitter 11`: 10 % of ticks late by up to 6 ms, one in 200 stalled
    // for 8–16 ms; about 10 % of the ticks skipped (1259 over the five
    // identification runs, 2471 over Table 6's). Measured: k1 +0.21, k2
    // +0.32, b2 +0.02, K +0.57, F1 -1.0, F2 +2.0 %; modes 2.71 and
    // 8.36 Hz (before the frequency section resampled gaps, 2.33 and
    // 3.02 Hz). The bounds are the default schedule's worst over seeds
    // 1–10 (above), rounded up: 2 % (k1, k2, K, b2), 10 % (F1, F2).
    let report = lab5("11");
    check_sections(&report, "11");
    for (name, e) in identification_errors(&report) {
        let bound = match name.as_str() {
            "F1" | "F2" => 10.0,
            "b1" => 5.0,
            _ => 2.0,
        };
        assert!(e.abs() < bound, "{name} {e:+.2} %");
    }
}
