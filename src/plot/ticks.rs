//! Axis ticks whose labels cannot collide: the tick step is chosen from the
//! axis' length in pixels and the labels' own size, not from a fixed count.

/// A label's width in pixels, estimated: 0.6 of the font size per
/// character, a bound for the digits, signs and points of tick labels in
/// the sans-serif faces viewers substitute (DejaVu Sans digits are 0.64 em
/// of the SVG font size, which plotters writes as the size / 1.24).
pub(crate) fn text_width(text: &str, font_px: f64) -> f64 {
    0.6 * font_px * text.chars().count() as f64
}

/// Which way an axis runs: along it, horizontal labels need their width
/// of room, vertical ones their height.
///
/// # Examples
///
/// ```
/// use ctrlab::plot::{Along, Ticks};
///
/// // 40 px of a vertical axis at 14 px labels: room for two.
/// assert_eq!(Ticks::linear(0.0, 10.0, 40.0, 14.0, Along::Vertical).values.len(), 2);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Along {
    /// An x axis: labels side by side.
    Horizontal,
    /// A y axis: labels one above the other.
    Vertical,
}

/// Tick values of one axis and their labels, spaced so that no two labels
/// overlap: the densest 1–2–5 step (linear) or decade subdivision (log)
/// whose labels, at the given font size, fit between neighbouring ticks
/// with a gap of at least half a character.
///
/// # Examples
///
/// ```
/// use ctrlab::plot::{Along, Ticks};
///
/// // ±26.4 V on a 50 px voltage panel: three labels, not eleven.
/// let t = Ticks::linear(-26.4, 26.4, 50.0, 11.0, Along::Vertical);
/// assert_eq!(t.labels, ["-20", "0", "20"]);
/// // 3 s on 300 px: every 0.5 s, one decimal.
/// let t = Ticks::linear(0.0, 3.0, 300.0, 11.0, Along::Horizontal);
/// assert_eq!(t.labels.first().map(String::as_str), Some("0.0"));
/// assert_eq!(t.labels.len(), 7);
/// // 0.2 to 25 Hz on a log axis: 1-2-5 labels up to the top, with minor
/// // ticks at the other integers of each decade.
/// let t = Ticks::log(0.2, 25.0, 800.0, 14.0);
/// assert_eq!(t.labels, ["0.2", "0.5", "1", "2", "5", "10", "20"]);
/// assert!(t.minor.contains(&3.0));
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct Ticks {
    /// Tick values, ascending, in the axis' units.
    pub values: Vec<f64>,
    /// One label per value.
    pub labels: Vec<String>,
    /// Unlabelled minor ticks (log axes: the other integers of a decade),
    /// for a light grid; empty on linear axes.
    pub minor: Vec<f64>,
}

impl Ticks {
    /// Ticks on the linear axis `[lo, hi]` drawn `length_px` long, labels
    /// at `font_px`: multiples of the densest step 1, 2 or 5 × 10ᵏ that
    /// leaves room for every label, all with the step's decimals.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::plot::{Along, Ticks};
    ///
    /// // 150 px: a label every 22 px, where 16.5 px (1.5 lines) are needed.
    /// let t = Ticks::linear(-2.0, 31.5, 150.0, 11.0, Along::Vertical);
    /// assert_eq!(t.labels, ["0", "5", "10", "15", "20", "25", "30"]);
    /// ```
    pub fn linear(lo: f64, hi: f64, length_px: f64, font_px: f64, along: Along) -> Self {
        let span = hi - lo;
        if !(span > 0.0 && span.is_finite() && length_px > 0.0) {
            return Self::from_values(vec![lo].into_iter().filter(|v| v.is_finite()), 0);
        }
        let mut exp = (span / 100.0).log10().floor() as i32;
        loop {
            for m in [1.0, 2.0, 5.0] {
                let step = m * 10f64.powi(exp);
                let decimals = (-exp).max(0) as usize;
                let first = (lo / step - 1e-9).ceil() as i64;
                let last = (hi / step + 1e-9).floor() as i64;
                // Values as k × step, with −0 and rounding dust snapped.
                let values = (first..=last).map(|k| {
                    let v = k as f64 * step;
                    if k == 0 { 0.0 } else { v }
                });
                let ticks = Self::from_values(values, decimals);
                let room = length_px * step / span;
                let need = match along {
                    Along::Horizontal => ticks.widest(font_px) + 0.6 * font_px,
                    Along::Vertical => 1.5 * font_px,
                };
                if room >= need || ticks.values.len() <= 1 {
                    return ticks;
                }
            }
            exp += 1;
        }
    }

    /// Ticks on the logarithmic axis `[lo, hi]` (both positive) drawn
    /// `length_px` long, labels at `font_px`: 1, 2 and 5 in each decade if
    /// their labels fit, else 1 and 3, else the decades, else every
    /// second or third decade; the other integers of each decade are the
    /// minor ticks.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::plot::Ticks;
    ///
    /// let t = Ticks::log(0.01, 100.0, 300.0, 14.0);
    /// assert_eq!(t.labels, ["0.01", "0.1", "1", "10", "100"]);
    /// ```
    pub fn log(lo: f64, hi: f64, length_px: f64, font_px: f64) -> Self {
        if !(lo > 0.0 && hi > lo && hi.is_finite() && length_px > 0.0) {
            return Self::from_values(vec![lo].into_iter().filter(|v| v.is_finite()), 0);
        }
        let (d0, d1) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
        let in_range = |v: &f64| *v >= lo * (1.0 - 1e-9) && *v <= hi * (1.0 + 1e-9);
        let at = |mantissas: &[f64], every: i32| -> Vec<f64> {
            (d0..=d1)
                .filter(|d| d.rem_euclid(every) == 0)
                .flat_map(|d| mantissas.iter().map(move |m| m * 10f64.powi(d)))
                .filter(in_range)
                .collect()
        };
        let px = |v: f64| length_px * (v / lo).log10() / (hi / lo).log10();
        let fits = |t: &Ticks| {
            t.values.windows(2).zip(t.labels.windows(2)).all(|(v, l)| {
                let half = 0.5 * (text_width(&l[0], font_px) + text_width(&l[1], font_px));
                px(v[1]) - px(v[0]) >= half + 0.6 * font_px
            })
        };
        let minor = at(&[2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0], 1);
        let mut candidates = vec![(vec![1.0, 2.0, 5.0], 1), (vec![1.0, 3.0], 1)];
        candidates.extend((1..=(d1 - d0).max(1)).map(|every| (vec![1.0], every)));
        for (mantissas, every) in candidates {
            let values = at(&mantissas, every);
            let mut ticks = Self {
                labels: values.iter().map(|&v| log_label(v)).collect(),
                values,
                minor: Vec::new(),
            };
            if fits(&ticks) || ticks.values.len() <= 1 {
                ticks.minor = minor.clone();
                return ticks;
            }
        }
        Self::from_values(std::iter::empty(), 0)
    }

    /// The label of tick value `v` (the nearest tick's, so a value that
    /// went through pixel arithmetic still finds its label).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::plot::{Along, Ticks};
    ///
    /// let t = Ticks::linear(0.0, 1.0, 500.0, 11.0, Along::Horizontal);
    /// assert_eq!(t.label(0.2), "0.2");
    /// ```
    pub fn label(&self, v: f64) -> String {
        self.values
            .iter()
            .zip(&self.labels)
            .min_by(|a, b| (a.0 - v).abs().total_cmp(&(b.0 - v).abs()))
            .map_or_else(String::new, |(_, l)| l.clone())
    }

    fn from_values(values: impl Iterator<Item = f64>, decimals: usize) -> Self {
        let values: Vec<f64> = values.collect();
        Self {
            labels: values.iter().map(|v| format!("{v:.decimals$}")).collect(),
            values,
            minor: Vec::new(),
        }
    }

    /// The widest label, px.
    fn widest(&self, font_px: f64) -> f64 {
        self.labels
            .iter()
            .map(|l| text_width(l, font_px))
            .fold(0.0, f64::max)
    }
}

/// A log tick's label: as many decimals as its decade needs (0.02, 0.5,
/// 1, 20).
fn log_label(v: f64) -> String {
    let decimals = (-v.log10().floor()).max(0.0) as usize;
    format!("{v:.decimals$}")
}

/// An axis (`inner`: linear or log) whose grid lines and labels are at
/// given ticks rather than plotters' own choice, which knows neither the
/// labels' width nor the axis' length in pixels.
pub(crate) struct Ticked<R> {
    pub(crate) inner: R,
    pub(crate) bold: Vec<f64>,
    pub(crate) light: Vec<f64>,
}

impl<R> Ticked<R> {
    /// `inner` with `ticks`' values as grid lines and labels, its minor
    /// ticks as light grid lines.
    pub(crate) fn new(inner: R, ticks: &Ticks) -> Self {
        Self {
            inner,
            bold: ticks.values.clone(),
            light: ticks.minor.clone(),
        }
    }
}

impl<R: plotters::coord::ranged1d::Ranged<ValueType = f64>> plotters::coord::ranged1d::Ranged
    for Ticked<R>
{
    type ValueType = f64;
    type FormatOption = plotters::coord::ranged1d::DefaultFormatting;

    fn range(&self) -> std::ops::Range<f64> {
        self.inner.range()
    }

    fn map(&self, value: &f64, limit: (i32, i32)) -> i32 {
        self.inner.map(value, limit)
    }

    fn key_points<H: plotters::coord::ranged1d::KeyPointHint>(&self, hint: H) -> Vec<f64> {
        if hint.weight().allow_light_points() {
            self.light.clone()
        } else {
            self.bold.clone()
        }
    }

    fn axis_pixel_range(&self, limit: (i32, i32)) -> std::ops::Range<i32> {
        self.inner.axis_pixel_range(limit)
    }
}
