//! Checks the report written by `cargo run --release --example lab5 -- --out DIR`,
//! end to end.
//!
//! `.ci/run` runs the example, then this test with `--ignored` and
//! `LAB5_REPORT=DIR/report.md`. The numbers themselves are checked on the
//! library's typed results (`tests/lab_tables.rs`,
//! `tests/lab_identification.rs`, `tests/lab5_design.rs`); this checks that
//! the program rendered all of them: every section with its table, a number
//! (or an explained outcome) in every result cell, every figure linked and
//! written.

use std::collections::HashMap;
use std::path::Path;

/// Markdown table rows (cells trimmed) under each `##`/`###` heading.
fn tables(report: &str) -> HashMap<String, Vec<Vec<String>>> {
    let mut out: HashMap<String, Vec<Vec<String>>> = HashMap::new();
    let mut current = String::new();
    for line in report.lines() {
        if line.starts_with('#') {
            current = line.trim_start_matches('#').trim().to_string();
        } else if line.starts_with('|') && !line.starts_with("|---") {
            let cells = line
                .trim_matches('|')
                .split(" | ")
                .map(|c| c.trim().to_string())
                .collect();
            out.entry(current.clone()).or_default().push(cells);
        }
    }
    out
}

/// The rows of the table under the heading that starts with `heading`.
fn table<'a>(tables: &'a HashMap<String, Vec<Vec<String>>>, heading: &str) -> &'a [Vec<String>] {
    tables
        .iter()
        .find(|(h, _)| h.starts_with(heading))
        .map(|(_, rows)| rows.as_slice())
        .unwrap_or_else(|| panic!("no table under `{heading}`"))
}

/// A cell's leading number (`12.3`, `**12.3 ✗**`, `950.0 ± 0.1`, `1.1 (+0.2 %)`).
fn number(cell: &str) -> Option<f64> {
    cell.trim_matches('*')
        .split_whitespace()
        .next()?
        .parse()
        .ok()
}

#[test]
#[ignore = "run by .ci/run after the lab5 example, with LAB5_REPORT set"]
fn the_lab5_report_renders_every_section_with_numbers_and_figures() {
    let path = std::env::var("LAB5_REPORT").expect("LAB5_REPORT names the report to check");
    let report = std::fs::read_to_string(&path).expect("the report is readable");
    assert!(!report.contains("The lab stopped early"), "{report}");
    assert!(
        !report.contains("NaN") && !report.contains("Some("),
        "Debug or NaN text"
    );
    let tables = tables(&report);

    // Every table of the lab and every section's table, with a header and
    // rows of numbers in their result columns (from the first numeric
    // column on; `–`, an outcome or a verdict where there is no number).
    let sections = [
        ("Table 1", 5, 0),
        ("Table 2", 6, 1),
        ("Table 3", 7, 1),
        ("Table 4", 7, 1),
        ("The identified model and its uncertainty", 7, 1),
        ("What the identification does not recover", 7, 1),
        ("Excitation", 4, 1),
        ("Validation", 4, 1),
        ("The refined parameters over every run", 3, 1),
        ("Frequency response", 2, 1),
        ("Table 5", 9, 1),
        ("Table 6", 15, 1),
        ("Predicted against measured", 6, 2),
    ];
    for (heading, rows, first) in sections {
        let t = table(&tables, heading);
        assert_eq!(t.len(), rows + 1, "`{heading}`: {t:?}");
        for row in &t[1..] {
            assert_eq!(row.len(), t[0].len(), "`{heading}`: {row:?}");
            let numeric = row[first..].iter().filter(|c| number(c).is_some()).count();
            assert!(numeric > 0, "`{heading}`: no number in {row:?}");
        }
    }
    // Tables 5 and 6: a settled row has its metrics; any other says why.
    for heading in ["Table 5", "Table 6"] {
        let t = table(&tables, heading);
        let outcome = t[0].iter().position(|h| h == "outcome").unwrap();
        for row in &t[1..] {
            if row[outcome] == "settled" {
                assert!(
                    row[outcome + 1..].iter().all(|c| number(c).is_some()),
                    "{row:?}"
                );
            } else {
                let known = [
                    "too slow",
                    "bounded oscillation",
                    "sustained oscillation",
                    "diverged",
                ];
                assert!(known.iter().any(|k| row[outcome].starts_with(k)), "{row:?}");
                assert!(row[outcome + 1..].iter().all(|c| c == "–"), "{row:?}");
            }
        }
    }
    for text in [
        "## Design: predict, then run",
        "### Where prediction and rig differ",
        "### 1. The state equations with the identified parameters",
        "### 2. The effect of each entry of Kf",
        "One more run on a card whose springs are equal",
        "Not recovered: **the rotor's mass**",
    ] {
        assert!(report.contains(text), "the report has no `{text}`");
    }

    // Every figure is linked, and written beside the report.
    let dir = Path::new(&path).parent().unwrap();
    for figure in [
        "table1.svg",
        "table2.svg",
        "table3.svg",
        "table4.svg",
        "identification.svg",
        "bode.svg",
        "table5.svg",
        "table6.svg",
        "design.svg",
    ] {
        assert!(
            report.contains(&format!("]({figure})")),
            "{figure} not linked"
        );
        assert!(dir.join(figure).is_file(), "{figure} not written");
    }
    assert!(
        dir.join("runs/ident_1.csv").is_file() && dir.join("runs/design_cart1_rig.csv").is_file()
    );
}

/// The lighter-damped rig of `tests/data/lighter_rig.toml`, where the lab's
/// old fixed ±8 V square wave drove cart 2 past its ±50 mm travel: lab5
/// completes, and its chosen amplitude keeps every identification run
/// inside 60 % of the travel, with the prediction's measured error as
/// slack. Measured with the default unmodelled effects on: 4.78 V chosen
/// for a predicted 24.1 / 30.0 mm; the runs peaked at 23.8–24.3 /
/// 30.2–31.0 mm (up to +3.2 % over the prediction: each run draws its own
/// friction, σ = 5 %, the probes theirs). Bound: 60 % of 50 mm plus 5 %.
/// (With `--ident-fixed`'s 8 V the runs halt and lab5 exits 1.)
#[test]
#[ignore = "run by .ci/run after lab5 --truth tests/data/lighter_rig.toml, with LAB5_LIGHTER_REPORT set"]
fn on_the_lighter_damped_rig_the_lab_completes_with_its_identification_inside_the_travel() {
    let path = std::env::var("LAB5_LIGHTER_REPORT").expect("LAB5_LIGHTER_REPORT names the report");
    let report = std::fs::read_to_string(&path).expect("the report is readable");
    assert!(!report.contains("The lab stopped early"), "{report}");
    let tables = tables(&report);
    let input = table(&tables, "Identification input");
    let runs: Vec<_> = input[1..]
        .iter()
        .filter(|r| r[0].starts_with("`ident_"))
        .collect();
    assert_eq!(runs.len(), 5, "{input:?}");
    for row in runs {
        assert_eq!(row[4], "completed", "{row:?}");
        let volts = number(&row[1]).unwrap();
        assert!(volts > 2.0 && volts < 8.0, "scaled down from 8 V: {row:?}");
        for peak in [number(&row[2]).unwrap(), number(&row[3]).unwrap()] {
            assert!(peak > 5.0 && peak <= 0.6 * 50.0 * 1.05, "{row:?}");
        }
    }
    // The rest of the lab ran on it too.
    for heading in ["Table 5", "Table 6", "Predicted against measured"] {
        assert!(table(&tables, heading).len() > 1, "`{heading}`");
    }
}
