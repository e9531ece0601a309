//! The rig's measured frequency response against the identified model:
//! a periodic multisine run, its empirical transfer-function estimate
//! (ETFE, one point per line) and Blackman–Tukey smoothing from the drive
//! voltage to cart 2's position, the identified model's Bode plot, the
//! identified model with its Coulomb friction simulated on the same input
//! and estimated the same way, and the two modes located on each.
//!
//! # Examples
//!
//! ```
//! use ctrlab::lab::{MassSpring, frequency};
//! let modes = frequency::modes_hz(&MassSpring::nominal())?;
//! assert_eq!(modes.len(), 2);
//! // k1 = k2 = 1000 N/m, m1 = 1.3 kg, m2 = 0.7 kg: 3.31 and 8.01 Hz.
//! assert!((modes[0] - 3.31).abs() < 0.05 && (modes[1] - 8.01).abs() < 0.05);
//! let ms = frequency::multisine(8.0)?;
//! assert_eq!(ms.harmonics().len(), 75);
//! # Ok::<(), ctrlab::Error>(())
//! ```

use std::ops::RangeInclusive;

use crate::nalgebra::{SVector, vector};

use super::{Cart, MassSpring, SimulatedRig};
use crate::data::Recording;
use crate::design::OpenLoop;
use crate::error::Error;
use crate::freq::{Bode, bode, logspace};
use crate::ident::{FrequencyEstimate, etfe, spa};
use crate::signal::{Multisine, Phases, Signal};
use crate::sim::run_sampled;

/// One period of the multisine, s: lines every 0.2 Hz.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::frequency::{MS_PERIOD, multisine};
/// assert_eq!(1.0 / MS_PERIOD, 0.2); // Hz between lines
/// assert_eq!(multisine(8.0)?.period(), MS_PERIOD);
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub const MS_PERIOD: f64 = 5.0;
/// Harmonics of `1 / MS_PERIOD`: 0.2 to 15 Hz, past both modes.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::{MassSpring, frequency::{LINES, MS_PERIOD, modes_hz}};
/// let top = *LINES.end() as f64 / MS_PERIOD;
/// assert_eq!(top, 15.0); // Hz
/// assert!(modes_hz(&MassSpring::nominal())?.iter().all(|&f| f < top));
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub const LINES: RangeInclusive<u32> = 1..=75;
/// Periods run; the first lets the transient die out (the slowest mode
/// decays in about a second) and is left out of the estimate.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::frequency::{DURATION, MS_PERIOD, PERIODS};
/// // The estimate uses the periods after the first: 10 s.
/// assert_eq!(DURATION - MS_PERIOD, (PERIODS - 1) as f64 * MS_PERIOD);
/// assert_eq!(DURATION - MS_PERIOD, 10.0);
/// ```
pub const PERIODS: usize = 3;
/// The smoothed estimate's lag window, s.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::frequency::{MS_PERIOD, SPA_WINDOW};
/// use ctrlab::lab::protocol::PERIOD;
/// assert_eq!(2.0 * SPA_WINDOW, MS_PERIOD); // half a multisine period
/// assert!((SPA_WINDOW / PERIOD - 1250.0).abs() < 1e-9); // lags, samples
/// ```
pub const SPA_WINDOW: f64 = 2.5;
/// Points of the smoothed estimate and the Bode plots, log-spaced from 0.2
/// to 15 Hz.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::frequency::{GRID_POINTS, LINES};
/// // The smoothed curve is finer than the ETFE's one point per line.
/// assert!(GRID_POINTS > LINES.count());
/// ```
pub const GRID_POINTS: usize = 400;

/// The multisine of [`LINES`] with Schroeder phases, scaled to `volts`
/// peak.
///
/// # Errors
///
/// [`Error::InvalidParameter`] for a non-positive or non-finite `volts`.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::frequency::{LINES, multisine};
/// let ms = multisine(8.0)?;
/// assert!((ms.peak() - 8.0).abs() < 1e-9); // V
/// assert_eq!(ms.harmonics().len(), LINES.count());
/// assert!(multisine(f64::NAN).is_err());
/// assert!(multisine(0.0).is_err() && multisine(-8.0).is_err());
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub fn multisine(volts: f64) -> Result<Multisine, Error> {
    super::protocol::check_volts(volts)?;
    let unit = Multisine::new(1.0, MS_PERIOD, LINES, Phases::Schroeder)?;
    Multisine::new(volts / unit.peak(), MS_PERIOD, LINES, Phases::Schroeder)
}

/// The run's length, s: [`PERIODS`] periods.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::{frequency::DURATION, protocol::PERIOD};
/// assert_eq!(DURATION, 15.0);
/// assert!((DURATION / PERIOD - 7500.0).abs() < 1e-9); // whole loop periods
/// ```
pub const DURATION: f64 = MS_PERIOD * PERIODS as f64;

/// The natural frequencies of `model`'s two complex pole pairs, Hz,
/// ascending.
///
/// # Errors
///
/// An invalid model.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::{MassSpring, frequency::modes_hz};
/// let nominal = MassSpring::nominal();
/// let slow = modes_hz(&nominal)?;
/// assert!(slow[0] < slow[1]); // Hz, ascending
/// // Four times the springs and twice the damping: both modes an octave up.
/// let stiff = MassSpring { k1: 4000.0, k2: 4000.0, b1: 20.0, b2: 10.0, ..nominal };
/// let fast = modes_hz(&stiff)?;
/// assert!((fast[0] / slow[0] - 2.0).abs() < 1e-9 && (fast[1] / slow[1] - 2.0).abs() < 1e-9);
/// assert!(modes_hz(&MassSpring { m1: -1.0, ..nominal }).is_err());
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub fn modes_hz(model: &MassSpring) -> Result<Vec<f64>, Error> {
    let mut hz: Vec<f64> = model
        .state_space(Cart::Two)?
        .damping()?
        .iter()
        .filter(|d| d.pole.im > 0.0)
        .map(|d| d.natural_frequency / std::f64::consts::TAU)
        .collect();
    hz.sort_by(f64::total_cmp);
    Ok(hz)
}

/// The frequencies (Hz) of the `count` most prominent local maxima of
/// `|G|`, ascending. A peak's prominence is how far (in log magnitude) it
/// rises above the higher of the two lowest points that separate it from
/// a higher point on either side (or from the end of the curve): a mode
/// stands out, while a ripple of the estimate on a high, falling
/// low-frequency gain does not, however high it lies. (Ranked by height
/// instead, a ripple at 0.86 Hz on a jittered run's smoothed estimate
/// outranked the 8.45 Hz mode.)
///
/// # Examples
///
/// ```
/// use ctrlab::ident::FrequencyEstimate;
/// use ctrlab::nalgebra::Complex;
/// let tau = std::f64::consts::TAU;
/// let g = FrequencyEstimate {
///     omega: [1.0, 2.0, 3.0, 4.0, 5.0].map(|f| f * tau).to_vec(),
///     response: [1.0, 3.0, 1.0, 2.0, 1.0].map(|m| Complex::new(m, 0.0)).to_vec(),
/// };
/// assert_eq!(ctrlab::lab::frequency::peaks_hz(&g, 2), [2.0, 4.0]);
/// // A ripple on a high falling gain (at 3 Hz, the highest local maximum)
/// // against two modes.
/// let g = FrequencyEstimate {
///     omega: (1..=9).map(|f| f as f64 * tau).collect(),
///     response: [10.0, 9.0, 9.5, 2.0, 4.0, 1.0, 0.5, 3.0, 0.4]
///         .map(|m| Complex::new(m, 0.0)).to_vec(),
/// };
/// assert_eq!(ctrlab::lab::frequency::peaks_hz(&g, 2), [5.0, 8.0]);
/// ```
pub fn peaks_hz(g: &FrequencyEstimate, count: usize) -> Vec<f64> {
    let m: Vec<f64> = g.magnitude().iter().map(|m| m.ln()).collect();
    let hz = g.frequency_hz();
    // The lowest point between `i` and the first higher point in `range`
    // (or the end of the curve).
    let floor = |i: usize, range: &mut dyn Iterator<Item = usize>| {
        let mut low = m[i];
        for j in range {
            if m[j] > m[i] {
                break;
            }
            low = low.min(m[j]);
        }
        low
    };
    let mut peaks: Vec<(f64, f64)> = (1..m.len().saturating_sub(1))
        .filter(|&i| m[i] > m[i - 1] && m[i] >= m[i + 1])
        .map(|i| {
            let left = floor(i, &mut (0..i).rev());
            let right = floor(i, &mut (i + 1..m.len()));
            (m[i] - left.max(right), hz[i])
        })
        .collect();
    peaks.sort_by(|a, b| b.0.total_cmp(&a.0));
    let mut out: Vec<f64> = peaks.iter().take(count).map(|p| p.1).collect();
    out.sort_by(f64::total_cmp);
    out
}

/// The ETFE on the multisine's lines (bins above them hold only the
/// drive's quantisation) and the smoothed estimate on `w` (rad/s), from u
/// (V) to x2 (m) over the periods after the first, on the grid of one
/// `period` (s) from the first sample. A recording with late samples or
/// gaps (skipped ticks) is first brought onto that grid (the input held,
/// the positions interpolated); a uniform one is used as it is.
///
/// # Errors
///
/// A recording without `u` or `x2`, or too short for the window.
///
/// # Examples
///
/// The model's own multisine run, and the same run with every tenth
/// sample lost (skipped ticks): the same two modes. (Taken as uniform, the
/// gaps would compress time by a tenth and move them up by as much.)
///
/// ```
/// use ctrlab::{OpenLoop, Recording};
/// use ctrlab::freq::logspace;
/// use ctrlab::lab::{SimulatedRig, frequency, lqi};
/// use ctrlab::nalgebra::vector;
/// use ctrlab::signal::Signal;
/// let sim = SimulatedRig::default();
/// let rig = lqi::predicted_rig(sim.truth, sim.friction.coulomb, &sim.calibration, sim.period);
/// let ms = frequency::multisine(8.0)?;
/// let rec = ctrlab::run_sampled(rig.plant(), rig.sensor(), OpenLoop, |t| vector![ms.value(t)],
///                               vector![0.0, 0.0, 0.0, 0.0], &rig.sampled_config(frequency::DURATION))?;
/// let mut gaps = Recording::new(rec.schema().clone());
/// for k in (0..rec.len()).filter(|k| k % 10 != 5) {
///     let y: Vec<f64> = (0..4).map(|i| rec.measurement(i).unwrap()[k]).collect();
///     gaps.push(rec.time()[k], &[rec.input(0).unwrap()[k]], &y)?;
/// }
/// let tau = std::f64::consts::TAU;
/// let w = logspace((0.2 * tau).log10(), (15.0 * tau).log10(), 400)?; // 0.2–15 Hz, rad/s
/// let (_, full) = frequency::estimates(&rec, &w, sim.period)?;
/// let (_, lost) = frequency::estimates(&gaps, &w, sim.period)?;
/// let (a, b) = (frequency::peaks_hz(&full, 2), frequency::peaks_hz(&lost, 2));
/// assert!(a.iter().zip(&b).all(|(a, b)| (a - b).abs() < 0.1), "{a:?} {b:?}");
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn estimates(
    rec: &Recording,
    w: &[f64],
    period: f64,
) -> Result<(FrequencyEstimate, FrequencyEstimate), Error> {
    let skip = (MS_PERIOD / period).round() as usize;
    let (u, x2) = on_period_grid(rec, period)?;
    if u.len() <= skip {
        return Err(Error::TooFewSamples {
            what: "multisine run after its first period",
            needed: skip + 1,
            got: u.len(),
        });
    }
    let (u, y) = (&u[skip..], &x2[skip..]);
    let mut raw = etfe(u, y, period)?;
    let top = f64::from(*LINES.end()) / MS_PERIOD * std::f64::consts::TAU * (1.0 + 1e-9);
    let keep = raw.omega.iter().take_while(|w| **w <= top).count();
    raw.omega.truncate(keep);
    raw.response.truncate(keep);
    let smooth = spa(u, y, period, Some((SPA_WINDOW / period) as usize), w)?;
    Ok((raw, smooth))
}

/// u (V) and x2 (m) of `rec` on the grid `t0 + k·period` from its first
/// sample to its last: the spectral estimates assume one sample per
/// period, and a late sample or a gap of skipped ticks would otherwise
/// compress time and move every line (a run that skipped 10 % of its
/// ticks put the second mode at 3.0 Hz instead of 8.5). A sample within
/// [`MAX_JITTER`](crate::data::MAX_JITTER) of a grid point is that point,
/// so a uniform recording is used exactly as it is; between samples, u is
/// the last one applied (the drive holds it) and x2 is interpolated
/// linearly (the cart moves continuously).
fn on_period_grid(rec: &Recording, period: f64) -> Result<(Vec<f64>, Vec<f64>), Error> {
    let (t, u, x2) = (rec.time(), rec.channel("u")?, rec.channel("x2")?);
    let (Some(&first), Some(&last)) = (t.first(), t.last()) else {
        return Ok((Vec::new(), Vec::new()));
    };
    let tol = crate::data::MAX_JITTER * period;
    let points = ((last - first + tol) / period).floor() as usize + 1;
    let (mut u_grid, mut x_grid) = (Vec::with_capacity(points), Vec::with_capacity(points));
    // `j`: the last sample at or before the grid point (within `tol`).
    let mut j = 0;
    for k in 0..points {
        let tk = first + k as f64 * period;
        while j + 1 < t.len() && t[j + 1] <= tk + tol {
            j += 1;
        }
        let x = if (t[j] - tk).abs() <= tol || j + 1 == t.len() {
            x2[j]
        } else {
            let a = (tk - t[j]) / (t[j + 1] - t[j]);
            x2[j] + a * (x2[j + 1] - x2[j])
        };
        u_grid.push(u[j]);
        x_grid.push(x);
    }
    Ok((u_grid, x_grid))
}

/// Median relative distance between two magnitude curves on one grid.
fn median_gap(a: &[f64], b: &[f64]) -> f64 {
    let mut rel: Vec<f64> = a.iter().zip(b).map(|(a, b)| (a / b - 1.0).abs()).collect();
    rel.sort_by(f64::total_cmp);
    rel.get(rel.len() / 2).copied().unwrap_or(f64::NAN)
}

/// One mode located four ways, Hz (`None` where not found).
///
/// # Examples
///
/// ```
/// use ctrlab::lab::{MassSpring, frequency::{Mode, modes_hz}};
/// let identified = modes_hz(&MassSpring { k1: 980.0, ..MassSpring::nominal() })?;
/// let truth = modes_hz(&MassSpring::nominal())?;
/// let first = Mode {
///     model_hz: identified.first().copied(),
///     simulated_hz: None,
///     measured_hz: None,
///     truth_hz: truth.first().copied(),
/// };
/// // 2 % off a spring puts the model's first mode within 1 % of the truth's.
/// let (m, t) = (first.model_hz.unwrap(), first.truth_hz.unwrap());
/// assert!(m < t && (m / t - 1.0).abs() < 0.01);
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Mode {
    /// The identified linear model's natural frequency.
    pub model_hz: Option<f64>,
    /// The gain peak of the identified model with friction, simulated.
    pub simulated_hz: Option<f64>,
    /// The gain peak of the measured (smoothed) response.
    pub measured_hz: Option<f64>,
    /// The truth's natural frequency (a simulated rig).
    pub truth_hz: Option<f64>,
}

/// The measured response against the identified model.
///
/// # Examples
///
/// A response put together by hand ([`frequency_response`] measures one
/// from a 15 s run):
///
/// ```
/// use ctrlab::freq::{bode, logspace};
/// use ctrlab::ident::FrequencyEstimate;
/// use ctrlab::lab::{Cart, MassSpring, frequency::{self, FrequencyResponse, Mode}};
/// use ctrlab::nalgebra::Complex;
/// let tau = std::f64::consts::TAU;
/// let omega = logspace((0.2 * tau).log10(), (15.0 * tau).log10(), frequency::GRID_POINTS)?;
/// # let plant = MassSpring::nominal();
/// # let model = bode(&plant.state_space(Cart::Two)?, &omega)?;
/// # let flat = FrequencyEstimate { omega: omega.clone(), response: vec![Complex::new(1e-3, 0.0); omega.len()] };
/// # let hz = frequency::modes_hz(&plant)?;
/// # let mode = |i: usize| Mode { model_hz: Some(hz[i]), simulated_hz: None, measured_hz: None, truth_hz: None };
/// let r = FrequencyResponse { omega, measured: flat.clone(), smoothed: flat.clone(), simulated: flat,
///     model, truth: None, modes: [mode(0), mode(1)], gap_linear: 0.3, gap_friction: 0.1 };
/// // The grid is in rad/s: 0.2 to 15 Hz.
/// let f = r.smoothed.frequency_hz();
/// assert!((f[0] - 0.2).abs() < 1e-9 && (f[f.len() - 1] - 15.0).abs() < 1e-9);
/// assert!(r.modes[0].model_hz < r.modes[1].model_hz); // in phase, then in opposition
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct FrequencyResponse {
    /// The grid of the smoothed estimates and Bode plots, rad/s.
    pub omega: Vec<f64>,
    /// The ETFE on the multisine's lines, m/V.
    pub measured: FrequencyEstimate,
    /// Its Blackman–Tukey smoothing on [`omega`](Self::omega), m/V.
    pub smoothed: FrequencyEstimate,
    /// The identified model with friction, simulated and smoothed the same
    /// way, m/V.
    pub simulated: FrequencyEstimate,
    /// The identified model's linear part.
    pub model: Bode,
    /// The truth's linear part (a simulated rig).
    pub truth: Option<Bode>,
    /// The first (carts in phase) and second (in opposition) mode.
    pub modes: [Mode; 2],
    /// Median relative distance of the measured magnitude from the linear
    /// model's (a fraction).
    pub gap_linear: f64,
    /// The same from the model with friction, simulated.
    pub gap_friction: f64,
}

/// The response of `measured`, a run of `multisine` for [`DURATION`] s,
/// against `rig`: the identified plant and Coulomb friction as the
/// prediction knows the rig
/// ([`lqi::predicted_rig`](super::lqi::predicted_rig)), simulated on the
/// same input through the same drive; `truth` is a simulated card's plant.
/// Work: one simulation of the run and three spectral estimates on
/// [`GRID_POINTS`] frequencies.
///
/// # Errors
///
/// A recording without `u` or `x2` or too short, an invalid model.
///
/// # Examples
///
/// ```
/// use ctrlab::OpenLoop;
/// use ctrlab::lab::{Calibration, SimulatedRig, frequency, lqi};
/// use ctrlab::signal::Signal;
/// use ctrlab::nalgebra::vector;
/// let sim = SimulatedRig::default();
/// let rig = lqi::predicted_rig(sim.truth, sim.friction.coulomb, &sim.calibration, sim.period);
/// let ms = frequency::multisine(8.0)?;
/// // The model's own run as the measurement: both peaks where the model's are.
/// let rec = ctrlab::run_sampled(rig.plant(), rig.sensor(), OpenLoop, |t| vector![ms.value(t)],
///                               vector![0.0, 0.0, 0.0, 0.0], &rig.sampled_config(frequency::DURATION))?;
/// let r = frequency::frequency_response(&rec, &rig, Some(&sim.truth), &ms)?;
/// assert_eq!(r.modes[0].measured_hz, r.modes[0].simulated_hz);
/// assert!(r.gap_friction < 1e-9);
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub fn frequency_response(
    measured: &Recording,
    rig: &SimulatedRig,
    truth: Option<&MassSpring>,
    multisine: &Multisine,
) -> Result<FrequencyResponse, Error> {
    let tau = std::f64::consts::TAU;
    let omega = logspace((0.2 * tau).log10(), (15.0 * tau).log10(), GRID_POINTS)?;
    let (raw, smoothed) = estimates(measured, &omega, rig.period)?;
    let simulated = run_sampled(
        rig.plant(),
        rig.sensor(),
        OpenLoop,
        |t| vector![multisine.value(t)],
        SVector::zeros(),
        &rig.sampled_config(DURATION),
    )?;
    let (_, simulated) = estimates(&simulated, &omega, rig.period)?;
    let model = bode(&rig.effective_truth().state_space(Cart::Two)?, &omega)?;
    let truth_bode = truth
        .map(|t| bode(&t.state_space(Cart::Two)?, &omega))
        .transpose()?;
    let model_modes = modes_hz(&rig.effective_truth())?;
    let measured_peaks = peaks_hz(&smoothed, 2);
    let simulated_peaks = peaks_hz(&simulated, 2);
    let truth_modes = truth.map(modes_hz).transpose()?;
    let modes = [0, 1].map(|i| Mode {
        model_hz: model_modes.get(i).copied(),
        simulated_hz: simulated_peaks.get(i).copied(),
        measured_hz: measured_peaks.get(i).copied(),
        truth_hz: truth_modes.as_ref().and_then(|t| t.get(i).copied()),
    });
    let magnitude = smoothed.magnitude();
    Ok(FrequencyResponse {
        gap_linear: median_gap(&magnitude, &model.magnitude),
        gap_friction: median_gap(&magnitude, &simulated.magnitude()),
        omega,
        measured: raw,
        smoothed,
        simulated,
        model,
        truth: truth_bode,
        modes,
    })
}
