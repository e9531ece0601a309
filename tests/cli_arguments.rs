//! lab5's and probe's command lines refuse a bad `--out`, `--volts` or
//! `--metres-per-count` at once, naming the argument or path, before a run
//! or a pulse (issue 28: `lab5 --out /etc/hostname/x` said "Not a
//! directory (os error 20)" with no path; with `o/report.md` a directory
//! lab5 ran everything and lost the report; `probe --volts nan` pulsed the
//! motor, then blamed "TOML line 18" of a file the user never wrote).
//!
//! Ignored: `.ci/run` builds the binaries in release and runs these
//! (`LAB5=…`, `PROBE=…` to point at others).

// Built on the two-cart lab.
#![cfg(feature = "lab")]

#[path = "common/example.rs"]
mod example;

use std::path::PathBuf;
use std::process::{Command, Output};

use example::example_binary;

fn lab5(args: &[&str]) -> Output {
    let bin = example_binary("lab5", "LAB5", "cargo build --release --example lab5");
    Command::new(bin).args(args).output().unwrap()
}

fn probe(args: &[&str]) -> Output {
    let bin = example_binary("probe", "PROBE", "cargo build --release --example probe");
    Command::new(bin).args(args).output().unwrap()
}

/// A fresh scratch directory under the target directory.
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("ctrlab_cli_{name}_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Failed, at once (no run started: nothing on stdout), naming `needle`.
fn refused(out: &Output, needle: &str) {
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "accepted: {stderr}");
    assert!(stderr.contains(needle), "`{needle}` not named: {stderr}");
    assert!(
        out.stdout.is_empty(),
        "ran before refusing: {}",
        String::from_utf8_lossy(&out.stdout)
    );
}

#[test]
#[ignore = "runs the lab5 binary; .ci/run builds it first"]
fn a_bad_out_directory_stops_lab5_at_once_naming_the_path() {
    let dir = scratch("lab5_out");
    refused(&lab5(&["--out", "/etc/hostname/x"]), "/etc/hostname/x");
    let report_dir = dir.join("a");
    std::fs::create_dir_all(report_dir.join("report.md")).unwrap();
    refused(&lab5(&["--out", report_dir.to_str().unwrap()]), "report.md");
    let logs = PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/logs/lab5"));
    let offline = [
        "--logs",
        logs.to_str().unwrap(),
        "--metres-per-count",
        "9.765625e-6",
        "--out",
        report_dir.to_str().unwrap(),
    ];
    refused(&lab5(&offline), "report.md");
    let runs_file = dir.join("b");
    std::fs::create_dir_all(&runs_file).unwrap();
    std::fs::write(runs_file.join("runs"), "").unwrap();
    refused(&lab5(&["--out", runs_file.to_str().unwrap()]), "runs");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
#[ignore = "runs the probe binary; .ci/run builds it first"]
fn probe_refuses_bad_arguments_before_probing() {
    let dir = scratch("probe");
    let out = dir.join("card.toml");
    let out = out.to_str().unwrap();
    refused(
        &probe(&["--simulated", "--volts", "nan", "--out", out]),
        "--volts nan",
    );
    refused(
        &probe(&["--simulated", "--metres-per-count", "-1e300", "--out", out]),
        "--metres-per-count -1e300",
    );
    refused(
        &probe(&["--simulated", "--out", dir.to_str().unwrap()]),
        "is a directory",
    );
    assert!(!PathBuf::from(out).exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A truth file's faults are named by file, line and key before anything
/// runs (issue 28: `TOML line 1` without the file; `m1 = nan` without file,
/// line or table; `max_substep = 1e-9` ran for hours; `period = -1.0` was
/// ignored), and `--metres-per-count nan` is refused as an argument.
#[test]
#[ignore = "runs the lab5 binary; .ci/run builds it first"]
fn a_bad_truth_file_or_calibration_stops_lab5_at_once_naming_it() {
    let dir = scratch("lab5_truth");
    let out = dir.join("out");
    let out = out.to_str().unwrap();
    let cases = [
        (
            "syntax.toml",
            "garbage = =\n",
            vec!["syntax.toml", "line 1"],
        ),
        (
            "mass.toml",
            "[truth]\nm1 = nan\n",
            vec!["mass.toml", "line 2", "truth.m1"],
        ),
        (
            "substep.toml",
            "[card]\nmax_substep = 1e-9\n",
            vec!["substep.toml", "line 2", "card.max_substep", "1e-9"],
        ),
        (
            "period.toml",
            "period = -1.0\n",
            vec!["period.toml", "line 1", "`period`"],
        ),
    ];
    for (name, text, needles) in cases {
        let path = dir.join(name);
        std::fs::write(&path, text).unwrap();
        let output = lab5(&["--truth", path.to_str().unwrap(), "--out", out]);
        for needle in needles {
            refused(&output, needle);
        }
    }
    let logs = PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/logs/lab5"));
    let output = lab5(&[
        "--logs",
        logs.to_str().unwrap(),
        "--metres-per-count",
        "nan",
        "--out",
        out,
    ]);
    refused(&output, "--metres-per-count");
    assert!(!PathBuf::from(out).exists(), "lab5 wrote before refusing");
    std::fs::remove_dir_all(&dir).unwrap();
}
