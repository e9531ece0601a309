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
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::{Calibration, Cart, lqi::{CASES, Spec}};
    /// let [(cart, setpoint), _] = CASES;
    /// let spec = Spec::new(cart, setpoint, Calibration::default().volts_full_scale);
    /// assert_eq!((spec.cart, spec.setpoint, spec.volts), (Cart::Two, 0.030, 24.0));
    /// assert_eq!((spec.overshoot, spec.settling, spec.error_counts), (5.0, 0.5, 1.0)); // %, s, counts
    /// ```
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
///
/// # Examples
///
/// ```
/// use ctrlab::lab::lqi::Step;
/// let count_mm = 80.0 / 8192.0; // the default encoder's count, mm
/// let s = Step { rise: 0.15, overshoot: 2.0, settling: 0.45, error_mm: 2.0 * count_mm, error_counts: 2.0 };
/// assert!((s.error_mm / s.error_counts - count_mm).abs() < 1e-15); // the same error, two units
/// assert!(s.rise < s.settling); // s
/// ```
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
///
/// # Examples
///
/// ```
/// use ctrlab::lab::lqi::{Item, Verdict};
/// let v = Verdict { overshoot: true, settling: true, error: false, volts: true };
/// assert_eq!(Item::ALL.map(|i| v.met(i)), [true, true, false, true]);
/// ```
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
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::lqi::{Item, Verdict};
    /// let v = Verdict { overshoot: false, settling: true, error: true, volts: true };
    /// assert!(!v.met(Item::Overshoot) && v.met(Item::Voltage));
    /// ```
    pub fn met(&self, item: Item) -> bool {
        match item {
            Item::Overshoot => self.overshoot,
            Item::Settling => self.settling,
            Item::Error => self.error,
            Item::Voltage => self.volts,
        }
    }

    /// Whether every item is met.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::lqi::Verdict;
    /// assert!(Verdict { overshoot: true, settling: true, error: true, volts: true }.passes());
    /// assert!(!Verdict { overshoot: true, settling: true, error: true, volts: false }.passes());
    /// ```
    pub fn passes(&self) -> bool {
        Item::ALL.iter().all(|&i| self.met(i))
    }

    /// The items not met, in the spec's order.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::lqi::{Item, Verdict};
    /// let v = Verdict { overshoot: false, settling: true, error: false, volts: true };
    /// assert_eq!(v.failing(), [Item::Overshoot, Item::Error]);
    /// ```
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
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::{Cart, lqi::{Metrics, Spec}};
    /// # use ctrlab::Recording;
    /// # // Cart 2 from rest to 30 mm, a first-order approach of `tau` s, 1 V drive.
    /// # let approach = |tau: f64| {
    /// #     let t: Vec<f64> = (0..1500).map(|k| k as f64 * 0.002).collect();
    /// #     let x2: Vec<f64> = t.iter().map(|t| 0.030 * (1.0 - (-t / tau).exp())).collect();
    /// #     let z = vec![0.0; 1500];
    /// #     Recording::from_columns(ctrlab::lab::schema(), t, vec![vec![1.0; 1500], z.clone(), z.clone(), x2, z])
    /// # };
    /// let spec = Spec::new(Cart::Two, 0.030, 24.0);
    /// let m = Metrics::of(&approach(0.1)?, &spec, 0.080 / 8192.0)?;
    /// // A 0.1 s first-order approach: no overshoot, settled in 0.39 s, 1 V peak.
    /// assert!(m.passes(&spec) && (m.peak_u, m.clipped) == (1.0, 0));
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
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
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::lab::{Cart, lqi::{Metrics, Spec, Step}};
    /// # let spec = Spec::new(Cart::Two, 0.030, 24.0);
    /// # // Half a count short (a count is 80 mm / 8192).
    /// # let step = Step { rise: 0.1, overshoot: 3.0, settling: 0.4, error_mm: 0.5 * 80.0 / 8192.0, error_counts: 0.5 };
    /// # let m = Metrics { step: Ok(step), peak_u: 12.0, clipped: 0 };
    /// let v = m.verdict(&spec);
    /// assert!(v.passes()); // 3 % ≤ 5 %, 0.4 s ≤ 0.5 s, ½ count ≤ 1, 12 V
    /// let unsettled = Metrics { step: Err(ctrlab::Error::TooFewSamples { what: "step", needed: 2, got: 0 }), ..m };
    /// assert_eq!(unsettled.verdict(&spec).failing().len(), 3); // only the voltage met
    /// ```
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
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::lab::{Cart, lqi::{Metrics, Spec, Step}};
    /// # let spec = Spec::new(Cart::Two, 0.030, 24.0);
    /// # // Half a count short (a count is 80 mm / 8192).
    /// # let step = Step { rise: 0.1, overshoot: 3.0, settling: 0.4, error_mm: 0.5 * 80.0 / 8192.0, error_counts: 0.5 };
    /// # let m = Metrics { step: Ok(step), peak_u: 12.0, clipped: 0 };
    /// assert!(m.passes(&spec));
    /// assert!(!Metrics { clipped: 1, ..m }.passes(&spec)); // the drive touched its limit
    /// ```
    pub fn passes(&self, spec: &Spec) -> bool {
        self.verdict(spec).passes()
    }

    /// The smallest relative margin to the spec of each item (negative:
    /// out of spec; −∞ without step figures): `1 − figure / limit`.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::lab::{Cart, lqi::{Metrics, Spec, Step}};
    /// # let spec = Spec::new(Cart::Two, 0.030, 24.0);
    /// # // Half a count short (a count is 80 mm / 8192).
    /// # let step = Step { rise: 0.1, overshoot: 3.0, settling: 0.4, error_mm: 0.5 * 80.0 / 8192.0, error_counts: 0.5 };
    /// # let m = Metrics { step: Ok(step), peak_u: 12.0, clipped: 0 };
    /// // Overshoot 0.4, settling 0.2, error 0.5, voltage 0.5: the settling time's is smallest.
    /// assert!((m.margin(&spec) - 0.2).abs() < 1e-12);
    /// ```
    pub fn margin(&self, spec: &Spec) -> f64 {
        self.step.as_ref().map_or(f64::NEG_INFINITY, |s| {
            (1.0 - s.overshoot / spec.overshoot)
                .min(1.0 - s.settling / spec.settling)
                .min(1.0 - s.error_counts.abs() / spec.error_counts)
                .min(1.0 - self.peak_u / spec.volts)
        })
    }
}
