//! SVG figures of time responses (feature `plot`).
//!
//! One small, general entry point, [`responses_svg`]: any number of labelled
//! `(t, y)` series on one pair of axes, written as an SVG file. Built on
//! `plotters` with only its SVG backend, so it needs no system fonts or
//! libraries.
//!
//! # Examples
//!
//! ```
//! use ctrlab::plot::{Series, responses_svg};
//!
//! let t: Vec<f64> = (0..100).map(|k| k as f64 * 0.01).collect();
//! let y: Vec<f64> = t.iter().map(|t| 1.0 - (-t / 0.2f64).exp()).collect();
//! let path = std::env::temp_dir().join("ctrlab_plot_doc.svg");
//! responses_svg(&path, "First order", "t (s)", "y", &[Series::new("τ = 0.2 s", &t, &y)])?;
//! assert!(std::fs::read_to_string(&path).unwrap().contains("<svg"));
//! # Ok::<(), ctrlab::plot::PlotError>(())
//! ```

use std::path::{Path, PathBuf};

use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;

mod legend;
mod ticks;

pub(crate) use legend::{Mark, titled_with_legend};
pub use ticks::{Along, Ticks};
pub(crate) use ticks::{Ticked, text_width};

use crate::error::Error;

/// Why a figure was not written: data that cannot be drawn (a numeric
/// [`Error`]), or the file (the backend's error, kept as the source).
///
/// # Examples
///
/// ```
/// use ctrlab::plot::{PlotError, PlotErrorKind, Series, responses_svg};
///
/// let dir = std::env::temp_dir().join("ctrlab_plot_error_doc");
/// std::fs::create_dir_all(&dir)?;
/// // A directory is not a file: the write fails, and says where.
/// let err = responses_svg(&dir, "t", "t (s)", "y", &[Series::new("y", &[0.0, 1.0], &[0.0, 1.0])])
///     .unwrap_err();
/// assert_eq!(err.kind(), PlotErrorKind::Write);
/// assert!(err.to_string().contains("ctrlab_plot_error_doc"));
/// assert!(std::error::Error::source(&err).is_some());
/// // Nothing finite to draw is the data's fault.
/// let err = responses_svg(dir.join("nan.svg"), "t", "t (s)", "y", &[Series::new("y", &[f64::NAN], &[0.0])])
///     .unwrap_err();
/// assert_eq!(err.kind(), PlotErrorKind::Data);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum PlotError {
    /// The data cannot be drawn (no finite point, lengths that differ, a
    /// range no axis can hold).
    #[error(transparent)]
    Data(#[from] Error),
    /// Writing the figure failed.
    #[error("cannot write figure {}: {source}", path.display())]
    Write {
        /// The file being written.
        path: PathBuf,
        /// The drawing backend's error (an I/O error underneath).
        #[source]
        source: Box<dyn std::error::Error + Send + Sync>,
    },
}

/// The category of a [`PlotError`].
///
/// # Examples
///
/// ```
/// use ctrlab::plot::{PlotError, PlotErrorKind};
/// let e = PlotError::from(ctrlab::Error::Singular { operation: "x" });
/// assert_eq!(e.kind(), PlotErrorKind::Data);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum PlotErrorKind {
    /// [`PlotError::Data`].
    Data,
    /// [`PlotError::Write`].
    Write,
}

impl PlotError {
    /// What kind of failure this is.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::plot::{PlotError, PlotErrorKind};
    /// let e = PlotError::from(ctrlab::Error::Singular { operation: "x" });
    /// assert_eq!(e.kind(), PlotErrorKind::Data);
    /// ```
    pub fn kind(&self) -> PlotErrorKind {
        match self {
            PlotError::Data(_) => PlotErrorKind::Data,
            PlotError::Write { .. } => PlotErrorKind::Write,
        }
    }
}

/// A [`PlotError::Write`] for `path` from the backend's error.
pub(crate) fn write_error<E>(path: &Path, source: E) -> PlotError
where
    E: std::error::Error + Send + Sync + 'static,
{
    PlotError::Write {
        path: path.to_path_buf(),
        source: Box::new(source),
    }
}

/// Figure size in pixels.
pub(crate) const SIZE: (u32, u32) = (960, 600);
/// Points drawn per series at most; longer series are thinned to every k-th
/// sample, which keeps files small and is invisible at this size.
///
/// # Examples
///
/// ```
/// // A 20 s record at 0.5 ms (40 001 samples) is drawn through every 21st.
/// assert_eq!(40_001usize.div_ceil(ctrlab::plot::MAX_POINTS), 21);
/// ```
pub const MAX_POINTS: usize = 2000;

/// One labelled curve: `y` against `t`, equal lengths, any units.
///
/// # Examples
///
/// ```
/// use ctrlab::plot::Series;
///
/// let s = Series::new("x2", &[0.0, 1.0], &[0.0, 0.5]);
/// assert_eq!(s.label, "x2");
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Series<'a> {
    /// Legend entry.
    pub label: &'a str,
    /// Abscissae (usually time, s).
    pub t: &'a [f64],
    /// Ordinates, one per abscissa.
    pub y: &'a [f64],
}

impl<'a> Series<'a> {
    /// A series from its label and data.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::plot::Series;
    ///
    /// let s = Series::new("cart 2", &[0.0, 0.1], &[0.0, 30.0]);
    /// assert_eq!(s.y[1], 30.0);
    /// ```
    pub fn new(label: &'a str, t: &'a [f64], y: &'a [f64]) -> Self {
        Self { label, t, y }
    }
}

/// An axis range that holds `[lo, hi]` (finite, `lo ≤ hi`) and that the
/// tick search can work with: padded by `pad` of the span on each side,
/// at least `1e-9` of the values' magnitude (and 1e-250) wide, so that a
/// constant or nearly constant series still has ticks to find, and at most
/// `f64::MAX` wide, so that its width is a number. `None` when the points
/// themselves span more than `f64::MAX`.
pub(crate) fn axis(lo: f64, hi: f64, pad: f64) -> Option<(f64, f64)> {
    let span = hi - lo;
    if !span.is_finite() {
        return None;
    }
    let min_span = (1e-9 * lo.abs().max(hi.abs())).max(1e-250);
    let (lo, hi, span) = if span < min_span {
        let centre = 0.5 * lo + 0.5 * hi;
        (centre - 0.5 * min_span, centre + 0.5 * min_span, min_span)
    } else {
        (lo, hi, span)
    };
    let pad = (pad * span).min(0.5 * (f64::MAX - span));
    Some(((lo - pad).max(-f64::MAX), (hi + pad).min(f64::MAX)))
}

/// Writes every series on one pair of axes to an SVG file at `path`, with a
/// title, axis labels and a legend. Axis ranges cover all finite points;
/// non-finite points are skipped; a series longer than [`MAX_POINTS`] is
/// drawn through every k-th sample (and its last).
///
/// # Errors
///
/// [`PlotError::Data`] with [`Error::LengthMismatch`] if a series' `t` and
/// `y` differ in length, with [`Error::InvalidData`] if there is no finite
/// point at all, or the points span more than `f64::MAX` (`y` from −1e308
/// to 1e308); [`PlotError::Write`] if the file cannot be written.
///
/// # Examples
///
/// ```
/// use ctrlab::{Error, plot::{PlotError, Series, responses_svg}};
///
/// let path = std::env::temp_dir().join("ctrlab_plot_mismatch.svg");
/// let err = responses_svg(&path, "bad", "t", "y", &[Series::new("s", &[0.0, 1.0], &[0.0])]).unwrap_err();
/// assert!(matches!(err, PlotError::Data(Error::LengthMismatch { .. })));
/// ```
pub fn responses_svg(
    path: impl AsRef<Path>,
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[Series<'_>],
) -> Result<(), PlotError> {
    responses_with_references_svg(path, title, (x_label, y_label), series, &[])
}

/// A labelled horizontal line across a figure (a setpoint, a limit), drawn
/// dashed in black; its value is kept inside the y axis.
///
/// # Examples
///
/// ```
/// use ctrlab::plot::Reference;
///
/// let r = Reference::new("setpoint 30 mm", 30.0);
/// assert_eq!(r.y, 30.0);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Reference<'a> {
    /// Legend entry.
    pub label: &'a str,
    /// The line's ordinate, in the series' units.
    pub y: f64,
}

impl<'a> Reference<'a> {
    /// A reference line from its label and ordinate.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::plot::Reference;
    /// assert_eq!(Reference::new("limit", 24.0).label, "limit");
    /// ```
    pub fn new(label: &'a str, y: f64) -> Self {
        Self { label, y }
    }
}

/// Curve colours: Okabe–Ito, distinguishable by colour-blind readers
/// (plotters' Palette99 has a yellow that vanishes on white).
pub(crate) const PALETTE: [RGBColor; 7] = [
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(230, 159, 0),
    RGBColor(86, 180, 233),
    RGBColor(0, 0, 0),
];

/// Label font size, px (plotters' size; the SVG says / 1.24).
const LABEL_FONT: f64 = 14.0;
/// The y axis' label area and the right margin, px.
const Y_AREA: u32 = 72;
const MARGIN: u32 = 12;

/// [`responses_svg`] with reference lines (a setpoint, a limit) dashed
/// across the axes, each with its own legend entry. The legend is a strip
/// between the title and the axes, one entry per curve, so it covers no
/// data; tick labels are spaced by their size ([`Ticks`]), so none
/// collide.
///
/// # Errors
///
/// As [`responses_svg`]; a non-finite reference is [`Error::InvalidData`].
///
/// # Examples
///
/// ```
/// use ctrlab::plot::{Reference, Series, responses_with_references_svg};
///
/// let t: Vec<f64> = (0..300).map(|k| k as f64 * 0.01).collect();
/// let x: Vec<f64> = t.iter().map(|t| 28.5 * (1.0 - (-t / 0.1f64).exp())).collect();
/// let path = std::env::temp_dir().join("ctrlab_plot_reference_doc.svg");
/// responses_with_references_svg(
///     &path,
///     "Cart 2",
///     ("t (s)", "x2 (mm)"),
///     &[Series::new("Kf = [0 0 10 0.5]", &t, &x)],
///     &[Reference::new("setpoint 30 mm", 30.0)],
/// )?;
/// assert!(std::fs::read_to_string(&path).unwrap().contains("setpoint 30 mm"));
/// # Ok::<(), ctrlab::plot::PlotError>(())
/// ```
pub fn responses_with_references_svg(
    path: impl AsRef<Path>,
    title: &str,
    (x_label, y_label): (&str, &str),
    series: &[Series<'_>],
    references: &[Reference<'_>],
) -> Result<(), PlotError> {
    let path = path.as_ref();
    let (mut x0, mut x1, mut y0, mut y1) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    for s in series {
        if s.t.len() != s.y.len() {
            return Err(PlotError::Data(Error::LengthMismatch {
                what: "series y",
                expected: s.t.len(),
                found: s.y.len(),
            }));
        }
        for (&t, &y) in s.t.iter().zip(s.y) {
            if t.is_finite() && y.is_finite() {
                x0 = x0.min(t);
                x1 = x1.max(t);
                y0 = y0.min(y);
                y1 = y1.max(y);
            }
        }
    }
    if !(x0.is_finite() && y0.is_finite()) {
        return Err(PlotError::Data(Error::InvalidData {
            what: "series",
            index: 0,
            reason: "no finite point to plot",
        }));
    }
    for (index, r) in references.iter().enumerate() {
        if !r.y.is_finite() {
            return Err(PlotError::Data(Error::InvalidData {
                what: "reference",
                index,
                reason: "not finite",
            }));
        }
        y0 = y0.min(r.y);
        y1 = y1.max(r.y);
    }
    let too_wide = |what| Error::InvalidData {
        what,
        index: 0,
        reason: "the points span more than f64::MAX: no axis can hold them",
    };
    let (x0, x1) = axis(x0, x1, 0.0).ok_or_else(|| too_wide("series t"))?;
    let (y0, y1) = axis(y0, y1, 0.05).ok_or_else(|| too_wide("series y"))?;

    let colors: Vec<RGBAColor> = (0..series.len())
        .map(|i| PALETTE[i % PALETTE.len()].to_rgba())
        .collect();
    let mut entries: Vec<(&str, Mark)> = series
        .iter()
        .zip(&colors)
        .map(|(s, &c)| (s.label, Mark::Line(c, 2)))
        .collect();
    entries.extend(
        references
            .iter()
            .map(|r| (r.label, Mark::Dashed(BLACK.to_rgba()))),
    );
    let plot_err = |e| write_error(path, e);
    let root = SVGBackend::new(path, SIZE).into_drawing_area();
    let plot = titled_with_legend(&root, title, &entries, LABEL_FONT).map_err(plot_err)?;
    let (w, h) = plot.dim_in_pixel();
    let xt = Ticks::linear(
        x0,
        x1,
        f64::from(w - Y_AREA - 2 * MARGIN),
        LABEL_FONT,
        Along::Horizontal,
    );
    let yt = Ticks::linear(
        y0,
        y1,
        f64::from(h - 44 - 2 * MARGIN),
        LABEL_FONT,
        Along::Vertical,
    );
    let mut chart = ChartBuilder::on(&plot)
        .margin(MARGIN)
        .x_label_area_size(44)
        .y_label_area_size(Y_AREA)
        .build_cartesian_2d(
            Ticked::new(RangedCoordf64::from(x0..x1), &xt),
            Ticked::new(RangedCoordf64::from(y0..y1), &yt),
        )
        .map_err(plot_err)?;
    chart
        .configure_mesh()
        .x_desc(x_label)
        .y_desc(y_label)
        .x_label_formatter(&|v| xt.label(*v))
        .y_label_formatter(&|v| yt.label(*v))
        .bold_line_style(BLACK.mix(0.12))
        .label_style(("sans-serif", LABEL_FONT))
        .axis_desc_style(("sans-serif", 16))
        .draw()
        .map_err(plot_err)?;
    for (s, &color) in series.iter().zip(&colors) {
        // Every k-th sample (and the last), at most MAX_POINTS per series.
        let stride = s.t.len().div_ceil(MAX_POINTS).max(1);
        let last = s.t.len().saturating_sub(1);
        let points =
            s.t.iter()
                .zip(s.y)
                .enumerate()
                .filter(move |(i, _)| i % stride == 0 || *i == last)
                .map(|(_, p)| p)
                .filter(|(t, y)| t.is_finite() && y.is_finite())
                .map(|(&t, &y)| (t, y));
        chart
            .draw_series(LineSeries::new(points, color.stroke_width(2)))
            .map_err(plot_err)?;
    }
    // The references on top: a setpoint under six curves must still show.
    for r in references {
        chart
            .draw_series(DashedLineSeries::new(
                [(x0, r.y), (x1, r.y)],
                8,
                5,
                BLACK.stroke_width(2),
            ))
            .map_err(plot_err)?;
    }
    root.present().map_err(plot_err)?;
    Ok(())
}
