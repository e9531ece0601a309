//! Root-locus and pole-zero figures (feature `plot`), in the conventions
//! of [`crate::plot`]: SVG through plotters, a legend strip above the
//! axes, tick labels spaced by their size. Both planes are drawn with
//! equal scales on the two axes (a circle is round, an angle true) unless
//! the caller fixes the view.

use std::path::Path;

use nalgebra::Complex;
use plotters::prelude::*;

use super::pzmap::PoleZeroMap;
use super::rlocus::RootLocus;
use super::svg::{
    FONT, LinearChart, MARGIN, X_AREA, Y_AREA, curve_color, frequency_label, linear_axes, range,
};
use crate::error::Error;
use crate::plot::{Mark, PlotError, text_width, titled_with_legend, write_error};

/// A view: `((x0, x1), (y0, y1))`.
type View = ((f64, f64), (f64, f64));

/// Breakaways in dark green, crossings in red: neither is a branch
/// colour.
const BREAKAWAY: RGBColor = RGBColor(0, 100, 0);
const CROSSING: RGBColor = RGBColor(200, 0, 0);

/// Figure size, px: taller than the time plots, for a plane.
const SIZE: (u32, u32) = (960, 780);

/// The segment `a`–`b` clipped to the view (Liang–Barsky), if any of it
/// is inside.
fn clip(a: (f64, f64), b: (f64, f64), v: View) -> Option<((f64, f64), (f64, f64))> {
    let ((x0, x1), (y0, y1)) = v;
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for (p, q) in [
        (-dx, a.0 - x0),
        (dx, x1 - a.0),
        (-dy, a.1 - y0),
        (dy, y1 - a.1),
    ] {
        if p == 0.0 {
            if q < 0.0 {
                return None;
            }
        } else {
            let r = q / p;
            if p < 0.0 {
                t0 = t0.max(r);
            } else {
                t1 = t1.min(r);
            }
        }
    }
    (t0 <= t1).then_some((
        (a.0 + t0 * dx, a.1 + t0 * dy),
        (a.0 + t1 * dx, a.1 + t1 * dy),
    ))
}

/// A polyline cut to the view: the pieces inside, each a polyline.
fn clipped(points: &[(f64, f64)], v: View) -> Vec<Vec<(f64, f64)>> {
    let mut out: Vec<Vec<(f64, f64)>> = Vec::new();
    let mut open = false;
    for w in points.windows(2) {
        match clip(w[0], w[1], v) {
            Some((p, q)) => {
                if !open || out.last().and_then(|l| l.last()) != Some(&p) {
                    out.push(vec![p]);
                }
                if let Some(l) = out.last_mut() {
                    l.push(q);
                }
                open = q == w[1];
            }
            None => open = false,
        }
    }
    out
}

fn xy(p: Complex<f64>) -> (f64, f64) {
    (p.re, p.im)
}

fn inside(p: (f64, f64), v: View) -> bool {
    p.0 >= v.0.0 && p.0 <= v.0.1 && p.1 >= v.1.0 && p.1 <= v.1.1
}

/// The unit circle as a polyline.
fn unit_circle() -> Vec<(f64, f64)> {
    (0..=720)
        .map(|i| {
            let t = f64::from(i) * std::f64::consts::PI / 360.0;
            (t.cos(), t.sin())
        })
        .collect()
}

/// The view holding `points` (and the boundary's nearest part: the
/// origin for a continuous plane, the unit circle for a discrete one),
/// padded by 8 %, then widened along one axis so that a unit is as long
/// on both in a plot area of `px` pixels.
fn equal_view(points: &[(f64, f64)], discrete: bool, px: (f64, f64)) -> Result<View, Error> {
    let extra: &[(f64, f64)] = if discrete {
        &[(-1.0, -1.0), (1.0, 1.0)]
    } else {
        &[(0.0, 0.0)]
    };
    let all = || points.iter().chain(extra);
    let (x0, x1) = range(all().map(|p| p.0), 0.08)?;
    let (y0, y1) = range(all().map(|p| p.1).chain(all().map(|p| -p.1)), 0.08)?;
    let unit = ((x1 - x0) / px.0).max((y1 - y0) / px.1);
    let (cx, cy) = (0.5 * (x0 + x1), 0.5 * (y0 + y1));
    let (hx, hy) = (0.5 * unit * px.0, 0.5 * unit * px.1);
    let v = ((cx - hx, cx + hx), (cy - hy, cy + hy));
    if [v.0.0, v.0.1, v.1.0, v.1.1].iter().all(|c| c.is_finite()) {
        Ok(v)
    } else {
        Err(Error::InvalidData {
            what: "series",
            index: 0,
            reason: "the points span more than f64::MAX: no axis can hold them",
        })
    }
}

/// Draws a label at a data point: dark text on a white box, offset by
/// `(dx, dy)` px (to the left of the point for a negative `dx`).
fn label(
    chart: &mut Plane<'_, '_>,
    path: &Path,
    p: (f64, f64),
    text: &str,
    (dx, dy): (i32, i32),
) -> Result<(), PlotError> {
    // text_width bounds tick labels; prose runs narrower (measured ~0.5 em
    // in DejaVu Sans at this size), and the box should hug it.
    let w = (0.85 * text_width(text, FONT)) as i32;
    let h = (1.3 * FONT) as i32;
    let x = if dx < 0 { dx - w } else { dx };
    let font = TextStyle::from(("sans-serif", FONT).into_font());
    let element = EmptyElement::at(p)
        + Rectangle::new(
            [(x - 2, dy - 2), (x + w + 2, dy + h)],
            WHITE.mix(0.75).filled(),
        )
        + Text::new(text.to_string(), (x, dy), font);
    chart
        .draw_series(std::iter::once(element))
        .map_err(|e| write_error(path, e))?;
    Ok(())
}

/// The plane's axis names.
fn axis_names(discrete: bool) -> (&'static str, &'static str) {
    if discrete {
        ("Re z", "Im z")
    } else {
        ("Re s (rad/s)", "Im s (rad/s)")
    }
}

type Plane<'a, 'b> = LinearChart<'a, 'b>;

/// The axes, the real axis and the stability boundary (the imaginary axis
/// or the unit circle) in `area` over `view`.
fn plane<'a, 'b>(
    area: &'a DrawingArea<SVGBackend<'b>, plotters::coord::Shift>,
    path: &Path,
    view: View,
    discrete: bool,
) -> Result<Plane<'a, 'b>, PlotError> {
    let err = |e| write_error(path, e);
    let ((x0, x1), (y0, y1)) = view;
    let mut chart = linear_axes(area, path, view, axis_names(discrete))?;
    let real_axis = clipped(&[(x0, 0.0), (x1, 0.0)], view);
    let boundary = if discrete {
        clipped(&unit_circle(), view)
    } else {
        clipped(&[(0.0, y0), (0.0, y1)], view)
    };
    for piece in real_axis {
        chart
            .draw_series(LineSeries::new(piece, BLACK.mix(0.35).stroke_width(1)))
            .map_err(err)?;
    }
    for piece in boundary {
        chart
            .draw_series(LineSeries::new(piece, BLACK.mix(0.8).stroke_width(2)))
            .map_err(err)?;
    }
    Ok(chart)
}

/// Writes a root-locus figure to an SVG file: each branch in its own
/// colour, the open-loop poles (×) and zeros (○), the asymptotes (faint,
/// dashed, from the centroid), the breakaway points and the crossings of
/// the stability boundary (the imaginary axis, or the unit circle for a
/// discrete loop) labelled with their gains, and the gains in `marks`
/// (`(label, k)`: e.g. `("Kf3 = 10", 10.0)`) as dots on every branch,
/// labelled once at the pole highest in the plane. Equal scales on both
/// axes; the view holds the poles, zeros, special points and the branches
/// within the locus' region (see [`root_locus`](super::root_locus)).
///
/// # Errors
///
/// [`PlotError::Data`] with [`Error::InvalidParameter`] for a non-finite
/// mark, with [`Error::InvalidData`] if the points span more than
/// `f64::MAX`, or the errors of [`RootLocus::poles_at_gain`] at a mark;
/// [`PlotError::Write`] if the file cannot be written.
///
/// # Examples
///
/// ```
/// use ctrlab::freq::{TransferFunction, root_locus, root_locus_svg};
///
/// let l = TransferFunction::continuous(&[1.0], &[1.0, 6.0, 11.0, 6.0])?;
/// let locus = root_locus(&l)?;
/// let path = std::env::temp_dir().join("ctrlab_rlocus_doc.svg");
/// root_locus_svg(&path, "1 / ((s+1)(s+2)(s+3))", &locus, &[("k = 10", 10.0)])?;
/// let svg = std::fs::read_to_string(&path).unwrap();
/// assert!(svg.contains("k = 60") && svg.contains("Im s (rad/s)"));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[doc(alias = "rlocus")]
#[doc(alias = "root_locus_plot")]
pub fn root_locus_svg(
    path: impl AsRef<Path>,
    title: &str,
    locus: &RootLocus,
    marks: &[(&str, f64)],
) -> Result<(), PlotError> {
    draw_locus(path.as_ref(), title, locus, marks, None)
}

/// [`root_locus_svg`] over a fixed view, `x = (x0, x1)` and
/// `y = (y0, y1)` (python-control's `xlim`, `ylim`), each drawn as given
/// (the scales may then differ): for a detail, such as a sampled loop's
/// poles near `z = 1`.
///
/// # Errors
///
/// As [`root_locus_svg`]; [`Error::InvalidParameter`] (`"x"` or `"y"`)
/// for a limit that is not finite or a range that is empty.
///
/// # Examples
///
/// ```
/// use ctrlab::freq::{TransferFunction, root_locus, root_locus_zoomed_svg};
///
/// let l = TransferFunction::discrete(&[0.25], &[1.0, -1.5, 0.5], 0.1)?;
/// let path = std::env::temp_dir().join("ctrlab_rlocus_zoom_doc.svg");
/// root_locus_zoomed_svg(&path, "detail", &root_locus(&l)?, &[], (0.4, 1.1), (-0.7, 0.7))?;
/// assert!(std::fs::read_to_string(&path).unwrap().contains("Re z"));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn root_locus_zoomed_svg(
    path: impl AsRef<Path>,
    title: &str,
    locus: &RootLocus,
    marks: &[(&str, f64)],
    x: (f64, f64),
    y: (f64, f64),
) -> Result<(), PlotError> {
    for (name, (lo, hi)) in [("x", x), ("y", y)] {
        if !(lo.is_finite() && hi.is_finite() && lo < hi && (hi - lo).is_finite()) {
            return Err(PlotError::Data(Error::InvalidParameter {
                name,
                value: if lo.is_finite() { hi } else { lo },
                reason: "a view's limits must be finite, the first below the second",
            }));
        }
    }
    draw_locus(path.as_ref(), title, locus, marks, Some((x, y)))
}

fn draw_locus(
    path: &Path,
    title: &str,
    locus: &RootLocus,
    marks: &[(&str, f64)],
    fixed: Option<View>,
) -> Result<(), PlotError> {
    let err = |e| write_error(path, e);
    let discrete = locus.period.is_some();
    let mut at_marks = Vec::with_capacity(marks.len());
    for &(_, k) in marks {
        at_marks.push(locus.poles_at_gain(k)?);
    }
    let region = locus.region();
    let in_scope = |p: Complex<f64>| match fixed {
        Some(v) => inside(xy(p), v),
        None => (p - region.0).norm() <= 1.5 * region.1,
    };
    let mut entries: Vec<(String, Mark)> = vec![
        ("branches".into(), Mark::Line(curve_color(0).to_rgba(), 2)),
        ("open-loop poles".into(), Mark::Cross(BLACK.to_rgba())),
    ];
    if !locus.zeros.is_empty() {
        entries.push(("open-loop zeros".into(), Mark::Circle(BLACK.to_rgba())));
    }
    if locus.asymptotes.is_some() {
        entries.push(("asymptotes".into(), Mark::Dashed(BLACK.mix(0.4))));
    }
    if locus.breakaways.iter().any(|b| in_scope(b.point)) {
        entries.push(("breakaway (gain)".into(), Mark::Dot(BREAKAWAY.to_rgba())));
    }
    if locus.crossings.iter().any(|c| in_scope(c.point)) {
        let what = if discrete {
            "unit circle"
        } else {
            "imaginary axis"
        };
        entries.push((
            format!("crosses the {what} (gain)"),
            Mark::Dot(CROSSING.to_rgba()),
        ));
    }
    if !marks.is_empty() {
        entries.push(("gains marked".into(), Mark::Dot(BLACK.to_rgba())));
    }
    let entries: Vec<(&str, Mark)> = entries.iter().map(|(s, m)| (s.as_str(), *m)).collect();
    let root = SVGBackend::new(path, SIZE).into_drawing_area();
    let area = titled_with_legend(&root, title, &entries, FONT).map_err(err)?;
    let view = match fixed {
        Some(v) => v,
        None => {
            let (centre, radius) = region;
            let mut pts: Vec<(f64, f64)> = locus
                .branches
                .iter()
                .flatten()
                .filter(|p| (*p - centre).norm() <= 1.5 * radius)
                .map(|p| xy(*p))
                .collect();
            pts.extend(locus.poles.iter().chain(&locus.zeros).map(|p| xy(*p)));
            pts.extend(at_marks.iter().flatten().map(|p| xy(*p)));
            let (w, h) = area.dim_in_pixel();
            let px = (
                f64::from(w - Y_AREA - 2 * MARGIN),
                f64::from(h - X_AREA - 2 * MARGIN),
            );
            equal_view(&pts, discrete, px)?
        }
    };
    let mut chart = plane(&area, path, view, discrete)?;
    if let Some(a) = &locus.asymptotes {
        let ((x0, x1), (y0, y1)) = view;
        let reach = 2.0 * ((x1 - x0).abs() + (y1 - y0).abs() + (a.centroid - x0).abs());
        for &t in &a.angles {
            let end = (a.centroid + reach * t.cos(), reach * t.sin());
            for piece in clipped(&[(a.centroid, 0.0), end], view) {
                chart
                    .draw_series(DashedLineSeries::new(
                        piece,
                        7,
                        5,
                        BLACK.mix(0.4).stroke_width(1),
                    ))
                    .map_err(err)?;
            }
        }
    }
    // A step between two points both outside the locus' region is not
    // drawn: it is where a branch goes through infinity (a biproper loop
    // at d₀ + k n₀ = 0), and its chord would cross the plane.
    let near = |p: &Complex<f64>| (p - region.0).norm() <= 1.5 * region.1;
    for (i, b) in locus.branches.iter().enumerate() {
        let mut runs: Vec<Vec<(f64, f64)>> = vec![Vec::new()];
        for (j, p) in b.iter().enumerate() {
            if j > 0 && !near(p) && !near(&b[j - 1]) {
                runs.push(Vec::new());
            }
            if let Some(run) = runs.last_mut() {
                run.push(xy(*p));
            }
        }
        for piece in runs.iter().flat_map(|r| clipped(r, view)) {
            let style = curve_color(i).stroke_width(2);
            chart
                .draw_series(LineSeries::new(piece, style))
                .map_err(err)?;
        }
    }
    let shown = |p: &Complex<f64>| inside(xy(*p), view);
    let cross = |p: &Complex<f64>| Cross::new(xy(*p), 7, BLACK.stroke_width(2));
    chart
        .draw_series(locus.poles.iter().filter(|p| shown(p)).map(cross))
        .map_err(err)?;
    let ring = |p: &Complex<f64>| Circle::new(xy(*p), 6, BLACK.stroke_width(2));
    chart
        .draw_series(locus.zeros.iter().filter(|p| shown(p)).map(ring))
        .map_err(err)?;
    for (k, (&(text, _), poles)) in marks.iter().zip(&at_marks).enumerate() {
        let dot = |p: &Complex<f64>| Circle::new(xy(*p), 4, BLACK.filled());
        chart
            .draw_series(poles.iter().filter(|p| shown(p)).map(dot))
            .map_err(err)?;
        // Labelled at each pole in the upper half-plane (its mirror image
        // is the same pole), or at the highest if all are real.
        let scale = poles.iter().map(|p| p.norm()).fold(0.0, f64::max);
        let mut at: Vec<&Complex<f64>> = poles
            .iter()
            .filter(|p| shown(p) && p.im > 1e-9 * scale)
            .collect();
        if at.is_empty() {
            at.extend(
                poles
                    .iter()
                    .filter(|p| shown(p))
                    .max_by(|a, b| a.im.total_cmp(&b.im).then(a.re.total_cmp(&b.re))),
            );
        }
        let dx = if k % 2 == 0 { 8 } else { -8 };
        for p in at {
            label(&mut chart, path, xy(*p), text, (dx, -8))?;
        }
    }
    for b in locus.breakaways.iter().filter(|b| shown(&b.point)) {
        let p = xy(b.point);
        chart
            .draw_series([Circle::new(p, 5, BREAKAWAY.filled())])
            .map_err(err)?;
        let text = format!("k = {}", frequency_label(b.gain));
        label(&mut chart, path, p, &text, (6, 6))?;
    }
    for c in &locus.crossings {
        for (i, p) in [c.point, c.point.conj()].iter().enumerate() {
            if !shown(p) || (i == 1 && c.point.im == 0.0) {
                continue;
            }
            chart
                .draw_series([Circle::new(xy(*p), 5, CROSSING.filled())])
                .map_err(err)?;
            if i == 0 {
                let text = format!(
                    "k = {}, ω = {} rad/s",
                    frequency_label(c.gain),
                    frequency_label(c.frequency)
                );
                label(&mut chart, path, xy(*p), &text, (8, 4))?;
            }
        }
    }
    root.present().map_err(err)?;
    Ok(())
}

/// Writes a pole-zero map to an SVG file (MATLAB's and python-control's
/// `pzmap` figure): each model's poles (×) and zeros (○) in its own
/// colour, the stability boundary (the imaginary axis, or the unit circle
/// for discrete maps) and equal scales on both axes. The first map's
/// domain names the axes.
///
/// # Errors
///
/// [`PlotError::Data`] with [`Error::InvalidData`] for no map or no
/// finite point; [`PlotError::Write`] if the file cannot be written.
///
/// # Examples
///
/// ```
/// use ctrlab::{Cart, MassSpring};
/// use ctrlab::freq::{pole_zero_map, pole_zero_svg};
///
/// let plant = MassSpring::nominal().state_space(Cart::Two)?;
/// let path = std::env::temp_dir().join("ctrlab_pzmap_doc.svg");
/// pole_zero_svg(&path, "Two-cart plant", &[("force to x2", &pole_zero_map(&plant)?)])?;
/// assert!(std::fs::read_to_string(&path).unwrap().contains("force to x2: poles"));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[doc(alias = "pzmap")]
#[doc(alias = "pzplot")]
pub fn pole_zero_svg(
    path: impl AsRef<Path>,
    title: &str,
    maps: &[(&str, &PoleZeroMap)],
) -> Result<(), PlotError> {
    let path = path.as_ref();
    let err = |e| write_error(path, e);
    let Some(first) = maps.first() else {
        return Err(PlotError::Data(Error::InvalidData {
            what: "maps",
            index: 0,
            reason: "no pole-zero map to draw",
        }));
    };
    let discrete = first.1.period.is_some();
    let mut names = Vec::new();
    for (i, (l, m)) in maps.iter().enumerate() {
        let c = curve_color(i).to_rgba();
        names.push((format!("{l}: poles"), Mark::Cross(c)));
        if !m.zeros.is_empty() {
            names.push((format!("{l}: zeros"), Mark::Circle(c)));
        }
    }
    let entries: Vec<(&str, Mark)> = names.iter().map(|(s, m)| (s.as_str(), *m)).collect();
    let root = SVGBackend::new(path, SIZE).into_drawing_area();
    let area = titled_with_legend(&root, title, &entries, FONT).map_err(err)?;
    let pts: Vec<(f64, f64)> = maps
        .iter()
        .flat_map(|(_, m)| m.poles.iter().chain(&m.zeros).map(|p| xy(*p)))
        .filter(|p| p.0.is_finite() && p.1.is_finite())
        .collect();
    let (w, h) = area.dim_in_pixel();
    let px = (
        f64::from(w - Y_AREA - 2 * MARGIN),
        f64::from(h - X_AREA - 2 * MARGIN),
    );
    let view = equal_view(&pts, discrete, px)?;
    let mut chart = plane(&area, path, view, discrete)?;
    for (i, (_, m)) in maps.iter().enumerate() {
        let c = curve_color(i);
        let cross = |p: &Complex<f64>| Cross::new(xy(*p), 7, c.stroke_width(2));
        chart.draw_series(m.poles.iter().map(cross)).map_err(err)?;
        let ring = |p: &Complex<f64>| Circle::new(xy(*p), 6, c.stroke_width(2));
        chart.draw_series(m.zeros.iter().map(ring)).map_err(err)?;
    }
    root.present().map_err(err)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clipping_keeps_the_inside() {
        let v = ((0.0, 1.0), (0.0, 1.0));
        assert_eq!(
            clip((-1.0, 0.5), (2.0, 0.5), v),
            Some(((0.0, 0.5), (1.0, 0.5)))
        );
        assert_eq!(clip((-1.0, 2.0), (-0.5, 3.0), v), None);
        let pieces = clipped(&[(0.5, 0.5), (2.0, 0.5), (0.5, 0.6)], v);
        assert_eq!(pieces.len(), 2);
    }
}
