//! Checks the answers of a lab5 report against its own tables: every
//! trend the answers claim holds over every row of Table 5 or 6 it quotes,
//! every entry of Kf is concluded, the stability verdicts agree with the
//! ρ printed beside them, and the steady-state error section's "within the
//! band" agrees with its numbers.
//!
//! `.ci/run` runs lab5, then this test with `--ignored` and
//! `LAB5_REPORT=DIR/report.md`. The check is written apart from lab5's
//! renderer: it reads only the Markdown, and a claim's meaning (a part
//! *rises* when no value lies below an earlier one by more than the noise
//! between them, and it ends above its start by more than that) is
//! checked on every pair of rows.

#![cfg(feature = "lab")]

use ctrlab::lab::tables::{ERROR_NOISE, Noise, OVERSHOOT_NOISE, SETTLING_NOISE};

/// The rows (cells trimmed) of the first table after the heading that
/// starts with `heading`, header first.
fn table(report: &str, heading: &str) -> Result<Vec<Vec<String>>, String> {
    let mut lines = report.lines().skip_while(|l| {
        !(l.starts_with('#') && l.trim_start_matches('#').trim().starts_with(heading))
    });
    lines.next().ok_or(format!("no heading `{heading}`"))?;
    Ok(lines
        .skip_while(|l| !l.starts_with('|'))
        .take_while(|l| l.starts_with('|'))
        .filter(|l| !l.starts_with("|---"))
        .map(|l| {
            l.trim_matches('|')
                .split(" | ")
                .map(|c| c.trim().to_string())
                .collect()
        })
        .collect())
}

fn column(rows: &[Vec<String>], name: &str) -> Result<Vec<String>, String> {
    let i = rows[0]
        .iter()
        .position(|h| h == name)
        .ok_or(format!("no column `{name}`"))?;
    Ok(rows[1..].iter().map(|r| r[i].clone()).collect())
}

fn num(s: &str) -> Result<f64, String> {
    s.trim().parse().map_err(|_| format!("not a number: `{s}`"))
}

/// Between `start` and `end` in `s`.
fn between<'a>(s: &'a str, start: &str, end: &str) -> Result<&'a str, String> {
    let a = s.find(start).ok_or(format!("no `{start}` in `{s}`"))? + start.len();
    let b = s[a..]
        .find(end)
        .ok_or(format!("no `{end}` after `{start}` in `{s}`"))?;
    Ok(&s[a..a + b])
}

fn up(v: &[f64], n: Noise) -> bool {
    let (a, b) = (v[0], v[v.len() - 1]);
    b - a > n.between(a, b)
        && (0..v.len()).all(|i| (i..v.len()).all(|j| v[j] >= v[i] - n.between(v[i], v[j])))
}

fn down(v: &[f64], n: Noise) -> bool {
    let (a, b) = (v[0], v[v.len() - 1]);
    a - b > n.between(a, b)
        && (0..v.len()).all(|i| (i..v.len()).all(|j| v[j] <= v[i] + n.between(v[i], v[j])))
}

/// Checks one trend claim (`rises from 1.00 to 2.00 mm`, `rises to 35.68 %
/// at Kf3 = 1, then falls to 20.95 %`, …) on the settled `series` (in row
/// order, with the gain's value at each).
fn claim_holds(claim: &str, series: &[(f64, f64)], noise: Noise) -> Result<(), String> {
    let v: Vec<f64> = series.iter().map(|(_, y)| *y).collect();
    let max = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let min = v.iter().copied().fold(f64::INFINITY, f64::min);
    let turn = |value: &str| -> Result<usize, String> {
        let gain = num(between(claim, " = ", ",")?)?;
        let at = series
            .iter()
            .position(|(g, _)| *g == gain)
            .ok_or(format!("no settled row at {gain}"))?;
        let quoted = num(value.split_whitespace().next().unwrap_or(""))?;
        if (quoted - v[at]).abs() > 0.006 {
            return Err(format!("{quoted} is not the value at the turn, {}", v[at]));
        }
        Ok(at)
    };
    let ok = if claim.starts_with("stays within") {
        (0..v.len()).all(|i| (0..v.len()).all(|j| (v[i] - v[j]).abs() <= noise.between(v[i], v[j])))
    } else if claim.starts_with("rises from") {
        up(&v, noise)
    } else if claim.starts_with("falls from") {
        down(&v, noise)
    } else if let Some(rest) = claim.strip_prefix("rises to ") {
        let at = turn(rest)?;
        v[at] == max && up(&v[..=at], noise) && down(&v[at..], noise)
    } else if let Some(rest) = claim.strip_prefix("falls to ") {
        let at = turn(rest)?;
        v[at] == min && down(&v[..=at], noise) && up(&v[at..], noise)
    } else if claim.starts_with("turns more than once") {
        !(up(&v, noise) || down(&v, noise))
    } else {
        return Err(format!("an unknown claim: `{claim}`"));
    };
    if ok {
        Ok(())
    } else {
        Err(format!("`{claim}` does not hold over {v:?}"))
    }
}

/// Every check, on the report's text.
fn answers_hold(report: &str) -> Result<(), String> {
    let mut concluded = Vec::new();
    for n in [5, 6] {
        let rows = table(report, &format!("Table {n}:"))?;
        // Verdicts agree with the ρ printed beside them.
        for cell in column(&rows, "sampled loop, identified model")? {
            let rho = num(between(&cell, "ρ = ", ")")?)?;
            let stable = cell.starts_with("stable");
            if stable != (rho < 1.0) {
                return Err(format!("`{cell}` contradicts itself"));
            }
        }
        let kf = column(&rows, "Kf (per mm)")?;
        let cols = [
            column(&rows, "POT (%)")?,
            column(&rows, "settling time (s)")?,
            column(&rows, "steady-state error (mm)")?,
        ];
        let lines: Vec<&str> = report.lines().collect();
        for (i, line) in lines.iter().enumerate() {
            if !(line.starts_with("- **Kf") && line.contains(&format!("Table {n}) = "))) {
                continue;
            }
            let name = between(line, "**", "**")?;
            let values: Vec<f64> = between(line, ") = ", ": POT")?
                .split(", ")
                .map(num)
                .collect::<Result<_, _>>()?;
            let quoted = [
                between(line, ": POT ", " %;")?,
                between(line, "; settling ", " s;")?,
                between(line, "; steady-state error ", " mm;")?,
            ];
            let quoted: Vec<Vec<&str>> = quoted.iter().map(|q| q.split(", ").collect()).collect();
            // The quoted series are the table's rows, in order: the rows
            // whose Kf has the varied entry at the quoted values.
            let entry = num(name.trim_start_matches("Kf"))? as usize - 1;
            let kf_at = |row: usize| -> Option<f64> {
                kf[row]
                    .trim_matches(['[', ']'])
                    .split_whitespace()
                    .nth(entry)?
                    .parse()
                    .ok()
            };
            if !(0..=kf.len().saturating_sub(values.len())).any(|s| {
                (0..values.len()).all(|j| kf_at(s + j) == Some(values[j]))
                    && (0..3).all(|m| cols[m][s..s + values.len()] == quoted[m][..])
            }) {
                return Err(format!(
                    "{name} (Table {n}): the series are not the table's rows"
                ));
            }
            // Each metric's claim, over the settled rows.
            let noises = [
                ("POT", OVERSHOOT_NOISE),
                ("settling time", SETTLING_NOISE),
                ("steady-state error", ERROR_NOISE),
            ];
            for (m, (label, noise)) in noises.iter().enumerate() {
                let series: Vec<(f64, f64)> = values
                    .iter()
                    .zip(&quoted[m])
                    .filter(|(_, q)| **q != "–")
                    .map(|(g, q)| Ok((*g, num(q)?)))
                    .collect::<Result<_, String>>()?;
                let prefix = format!("  - {label}: ");
                let claim = lines[i + 1..]
                    .iter()
                    .take_while(|l| l.starts_with("  - "))
                    .find_map(|l| l.strip_prefix(prefix.as_str()));
                match (claim, series.len()) {
                    (Some(c), k) if k >= 2 => claim_holds(c, &series, *noise)
                        .map_err(|e| format!("{name} (Table {n}), {label}: {e}"))?,
                    (None, k) if k < 2 => {}
                    (c, k) => {
                        return Err(format!(
                            "{name} (Table {n}), {label}: claim {c:?} over {k} settled rows"
                        ));
                    }
                }
            }
            if lines[i + 1..]
                .iter()
                .take_while(|l| l.starts_with("  - "))
                .any(|l| l.starts_with(&format!("  - **In short**: {name}")))
            {
                concluded.push(name.to_string());
            }
        }
    }
    for name in ["Kf1", "Kf2", "Kf3", "Kf4"] {
        if !concluded.iter().any(|c| c == name) {
            return Err(format!("{name} is never concluded"));
        }
    }
    // The steady-state error on its own: "within the band" as its numbers say.
    let rows = table(report, "3. The steady-state error")?;
    let linear = column(&rows, "linear model e_ss (mm)")?;
    let band = column(&rows, "friction band ± (mm)")?;
    let measured = column(&rows, "measured e_ss (mm)")?;
    let within = column(&rows, "within the band")?;
    if rows.len() < 10 {
        return Err("the steady-state error table has too few rows".into());
    }
    for k in 0..linear.len() {
        let inside = (num(&measured[k])? - num(&linear[k])?).abs() <= num(&band[k])? + 0.006;
        if inside != (within[k] == "yes") {
            return Err(format!("steady-state error row {}: `{}`", k + 1, within[k]));
        }
    }
    Ok(())
}

#[test]
#[ignore = "run by .ci/run after the lab5 example, with LAB5_REPORT set"]
fn the_answers_hold_over_the_tables_rows() {
    let path = std::env::var("LAB5_REPORT").expect("LAB5_REPORT names the report to check");
    let report = std::fs::read_to_string(&path).expect("the report is readable");
    answers_hold(&report).unwrap();
    // The check can fail: a claim turned round, or a verdict that
    // contradicts its ρ, is caught.
    let first = report
        .lines()
        .find(|l| l.starts_with("  - POT: rises from") || l.starts_with("  - POT: falls from"))
        .expect("a rising or falling overshoot");
    let turned = if first.contains("rises from") {
        first.replace("rises from", "falls from")
    } else {
        first.replace("falls from", "rises from")
    };
    assert!(answers_hold(&report.replacen(first, &turned, 1)).is_err());
    let wrong = report.replacen("| stable (ρ = 0.", "| unstable (ρ = 0.", 1);
    assert!(answers_hold(&wrong).is_err());
}
