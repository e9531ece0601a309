//! Tables 5 and 6 on the rig: what the identified model predicts for a row,
//! how a run ended, and what a group of rows says about its gain.

use nalgebra::Complex;

use super::{Gain, GainGroup};
use crate::data::Recording;
use crate::discretize::Discretization;
use crate::error::Error;
use crate::hw::{LoopFault, RigError};
use crate::lab::{self, Cart, LabGains, MassSpring};
use crate::metrics::{StepInfo, StepInfoOptions, step_info};

/// What the identified linear model predicts for a row: the closed loop
/// sampled at the rig's period (ZOH, no saturation, no friction) is stable
/// when its spectral radius is below 1; the continuous poles for reference.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::{Cart, MassSpring, tables::Prediction};
/// let plant = MassSpring::nominal();
/// let p = Prediction::of(&plant, [0.0, 0.0, 1.0, 0.0], Cart::Two, 0.002)?;
/// assert!(p.is_stable() && p.radius > 0.9);
/// // Cart 1 through the spring k2 destabilises far sooner.
/// assert!(!Prediction::of(&plant, [2.0, 0.0, 0.0, 0.0], Cart::One, 0.002)?.is_stable());
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Prediction {
    /// The sampled closed loop's spectral radius `max |z|` (< 1: stable).
    pub radius: f64,
    /// The continuous closed loop's poles, 1/s.
    pub poles: [Complex<f64>; 4],
}

impl Prediction {
    /// The prediction for gains `kf` (per mm) on `cart` of `model`, sampled
    /// every `period` s.
    ///
    /// # Errors
    ///
    /// A non-finite gain, an invalid model or period, or an eigenvalue
    /// iteration that fails.
    pub fn of(model: &MassSpring, kf: [f64; 4], cart: Cart, period: f64) -> Result<Self, Error> {
        let sys = model.state_space(cart)?;
        // The rig samples every period: the loop that can be stable or not
        // is the sampled one, so predict with the ZOH-discretised model.
        let sampled = sys.discretize(period, Discretization::Zoh)?;
        let ctrl = LabGains::new(kf, cart).state_feedback()?;
        let poles = ctrl.closed_loop(&sys)?.poles()?;
        let radius = ctrl
            .closed_loop(&sampled)?
            .poles()?
            .iter()
            .map(|z| z.norm())
            .fold(0.0, f64::max);
        Ok(Self { radius, poles })
    }

    /// Whether the sampled loop is stable.
    pub fn is_stable(&self) -> bool {
        self.radius < 1.0
    }
}

/// Why a run stopped before its end, or has no metrics.
#[derive(Debug, Clone, PartialEq)]
pub enum Halt {
    /// The rig halted a cart beyond its travel limit.
    TravelLimit {
        /// The cart, 1 or 2.
        cart: usize,
        /// Its position, m.
        position: f64,
        /// The limit, m (symmetric about zero).
        limit: f64,
    },
    /// Another fault of the rig or the loop: its message.
    Fault(String),
    /// The run completed, but its step metrics failed for a reason other
    /// than not settling.
    NoMetrics(Error),
}

/// Fraction of the time at full scale above which a sustained oscillation
/// is the drive chattering between its limits.
pub const SATURATED_OSCILLATION: f64 = 0.2;

/// How a closed-loop rig run ended.
///
/// # Examples
///
/// ```
/// use ctrlab::Recording;
/// use ctrlab::lab::{Cart, tables::RigOutcome};
///
/// // Cart 2 still creeping toward 30 mm when the run ends.
/// let t: Vec<f64> = (0..1500).map(|k| k as f64 * 0.002).collect();
/// let x2: Vec<f64> = t.iter().map(|t| 0.010 * t).collect();
/// let zeros = vec![0.0; 1500];
/// let columns = vec![vec![1.0; 1500], zeros.clone(), zeros.clone(), x2, zeros];
/// let rec = Recording::from_columns(ctrlab::lab::schema(), t, columns)?;
/// let outcome = RigOutcome::classify(&rec, Cart::Two, 30.0, 24.0)?;
/// assert!(matches!(outcome, RigOutcome::TooSlow { y_end_mm } if (y_end_mm - 29.98).abs() < 1e-9));
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub enum RigOutcome {
    /// Settled inside the 2 % band: the metrics of the position in mm
    /// (y∞ the mean of the last 5 %, overshoot relative to y∞, steady-state
    /// error = setpoint − y∞, mm).
    Settled(StepInfo),
    /// Still moving toward the setpoint when the run ended.
    TooSlow {
        /// The position at the end, mm.
        y_end_mm: f64,
    },
    /// A bounded oscillation over the last quarter of the run that never
    /// settles.
    Oscillating {
        /// Lowest position, mm.
        lo_mm: f64,
        /// Highest position, mm.
        hi_mm: f64,
        /// Fraction of the time the drive is at its full scale (0–1).
        saturated: f64,
    },
    /// Halted by the rig or the loop, or without metrics.
    Diverged {
        /// When, s (the recording's last time).
        at: f64,
        /// Why.
        why: Halt,
    },
}

impl RigOutcome {
    /// Classifies a completed run of `cart` to `setpoint_mm` (mm): its
    /// step metrics, or why there are none; `volts_full_scale` (V) is the
    /// drive's limit, for telling saturation.
    ///
    /// # Errors
    ///
    /// [`Error::Channel`] when `rec` lacks the cart's position or `u`.
    pub fn classify(
        rec: &Recording,
        cart: Cart,
        setpoint_mm: f64,
        volts_full_scale: f64,
    ) -> Result<Self, Error> {
        let y: Vec<f64> = rec
            .channel(lab::position_channel(cart))?
            .iter()
            .map(|v| v * 1e3)
            .collect();
        let options = StepInfoOptions {
            reference: Some(setpoint_mm),
            ..Default::default()
        };
        Ok(match step_info(rec.time(), &y, &options) {
            Ok(info) => Self::Settled(info),
            Err(Error::NotSettled { .. }) => unsettled(&y, rec.channel("u")?, volts_full_scale),
            Err(e) => Self::Diverged {
                at: rec.time().last().copied().unwrap_or(0.0),
                why: Halt::NoMetrics(e),
            },
        })
    }

    /// A run the rig or the loop halted with `error`; `rec` is the
    /// recording up to the halt.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::Recording;
    /// use ctrlab::hw::{LoopFault, RigError};
    /// use ctrlab::lab::tables::{Halt, RigOutcome};
    /// let columns = vec![vec![0.0; 2]; 5];
    /// let rec = Recording::from_columns(ctrlab::lab::schema(), vec![0.0, 0.002], columns)?;
    /// let e = RigError::Fault(LoopFault::TravelLimit { axis: 1, position: 0.051, limit: 0.05 });
    /// let o = RigOutcome::halted(&rec, &e);
    /// assert_eq!(o, RigOutcome::Diverged {
    ///     at: 0.002,
    ///     why: Halt::TravelLimit { cart: 1, position: 0.051, limit: 0.05 },
    /// });
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn halted(rec: &Recording, error: &RigError) -> Self {
        let why = match error {
            RigError::Fault(LoopFault::TravelLimit {
                axis,
                position,
                limit,
            }) => Halt::TravelLimit {
                cart: *axis,
                position: *position,
                limit: *limit,
            },
            other => Halt::Fault(other.to_string()),
        };
        Self::Diverged {
            at: rec.time().last().copied().unwrap_or(0.0),
            why,
        }
    }

    /// The step metrics, when the run settled.
    pub fn step(&self) -> Option<&StepInfo> {
        match self {
            Self::Settled(info) => Some(info),
            _ => None,
        }
    }

    /// Whether the run settled.
    pub fn is_settled(&self) -> bool {
        self.step().is_some()
    }
}

/// Classifies a completed run that did not settle, from its last quarter.
fn unsettled(y_mm: &[f64], u: &[f64], full_scale: f64) -> RigOutcome {
    let tail = y_mm.len() * 3 / 4;
    let (y_tail, u_tail) = (&y_mm[tail..], &u[tail.min(u.len())..]);
    let lo = y_tail.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = y_tail.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let mean = y_tail.iter().sum::<f64>() / y_tail.len().max(1) as f64;
    let crossings = y_tail
        .windows(2)
        .filter(|w| (w[0] - mean) * (w[1] - mean) < 0.0)
        .count();
    let saturated = u_tail
        .iter()
        .filter(|v| v.abs() >= 0.99 * full_scale)
        .count() as f64
        / u_tail.len().max(1) as f64;
    if crossings >= 4 {
        RigOutcome::Oscillating {
            lo_mm: lo,
            hi_mm: hi,
            saturated,
        }
    } else {
        RigOutcome::TooSlow {
            y_end_mm: y_mm.last().copied().unwrap_or(f64::NAN),
        }
    }
}

/// One row of a rig table: the gains, the prediction and the outcome.
#[derive(Debug, Clone, PartialEq)]
pub struct RigRun {
    /// The lab's gains, per mm.
    pub kf: [f64; 4],
    /// What the identified model predicted.
    pub prediction: Prediction,
    /// How the run ended.
    pub outcome: RigOutcome,
}

impl RigRun {
    /// Whether the prediction was right: stable and settled, or unstable
    /// and not.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::tables::{Prediction, RigOutcome, RigRun};
    /// use ctrlab::nalgebra::Complex;
    /// let run = RigRun {
    ///     kf: [0.0, 0.0, 1.0, 0.0],
    ///     prediction: Prediction { radius: 1.01, poles: [Complex::new(0.0, 0.0); 4] },
    ///     outcome: RigOutcome::TooSlow { y_end_mm: 12.0 },
    /// };
    /// assert!(run.prediction_agrees());
    /// ```
    pub fn prediction_agrees(&self) -> bool {
        self.prediction.is_stable() == self.outcome.is_settled()
    }
}

/// How a group's overshoot changes from its first settled row to its last.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum OvershootTrend {
    /// Down by more than a fifth: the gain damps the response (%, from, to).
    Damps {
        /// First settled row's overshoot, %.
        from: f64,
        /// Last settled row's, %.
        to: f64,
    },
    /// Up by more than a fifth: less damping (%, from, to).
    Grows {
        /// First settled row's overshoot, %.
        from: f64,
        /// Last settled row's, %.
        to: f64,
    },
}

/// What a group of rows says about the gain it varies.
///
/// # Examples
///
/// ```
/// use ctrlab::StepInfo;
/// use ctrlab::lab::tables::{GroupEffect, OvershootTrend, RigOutcome, TABLE5};
///
/// let settled = |overshoot: f64, error: f64| RigOutcome::Settled(StepInfo {
///     overshoot,
///     steady_state_error: Some(error),
///     rise_time: 0.1, settling_time: 0.5, transient_time: 0.5, settling_min: 27.0,
///     settling_max: 31.0, undershoot: 0.0, peak: 31.0, peak_time: 0.2,
///     steady_state_value: 30.0 - error,
/// });
/// let kf3 = &TABLE5.groups[0];
/// let outcomes = [settled(0.0, 20.0), settled(1.0, 8.0), settled(2.0, 5.0),
///                 settled(5.0, 1.5), RigOutcome::TooSlow { y_end_mm: 29.0 }];
/// let e = GroupEffect::of(kf3, &outcomes);
/// assert_eq!(e.error_shrinks, Some((20.0, 1.5)));
/// assert_eq!(e.overshoot, Some(OvershootTrend::Grows { from: 0.0, to: 5.0 }));
/// assert_eq!(e.not_settled, [10.0]);
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct GroupEffect {
    /// The gain varied.
    pub varied: Gain,
    /// Its values, row by row.
    pub values: Vec<f64>,
    /// Each row's metrics (mm), `None` where it did not settle.
    pub steps: Vec<Option<StepInfo>>,
    /// |steady-state error| (mm) of the first and last settled rows, when
    /// the last is below four fifths of the first: raising the gain
    /// shrinks the error.
    pub error_shrinks: Option<(f64, f64)>,
    /// How the overshoot changes, when it does by more than a fifth.
    pub overshoot: Option<OvershootTrend>,
    /// The values at which the run did not settle.
    pub not_settled: Vec<f64>,
}

impl GroupEffect {
    /// The effect of `group`'s gain from its rows' `outcomes` (in the
    /// group's order; fewer outcomes than rows, when the lab stopped
    /// early, use the rows that have one).
    pub fn of(group: &GainGroup, outcomes: &[RigOutcome]) -> Self {
        let n = group.values.len().min(outcomes.len());
        let values = group.values[..n].to_vec();
        let steps: Vec<Option<StepInfo>> =
            outcomes[..n].iter().map(|o| o.step().copied()).collect();
        let not_settled = values
            .iter()
            .zip(&steps)
            .filter(|(_, s)| s.is_none())
            .map(|(v, _)| *v)
            .collect();
        let measured: Vec<&StepInfo> = steps.iter().flatten().collect();
        let (mut error_shrinks, mut overshoot) = (None, None);
        if let (Some(first), Some(last)) = (measured.first(), measured.last())
            && measured.len() > 1
        {
            let (e0, e1) = (
                first.steady_state_error.unwrap_or(f64::NAN).abs(),
                last.steady_state_error.unwrap_or(f64::NAN).abs(),
            );
            if e1 < 0.8 * e0 {
                error_shrinks = Some((e0, e1));
            }
            let (from, to) = (first.overshoot, last.overshoot);
            if to < 0.8 * from {
                overshoot = Some(OvershootTrend::Damps { from, to });
            } else if to > 1.2 * from {
                overshoot = Some(OvershootTrend::Grows { from, to });
            }
        }
        Self {
            varied: group.varied,
            values,
            steps,
            error_shrinks,
            overshoot,
            not_settled,
        }
    }
}
