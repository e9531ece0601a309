//! Every table of the report also as CSV, in `tables/` beside it: one row
//! per Markdown row, the same numbers at full precision (Rust's shortest
//! round-trip form), the unit in every column's name, and an empty cell
//! where the Markdown has none (a run that did not settle has no
//! metrics; its outcome column says why). Written with `csv-core`, the
//! library's own CSV writer's core, which quotes what needs quoting.

use std::path::PathBuf;

use ctrlab::StepInfo;
use ctrlab::lab::FrictionPlant;
use ctrlab::lab::ident::{MassSpringEstimate, Spread, Summary};
use ctrlab::lab::tables::{Halt, RigOutcome, Table1, Table2};
use ctrlab::nalgebra::Complex;

use super::Report;
use crate::rig_tables::RigTable;

/// A number at full precision; empty when it is not finite (no value).
fn num(v: f64) -> String {
    if v.is_finite() {
        format!("{v:?}")
    } else {
        String::new()
    }
}

/// An optional number: empty when there is none.
fn opt(v: Option<f64>) -> String {
    v.map_or_else(String::new, num)
}

/// The four gains' columns: `kf1_{unit}` … `kf4_{unit}`.
/// The gains' columns: `unit` per mm on the positions (Kf1, Kf3) and per
/// mm/s on the speeds (Kf2, Kf4), e.g. `kf1_V_per_mm`, `kf2_V_s_per_mm`.
fn kf_header(unit: &str) -> Vec<String> {
    (1..=4)
        .map(|i| {
            if i % 2 == 0 {
                format!("kf{i}_{unit}_s_per_mm")
            } else {
                format!("kf{i}_{unit}_per_mm")
            }
        })
        .collect()
}

/// The four poles' columns, real and imaginary parts, 1/s.
fn poles_header(prefix: &str) -> Vec<String> {
    (1..=4)
        .flat_map(|i| {
            [
                format!("{prefix}{i}_re_per_s"),
                format!("{prefix}{i}_im_per_s"),
            ]
        })
        .collect()
}

fn poles(p: &[Complex<f64>; 4]) -> Vec<String> {
    p.iter().flat_map(|p| [num(p.re), num(p.im)]).collect()
}

/// A run's outcome in one word or two, and what the Markdown says beside it.
fn outcome(o: &RigOutcome) -> (&'static str, String) {
    match o {
        RigOutcome::Settled(_) => ("settled", String::new()),
        RigOutcome::TooSlow { y_end_mm } => ("too slow", format!("at {y_end_mm} mm at the end")),
        RigOutcome::Oscillating {
            lo_mm,
            hi_mm,
            saturated,
        } => (
            "oscillating",
            format!(
                "{lo_mm} to {hi_mm} mm, the drive saturated {} % of the time",
                100.0 * saturated
            ),
        ),
        RigOutcome::Diverged { at, why } => (
            "diverged",
            format!(
                "halted at t = {at} s: {}",
                match why {
                    Halt::TravelLimit {
                        cart,
                        position,
                        limit,
                    } => format!(
                        "cart {cart} at {} mm beyond the ±{} mm travel limit",
                        position * 1e3,
                        limit * 1e3
                    ),
                    Halt::Fault(message) => message.clone(),
                    Halt::NoMetrics(e) => format!("no metrics: {e}"),
                }
            ),
        ),
    }
}

/// A step's metrics as the rig tables show them; empty without one.
fn metrics(step: Option<&StepInfo>) -> Vec<String> {
    match step {
        Some(i) => vec![
            num(i.steady_state_value),
            num(i.peak),
            num(i.overshoot),
            num(i.settling_time),
            opt(i.steady_state_error),
        ],
        None => vec![String::new(); 5],
    }
}

impl Report {
    /// Writes `tables/{file}` and has the next Markdown table link it.
    fn csv<S: AsRef<str>>(
        &mut self,
        file: &str,
        header: &[S],
        rows: &[Vec<String>],
    ) -> Result<PathBuf, Box<dyn std::error::Error>> {
        let dir = self.out.join("tables");
        std::fs::create_dir_all(&dir)?;
        let header: Vec<String> = header.iter().map(|h| h.as_ref().to_owned()).collect();
        let mut core = csv_core::WriterBuilder::new().build();
        let (mut text, mut buf) = (Vec::new(), vec![0; 1024]);
        for record in std::iter::once(&header).chain(rows) {
            for (i, field) in record.iter().enumerate() {
                if i > 0 {
                    drain(&mut text, &mut buf, |b| core.delimiter(b));
                }
                let mut input = field.as_bytes();
                drain(&mut text, &mut buf, |b| {
                    let (r, nin, n) = core.field(input, b);
                    input = &input[nin..];
                    (r, n)
                });
            }
            drain(&mut text, &mut buf, |b| core.terminator(b));
        }
        let path = dir.join(file);
        std::fs::write(&path, text)?;
        self.csvs.push(file.to_owned());
        self.csv_next = Some(file.to_owned());
        Ok(path)
    }

    /// Table 1 as `tables/table1.csv`, linked under its Markdown table.
    pub fn table1_csv(&mut self, t: &Table1) -> Result<(), Box<dyn std::error::Error>> {
        let rows: Vec<Vec<String>> = t
            .rows
            .iter()
            .map(|r| {
                vec![
                    num(r.force),
                    num(r.x1_mm),
                    num(r.x1_static_mm),
                    num(r.x2_mm),
                    num(r.x2_static_mm),
                ]
            })
            .collect();
        let header = [
            "F_N",
            "x1_sim_mm",
            "x1_exact_mm",
            "x2_sim_mm",
            "x2_exact_mm",
        ];
        self.csv("table1.csv", &header, &rows)?;
        Ok(())
    }

    /// Table 2 as `tables/table2.csv`: the gains act on a force (the
    /// nominal model's K = 1), so N per mm.
    pub fn table2_csv(&mut self, t: &Table2) -> Result<(), Box<dyn std::error::Error>> {
        let mut header = kf_header("N");
        header.extend(poles_header("pole"));
        header.extend(
            [
                "outcome",
                "POT_pct",
                "settling_time_s",
                "steady_state_error_mm",
            ]
            .map(String::from),
        );
        let rows: Vec<Vec<String>> = t
            .rows
            .iter()
            .map(|r| {
                let mut row: Vec<String> = r.kf.iter().map(|&k| num(k)).collect();
                row.extend(poles(&r.poles));
                match &r.step {
                    Some(step) => row.extend([
                        "settled".into(),
                        num(step.info.overshoot),
                        num(step.info.settling_time),
                        opt(step.info.steady_state_error),
                    ]),
                    None => {
                        row.push("unstable".into());
                        row.extend(vec![String::new(); 3]);
                    }
                }
                row
            })
            .collect();
        self.csv("table2.csv", &header, &rows)?;
        Ok(())
    }

    /// Table 5 or 6 as `tables/table{n}.csv`, each row with its recording.
    pub fn rig_table_csv(&mut self, t: &RigTable) -> Result<(), Box<dyn std::error::Error>> {
        let mut header = kf_header("V");
        header.extend(["predicted", "spectral_radius"].map(String::from));
        header.extend(poles_header("pole"));
        header.extend(
            [
                "outcome",
                "y_inf_mm",
                "peak_mm",
                "POT_pct",
                "settling_time_s",
                "steady_state_error_mm",
                "why",
                "recording",
            ]
            .map(String::from),
        );
        let rows: Vec<Vec<String>> = t
            .runs
            .iter()
            .zip(&t.names)
            .map(|((run, _), name)| {
                let p = &run.prediction;
                let mut row: Vec<String> = run.kf.iter().map(|&k| num(k)).collect();
                row.push(if p.is_stable() { "stable" } else { "unstable" }.into());
                row.push(num(p.radius));
                row.extend(poles(&p.poles));
                let (label, why) = outcome(&run.outcome);
                row.push(label.into());
                row.extend(metrics(run.outcome.step()));
                row.push(why);
                row.push(format!("runs/{name}.csv"));
                row
            })
            .collect();
        self.csv(&format!("table{}.csv", t.table.number), &header, &rows)?;
        Ok(())
    }

    /// Tables 3 and 4 as `tables/table3.csv` and `table4.csv`: a row per
    /// run, then the mean and the standard deviation over the runs (the
    /// Markdown's `mean ± sd` row, split so that every cell is a number),
    /// then the simulated card's truth when there is one.
    pub(super) fn table3_csv(
        &mut self,
        s: &Summary,
        truth: Option<&FrictionPlant>,
    ) -> Result<(), Box<dyn std::error::Error>> {
        let header = [
            "run",
            "k12_lab_N_per_m",
            "b1_lab_N_s_per_m",
            "k12_central_N_per_m",
            "b1_central_N_s_per_m",
            "k1_separate_N_per_m",
            "k2_separate_N_per_m",
            "b1_separate_N_s_per_m",
            "coulomb1_separate_N",
        ];
        let row = |run: String, l: [f64; 2], c: [f64; 2], e: [f64; 4]| {
            let mut r = vec![run];
            r.extend(l.into_iter().chain(c).chain(e).map(num));
            r
        };
        let est = |l: &MassSpringEstimate, c: &MassSpringEstimate, e: &MassSpringEstimate| {
            (
                [l.k1().value, l.b1.value],
                [c.k1().value, c.b1.value],
                [e.k1().value, e.k2().value, e.b1.value, coulomb(e, 0)],
            )
        };
        let mut rows = Vec::new();
        for (i, ((l, c), e)) in s.lab.iter().zip(&s.central).zip(&s.separate).enumerate() {
            let (l, c, e) = est(l, c, e);
            rows.push(row(format!("{}", i + 1), l, c, e));
        }
        let (al, ac, a) = (&s.lab_average, &s.central_average, &s.average);
        let stat = |f: fn(&Spread) -> f64| {
            (
                [f(&al.k1()), f(&al.b1)],
                [f(&ac.k1()), f(&ac.b1)],
                [f(&a.k1()), f(&a.k2()), f(&a.b1), f(&s.coulomb[0])],
            )
        };
        for (name, f) in [("mean", mean as fn(&Spread) -> f64), ("sd", sd)] {
            let (l, c, e) = stat(f);
            rows.push(row(name.into(), l, c, e));
        }
        if let Some(plant) = truth {
            let (t, forces) = (plant.truth(), plant.friction());
            // The lab's k12 has no true value when k1 ≠ k2.
            let (l, c) = ([f64::NAN, t.b1], [f64::NAN; 2]);
            rows.push(row("truth".into(), l, c, [t.k1, t.k2, t.b1, forces[0]]));
        }
        self.csv("table3.csv", &header, &rows)?;
        Ok(())
    }

    /// Table 4 as `tables/table4.csv`, rows as Table 3's.
    pub(super) fn table4_csv(
        &mut self,
        s: &Summary,
        truth: Option<&FrictionPlant>,
    ) -> Result<(), Box<dyn std::error::Error>> {
        let header = [
            "run",
            "K_lab_N_per_V",
            "b2_lab_N_s_per_m",
            "K_central_N_per_V",
            "b2_central_N_s_per_m",
            "K_separate_N_per_V",
            "b2_separate_N_s_per_m",
            "coulomb2_separate_N",
        ];
        let row = |run: String, v: [f64; 7]| {
            let mut r = vec![run];
            r.extend(v.map(num));
            r
        };
        let mut rows = Vec::new();
        for (i, ((l, c), e)) in s.lab.iter().zip(&s.central).zip(&s.separate).enumerate() {
            rows.push(row(
                format!("{}", i + 1),
                [
                    l.gain.value,
                    l.b2.value,
                    c.gain.value,
                    c.b2.value,
                    e.gain.value,
                    e.b2.value,
                    coulomb(e, 1),
                ],
            ));
        }
        let (al, ac, a) = (&s.lab_average, &s.central_average, &s.average);
        for (name, f) in [("mean", mean as fn(&Spread) -> f64), ("sd", sd)] {
            rows.push(row(
                name.into(),
                [
                    f(&al.gain),
                    f(&al.b2),
                    f(&ac.gain),
                    f(&ac.b2),
                    f(&a.gain),
                    f(&a.b2),
                    f(&s.coulomb[1]),
                ],
            ));
        }
        if let Some(plant) = truth {
            let (t, forces) = (plant.truth(), plant.friction());
            rows.push(row(
                "truth".into(),
                [t.gain, t.b2, f64::NAN, f64::NAN, t.gain, t.b2, forces[1]],
            ));
        }
        self.csv("table4.csv", &header, &rows)?;
        Ok(())
    }

    /// The identified model's parameters with their uncertainty as
    /// `tables/model.csv`: one row per parameter, its unit in a column.
    pub(super) fn model_csv(
        &mut self,
        s: &Summary,
        truth: Option<&FrictionPlant>,
    ) -> Result<(), Box<dyn std::error::Error>> {
        let header = [
            "parameter",
            "unit",
            "mean",
            "sd_over_runs",
            "standard_error_of_one_run",
            "se_over_sd",
            "se_of_the_mean",
            "truth",
            "mean_minus_truth_over_se_of_the_mean",
        ];
        let rows: Vec<Vec<String>> = s
            .uncertainty(truth)
            .iter()
            .map(|u| {
                vec![
                    u.parameter.symbol().to_owned(),
                    u.parameter.unit().to_owned(),
                    num(u.spread.mean),
                    num(u.spread.std_dev),
                    num(u.std_error),
                    num(u.ratio()),
                    num(u.std_error_of_mean()),
                    opt(u.truth),
                    opt(u.bias()),
                ]
            })
            .collect();
        self.csv("model.csv", &header, &rows)?;
        Ok(())
    }
}

/// Runs one of `csv-core`'s writer steps into `text` until it has
/// written all its input (`OutputFull` only means the buffer filled).
fn drain(
    text: &mut Vec<u8>,
    buf: &mut [u8],
    mut step: impl FnMut(&mut [u8]) -> (csv_core::WriteResult, usize),
) {
    loop {
        let (result, n) = step(buf);
        text.extend_from_slice(&buf[..n]);
        if let csv_core::WriteResult::InputEmpty = result {
            return;
        }
    }
}

fn mean(s: &Spread) -> f64 {
    s.mean
}

fn sd(s: &Spread) -> f64 {
    s.std_dev
}

/// A separate-springs estimate's Coulomb force on `cart` (0 or 1), N;
/// not finite (an empty cell) without one.
fn coulomb(e: &MassSpringEstimate, cart: usize) -> f64 {
    e.coulomb.map_or(f64::NAN, |c| c[cart].value)
}
