//! The shape of a series of measurements along a group's rows, read from
//! every row: what the lab's answers may claim about a gain.

use std::fmt;

/// What counts as noise when reading a [`Trend`]: a change between two
/// values `a` and `b` of at most `max(floor, relative · max(|a|, |b|))`.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::tables::Noise;
/// let n = Noise { relative: 0.1, floor: 0.01 };
/// assert_eq!(n.between(2.0, -3.0), 0.30000000000000004);
/// assert_eq!(n.between(0.05, 0.02), 0.01);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Noise {
    /// The fraction of the larger magnitude (0 ≤ relative < 1).
    pub relative: f64,
    /// The smallest change read as a change, in the values' unit (≥ 0):
    /// the resolution the metric is read at.
    pub floor: f64,
}

impl Noise {
    /// The largest change between `a` and `b` that is noise.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::tables::Noise;
    /// let n = Noise { relative: 0.25, floor: 0.05 }; // mm
    /// assert_eq!(n.between(1.2, 1.6), 0.4); // 25 % of the larger
    /// assert_eq!(n.between(0.01, 0.02), 0.05); // but never below the floor
    /// ```
    pub fn between(&self, a: f64, b: f64) -> f64 {
        (self.relative * a.abs().max(b.abs())).max(self.floor)
    }

    fn is_valid(&self) -> bool {
        (0.0..1.0).contains(&self.relative) && self.floor.is_finite() && self.floor >= 0.0
    }
}

/// How a series changes along its rows, with changes within a [`Noise`]
/// taken as noise ([`Trend::of`]). Each variant is a claim about every
/// row, not only the ends:
///
/// - a part *rises* when no value lies below an earlier one by more than
///   the noise between the two, and its last lies above its first by more
///   than theirs (*falls* likewise, mirrored);
/// - a series is *flat* when every two values differ by at most the noise
///   between them.
///
/// # Examples
///
/// Table 5's overshoot along Kf3 on the simulated rig: it climbs, turns at
/// Kf3 = 1 (where the drive starts to saturate) and comes down.
///
/// ```
/// use ctrlab::lab::tables::Trend;
/// use ctrlab::lab::tables::{Noise, OVERSHOOT_NOISE};
/// let noise = OVERSHOOT_NOISE;
/// let pot = [1.41, 17.60, 35.68, 23.77, 20.95];
/// let t = Trend::of(&pot, noise).unwrap();
/// assert_eq!(t, Trend::Peaks { from: 1.41, peak: 35.68, at: 2, to: 20.95 });
/// assert_eq!(t.to_string(), "rises to 35.68 (row 3), then falls to 20.95");
/// // Read from its ends only, the same series "grows".
/// assert_eq!(Trend::of(&[1.41, 20.95], noise), Some(Trend::Rises { from: 1.41, to: 20.95 }));
/// // Exactly, with no noise, it turns twice.
/// let exact = Noise { relative: 0.0, floor: 0.0 };
/// assert!(matches!(Trend::of(&[6.40, 7.01, 6.91, 6.58, 6.61], exact), Some(Trend::Mixed { .. })));
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Trend {
    /// Every value within the band of every other.
    Flat {
        /// The smallest value.
        lo: f64,
        /// The largest.
        hi: f64,
    },
    /// Rises over the whole series.
    Rises {
        /// The first value.
        from: f64,
        /// The last.
        to: f64,
    },
    /// Falls over the whole series.
    Falls {
        /// The first value.
        from: f64,
        /// The last.
        to: f64,
    },
    /// Rises up to its largest value, then falls: each part as
    /// [`Rises`](Self::Rises) and [`Falls`](Self::Falls), the turn shared.
    Peaks {
        /// The first value.
        from: f64,
        /// The largest.
        peak: f64,
        /// Its index in the series (the first, if it repeats).
        at: usize,
        /// The last value.
        to: f64,
    },
    /// Falls down to its smallest value, then rises.
    Dips {
        /// The first value.
        from: f64,
        /// The smallest.
        low: f64,
        /// Its index in the series (the first, if it repeats).
        at: usize,
        /// The last value.
        to: f64,
    },
    /// Turns more than once beyond the band.
    Mixed {
        /// The smallest value.
        lo: f64,
        /// The largest.
        hi: f64,
    },
}

// The pairwise claims checked against running extremes, in one pass: for
// a later value v, `u − noise(u, v)` grows with an earlier u (the relative
// part is below 1), so the highest earlier value is the one to compare
// with (mirrored for the lowest).

/// No value below an earlier one by more than the noise between them.
fn never_falls(values: &[f64], noise: Noise) -> bool {
    let mut highest = f64::NEG_INFINITY;
    values.iter().all(|&v| {
        highest = highest.max(v);
        v >= highest - noise.between(highest, v)
    })
}

/// No value above an earlier one by more than the noise between them.
fn never_rises(values: &[f64], noise: Noise) -> bool {
    let mut lowest = f64::INFINITY;
    values.iter().all(|&v| {
        lowest = lowest.min(v);
        v <= lowest + noise.between(lowest, v)
    })
}

/// Rises beyond the noise, end to end, without falling beyond it.
fn rises(values: &[f64], noise: Noise) -> bool {
    matches!((values.first(), values.last()), (Some(&a), Some(&b)) if b - a > noise.between(a, b))
        && never_falls(values, noise)
}

/// Falls beyond the noise, end to end, without rising beyond it.
fn falls(values: &[f64], noise: Noise) -> bool {
    matches!((values.first(), values.last()), (Some(&a), Some(&b)) if a - b > noise.between(a, b))
        && never_rises(values, noise)
}

impl Trend {
    /// The shape of `values` (in row order) with changes within `noise`
    /// taken as noise; `None` for fewer than two values, a non-finite
    /// value or an invalid noise (relative outside 0–1, negative floor).
    /// One pass over the values.
    ///
    /// # Examples
    ///
    /// Table 6's settling time along Kf4 (with Kf1 = 1), s: faster, then
    /// much slower as a real closed-loop pole moves toward the origin.
    ///
    /// ```
    /// use ctrlab::lab::tables::Trend;
    /// use ctrlab::lab::tables::SETTLING_NOISE as noise;
    /// let t = Trend::of(&[0.35, 0.27, 0.19, 0.78, 2.01], noise).unwrap();
    /// assert!(matches!(t, Trend::Dips { at: 2, .. }));
    /// assert_eq!(Trend::of(&[1.0], noise), None);
    /// assert_eq!(Trend::of(&[1.0, f64::NAN], noise), None);
    /// ```
    pub fn of(values: &[f64], noise: Noise) -> Option<Self> {
        if values.len() < 2 || !noise.is_valid() {
            return None;
        }
        if values.iter().any(|v| !v.is_finite()) {
            return None;
        }
        let (first, last) = (values[0], values[values.len() - 1]);
        let (mut lo, mut hi, mut at_lo, mut at_hi) = (first, first, 0, 0);
        for (i, &v) in values.iter().enumerate() {
            if v < lo {
                (lo, at_lo) = (v, i);
            }
            if v > hi {
                (hi, at_hi) = (v, i);
            }
        }
        // The extreme pair differs most and allows the most noise: when it
        // is within the noise, every pair is.
        Some(if hi - lo <= noise.between(lo, hi) {
            Self::Flat { lo, hi }
        } else if rises(values, noise) {
            Self::Rises {
                from: first,
                to: last,
            }
        } else if falls(values, noise) {
            Self::Falls {
                from: first,
                to: last,
            }
        } else if rises(&values[..=at_hi], noise) && falls(&values[at_hi..], noise) {
            Self::Peaks {
                from: first,
                peak: hi,
                at: at_hi,
                to: last,
            }
        } else if falls(&values[..=at_lo], noise) && rises(&values[at_lo..], noise) {
            Self::Dips {
                from: first,
                low: lo,
                at: at_lo,
                to: last,
            }
        } else {
            Self::Mixed { lo, hi }
        })
    }

    /// The index of the turn, for [`Peaks`](Self::Peaks) and
    /// [`Dips`](Self::Dips).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::tables::{Noise, Trend};
    /// let noise = Noise { relative: 0.1, floor: 0.0 };
    /// let overshoot = Trend::of(&[2.0, 18.0, 34.0, 20.0], noise).unwrap(); // %
    /// assert_eq!(overshoot.turn(), Some(2)); // peaks at the third row
    /// assert_eq!(Trend::of(&[1.0, 2.0, 4.0], noise).unwrap().turn(), None); // rises
    /// ```
    pub fn turn(&self) -> Option<usize> {
        match self {
            Self::Peaks { at, .. } | Self::Dips { at, .. } => Some(*at),
            _ => None,
        }
    }
}

/// Two decimals, as the lab's tables print their metrics; rows numbered
/// from 1.
impl fmt::Display for Trend {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Flat { lo, hi } => write!(f, "stays within {lo:.2}–{hi:.2}"),
            Self::Rises { from, to } => write!(f, "rises from {from:.2} to {to:.2}"),
            Self::Falls { from, to } => write!(f, "falls from {from:.2} to {to:.2}"),
            Self::Peaks { peak, at, to, .. } => write!(
                f,
                "rises to {peak:.2} (row {}), then falls to {to:.2}",
                at + 1
            ),
            Self::Dips { low, at, to, .. } => write!(
                f,
                "falls to {low:.2} (row {}), then rises to {to:.2}",
                at + 1
            ),
            Self::Mixed { lo, hi } => {
                write!(f, "turns more than once, between {lo:.2} and {hi:.2}")
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// The claims as the variants' docs state them, checked on every pair
    /// of rows (written apart from the running extremes above).
    fn holds(t: Trend, v: &[f64], noise: Noise) -> bool {
        let n = |a: f64, b: f64| noise.between(a, b);
        let pairs = |s: &[f64], ok: &dyn Fn(f64, f64) -> bool| {
            (0..s.len()).all(|i| (i..s.len()).all(|j| ok(s[i], s[j])))
        };
        let up = |s: &[f64]| {
            let (a, b) = (s[0], *s.last().unwrap());
            b - a > n(a, b) && pairs(s, &|x, y| y >= x - n(x, y))
        };
        let down = |s: &[f64]| {
            let (a, b) = (s[0], *s.last().unwrap());
            a - b > n(a, b) && pairs(s, &|x, y| y <= x + n(x, y))
        };
        let flat = pairs(v, &|x, y| (y - x).abs() <= n(x, y));
        let max = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let min = v.iter().copied().fold(f64::INFINITY, f64::min);
        match t {
            Trend::Flat { lo, hi } => flat && lo == min && hi == max,
            Trend::Rises { .. } => up(v),
            Trend::Falls { .. } => down(v),
            Trend::Peaks { peak, at, .. } => peak == max && up(&v[..=at]) && down(&v[at..]),
            Trend::Dips { low, at, .. } => low == min && down(&v[..=at]) && up(&v[at..]),
            Trend::Mixed { .. } => !(flat || up(v) || down(v)),
        }
    }

    proptest! {
        #[test]
        fn every_claim_holds_over_every_row(
            v in prop::collection::vec(-100.0..100.0f64, 2..12),
            relative in 0.0..0.9f64,
            floor in 0.0..30.0f64,
        ) {
            let noise = Noise { relative, floor };
            let t = Trend::of(&v, noise).unwrap();
            prop_assert!(holds(t, &v, noise), "{t:?} on {v:?} with {noise:?}");
        }

        #[test]
        fn a_monotone_series_rises_or_falls(
            mut v in prop::collection::vec(-100.0..100.0f64, 2..12),
        ) {
            v.sort_by(f64::total_cmp);
            v.dedup();
            prop_assume!(v.len() >= 2);
            let exact = Noise { relative: 0.0, floor: 0.0 };
            let t = Trend::of(&v, exact).unwrap();
            prop_assert!(matches!(t, Trend::Rises { .. }), "{t:?}");
            v.reverse();
            let t = Trend::of(&v, exact).unwrap();
            prop_assert!(matches!(t, Trend::Falls { .. }), "{t:?}");
        }
    }

    #[test]
    fn two_turns_are_mixed_and_bad_input_is_none() {
        let noise = Noise {
            relative: 0.1,
            floor: 1.0,
        };
        assert!(matches!(
            Trend::of(&[0.0, 10.0, 0.0, 10.0], noise),
            Some(Trend::Mixed { lo: 0.0, hi: 10.0 })
        ));
        assert_eq!(Trend::of(&[], noise), None);
        let bad = |relative, floor| Trend::of(&[1.0, 2.0], Noise { relative, floor });
        assert_eq!(bad(0.1, -1.0), None);
        assert_eq!(bad(0.1, f64::INFINITY), None);
        assert_eq!(bad(1.0, 0.0), None);
        assert_eq!(bad(f64::NAN, 0.0), None);
        assert_eq!(Trend::of(&[1.0, f64::INFINITY], noise), None);
    }
}
