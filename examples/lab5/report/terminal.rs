//! What lab5 says on the terminal: a line per section as it finishes, and
//! at the end a short summary of the results and where everything is. The
//! report itself is in `report.md`; the terminal does not repeat it.

use std::path::Path;

use ctrlab::lab::tables::{RigOutcome, Table1, Table2};

use super::Report;
use crate::identification::Identification;
use crate::rig_tables::RigTable;

/// Table 1's progress line.
pub fn table1_line(t: &Table1) -> String {
    format!("Table 1 (simulation): {} forces", t.rows.len())
}

/// Table 2's progress line: how many gains settle in simulation.
pub fn table2_line(t: &Table2) -> String {
    let settled = t.rows.iter().filter(|r| r.step.is_some()).count();
    let unstable = t.rows.len() - settled;
    format!(
        "Table 2 (simulation, {} gains): {settled} settled{}",
        t.rows.len(),
        if unstable > 0 {
            format!(", {unstable} unstable")
        } else {
            String::new()
        }
    )
}

/// A rig table in one line: its runs by outcome.
pub fn rig_table_line(t: &RigTable) -> String {
    let mut counts = [0; 4];
    for (run, _) in &t.runs {
        counts[match run.outcome {
            RigOutcome::Settled(_) => 0,
            RigOutcome::TooSlow { .. } => 1,
            RigOutcome::Oscillating { .. } => 2,
            RigOutcome::Diverged { .. } => 3,
        }] += 1;
    }
    let outcomes: Vec<String> = ["settled", "too slow", "oscillating", "diverged"]
        .iter()
        .zip(counts)
        .filter(|&(_, n)| n > 0)
        .map(|(what, n)| format!("{n} {what}"))
        .collect();
    format!(
        "Table {} (cart {}, setpoint {} mm, {} runs): {}",
        t.table.number,
        t.table.cart.number(),
        t.table.setpoint_mm,
        t.runs.len(),
        outcomes.join(", ")
    )
}

/// The identified model in one line.
pub fn model_line(ident: &Identification) -> String {
    let m = ident.model();
    let [f1, f2] = ident.coulomb();
    format!(
        "Identified ({} runs): k1 = {:.1} N/m, k2 = {:.1} N/m, b1 = {:.3} N·s/m, b2 = {:.3} N·s/m, K = {:.4} N/V, Coulomb {:.2} / {:.2} N",
        ident.runs.len(),
        m.k1,
        m.k2,
        m.b1,
        m.b2,
        m.gain,
        f1,
        f2
    )
}

impl Report {
    /// A section's line on the terminal as it finishes.
    pub fn progress(&self, line: &str) {
        println!("{line}");
    }

    /// A result worth repeating in the closing summary, shown now too.
    pub fn result(&mut self, line: String) {
        self.progress(&line);
        self.results.push(line);
    }

    /// The closing summary: the results kept, then where the report, the
    /// figures, the tables and the recordings (`recordings` of them this
    /// run, `None` offline) are.
    pub fn summary(&self, report: &Path, recordings: Option<usize>) -> String {
        let out = self.out.display();
        let mut s = String::new();
        for line in &self.results {
            s += &format!("  {line}\n");
        }
        s += &format!(
            "  report:     {} (the lab's tables and the answers first, then the further sections)\n",
            report.display()
        );
        if self.skipped.is_some() {
            s += "  skipped:    the further sections' runs (--tables-only)\n";
        }
        if !self.figures.is_empty() {
            s += &format!("  figures:    {out}/*.svg ({})\n", self.figures.len());
        }
        if !self.csvs.is_empty() {
            s += &format!("  tables:     {out}/tables/ ({})\n", self.csvs.join(", "));
        }
        match recordings {
            Some(0) | None => {}
            Some(n) => s += &format!("  recordings: {out}/runs/ ({n} CSV, one per run)\n"),
        }
        s
    }
}
