//! [`Bode`] and [`Nyquist`] data of one SISO channel, from a
//! [`FrequencyResponse`](super::FrequencyResponse).

use std::f64::consts::PI;

use nalgebra::Complex;

type C64 = Complex<f64>;
use crate::error::Error;

/// Bode data of a SISO channel: magnitude (absolute, in the model's units)
/// and phase (rad, unwrapped) at each angular frequency `ω` (rad/s).
///
/// The phase starts at the principal value `atan2(Im G, Re G)` ∈ (−π, π]
/// of the first point and is unwrapped in the order of `ω` as NumPy's
/// `unwrap` does (each step brought within ±π), so a grid too coarse for a
/// fast phase change can unwrap by the wrong turn. python-control's `bode`
/// unwraps the same way and then shifts the whole curve by a multiple of
/// 360° to start within 180° of −180° (its default `initial_phase`), so
/// 1/s³ starts at +90° here and at −270° there; [`bode_with`](super::bode_with)
/// with [`BodeOptions`](super::BodeOptions) applies python-control's
/// conventions (`initial_phase`, `wrap_phase`).
///
/// # Examples
///
/// ```
/// use ctrlab::freq::{Bode, FrequencyDomain, TransferFunction};
///
/// let g = TransferFunction::continuous(&[1.0], &[1.0, 2.0, 1.0])?; // 1/(s + 1)²
/// let b: Bode = g.frequency_response(&[1.0])?.bode(0, 0)?;
/// assert!((b.magnitude_db()[0] + 6.0206).abs() < 1e-4);
/// assert!((b.phase_deg()[0] + 90.0).abs() < 1e-12);
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct Bode {
    /// Angular frequencies, rad/s.
    pub omega: Vec<f64>,
    /// `|G|` at each frequency (absolute).
    pub magnitude: Vec<f64>,
    /// `∠G` at each frequency, rad, unwrapped.
    pub phase: Vec<f64>,
}

/// `|g|`: `√(re² + im²)`, through `hypot` only where the squares
/// under- or overflow.
fn magnitude(g: C64) -> f64 {
    let n2 = g.norm_sqr();
    if n2.is_finite() && n2 >= f64::MIN_POSITIVE {
        n2.sqrt()
    } else {
        g.norm()
    }
}

/// The phase angles of `g`, unwrapped (NumPy's `unwrap` with period 2π).
pub(crate) fn unwrapped_phase(g: &[C64]) -> Vec<f64> {
    let mut out: Vec<f64> = Vec::with_capacity(g.len());
    let mut prev_raw = 0.0;
    for (k, g) in g.iter().enumerate() {
        let raw = g.im.atan2(g.re);
        if k == 0 {
            out.push(raw);
        } else {
            // Both angles are in [−π, π], so the step is within ±2π: one
            // turn at most to take off (NumPy keeps +π for a step of +π).
            let d = raw - prev_raw;
            let dd = if d > PI {
                d - 2.0 * PI
            } else if d < -PI {
                d + 2.0 * PI
            } else {
                d
            };
            let last = out[k - 1];
            out.push(last + dd);
        }
        prev_raw = raw;
    }
    out
}

impl Bode {
    /// Bode data of complex response values `g` at `omega` (rad/s): the
    /// magnitudes, and the phases unwrapped along the given order as
    /// [`bode`](super::bode) unwraps them. For responses computed elsewhere, such as an
    /// estimate from data ([`ident::etfe`](crate::ident::etfe)).
    ///
    /// # Errors
    ///
    /// [`Error::LengthMismatch`] if `g` does not have one value per
    /// frequency.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::freq::Bode;
    /// use ctrlab::nalgebra::Complex;
    ///
    /// // Three points going once around the origin: the phase keeps falling.
    /// let g = [Complex::new(0.0, -1.0), Complex::new(-1.0, 0.0), Complex::new(0.0, 1.0)];
    /// let b = Bode::from_response(&[1.0, 2.0, 3.0], &g)?;
    /// assert_eq!(b.magnitude, vec![1.0; 3]);
    /// assert!((b.phase_deg()[2] + 270.0).abs() < 1e-12);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn from_response(omega: &[f64], g: &[C64]) -> Result<Self, Error> {
        if g.len() != omega.len() {
            return Err(Error::LengthMismatch {
                what: "g",
                expected: omega.len(),
                found: g.len(),
            });
        }
        Ok(Self::from_checked(omega, g))
    }

    pub(super) fn from_checked(omega: &[f64], g: &[C64]) -> Self {
        Self {
            omega: omega.to_vec(),
            magnitude: g.iter().map(|&g| magnitude(g)).collect(),
            phase: unwrapped_phase(g),
        }
    }

    /// The magnitude in decibels, `20 log₁₀ |G|`. An exact zero of `G`
    /// gives `20 log₁₀(f64::MIN_POSITIVE)` ≈ −6153.6 dB, not −∞, so every
    /// value is finite.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::freq::{FrequencyDomain, TransferFunction};
    /// let b = TransferFunction::continuous(&[10.0], &[1.0])?.frequency_response(&[1.0])?.bode(0, 0)?;
    /// assert_eq!(b.magnitude_db(), vec![20.0]);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn magnitude_db(&self) -> Vec<f64> {
        self.magnitude
            .iter()
            .map(|m| 20.0 * m.max(f64::MIN_POSITIVE).log10())
            .collect()
    }

    /// The unwrapped phase in degrees.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::freq::{FrequencyDomain, TransferFunction};
    /// let b = TransferFunction::continuous(&[-1.0], &[1.0])?.frequency_response(&[1.0])?.bode(0, 0)?;
    /// assert_eq!(b.phase_deg(), vec![180.0]);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn phase_deg(&self) -> Vec<f64> {
        self.phase.iter().map(|p| p.to_degrees()).collect()
    }

    /// The frequencies in hertz, `ω / 2π`.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::freq::{FrequencyDomain, TransferFunction};
    /// let b = TransferFunction::continuous(&[1.0], &[1.0])?.frequency_response(&[std::f64::consts::PI])?.bode(0, 0)?;
    /// assert_eq!(b.frequency_hz(), vec![0.5]);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn frequency_hz(&self) -> Vec<f64> {
        self.omega.iter().map(|w| w / (2.0 * PI)).collect()
    }
}

/// Nyquist data of a SISO channel: `G(jω)` split into real and imaginary
/// parts, at each angular frequency `ω` (rad/s). The mirror image for
/// negative frequencies is `(re, −im)`.
///
/// # Examples
///
/// ```
/// use ctrlab::freq::{FrequencyDomain, TransferFunction};
///
/// let n = TransferFunction::continuous(&[1.0], &[1.0, 1.0])?.frequency_response(&[0.0, 1.0])?.nyquist(0, 0)?;
/// assert_eq!(n.re, vec![1.0, 0.5]);
/// assert_eq!(n.im, vec![0.0, -0.5]);
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct Nyquist {
    /// Angular frequencies, rad/s.
    pub omega: Vec<f64>,
    /// `Re G` at each frequency.
    pub re: Vec<f64>,
    /// `Im G` at each frequency.
    pub im: Vec<f64>,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unwrap_follows_numpy() {
        let g: Vec<C64> = [170.0f64, -170.0, -100.0, 10.0, 179.0, -179.0]
            .iter()
            .map(|d| C64::from_polar(1.0, d.to_radians()))
            .collect();
        let p: Vec<f64> = unwrapped_phase(&g).iter().map(|p| p.to_degrees()).collect();
        let want = [170.0, 190.0, 260.0, 370.0, 539.0, 541.0];
        for (p, w) in p.iter().zip(want) {
            assert!((p - w).abs() < 1e-9, "{p} vs {w}");
        }
    }
}
