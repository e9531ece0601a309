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
        ("The MPC predicted and run, against its limits", 13, 1),
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
    // The MPC on the rig (issue 31): cart 2 near its travel limit and
    // cart 1, predicted and run, never touch a travel limit, keep the
    // drive's rate limit (to half a 24 mV step), are never held at full
    // scale anywhere near the rig's 2 s, and solve their ticks (on a
    // jittered clock a stall can leave a tick's solve to its fallback:
    // counted, and rare).
    let mpc = table(&tables, "The MPC predicted and run, against its limits");
    assert_eq!(
        mpc[0].len(),
        5,
        "two cases, predicted and rig: {:?}",
        mpc[0]
    );
    assert!(mpc[0][1].starts_with("cart 2 to 45 mm") && mpc[0][3].starts_with("cart 1 to 15 mm"));
    let row = |name: &str| {
        mpc.iter()
            .find(|r| r[0] == name)
            .unwrap_or_else(|| panic!("no MPC row `{name}`"))
    };
    for (c, case) in mpc[0].iter().enumerate().skip(1) {
        let cell =
            |name: &str| number(&row(name)[c]).unwrap_or_else(|| panic!("`{name}` of {case}"));
        assert!(
            cell("closest approach to a travel limit (mm)") > 0.0,
            "{case}"
        );
        assert!(cell("largest change of drive per period (V)") <= 2.0 + 0.012 + 1e-9);
        assert!(cell("peak drive (V)") <= 24.0);
        assert!(cell("longest at full scale (s)") < 0.5, "{case}");
        let counts: Vec<f64> = row("ticks solved / fallbacks")[c]
            .split(" / ")
            .map(|v| v.parse().unwrap())
            .collect();
        assert!(counts[1] <= 0.01 * counts[0], "{case}: {counts:?}");
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
        "## Constrained MPC: predict, then run",
        "### Prediction and rig",
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
        "mpc.svg",
    ] {
        assert!(
            report.contains(&format!("]({figure})")),
            "{figure} not linked"
        );
        assert!(dir.join(figure).is_file(), "{figure} not written");
    }
    // Recordings are named for what ran: the identification's signal, peak
    // and seed; a table row as examples/experiment names it.
    let runs: Vec<String> = std::fs::read_dir(dir.join("runs"))
        .expect("runs/ is written")
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert!(
        runs.iter()
            .any(|n| n.starts_with("ident_square_") && n.ends_with("V_seed1.csv")),
        "{runs:?}"
    );
    for file in [
        "table5_cart2_kf_0_0_10_0.1_to_30mm.csv",
        "table6_cart1_kf_1_0.01_0_0_to_15mm.csv",
        "design_cart1_rig.csv",
    ] {
        assert!(runs.iter().any(|n| n == file), "no runs/{file} in {runs:?}");
    }
    the_tables_are_written_as_csv(&report, dir);
    the_lab_comes_before_the_further_sections(&report);
}

/// A CSV record's fields (quoted fields unquoted, `""` as `"`).
fn fields(line: &str) -> Vec<String> {
    let (mut out, mut field, mut quoted) = (Vec::new(), String::new(), false);
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match (c, quoted) {
            ('"', true) if chars.peek() == Some(&'"') => {
                field.push('"');
                chars.next();
            }
            ('"', _) => quoted = !quoted,
            (',', false) => out.push(std::mem::take(&mut field)),
            (c, _) => field.push(c),
        }
    }
    out.push(field);
    out
}

/// Every table is in `tables/` as CSV, linked under its Markdown table:
/// units in the header, a row per Markdown row (Tables 3 and 4 split the
/// `mean ± sd` row in two), the same numbers, and each rig run's
/// recording named.
fn the_tables_are_written_as_csv(report: &str, dir: &Path) {
    let tables = tables(report);
    for (heading, file, extra, columns) in [
        (
            "Table 1",
            "table1.csv",
            0,
            &["F_N", "x1_sim_mm", "x2_exact_mm"][..],
        ),
        (
            "Table 2",
            "table2.csv",
            0,
            &[
                "kf1_N_per_mm",
                "pole1_re_per_s",
                "POT_pct",
                "settling_time_s",
                "steady_state_error_mm",
            ],
        ),
        (
            "Table 3",
            "table3.csv",
            1,
            &[
                "k12_lab_N_per_m",
                "k1_separate_N_per_m",
                "coulomb1_separate_N",
            ],
        ),
        (
            "Table 4",
            "table4.csv",
            1,
            &[
                "K_lab_N_per_V",
                "b2_separate_N_s_per_m",
                "coulomb2_separate_N",
            ],
        ),
        (
            "The identified model and its uncertainty",
            "model.csv",
            0,
            &["parameter", "unit", "mean"],
        ),
        (
            "Table 5",
            "table5.csv",
            0,
            &[
                "kf1_V_per_mm",
                "outcome",
                "y_inf_mm",
                "POT_pct",
                "settling_time_s",
                "steady_state_error_mm",
                "recording",
            ],
        ),
        (
            "Table 6",
            "table6.csv",
            0,
            &[
                "kf4_V_s_per_mm",
                "outcome",
                "POT_pct",
                "steady_state_error_mm",
                "recording",
            ],
        ),
    ] {
        assert!(
            report.contains(&format!("(tables/{file})")),
            "{file} not linked"
        );
        let text = std::fs::read_to_string(dir.join("tables").join(file))
            .unwrap_or_else(|e| panic!("tables/{file}: {e}"));
        let mut lines = text.lines();
        let header = fields(lines.next().unwrap());
        for c in columns {
            assert!(
                header.iter().any(|h| h == c),
                "{file}: no {c} in {header:?}"
            );
        }
        let rows: Vec<Vec<String>> = lines.map(fields).collect();
        let markdown = table(&tables, heading);
        assert_eq!(
            rows.len(),
            markdown.len() - 1 + extra,
            "{file} against `{heading}`"
        );
        for row in &rows {
            assert_eq!(row.len(), header.len(), "{file}: {row:?}");
        }
        if !file.starts_with("table5") && !file.starts_with("table6") {
            continue;
        }
        // The rig tables: the Markdown's metrics, at its precision; none
        // where the run did not settle, the outcome saying why.
        let col = |name: &str| header.iter().position(|h| h == name).unwrap();
        let md_outcome = markdown[0].iter().position(|h| h == "outcome").unwrap();
        for (row, md) in rows.iter().zip(&markdown[1..]) {
            assert!(
                md[md_outcome].starts_with(row[col("outcome")].as_str())
                    || row[col("outcome")] == "oscillating",
                "{row:?} against {md:?}"
            );
            let pot = &row[col("POT_pct")];
            if md[md_outcome] == "settled" {
                let value: f64 = pot.parse().unwrap();
                assert_eq!(format!("{value:.2}"), md[md_outcome + 3], "{file}: {row:?}");
            } else {
                assert!(
                    pot.is_empty() && row[col("settling_time_s")].is_empty(),
                    "{row:?}"
                );
            }
            let recording = dir.join(&row[col("recording")]);
            assert!(recording.is_file(), "{}", recording.display());
        }
    }
}

/// Tables 1–6 and the answers come first, the further sections after
/// their own heading, whatever order the sections ran in.
fn the_lab_comes_before_the_further_sections(report: &str) {
    let at = |heading: &str| {
        report
            .find(&format!("\n{heading}"))
            .unwrap_or_else(|| panic!("no `{heading}`"))
    };
    let order = [
        "## Contents",
        "## Table 1",
        "## Table 2",
        "### Table 3",
        "### Table 4",
        "## Table 5",
        "## Table 6",
        "## Answers to the report's questions",
        "## Further sections",
        "## Excitation",
        "## Validation",
        "## Frequency response",
        "## Design",
    ];
    for pair in order.windows(2) {
        assert!(
            at(pair[0]) < at(pair[1]),
            "`{}` after `{}`",
            pair[0],
            pair[1]
        );
    }
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
