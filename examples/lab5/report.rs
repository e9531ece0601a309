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
    ) -> Result<(), Box<dyn std::error::Error>> {
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

    /// Writes a Bode figure (magnitude in dB, phase in degrees, against Hz)
    /// of the curves and links it from the report.
    #[cfg(feature = "plot")]
    pub fn bode(
        &mut self,
        file: &str,
        title: &str,
        curves: &[(&str, &ctrlab::freq::Bode)],
    ) -> Result<(), Box<dyn std::error::Error>> {
        use ctrlab::freq::{FrequencyUnit, bode_svg};
        bode_svg(self.out.join(file), title, FrequencyUnit::Hertz, curves)?;
        self.add(&format!("![{title}]({file})\n"));
        Ok(())
    }

    /// Writes the rig runs as small multiples (position over the setpoint,
    /// applied voltage beneath) and links the figure.
    pub fn runs(
        &mut self,
        file: &str,
        title: &str,
        setpoint_mm: f64,
        volts_full_scale: f64,
        runs: &[crate::figures::RunCurve],
    ) -> Result<(), Box<dyn std::error::Error>> {
        #[cfg(feature = "plot")]
        {
            crate::figures::runs_svg(
                &self.out.join(file),
                title,
                setpoint_mm,
                volts_full_scale,
                runs,
            )?;
            self.add(&format!("![{title}]({file})\n"));
        }
        #[cfg(not(feature = "plot"))]
        {
            let (_, _, _) = (setpoint_mm, volts_full_scale, runs);
            self.add(&format!(
                "(figure `{file}`, {title}, needs the `plot` feature)\n"
            ));
        }
        Ok(())
    }

    /// Writes panels of overlaid runs (predicted and measured) and links the
    /// figure.
    pub fn compare(
        &mut self,
        file: &str,
        title: &str,
        volts_full_scale: f64,
        panels: &[crate::figures::ComparePanel],
    ) -> Result<(), Box<dyn std::error::Error>> {
        #[cfg(feature = "plot")]
        {
            crate::figures::compare_svg(&self.out.join(file), title, volts_full_scale, panels)?;
            self.add(&format!("![{title}]({file})\n"));
        }
        #[cfg(not(feature = "plot"))]
        {
            let _ = (volts_full_scale, panels);
            self.add(&format!(
                "(figure `{file}`, {title}, needs the `plot` feature)\n"
            ));
        }
        Ok(())
    }

    /// Writes the per-run estimates with their mean and the truth, and
    /// links the figure.
    pub fn estimates(
        &mut self,
        file: &str,
        title: &str,
        panels: &[crate::figures::ParamPanel],
    ) -> Result<(), Box<dyn std::error::Error>> {
        #[cfg(feature = "plot")]
        {
            crate::figures::estimates_svg(&self.out.join(file), title, panels)?;
            self.add(&format!("![{title}]({file})\n"));
        }
        #[cfg(not(feature = "plot"))]
        {
            let _ = panels;
            self.add(&format!(
                "(figure `{file}`, {title}, needs the `plot` feature)\n"
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

/// The identified model as the report shows it: its `Display`, in a text block.
pub fn fmt_state_equations<D: ctrlab::Domain>(sys: &ctrlab::StateSpace<4, 1, 1, D>) -> String {
    format!("```text\nx = [x1 (m), x1' (m/s), x2 (m), x2' (m/s)],   u in V\n{sys:.4}```\n")
}
