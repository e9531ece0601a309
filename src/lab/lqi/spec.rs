//! The spec of a step and a run's figures against it.

use crate::data::Recording;
use crate::error::Error;
use crate::lab::{Cart, position_channel};
use crate::metrics::{StepInfoOptions, step_info};

/// The spec of a step: overshoot, 2 % settling time, steady-state error
/// and drive voltage.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::{Cart, lqi::Spec};
/// let spec = Spec::new(Cart::Two, 0.030, 24.0);
/// assert_eq!((spec.overshoot, spec.settling, spec.error_counts, spec.volts), (5.0, 0.5, 1.0, 24.0));
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Spec {
    /// The cart whose position is tracked.
    pub cart: Cart,
    /// The setpoint, m.
    pub setpoint: f64,
    /// Largest overshoot, %.
    pub overshoot: f64,
    /// Largest 2 % settling time, s.
    pub settling: f64,
    /// Largest |steady-state error|, encoder counts.
    pub error_counts: f64,
    /// Largest |u|, V: the drive's range, never clipped.
    pub volts: f64,
}

impl Spec {
    /// The lab's spec for `cart` to `setpoint` (m) on a drive of
    /// `volts_full_scale` (V): overshoot ≤ 5 %, settling ≤ 0.5 s, within a
    /// count, |u| within the drive's range and never at its limit.
    pub fn new(cart: Cart, setpoint: f64, volts_full_scale: f64) -> Self {
        Self {
            cart,
            setpoint,
            overshoot: 5.0,
            settling: 0.5,
            error_counts: 1.0,
            volts: volts_full_scale,
        }
    }
}

/// A step's figures, from [`step_info`] (2 % band, 10–90 % rise, y∞ the
/// mean of the last 5 %).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Step {
    /// 10–90 % rise time, s.
    pub rise: f64,
    /// Overshoot relative to y∞, %.
    pub overshoot: f64,
    /// 2 % settling time, s.
    pub settling: f64,
    /// setpoint − y∞, mm.
    pub error_mm: f64,
    /// The same in encoder counts.
    pub error_counts: f64,
}

/// One item of the spec.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Item {
    /// [`Spec::overshoot`].
    Overshoot,
    /// [`Spec::settling`].
    Settling,
    /// [`Spec::error_counts`].
    Error,
    /// [`Spec::volts`].
    Voltage,
}

impl Item {
    /// Every item, in the spec's order.
    pub const ALL: [Item; 4] = [Item::Overshoot, Item::Settling, Item::Error, Item::Voltage];
}

/// Each item of the spec, met or not.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::lqi::{Item, Verdict};
/// let v = Verdict { overshoot: true, settling: false, error: true, volts: false };
/// assert!(!v.passes());
/// assert_eq!(v.failing(), [Item::Settling, Item::Voltage]);
/// assert!(v.met(Item::Error));
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Verdict {
    /// Overshoot within the spec.
    pub overshoot: bool,
    /// Settling time within the spec.
    pub settling: bool,
    /// Steady-state error within the spec.
    pub error: bool,
    /// Voltage within the drive's range, never at its limit.
    pub volts: bool,
}

impl Verdict {
    /// Whether `item` is met.
    pub fn met(&self, item: Item) -> bool {
        match item {
            Item::Overshoot => self.overshoot,
            Item::Settling => self.settling,
            Item::Error => self.error,
            Item::Voltage => self.volts,
        }
    }

    /// Whether every item is met.
    pub fn passes(&self) -> bool {
        Item::ALL.iter().all(|&i| self.met(i))
    }

    /// The items not met, in the spec's order.
    pub fn failing(&self) -> Vec<Item> {
        Item::ALL.into_iter().filter(|&i| !self.met(i)).collect()
    }
}

/// A run's figures against the spec.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::LabGains;
/// use ctrlab::lab::{Cart, SimulatedRig, lqi::{self, Metrics, Spec}};
/// let sim = SimulatedRig::default();
/// let law = LabGains::new([0.0, 0.0, 1.0, 0.0], Cart::Two).state_feedback()?;
/// let rec = lqi::predict(&sim, law, 0.030, 3.0)?;
/// let spec = Spec::new(Cart::Two, 0.030, 24.0);
/// let m = Metrics::of(&rec, &spec, sim.metres_per_count())?;
/// // Proportional only: a standing error of many counts.
/// assert!(!m.verdict(&spec).error && m.margin(&spec) < 0.0);
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct Metrics {
    /// The step's figures, or why there are none
    /// ([`Error::NotSettled`], …).
    pub step: Result<Step, Error>,
    /// Largest |u|, V.
    pub peak_u: f64,
    /// Samples with the drive at its limit.
    pub clipped: usize,
}

impl Metrics {
    /// The figures of `rec` for `spec`, counts of `metres_per_count` (m).
    ///
    /// # Errors
    ///
    /// [`Error::Channel`] for a channel missing from `rec`.
    pub fn of(rec: &Recording, spec: &Spec, metres_per_count: f64) -> Result<Self, Error> {
        let y: Vec<f64> = rec
            .channel(position_channel(spec.cart))?
            .iter()
            .map(|v| v * 1e3)
            .collect();
        let options = StepInfoOptions {
            reference: Some(spec.setpoint * 1e3),
            ..Default::default()
        };
        let step = step_info(rec.time(), &y, &options).map(|info| {
            let error_mm = info.steady_state_error.unwrap_or(f64::NAN);
            Step {
                rise: info.rise_time,
                overshoot: info.overshoot,
                settling: info.settling_time,
                error_mm,
                error_counts: error_mm * 1e-3 / metres_per_count,
            }
        });
        let u = rec.channel("u")?;
        Ok(Self {
            step,
            peak_u: u.iter().fold(0.0, |m: f64, v| m.max(v.abs())),
            clipped: u.iter().filter(|v| v.abs() >= spec.volts).count(),
        })
    }

    /// Each item of `spec`, met or not (without step figures, only the
    /// voltage can be).
    pub fn verdict(&self, spec: &Spec) -> Verdict {
        let volts = self.clipped == 0 && self.peak_u <= spec.volts;
        match &self.step {
            Ok(s) => Verdict {
                overshoot: s.overshoot <= spec.overshoot,
                settling: s.settling <= spec.settling,
                error: s.error_counts.abs() <= spec.error_counts,
                volts,
            },
            Err(_) => Verdict {
                overshoot: false,
                settling: false,
                error: false,
                volts,
            },
        }
    }

    /// Whether every item of `spec` is met.
    pub fn passes(&self, spec: &Spec) -> bool {
        self.verdict(spec).passes()
    }

    /// The smallest relative margin to the spec of each item (negative:
    /// out of spec; −∞ without step figures): `1 − figure / limit`.
    pub fn margin(&self, spec: &Spec) -> f64 {
        self.step.as_ref().map_or(f64::NEG_INFINITY, |s| {
            (1.0 - s.overshoot / spec.overshoot)
                .min(1.0 - s.settling / spec.settling)
                .min(1.0 - s.error_counts.abs() / spec.error_counts)
                .min(1.0 - self.peak_u / spec.volts)
        })
    }
}
