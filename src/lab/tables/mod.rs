//! The lab's tables (`docs/lab.md`): the gains of Tables 2, 5 and 6 as data, with
//! the rows that belong together named ([`GainGroup`]), and the computation
//! of each table as a function returning a typed result.
//!
//! - Table 1, the nominal model's static deflection under a constant force:
//!   [`table1`] → [`Table1`];
//! - Table 2, state feedback on the nominal model: [`table2`] → [`Table2`];
//! - Tables 5 and 6 on the rig: the rows ([`TABLE5`], [`TABLE6`]), the root
//!   locus behind a group of rows ([`GroupLocus`]), what the
//!   identified model predicts for each ([`Prediction`]), how a run ended
//!   ([`RigOutcome::classify`]), and what a group of rows says about its
//!   gain over every row ([`GroupEffect`], [`Trend`]);
//! - one experiment, a row or any other gains, setpoint and duration:
//!   [`Experiment`] → [`ExperimentRun`], the one path a row takes run
//!   alone or in the batch ([`GainTable::experiment`]).
//!
//! The lab writes its tables in millimetres (setpoints, positions, errors)
//! with gains per millimetre: fields in mm say so in their names (`_mm`),
//! and [`LabGains::state_feedback`](crate::lab::LabGains::state_feedback)
//! is where the gains become SI.
//!
//! # Examples
//!
//! Table 5's rows, by group: Kf3 alone, then Kf4 with Kf3 = 10.
//!
//! ```
//! use ctrlab::lab::tables::{Gain, TABLE5};
//!
//! let groups: Vec<_> = TABLE5.groups.iter().map(|g| (g.varied, g.values.len())).collect();
//! assert_eq!(groups, [(Gain::Kf3, 5), (Gain::Kf4, 4)]);
//! assert_eq!(TABLE5.rows()[5], [0.0, 0.0, 10.0, 0.02]);
//! assert_eq!(TABLE5.setpoint_mm, 30.0);
//! ```

mod experiment;
mod locus;
mod prediction;
mod rig;
mod simulated;
mod trend;

use std::fmt;
use std::ops::Range;

use nalgebra::Complex;

use super::Cart;

pub use experiment::{
    Experiment, ExperimentError, ExperimentRun, MAX_DURATION, ROW_SEEDS_FROM, drive,
};
pub use locus::{GroupLocus, gain_loop, sampled_gain_loop};
pub use prediction::Prediction;
pub use rig::{
    ERROR_NOISE, GroupEffect, Halt, OVERSHOOT_NOISE, RigOutcome, RigRun, SATURATED_OSCILLATION,
    SETTLING_NOISE,
};
pub use simulated::{
    FORCES, SimulatedStep, TABLE1_DURATION, TABLE1_STEP, TABLE2_DURATION, TABLE2_STEP, Table1,
    Table1Row, Table2, Table2Row, linear_step, table1, table2,
};
pub use trend::{Noise, Trend};

/// One entry of the lab's gain row `Kf = [Kf1 Kf2 Kf3 Kf4]`, on the state
/// `[x1, x1', x2, x2']` in mm and mm/s.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::tables::Gain;
/// assert_eq!(Gain::Kf4.index(), 3);
/// assert_eq!(Gain::Kf4.to_string(), "Kf4");
/// assert_eq!(Gain::Kf4.acts_on(), "cart 2 velocity");
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Gain {
    /// On cart 1's position, V (or N) per mm.
    Kf1,
    /// On cart 1's velocity, per mm/s.
    Kf2,
    /// On cart 2's position, per mm.
    Kf3,
    /// On cart 2's velocity, per mm/s.
    Kf4,
}

impl Gain {
    /// All four, in the order of `Kf`.
    pub const ALL: [Gain; 4] = [Gain::Kf1, Gain::Kf2, Gain::Kf3, Gain::Kf4];

    /// Index into `Kf` (0-based).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::tables::{Gain, TABLE5};
    /// // Table 5's last row, read by gain.
    /// let kf = TABLE5.rows()[8];
    /// assert_eq!((kf[Gain::Kf3.index()], kf[Gain::Kf4.index()]), (10.0, 0.2));
    /// ```
    pub fn index(self) -> usize {
        match self {
            Gain::Kf1 => 0,
            Gain::Kf2 => 1,
            Gain::Kf3 => 2,
            Gain::Kf4 => 3,
        }
    }

    /// The state it multiplies, in words (`"cart 1 position"`).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::tables::Gain;
    /// assert_eq!(Gain::Kf2.acts_on(), "cart 1 velocity");
    /// assert_eq!(Gain::Kf3.acts_on(), "cart 2 position");
    /// ```
    pub fn acts_on(self) -> &'static str {
        match self {
            Gain::Kf1 => "cart 1 position",
            Gain::Kf2 => "cart 1 velocity",
            Gain::Kf3 => "cart 2 position",
            Gain::Kf4 => "cart 2 velocity",
        }
    }
}

impl fmt::Display for Gain {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "Kf{}", self.index() + 1)
    }
}

/// Rows of a table that vary one gain over `values` with the others held
/// at `base`: the rows that say what that gain does.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::tables::{Gain, TABLE6};
/// let kf2 = &TABLE6.groups[1];
/// assert_eq!(kf2.varied, Gain::Kf2);
/// assert_eq!(kf2.held(), vec![(Gain::Kf1, 1.0)]);
/// assert_eq!(kf2.rows().next(), Some([1.0, 0.001, 0.0, 0.0]));
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GainGroup {
    /// The gain the group varies.
    pub varied: Gain,
    /// The other gains, held (the varied entry is ignored).
    pub base: [f64; 4],
    /// The varied gain's values, in the table's order.
    pub values: &'static [f64],
}

impl GainGroup {
    /// The group's rows `Kf`, in order.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::tables::{Gain, TABLE5};
    /// let kf4 = &TABLE5.groups[1];
    /// assert_eq!(kf4.varied, Gain::Kf4);
    /// // Kf3 held at 10 V/mm in every row, Kf4 as the table lists it.
    /// assert!(kf4.rows().all(|kf| kf[2] == 10.0));
    /// assert_eq!(kf4.rows().map(|kf| kf[3]).collect::<Vec<_>>(), [0.02, 0.05, 0.1, 0.2]);
    /// ```
    pub fn rows(&self) -> impl Iterator<Item = [f64; 4]> + '_ {
        self.values.iter().map(move |&v| {
            let mut kf = self.base;
            kf[self.varied.index()] = v;
            kf
        })
    }

    /// The gains held at a non-zero value, with their values.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::tables::{Gain, TABLE6};
    /// assert!(TABLE6.groups[0].held().is_empty()); // Kf1 alone
    /// assert_eq!(TABLE6.groups[2].held(), [(Gain::Kf1, 1.0)]); // Kf4 with Kf1 = 1
    /// ```
    pub fn held(&self) -> Vec<(Gain, f64)> {
        Gain::ALL
            .into_iter()
            .filter(|g| *g != self.varied && self.base[g.index()] != 0.0)
            .map(|g| (g, self.base[g.index()]))
            .collect()
    }
}

/// One of the lab's state-feedback tables: which cart, to which setpoint,
/// and its rows as groups.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::{Cart, tables::TABLE6};
/// assert_eq!((TABLE6.number, TABLE6.cart, TABLE6.setpoint_mm), (6, Cart::One, 15.0));
/// assert_eq!(TABLE6.rows().len(), 15);
/// let ranges: Vec<_> = TABLE6.group_ranges().map(|(_, r)| r).collect();
/// assert_eq!(ranges, [0..5, 5..10, 10..15]);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GainTable {
    /// The table's number in the lab handout (and `docs/lab.md`).
    pub number: u8,
    /// The cart whose position is controlled (`G` selects it).
    pub cart: Cart,
    /// The setpoint, mm.
    pub setpoint_mm: f64,
    /// The rows, group by group.
    pub groups: &'static [GainGroup],
}

impl GainTable {
    /// Every row `Kf` (per mm), in the table's order.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::tables::TABLE2;
    /// let rows = TABLE2.rows();
    /// assert_eq!(rows.len(), TABLE2.groups.iter().map(|g| g.values.len()).sum::<usize>());
    /// assert_eq!(rows[3], [0.0, 0.0, 10.0, 0.1]); // the first Kf4 row
    /// ```
    pub fn rows(&self) -> Vec<[f64; 4]> {
        self.groups.iter().flat_map(GainGroup::rows).collect()
    }

    /// Each group with the range of its rows in [`rows`](Self::rows).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::tables::{Gain, TABLE5};
    /// let rows = TABLE5.rows();
    /// let (group, range) = TABLE5.group_ranges().nth(1).unwrap();
    /// assert_eq!((group.varied, range.clone()), (Gain::Kf4, 5..9));
    /// assert_eq!(rows[range].to_vec(), group.rows().collect::<Vec<_>>());
    /// ```
    pub fn group_ranges(&self) -> impl Iterator<Item = (&GainGroup, Range<usize>)> + '_ {
        let mut start = 0;
        self.groups.iter().map(move |g| {
            let range = start..start + g.values.len();
            start = range.end;
            (g, range)
        })
    }
}

/// Gains on cart 2 (`Kf3`, `Kf4`).
const fn cart2(kf3: f64, kf4: f64) -> [f64; 4] {
    [0.0, 0.0, kf3, kf4]
}

/// Gains on cart 1 (`Kf1`, `Kf2`, `Kf4`).
const fn cart1(kf1: f64, kf2: f64, kf4: f64) -> [f64; 4] {
    [kf1, kf2, 0.0, kf4]
}

/// Table 2 (simulation, nominal model): cart 2 to 30 mm; Kf3 = 0.1, 1, 10,
/// then Kf4 = 0.1, 0.3, 0.5 with Kf3 = 10.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::{Cart, tables::TABLE2};
/// assert_eq!((TABLE2.cart, TABLE2.setpoint_mm), (Cart::Two, 30.0));
/// assert_eq!(TABLE2.rows().len(), 6);
/// ```
pub const TABLE2: GainTable = GainTable {
    number: 2,
    cart: Cart::Two,
    setpoint_mm: 30.0,
    groups: &[
        GainGroup {
            varied: Gain::Kf3,
            base: cart2(0.0, 0.0),
            values: &[0.1, 1.0, 10.0],
        },
        GainGroup {
            varied: Gain::Kf4,
            base: cart2(10.0, 0.0),
            values: &[0.1, 0.3, 0.5],
        },
    ],
};

/// Table 5 (rig): cart 2 to 30 mm; Kf3 = 0.1, 0.5, 1, 5, 10, then Kf4 =
/// 0.02, 0.05, 0.1, 0.2 with Kf3 = 10.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::{Cart, tables::{TABLE2, TABLE5}};
/// // The rig's version of Table 2: same cart and setpoint, more rows.
/// assert_eq!((TABLE5.cart, TABLE5.setpoint_mm), (TABLE2.cart, TABLE2.setpoint_mm));
/// assert_eq!((TABLE5.cart, TABLE5.rows().len()), (Cart::Two, 9));
/// ```
pub const TABLE5: GainTable = GainTable {
    number: 5,
    cart: Cart::Two,
    setpoint_mm: 30.0,
    groups: &[
        GainGroup {
            varied: Gain::Kf3,
            base: cart2(0.0, 0.0),
            values: &[0.1, 0.5, 1.0, 5.0, 10.0],
        },
        GainGroup {
            varied: Gain::Kf4,
            base: cart2(10.0, 0.0),
            values: &[0.02, 0.05, 0.1, 0.2],
        },
    ],
};

/// Table 6 (rig): cart 1 to 15 mm; Kf1 = 0.2, 0.5, 1, 1.5, 2, then Kf2 =
/// 0.001 … 0.01 with Kf1 = 1, then Kf4 = 0.01 … 0.2 with Kf1 = 1.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::{Cart, Calibration, tables::TABLE6};
/// assert_eq!(TABLE6.cart, Cart::One);
/// // 15 mm, well inside cart 1's ±50 mm travel.
/// assert!(TABLE6.setpoint_mm / 1000.0 < Calibration::default().travel_limits[0]);
/// ```
pub const TABLE6: GainTable = GainTable {
    number: 6,
    cart: Cart::One,
    setpoint_mm: 15.0,
    groups: &[
        GainGroup {
            varied: Gain::Kf1,
            base: cart1(0.0, 0.0, 0.0),
            values: &[0.2, 0.5, 1.0, 1.5, 2.0],
        },
        GainGroup {
            varied: Gain::Kf2,
            base: cart1(1.0, 0.0, 0.0),
            values: &[0.001, 0.002, 0.005, 0.008, 0.01],
        },
        GainGroup {
            varied: Gain::Kf4,
            base: cart1(1.0, 0.0, 0.0),
            values: &[0.01, 0.02, 0.05, 0.1, 0.2],
        },
    ],
};

/// The rig's tables, in the lab's order.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::tables::RIG_TABLES;
/// assert_eq!(RIG_TABLES.map(|t| t.number), [5, 6]);
/// let rows: usize = RIG_TABLES.iter().map(|t| t.rows().len()).sum();
/// assert_eq!(rows, 24); // closed-loop runs on the rig
/// ```
pub const RIG_TABLES: [GainTable; 2] = [TABLE5, TABLE6];

/// `Kf` as the lab writes it: `[0 0 10 0.1]`.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::tables::kf_display;
/// assert_eq!(kf_display(&[0.0, 0.0, 10.0, 0.1]).to_string(), "[0 0 10 0.1]");
/// ```
pub fn kf_display(kf: &[f64; 4]) -> impl fmt::Display + '_ {
    KfDisplay(kf)
}

struct KfDisplay<'a>(&'a [f64; 4]);

impl fmt::Display for KfDisplay<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let [a, b, c, d] = self.0;
        write!(f, "[{a} {b} {c} {d}]")
    }
}

/// Poles as the tables print them: each complex pair once as `a ± bj`, real
/// poles as `a`, two decimals, separated by commas.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::tables::poles_display;
/// use ctrlab::nalgebra::Complex;
/// let poles = [Complex::new(-1.0, 2.0), Complex::new(-1.0, -2.0), Complex::new(-3.5, 0.0)];
/// assert_eq!(poles_display(&poles).to_string(), "-1.00 ± 2.00j, -3.50");
/// ```
pub fn poles_display(poles: &[Complex<f64>]) -> impl fmt::Display + '_ {
    PolesDisplay(poles)
}

struct PolesDisplay<'a>(&'a [Complex<f64>]);

impl fmt::Display for PolesDisplay<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mut first = true;
        for p in self.0.iter().filter(|p| p.im >= 0.0) {
            if !first {
                f.write_str(", ")?;
            }
            first = false;
            if p.im > 0.0 {
                write!(f, "{:.2} ± {:.2}j", p.re, p.im)?;
            } else {
                write!(f, "{:.2}", p.re)?;
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_tables_hold_the_labs_rows_in_order() {
        assert_eq!(
            TABLE2.rows(),
            [
                [0.0, 0.0, 0.1, 0.0],
                [0.0, 0.0, 1.0, 0.0],
                [0.0, 0.0, 10.0, 0.0],
                [0.0, 0.0, 10.0, 0.1],
                [0.0, 0.0, 10.0, 0.3],
                [0.0, 0.0, 10.0, 0.5],
            ]
        );
        assert_eq!(TABLE5.rows().len(), 9);
        let t6 = TABLE6.rows();
        assert_eq!(t6[0], [0.2, 0.0, 0.0, 0.0]);
        assert_eq!(t6[9], [1.0, 0.01, 0.0, 0.0]);
        assert_eq!(t6[14], [1.0, 0.0, 0.0, 0.2]);
    }

    #[test]
    fn groups_name_what_they_hold() {
        let (g, r) = TABLE5.group_ranges().nth(1).unwrap();
        assert_eq!((g.varied, r), (Gain::Kf4, 5..9));
        assert_eq!(g.held(), [(Gain::Kf3, 10.0)]);
        assert!(TABLE5.groups[0].held().is_empty());
    }
}
