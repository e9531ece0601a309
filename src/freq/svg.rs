//! Bode and Nyquist figures (feature `plot`), in the conventions of
//! [`crate::plot`]: SVG through plotters, axes covering every finite point,
//! non-finite points skipped.

use std::f64::consts::PI;
use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

use super::bode::{Bode, Nyquist};
use crate::error::Error;
use plotters::coord::combinators::LogCoord;
use plotters::coord::types::RangedCoordf64;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use crate::plot::{
    Along, MAX_POINTS, Mark, PlotError, Ticked, Ticks, axis, titled_with_legend, write_error,
};

/// The unit of a Bode figure's frequency axis.
///
/// # Examples
///
/// ```
/// use ctrlab::freq::FrequencyUnit;
///
/// assert_eq!(FrequencyUnit::Hertz.label(), "frequency (Hz)");
/// assert_eq!(FrequencyUnit::RadPerSecond.scale(), 1.0);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FrequencyUnit {
    /// Angular frequency, rad/s.
    RadPerSecond,
    /// Frequency, Hz (`ω / 2π`).
    Hertz,
}

impl FrequencyUnit {
    /// The axis label, with the unit.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::freq::FrequencyUnit;
    /// assert_eq!(FrequencyUnit::RadPerSecond.label(), "angular frequency (rad/s)");
    /// ```
    pub fn label(self) -> &'static str {
        match self {
            FrequencyUnit::RadPerSecond => "angular frequency (rad/s)",
            FrequencyUnit::Hertz => "frequency (Hz)",
        }
    }

    /// The factor from rad/s to this unit.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::freq::FrequencyUnit;
    /// assert_eq!(FrequencyUnit::Hertz.scale(), 1.0 / (2.0 * std::f64::consts::PI));
    /// ```
    pub fn scale(self) -> f64 {
        match self {
            FrequencyUnit::RadPerSecond => 1.0,
            FrequencyUnit::Hertz => 1.0 / (2.0 * PI),
        }
    }
}

fn no_points() -> Error {
    Error::InvalidData {
        what: "series",
        index: 0,
        reason: "no finite point to plot",
    }
}

/// Finite `(x, y)` points, at most [`MAX_POINTS`] (every k-th and the
/// last).
fn thin(x: &[f64], y: &[f64]) -> Vec<(f64, f64)> {
    let stride = x.len().div_ceil(MAX_POINTS).max(1);
    let last = x.len().saturating_sub(1);
    x.iter()
        .zip(y)
        .enumerate()
        .filter(|(i, _)| i % stride == 0 || *i == last)
        .map(|(_, (&x, &y))| (x, y))
        .filter(|(x, y)| x.is_finite() && y.is_finite())
        .collect()
}

/// The range of finite values, padded as [`crate::plot`] pads.
pub(super) fn range(values: impl Iterator<Item = f64>, pad: f64) -> Result<(f64, f64), Error> {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.filter(|v| v.is_finite()) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if !lo.is_finite() {
        return Err(no_points());
    }
    axis(lo, hi, pad).ok_or(Error::InvalidData {
        what: "series",
        index: 0,
        reason: "the points span more than f64::MAX: no axis can hold them",
    })
}

/// Label font size, px (plotters' size).
pub(super) const FONT: f64 = 14.0;
/// Label areas and margin, px.
pub(super) const X_AREA: u32 = 44;
pub(super) const Y_AREA: u32 = 72;
pub(super) const MARGIN: u32 = 12;

/// A Bode panel's frame: x range, axis names, and whether the marks are
/// labelled (in the top panel only).
struct Frame<'a> {
    x: (f64, f64),
    y_label: &'a str,
    x_label: &'a str,
    /// The frequency unit's symbol, after a mark's value.
    symbol: &'a str,
    label_marks: bool,
}

/// One Bode panel: the curves over the marks (dashed verticals), with
/// ticks spaced by their labels' size.
fn panel(
    area: &DrawingArea<SVGBackend<'_>, Shift>,
    path: &Path,
    frame: &Frame<'_>,
    curves: &[(&str, Vec<(f64, f64)>)],
    marks: &[(&str, f64)],
) -> Result<(), PlotError> {
    let err = |e| write_error(path, e);
    let (x0, x1) = frame.x;
    let (y0, y1) = range(curves.iter().flat_map(|(_, p)| p.iter().map(|q| q.1)), 0.05)?;
    let (w, h) = area.dim_in_pixel();
    let xt = Ticks::log(x0, x1, f64::from(w - Y_AREA - 2 * MARGIN), FONT);
    let yt = Ticks::linear(
        y0,
        y1,
        f64::from(h - X_AREA - 2 * MARGIN),
        FONT,
        Along::Vertical,
    );
    let mut chart = ChartBuilder::on(area)
        .margin(MARGIN)
        .x_label_area_size(X_AREA)
        .y_label_area_size(Y_AREA)
        .build_cartesian_2d(
            Ticked::new(LogCoord::from((x0..x1).log_scale()), &xt),
            Ticked::new(RangedCoordf64::from(y0..y1), &yt),
        )
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc(frame.x_label)
        .y_desc(frame.y_label)
        .x_label_formatter(&|v| xt.label(*v))
        .y_label_formatter(&|v| yt.label(*v))
        // The minor grid only a hint: dense decades must not read as a band.
        .light_line_style(BLACK.mix(0.04))
        .bold_line_style(BLACK.mix(0.15))
        .label_style(("sans-serif", FONT))
        .axis_desc_style(("sans-serif", 16))
        .draw()
        .map_err(err)?;
    for (i, (_, points)) in curves.iter().enumerate() {
        chart
            .draw_series(LineSeries::new(
                points.iter().copied(),
                curve_color(i).stroke_width(curve_width(i, curves.len())),
            ))
            .map_err(err)?;
    }
    let font = TextStyle::from(("sans-serif", FONT).into_font());
    for (k, &(label, f)) in marks.iter().enumerate() {
        if !(f > x0 && f < x1) {
            continue;
        }
        chart
            .draw_series(DashedLineSeries::new(
                [(f, y0), (f, y1)],
                6,
                4,
                BLACK.mix(0.7).stroke_width(1),
            ))
            .map_err(err)?;
        if frame.label_marks {
            // Alternately left and right of the line, so that two modes
            // close together label away from each other.
            let (px, py) = chart.backend_coord(&(f, y1));
            let (bx, by) = area.get_base_pixel();
            let (anchor, dx) = if k % 2 == 1 {
                (HPos::Left, 5)
            } else {
                (HPos::Right, -5)
            };
            area.draw(&Text::new(
                format!("{label}: {} {}", frequency_label(f), frame.symbol),
                (px - bx + dx, py - by + 4),
                font.pos(Pos::new(anchor, VPos::Top)),
            ))
            .map_err(err)?;
        }
    }
    Ok(())
}

/// A mark's frequency in the axis' unit, three significant figures.
pub(super) fn frequency_label(f: f64) -> String {
    let decimals = (2.0 - f.abs().log10().floor()).clamp(0.0, 6.0) as usize;
    format!("{f:.decimals$}")
}

/// The i-th curve's colour: Okabe–Ito, readable by colour-blind readers.
pub(super) fn curve_color(i: usize) -> RGBColor {
    crate::plot::PALETTE[i % crate::plot::PALETTE.len()]
}

/// The i-th of n curves' stroke width: 3 px for the first down to 1 px for
/// the last, so a curve drawn over an earlier one it follows closely
/// leaves the earlier one's edges in sight.
fn curve_width(i: usize, n: usize) -> u32 {
    if n <= 1 {
        2
    } else {
        3 - (2 * i / (n - 1)) as u32
    }
}

/// Writes a Bode figure to an SVG file: magnitude (dB) above, unwrapped
/// phase (degrees) below, against a logarithmic frequency axis in `unit`
/// (named in the axis label). One labelled curve per [`Bode`]; points at
/// non-positive frequencies (no place on a log axis) and non-finite points
/// are skipped.
///
/// # Errors
///
/// [`PlotError::Data`] with [`Error::InvalidData`] if there is no finite
/// point at a positive frequency; [`PlotError::Write`] if the file cannot
/// be written.
///
/// # Examples
///
/// ```
/// use ctrlab::{Cart, MassSpring};
/// use ctrlab::freq::{FrequencyUnit, bode, bode_svg, logspace};
///
/// let plant = MassSpring::nominal().state_space(Cart::Two)?;
/// let b = bode(&plant, &logspace(0.0, 3.0, 400)?)?;
/// let path = std::env::temp_dir().join("ctrlab_bode_doc.svg");
/// bode_svg(&path, "Two-cart plant", FrequencyUnit::Hertz, &[("force to x2", &b)])?;
/// assert!(std::fs::read_to_string(&path).unwrap().contains("frequency (Hz)"));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[doc(alias = "bodeplot")]
pub fn bode_svg(
    path: impl AsRef<Path>,
    title: &str,
    unit: FrequencyUnit,
    curves: &[(&str, &Bode)],
) -> Result<(), PlotError> {
    bode_marked_svg(path, title, unit, curves, &[])
}

/// [`bode_svg`] with frequencies marked (a mode, a crossover): a dashed
/// vertical line across both panels at each `(label, ω)` (ω in rad/s,
/// shown in `unit`), labelled with its name and frequency at the top of
/// the magnitude panel. The curves are drawn in order, from 3 px wide for
/// the first down to 1 px for the last, so one that follows another
/// closely still shows; one legend, above the panels.
///
/// # Errors
///
/// As [`bode_svg`].
///
/// # Examples
///
/// ```
/// use ctrlab::{Cart, MassSpring};
/// use ctrlab::freq::{FrequencyUnit, bode, bode_marked_svg, logspace};
///
/// let plant = MassSpring::nominal().state_space(Cart::Two)?;
/// let b = bode(&plant, &logspace(0.0, 3.0, 400)?)?;
/// let path = std::env::temp_dir().join("ctrlab_bode_marked_doc.svg");
/// let marks = [("mode 1", 20.0)];
/// bode_marked_svg(&path, "Two-cart plant", FrequencyUnit::Hertz, &[("force to x2", &b)], &marks)?;
/// let svg = std::fs::read_to_string(&path).unwrap();
/// // 20 rad/s is 3.18 Hz.
/// assert!(svg.contains("mode 1: 3.18 Hz"));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn bode_marked_svg(
    path: impl AsRef<Path>,
    title: &str,
    unit: FrequencyUnit,
    curves: &[(&str, &Bode)],
    marks: &[(&str, f64)],
) -> Result<(), PlotError> {
    let path = path.as_ref();
    let scale = unit.scale();
    let keep = |b: &Bode, y: Vec<f64>| {
        let x: Vec<f64> = b.omega.iter().map(|w| w * scale).collect();
        thin(&x, &y)
            .into_iter()
            .filter(|(x, _)| *x > 0.0)
            .collect::<Vec<_>>()
    };
    let mag: Vec<(&str, Vec<(f64, f64)>)> = curves
        .iter()
        .map(|(l, b)| (*l, keep(b, b.magnitude_db())))
        .collect();
    let phase: Vec<(&str, Vec<(f64, f64)>)> = curves
        .iter()
        .map(|(l, b)| (*l, keep(b, b.phase_deg())))
        .collect();
    let marks: Vec<(&str, f64)> = marks.iter().map(|&(l, w)| (l, w * scale)).collect();
    let (x0, x1) = range(mag.iter().flat_map(|(_, p)| p.iter().map(|q| q.0)), 0.0)?;
    let x0 = if x0 > 0.0 { x0 } else { x1 / 10.0 };
    let entries: Vec<(&str, Mark)> = curves
        .iter()
        .enumerate()
        .map(|(i, (l, _))| {
            let w = curve_width(i, curves.len()).max(2);
            (*l, Mark::Line(curve_color(i).to_rgba(), w))
        })
        .collect();
    let root = SVGBackend::new(path, (960, 840)).into_drawing_area();
    let err = |e| write_error(path, e);
    let panels = titled_with_legend(&root, title, &entries, FONT).map_err(err)?;
    let half = panels.dim_in_pixel().1 / 2;
    let (top, bottom) = panels.split_vertically(half);
    let mut frame = Frame {
        x: (x0, x1),
        y_label: "magnitude (dB)",
        x_label: unit.label(),
        symbol: match unit {
            FrequencyUnit::Hertz => "Hz",
            FrequencyUnit::RadPerSecond => "rad/s",
        },
        label_marks: true,
    };
    panel(&top, path, &frame, &mag, &marks)?;
    frame.y_label = "phase (deg)";
    frame.label_marks = false;
    panel(&bottom, path, &frame, &phase, &marks)?;
    root.present().map_err(err)?;
    Ok(())
}

/// Writes a Nyquist figure to an SVG file: `Im G` against `Re G` for each
/// [`Nyquist`] (solid for the given frequencies, thin for their mirror
/// image, the negative frequencies), with the critical point −1 marked.
///
/// # Errors
///
/// [`PlotError::Data`] with [`Error::InvalidData`] if there is no finite
/// point, or the points span more than `f64::MAX`; [`PlotError::Write`] if
/// the file cannot be written.
///
/// # Examples
///
/// ```
/// use ctrlab::freq::{TransferFunction, logspace, nyquist, nyquist_svg};
///
/// let l = TransferFunction::continuous(&[2.0], &[1.0, 3.0, 3.0, 1.0])?;
/// let n = nyquist(&l, &logspace(-2.0, 2.0, 400)?)?;
/// let path = std::env::temp_dir().join("ctrlab_nyquist_doc.svg");
/// nyquist_svg(&path, "2/(s + 1)³", &[("L", &n)])?;
/// assert!(std::fs::read_to_string(&path).unwrap().contains("<svg"));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[doc(alias = "nyquistplot")]
pub fn nyquist_svg(
    path: impl AsRef<Path>,
    title: &str,
    curves: &[(&str, &Nyquist)],
) -> Result<(), PlotError> {
    let path = path.as_ref();
    let err = |e| write_error(path, e);
    let points: Vec<Vec<(f64, f64)>> = curves.iter().map(|(_, n)| thin(&n.re, &n.im)).collect();
    let all = || points.iter().flatten();
    let (x0, x1) = range(all().map(|p| p.0).chain([-1.0]), 0.05)?;
    let (y0, y1) = range(all().flat_map(|p| [p.1, -p.1]).chain([0.0]), 0.05)?;
    let mut entries: Vec<(&str, Mark)> = curves
        .iter()
        .enumerate()
        .map(|(i, (l, _))| (*l, Mark::Line(curve_color(i).to_rgba(), 2)))
        .collect();
    entries.push(("−1", Mark::Cross(RED.to_rgba())));
    let size = crate::plot::SIZE;
    let root = SVGBackend::new(path, size).into_drawing_area();
    let plot = titled_with_legend(&root, title, &entries, FONT).map_err(err)?;
    let mut chart = linear_axes(&plot, path, ((x0, x1), (y0, y1)), ("Re G", "Im G"))?;
    for (i, p) in points.iter().enumerate() {
        let color = curve_color(i);
        chart
            .draw_series(LineSeries::new(
                p.iter().map(|&(x, y)| (x, -y)),
                color.stroke_width(1),
            ))
            .map_err(err)?;
        chart
            .draw_series(LineSeries::new(p.iter().copied(), color.stroke_width(2)))
            .map_err(err)?;
    }
    chart
        .draw_series(std::iter::once(Cross::new(
            (-1.0, 0.0),
            6,
            RED.stroke_width(2),
        )))
        .map_err(err)?;
    root.present().map_err(err)?;
    Ok(())
}

/// A chart on linear axes over `((x0, x1), (y0, y1))` in `area`, its grid
/// and tick labels (spaced by their size) drawn, the axes named.
pub(super) type LinearChart<'a, 'b> =
    ChartContext<'a, SVGBackend<'b>, Cartesian2d<Ticked<RangedCoordf64>, Ticked<RangedCoordf64>>>;

pub(super) fn linear_axes<'a, 'b>(
    area: &'a DrawingArea<SVGBackend<'b>, Shift>,
    path: &Path,
    ((x0, x1), (y0, y1)): ((f64, f64), (f64, f64)),
    (x_desc, y_desc): (&str, &str),
) -> Result<LinearChart<'a, 'b>, PlotError> {
    let err = |e| write_error(path, e);
    let (w, h) = area.dim_in_pixel();
    let xt = Ticks::linear(
        x0,
        x1,
        f64::from(w - Y_AREA - 2 * MARGIN),
        FONT,
        Along::Horizontal,
    );
    let yt = Ticks::linear(
        y0,
        y1,
        f64::from(h - X_AREA - 2 * MARGIN),
        FONT,
        Along::Vertical,
    );
    let mut chart = ChartBuilder::on(area)
        .margin(MARGIN)
        .x_label_area_size(X_AREA)
        .y_label_area_size(Y_AREA)
        .build_cartesian_2d(
            Ticked::new(RangedCoordf64::from(x0..x1), &xt),
            Ticked::new(RangedCoordf64::from(y0..y1), &yt),
        )
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc(x_desc)
        .y_desc(y_desc)
        .x_label_formatter(&|v| xt.label(*v))
        .y_label_formatter(&|v| yt.label(*v))
        .bold_line_style(BLACK.mix(0.15))
        .label_style(("sans-serif", FONT))
        .axis_desc_style(("sans-serif", 16))
        .draw()
        .map_err(err)?;
    Ok(chart)
}
