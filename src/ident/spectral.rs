//! Frequency responses from data: the empirical transfer-function estimate
//! ([`etfe`]) and the smoothed spectral estimate of Blackman and Tukey
//! ([`spa`]), MATLAB's `etfe` and `spa`.

use nalgebra::Complex;
use rustfft::FftPlanner;

use crate::error::{Error, check_dt};
use crate::kernels::reduce::pow2_floor;

/// Bins of the ETFE whose input amplitude is below this fraction of the
/// largest (−60 dB) are left out: the input did not excite them, so the
/// ratio there is noise over nothing.
///
/// # Examples
///
/// A second tone at a tenth of the threshold is left out:
///
/// ```
/// use ctrlab::ident::{ETFE_MIN_INPUT, etfe};
/// let n = 64;
/// let tone = |k: usize, f: f64| (std::f64::consts::TAU * f * k as f64 / n as f64).sin();
/// let u: Vec<f64> = (0..n).map(|k| tone(k, 3.0) + 0.1 * ETFE_MIN_INPUT * tone(k, 5.0)).collect();
/// let g = etfe(&u, &u, 0.01)?;
/// assert_eq!(g.omega.len(), 1); // only the 3rd harmonic's bin
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub const ETFE_MIN_INPUT: f64 = 1e-3;

/// MATLAB's default lag window size for [`spa`]: `min(N / 10, 30)` samples.
///
/// # Examples
///
/// ```
/// use ctrlab::ident::{SPA_DEFAULT_LAG, spa};
/// use ctrlab::signal::Rng;
/// let mut rng = Rng::new(1);
/// let u: Vec<f64> = (0..1000).map(|_| rng.gaussian()).collect();
/// let y: Vec<f64> = u.iter().map(|v| 3.0 * v).collect();
/// // 1000 samples: min(1000 / 10, 30) = 30, the default window.
/// let g = spa(&u, &y, 0.01, None, &[1.0, 10.0])?;
/// assert_eq!(g, spa(&u, &y, 0.01, Some(SPA_DEFAULT_LAG), &[1.0, 10.0])?);
/// assert!(g.response.iter().all(|r| (r - 3.0).norm() < 1e-12));
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub const SPA_DEFAULT_LAG: usize = 30;

/// The most samples either estimate takes (one hour at 2 ms is 1.8e6):
/// bounds the work and the memory.
///
/// # Examples
///
/// ```
/// use ctrlab::ident::MAX_SPECTRAL_SAMPLES;
/// // At the rig's 2 ms period, over nine hours of data.
/// assert!(MAX_SPECTRAL_SAMPLES as f64 * 0.002 > 9.0 * 3600.0); // s
/// ```
pub const MAX_SPECTRAL_SAMPLES: usize = 1 << 24;

/// A frequency response estimated from data: the response (output unit per
/// input unit, complex) at each angular frequency.
///
/// # Examples
///
/// ```
/// use ctrlab::ident::etfe;
///
/// // y = 2 u over one period of a two-tone input: the estimate is 2 wherever
/// // the input has power.
/// let n = 64;
/// let u: Vec<f64> = (0..n).map(|k| {
///     let t = k as f64 / n as f64 * std::f64::consts::TAU;
///     (3.0 * t).sin() + (5.0 * t).cos()
/// }).collect();
/// let y: Vec<f64> = u.iter().map(|v| 2.0 * v).collect();
/// let g = etfe(&u, &y, 0.01)?;
/// assert_eq!(g.omega.len(), 2);
/// assert!(g.response.iter().all(|r| (r.re - 2.0).abs() < 1e-12 && r.im.abs() < 1e-12));
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct FrequencyEstimate {
    /// Angular frequencies, rad/s, ascending.
    pub omega: Vec<f64>,
    /// The estimated response at each frequency (output unit per input
    /// unit): `G(e^{jω dt})` of the sampled system.
    pub response: Vec<Complex<f64>>,
}

impl FrequencyEstimate {
    /// The frequencies in Hz (`ω / 2π`).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::ident::FrequencyEstimate;
    /// let g = FrequencyEstimate { omega: vec![std::f64::consts::TAU], response: vec![1.0.into()] };
    /// assert!((g.frequency_hz()[0] - 1.0).abs() < 1e-15);
    /// ```
    pub fn frequency_hz(&self) -> Vec<f64> {
        self.omega
            .iter()
            .map(|w| w / std::f64::consts::TAU)
            .collect()
    }

    /// The magnitudes `|G|` (output unit per input unit).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::ident::FrequencyEstimate;
    /// # use ctrlab::nalgebra::Complex;
    /// let g = FrequencyEstimate { omega: vec![1.0], response: vec![Complex::new(3.0, 4.0)] };
    /// assert_eq!(g.magnitude(), vec![5.0]);
    /// ```
    pub fn magnitude(&self) -> Vec<f64> {
        self.response.iter().map(|g| g.norm()).collect()
    }
}

/// Checks the shared inputs of both estimates.
fn check_data(u: &[f64], y: &[f64], dt: f64) -> Result<(), Error> {
    check_dt(dt)?;
    if u.len() != y.len() {
        return Err(Error::LengthMismatch {
            what: "y",
            expected: u.len(),
            found: y.len(),
        });
    }
    if u.len() < 4 {
        return Err(Error::TooFewSamples {
            what: "frequency-response estimate",
            needed: 4,
            got: u.len(),
        });
    }
    if u.len() > MAX_SPECTRAL_SAMPLES {
        return Err(Error::InvalidParameter {
            name: "u",
            value: u.len() as f64,
            reason: "more samples than MAX_SPECTRAL_SAMPLES",
        });
    }
    for (name, v) in [("u", u), ("y", y)] {
        if let Some(i) = v.iter().position(|x| !x.is_finite()) {
            return Err(Error::InvalidData {
                what: name,
                index: i,
                reason: "sample is NaN or infinite",
            });
        }
    }
    Ok(())
}

/// A power of two near the largest magnitude in `v` (1 for all zeros):
/// dividing by it is exact and leaves the largest entry in `[1, 2)`.
fn magnitude(v: &[f64]) -> f64 {
    pow2_floor(v.iter().fold(0.0f64, |m, x| m.max(x.abs())))
}

/// The empirical transfer-function estimate `Ĝ(ω_k) = Y(ω_k) / U(ω_k)`, the
/// ratio of the discrete Fourier transforms of output and input (MATLAB's
/// `etfe` without smoothing; Ljung, *System Identification*, §6.3).
///
/// `u` and `y` are sampled every `dt` seconds (input unit and output unit).
/// The frequencies are the DFT's, `ω_k = 2π k / (N dt)` rad/s for
/// `k = 1 … ⌊N/2⌋`, keeping only the bins where `|U(ω_k)|` is at least
/// [`ETFE_MIN_INPUT`] of its largest value (the excited ones).
///
/// The estimate is exact when the record holds whole periods of a periodic
/// input (a [`Multisine`](crate::signal::Multisine) or a full-period
/// [`Prbs`](crate::signal::Prbs)) in steady state; with a chirp or noise it
/// is unbiased but as noisy at each frequency as the data (smooth it with
/// [`spa`]). Transients and a non-periodic input leak between bins.
///
/// # Errors
///
/// [`Error::InvalidParameter`] for a `dt` that is not finite and positive or
/// more than [`MAX_SPECTRAL_SAMPLES`] samples; [`Error::LengthMismatch`] if
/// `y` and `u` differ in length; [`Error::TooFewSamples`] for fewer than
/// 4; [`Error::InvalidData`] for a non-finite sample;
/// [`Error::InvalidData`] (`"u"`) if the input is zero at every
/// non-zero frequency.
///
/// # Examples
///
/// ```
/// use ctrlab::ident::etfe;
///
/// // y[k] = u[k − 1] (one-sample delay) over whole periods: Ĝ = e^{−jω dt}.
/// let dt = 0.002;
/// let u: Vec<f64> = (0..200).map(|k| (std::f64::consts::TAU * 7.0 * k as f64 / 200.0).sin()).collect();
/// let y: Vec<f64> = (0..200).map(|k| u[(k + 199) % 200]).collect();
/// let g = etfe(&u, &y, dt)?;
/// let w = g.omega[0];
/// assert!((w - std::f64::consts::TAU * 7.0 / (200.0 * dt)).abs() < 1e-9);
/// assert!((g.response[0] - ctrlab::nalgebra::Complex::from_polar(1.0, -w * dt)).norm() < 1e-12);
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[doc(alias = "tfestimate")]
pub fn etfe(u: &[f64], y: &[f64], dt: f64) -> Result<FrequencyEstimate, Error> {
    check_data(u, y, dt)?;
    let n = u.len();
    let fft = FftPlanner::<f64>::new().plan_fft_forward(n);
    // Each signal divided by a power of two near its largest magnitude
    // (exact): the transform of ±1e308 would overflow. `G` is undone by
    // their ratio below.
    let (su, sy) = (magnitude(u), magnitude(y));
    let mut uf: Vec<Complex<f64>> = u.iter().map(|&v| Complex::new(v / su, 0.0)).collect();
    let mut yf: Vec<Complex<f64>> = y.iter().map(|&v| Complex::new(v / sy, 0.0)).collect();
    fft.process(&mut uf);
    fft.process(&mut yf);
    let bins = 1..=n / 2;
    let peak = bins.clone().map(|k| uf[k].norm()).fold(0.0, f64::max);
    if !(peak > 0.0 && peak.is_finite()) {
        return Err(Error::InvalidData {
            what: "u",
            index: 0,
            reason: "the input has no power at any non-zero frequency",
        });
    }
    let base = std::f64::consts::TAU / (n as f64 * dt);
    let mut out = FrequencyEstimate {
        omega: Vec::new(),
        response: Vec::new(),
    };
    for k in bins {
        if uf[k].norm() >= ETFE_MIN_INPUT * peak {
            let g = yf[k] / uf[k] * (sy / su);
            let w = base * k as f64;
            if !(g.re.is_finite() && g.im.is_finite() && w.is_finite()) {
                return Err(Error::Overflow {
                    operation: "empirical transfer-function estimate",
                });
            }
            out.omega.push(w);
            out.response.push(g);
        }
    }
    Ok(out)
}

/// The smoothed spectral estimate of Blackman and Tukey (MATLAB's `spa`):
/// `Ĝ(ω) = Φ̂_yu(ω) / Φ̂_u(ω)` with
///
/// ```text
/// R̂_yu(τ) = (1/N) Σ_t y(t+τ) u(t),   R̂_u(τ) = (1/N) Σ_t u(t+τ) u(t)
/// Φ̂_yu(ω) = Σ_{τ=−M}^{M} W_M(τ) R̂_yu(τ) e^{−jωτ dt}   (Φ̂_u likewise)
/// W_M(τ) = ½ (1 + cos(π τ / M))                     (Hann lag window)
/// ```
///
/// at the angular frequencies `omega` (rad/s, finite, ≥ 0; MATLAB's default
/// grid is 128 points up to the Nyquist frequency `π / dt`). A larger lag
/// window `lag = M` resolves sharper peaks with more variance; `None` takes
/// MATLAB's default `min(N/10, 30)`, which smooths the lab's lightly damped
/// modes: use a few hundred for them. The data's means are not removed
/// (as MATLAB's `spa`): detrend first if the record has an offset.
///
/// # Errors
///
/// As [`etfe`]; also [`Error::InvalidParameter`] (`"lag"`) for `M = 0` or
/// `M ≥ N`, (`"omega"`) for a negative or non-finite frequency or one whose
/// `ω·dt·M` overflows, and
/// [`Error::InvalidData`] (`"u"`) where the input's smoothed spectrum is not
/// positive at a requested frequency (no input power there).
///
/// # Examples
///
/// ```
/// use ctrlab::ident::spa;
/// use ctrlab::signal::Rng;
///
/// // White noise through y[k] = u[k] + 0.5 u[k−1]: G = 1 + 0.5 e^{−jω dt}.
/// let dt = 0.01;
/// let mut rng = Rng::new(7);
/// let u: Vec<f64> = (0..20_000).map(|_| rng.gaussian()).collect();
/// let y: Vec<f64> = (0..u.len()).map(|k| u[k] + if k > 0 { 0.5 * u[k - 1] } else { 0.0 }).collect();
/// let w = [10.0, 100.0];
/// let g = spa(&u, &y, dt, None, &w)?;
/// for (w, g) in w.iter().zip(&g.response) {
///     let truth = 1.0 + ctrlab::nalgebra::Complex::from_polar(0.5, -w * dt);
///     assert!((g - truth).norm() < 0.02);
/// }
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub fn spa(
    u: &[f64],
    y: &[f64],
    dt: f64,
    lag: Option<usize>,
    omega: &[f64],
) -> Result<FrequencyEstimate, Error> {
    check_data(u, y, dt)?;
    let n = u.len();
    let m = lag.unwrap_or_else(|| (n / 10).clamp(1, SPA_DEFAULT_LAG));
    if m == 0 || m >= n {
        return Err(Error::InvalidParameter {
            name: "lag",
            value: m as f64,
            reason: "the lag window must be at least 1 and less than the number of samples",
        });
    }
    if let Some(&w) = omega.iter().find(|w| !(w.is_finite() && **w >= 0.0)) {
        return Err(Error::InvalidParameter {
            name: "omega",
            value: w,
            reason: "frequencies must be finite and >= 0 rad/s",
        });
    }
    if let Some(&w) = omega.iter().find(|w| !(**w * dt * m as f64).is_finite()) {
        return Err(Error::InvalidParameter {
            name: "omega",
            value: w,
            reason: "ω·dt·lag overflows: the frequency is far beyond the Nyquist frequency \
                     of this dt",
        });
    }
    // The signals divided by powers of two near their largest magnitudes
    // (exact), so their products cannot overflow; `G` is undone by their
    // ratio below.
    let (su, sy) = (magnitude(u), magnitude(y));
    let u: Vec<f64> = u.iter().map(|v| v / su).collect();
    let y: Vec<f64> = y.iter().map(|v| v / sy).collect();
    let (u, y) = (u.as_slice(), y.as_slice());
    // Covariances at lags −M … M (R̂_yu is not symmetric; R̂_u is).
    let cross = |a: &[f64], b: &[f64], tau: usize| -> f64 {
        a[tau..].iter().zip(b).map(|(x, y)| x * y).sum::<f64>() / n as f64
    };
    let mut r_u = Vec::with_capacity(m + 1);
    let mut r_yu_pos = Vec::with_capacity(m + 1);
    let mut r_yu_neg = Vec::with_capacity(m + 1);
    for tau in 0..=m {
        let w = 0.5 * (1.0 + (std::f64::consts::PI * tau as f64 / m as f64).cos());
        r_u.push(w * cross(u, u, tau));
        r_yu_pos.push(w * cross(y, u, tau)); // y(t+τ) u(t)
        r_yu_neg.push(w * cross(u, y, tau)); // y(t) u(t+τ) = R_yu(−τ)
    }
    let scale = r_u[0].abs().max(f64::MIN_POSITIVE);
    let mut out = FrequencyEstimate {
        omega: omega.to_vec(),
        response: Vec::with_capacity(omega.len()),
    };
    for &w in omega {
        let (mut phi_u, mut phi_yu) = (r_u[0], Complex::new(r_yu_pos[0], 0.0));
        for tau in 1..=m {
            let (s, c) = (w * dt * tau as f64).sin_cos();
            phi_u += 2.0 * r_u[tau] * c;
            // e^{−jωτ} R(τ) + e^{+jωτ} R(−τ)
            phi_yu += Complex::new(
                (r_yu_pos[tau] + r_yu_neg[tau]) * c,
                (r_yu_neg[tau] - r_yu_pos[tau]) * s,
            );
        }
        // A spectrum below rounding of its lag-0 term is no input power.
        if phi_u.is_nan() || phi_u <= 1e-12 * scale {
            return Err(Error::InvalidData {
                what: "u",
                index: 0,
                reason: "the input's smoothed spectrum is not positive at a requested frequency",
            });
        }
        let g = phi_yu / phi_u * (sy / su);
        if !(g.re.is_finite() && g.im.is_finite()) {
            return Err(Error::Overflow {
                operation: "spectral estimate (spa)",
            });
        }
        out.response.push(g);
    }
    Ok(out)
}
