//! An identification input that respects the rig: which signal, its peak
//! voltage and (for the square wave) its half period ([`IdentInput`]), and
//! the amplitude that keeps both carts inside their travel
//! ([`AmplitudeSearch`], its result [`AmplitudeChoice`]).
//!
//! # How the amplitude is chosen
//!
//! Two short probe runs of the same signal come first, at
//! [`PROBE_FRACTIONS`] of the amplitude asked for (the second lowered if
//! the first already says it would go too far). Each gives both carts'
//! peak |x| ([`peaks`]). Above the friction the response grows linearly
//! with the amplitude, but Coulomb friction takes a fixed force off it, so
//! the peak is affine in the volts, `p(V) ≈ s·(V − V₀)`, not proportional.
//! Each cart's peak at `V` is predicted ([`predict`]) as the larger of the
//! line through the two probes and the line through the origin and the
//! larger probe: the affine line where friction makes the small probe
//! move less, the proportional one (never below it) when noise makes the
//! probes look concave. The amplitude is then the largest, up to the one
//! asked for, whose predicted peak on either cart is at most
//! [`TRAVEL_FRACTION`] of its travel limit
//! ([`Calibration::travel_limits`](super::Calibration::travel_limits)),
//! rounded down to 10 mV.
//!
//! How well, measured on the simulated rigs (`tests/lab_ident_input.rs`):
//! where the travel limits the amplitude, the runs' peak is within 3 % of
//! the prediction (the square wave: −1.3 % on the default rig, −0.3 % on a
//! lighter-damped one; a PRBS +2.5 %). Where the amplitude asked for fits,
//! the prediction is farther off (a multisine whose probes barely clear
//! the friction: +45 %) but far from the limit.
//!
//! # Examples
//!
//! ```
//! use ctrlab::lab::ident_input::{AmplitudeSearch, ProbeFault, Reason};
//! // A rig whose carts move 5 mm per volt above 1 V of friction, limits ±50 mm.
//! let rig = |volts: f64| Ok::<_, ProbeFault>([0.0, 0.005 * (volts - 1.0).max(0.0)]);
//! let choice = AmplitudeSearch::new(8.0, [0.05, 0.05])?.run(rig)?;
//! // 60 % of 50 mm is 30 mm: 5 mm/V × (V − 1 V) = 30 mm at 7 V.
//! assert!((choice.volts - 7.0).abs() < 1e-9);
//! assert_eq!(choice.reason, Reason::Scaled { cart: 1 });
//! assert!((choice.predicted.unwrap()[1] - 0.030).abs() < 1e-12);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use std::cmp::Ordering;
use std::fmt;
use std::str::FromStr;

use super::excitation::{Input, MULTISINE_LINES, PRBS_BITS, PRBS_CLOCK, PRBS_SEED};
use super::protocol::{IDENT_HALF_PERIOD, IDENT_VOLTS, PERIOD};
use crate::Recording;
use crate::error::Error;
use crate::hw::{ConfigError, LoopFault, RigError};
use crate::signal::{Multisine, Phases, Prbs, SquareWave};

mod runs;
mod search;

pub use runs::{CompletedRun, HaltedRun, IdentRuns, RunFault, TooFewRuns};
pub use search::{
    AmplitudeChoice, AmplitudeSearch, Probe, ProbeFault, ProbeOutcome, Reason, predict,
};

/// The largest predicted peak excursion of either cart, as a fraction of
/// its travel limit: 60 %.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::{Calibration, ident_input::TRAVEL_FRACTION};
/// // On the default ±50 mm travel a run may be predicted to swing 30 mm.
/// let limit = Calibration::default().travel_limits[1];
/// assert!((TRAVEL_FRACTION * limit - 0.030).abs() < 1e-15); // m
/// ```
pub const TRAVEL_FRACTION: f64 = 0.6;

/// The probe runs' amplitudes, as fractions of the amplitude asked for.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::{ident_input::PROBE_FRACTIONS, protocol::IDENT_VOLTS};
/// // Asked for the lab's 8 V, the probes run at 2 V and 4 V: both well
/// // under it, and apart, to see the friction's offset.
/// assert_eq!(PROBE_FRACTIONS.map(|f| f * IDENT_VOLTS), [2.0, 4.0]);
/// ```
pub const PROBE_FRACTIONS: [f64; 2] = [0.25, 0.5];

/// Each probe run's length, s: long enough for the square wave's response
/// near the first mode to build up. On the default and the lighter-damped
/// rig of `tests/lab_ident_input.rs` a 3 s probe sees the same peaks as a
/// whole 5 s run; a PRBS's cart 1 peaks later (4.7 s: at 4 V on the
/// lighter rig the probe sees 11.8 of its 13.3 mm), which is why a PRBS's
/// prediction is the least close (+2.5 % where it limits the amplitude).
///
/// # Examples
///
/// ```
/// use ctrlab::lab::ident_input::PROBE_DURATION;
/// use ctrlab::lab::protocol::{IDENT_DURATION, IDENT_HALF_PERIOD, PERIOD};
/// assert!(PROBE_DURATION < IDENT_DURATION); // s
/// // 15 half periods of the square wave, 1500 loop periods.
/// assert!((PROBE_DURATION / IDENT_HALF_PERIOD - 15.0).abs() < 1e-12);
/// assert!((PROBE_DURATION / PERIOD - 1500.0).abs() < 1e-9);
/// ```
pub const PROBE_DURATION: f64 = 3.0;

/// The identification signal.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::ident_input::IdentSignal;
/// assert_eq!("prbs".parse::<IdentSignal>()?, IdentSignal::Prbs);
/// assert_eq!(IdentSignal::Multisine.to_string(), "multisine");
/// assert!("sine".parse::<IdentSignal>().is_err());
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Hash, Default, serde::Serialize, serde::Deserialize,
)]
#[serde(rename_all = "lowercase")]
pub enum IdentSignal {
    /// The lab's square wave (±volts, a half period).
    #[default]
    Square,
    /// A maximum-length PRBS ([`PRBS_CLOCK`], [`PRBS_BITS`], [`PRBS_SEED`]).
    Prbs,
    /// A Schroeder-phased multisine ([`MULTISINE_LINES`] of one over the
    /// run's length) scaled to the peak.
    Multisine,
}

impl IdentSignal {
    /// Every signal, in the order the command line lists them.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::ident_input::IdentSignal;
    /// assert_eq!(IdentSignal::ALL[0], IdentSignal::default());
    /// ```
    pub const ALL: [Self; 3] = [Self::Square, Self::Prbs, Self::Multisine];

    /// Its name on the command line and in files.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::ident_input::IdentSignal;
    /// assert_eq!(IdentSignal::Square.name(), "square");
    /// ```
    pub fn name(self) -> &'static str {
        match self {
            Self::Square => "square",
            Self::Prbs => "prbs",
            Self::Multisine => "multisine",
        }
    }
}

impl fmt::Display for IdentSignal {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for IdentSignal {
    type Err = Error;

    fn from_str(s: &str) -> Result<Self, Error> {
        Self::ALL
            .into_iter()
            .find(|k| k.name() == s)
            .ok_or(Error::InvalidParameter {
                name: "signal",
                value: f64::NAN,
                reason: "must be square, prbs or multisine",
            })
    }
}

/// The identification input asked for: the signal, its peak voltage (the
/// largest the scaling may choose), the square wave's half period, and
/// whether to scale the amplitude to the travel. The optional `[ident]`
/// table of a card file ([`RigConfig`](super::RigConfig)); each key
/// defaults. The default is the lab's: a ±8 V square wave of 0.2 s half
/// period, scaled to the travel.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::ident_input::{IdentInput, IdentSignal};
/// let input = IdentInput::default();
/// assert_eq!((input.signal, input.volts, input.half_period), (IdentSignal::Square, 8.0, 0.2));
/// let bad = IdentInput { volts: -1.0, ..input };
/// assert_eq!(bad.validate().unwrap_err().key(), "volts");
/// ```
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct IdentInput {
    /// The signal.
    pub signal: IdentSignal,
    /// Peak voltage asked for, V (finite, > 0, at most 1000 V): the
    /// amplitude when it fits the travel, the largest the scaling chooses.
    pub volts: f64,
    /// The square wave's half period, s (finite, at least the loop's
    /// period [`PERIOD`], at most 10 s); the other signals ignore it.
    pub half_period: f64,
    /// Probe runs first and the amplitude scaled to the travel (true), or
    /// `volts` as is (false).
    pub scale_to_travel: bool,
}

impl Default for IdentInput {
    fn default() -> Self {
        Self {
            signal: IdentSignal::Square,
            volts: IDENT_VOLTS,
            half_period: IDENT_HALF_PERIOD,
            scale_to_travel: true,
        }
    }
}

impl IdentInput {
    /// Whether this is the default (a card file without `[ident]` writes
    /// none).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::ident_input::IdentInput;
    /// assert!(IdentInput::default().is_default());
    /// assert!(!IdentInput { volts: 4.0, ..Default::default() }.is_default());
    /// ```
    pub fn is_default(&self) -> bool {
        *self == Self::default()
    }

    /// Checks the values: `volts` finite, > 0 and at most 1000 V;
    /// `half_period` finite, at least [`PERIOD`] and at most 10 s.
    ///
    /// # Errors
    ///
    /// [`ConfigError`] naming the key (`volts`, `half_period`; a card file
    /// names it `ident.volts`).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::ident_input::IdentInput;
    /// let bad = IdentInput { half_period: 0.001, ..Default::default() };
    /// assert_eq!(bad.validate().unwrap_err().key(), "half_period");
    /// assert!(IdentInput::default().validate().is_ok());
    /// ```
    pub fn validate(&self) -> Result<(), ConfigError> {
        if !(self.volts.is_finite() && self.volts > 0.0 && self.volts <= 1000.0) {
            return Err(ConfigError::invalid(
                "volts",
                self.volts,
                "must be finite, > 0 and at most 1000 V",
            ));
        }
        let h = self.half_period;
        if !(h.is_finite() && (PERIOD..=10.0).contains(&h)) {
            return Err(ConfigError::invalid(
                "half_period",
                h,
                "must be finite, at least the loop's period (0.002 s) and at most 10 s",
            ));
        }
        Ok(())
    }

    /// Checks `volts` against the drive's range: at most
    /// `volts_full_scale` (V,
    /// [`Calibration::volts_full_scale`](super::Calibration::volts_full_scale)).
    /// Above it the drive saturates: the run is not the signal asked for
    /// (a square wave becomes a bang-bang at the limit, a PRBS or a
    /// multisine is clipped), and the amplitude the probes choose would be
    /// scaled from a signal the rig never gives.
    ///
    /// # Errors
    ///
    /// [`ConfigError::Conflict`] naming `volts` (a card file names it
    /// `ident.volts`; lab5's `--ident-volts` says so too).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::ConfigErrorKind;
    /// use ctrlab::lab::ident_input::IdentInput;
    /// let too_big = IdentInput { volts: 30.0, ..Default::default() };
    /// let err = too_big.check_drive(24.0).unwrap_err();
    /// assert_eq!((err.kind(), err.key(), err.value()), (ConfigErrorKind::Conflict, "volts", 30.0));
    /// assert!(IdentInput { volts: 24.0, ..Default::default() }.check_drive(24.0).is_ok());
    /// ```
    pub fn check_drive(&self, volts_full_scale: f64) -> Result<(), ConfigError> {
        // Not `>`: a NaN full scale (refused by the calibration's own
        // check) must not let any amplitude through.
        let within = self.volts.partial_cmp(&volts_full_scale);
        if !matches!(within, Some(Ordering::Less | Ordering::Equal)) {
            return Err(ConfigError::conflict(
                "volts",
                self.volts,
                "must be at most the drive's full scale (calibration volts_full_scale): above it the drive saturates and the input is not the one asked for",
            ));
        }
        Ok(())
    }

    /// The signal at `volts` peak for runs of `duration` s (the multisine's
    /// lines are harmonics of `1 / duration`).
    ///
    /// # Errors
    ///
    /// [`Error::InvalidParameter`] for a non-positive or non-finite
    /// `volts`, `duration` or half period.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::ident_input::{IdentInput, IdentSignal};
    /// let prbs = IdentInput { signal: IdentSignal::Prbs, ..Default::default() };
    /// let input = prbs.input(2.0, 5.0)?;
    /// assert!((input.peak(0.002, 5.0) - 2.0).abs() < 1e-12);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn input(&self, volts: f64, duration: f64) -> Result<Input, Error> {
        Ok(match self.signal {
            IdentSignal::Square => Input::Square(SquareWave::new(volts, self.half_period)?),
            IdentSignal::Prbs => Input::Prbs(Prbs::new(volts, PRBS_CLOCK, PRBS_BITS, PRBS_SEED)?),
            IdentSignal::Multisine => {
                let unit = Multisine::new(1.0, duration, MULTISINE_LINES, Phases::Schroeder)?;
                Input::Multisine(Multisine::new(
                    volts / unit.peak(),
                    duration,
                    MULTISINE_LINES,
                    Phases::Schroeder,
                )?)
            }
        })
    }
}

/// Both carts' largest |position| in `recording` (channels `x1`, `x2`), m.
///
/// # Errors
///
/// [`Error`] when a channel is missing.
///
/// # Examples
///
/// ```
/// use ctrlab::Recording;
/// use ctrlab::lab::ident_input::peaks;
/// let rec = Recording::read_csv(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ident_square_wave.csv"))?;
/// let [p1, p2] = peaks(&rec)?;
/// // The fixture's largest |x1| and |x2|: 53.98 mm and 76.38 mm.
/// assert!((p1 - 0.05398).abs() < 1e-5 && (p2 - 0.07638).abs() < 1e-5);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn peaks(recording: &Recording) -> Result<[f64; 2], Error> {
    let peak = |name| -> Result<f64, Error> {
        Ok(recording
            .channel(name)?
            .iter()
            .fold(0.0, |m: f64, x| m.max(x.abs())))
    };
    Ok([peak("x1")?, peak("x2")?])
}

/// Whether the rig halted a run because its input was too big for the
/// rig: a cart past its travel limit ([`LoopFault::TravelLimit`]) or the
/// drive held at its limit too long ([`LoopFault::Saturated`]). A smaller
/// amplitude is the answer to these, and the other runs may go on; any
/// other fault (a bus fault, a dead encoder, a motor not responding, a
/// timing gap, Ctrl-C, a panic, a port error) says the rig or the program
/// is not fit to measure, and no run after it means anything.
///
/// # Examples
///
/// ```
/// use ctrlab::hw::{LoopFault, RigError};
/// use ctrlab::lab::ident_input::input_too_big;
/// let travel = RigError::Fault(LoopFault::TravelLimit { axis: 2, position: 0.051, limit: 0.05 });
/// assert!(input_too_big(&travel));
/// let stopped = RigError::Fault(LoopFault::Interrupted { at: 1.0 });
/// assert!(!input_too_big(&stopped));
/// ```
pub fn input_too_big(error: &RigError) -> bool {
    matches!(
        error,
        RigError::Fault(LoopFault::TravelLimit { .. } | LoopFault::Saturated { .. })
    )
}
