//! The Markdown report: sections and tables, echoed to stdout as they are
//! written, and SVG figures (feature `plot`).

use std::path::{Path, PathBuf};

/// The report being written: Markdown text plus the figures' file names.
pub struct Report {
    text: String,
    out: PathBuf,
}

impl Report {
    pub fn new(out: &Path) -> Self {
        Self {
            text: String::new(),
            out: out.to_path_buf(),
        }
    }

    /// Appends Markdown and echoes it to stdout.
    pub fn add(&mut self, markdown: &str) {
        println!("{markdown}");
        self.text.push_str(markdown);
        self.text.push('\n');
    }

    pub fn heading(&mut self, level: usize, title: &str) {
        self.add(&format!("{} {title}\n", "#".repeat(level)));
    }

    /// A Markdown table: header cells, alignment row, body rows.
    pub fn table(&mut self, header: &[&str], rows: &[Vec<String>]) {
        let mut s = format!(
            "| {} |\n|{}|\n",
            header.join(" | "),
            vec!["---"; header.len()].join("|")
        );
        for row in rows {
            s += &format!("| {} |\n", row.join(" | "));
        }
        self.add(&s);
    }

    /// Writes an SVG of the series and links it from the report. Without the
    /// `plot` feature, says how to get it.
    pub fn figure(
        &mut self,
        file: &str,
        title: &str,
        x_label: &str,
        y_label: &str,
        series: &[(String, Vec<f64>, Vec<f64>)],
    ) -> Result<(), ctrlab::Error> {
        #[cfg(feature = "plot")]
        {
            use ctrlab::plot::{Series, responses_svg};
            let s: Vec<Series<'_>> = series
                .iter()
                .map(|(label, t, y)| Series::new(label, t, y))
                .collect();
            responses_svg(self.out.join(file), title, x_label, y_label, &s)?;
            self.add(&format!("![{title}]({file})\n"));
        }
        #[cfg(not(feature = "plot"))]
        {
            // Without plotters there is nothing to draw these with.
            let (_, _, _, _) = (title, x_label, y_label, series);
            self.add(&format!(
                "(figure `{file}` needs the `plot` feature, on by default)\n"
            ));
        }
        Ok(())
    }

    pub fn write(&self) -> std::io::Result<PathBuf> {
        let path = self.out.join("report.md");
        std::fs::write(&path, &self.text)?;
        Ok(path)
    }
}

/// A 4×4 and a 4×1 matrix side by side, as the state equations.
pub fn fmt_state_equations(
    a: &nalgebra::SMatrix<f64, 4, 4>,
    b: &nalgebra::SMatrix<f64, 4, 1>,
) -> String {
    let mut s = String::from(
        "```text\nx' = A x + B u,   x = [x1 (m), x1' (m/s), x2 (m), x2' (m/s)],   u in V\n\n",
    );
    for r in 0..4 {
        let label = if r == 1 { "A = " } else { "    " };
        let blabel = if r == 1 { "B = " } else { "    " };
        s += &format!(
            "{label}[ {:11.4} {:11.4} {:11.4} {:11.4} ]   {blabel}[ {:9.4} ]\n",
            a[(r, 0)],
            a[(r, 1)],
            a[(r, 2)],
            a[(r, 3)],
            b[(r, 0)]
        );
    }
    s.push_str("```\n");
    s
}
