//! Bode and Nyquist figures (feature `plot`), in the conventions of
//! [`crate::plot`]: SVG through plotters, axes covering every finite point,
//! non-finite points skipped.

use std::f64::consts::PI;
use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

use super::response::{Bode, Nyquist};
use crate::error::Error;
use crate::plot::{MAX_POINTS, PlotError, axis, write_error};

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
fn range(values: impl Iterator<Item = f64>, pad: f64) -> Result<(f64, f64), Error> {
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

fn panel(
    area: &DrawingArea<SVGBackend<'_>, Shift>,
    path: &Path,
    caption: Option<&str>,
    (x0, x1): (f64, f64),
    y_label: &str,
    x_label: &str,
    curves: &[(&str, Vec<(f64, f64)>)],
) -> Result<(), PlotError> {
    let err = |e| write_error(path, e);
    let (y0, y1) = range(curves.iter().flat_map(|(_, p)| p.iter().map(|q| q.1)), 0.05)?;
    let mut builder = ChartBuilder::on(area);
    if let Some(c) = caption {
        builder.caption(c, ("sans-serif", 22));
    }
    let mut chart = builder
        .margin(12)
        .x_label_area_size(44)
        .y_label_area_size(64)
        .build_cartesian_2d((x0..x1).log_scale(), y0..y1)
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc(x_label)
        .y_desc(y_label)
        .label_style(("sans-serif", 14))
        .axis_desc_style(("sans-serif", 16))
        .draw()
        .map_err(err)?;
    for (i, (label, points)) in curves.iter().enumerate() {
        let color = Palette99::pick(i).to_rgba();
        chart
            .draw_series(LineSeries::new(
                points.iter().copied(),
                color.stroke_width(2),
            ))
            .map_err(err)?
            .label(*label)
            .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], color.stroke_width(2)));
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 14))
        .position(SeriesLabelPosition::LowerLeft)
        .draw()
        .map_err(err)?;
    Ok(())
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
    let (x0, x1) = range(mag.iter().flat_map(|(_, p)| p.iter().map(|q| q.0)), 0.0)?;
    let x0 = if x0 > 0.0 { x0 } else { x1 / 10.0 };
    let root = SVGBackend::new(path, (960, 800)).into_drawing_area();
    let err = |e| write_error(path, e);
    root.fill(&WHITE).map_err(err)?;
    let (top, bottom) = root.split_vertically(400);
    panel(
        &top,
        path,
        Some(title),
        (x0, x1),
        "magnitude (dB)",
        unit.label(),
        &mag,
    )?;
    panel(
        &bottom,
        path,
        None,
        (x0, x1),
        "phase (deg)",
        unit.label(),
        &phase,
    )?;
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
    let root = SVGBackend::new(path, crate::plot::SIZE).into_drawing_area();
    root.fill(&WHITE).map_err(err)?;
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 22))
        .margin(12)
        .x_label_area_size(44)
        .y_label_area_size(64)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("Re G")
        .y_desc("Im G")
        .label_style(("sans-serif", 14))
        .axis_desc_style(("sans-serif", 16))
        .draw()
        .map_err(err)?;
    for (i, ((label, _), p)) in curves.iter().zip(&points).enumerate() {
        let color = Palette99::pick(i).to_rgba();
        chart
            .draw_series(LineSeries::new(
                p.iter().map(|&(x, y)| (x, -y)),
                color.stroke_width(1),
            ))
            .map_err(err)?;
        chart
            .draw_series(LineSeries::new(p.iter().copied(), color.stroke_width(2)))
            .map_err(err)?
            .label(*label)
            .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], color.stroke_width(2)));
    }
    chart
        .draw_series(std::iter::once(Cross::new(
            (-1.0, 0.0),
            6,
            RED.stroke_width(2),
        )))
        .map_err(err)?
        .label("−1")
        .legend(|(x, y)| Cross::new((x + 10, y), 5, RED.stroke_width(2)));
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 14))
        .position(SeriesLabelPosition::LowerRight)
        .draw()
        .map_err(err)?;
    root.present().map_err(err)?;
    Ok(())
}
