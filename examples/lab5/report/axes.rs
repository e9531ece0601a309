//! lab5's axes and legend: ticks from `ctrlab::plot::Ticks` (spaced by the
//! labels' size, so none collide), a legend strip under the title (so it
//! covers no data), dashed lines for setpoints and the drive's limits.

use std::ops::Range;

use ctrlab::plot::{Along, Ticks};
use plotters::coord::Shift;
use plotters::coord::ranged1d::{DefaultFormatting, KeyPointHint, Ranged};
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

pub type Area<'a> = DrawingArea<SVGBackend<'a>, Shift>;
pub type Chart<'a, 'b> = ChartContext<'a, SVGBackend<'b>, Cartesian2d<Ticked, Ticked>>;
pub type Failure = Box<dyn std::error::Error>;

/// Tick labels' font size, px.
pub const FONT: f64 = 12.0;
/// The y label area and margin, px.
const Y_AREA: u32 = 56;
const MARGIN: u32 = 6;
/// The drive's limits: dark red, dashed.
pub const LIMIT: RGBColor = RGBColor(150, 0, 0);

/// A linear axis with its grid and labels at given ticks (plotters picks
/// its own count, blind to the labels' width).
pub struct Ticked {
    inner: RangedCoordf64,
    ticks: Vec<f64>,
}

impl Ranged for Ticked {
    type ValueType = f64;
    type FormatOption = DefaultFormatting;

    fn range(&self) -> Range<f64> {
        self.inner.range()
    }

    fn map(&self, value: &f64, limit: (i32, i32)) -> i32 {
        self.inner.map(value, limit)
    }

    fn key_points<H: KeyPointHint>(&self, hint: H) -> Vec<f64> {
        // No minor grid: at panel size it reads as a grey band.
        if hint.weight().allow_light_points() {
            Vec::new()
        } else {
            self.ticks.clone()
        }
    }

    fn axis_pixel_range(&self, limit: (i32, i32)) -> Range<i32> {
        self.inner.axis_pixel_range(limit)
    }
}

/// A chart on `area` over `x` × `y`: x labels only when `x_desc` is given
/// (panels stacked on one time axis label the bottom one).
pub fn chart<'a, 'b>(
    area: &'a Area<'b>,
    caption: Option<&str>,
    ranges: (Range<f64>, Range<f64>),
    x_desc: Option<&str>,
    y_desc: &str,
) -> Result<Chart<'a, 'b>, Failure> {
    chart_ticks(area, caption, ranges, x_desc, y_desc, None)
}

/// [`chart`] with the x ticks given (run numbers: whole numbers only).
pub fn chart_ticks<'a, 'b>(
    area: &'a Area<'b>,
    caption: Option<&str>,
    (x, y): (Range<f64>, Range<f64>),
    x_desc: Option<&str>,
    y_desc: &str,
    x_ticks: Option<Ticks>,
) -> Result<Chart<'a, 'b>, Failure> {
    let (w, h) = area.dim_in_pixel();
    let x_area = if x_desc.is_some() { 34 } else { 0 };
    let caption_px = if caption.is_some() { 22 } else { 0 };
    let inner_w = f64::from(w.saturating_sub(Y_AREA + 2 * MARGIN));
    let inner_h = f64::from(h.saturating_sub(x_area + 2 * MARGIN + caption_px));
    let xt =
        x_ticks.unwrap_or_else(|| Ticks::linear(x.start, x.end, inner_w, FONT, Along::Horizontal));
    let yt = Ticks::linear(y.start, y.end, inner_h, FONT, Along::Vertical);
    let mut builder = ChartBuilder::on(area);
    if let Some(c) = caption {
        builder.caption(c, ("sans-serif", 15));
    }
    let mut chart = builder
        .margin(MARGIN)
        .x_label_area_size(x_area)
        .y_label_area_size(Y_AREA)
        .build_cartesian_2d(
            Ticked {
                inner: x.into(),
                ticks: xt.values.clone(),
            },
            Ticked {
                inner: y.into(),
                ticks: yt.values.clone(),
            },
        )?;
    let (x_label, y_label) = (|v: &f64| xt.label(*v), |v: &f64| yt.label(*v));
    let mut mesh = chart.configure_mesh();
    mesh.y_desc(y_desc)
        .x_label_formatter(&x_label)
        .y_label_formatter(&y_label)
        .bold_line_style(BLACK.mix(0.12))
        .label_style(("sans-serif", FONT))
        .axis_desc_style(("sans-serif", FONT));
    if let Some(d) = x_desc {
        mesh.x_desc(d);
    } else {
        mesh.x_labels(0);
    }
    mesh.draw()?;
    Ok(chart)
}

/// A dashed horizontal line across the chart at `y`.
pub fn hline(chart: &mut Chart<'_, '_>, y: f64, color: RGBColor) -> Result<(), Failure> {
    let x = chart.x_range();
    chart.draw_series(DashedLineSeries::new(
        [(x.start, y), (x.end, y)],
        7,
        5,
        color.stroke_width(2),
    ))?;
    Ok(())
}

/// A legend entry's mark.
#[derive(Clone, Copy)]
pub enum Mark {
    Line(RGBColor),
    Dashed(RGBColor),
}

/// The height (px) a legend strip needs: one row.
pub const LEGEND_HEIGHT: u32 = 26;

/// Draws the entries in one row, centred, in `area`.
pub fn legend(area: &Area<'_>, entries: &[(&str, Mark)]) -> Result<(), Failure> {
    let font = 14.0;
    let widths: Vec<i32> = entries
        .iter()
        .map(|(l, _)| 30 + (0.6 * font * l.chars().count() as f64) as i32)
        .collect();
    let total: i32 = widths.iter().sum::<i32>() + 24 * (entries.len() as i32 - 1).max(0);
    let mut x = ((area.dim_in_pixel().0 as i32 - total) / 2).max(8);
    let y = (LEGEND_HEIGHT / 2) as i32;
    let style =
        TextStyle::from(("sans-serif", font).into_font()).pos(Pos::new(HPos::Left, VPos::Center));
    for ((label, mark), w) in entries.iter().zip(widths) {
        match *mark {
            Mark::Line(c) => {
                area.draw(&PathElement::new([(x, y), (x + 24, y)], c.stroke_width(2)))?
            }
            Mark::Dashed(c) => {
                for k in 0..3 {
                    let a = x + k * 9;
                    area.draw(&PathElement::new([(a, y), (a + 6, y)], c.stroke_width(2)))?;
                }
            }
        }
        area.draw(&Text::new(*label, (x + 30, y), style.clone()))?;
        x += w + 24;
    }
    Ok(())
}

/// Where the runs' transients end, s: the last time any position is more
/// than 5 % of the setpoint (at least `tol_mm`) from where it ends, with a
/// quarter more, rounded up to 0.25 s, at least 0.5 s and at most
/// `t_end`. Positions only: a rig's voltage carries the encoder's noise
/// through the gains to the end. A run still moving in the last fifth
/// (oscillating) has no end to its transient and does not count: the
/// window shows its swings all the same.
pub fn transient_end<'a>(
    runs: impl Iterator<Item = (&'a [f64], &'a [f64])>,
    setpoint_mm: f64,
    tol_mm: f64,
    t_end: f64,
) -> f64 {
    let tol = (0.05 * setpoint_mm.abs()).max(tol_mm);
    let mut last: f64 = 0.0;
    for (t, x) in runs {
        let Some(&xf) = x.last() else {
            continue;
        };
        let out = |(&t, &x): (&f64, &f64)| ((x - xf).abs() > tol).then_some(t);
        let run_last = t.iter().zip(x).filter_map(out).fold(0.0, f64::max);
        if run_last < 0.8 * t_end {
            last = last.max(run_last);
        }
    }
    ((1.25 * last / 0.25).ceil() * 0.25).clamp(0.5, t_end)
}
