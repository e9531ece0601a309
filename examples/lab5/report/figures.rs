//! lab5's own figures: the rig runs as small multiples, each run's position
//! over its setpoint with the applied voltage beneath, predicted and
//! measured runs overlaid the same way with a zoom in encoder counts, the
//! identification run over its input, and the identification estimates
//! per run against their mean and the truth.

use plotters::prelude::*;

use super::axes::{self, Area, Failure, LEGEND_HEIGHT, LIMIT, Mark};

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

/// `(t, y)` points up to `t_end` (and one past it, so the line reaches
/// the axis' end).
fn upto(t: &[f64], y: &[f64], t_end: f64) -> Vec<(f64, f64)> {
    let n = t.partition_point(|&t| t <= t_end);
    t.iter()
        .copied()
        .zip(y.iter().copied())
        .take(n + 1)
        .collect()
}

/// The figure's time axis description: the window shown, of how long.
fn time_desc(t_show: f64, t_end: f64) -> String {
    if t_show < t_end {
        format!(
            "t (s): the first {t_show} of {t_end:.1} s; later, a settling run moves < 5 % of the setpoint"
        )
    } else {
        "t (s)".to_owned()
    }
}

/// A grid of panels, one per run: position (mm) and the setpoint as a
/// dashed line on top, the applied voltage (V) beneath with the drive's
/// ±`volts_full_scale` dashed. Small multiples keep 15 runs readable where
/// one chart of 15 curves would not be. The time axis ends where the
/// slowest run has settled (`axes::transient_end`): the seconds after it
/// are a flat line that would squeeze the transient into a corner.
pub fn runs_svg(
    path: &std::path::Path,
    title: &str,
    setpoint_mm: f64,
    volts_full_scale: f64,
    runs: &[RunCurve],
) -> Result<(), Failure> {
    let cols = 3usize;
    let rows = runs.len().div_ceil(cols).max(1);
    let root =
        SVGBackend::new(path, (WIDTH, 60 + LEGEND_HEIGHT + 290 * rows as u32)).into_drawing_area();
    root.fill(&WHITE)?;
    let root = root.titled(title, ("sans-serif", 22))?;
    let (legend, grid) = root.split_vertically(LEGEND_HEIGHT);
    let limit = format!("drive limits ±{volts_full_scale} V");
    axes::legend(
        &legend,
        &[
            ("position", Mark::Line(OKABE_ITO[0])),
            ("setpoint", Mark::Dashed(BLACK)),
            ("applied voltage", Mark::Line(OKABE_ITO[1])),
            (&limit, Mark::Dashed(LIMIT)),
        ],
    )?;
    let cells = grid.split_evenly((rows, cols));
    let t_end = t_end(runs.iter());
    let t_show = axes::transient_end(
        runs.iter().map(|r| (&r.t[..], &r.x_mm[..])),
        setpoint_mm,
        0.2,
        t_end,
    );
    let desc = time_desc(t_show, t_end);
    for (k, (run, cell)) in runs.iter().zip(cells.iter()).enumerate() {
        let curve = Styled {
            run,
            position: OKABE_ITO[0],
            volts: OKABE_ITO[1],
        };
        // The window's sentence under the bottom-left panel only: it
        // is the figure's, and it is wider than one panel.
        let bottom_left = k == cols * (runs.len().div_ceil(cols) - 1);
        let panel = Panel {
            caption: &run.title,
            setpoint_mm,
            volts_full_scale,
            t_end: t_show,
            time_desc: if bottom_left { &desc } else { "t (s)" },
            heights: (170, 0),
        };
        run_panel(cell, &panel, &[curve], None)?;
    }
    root.present()?;
    Ok(())
}

/// Panels side by side, each with its runs overlaid in the scheme's
/// colours: position over the setpoint, beneath it the same in encoder
/// counts from the setpoint, zoomed to where the runs come to rest (the
/// few counts the text compares do not show at the full scale), and the
/// voltage with the drive's limits.
pub fn compare_svg(
    path: &std::path::Path,
    title: &str,
    (volts_full_scale, mm_per_count): (f64, f64),
    panels: &[ComparePanel],
) -> Result<(), Failure> {
    let root = SVGBackend::new(path, (WIDTH, 60 + LEGEND_HEIGHT + 640)).into_drawing_area();
    root.fill(&WHITE)?;
    let root = root.titled(title, ("sans-serif", 22))?;
    let (legend, grid) = root.split_vertically(LEGEND_HEIGHT);
    let names: Vec<&str> = panels
        .first()
        .map(|p| p.runs.iter().map(|r| r.title.as_str()).collect())
        .unwrap_or_default();
    let limit = format!("drive limits ±{volts_full_scale} V");
    let mut entries: Vec<(&str, Mark)> = names
        .iter()
        .enumerate()
        .map(|(k, n)| (*n, Mark::Line(OKABE_ITO[k % OKABE_ITO.len()])))
        .collect();
    entries.push(("setpoint", Mark::Dashed(BLACK)));
    entries.push((&limit, Mark::Dashed(LIMIT)));
    axes::legend(&legend, &entries)?;
    let cells = grid.split_evenly((1, panels.len().max(1)));
    let t_end = t_end(panels.iter().flat_map(|p| p.runs.iter()));
    for (panel, cell) in panels.iter().zip(cells.iter()) {
        let curves: Vec<Styled<'_>> = panel
            .runs
            .iter()
            .enumerate()
            .map(|(k, run)| Styled {
                run,
                position: OKABE_ITO[k % OKABE_ITO.len()],
                volts: OKABE_ITO[k % OKABE_ITO.len()],
            })
            .collect();
        let frame = Panel {
            caption: &panel.title,
            setpoint_mm: panel.setpoint_mm,
            volts_full_scale,
            t_end,
            time_desc: "t (s)",
            heights: (250, 200),
        };
        run_panel(cell, &frame, &curves, Some(mm_per_count))?;
    }
    root.present()?;
    Ok(())
}

/// The identification run: both carts' positions, and beneath them the
/// input voltage with the drive's limits (when known).
pub fn ident_svg(
    path: &std::path::Path,
    title: &str,
    t: &[f64],
    [x1, x2]: [&[f64]; 2],
    (u, volts_full_scale): (&[f64], Option<f64>),
) -> Result<(), Failure> {
    let root = SVGBackend::new(path, (WIDTH, 60 + LEGEND_HEIGHT + 620)).into_drawing_area();
    root.fill(&WHITE)?;
    let root = root.titled(title, ("sans-serif", 22))?;
    let (legend, rest) = root.split_vertically(LEGEND_HEIGHT);
    let limit = volts_full_scale.map(|v| format!("drive limits ±{v} V"));
    let mut entries = vec![
        ("x1", Mark::Line(OKABE_ITO[0])),
        ("x2", Mark::Line(OKABE_ITO[2])),
        ("input u", Mark::Line(OKABE_ITO[1])),
    ];
    if let Some(l) = &limit {
        entries.push((l, Mark::Dashed(LIMIT)));
    }
    axes::legend(&legend, &entries)?;
    let (top, bottom) = rest.split_vertically(400);
    let t_end = t.last().copied().unwrap_or(1.0).max(1e-3);
    let (y0, y1) = range(x1.iter().chain(x2).copied());
    let mut chart = axes::chart(&top, None, (0.0..t_end, y0..y1), None, "position (mm)")?;
    for (x, c) in [(x1, OKABE_ITO[0]), (x2, OKABE_ITO[2])] {
        chart.draw_series(LineSeries::new(upto(t, x, t_end), c.stroke_width(2)))?;
    }
    let v = volts_full_scale.unwrap_or_else(|| range(u.iter().copied()).1.abs()) * 1.15;
    let mut volts = axes::chart(&bottom, None, (0.0..t_end, -v..v), Some("t (s)"), "u (V)")?;
    if let Some(full) = volts_full_scale {
        axes::hline(&mut volts, full, LIMIT)?;
        axes::hline(&mut volts, -full, LIMIT)?;
    }
    volts.draw_series(LineSeries::new(
        upto(t, u, t_end),
        OKABE_ITO[1].stroke_width(2),
    ))?;
    root.present()?;
    Ok(())
}

/// The longest run's end, s.
fn t_end<'a>(runs: impl Iterator<Item = &'a RunCurve>) -> f64 {
    runs.filter_map(|r| r.t.last().copied())
        .fold(0.0, f64::max)
        .max(1e-3)
}

/// A run in a panel, with its colours.
struct Styled<'a> {
    run: &'a RunCurve,
    position: RGBColor,
    volts: RGBColor,
}

/// A panel's frame: caption, setpoint (mm), voltage scale (V), time axis
/// (s) and its description, and the heights of its position chart and
/// its zoom (px; 0 for none).
struct Panel<'a> {
    caption: &'a str,
    setpoint_mm: f64,
    volts_full_scale: f64,
    t_end: f64,
    time_desc: &'a str,
    heights: (u32, u32),
}

/// One panel: the runs' positions over the dashed setpoint on top, with
/// `mm_per_count` a zoom in counts from the setpoint, their voltages
/// beneath between the drive's dashed limits.
fn run_panel(
    cell: &Area<'_>,
    panel: &Panel<'_>,
    curves: &[Styled<'_>],
    mm_per_count: Option<f64>,
) -> Result<(), Failure> {
    let Panel {
        caption,
        setpoint_mm,
        volts_full_scale,
        t_end,
        time_desc,
        heights: (top_px, zoom_px),
    } = *panel;
    let (top, rest) = cell.split_vertically(top_px);
    let (y0, y1) = range(
        curves
            .iter()
            .flat_map(|c| c.run.x_mm.iter().copied())
            .chain([0.0, setpoint_mm]),
    );
    let mut chart = axes::chart(&top, Some(caption), (0.0..t_end, y0..y1), None, "mm")?;
    for c in curves {
        chart.draw_series(LineSeries::new(
            upto(&c.run.t, &c.run.x_mm, t_end),
            c.position.stroke_width(2),
        ))?;
    }
    // On top: a setpoint under the curves must still show.
    axes::hline(&mut chart, setpoint_mm, BLACK)?;
    let bottom = match mm_per_count {
        Some(count) if zoom_px > 0 => {
            let (zoom, bottom) = rest.split_vertically(zoom_px);
            zoom_panel(&zoom, (setpoint_mm, count), t_end, curves)?;
            bottom
        }
        _ => rest,
    };
    let v = volts_full_scale * 1.15;
    let mut volts = axes::chart(&bottom, None, (0.0..t_end, -v..v), Some(time_desc), "V")?;
    axes::hline(&mut volts, volts_full_scale, LIMIT)?;
    axes::hline(&mut volts, -volts_full_scale, LIMIT)?;
    for c in curves {
        volts.draw_series(LineSeries::new(
            upto(&c.run.t, &c.run.u, t_end),
            c.volts.stroke_width(1),
        ))?;
    }
    Ok(())
}

/// The runs in encoder counts from the setpoint, from the time they all
/// stay within the window on: the window is ±1.3 × the largest error of
/// the runs' second half (at least ±3 counts), so their resting places
/// and the counts between them show.
fn zoom_panel(
    area: &Area<'_>,
    (setpoint_mm, mm_per_count): (f64, f64),
    t_end: f64,
    curves: &[Styled<'_>],
) -> Result<(), Failure> {
    let counts = |c: &Styled<'_>| -> Vec<f64> {
        c.run
            .x_mm
            .iter()
            .map(|x| (x - setpoint_mm) / mm_per_count)
            .collect()
    };
    let errors: Vec<Vec<f64>> = curves.iter().map(counts).collect();
    let w = curves
        .iter()
        .zip(&errors)
        .flat_map(|(c, e)| {
            c.run
                .t
                .iter()
                .zip(e)
                .filter(|(t, _)| **t >= 0.5 * t_end)
                .map(|(_, e)| e.abs())
        })
        .fold(0.0, f64::max);
    let w = (1.3 * w).max(3.0);
    // The last time any run is outside the window: the zoom starts there.
    let t0 = curves
        .iter()
        .zip(&errors)
        .flat_map(|(c, e)| {
            c.run
                .t
                .iter()
                .zip(e)
                .filter(|(_, e)| e.abs() > w)
                .map(|(t, _)| *t)
        })
        .fold(0.0, f64::max)
        .min(0.9 * t_end);
    let mut chart = axes::chart(
        area,
        None,
        (t0..t_end, -w..w),
        Some("t (s)"),
        "counts from setpoint",
    )?;
    // The setpoint first, thin: a run resting on it must not vanish under
    // its dashes.
    let x = chart.x_range();
    chart.draw_series(DashedLineSeries::new(
        [(x.start, 0.0), (x.end, 0.0)],
        7,
        5,
        BLACK.stroke_width(1),
    ))?;
    for (c, e) in curves.iter().zip(&errors) {
        let points: Vec<(f64, f64)> = c
            .run
            .t
            .iter()
            .copied()
            .zip(e.iter().copied())
            .filter(|(t, _)| *t >= t0)
            .collect();
        chart.draw_series(LineSeries::new(points, c.position.stroke_width(2)))?;
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
        // Run numbers, every one: whole numbers, not the 0.5 steps a
        // linear axis would pick.
        let run_ticks = ctrlab::plot::Ticks {
            values: (1..=runs).map(|r| r as f64).collect(),
            labels: (1..=runs).map(|r| r.to_string()).collect(),
            minor: Vec::new(),
        };
        let mut chart = axes::chart_ticks(
            cell,
            Some(&panel.name),
            (0.5..runs as f64 + 0.5, y0..y1),
            Some("run"),
            "",
            Some(run_ticks),
        )?;
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
    // Dashed as the truth's line is.
    for k in 0..3 {
        let a = x + k * 11;
        legend.draw(&PathElement::new(
            [(a, 30), (a + 7, 30)],
            BLACK.stroke_width(2),
        ))?;
    }
    legend.draw(&Text::new(
        "truth (dashed)",
        (x + 36, 22),
        ("sans-serif", 14),
    ))?;
    legend.present()?;
    Ok(())
}
