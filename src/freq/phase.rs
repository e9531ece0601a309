//! python-control's phase conventions for Bode data: where the phase
//! starts (`initial_phase`) and whether it is unwrapped or wrapped
//! (`wrap_phase`), as its `bode_plot` applies them.

use std::f64::consts::PI;

use nalgebra::Complex;

use super::bode::{Bode, unwrapped_phase};
use super::response::{FrequencyDomain, FrequencyResponse, siso};
use crate::error::Error;

/// How [`bode_with`] presents the phase: python-control's `wrap_phase`.
///
/// # Examples
///
/// ```
/// use ctrlab::freq::{BodeOptions, TransferFunction, WrapPhase, bode_with};
///
/// // 1/s⁵: −450° unwrapped from python-control's start, −90° wrapped.
/// let g = TransferFunction::continuous(&[1.0], &[1.0, 0.0, 0.0, 0.0, 0.0, 0.0])?;
/// let wrapped = BodeOptions { wrap_phase: WrapPhase::Wrap, ..Default::default() };
/// assert!((bode_with(&g, &[1.0], &wrapped)?.phase_deg()[0] + 90.0).abs() < 1e-12);
/// let at_least = BodeOptions { wrap_phase: WrapPhase::AtLeast(-270.0), ..Default::default() };
/// assert!((bode_with(&g, &[1.0], &at_least)?.phase_deg()[0] + 90.0).abs() < 1e-12);
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[doc(alias = "wrap_phase")]
pub enum WrapPhase {
    /// Unwrapped along `ω` (NumPy's `unwrap`): continuous, possibly
    /// beyond ±180°. python-control's `wrap_phase=False`, its default.
    #[default]
    Unwrap,
    /// The principal value at each frequency, in [−180°, 180°] (after the
    /// `initial_phase` shift, which here defaults to 0°):
    /// `wrap_phase=True`.
    Wrap,
    /// Unwrapped, then each point raised by whole turns until it is at
    /// least this value (degrees): `wrap_phase=<float>`.
    AtLeast(f64),
}

/// Phase options for [`bode_with`] and [`FrequencyResponse::bode_with`],
/// named as python-control's `bode_plot` names them (degrees, its default
/// `deg=True`). `Default` is python-control's default: unwrapped, starting
/// within 180° of −180° (0° when wrapped), so `1/s³` starts at −270°
/// where [`bode`](super::bode) — the principal value at the first
/// frequency, unwrapped — starts at +90°.
///
/// # Examples
///
/// ```
/// use ctrlab::freq::{BodeOptions, TransferFunction, bode, bode_with};
///
/// let g = TransferFunction::continuous(&[1.0], &[1.0, 0.0, 0.0, 0.0])?; // 1/s³
/// assert!((bode(&g, &[1.0])?.phase_deg()[0] - 90.0).abs() < 1e-12);
/// let peer = bode_with(&g, &[1.0], &BodeOptions::default())?;
/// assert!((peer.phase_deg()[0] + 270.0).abs() < 1e-12);
/// let near_180 = BodeOptions { initial_phase: Some(180.0), ..Default::default() };
/// assert!((bode_with(&g, &[1.0], &near_180)?.phase_deg()[0] - 90.0).abs() < 1e-12);
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct BodeOptions {
    /// The phase (degrees) the curve starts nearest to: the whole curve is
    /// shifted by the whole turns that bring its first point within 180°
    /// of it (ties rounded to even, as Python's `round`). `None`:
    /// python-control's default, −180° ([`WrapPhase::Wrap`]: 0°).
    pub initial_phase: Option<f64>,
    /// Unwrapped, wrapped, or unwrapped and kept above a floor.
    pub wrap_phase: WrapPhase,
}

impl BodeOptions {
    fn validate(&self) -> Result<(), Error> {
        let bad = |name, value| Error::InvalidParameter {
            name,
            value,
            reason: "must be finite (degrees)",
        };
        if let Some(p) = self.initial_phase
            && !p.is_finite()
        {
            return Err(bad("initial_phase", p));
        }
        if let WrapPhase::AtLeast(p) = self.wrap_phase
            && !p.is_finite()
        {
            return Err(bad("wrap_phase", p));
        }
        Ok(())
    }

    /// The phases of `g` under these options (python-control's
    /// `bode_plot`, SISO channel).
    fn phase(&self, g: &[Complex<f64>]) -> Vec<f64> {
        let initial = match (self.initial_phase, self.wrap_phase) {
            (Some(p), _) => p.to_radians(),
            (None, WrapPhase::Wrap) => 0.0,
            (None, _) => -PI,
        };
        let mut phase = match self.wrap_phase {
            WrapPhase::Wrap => g.iter().map(|g| g.im.atan2(g.re)).collect(),
            _ => unwrapped_phase(g),
        };
        // Unwrapping keeps the first point, so shifting before or after it
        // is the same.
        if let Some(&first) = phase.first()
            && (first - initial).abs() > PI
        {
            let turns = ((first - initial) / (2.0 * PI)).round_ties_even();
            phase.iter_mut().for_each(|p| *p -= 2.0 * PI * turns);
        }
        if let WrapPhase::AtLeast(floor) = self.wrap_phase {
            let floor = floor.to_radians();
            for p in &mut phase {
                *p += 2.0 * PI * ((floor - *p) / (2.0 * PI)).ceil().max(0.0);
            }
        }
        phase
    }
}

impl FrequencyResponse {
    /// [`bode`](Self::bode) with python-control's phase conventions
    /// ([`BodeOptions`]).
    ///
    /// # Errors
    ///
    /// As [`response`](Self::response); [`Error::InvalidParameter`] for a
    /// non-finite `initial_phase` or [`WrapPhase::AtLeast`].
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::freq::{BodeOptions, FrequencyDomain, TransferFunction};
    ///
    /// let g = TransferFunction::continuous(&[1.0], &[1.0, 0.0, 0.0])?; // 1/s²
    /// let b = g.frequency_response(&[1.0])?.bode_with(0, 0, &BodeOptions::default())?;
    /// assert!((b.phase_deg()[0] + 180.0).abs() < 1e-12);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn bode_with(
        &self,
        output: usize,
        input: usize,
        options: &BodeOptions,
    ) -> Result<Bode, Error> {
        options.validate()?;
        let mut b = self.bode(output, input)?;
        b.phase = options.phase(self.response(output, input)?);
        Ok(b)
    }
}

/// [`bode`](super::bode) with python-control's phase conventions: its
/// `bode_plot(sys, omega, initial_phase=…, wrap_phase=…)` phases, in rad
/// in [`Bode::phase`] as everywhere in the crate (the options are in
/// degrees, as python-control's with its default `deg=True`).
///
/// # Errors
///
/// [`Error::DimensionMismatch`] unless the model has one input and one
/// output; [`Error::InvalidParameter`] for a non-finite option; as
/// [`FrequencyDomain::frequency_response`].
///
/// # Examples
///
/// ```
/// use ctrlab::freq::{BodeOptions, TransferFunction, bode_with};
///
/// // 1/(s − 1)²: python-control puts it between −360° and −180°.
/// let g = TransferFunction::continuous(&[1.0], &[1.0, -2.0, 1.0])?;
/// let b = bode_with(&g, &[0.01, 1.0, 100.0], &BodeOptions::default())?;
/// assert!(b.phase_deg().iter().all(|&p| (-360.0..=-180.0).contains(&p)));
/// let bad = BodeOptions { initial_phase: Some(f64::NAN), ..Default::default() };
/// assert!(bode_with(&g, &[1.0], &bad).is_err());
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[doc(alias = "bode_plot")]
pub fn bode_with(
    sys: &impl FrequencyDomain,
    omega: &[f64],
    options: &BodeOptions,
) -> Result<Bode, Error> {
    options.validate()?;
    siso(sys.frequency_response(omega)?)?.bode_with(0, 0, options)
}
