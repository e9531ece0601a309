//! The amplitude from the probe runs: [`AmplitudeSearch`] and what it
//! gives, [`AmplitudeChoice`] (see [the module](super#how-the-amplitude-is-chosen)).

use std::fmt;

use super::{PROBE_FRACTIONS, TRAVEL_FRACTION, peaks};
use crate::Recording;
use crate::error::Error;
use crate::hw::{LoopFault, RigError, RunError};

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
/// volts; see [the module](crate::lab::ident_input#how-the-amplitude-is-chosen)), m: the
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
    /// As asked, without probe runs ([`IdentInput::scale_to_travel`](super::IdentInput::scale_to_travel)
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
    /// Lowered below the probe run the rig halted at a travel limit
    /// ([`AmplitudeChoice::halted`]), in proportion to the peaks it
    /// reached, so that cart `cart`'s (0 or 1) would be [`TRAVEL_FRACTION`]
    /// of its travel limit. The halt cut that probe's peak short: what it
    /// reached is a lower bound, so this is the most the probe allows, not
    /// a prediction.
    Halted {
        /// The cart that limits it, 0 or 1.
        cart: usize,
    },
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
            Reason::Halted { cart } => write!(
                f,
                "lowered below the probe run the rig halted at a travel limit, in proportion to the peaks it reached, so that cart {}'s would be {:.0} % of its travel limit (a peak the halt cut short: the most that probe allows, not a prediction)",
                cart + 1,
                TRAVEL_FRACTION * 100.0
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
/// assert!(fixed.probes.is_empty() && fixed.halted.is_none() && fixed.predicted.is_none());
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
    /// The probe runs that completed, in the order they ran (none for
    /// [`Reason::Fixed`]); the predictions are theirs.
    pub probes: Vec<Probe>,
    /// The probe run the rig halted at a travel limit, if one did: its
    /// volts and the peaks it reached (the recording's, and the halted
    /// cart's position in the fault; the last probe run: none runs after
    /// it). See [`Reason::Halted`].
    pub halted: Option<Probe>,
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
            halted: None,
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
/// use ctrlab::lab::ident_input::{AmplitudeSearch, ProbeFault, Reason};
/// // 2 mm per volt on cart 2, no friction: 8 V is 16 mm, within 30 mm.
/// let choice = AmplitudeSearch::new(8.0, [0.05, 0.05])?
///     .run(|v| Ok::<_, ProbeFault>([0.001 * v, 0.002 * v]))?;
/// assert_eq!((choice.volts, choice.reason), (8.0, Reason::Fits));
/// assert_eq!(choice.probes.iter().map(|p| p.volts).collect::<Vec<_>>(), [2.0, 4.0]);
/// # Ok::<(), Box<dyn std::error::Error>>(())
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
        crate::lab::protocol::check_volts(asked)?;
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
    /// it is given for [`PROBE_DURATION`](super::PROBE_DURATION) s and says how it went:
    /// [`ProbeOutcome::of`] its run, or both carts' peak |x|, m, when it
    /// completed) and chooses the amplitude.
    ///
    /// The first probe runs at `PROBE_FRACTIONS[0]` of the amplitude
    /// asked for; the second at `PROBE_FRACTIONS[1]`, lowered to what the
    /// first predicts is allowed (and left out if that is not above the
    /// first).
    ///
    /// A probe the rig halts at a travel limit ends the probing (a higher
    /// amplitude would only go further) and is the answer that the
    /// amplitude must come down: it is lowered in proportion to the peaks
    /// that probe reached ([`Reason::Halted`]), never above what the
    /// completed probes allow. Any other fault is an error: a bus fault,
    /// a dead encoder or a motor not responding makes the probe's peaks
    /// no measurement, and neither does a run cut short by Ctrl-C or a
    /// timing gap.
    ///
    /// # Errors
    ///
    /// [`ProbeFault`] (into `E`) for a probe the rig halted other than at
    /// a travel limit; `probe`'s own error, as it gives it.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::{LoopFault, RigError};
    /// use ctrlab::lab::ident_input::{AmplitudeSearch, ProbeFault, ProbeOutcome, Reason};
    /// // 20 mm per volt: the first probe (2 V, 40 mm) is already too far.
    /// let search = AmplitudeSearch::new(8.0, [0.05, 0.05])?;
    /// let choice = search.run(|v| Ok::<_, ProbeFault>([0.0, 0.02 * v]))?;
    /// assert_eq!(choice.probes.len(), 1);
    /// assert!((choice.volts - 1.5).abs() < 1e-12);
    /// assert_eq!(choice.reason, Reason::Scaled { cart: 1 });
    /// // 30 mm per volt: the rig halts the first probe at cart 2's 50 mm.
    /// let choice = search.run(|_| {
    ///     let error = RigError::Fault(LoopFault::TravelLimit { axis: 2, position: 0.0501, limit: 0.05 });
    ///     Ok::<_, ProbeFault>(ProbeOutcome::Halted { error, peaks: [0.01, 0.0501] })
    /// })?;
    /// assert_eq!(choice.reason, Reason::Halted { cart: 1 });
    /// assert!(choice.probes.is_empty() && choice.halted.unwrap().volts == 2.0);
    /// // 2 V × 30 mm / 50.1 mm, rounded down to 10 mV.
    /// assert!((choice.volts - 1.19).abs() < 1e-12);
    /// // Any other fault is no measurement.
    /// let err = search.run(|_| {
    ///     let error = RigError::Fault(LoopFault::Interrupted { at: 1.0 });
    ///     Ok::<_, ProbeFault>(ProbeOutcome::Halted { error, peaks: [0.0, 0.0] })
    /// });
    /// assert_eq!(err.unwrap_err().number, 1);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn run<O: Into<ProbeOutcome>, E: From<ProbeFault>>(
        &self,
        mut probe: impl FnMut(f64) -> Result<O, E>,
    ) -> Result<AmplitudeChoice, E> {
        let mut probes = Vec::with_capacity(PROBE_FRACTIONS.len());
        let mut halted = None;
        for (n, fraction) in PROBE_FRACTIONS.into_iter().enumerate() {
            let mut volts = fraction * self.asked;
            if !probes.is_empty() {
                volts = volts.min(self.largest(&probes).0);
                if probes.last().is_some_and(|p: &Probe| volts <= p.volts) {
                    break;
                }
            }
            match probe(volts)?.into() {
                ProbeOutcome::Completed(peaks) => probes.push(Probe { volts, peaks }),
                ProbeOutcome::Halted {
                    error: RigError::Fault(LoopFault::TravelLimit { axis, position, .. }),
                    mut peaks,
                } => {
                    // The read that broke the limit is not recorded: the
                    // fault's own position is the least the cart reached.
                    if let Some(p) = peaks.get_mut(axis.wrapping_sub(1)) {
                        *p = p.max(position.abs());
                    }
                    halted = Some(Probe { volts, peaks });
                    break;
                }
                ProbeOutcome::Halted { error, .. } => {
                    return Err(ProbeFault {
                        number: n + 1,
                        volts,
                        error,
                    }
                    .into());
                }
            }
        }
        let (largest, cart) = self.largest(&probes);
        let (mut volts, mut reason) = match cart {
            None => (self.asked, Reason::NoMotion),
            Some(_) if largest >= self.asked => (self.asked, Reason::Fits),
            Some(cart) => (round_down(largest), Reason::Scaled { cart }),
        };
        if let Some(h) = halted {
            // What the halted probe reached is a lower bound of its peak:
            // in proportion to it is the most that probe allows (below the
            // completed probes' own bound, which it broke).
            let (ceiling, cart) = self.proportional(&h);
            if ceiling < volts {
                (volts, reason) = (round_down(ceiling), Reason::Halted { cart });
            }
        }
        Ok(AmplitudeChoice {
            asked: self.asked,
            volts,
            reason,
            predicted: predict(&probes, volts),
            predicted_asked: predict(&probes, self.asked),
            probes,
            halted,
            limits: self.limits,
        })
    }

    /// The largest amplitude at which `probe`'s peaks, scaled in
    /// proportion to the volts, are within [`TRAVEL_FRACTION`] of the
    /// limits, V, and the cart that limits it.
    fn proportional(&self, probe: &Probe) -> (f64, usize) {
        let mut best = (f64::INFINITY, 0);
        for (c, &peak) in probe.peaks.iter().enumerate() {
            let v = Line {
                slope: peak / probe.volts,
                intercept: 0.0,
            }
            .volts_at(TRAVEL_FRACTION * self.limits[c]);
            if v < best.0 {
                best = (v, c);
            }
        }
        best
    }
}

/// Down to 10 mV (below the drive's 24 mV step): a round number to report,
/// never above the bound it rounds.
fn round_down(volts: f64) -> f64 {
    ((volts * 100.0).floor() / 100.0).max(0.0)
}

/// How a probe run went.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::ident_input::ProbeOutcome;
/// // A probe that ran its length, by its peaks (m).
/// let done: ProbeOutcome = [0.001, 0.004].into();
/// assert!(matches!(done, ProbeOutcome::Completed(p) if p[1] == 0.004));
/// ```
#[derive(Debug)]
pub enum ProbeOutcome {
    /// It ran its [`PROBE_DURATION`](super::PROBE_DURATION): both carts' peak |x|, m.
    Completed([f64; 2]),
    /// The rig halted it: why, and both carts' peak |x| before, m.
    Halted {
        /// The loop's error.
        error: RigError,
        /// Cart 1's and cart 2's largest |position| before the halt, m.
        peaks: [f64; 2],
    },
}

impl From<[f64; 2]> for ProbeOutcome {
    fn from(peaks: [f64; 2]) -> Self {
        Self::Completed(peaks)
    }
}

impl ProbeOutcome {
    /// The outcome of a probe's run: its recording (completed) or the
    /// loop's error with what it recorded (halted), with [`peaks`].
    ///
    /// # Errors
    ///
    /// [`Error`] when the recording lacks `x1` or `x2`.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::ident_input::ProbeOutcome;
    /// let empty = ctrlab::Recording::new(ctrlab::lab::schema());
    /// assert!(matches!(ProbeOutcome::of(Ok(empty))?, ProbeOutcome::Completed([0.0, 0.0])));
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn of(run: Result<Recording, Box<RunError>>) -> Result<Self, Error> {
        Ok(match run {
            Ok(recording) => Self::Completed(peaks(&recording)?),
            Err(e) => Self::Halted {
                peaks: peaks(&e.recording)?,
                error: e.error,
            },
        })
    }
}

/// A probe run the rig halted other than at a travel limit: its peaks are
/// no measurement (a bus fault, a dead encoder, a motor not responding, a
/// run cut short by Ctrl-C or a timing gap), so the amplitude cannot be
/// chosen and the identification does not start.
///
/// # Examples
///
/// ```
/// use ctrlab::hw::{LoopFault, RigError};
/// use ctrlab::lab::ident_input::ProbeFault;
/// let e = ProbeFault { number: 1, volts: 2.0, error: RigError::Fault(LoopFault::Interrupted { at: 0.5 }) };
/// assert!(e.to_string().starts_with("probe run 1 at 2.00 V was halted"), "{e}");
/// ```
#[derive(Debug, thiserror::Error)]
#[error(
    "probe run {number} at {volts:.2} V was halted by a fault other than a travel limit, so its peaks are no measurement and the identification does not start: {error}"
)]
pub struct ProbeFault {
    /// The probe's number, from 1.
    pub number: usize,
    /// Its amplitude, V.
    pub volts: f64,
    /// The loop's error.
    pub error: RigError,
}
