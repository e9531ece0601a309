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
//! use ctrlab::lab::ident_input::{AmplitudeSearch, Reason};
//! // A rig whose carts move 5 mm per volt above 1 V of friction, limits ±50 mm.
//! let rig = |volts: f64| Ok::<_, ctrlab::Error>([0.0, 0.005 * (volts - 1.0).max(0.0)]);
//! let choice = AmplitudeSearch::new(8.0, [0.05, 0.05])?.run(rig)?;
//! // 60 % of 50 mm is 30 mm: 5 mm/V × (V − 1 V) = 30 mm at 7 V.
//! assert!((choice.volts - 7.0).abs() < 1e-9);
//! assert_eq!(choice.reason, Reason::Scaled { cart: 1 });
//! assert!((choice.predicted.unwrap()[1] - 0.030).abs() < 1e-12);
//! # Ok::<(), ctrlab::Error>(())
//! ```

use std::fmt;
use std::str::FromStr;

use super::excitation::{Input, MULTISINE_LINES, PRBS_BITS, PRBS_CLOCK, PRBS_SEED};
use super::protocol::{IDENT_HALF_PERIOD, IDENT_VOLTS, PERIOD};
use crate::Recording;
use crate::error::Error;
use crate::hw::{ConfigError, RigError, RunError};
use crate::signal::{Multisine, Phases, Prbs, SquareWave};

/// The largest predicted peak excursion of either cart, as a fraction of
/// its travel limit: 60 %.
pub const TRAVEL_FRACTION: f64 = 0.6;

/// The probe runs' amplitudes, as fractions of the amplitude asked for.
pub const PROBE_FRACTIONS: [f64; 2] = [0.25, 0.5];

/// Each probe run's length, s: long enough for the square wave's response
/// near the first mode to build up. On the default and the lighter-damped
/// rig of `tests/lab_ident_input.rs` a 3 s probe sees the same peaks as a
/// whole 5 s run; a PRBS's cart 1 peaks later (4.7 s: at 4 V on the
/// lighter rig the probe sees 11.8 of its 13.3 mm), which is why a PRBS's
/// prediction is the least close (+2.5 % where it limits the amplitude).
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

/// A probe run: its amplitude and both carts' peak |x|.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::ident_input::Probe;
/// let p = Probe { volts: 2.0, peaks: [0.004, 0.008] };
/// assert_eq!(p.peaks[1] / p.volts, 0.004);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Probe {
    /// Peak voltage, V.
    pub volts: f64,
    /// Cart 1's and cart 2's largest |position|, m.
    pub peaks: [f64; 2],
}

/// Each cart's predicted peak |x| at `volts` from `probes` (in increasing
/// volts; see [the module](self#how-the-amplitude-is-chosen)), m: the
/// larger of the line through the last two probes and the line through
/// the origin and the last probe. `None` without probes.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::ident_input::{Probe, predict};
/// let probes = [
///     Probe { volts: 2.0, peaks: [0.001, 0.004] },
///     Probe { volts: 4.0, peaks: [0.002, 0.010] },
/// ];
/// let p = predict(&probes, 8.0).unwrap();
/// // Cart 1 is proportional (4 mm); cart 2 affine, 3 mm/V (22 mm).
/// assert!((p[0] - 0.004).abs() < 1e-12 && (p[1] - 0.022).abs() < 1e-12);
/// ```
pub fn predict(probes: &[Probe], volts: f64) -> Option<[f64; 2]> {
    let lines = lines(probes)?;
    Some(lines.map(|cart| {
        cart.iter()
            .map(|l| l.slope * volts + l.intercept)
            .fold(0.0, f64::max)
    }))
}

/// A line of peak against volts: `slope` m/V, `intercept` m.
#[derive(Debug, Clone, Copy)]
struct Line {
    slope: f64,
    intercept: f64,
}

impl Line {
    /// The largest volts at which the line is at most `peak` m (infinite
    /// for a flat line: a cart the probes did not move).
    fn volts_at(self, peak: f64) -> f64 {
        if self.slope > 0.0 {
            (peak - self.intercept) / self.slope
        } else {
            f64::INFINITY
        }
    }
}

/// Each cart's two lines: through the origin and the last probe, and
/// through the last two probes (the first when the probes look concave or
/// there is one).
fn lines(probes: &[Probe]) -> Option<[[Line; 2]; 2]> {
    let last = *probes.last()?;
    let before = probes.len().checked_sub(2).map(|i| probes[i]);
    Some([0, 1].map(|c| {
        let proportional = Line {
            slope: last.peaks[c] / last.volts,
            intercept: 0.0,
        };
        let affine = before
            .map(|b| (last.peaks[c] - b.peaks[c]) / (last.volts - b.volts))
            .filter(|s| s.is_finite() && *s > proportional.slope)
            .map_or(proportional, |slope| Line {
                slope,
                intercept: last.peaks[c] - slope * last.volts,
            });
        [proportional, affine]
    }))
}

/// Why the amplitude is what it is.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::ident_input::Reason;
/// assert_eq!(Reason::Scaled { cart: 1 }.to_string(), "scaled so that cart 2's predicted peak is 60 % of its travel limit");
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Reason {
    /// As asked, without probe runs ([`IdentInput::scale_to_travel`]
    /// false).
    Fixed,
    /// As asked: its predicted peaks are within [`TRAVEL_FRACTION`] of the
    /// travel limits.
    Fits,
    /// Lowered so that cart `cart`'s (0 or 1) predicted peak is
    /// [`TRAVEL_FRACTION`] of its travel limit.
    Scaled {
        /// The cart that limits it, 0 or 1.
        cart: usize,
    },
    /// As asked, unpredicted: neither probe moved either cart (friction
    /// held them), so the probes say nothing of the amplitude asked for.
    NoMotion,
}

impl fmt::Display for Reason {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Reason::Fixed => f.write_str("as asked, not scaled to the travel"),
            Reason::Fits => write!(
                f,
                "as asked: its predicted peaks are within {:.0} % of the travel limits",
                TRAVEL_FRACTION * 100.0
            ),
            Reason::Scaled { cart } => write!(
                f,
                "scaled so that cart {}'s predicted peak is {:.0} % of its travel limit",
                cart + 1,
                TRAVEL_FRACTION * 100.0
            ),
            Reason::NoMotion => f.write_str(
                "as asked, unpredicted: the probe runs did not move the carts past their friction",
            ),
        }
    }
}

/// The amplitude chosen and why: the probes behind it and what they
/// predict.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::ident_input::{AmplitudeChoice, Reason};
/// let fixed = AmplitudeChoice::fixed(8.0, [0.05, 0.05]);
/// assert_eq!((fixed.volts, fixed.reason), (8.0, Reason::Fixed));
/// assert!(fixed.probes.is_empty() && fixed.predicted.is_none());
/// assert_eq!(fixed.allowed(), [0.03, 0.03]);
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct AmplitudeChoice {
    /// The peak voltage asked for, V.
    pub asked: f64,
    /// The peak voltage chosen, V (at most `asked`; when scaled, rounded
    /// down to 10 mV).
    pub volts: f64,
    /// Why.
    pub reason: Reason,
    /// The probe runs, in the order they ran (none for
    /// [`Reason::Fixed`]).
    pub probes: Vec<Probe>,
    /// Each cart's predicted peak |x| at `volts`, m (none without probes).
    pub predicted: Option<[f64; 2]>,
    /// Each cart's predicted peak |x| at `asked`, m.
    pub predicted_asked: Option<[f64; 2]>,
    /// The carts' travel limits, m.
    pub limits: [f64; 2],
}

impl AmplitudeChoice {
    /// `asked` as is, without probes ([`Reason::Fixed`]), on a rig with
    /// travel limits `limits` (m).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::ident_input::AmplitudeChoice;
    /// assert_eq!(AmplitudeChoice::fixed(12.0, [0.05, 0.04]).volts, 12.0);
    /// ```
    pub fn fixed(asked: f64, limits: [f64; 2]) -> Self {
        Self {
            asked,
            volts: asked,
            reason: Reason::Fixed,
            probes: Vec::new(),
            predicted: None,
            predicted_asked: None,
            limits,
        }
    }

    /// The largest predicted peak allowed per cart, m: [`TRAVEL_FRACTION`]
    /// of each travel limit.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::ident_input::AmplitudeChoice;
    /// assert_eq!(AmplitudeChoice::fixed(8.0, [0.05, 0.04]).allowed()[1], 0.6 * 0.04);
    /// ```
    pub fn allowed(&self) -> [f64; 2] {
        self.limits.map(|l| TRAVEL_FRACTION * l)
    }
}

/// The probe runs and the choice: ask for `asked` V on a rig with travel
/// limits `limits` m, then [`run`](Self::run) the probes.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::ident_input::{AmplitudeSearch, Reason};
/// // 2 mm per volt on cart 2, no friction: 8 V is 16 mm, within 30 mm.
/// let choice = AmplitudeSearch::new(8.0, [0.05, 0.05])?
///     .run(|v| Ok::<_, ctrlab::Error>([0.001 * v, 0.002 * v]))?;
/// assert_eq!((choice.volts, choice.reason), (8.0, Reason::Fits));
/// assert_eq!(choice.probes.iter().map(|p| p.volts).collect::<Vec<_>>(), [2.0, 4.0]);
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AmplitudeSearch {
    asked: f64,
    limits: [f64; 2],
}

impl AmplitudeSearch {
    /// A search up to `asked` V on travel limits `limits` m.
    ///
    /// # Errors
    ///
    /// [`Error::InvalidParameter`] for an `asked` or a limit that is not
    /// finite and > 0.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::ident_input::AmplitudeSearch;
    /// assert!(AmplitudeSearch::new(8.0, [0.05, 0.0]).is_err());
    /// assert!(AmplitudeSearch::new(f64::NAN, [0.05, 0.05]).is_err());
    /// ```
    pub fn new(asked: f64, limits: [f64; 2]) -> Result<Self, Error> {
        if !(asked.is_finite() && asked > 0.0) {
            return Err(Error::InvalidParameter {
                name: "volts",
                value: asked,
                reason: "must be finite and > 0 V",
            });
        }
        if let Some(&l) = limits.iter().find(|l| !(l.is_finite() && **l > 0.0)) {
            return Err(Error::InvalidParameter {
                name: "travel_limits",
                value: l,
                reason: "must be finite and > 0 m",
            });
        }
        Ok(Self { asked, limits })
    }

    /// The amplitude asked for, V.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::ident_input::AmplitudeSearch;
    /// assert_eq!(AmplitudeSearch::new(8.0, [0.05, 0.05])?.asked(), 8.0);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn asked(&self) -> f64 {
        self.asked
    }

    /// The largest amplitude whose predicted peaks from `probes` are
    /// within [`TRAVEL_FRACTION`] of the limits, V, and the cart that
    /// limits it (infinite and `None` when no probe moved a cart).
    fn largest(&self, probes: &[Probe]) -> (f64, Option<usize>) {
        let Some(lines) = lines(probes) else {
            return (f64::INFINITY, None);
        };
        let mut best = (f64::INFINITY, None);
        for (c, cart) in lines.iter().enumerate() {
            let allowed = TRAVEL_FRACTION * self.limits[c];
            for line in cart {
                let v = line.volts_at(allowed);
                if v < best.0 {
                    best = (v, Some(c));
                }
            }
        }
        best
    }

    /// Runs the probes with `probe` (which runs the signal at the volts
    /// it is given for [`PROBE_DURATION`] s and returns both carts' peak
    /// |x|, m: [`peaks`] of its recording, also when the run was halted)
    /// and chooses the amplitude.
    ///
    /// The first probe runs at `PROBE_FRACTIONS[0]` of the amplitude
    /// asked for; the second at `PROBE_FRACTIONS[1]`, lowered to what the
    /// first predicts is allowed (and left out if that is not above the
    /// first).
    ///
    /// # Errors
    ///
    /// `probe`'s own error, as it gives it.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::ident_input::{AmplitudeSearch, Reason};
    /// // 20 mm per volt: the first probe (2 V, 40 mm) is already too far.
    /// let choice = AmplitudeSearch::new(8.0, [0.05, 0.05])?
    ///     .run(|v| Ok::<_, ctrlab::Error>([0.0, 0.02 * v]))?;
    /// assert_eq!(choice.probes.len(), 1);
    /// assert!((choice.volts - 1.5).abs() < 1e-12);
    /// assert_eq!(choice.reason, Reason::Scaled { cart: 1 });
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn run<E>(
        &self,
        mut probe: impl FnMut(f64) -> Result<[f64; 2], E>,
    ) -> Result<AmplitudeChoice, E> {
        let mut probes = Vec::with_capacity(PROBE_FRACTIONS.len());
        for fraction in PROBE_FRACTIONS {
            let mut volts = fraction * self.asked;
            if !probes.is_empty() {
                volts = volts.min(self.largest(&probes).0);
                if probes.last().is_some_and(|p: &Probe| volts <= p.volts) {
                    break;
                }
            }
            let peaks = probe(volts)?;
            probes.push(Probe { volts, peaks });
        }
        let (largest, cart) = self.largest(&probes);
        let (volts, reason) = match cart {
            None => (self.asked, Reason::NoMotion),
            Some(_) if largest >= self.asked => (self.asked, Reason::Fits),
            // Down to 10 mV (below the drive's 24 mV step): a round
            // number to report, never above the prediction's.
            Some(cart) => (
                ((largest * 100.0).floor() / 100.0).max(0.0),
                Reason::Scaled { cart },
            ),
        };
        Ok(AmplitudeChoice {
            asked: self.asked,
            volts,
            reason,
            predicted: predict(&probes, volts),
            predicted_asked: predict(&probes, self.asked),
            probes,
            limits: self.limits,
        })
    }
}

/// An identification run that completed: its seed (its number in the
/// lab's order, from 1) and recording.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::ident_input::CompletedRun;
/// let run = CompletedRun { seed: 1, recording: ctrlab::Recording::new(ctrlab::lab::schema()) };
/// assert_eq!(run.seed, 1);
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct CompletedRun {
    /// The run's seed (its number, from 1).
    pub seed: u64,
    /// Its recording.
    pub recording: Recording,
}

/// An identification run the rig halted (a travel limit, say): its seed,
/// the loop's error and what it recorded up to the fault.
///
/// # Examples
///
/// ```
/// use ctrlab::hw::{LoopFault, RigError};
/// use ctrlab::lab::ident_input::HaltedRun;
/// let run = HaltedRun {
///     seed: 3,
///     error: RigError::Fault(LoopFault::TravelLimit { axis: 2, position: 0.0501, limit: 0.05 }),
///     recording: ctrlab::Recording::new(ctrlab::lab::schema()),
/// };
/// assert!(run.error.to_string().contains("beyond its travel limit"));
/// ```
#[derive(Debug)]
pub struct HaltedRun {
    /// The run's seed (its number, from 1).
    pub seed: u64,
    /// Why the rig halted it (a [`LoopFault::TravelLimit`] names the cart's
    /// axis, its position and the limit, m).
    ///
    /// [`LoopFault::TravelLimit`]: crate::hw::LoopFault::TravelLimit
    pub error: RigError,
    /// Every sample before the fault.
    pub recording: Recording,
}

/// The identification runs on a rig: those that completed, which the
/// identification averages, and those the rig halted, which it leaves
/// out. A halted run does not stop the others.
///
/// # Examples
///
/// ```
/// use ctrlab::hw::{LoopFault, RigError, RunError, LoopStats};
/// use ctrlab::lab::ident_input::IdentRuns;
/// use ctrlab::Recording;
/// let runs = IdentRuns::collect(1..=3, |seed| {
///     let recording = Recording::new(ctrlab::lab::schema());
///     Ok::<_, ctrlab::Error>(if seed == 2 {
///         let error = RigError::Fault(LoopFault::TravelLimit { axis: 2, position: 0.051, limit: 0.05 });
///         Err(Box::new(RunError { error, recording, last_measurement: None, stats: LoopStats::default() }))
///     } else {
///         Ok(recording)
///     })
/// })?;
/// assert_eq!(runs.completed.iter().map(|r| r.seed).collect::<Vec<_>>(), [1, 3]);
/// assert_eq!(runs.halted[0].seed, 2);
/// assert!(runs.enough().is_ok());
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Default)]
pub struct IdentRuns {
    /// The runs that completed, in order.
    pub completed: Vec<CompletedRun>,
    /// The runs the rig halted, in order.
    pub halted: Vec<HaltedRun>,
}

impl IdentRuns {
    /// Runs `run` for each of `seeds` (bounded by the iterator) and sorts
    /// the outcomes: a run's own error (the rig halted it, with what it
    /// recorded) goes to [`halted`](Self::halted) and the next run goes
    /// on; `run`'s outer error (a set-up failure, Ctrl-C) stops here.
    ///
    /// # Errors
    ///
    /// `run`'s outer error.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::ident_input::IdentRuns;
    /// let runs = IdentRuns::collect(1..=2, |_| Ok::<_, ctrlab::Error>(Ok(ctrlab::Recording::new(ctrlab::lab::schema()))))?;
    /// assert_eq!((runs.completed.len(), runs.halted.len()), (2, 0));
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn collect<E>(
        seeds: impl IntoIterator<Item = u64>,
        mut run: impl FnMut(u64) -> Result<Result<Recording, Box<RunError>>, E>,
    ) -> Result<Self, E> {
        let mut runs = Self::default();
        for seed in seeds {
            match run(seed)? {
                Ok(recording) => runs.completed.push(CompletedRun { seed, recording }),
                Err(e) => {
                    let RunError {
                        error, recording, ..
                    } = *e;
                    runs.halted.push(HaltedRun {
                        seed,
                        error,
                        recording,
                    });
                }
            }
        }
        Ok(runs)
    }

    /// The completed runs' recordings, in order, for
    /// [`summarize`](super::ident::summarize).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::ident_input::IdentRuns;
    /// assert_eq!(IdentRuns::default().recordings().count(), 0);
    /// ```
    pub fn recordings(&self) -> impl Iterator<Item = &Recording> {
        self.completed.iter().map(|r| &r.recording)
    }

    /// Whether enough runs completed for the averages (and a fresh run
    /// for the validation): at least two.
    ///
    /// # Errors
    ///
    /// [`TooFewRuns`], naming each halted run and why.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::ident_input::IdentRuns;
    /// let err = IdentRuns::default().enough().unwrap_err();
    /// assert_eq!((err.completed, err.total), (0, 0));
    /// assert!(err.to_string().starts_with("only 0 of 0 identification runs completed"), "{err}");
    /// ```
    pub fn enough(&self) -> Result<(), TooFewRuns> {
        if self.completed.len() >= 2 {
            return Ok(());
        }
        Err(TooFewRuns {
            completed: self.completed.len(),
            total: self.completed.len() + self.halted.len(),
            halted: self
                .halted
                .iter()
                .map(|h| format!("run {}: {}", h.seed, h.error))
                .collect(),
        })
    }
}

/// Fewer than two identification runs completed: the averages (and the
/// validation on a fresh run) need two.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::ident_input::TooFewRuns;
/// let e = TooFewRuns { completed: 1, total: 5, halted: vec!["run 2: beyond its travel limit".into()] };
/// assert!(e.to_string().contains("only 1 of 5") && e.to_string().contains("run 2: beyond"));
/// ```
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error(
    "only {completed} of {total} identification runs completed (halted: {}); the averages and the validation on a fresh run need at least two: lower the amplitude",
    halted.join("; ")
)]
pub struct TooFewRuns {
    /// Runs that completed.
    pub completed: usize,
    /// Runs tried.
    pub total: usize,
    /// Each halted run and why, as `run 3: <the loop's error>`.
    pub halted: Vec<String>,
}
