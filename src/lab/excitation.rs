//! Which input identifies best: the lab's square wave against the
//! identification inputs of [`signal`](crate::signal) (PRBS, multisine,
//! chirp) at the same peak voltage and length, each identified as the
//! separate-springs model with Coulomb friction
//! ([`SEPARATE_SPRINGS`](super::ident::SEPARATE_SPRINGS)) over repeated
//! runs, and compared by their means against a known truth.
//!
//! # Examples
//!
//! ```
//! use ctrlab::lab::excitation::{Input, inputs};
//! use ctrlab::signal::Signal;
//! let all = inputs(8.0, 5.0, 0.2)?;
//! assert!(matches!(all[0], Input::Square(_)));
//! // The same peak, different power: the square wave and the PRBS have
//! // the most, 8 V RMS; the multisine and the chirp less.
//! assert!(all.iter().all(|i| i.peak(0.002, 5.0) <= 8.0 + 1e-9));
//! assert!((all[1].rms(0.002, 5.0) - 8.0).abs() < 1e-9);
//! assert!(all[2..].iter().all(|i| i.rms(0.002, 5.0) < 6.0));
//! # Ok::<(), ctrlab::Error>(())
//! ```

use std::ops::RangeInclusive;

use super::FrictionPlant;
use super::ident::{MassSpringEstimate, Parameter};
use crate::error::Error;
use crate::signal::{Chirp, Multisine, Phases, Prbs, Signal, SquareWave, Sweep};

/// The PRBS's clock, s: a new bit every 40 ms, flat to 0.44 / 0.04 = 11 Hz,
/// past both modes.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::{excitation::{PRBS_BITS, PRBS_CLOCK}, protocol};
/// // One period of the sequence, 127 bits, covers a 5 s run.
/// let period = ((1u32 << PRBS_BITS) - 1) as f64 * PRBS_CLOCK;
/// assert!((period - 5.08).abs() < 1e-12 && period >= protocol::IDENT_DURATION);
/// ```
pub const PRBS_CLOCK: f64 = 0.04;
/// The PRBS's register length: 2⁷ − 1 bits = 5.08 s, one period per run.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::excitation::{PRBS_BITS, PRBS_CLOCK};
/// let bits = (1u32 << PRBS_BITS) - 1;
/// assert_eq!(bits, 127);
/// assert!((bits as f64 * PRBS_CLOCK - 5.08).abs() < 1e-12); // s
/// ```
pub const PRBS_BITS: u32 = 7;
/// The PRBS's seed.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::excitation::{PRBS_BITS, PRBS_SEED};
/// // A valid start state: non-zero and within the 7-bit register.
/// assert!(PRBS_SEED != 0 && PRBS_SEED < 1 << PRBS_BITS);
/// ```
pub const PRBS_SEED: u64 = 0x5b;
/// The multisine's harmonics of one over the run's length: with 5 s, 0.2
/// to 10 Hz, one period per run.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::excitation::{CHIRP_BAND, MULTISINE_LINES};
/// use ctrlab::lab::protocol::IDENT_DURATION;
/// let band = (
///     *MULTISINE_LINES.start() as f64 / IDENT_DURATION,
///     *MULTISINE_LINES.end() as f64 / IDENT_DURATION,
/// );
/// assert_eq!(band, (0.2, 10.0)); // Hz, the chirp's band too
/// assert_eq!(band, CHIRP_BAND);
/// ```
pub const MULTISINE_LINES: RangeInclusive<u32> = 1..=50;
/// The chirp's band, Hz (logarithmic sweep).
///
/// # Examples
///
/// ```
/// use ctrlab::lab::excitation::CHIRP_BAND;
/// let (low, high) = CHIRP_BAND;
/// assert_eq!(high / low, 50.0); // a factor of 50, almost six octaves
/// ```
pub const CHIRP_BAND: (f64, f64) = (0.2, 10.0);

/// An input compared.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::excitation::{Input, inputs};
/// use ctrlab::signal::Signal;
/// let all = inputs(8.0, 5.0, 0.2)?;
/// assert!(matches!(&all, [Input::Square(_), Input::Prbs(_), Input::Multisine(_), Input::Chirp(_)]));
/// assert_eq!(all[0].value(0.1), 8.0); // each is a signal in volts
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone)]
pub enum Input {
    /// The lab's square wave.
    Square(SquareWave),
    /// A maximum-length PRBS.
    Prbs(Prbs),
    /// A Schroeder-phased multisine scaled to the peak.
    Multisine(Multisine),
    /// A logarithmic chirp.
    Chirp(Chirp),
}

impl Signal for Input {
    fn value(&self, t: f64) -> f64 {
        match self {
            Input::Square(s) => s.value(t),
            Input::Prbs(s) => s.value(t),
            Input::Multisine(s) => s.value(t),
            Input::Chirp(s) => s.value(t),
        }
    }
}

impl Input {
    /// Its RMS over `duration` s sampled every `period` s, V.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::excitation::inputs;
    /// let [square, _, multisine, _] = inputs(8.0, 5.0, 0.2)?;
    /// assert!((square.rms(0.002, 5.0) - 8.0).abs() < 1e-12); // a square wave's RMS is its amplitude
    /// assert!(multisine.rms(0.002, 5.0) < 6.0); // same 8 V peak, less power
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn rms(&self, period: f64, duration: f64) -> f64 {
        let u = self.sample(0.0, period, samples(period, duration));
        (u.iter().map(|v| v * v).sum::<f64>() / u.len() as f64).sqrt()
    }

    /// Its largest |value| over `duration` s sampled every `period` s, V.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::excitation::inputs;
    /// let all = inputs(8.0, 5.0, 0.2)?;
    /// // All four share the 8 V peak.
    /// assert!(all.iter().all(|i| (i.peak(0.002, 5.0) - 8.0).abs() < 0.05));
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn peak(&self, period: f64, duration: f64) -> f64 {
        self.sample(0.0, period, samples(period, duration))
            .iter()
            .fold(0.0, |m: f64, v| m.max(v.abs()))
    }
}

/// Samples in `duration` at `period`, at least one; bounded to 10⁷.
fn samples(period: f64, duration: f64) -> usize {
    let n = duration / period;
    if n.is_finite() && n >= 1.0 {
        (n as usize).min(10_000_000)
    } else {
        1
    }
}

/// The four inputs at `volts` peak over `duration` s: the square wave
/// (`half_period` s), the PRBS ([`PRBS_CLOCK`], [`PRBS_BITS`]), the
/// multisine ([`MULTISINE_LINES`] of `1 / duration`, Schroeder phases), the
/// chirp ([`CHIRP_BAND`]).
///
/// # Errors
///
/// [`Error::InvalidParameter`] for a non-positive or non-finite `volts`,
/// `duration` or `half_period`.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::excitation::inputs;
/// let all = inputs(8.0, 5.0, 0.2)?;
/// assert!(all.iter().all(|i| i.peak(0.002, 5.0) <= 8.0 + 1e-9)); // V
/// assert!(inputs(8.0, 5.0, 0.0).is_err()); // no half period
/// assert!(inputs(0.0, 5.0, 0.2).is_err() && inputs(-8.0, 5.0, 0.2).is_err()); // no peak drive
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub fn inputs(volts: f64, duration: f64, half_period: f64) -> Result<[Input; 4], Error> {
    super::protocol::check_volts(volts)?;
    let square = SquareWave::new(volts, half_period)?;
    let prbs = Prbs::new(volts, PRBS_CLOCK, PRBS_BITS, PRBS_SEED)?;
    let unit = Multisine::new(1.0, duration, MULTISINE_LINES, Phases::Schroeder)?;
    let multisine = Multisine::new(
        volts / unit.peak(),
        duration,
        MULTISINE_LINES,
        Phases::Schroeder,
    )?;
    let chirp = Chirp::new(
        volts,
        CHIRP_BAND.0,
        CHIRP_BAND.1,
        duration,
        Sweep::Logarithmic,
    )?;
    Ok([
        Input::Square(square),
        Input::Prbs(prbs),
        Input::Multisine(multisine),
        Input::Chirp(chirp),
    ])
}

/// Why an input has no estimates.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::excitation::{Failure, InputResult, best, inputs};
/// let [square, ..] = inputs(8.0, 5.0, 0.2)?;
/// let halted = Failure::Halted("cart 2 at its end stop".into());
/// let results = [InputResult { input: square, rms: 8.0, outcome: Err(halted) }];
/// assert!(best(&results).is_none()); // a failed input is never the best
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub enum Failure {
    /// A run did not identify.
    NotIdentified(Error),
    /// The rig halted a run: its message.
    Halted(String),
}

/// An input's estimates: the means over its runs, and the truth when known.
///
/// # Examples
///
/// ```
/// use ctrlab::Recording;
/// use ctrlab::lab::ident::{SEPARATE_SPRINGS, identify_with};
/// use ctrlab::lab::{FrictionPlant, MassSpring, excitation::Estimates};
/// let rec = Recording::read_csv(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ident_square_wave.csv"))?;
/// let e = identify_with(&rec, 1.3, 0.7, &SEPARATE_SPRINGS)?;
/// let truth = FrictionPlant::new(MassSpring { k1: 950.0, k2: 950.0, ..MassSpring::nominal() }, [0.5; 2]);
/// let est = Estimates::of(&[e.clone(), e], Some(&truth))?;
/// assert!((est.means[0] / 950.0 - 1.0).abs() < 0.01);
/// // The fixture has no dry friction, the truth here 0.5 N: F1 is 100 % off.
/// assert!(est.worst_percent().is_some_and(|w| w > 90.0));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Estimates {
    /// Each parameter's mean over the runs, in [`Parameter::ALL`]'s order
    /// and their units.
    pub means: [f64; 7],
    /// The truth, in the same order, when known.
    pub truth: Option<[f64; 7]>,
}

impl Estimates {
    /// The means of `runs` against `truth` (a simulated card's plant and
    /// Coulomb forces).
    ///
    /// # Errors
    ///
    /// [`Error::TooFewSamples`] for no runs.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::excitation::Estimates;
    /// // Means need at least one run.
    /// let err = Estimates::of(&[], None).unwrap_err();
    /// assert!(matches!(err, ctrlab::Error::TooFewSamples { needed: 1, got: 0, .. }));
    /// ```
    pub fn of(runs: &[MassSpringEstimate], truth: Option<&FrictionPlant>) -> Result<Self, Error> {
        if runs.is_empty() {
            return Err(Error::TooFewSamples {
                what: "runs of an input",
                needed: 1,
                got: 0,
            });
        }
        let n = runs.len() as f64;
        let means = Parameter::ALL.map(|p| {
            runs.iter()
                .map(|e| p.estimate(e).map_or(f64::NAN, |e| e.value))
                .sum::<f64>()
                / n
        });
        let truth = truth.map(|t| Parameter::ALL.map(|p| p.of(&t.truth(), t.friction())));
        Ok(Self { means, truth })
    }

    /// Each mean's error against the truth, %, when it is known.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::excitation::Estimates;
    /// let est = Estimates { means: [1.02; 7], truth: Some([1.0; 7]) };
    /// assert!(est.errors_percent().unwrap().iter().all(|e| (e - 2.0).abs() < 1e-9));
    /// assert_eq!(Estimates { truth: None, ..est }.errors_percent(), None);
    /// ```
    pub fn errors_percent(&self) -> Option<[f64; 7]> {
        let t = self.truth?;
        Some(std::array::from_fn(|i| {
            (self.means[i] / t[i] - 1.0) * 100.0
        }))
    }

    /// The largest |error| against the truth, %, when it is known (an
    /// error that is not a number, from a zero truth and mean, is left
    /// out).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::excitation::Estimates;
    /// let mut means = [1.0; 7];
    /// (means[2], means[5]) = (1.03, 0.95);
    /// let est = Estimates { means, truth: Some([1.0; 7]) };
    /// assert!((est.worst_percent().unwrap() - 5.0).abs() < 1e-9); // the 5 % low one
    /// ```
    pub fn worst_percent(&self) -> Option<f64> {
        let e = self.errors_percent()?;
        Some(e.iter().map(|v| v.abs()).fold(0.0, f64::max))
    }
}

/// One input's result.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::excitation::{Estimates, InputResult, inputs};
/// let [square, ..] = inputs(8.0, 5.0, 0.2)?;
/// let rms = square.rms(0.002, 5.0);
/// let outcome = Ok(Estimates { means: [1.01; 7], truth: Some([1.0; 7]) });
/// let r = InputResult { input: square, rms, outcome };
/// assert_eq!(r.rms, 8.0); // V
/// assert!(r.outcome.unwrap().worst_percent().unwrap() < 1.1);
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct InputResult {
    /// The input.
    pub input: Input,
    /// Its RMS over a run, V.
    pub rms: f64,
    /// Its estimates, or why there are none.
    pub outcome: Result<Estimates, Failure>,
}

/// The input whose estimates' worst error against the truth is smallest,
/// with that error (%); `None` without a truth or estimates.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::excitation::{Estimates, InputResult, best, inputs};
/// let [square, prbs, ..] = inputs(8.0, 5.0, 0.2)?;
/// let truth = Some([1.0; 7]);
/// let results = [
///     InputResult { input: square, rms: 8.0, outcome: Ok(Estimates { means: [1.02; 7], truth }) },
///     InputResult { input: prbs, rms: 8.0, outcome: Ok(Estimates { means: [0.99; 7], truth }) },
/// ];
/// let (input, worst) = best(&results).unwrap();
/// assert!(matches!(input.input, ctrlab::lab::excitation::Input::Prbs(_)));
/// assert!((worst - 1.0).abs() < 1e-9);
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub fn best(results: &[InputResult]) -> Option<(&InputResult, f64)> {
    results
        .iter()
        .filter_map(|r| Some((r, r.outcome.as_ref().ok()?.worst_percent()?)))
        .min_by(|a, b| a.1.total_cmp(&b.1))
}
