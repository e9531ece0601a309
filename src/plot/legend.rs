//! The crate's legends: a strip of entries between the title and the
//! axes, one entry per drawn curve, so that no legend covers data (a box
//! inside the axes always covers some figure's curves).

use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::ticks::text_width;

/// How an entry's curve is drawn.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Mark {
    /// A solid line of this colour and width (px).
    Line(RGBAColor, u32),
    /// A dashed line of this colour.
    Dashed(RGBAColor),
    /// A cross (a marked point).
    Cross(RGBAColor),
    /// A hollow circle (a zero).
    Circle(RGBAColor),
    /// A filled dot (a point on a curve).
    Dot(RGBAColor),
}

/// Swatch length and the gap before its label, px.
const SWATCH: i32 = 24;
const GAP: i32 = 6;
/// Space between entries, px.
const SPACING: f64 = 22.0;

/// Rows of a strip `width_px` wide: entries flow left to right.
fn rows(entries: &[(&str, Mark)], width_px: f64, font_px: f64) -> Vec<Vec<(i32, usize)>> {
    let mut rows: Vec<Vec<(i32, usize)>> = vec![Vec::new()];
    let mut x = 0.0;
    for (i, (label, _)) in entries.iter().enumerate() {
        let w = f64::from(SWATCH + GAP) + text_width(label, font_px);
        if x > 0.0 && x + w > width_px {
            rows.push(Vec::new());
            x = 0.0;
        }
        if let Some(r) = rows.last_mut() {
            r.push((x as i32, i));
        }
        x += w + SPACING;
    }
    rows
}

/// The height (px) a strip of `entries` needs in `width_px`.
pub(crate) fn strip_height(entries: &[(&str, Mark)], width_px: u32, font_px: f64) -> u32 {
    if entries.is_empty() {
        return 0;
    }
    let n = rows(entries, f64::from(width_px) - 20.0, font_px).len();
    (n as f64 * 1.6 * font_px + 0.6 * font_px).ceil() as u32
}

/// Fills `root` white, writes `title` across its top and draws the legend
/// strip of `entries` under it; returns the area left for the axes
/// (`root` is still the one to `present`).
pub(crate) fn titled_with_legend<DB: DrawingBackend>(
    root: &DrawingArea<DB, plotters::coord::Shift>,
    title: &str,
    entries: &[(&str, Mark)],
    font_px: f64,
) -> Result<DrawingArea<DB, plotters::coord::Shift>, DrawingAreaErrorKind<DB::ErrorType>> {
    root.fill(&WHITE)?;
    let width = root.dim_in_pixel().0;
    let root = root.titled(title, ("sans-serif", 22))?;
    let (legend, plot) = root.split_vertically(strip_height(entries, width, font_px));
    draw_strip(&legend, entries, font_px)?;
    Ok(plot)
}

/// Draws the strip in `area` (as tall as [`strip_height`]), entries
/// centred row by row.
pub(crate) fn draw_strip<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    entries: &[(&str, Mark)],
    font_px: f64,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let width = f64::from(area.dim_in_pixel().0);
    let style = TextStyle::from(("sans-serif", font_px).into_font())
        .pos(Pos::new(HPos::Left, VPos::Center));
    for (r, row) in rows(entries, width - 20.0, font_px).iter().enumerate() {
        let used = row.last().map_or(0.0, |&(x, i)| {
            f64::from(x + SWATCH + GAP) + text_width(entries[i].0, font_px)
        });
        let left = ((width - used) / 2.0).max(10.0) as i32;
        let y = (0.3 * font_px + (r as f64 + 0.5) * 1.6 * font_px) as i32;
        for &(x, i) in row {
            let (label, mark) = entries[i];
            let x = left + x;
            match mark {
                Mark::Line(c, w) => area.draw(&PathElement::new(
                    [(x, y), (x + SWATCH, y)],
                    c.stroke_width(w),
                ))?,
                Mark::Dashed(c) => {
                    for k in 0..3 {
                        let a = x + k * 9;
                        area.draw(&PathElement::new([(a, y), (a + 6, y)], c.stroke_width(2)))?;
                    }
                }
                Mark::Cross(c) => {
                    area.draw(&Cross::new((x + SWATCH / 2, y), 5, c.stroke_width(2)))?
                }
                Mark::Circle(c) => {
                    area.draw(&Circle::new((x + SWATCH / 2, y), 5, c.stroke_width(2)))?
                }
                Mark::Dot(c) => area.draw(&Circle::new((x + SWATCH / 2, y), 4, c.filled()))?,
            }
            area.draw(&Text::new(label, (x + SWATCH + GAP, y), style.clone()))?;
        }
    }
    Ok(())
}
