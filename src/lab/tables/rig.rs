//! Tables 5 and 6 on the rig: what the identified model predicts for a row,
//! how a run ended, and what a group of rows says about its gain.

use super::{Gain, GainGroup, Noise, Prediction, Trend};
use crate::data::Recording;
use crate::error::Error;
use crate::hw::{LoopFault, RigError};
use crate::lab::{self, Cart};
use crate::metrics::{StepInfo, StepInfoOptions, step_info};

/// Why a run stopped before its end, or has no metrics.
///
/// # Examples
///
/// ```
/// use ctrlab::Recording;
/// use ctrlab::hw::{LoopFault, RigError};
/// use ctrlab::lab::tables::{Halt, RigOutcome};
/// # let rec = Recording::from_columns(ctrlab::lab::schema(), vec![0.0, 0.002], vec![vec![0.0; 2]; 5])?;
/// let stop = RigError::Fault(LoopFault::Interrupted { at: 0.002 });
/// let RigOutcome::Diverged { at, why } = RigOutcome::halted(&rec, &stop) else { unreachable!() };
/// assert_eq!(at, 0.002); // s
/// assert!(matches!(why, Halt::Fault(message) if message.contains("interrupted")));
/// # Ok::<(), ctrlab::Error>(())
/// ```
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
///
/// # Examples
///
/// ```
/// use ctrlab::Recording;
/// use ctrlab::lab::{Cart, tables::{RigOutcome, SATURATED_OSCILLATION}};
/// // Cart 2 swinging ±5 mm about 30 mm at 2 Hz, the drive slammed ±24 V.
/// let t: Vec<f64> = (0..1500).map(|k| k as f64 * 0.002).collect();
/// let x2: Vec<f64> = t.iter().map(|t| 0.030 * (1.0 - (-t / 0.05).exp()) + 0.005 * (12.566 * t).sin()).collect();
/// let u: Vec<f64> = t.iter().map(|t| 24.0f64.copysign((12.566 * t).cos())).collect();
/// # let z = vec![0.0; 1500];
/// let rec = Recording::from_columns(ctrlab::lab::schema(), t, vec![u, z.clone(), z.clone(), x2, z])?;
/// let o = RigOutcome::classify(&rec, Cart::Two, 30.0, 24.0)?;
/// assert!(matches!(o, RigOutcome::Oscillating { saturated, .. } if saturated > SATURATED_OSCILLATION));
/// # Ok::<(), ctrlab::Error>(())
/// ```
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
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::{Cart, tables::RigOutcome};
    /// # use ctrlab::Recording;
    /// # // Cart 2 from rest to 30 mm, a first-order approach of 0.1 s.
    /// # let t: Vec<f64> = (0..1500).map(|k| k as f64 * 0.002).collect();
    /// # let x2: Vec<f64> = t.iter().map(|t| 0.030 * (1.0 - (-t / 0.1).exp())).collect();
    /// # let z = vec![0.0; 1500];
    /// # let rec = Recording::from_columns(ctrlab::lab::schema(), t, vec![vec![1.0; 1500], z.clone(), z.clone(), x2, z])?;
    /// let o = RigOutcome::classify(&rec, Cart::Two, 30.0, 24.0)?;
    /// let step = o.step().expect("settled");
    /// assert!(step.overshoot < 0.1 && step.steady_state_error.unwrap().abs() < 0.01); // %, mm
    /// assert!(step.settling_time > 0.35 && step.settling_time < 0.45); // s: 2 % at 4 time constants
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
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
            // A cart that ends where it started (a command inside the
            // friction) has no step to measure: too slow, not a failure.
            Err(Error::InvalidData { reason, .. }) if reason.starts_with("no step") => {
                unsettled(&y, rec.channel("u")?, volts_full_scale)
            }
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
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::{Cart, tables::RigOutcome};
    /// # use ctrlab::Recording;
    /// # // Cart 2 from rest to 30 mm, a first-order approach of 0.1 s.
    /// # let t: Vec<f64> = (0..1500).map(|k| k as f64 * 0.002).collect();
    /// # let x2: Vec<f64> = t.iter().map(|t| 0.030 * (1.0 - (-t / 0.1).exp())).collect();
    /// # let z = vec![0.0; 1500];
    /// # let rec = Recording::from_columns(ctrlab::lab::schema(), t, vec![vec![1.0; 1500], z.clone(), z.clone(), x2, z])?;
    /// let o = RigOutcome::classify(&rec, Cart::Two, 30.0, 24.0)?;
    /// assert!((o.step().unwrap().steady_state_value - 30.0).abs() < 0.01); // mm
    /// assert_eq!(RigOutcome::TooSlow { y_end_mm: 29.0 }.step(), None);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn step(&self) -> Option<&StepInfo> {
        match self {
            Self::Settled(info) => Some(info),
            _ => None,
        }
    }

    /// Whether the run settled.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::tables::RigOutcome;
    /// assert!(!RigOutcome::TooSlow { y_end_mm: 29.0 }.is_settled());
    /// assert!(!RigOutcome::Oscillating { lo_mm: 25.0, hi_mm: 35.0, saturated: 0.0 }.is_settled());
    /// ```
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
///
/// # Examples
///
/// ```
/// use ctrlab::lab::{Cart, MassSpring, tables::{Prediction, RigOutcome, RigRun}};
/// let kf = [0.0, 0.0, 10.0, 0.1];
/// let prediction = Prediction::of(&MassSpring::nominal(), kf, Cart::Two, 0.002)?;
/// // Predicted stable, but friction held the cart short of the 2 % band.
/// let run = RigRun { kf, prediction, outcome: RigOutcome::TooSlow { y_end_mm: 27.5 } };
/// assert!(run.prediction.is_stable() && !run.prediction_agrees());
/// # Ok::<(), ctrlab::Error>(())
/// ```
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
    ///     prediction: Prediction {
    ///         radius: 1.01,
    ///         dominant: Complex::new(1.01, 0.0),
    ///         poles: [Complex::new(0.0, 0.0); 4],
    ///         dc_gain: f64::NAN,
    ///         compliance: [f64::NAN; 2],
    ///     },
    ///     outcome: RigOutcome::TooSlow { y_end_mm: 12.0 },
    /// };
    /// assert!(run.prediction_agrees());
    /// ```
    pub fn prediction_agrees(&self) -> bool {
        self.prediction.is_stable() == self.outcome.is_settled()
    }
}

// What two runs of one row differ by, measured on the default simulated
// rig (tests/lab_tables.rs::repeated_runs_of_a_row_spread_within_the_noise):
// every settled row of Tables 5 and 6 on ten seeds (each run its own
// friction draw, σ = 5 %, and encoder noise), the widest spread as a
// fraction of the larger value: overshoot 0.32 (Table 5's Kf = [0 0 0.5 0]:
// 13.8–20.3 %; small ones 1.04 points apart, [0 0 0.1 0]: 0.35–1.39 %),
// settling time 0.29 (Table 6's [1 0 0 0.2]: 1.62–2.28 s), steady-state
// error 0.20 (Table 5's [0 0 10 0]: 1.15–1.44 mm). A cart rests anywhere in
// its friction band, and a slow approach meets the 2 % band when the
// friction lets it. The constants round those up.

/// Overshoot's noise between two rig runs: 35 % of the larger, at least
/// 1.5 percentage points.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::tables::OVERSHOOT_NOISE;
/// assert_eq!(OVERSHOOT_NOISE.between(13.8, 20.3), 0.35 * 20.3); // %: the measured spread is noise
/// assert_eq!(OVERSHOOT_NOISE.between(0.35, 1.39), 1.5); // small overshoots: the floor
/// ```
pub const OVERSHOOT_NOISE: Noise = Noise {
    relative: 0.35,
    floor: 1.5,
};
/// Settling time's noise between two rig runs: 35 % of the larger, at
/// least 0.01 s (five periods).
///
/// # Examples
///
/// ```
/// use ctrlab::lab::{protocol::PERIOD, tables::SETTLING_NOISE};
/// assert!((SETTLING_NOISE.floor / PERIOD - 5.0).abs() < 1e-12);
/// assert!(2.28 - 1.62 <= SETTLING_NOISE.between(1.62, 2.28)); // s: within the noise
/// ```
pub const SETTLING_NOISE: Noise = Noise {
    relative: 0.35,
    floor: 0.01,
};
/// Steady-state error's noise between two rig runs: 25 % of the larger, at
/// least 0.05 mm (five encoder counts of 9.77 µm).
///
/// # Examples
///
/// ```
/// use ctrlab::lab::{Calibration, tables::ERROR_NOISE};
/// let count_mm = Calibration::default().metres_per_count * 1e3;
/// assert!((ERROR_NOISE.floor / count_mm - 5.0).abs() < 0.2); // about five counts
/// assert!(1.44 - 1.15 <= ERROR_NOISE.between(1.15, 1.44)); // mm: within the noise
/// ```
pub const ERROR_NOISE: Noise = Noise {
    relative: 0.25,
    floor: 0.05,
};

/// What a group of rows says about the gain it varies: each metric's
/// [`Trend`] over every settled row, changes within what two runs of one
/// row differ by taken as noise ([`OVERSHOOT_NOISE`], [`SETTLING_NOISE`],
/// [`ERROR_NOISE`]).
///
/// # Examples
///
/// ```
/// use ctrlab::StepInfo;
/// use ctrlab::lab::tables::{GroupEffect, RigOutcome, Trend, TABLE5};
///
/// let settled = |overshoot: f64, error: f64| RigOutcome::Settled(StepInfo {
///     overshoot,
///     steady_state_error: Some(error),
///     rise_time: 0.1, settling_time: 0.5, transient_time: 0.5, settling_min: 27.0,
///     settling_max: 31.0, undershoot: 0.0, peak: 31.0, peak_time: 0.2,
///     steady_state_value: 30.0 - error,
/// });
/// let kf3 = &TABLE5.groups[0];
/// let outcomes = [settled(0.4, 20.0), settled(18.7, 8.0), settled(34.1, 5.0),
///                 settled(20.0, 1.5), RigOutcome::TooSlow { y_end_mm: 29.0 }];
/// let e = GroupEffect::of(kf3, &outcomes);
/// assert_eq!(e.settled(), [0.1, 0.5, 1.0, 5.0]);
/// assert_eq!(e.steady_state_error, Some(Trend::Falls { from: 20.0, to: 1.5 }));
/// assert!(matches!(e.overshoot, Some(Trend::Peaks { at: 2, .. })));
/// assert!(matches!(e.settling_time, Some(Trend::Flat { .. })));
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
    /// Overshoot (%) over the settled rows; `None` with fewer than two.
    pub overshoot: Option<Trend>,
    /// Settling time (s) over the settled rows.
    pub settling_time: Option<Trend>,
    /// Steady-state error (mm, signed) over the settled rows.
    pub steady_state_error: Option<Trend>,
    /// The values at which the run did not settle.
    pub not_settled: Vec<f64>,
}

impl GroupEffect {
    /// The effect of `group`'s gain from its rows' `outcomes` (in the
    /// group's order; fewer outcomes than rows, when the lab stopped
    /// early, use the rows that have one).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::tables::{GroupEffect, RigOutcome, TABLE6};
    /// let kf4 = &TABLE6.groups[2];
    /// // The lab stopped after two rows, neither settled.
    /// let outcomes = [RigOutcome::TooSlow { y_end_mm: 14.0 }, RigOutcome::TooSlow { y_end_mm: 14.5 }];
    /// let e = GroupEffect::of(kf4, &outcomes);
    /// assert_eq!((e.values.len(), e.not_settled.clone()), (2, vec![0.01, 0.02]));
    /// assert_eq!(e.overshoot, None); // no trend without two settled rows
    /// ```
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
        let trend = |figure: fn(&StepInfo) -> f64, noise: Noise| {
            let series: Vec<f64> = measured.iter().map(|s| figure(s)).collect();
            Trend::of(&series, noise)
        };
        Self {
            varied: group.varied,
            overshoot: trend(|s| s.overshoot, OVERSHOOT_NOISE),
            settling_time: trend(|s| s.settling_time, SETTLING_NOISE),
            steady_state_error: trend(|s| s.steady_state_error.unwrap_or(f64::NAN), ERROR_NOISE),
            values,
            steps,
            not_settled,
        }
    }

    /// The gain's values at the settled rows, in order: what a
    /// [`Trend`]'s index counts.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::StepInfo;
    /// use ctrlab::lab::tables::{GroupEffect, RigOutcome, TABLE5};
    /// # let info = StepInfo { overshoot: 5.0, steady_state_error: Some(1.0), rise_time: 0.1, settling_time: 0.5,
    /// #     transient_time: 0.5, settling_min: 28.0, settling_max: 30.5, undershoot: 0.0, peak: 30.5,
    /// #     peak_time: 0.2, steady_state_value: 29.0 };
    /// let slow = RigOutcome::TooSlow { y_end_mm: 20.0 };
    /// let outcomes = [slow.clone(), RigOutcome::Settled(info), slow, RigOutcome::Settled(info)];
    /// let e = GroupEffect::of(&TABLE5.groups[0], &outcomes); // Kf3 = 0.1, 0.5, 1, 5
    /// assert_eq!(e.settled(), [0.5, 5.0]);
    /// ```
    pub fn settled(&self) -> Vec<f64> {
        self.values
            .iter()
            .zip(&self.steps)
            .filter(|(_, s)| s.is_some())
            .map(|(v, _)| *v)
            .collect()
    }
}
