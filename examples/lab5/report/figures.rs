//! lab5's own figures: the rig runs as small multiples, each run's position
//! over its setpoint with the applied voltage beneath, predicted and
//! measured runs overlaid the same way, and the identification estimates
//! per run against their mean and the truth.

use plotters::prelude::*;

/// One closed-loop rig run to draw.
pub struct RunCurve {
    /// Panel title (the gains, and the outcome).
    pub title: String,
    /// Time, s.
    pub t: Vec<f64>,
    /// Position, mm.
    pub x_mm: Vec<f64>,
    /// Applied voltage, V.
    pub u: Vec<f64>,
}

/// One panel of overlaid runs (predicted and measured), each run's
/// `title` its legend entry.
pub struct ComparePanel {
    pub title: String,
    pub setpoint_mm: f64,
    pub runs: Vec<RunCurve>,
}

/// One identified parameter: its estimate per run and scheme.
pub struct ParamPanel {
    /// Name and unit (`"k1 (N/m)"`).
    pub name: String,
    /// (scheme, estimate per run).
    pub schemes: Vec<(String, Vec<f64>)>,
    /// The truth (simulated rig only).
    pub truth: Option<f64>,
}

const WIDTH: u32 = 1200;
/// Scheme colours: distinguishable for colour-blind readers (Okabe–Ito).
const OKABE_ITO: [RGBColor; 4] = [
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
];

fn range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
    if !lo.is_finite() {
        return (-1.0, 1.0);
    }
    let pad = if hi > lo {
        0.08 * (hi - lo)
    } else {
        0.5 * lo.abs().max(1.0)
    };
    (lo - pad, hi + pad)
}

/// A grid of panels, one per run: position (mm) and the setpoint as a
/// dashed line on top, the applied voltage (V) beneath. Small multiples
/// keep 15 runs readable where one chart of 15 curves would not be.
pub fn runs_svg(
    path: &std::path::Path,
    title: &str,
    setpoint_mm: f64,
    volts_full_scale: f64,
    runs: &[RunCurve],
) -> Result<(), Box<dyn std::error::Error>> {
    let cols = 3usize;
    let rows = runs.len().div_ceil(cols).max(1);
    let root = SVGBackend::new(path, (WIDTH, 60 + 260 * rows as u32)).into_drawing_area();
    root.fill(&WHITE)?;
    let root = root.titled(title, ("sans-serif", 24))?;
    let cells = root.split_evenly((rows, cols));
    let t_end = t_end(runs.iter());
    for (run, cell) in runs.iter().zip(cells.iter()) {
        let curve = Styled {
            run,
            label: None,
            position: OKABE_ITO[0],
            volts: OKABE_ITO[1],
        };
        let panel = Panel {
            caption: &run.title,
            setpoint_mm,
            volts_full_scale,
            t_end,
            top: 160,
        };
        run_panel(cell, &panel, &[curve])?;
    }
    root.present()?;
    Ok(())
}

/// Panels side by side, each with its runs overlaid in the scheme's
/// colours (position and voltage alike) and a legend: predicted against
/// measured.
pub fn compare_svg(
    path: &std::path::Path,
    title: &str,
    volts_full_scale: f64,
    panels: &[ComparePanel],
) -> Result<(), Box<dyn std::error::Error>> {
    let root = SVGBackend::new(path, (WIDTH, 60 + 420)).into_drawing_area();
    root.fill(&WHITE)?;
    let root = root.titled(title, ("sans-serif", 24))?;
    let cells = root.split_evenly((1, panels.len().max(1)));
    let t_end = t_end(panels.iter().flat_map(|p| p.runs.iter()));
    for (panel, cell) in panels.iter().zip(cells.iter()) {
        let curves: Vec<Styled<'_>> = panel
            .runs
            .iter()
            .enumerate()
            .map(|(k, run)| Styled {
                run,
                label: Some(&run.title),
                position: OKABE_ITO[k % OKABE_ITO.len()],
                volts: OKABE_ITO[k % OKABE_ITO.len()],
            })
            .collect();
        let frame = Panel {
            caption: &panel.title,
            setpoint_mm: panel.setpoint_mm,
            volts_full_scale,
            t_end,
            top: cell.dim_in_pixel().1 * 5 / 8,
        };
        run_panel(cell, &frame, &curves)?;
    }
    root.present()?;
    Ok(())
}

/// The longest run's end, s.
fn t_end<'a>(runs: impl Iterator<Item = &'a RunCurve>) -> f64 {
    runs.filter_map(|r| r.t.last().copied())
        .fold(0.0, f64::max)
        .max(1e-3)
}

/// A run in a panel, with its legend entry and colours.
struct Styled<'a> {
    run: &'a RunCurve,
    label: Option<&'a str>,
    position: RGBColor,
    volts: RGBColor,
}

/// A panel's frame: caption, setpoint (mm), voltage scale (V), time axis
/// (s) and the height of its position chart (px).
struct Panel<'a> {
    caption: &'a str,
    setpoint_mm: f64,
    volts_full_scale: f64,
    t_end: f64,
    top: u32,
}

/// One panel: the runs' positions over the dashed setpoint on top, their
/// voltages beneath.
fn run_panel(
    cell: &DrawingArea<SVGBackend<'_>, plotters::coord::Shift>,
    panel: &Panel<'_>,
    curves: &[Styled<'_>],
) -> Result<(), Box<dyn std::error::Error>> {
    let Panel {
        caption,
        setpoint_mm,
        volts_full_scale,
        t_end,
        top,
    } = *panel;
    let (top, bottom) = cell.split_vertically(top);
    let (y0, y1) = range(
        curves
            .iter()
            .flat_map(|c| c.run.x_mm.iter().copied())
            .chain([0.0, setpoint_mm]),
    );
    let mut chart = ChartBuilder::on(&top)
        .caption(caption, ("sans-serif", 14))
        .margin(6)
        .x_label_area_size(0)
        .y_label_area_size(48)
        .build_cartesian_2d(0.0..t_end, y0..y1)?;
    chart
        .configure_mesh()
        .y_desc("mm")
        .label_style(("sans-serif", 11))
        .draw()?;
    chart.draw_series(DashedLineSeries::new(
        [(0.0, setpoint_mm), (t_end, setpoint_mm)],
        6,
        4,
        BLACK.stroke_width(1),
    ))?;
    for c in curves {
        let series = chart.draw_series(LineSeries::new(
            c.run.t.iter().copied().zip(c.run.x_mm.iter().copied()),
            c.position.stroke_width(2),
        ))?;
        if let Some(label) = c.label {
            let color = c.position;
            series.label(label).legend(move |(x, y)| {
                PathElement::new([(x, y), (x + 20, y)], color.stroke_width(2))
            });
        }
    }
    if curves.iter().any(|c| c.label.is_some()) {
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::LowerRight)
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .label_font(("sans-serif", 12))
            .draw()?;
    }
    let v = volts_full_scale * 1.1;
    let mut volts = ChartBuilder::on(&bottom)
        .margin(6)
        .x_label_area_size(28)
        .y_label_area_size(48)
        .build_cartesian_2d(0.0..t_end, -v..v)?;
    volts
        .configure_mesh()
        .x_desc("t (s)")
        .y_desc("V")
        .label_style(("sans-serif", 11))
        .draw()?;
    for c in curves {
        volts.draw_series(LineSeries::new(
            c.run.t.iter().copied().zip(c.run.u.iter().copied()),
            c.volts.stroke_width(1),
        ))?;
    }
    Ok(())
}

/// One panel per parameter: each run's estimate per scheme as points, their
/// mean as a line in the scheme's colour, the truth as a black dashed line;
/// the legend sits below the panels, outside the data.
pub fn estimates_svg(
    path: &std::path::Path,
    title: &str,
    panels: &[ParamPanel],
) -> Result<(), Box<dyn std::error::Error>> {
    let height = 440;
    let root = SVGBackend::new(path, (WIDTH, height)).into_drawing_area();
    root.fill(&WHITE)?;
    let root = root.titled(title, ("sans-serif", 24))?;
    let (plots, legend) = root.split_vertically(height - 90);
    let cells = plots.split_evenly((1, panels.len().max(1)));
    for (panel, cell) in panels.iter().zip(cells.iter()) {
        let runs = panel
            .schemes
            .iter()
            .map(|(_, v)| v.len())
            .max()
            .unwrap_or(1);
        let (y0, y1) = range(
            panel
                .schemes
                .iter()
                .flat_map(|(_, v)| v.iter().copied())
                .chain(panel.truth),
        );
        let mut chart = ChartBuilder::on(cell)
            .caption(&panel.name, ("sans-serif", 16))
            .margin(10)
            .x_label_area_size(30)
            .y_label_area_size(64)
            .build_cartesian_2d(0.5..runs as f64 + 0.5, y0..y1)?;
        chart
            .configure_mesh()
            .x_desc("run")
            .x_labels(runs)
            .label_style(("sans-serif", 11))
            .draw()?;
        for (k, (_, values)) in panel.schemes.iter().enumerate() {
            let color = OKABE_ITO[k % OKABE_ITO.len()];
            // Schemes side by side within a run, so points do not hide.
            let offset = (k as f64 - (panel.schemes.len() as f64 - 1.0) / 2.0) * 0.12;
            chart.draw_series(
                values
                    .iter()
                    .enumerate()
                    .map(|(i, &v)| Circle::new((i as f64 + 1.0 + offset, v), 4, color.filled())),
            )?;
            let mean = values.iter().sum::<f64>() / values.len().max(1) as f64;
            chart.draw_series(LineSeries::new(
                [(0.5, mean), (runs as f64 + 0.5, mean)],
                color.stroke_width(1),
            ))?;
        }
        if let Some(truth) = panel.truth {
            chart.draw_series(DashedLineSeries::new(
                [(0.5, truth), (runs as f64 + 0.5, truth)],
                6,
                4,
                BLACK.stroke_width(2),
            ))?;
        }
    }
    // The legend: scheme colours (points and their mean), and the truth.
    let names: Vec<&str> = panels
        .first()
        .map(|p| p.schemes.iter().map(|(n, _)| n.as_str()).collect())
        .unwrap_or_default();
    let mut x = 20;
    for (k, name) in names.iter().enumerate() {
        let color = OKABE_ITO[k % OKABE_ITO.len()];
        legend.draw(&Circle::new((x, 30), 5, color.filled()))?;
        legend.draw(&Text::new(
            format!("{name} (points: runs, line: mean)"),
            (x + 12, 22),
            ("sans-serif", 14),
        ))?;
        x += 330;
    }
    legend.draw(&PathElement::new(
        [(x, 30), (x + 30, 30)],
        BLACK.stroke_width(2),
    ))?;
    legend.draw(&Text::new(
        "truth (dashed)",
        (x + 36, 22),
        ("sans-serif", 14),
    ))?;
    legend.present()?;
    Ok(())
}
