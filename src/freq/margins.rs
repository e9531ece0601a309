//! Stability margins and bandwidth of a SISO loop, from exact crossings:
//! the crossover frequencies are roots of polynomials in `ω` (continuous)
//! or `z` (discrete) built from the transfer function, as python-control's
//! `stability_margins(method="poly")` finds them, so no crossing is missed
//! between grid points.

use std::f64::consts::PI;

use super::poly;
use super::response::{FrequencyDomain, point, siso_transfer_function};
use super::tf::TransferFunction;
use crate::error::Error;
use crate::model::{Domain, period_of};

/// A root counts as real when its imaginary part is below `√ε` of its
/// modulus: real eigenvalues of the companion matrix come out with a zero
/// imaginary part, but a double root (a curve touching the level) splits
/// into a pair about `√ε` apart.
fn real_roots(p: &[f64]) -> Result<Vec<f64>, Error> {
    let tol = f64::EPSILON.sqrt();
    Ok(poly::roots(p)?
        .into_iter()
        .filter(|r| r.im.abs() <= tol * r.norm())
        .map(|r| r.re)
        .collect())
}

/// `p(jω) = re(ω) + j im(ω)`: two real polynomials in `ω`.
fn jw_parts(p: &[f64]) -> (Vec<f64>, Vec<f64>) {
    let deg = p.len() - 1;
    let (mut re, mut im) = (vec![0.0; p.len()], vec![0.0; p.len()]);
    for (k, &c) in p.iter().enumerate() {
        match (deg - k) % 4 {
            0 => re[k] = c,
            1 => im[k] = c,
            2 => re[k] = -c,
            _ => im[k] = -c,
        }
    }
    (re, im)
}

/// `p · z^k`.
fn shift(mut p: Vec<f64>, k: usize) -> Vec<f64> {
    p.extend(std::iter::repeat_n(0.0, k));
    p
}

/// Which crossing: `Im G = 0` (phase ±180° or 0°), or `|G| = level`.
#[derive(Clone, Copy)]
pub(crate) enum Crossing {
    RealAxis,
    Magnitude(f64),
}

/// The frequencies `ω ≥ 0` (rad/s) of a crossing, ascending.
pub(crate) fn crossings<D: Domain>(
    g: &TransferFunction<D>,
    kind: Crossing,
) -> Result<Vec<f64>, Error> {
    let (num, den) = (g.num(), g.den());
    let w = match period_of(&g.domain()) {
        None => {
            let (nr, ni) = jw_parts(num);
            let (dr, di) = jw_parts(den);
            let test = match kind {
                // Im(N/D) = 0 ⇔ Ni Dr − Nr Di = 0.
                Crossing::RealAxis => {
                    poly::sub_scaled(&poly::mul(&ni, &dr), 1.0, &poly::mul(&nr, &di))
                }
                // |N|² − g²|D|² = 0.
                Crossing::Magnitude(level) => {
                    let n2 = poly::sub_scaled(&poly::mul(&nr, &nr), -1.0, &poly::mul(&ni, &ni));
                    let d2 = poly::sub_scaled(&poly::mul(&dr, &dr), -1.0, &poly::mul(&di, &di));
                    poly::sub_scaled(&n2, level * level, &d2)
                }
            };
            real_roots(&test)?
                .into_iter()
                .filter(|w| *w >= 0.0)
                .collect::<Vec<_>>()
        }
        Some(dt) => {
            // On |z| = 1, 1/z = z̄: N(1/z) = rev N(z) / z^p.
            let (p, q) = (num.len() - 1, den.len() - 1);
            let m = p.max(q);
            let rev = |x: &[f64]| x.iter().rev().copied().collect::<Vec<_>>();
            let test = match kind {
                Crossing::RealAxis => poly::sub_scaled(
                    &shift(poly::mul(num, &rev(den)), m - q),
                    1.0,
                    &shift(poly::mul(&rev(num), den), m - p),
                ),
                Crossing::Magnitude(level) => poly::sub_scaled(
                    &shift(poly::mul(num, &rev(num)), m - p),
                    level * level,
                    &shift(poly::mul(den, &rev(den)), m - q),
                ),
            };
            // python-control's tolerance on |z| = 1: ε^(1 / number of
            // coefficients), the spread of a root of that multiplicity.
            let tol = f64::EPSILON.powf(1.0 / (2 * m + 1) as f64);
            poly::roots(&test)?
                .into_iter()
                // Upper half circle, z = −1 (ω = π/dt) included whichever
                // sign rounding gave its imaginary part.
                .filter(|z| (z.norm() - 1.0).abs() < tol && z.im >= -1e-12)
                .map(|z| {
                    // ω = θ / dt overflows for a subnormal period
                    // (dt = 1e-310: every crossing but ω = 0 is beyond
                    // f64); refused, not returned as ∞.
                    let w = z.im.max(0.0).atan2(z.re) / dt;
                    if w.is_finite() {
                        Ok(w)
                    } else {
                        Err(Error::Overflow {
                            operation: "discrete crossing frequency (θ / dt)",
                        })
                    }
                })
                .collect::<Result<Vec<_>, _>>()?
        }
    };
    let period = period_of(&g.domain());
    let mut w: Vec<f64> = w
        .into_iter()
        .filter_map(|w| {
            polish(w, |w| {
                let v = g.evaluate(point(period, w)).ok()?;
                let f = match kind {
                    Crossing::RealAxis => v.im / v.norm(),
                    Crossing::Magnitude(level) => (v.norm() / level).ln(),
                };
                f.is_finite().then_some(f)
            })
        })
        .collect();
    w.sort_by(f64::total_cmp);
    // Two inaccurate roots may polish to the same crossing.
    w.dedup_by(|b, a| (*b - *a).abs() <= SAME_CROSSING * a.abs().max(b.abs()));
    Ok(w)
}

/// Two polished crossings this close (relative) are one.
const SAME_CROSSING: f64 = 1e-9;

/// A residual (relative: `Im G / |G|`, or `ln(|G| / level)`) this small
/// marks a crossing checked on the response itself; evaluating an
/// ill-conditioned transfer function near `z = 1` is itself only good to
/// ~1e-9 relative (gh-523 b: 1.1e-9 at the converged crossing).
const ON_CROSSING: f64 = 1e-6;

/// A root whose residual, polished or not, stays above this is no crossing
/// (gh-523 b's spurious root: `ln |L| = −0.145`).
const OFF_CROSSING: f64 = 1e-4;

/// A crossing frequency refined by secant steps on the exact residual `f`
/// (at most 16). The polynomial's roots carry the rounding of its
/// coefficients: ~1e-9 relative near |z| = 1 in general, but whole
/// percents for a discrete loop whose `|N|²` is many orders below `|D|²`
/// on the circle (python-control's "numerical inaccuracy in 'poly'" case,
/// where it falls back to interpolated frequency data): there the root is
/// only a starting point. The refined frequency is kept if its residual
/// shrank and either it moved by under 0.1 % or its residual is below
/// [`ON_CROSSING`] (a crossing checked on the response, however far the
/// root was from it). A root whose residual stays above [`OFF_CROSSING`]
/// either way is no crossing and is dropped (`None`); a root where `f`
/// cannot be evaluated (a pole on the axis) is kept as it is.
fn polish(w: f64, f: impl Fn(f64) -> Option<f64>) -> Option<f64> {
    if w == 0.0 {
        return Some(w); // exact: the real-axis polynomial is odd in ω
    }
    let Some(f_start) = f(w) else { return Some(w) };
    let (mut w0, mut f0) = (w, f_start);
    let mut w1 = w * (1.0 + 1e-7);
    let Some(mut f1) = f(w1) else { return Some(w) };
    for _ in 0..16 {
        if f1 == f0 || f1 == 0.0 {
            break;
        }
        let w2 = w1 - f1 * (w1 - w0) / (f1 - f0);
        let Some(f2) = f(w2) else { break };
        (w0, f0, w1, f1) = (w1, f1, w2, f2);
        if (w1 - w0).abs() <= 4.0 * f64::EPSILON * w1.abs() {
            break;
        }
    }
    let (best, f_best) = if f1.abs() <= f0.abs() {
        (w1, f1)
    } else {
        (w0, f0)
    };
    let near = (best - w).abs() <= 1e-3 * w.abs();
    let (w, f_w) = if best.is_finite()
        && best > 0.0
        && f_best.abs() <= f_start.abs()
        && (near || f_best.abs() <= ON_CROSSING)
    {
        (best, f_best)
    } else {
        (w, f_start)
    };
    (f_w.abs() <= OFF_CROSSING).then_some(w)
}

/// The gain margin and the phase crossover frequency it is read at.
///
/// # Examples
///
/// ```
/// # use ctrlab::freq::{TransferFunction, stability_margins};
/// let m = stability_margins(&TransferFunction::continuous(&[2.0], &[1.0, 3.0, 3.0, 1.0])?)?;
/// let gm = m.gain.unwrap();
/// assert!((gm.margin - 4.0).abs() < 1e-12 && (gm.margin_db() - 12.0412).abs() < 1e-4);
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GainMargin {
    /// `1 / |L(jω₁₈₀)|`, absolute (> 1: the gain may grow by that factor).
    pub margin: f64,
    /// The phase crossover frequency `ω₁₈₀`, rad/s.
    pub frequency: f64,
}

impl GainMargin {
    /// The margin in dB, `20 log₁₀ margin`.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::freq::GainMargin;
    /// assert_eq!(GainMargin { margin: 10.0, frequency: 1.0 }.margin_db(), 20.0);
    /// ```
    pub fn margin_db(&self) -> f64 {
        20.0 * self.margin.log10()
    }
}

/// The phase margin and the gain crossover frequency it is read at.
///
/// # Examples
///
/// ```
/// # use ctrlab::freq::{TransferFunction, stability_margins};
/// // 1/(s(s + 1)): |L| = 1 at ω ≈ 0.786 rad/s, phase margin ≈ 51.8°.
/// let pm = stability_margins(&TransferFunction::continuous(&[1.0], &[1.0, 1.0, 0.0])?)?.phase.unwrap();
/// assert!((pm.margin - 51.827).abs() < 1e-3 && (pm.frequency - 0.78615).abs() < 1e-5);
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PhaseMargin {
    /// `∠L(jω_c) + 180°`, in degrees, in [−180°, 180°).
    pub margin: f64,
    /// The gain crossover frequency `ω_c`, rad/s.
    pub frequency: f64,
}

/// The delay margin and the gain crossover frequency it is set by.
///
/// # Examples
///
/// ```
/// # use ctrlab::freq::{TransferFunction, stability_margins};
/// // 1/s: crossover at 1 rad/s with 90° of margin: a delay of π/2 s.
/// let dm = stability_margins(&TransferFunction::continuous(&[1.0], &[1.0, 0.0])?)?.delay.unwrap();
/// assert!((dm.margin - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DelayMargin {
    /// The smallest pure delay, in seconds, that brings the loop to the
    /// critical point: `((PM mod 360°) in rad) / ω_c`.
    pub margin: f64,
    /// The gain crossover frequency `ω_c` that sets it, rad/s.
    pub frequency: f64,
}

/// The stability margins of a SISO loop transfer function `L` (the loop
/// is closed with negative feedback, `1 + L = 0` at instability).
/// Each is `None` where its crossing does not exist.
///
/// `L` is any [`FrequencyDomain`] model: a [`TransferFunction`], a
/// [`Zpk`](super::Zpk), a 1 × 1 [`TransferMatrix`](super::TransferMatrix),
/// or a `StateSpace` / `DynStateSpace` with one input and one output, which
/// is converted by [`TransferFunction::from_state_space`] first (the same
/// numbers as converting it yourself).
///
/// Definitions (frequencies in rad/s; a discrete `L` is evaluated at
/// `z = e^(jω dt)`, `0 ≤ ω ≤ π/dt`):
///
/// - gain margin `1/|L(jω)|` at the phase crossovers, the `ω ≥ 0` where
///   `L(jω)` is real and negative; of several, the one closest to 1 in
///   log scale (`min |ln GM|`), as python-control;
/// - phase margin `(∠L(jω) mod 360°) − 180°` ∈ [−180°, 180°) at the gain
///   crossovers, the `ω > 0` where `|L(jω)| = 1`; of several, the one of
///   smallest magnitude, as python-control;
/// - delay margin: the smallest `(PM_i mod 360°)·π/180 / ω_i` over all
///   gain crossovers `ω_i > 0` (seconds also for a discrete loop: divide by
///   `dt` for MATLAB's sample periods). Meaningful when the closed loop is
///   stable; not checked.
///
/// Differences from python-control 0.10.2's `stability_margins`: a zero of
/// `L` on the axis is not a phase crossover (python-control reports an
/// infinite gain margin there); a discrete phase crossover at exactly the
/// Nyquist frequency (`z = −1`) counts (python-control drops `z = −1`);
/// python-control returns no delay margin and adds the stability margin
/// `min |1 + L|`, which this does not compute; `None` replaces its `inf`
/// and `nan`. Discrete loops always use the polynomial method (python-control
/// may fall back to interpolated frequency data, with a warning).
///
/// # Errors
///
/// [`Error::DimensionMismatch`] named `"D"` (expected 1 × 1) for a model
/// with several inputs or outputs; the errors of
/// [`TransferFunction::from_state_space`] for a state-space model; the
/// errors of the polynomial root computations ([`Error::Overflow`],
/// [`Error::NoConvergence`]); [`Error::Overflow`] for a discrete model
/// whose crossing frequency `θ/dt` is beyond `f64` (a subnormal `dt`).
///
/// # Examples
///
/// ```
/// use ctrlab::freq::{TransferFunction, stability_margins};
///
/// // L = 2 / (s + 1)³: phase crossover at √3 rad/s, |L| = 1/4 there.
/// let m = stability_margins(&TransferFunction::continuous(&[2.0], &[1.0, 3.0, 3.0, 1.0])?)?;
/// let (gm, pm) = (m.gain.unwrap(), m.phase.unwrap());
/// assert!((gm.margin - 4.0).abs() < 1e-12 && (gm.frequency - 3f64.sqrt()).abs() < 1e-12);
/// assert!(pm.margin > 0.0 && pm.frequency < gm.frequency);
/// // A stable first-order lag with gain below 1: no crossing at all.
/// let m = stability_margins(&TransferFunction::continuous(&[0.5], &[1.0, 1.0])?)?;
/// assert!(m.gain.is_none() && m.phase.is_none() && m.delay.is_none());
///
/// // A state-space loop directly: the lab's plant under 2000 N/m of
/// // position feedback, the same margins as through its transfer function.
/// use ctrlab::{Cart, MassSpring};
/// let plant = MassSpring::nominal().state_space(Cart::Two)?;
/// let loop_ss = ctrlab::StateSpace::continuous(*plant.a(), *plant.b(), plant.c() * 2000.0, *plant.d())?;
/// let m = stability_margins(&loop_ss)?;
/// assert_eq!(m, stability_margins(&TransferFunction::try_from(&loop_ss)?)?);
/// assert!(m.phase.is_some());
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[doc(alias = "margin")]
#[doc(alias = "allmargin")]
pub fn stability_margins(l: &impl FrequencyDomain) -> Result<Margins, Error> {
    margins(siso_transfer_function(l)?.as_ref())
}

/// [`stability_margins`] of a transfer function.
fn margins<D: Domain>(l: &TransferFunction<D>) -> Result<Margins, Error> {
    let period = period_of(&l.domain());
    let at = |w: f64| l.evaluate(point(period, w));
    let mut gain: Option<GainMargin> = None;
    for w in crossings(l, Crossing::RealAxis)? {
        let Ok(g) = at(w) else { continue }; // a pole on the axis
        if g.re >= 0.0 || g.re.is_nan() {
            continue;
        }
        let candidate = GainMargin {
            margin: 1.0 / g.norm(),
            frequency: w,
        };
        if candidate.margin.is_finite()
            && gain.is_none_or(|best| candidate.margin.ln().abs() < best.margin.ln().abs())
        {
            gain = Some(candidate);
        }
    }
    let (mut phase, mut delay): (Option<PhaseMargin>, Option<DelayMargin>) = (None, None);
    for w in crossings(l, Crossing::Magnitude(1.0))? {
        if w <= 0.0 {
            continue;
        }
        let Ok(g) = at(w) else { continue };
        let pm = g.im.atan2(g.re).to_degrees().rem_euclid(360.0) - 180.0;
        if phase.is_none_or(|best| pm.abs() < best.margin.abs()) {
            phase = Some(PhaseMargin {
                margin: pm,
                frequency: w,
            });
        }
        let dm = pm.rem_euclid(360.0).to_radians() / w;
        if dm.is_finite() && delay.is_none_or(|best| dm < best.margin) {
            delay = Some(DelayMargin {
                margin: dm,
                frequency: w,
            });
        }
    }
    Ok(Margins { gain, phase, delay })
}

/// Gain, phase and delay margins of a loop ([`stability_margins`]).
///
/// # Examples
///
/// ```
/// # use ctrlab::freq::{TransferFunction, stability_margins};
/// let m = stability_margins(&TransferFunction::continuous(&[1.0], &[1.0, 0.0])?)?;
/// assert!(m.gain.is_none()); // 1/s never reaches −180°
/// assert_eq!(m.phase.unwrap().margin, 90.0);
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Margins {
    /// Gain margin at the phase crossover, if `L` crosses the negative real
    /// axis.
    pub gain: Option<GainMargin>,
    /// Phase margin at the gain crossover, if `|L|` crosses 1.
    pub phase: Option<PhaseMargin>,
    /// Delay margin, if `|L|` crosses 1 at some `ω > 0`.
    pub delay: Option<DelayMargin>,
}

/// The bandwidth of a SISO model of any type ([`FrequencyDomain`], as
/// [`stability_margins`]): the first frequency (rad/s) at which
/// `|G|` falls `|dbdrop|` dB below the DC gain `|G(0)|` (`|G(1)|` for a
/// discrete model), python-control's `bandwidth(sys, dbdrop)`;
/// `dbdrop = −3.0` is the usual choice. `None` if it never does (for a
/// discrete model: not up to the Nyquist frequency `π/dt`).
///
/// The crossing is the smallest positive real root of
/// `|N(jω)|² − g² |D(jω)|²` with `g = |G(0)| · 10^(dbdrop/20)`, exact
/// where python-control searches a frequency grid and bisects (and so can
/// miss a dip narrower than its grid).
///
/// # Errors
///
/// [`Error::InvalidParameter`] (`"dbdrop"`) unless it is finite and
/// negative; [`Error::DimensionMismatch`] named `"D"` for a model with
/// several inputs or outputs; [`Error::Singular`] for an infinite DC gain
/// (python-control returns `nan`); [`Error::Overflow`] for a discrete
/// model whose crossing frequency `θ/dt` is beyond `f64` (a subnormal
/// `dt`); the errors of [`TransferFunction::from_state_space`] and of the
/// root computations.
///
/// # Examples
///
/// ```
/// use ctrlab::freq::{TransferFunction, bandwidth};
///
/// // A lag with corner 10 rad/s: −3.0103 dB exactly at the corner.
/// let g = TransferFunction::continuous(&[10.0], &[1.0, 10.0])?;
/// let wb = bandwidth(&g, -20.0 * 2f64.sqrt().log10())?.unwrap();
/// assert!((wb - 10.0).abs() < 1e-12);
/// assert!(bandwidth(&g, 0.0).is_err());
///
/// // The same lag as a state-space model: the same bandwidth.
/// let sys = ctrlab::StateSpace::continuous(ctrlab::nalgebra::matrix![-10.0], ctrlab::nalgebra::matrix![10.0],
///                                          ctrlab::nalgebra::matrix![1.0], ctrlab::nalgebra::matrix![0.0])?;
/// assert_eq!(bandwidth(&sys, -3.0)?, bandwidth(&TransferFunction::try_from(&sys)?, -3.0)?);
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub fn bandwidth(g: &impl FrequencyDomain, dbdrop: f64) -> Result<Option<f64>, Error> {
    if !(dbdrop.is_finite() && dbdrop < 0.0) {
        return Err(Error::InvalidParameter {
            name: "dbdrop",
            value: dbdrop,
            reason: "the drop must be finite and negative (dB)",
        });
    }
    crossing_below_dc(siso_transfer_function(g)?.as_ref(), dbdrop)
}

/// [`bandwidth`] of a transfer function, `dbdrop` checked.
fn crossing_below_dc<D: Domain>(
    g: &TransferFunction<D>,
    dbdrop: f64,
) -> Result<Option<f64>, Error> {
    let dc = g.dc_gain()?.abs();
    let level = dc * 10f64.powf(dbdrop / 20.0);
    if level == 0.0 {
        return Ok(None);
    }
    let nyquist = period_of(&g.domain()).map_or(f64::INFINITY, |dt| PI / dt);
    Ok(crossings(g, Crossing::Magnitude(level))?
        .into_iter()
        .find(|&w| w > 0.0 && w <= nyquist))
}
