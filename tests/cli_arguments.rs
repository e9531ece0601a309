//! lab5's and probe's command lines refuse a bad `--out`, `--volts` or
//! `--metres-per-count` at once, naming the argument or path, before a run
//! or a pulse (issue 28: `lab5 --out /etc/hostname/x` said "Not a
//! directory (os error 20)" with no path; with `o/report.md` a directory
//! lab5 ran everything and lost the report; `probe --volts nan` pulsed the
//! motor, then blamed "TOML line 18" of a file the user never wrote).
//!
//! Proptests then throw every kind of bad value at lab5's, experiment's and
//! probe's numeric and named arguments.
//!
//! Ignored: `.ci/run` builds the binaries in release and runs these
//! (`LAB5=…`, `PROBE=…`, `EXPERIMENT=…` to point at others).

// Built on the two-cart lab.
#![cfg(feature = "lab")]

#[path = "common/example.rs"]
mod example;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use example::example_binary;
use proptest::prelude::*;

fn lab5(args: &[&str]) -> Output {
    let bin = example_binary("lab5", "LAB5", "cargo build --release --example lab5");
    Command::new(bin).args(args).output().unwrap()
}

fn experiment(args: &[&str]) -> Output {
    let bin = example_binary(
        "experiment",
        "EXPERIMENT",
        "cargo build --release --example experiment",
    );
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

/// A value that no numeric argument accepts or a random one; extremes
/// weighted (NaN, ±inf, ±0, subnormal, ±1e308) as the reproducers.
fn number() -> impl Strategy<Value = f64> {
    prop_oneof![
        prop::sample::select(vec![
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            0.0,
            -0.0,
            5e-324,
            -5e-324,
            1e-310,
            1e308,
            -1e308,
            f64::MAX,
        ]),
        any::<f64>(),
        -1e4..1e4f64,
    ]
}

/// `x` as a user might type it: Rust's `{}` (every digit) or `{:e}`.
fn typed(x: f64) -> impl Strategy<Value = String> {
    prop_oneof![Just(format!("{x}")), Just(format!("{x:e}"))]
}

/// Text that is not a number (nor a signal's name, nor a seed).
fn garbage() -> impl Strategy<Value = String> {
    prop_oneof![
        Just(String::new()),
        Just("1e".to_owned()),
        Just("0x10".to_owned()),
        Just("1,,2".to_owned()),
        Just("½".to_owned()),
        Just(" 3".to_owned()),
        "[a-zA-Z%#/;é]{1,6}[0-9]{0,2}",
    ]
    .prop_filter("not a number", |s| s.trim().parse::<f64>().is_err())
}

/// A SCHED_FIFO priority outside 1–99, or not an integer.
fn bad_priority() -> impl Strategy<Value = String> {
    prop_oneof![
        any::<i64>()
            .prop_filter("in 1–99", |p| !(1..=99).contains(p))
            .prop_map(|p| p.to_string()),
        number()
            .prop_flat_map(typed)
            .prop_filter("an integer", |s| s.parse::<i64>().is_err()),
        garbage(),
    ]
}

/// One argument of experiment's that its parser refuses (the checks
/// against the rig, such as the setpoint within the travel, come later and
/// are tests/experiment.rs's): (flag, value).
fn bad_experiment_argument() -> impl Strategy<Value = (&'static str, String)> {
    let non_finite = prop::sample::select(vec![f64::NAN, f64::INFINITY, f64::NEG_INFINITY]);
    prop_oneof![
        bad_priority().prop_map(|v| ("--rt-priority", v)),
        prop_oneof![
            any::<i128>()
                .prop_filter("a u64", |s| u64::try_from(*s).is_err())
                .prop_map(|s| s.to_string()),
            garbage(),
        ]
        .prop_map(|v| ("--seed", v)),
        garbage()
            .prop_filter("a cart", |c| !matches!(c.trim(), "1" | "2"))
            .prop_map(|v| ("--cart", v)),
        prop_oneof![
            (number(), number(), number(), non_finite.clone())
                .prop_map(|(a, b, c, d)| format!("{a},{b},{d},{c}")),
            prop::collection::vec(-100.0..100.0f64, 0..8)
                .prop_filter("four", |v| v.len() != 4)
                .prop_map(|v| v.iter().map(f64::to_string).collect::<Vec<_>>().join(",")),
            garbage(),
        ]
        .prop_map(|v| ("--kf", v)),
        prop_oneof![
            number()
                .prop_filter("a valid duration", |&x| !(x.is_finite() && x > 0.0))
                .prop_flat_map(typed),
            garbage().prop_filter("3s", |s| s
                .trim()
                .trim_end_matches('s')
                .trim()
                .parse::<f64>()
                .is_err()),
        ]
        .prop_map(|v| ("--duration", v)),
        prop_oneof![
            non_finite.prop_map(|x| format!("{x}mm")),
            number().prop_flat_map(typed),
        ]
        .prop_map(|v| ("--setpoint", v)),
    ]
}

/// Refused by clap (exit 2) before anything ran, naming `flag`, without a
/// panic, and `out` not made.
fn refused_at_once(
    output: &Output,
    args: &[String],
    flag: &str,
    out: &Path,
) -> Result<(), TestCaseError> {
    let stderr = String::from_utf8_lossy(&output.stderr);
    prop_assert_eq!(output.status.code(), Some(2), "{:?}: {}", args, stderr);
    prop_assert!(
        stderr.contains(flag),
        "{:?}: `{}` not named: {}",
        args,
        flag,
        stderr
    );
    prop_assert!(!stderr.contains("panicked"), "{:?}: {}", args, stderr);
    prop_assert!(output.stdout.is_empty(), "{:?} ran", args);
    prop_assert!(!out.exists(), "{:?} made {}", args, out.display());
    Ok(())
}

/// One argument of lab5's that its own check (the library's validation,
/// not the binary's parser) refuses: (flag, value, extra arguments it needs).
fn bad_lab5_argument() -> impl Strategy<Value = (&'static str, String, Vec<String>)> {
    use ctrlab::hw::Jitter;
    use ctrlab::lab::ident_input::{IdentInput, IdentSignal};
    let logs = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/logs/lab5").to_owned();
    let volts = prop_oneof![
        number()
            .prop_filter("a valid voltage", |&volts| {
                IdentInput {
                    volts,
                    ..IdentInput::default()
                }
                .validate()
                .is_err()
            })
            .prop_flat_map(typed),
        garbage(),
    ]
    .prop_map(|v| ("--ident-volts", v, vec![]));
    let half_period = prop_oneof![
        number()
            .prop_filter("a valid half period", |&half_period| {
                IdentInput {
                    half_period,
                    ..IdentInput::default()
                }
                .validate()
                .is_err()
            })
            .prop_flat_map(typed),
        garbage(),
    ]
    .prop_map(|v| ("--ident-half-period", v, vec![]));
    let jitter = prop_oneof![
        (any::<u64>(), number(), number(), number(), number())
            .prop_filter("a valid schedule", |&(seed, a, b, c, d)| {
                let j = Jitter {
                    seed,
                    late_fraction: a,
                    max_late: b,
                    stall_fraction: c,
                    stall: d,
                };
                j.validate().is_err()
            })
            .prop_map(|(seed, a, b, c, d)| format!("{seed},{a},{b},{c},{d}")),
        garbage(),
        prop::sample::select(vec!["-1", "1.5", "1,2", "1,0.1,0.1,0.1"]).prop_map(str::to_owned),
    ]
    .prop_map(|v| ("--jitter", v, vec![]));
    let priority = bad_priority().prop_map(|v| ("--rt-priority", v, vec![]));
    let metres = prop_oneof![
        number()
            .prop_filter("a valid length", |&m| !(m.is_finite() && m > 0.0))
            .prop_flat_map(typed),
        garbage(),
    ]
    .prop_map(move |v| {
        (
            "--metres-per-count",
            v,
            vec!["--logs".to_owned(), logs.clone()],
        )
    });
    let signal = garbage()
        .prop_filter("a signal's name", |s| s.parse::<IdentSignal>().is_err())
        .prop_map(|v| ("--ident-signal", v, vec![]));
    prop_oneof![volts, half_period, jitter, priority, metres, signal]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 96, failure_persistence: None, ..ProptestConfig::default() })]

    /// Any argument its check refuses stops lab5 at once (clap's usage
    /// error, 2), naming the argument, with no panic, nothing run and no
    /// output directory made; with the value after `=` or as the next word,
    /// before or after the other arguments.
    #[test]
    #[ignore = "runs the lab5 binary; .ci/run builds it first"]
    fn lab5_refuses_every_bad_argument_before_running(
        (flag, value, extra) in bad_lab5_argument(),
        joined in any::<bool>(),
        first in any::<bool>(),
        tables_only in any::<bool>(),
    ) {
        let dir = scratch("lab5_prop");
        let out = dir.join("out");
        let mut args: Vec<String> = Vec::new();
        let mut bad = if joined {
            vec![format!("{flag}={value}")]
        } else {
            vec![flag.to_owned(), value.clone()]
        };
        bad.extend(extra);
        let mut rest = vec!["--out".to_owned(), out.to_str().unwrap().to_owned()];
        if tables_only {
            rest.push("--tables-only".to_owned());
        }
        if first {
            args.extend(bad);
            args.extend(rest);
        } else {
            args.extend(rest);
            args.extend(bad);
        }
        let refs: Vec<&str> = args.iter().map(String::as_str).collect();
        refused_at_once(&lab5(&refs), &args, flag, &out)?;
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// The same for the single experiment's arguments: the bad one in
    /// place of a good one, the value after `=` or as the next word.
    #[test]
    #[ignore = "runs the experiment binary; .ci/run builds it first"]
    fn experiment_refuses_every_bad_argument_before_running(
        (flag, value) in bad_experiment_argument(),
        joined in any::<bool>(),
    ) {
        let dir = scratch("experiment_prop");
        let out = dir.join("out");
        let good = [("--cart", "2"), ("--kf", "0,0,10,0.1"), ("--duration", "3"), ("--seed", "7")];
        let mut args: Vec<String> = vec!["--out".to_owned(), out.to_str().unwrap().to_owned()];
        for (name, v) in good.iter().filter(|(name, _)| *name != flag) {
            args.extend([(*name).to_owned(), (*v).to_owned()]);
        }
        if joined {
            args.push(format!("{flag}={value}"));
        } else {
            args.extend([flag.to_owned(), value.clone()]);
        }
        let refs: Vec<&str> = args.iter().map(String::as_str).collect();
        refused_at_once(&experiment(&refs), &args, flag, &out)?;
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// The probe refuses a bad `--volts` or `--metres-per-count` before it
    /// pulses anything, naming the argument and the value, writing no card
    /// file.
    #[test]
    #[ignore = "runs the probe binary; .ci/run builds it first"]
    fn probe_refuses_every_bad_number_before_probing(
        volts in any::<bool>(),
        value in prop_oneof![
            number().prop_filter("valid", |&x| !(x.is_finite() && x > 0.0)).prop_flat_map(typed),
            garbage().prop_filter("a flag", |s| !s.is_empty()),
        ],
    ) {
        let dir = scratch("probe_prop");
        let out = dir.join("card.toml");
        let flag = if volts { "--volts" } else { "--metres-per-count" };
        let args = ["--simulated", flag, value.as_str(), "--out", out.to_str().unwrap()];
        let output = probe(&args);
        let stderr = String::from_utf8_lossy(&output.stderr);
        prop_assert!(!output.status.success(), "{:?} accepted", args);
        prop_assert!(stderr.contains(&format!("{flag} {value}")), "{:?}: {}", args, stderr);
        prop_assert!(!stderr.contains("panicked"), "{:?}: {}", args, stderr);
        prop_assert!(output.stdout.is_empty(), "{:?} ran", args);
        prop_assert!(!out.exists(), "{:?} wrote the card file", args);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
