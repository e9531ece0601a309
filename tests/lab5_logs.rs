//! The student logs behind `lab5 --logs` (`tests/data/logs/lab5/`): three
//! identification runs of the default simulated rig, written as a student's
//! spreadsheet saves them (`;` separators, decimal commas, a comment line,
//! positions in raw encoder counts, `\r\n`). They load and identify near the
//! rig's truth here; `.ci/run` runs lab5 on them and checks its offline
//! report with `LAB5_LOGS_REPORT`.

// Built on the two-cart lab (its plant, simulated rig or card).
#![cfg(feature = "lab")]

mod common;

use std::fmt::Write as _;
use std::path::PathBuf;

use common::open_loop;
use ctrlab::Recording;
use ctrlab::data::CsvOptions;
use ctrlab::lab::ident::{Options, SpringModel, identify_with};
use ctrlab::lab::{CardSettings, SimulatedRig};
use ctrlab::signal::SquareWave;

/// The default rig's encoders: 8192 counts per 80 mm.
const METRES_PER_COUNT: f64 = 0.08 / 8192.0;
const SEEDS: [u64; 3] = [21, 22, 23];

fn dir() -> PathBuf {
    PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/logs/lab5"))
}

/// One run in the student's format.
fn student_log(rec: &Recording, seed: u64) -> String {
    let comma = |v: f64, digits: usize| format!("{v:.digits$}").replace('.', ",");
    let mut s = format!("# two-cart rig, square wave +-8 V, 0,2 s; run {seed}\r\n");
    s += "time [s];u_V;x1 [counts];x2 [counts]\r\n";
    let (u, x1, x2) = (
        rec.channel("u").unwrap(),
        rec.channel("x1").unwrap(),
        rec.channel("x2").unwrap(),
    );
    for (k, t) in rec.time().iter().enumerate() {
        let count = |x: f64| (x / METRES_PER_COUNT).round();
        write!(
            s,
            "{};{};{};{}\r\n",
            comma(*t, 4),
            comma(u[k], 3),
            count(x1[k]),
            count(x2[k])
        )
        .unwrap();
    }
    s
}

/// Regenerates the logs: `cargo test --test lab5_logs -- --ignored write`.
#[test]
#[ignore = "writes tests/data/logs/lab5; run by hand to regenerate"]
fn write_the_student_logs() {
    std::fs::create_dir_all(dir()).unwrap();
    for seed in SEEDS {
        let sim = SimulatedRig {
            card: CardSettings {
                seed,
                ..CardSettings::default()
            },
            ..SimulatedRig::default()
        };
        let rec = open_loop(&sim, &SquareWave::new(8.0, 0.2).unwrap(), 5.0);
        let path = dir().join(format!("group7_run{}.csv", seed - 20));
        std::fs::write(path, student_log(&rec, seed)).unwrap();
    }
}

#[test]
fn the_student_logs_load_and_identify_near_the_truth() {
    let options = CsvOptions {
        metres_per_count: Some(METRES_PER_COUNT),
    };
    let truth = SimulatedRig::default_truth();
    let mut read = 0;
    for n in 1..=SEEDS.len() {
        let rec =
            Recording::read_csv_with(dir().join(format!("group7_run{n}.csv")), &options).unwrap();
        assert_eq!(rec.len(), 2500); // 5 s at 2 ms
        let est = identify_with(
            &rec,
            1.3,
            0.7,
            &Options {
                springs: SpringModel::Separate,
                coulomb: true,
                ..Options::DEFAULT
            },
        )
        .unwrap();
        let err = |got: f64, want: f64| (got / want - 1.0).abs();
        assert!(err(est.k1().value, truth.k1) < 0.01, "{:?}", est.k1());
        assert!(err(est.k2().value, truth.k2) < 0.01, "{:?}", est.k2());
        assert!(err(est.gain.value, truth.gain) < 0.01, "{:?}", est.gain);
        read += 1;
    }
    assert_eq!(read, 3);
}

/// The report `lab5 --logs tests/data/logs/lab5` wrote.
fn offline_report() -> String {
    let path = std::env::var("LAB5_LOGS_REPORT").expect("LAB5_LOGS_REPORT names the report");
    std::fs::read_to_string(path).expect("the report is readable")
}

/// The table rows under `heading`, up to the next heading of any level.
fn rows<'a>(report: &'a str, heading: &str) -> Vec<Vec<&'a str>> {
    report
        .split(heading)
        .nth(1)
        .unwrap_or_else(|| panic!("the report has no `{heading}`"))
        .split("\n#")
        .next()
        .unwrap_or_default()
        .lines()
        .filter(|l| l.starts_with("| ") && !l.starts_with("|---"))
        .skip(1)
        .map(|l| l.trim_matches('|').split(" | ").map(str::trim).collect())
        .collect()
}

#[test]
#[ignore = "run by .ci/run after `lab5 --logs`, with LAB5_LOGS_REPORT set"]
fn the_offline_report_identifies_and_validates_from_the_logs() {
    let report = offline_report();
    assert!(!report.contains("The lab stopped early"), "{report}");
    assert!(!report.contains("Table 5") && !report.contains("simulated card"));
    // Tables 3 and 4: three runs, then the mean.
    let table4 = rows(&report, "### Table 4");
    assert_eq!(table4.len(), 4, "{table4:?}");
    let number = |c: &str| c.split(' ').next().and_then(|v| v.parse::<f64>().ok());
    // K separate (N/V), within 1 % of the default rig's 1.11 N/V.
    let k = number(table4[3][5]).unwrap();
    assert!((k / 1.11 - 1.0).abs() < 0.01, "{k}");
    // Every parameter with its standard error beside the spread.
    let uncertainty = rows(&report, "### The identified model and its uncertainty");
    assert_eq!(uncertainty.len(), 7, "{uncertainty:?}");
    for row in &uncertainty {
        assert_eq!(row.len(), 6, "{row:?}");
        assert!(row[1..].iter().all(|c| number(c).is_some()), "{row:?}");
    }
    // Validated on the second log: lab, least squares, refined.
    let validation = rows(&report, "## Validation");
    assert_eq!(validation.len(), 3, "{validation:?}");
    assert!(number(validation[2][9]).unwrap() > 95.0, "{validation:?}");
    // Every log refined: mean ± spread of the seven parameters, and the
    // first log ± its bootstrap standard errors.
    let spread = rows(&report, "### The refined parameters over every run");
    assert_eq!(spread.len(), 2, "{spread:?}");
    for row in &spread {
        assert_eq!(row.len(), 8, "{spread:?}");
        assert!(
            row[1..]
                .iter()
                .all(|c| c.contains(" ± ") && number(c).is_some()),
            "{spread:?}"
        );
    }
}
