//! The root locus of a SISO loop: the closed-loop poles of `1 + k L = 0`
//! as the gain `k` varies ([`root_locus`], [`root_locus_at`]), with the
//! asymptotes, breakaway points and the gains at which a branch crosses
//! the stability boundary.

mod special;
mod track;

use nalgebra::Complex;

use super::poly;
use super::response::{FrequencyDomain, siso_transfer_function};
use super::tf::TransferFunction;
use crate::error::Error;
use crate::model::{Domain, period_of};

use track::{Scale, refined, roots_at, track};

/// The most gains a root locus holds: [`root_locus`] refines its grid up
/// to this many, [`root_locus_at`] refuses more.
///
/// # Examples
///
/// ```
/// use ctrlab::freq::{MAX_GAINS, TransferFunction, root_locus, root_locus_at};
///
/// let l = TransferFunction::continuous(&[1.0], &[1.0, 2.0, 0.0])?;
/// assert!(root_locus(&l)?.gains.len() <= MAX_GAINS);
/// assert!(root_locus_at(&l, &vec![1.0; MAX_GAINS + 1]).is_err());
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub const MAX_GAINS: usize = 4096;

/// The straight lines the `n − m` branches that go to infinity approach
/// (`n` poles, `m` zeros): they leave the real axis at the `centroid`
/// `(Σ pᵢ − Σ zⱼ) / (n − m)` at the `angles` `(2q + 1) π / (n − m)`
/// (rad, `q = 0 … n − m − 1`).
///
/// # Examples
///
/// ```
/// use ctrlab::freq::{TransferFunction, root_locus};
///
/// // 1 / (s (s + 1)(s + 2)): three asymptotes from −1, at ±60° and 180°.
/// let l = TransferFunction::continuous(&[1.0], &[1.0, 3.0, 2.0, 0.0])?;
/// let a = root_locus(&l)?.asymptotes.unwrap();
/// assert_eq!(a.centroid, -1.0);
/// assert_eq!(a.angles.len(), 3);
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct Asymptotes {
    /// Where the asymptotes meet, on the real axis (rad/s, or `z`).
    pub centroid: f64,
    /// Their angles, rad, ascending in `(0, 2π)`.
    pub angles: Vec<f64>,
}

/// A breakaway (or break-in) point: where two or more branches meet, a
/// multiple root of `D + k N` (a root of `N' D − N D'` with `k > 0`).
///
/// # Examples
///
/// ```
/// use ctrlab::freq::{TransferFunction, root_locus};
///
/// // 1 / (s (s + 2)): the poles meet at −1 for k = 1.
/// let l = TransferFunction::continuous(&[1.0], &[1.0, 2.0, 0.0])?;
/// let b = &root_locus(&l)?.breakaways[0];
/// assert!((b.point.re + 1.0).abs() < 1e-12 && (b.gain - 1.0).abs() < 1e-12);
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Breakaway {
    /// The point (rad/s, or `z`); real unless the branches meet off the
    /// real axis.
    pub point: Complex<f64>,
    /// The gain `k = −D / N` there.
    pub gain: f64,
}

/// A gain at which a closed-loop pole is on the stability boundary: the
/// imaginary axis `s = jω` (continuous), the unit circle `z = e^(jω dt)`
/// (discrete). A conjugate pair is one crossing, at `ω ≥ 0`.
///
/// # Examples
///
/// ```
/// use ctrlab::freq::{TransferFunction, root_locus};
///
/// // 1 / ((s + 1)(s + 2)(s + 3)): unstable beyond k = 60, at ω = √11.
/// let l = TransferFunction::continuous(&[1.0], &[1.0, 6.0, 11.0, 6.0])?;
/// let c = &root_locus(&l)?.crossings[0];
/// assert!((c.gain - 60.0).abs() < 1e-9 && (c.frequency - 11f64.sqrt()).abs() < 1e-9);
/// assert!(c.destabilising);
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BoundaryCrossing {
    /// The gain `k = −1 / L` at the crossing.
    pub gain: f64,
    /// The pole's angular frequency, rad/s: `ω` of `s = jω`, or
    /// `arg z / dt` of `z = e^(jω dt)`.
    pub frequency: f64,
    /// The pole itself, `jω` or `e^(jω dt)`.
    pub point: Complex<f64>,
    /// Whether the pole leaves the stable region as `k` grows through
    /// `gain` (moves right of the axis, or out of the circle).
    pub destabilising: bool,
}

/// The root locus of `1 + k L = 0` for a SISO loop `L = N / D`: the
/// closed-loop poles (the roots of `D + k N`) at each gain, as branches
/// followed continuously from gain to gain, with the open loop's poles
/// (`k = 0`, where each branch starts) and zeros (where `m` branches end),
/// the [`Asymptotes`] of the others, the [`Breakaway`] points and the
/// [`BoundaryCrossing`]s. Points are in rad/s (continuous) or in the
/// `z`-plane (discrete, [`period`](Self::period) set).
///
/// # Examples
///
/// ```
/// use ctrlab::freq::{TransferFunction, root_locus};
///
/// let l = TransferFunction::continuous(&[1.0], &[1.0, 2.0, 0.0])?; // 1 / (s (s + 2))
/// let locus = root_locus(&l)?;
/// assert_eq!(locus.branches.len(), 2);
/// assert_eq!(locus.gains[0], 0.0);
/// // Every branch has one pole per gain.
/// assert!(locus.branches.iter().all(|b| b.len() == locus.gains.len()));
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct RootLocus {
    /// The gains `k`, ascending for [`root_locus`], as given for
    /// [`root_locus_at`].
    pub gains: Vec<f64>,
    /// One branch per closed-loop pole: `branches[b][j]` is branch `b`'s
    /// pole at `gains[j]`.
    pub branches: Vec<Vec<Complex<f64>>>,
    /// The open-loop poles (roots of `D`).
    pub poles: Vec<Complex<f64>>,
    /// The open-loop zeros (roots of `N`).
    pub zeros: Vec<Complex<f64>>,
    /// The asymptotes, if `deg D > deg N`.
    pub asymptotes: Option<Asymptotes>,
    /// Breakaway and break-in points at `k > 0` (within the gains' range
    /// for [`root_locus_at`]), by gain.
    pub breakaways: Vec<Breakaway>,
    /// Crossings of the stability boundary at `k > 0` (within the gains'
    /// range for [`root_locus_at`]), by gain.
    pub crossings: Vec<BoundaryCrossing>,
    /// The sampling period (s) of a discrete loop; `None` for a
    /// continuous one.
    pub period: Option<f64>,
    /// The open loop's numerator and denominator.
    num: Vec<f64>,
    den: Vec<f64>,
}

impl RootLocus {
    /// The closed-loop poles at any finite gain `k` (the roots of
    /// `D + k N`), sorted by real then imaginary part.
    ///
    /// # Errors
    ///
    /// [`Error::InvalidParameter`] (`"k"`) for a non-finite gain;
    /// [`Error::Singular`] where a branch is at infinity.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::freq::{TransferFunction, root_locus};
    ///
    /// let locus = root_locus(&TransferFunction::continuous(&[1.0], &[1.0, 2.0, 0.0])?)?;
    /// let p = locus.poles_at_gain(1.0)?; // (s + 1)²
    /// assert!(p.iter().all(|p| (p.re + 1.0).abs() < 1e-7));
    /// assert!(locus.poles_at_gain(f64::NAN).is_err());
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn poles_at_gain(&self, k: f64) -> Result<Vec<Complex<f64>>, Error> {
        if !k.is_finite() {
            return Err(Error::InvalidParameter {
                name: "k",
                value: k,
                reason: "the gain must be finite",
            });
        }
        roots_at(&self.num, &self.den, k)?.ok_or(AT_INFINITY)
    }

    /// The region the locus is worth showing in: centre and radius (four
    /// times the spread of the poles, zeros and special points around
    /// the centroid).
    #[cfg(feature = "plot")]
    pub(crate) fn region(&self) -> (Complex<f64>, f64) {
        let s = scale(
            &self.poles,
            &self.zeros,
            &self.breakaways,
            &self.crossings,
            self.asymptotes.as_ref(),
        );
        (s.centre, s.radius)
    }

    /// The closed-loop poles at `gains[index]`, one per branch.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::freq::{TransferFunction, root_locus_at};
    ///
    /// let l = TransferFunction::continuous(&[1.0], &[1.0, 2.0, 0.0])?;
    /// let locus = root_locus_at(&l, &[2.0])?;
    /// // s² + 2 s + 2: −1 ± j.
    /// assert!(locus.poles_at(0).iter().all(|p| (p.re + 1.0).abs() < 1e-12));
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn poles_at(&self, index: usize) -> Vec<Complex<f64>> {
        self.branches
            .iter()
            .filter_map(|b| b.get(index).copied())
            .collect()
    }
}

const AT_INFINITY: Error = Error::Singular {
    operation: "root locus (a branch is at infinity at this gain: d₀ + k n₀ = 0)",
};

/// The open loop checked: `(N, D)` with `N ≢ 0`, `deg N ≤ deg D`,
/// `deg D ≥ 1`.
fn open_loop<D: Domain>(l: &TransferFunction<D>) -> Result<(Vec<f64>, Vec<f64>), Error> {
    if l.num() == [0.0] {
        return Err(Error::InvalidData {
            what: "num",
            index: 0,
            reason: "L ≡ 0: the closed-loop poles do not depend on the gain",
        });
    }
    if !l.is_proper() {
        return Err(Error::InvalidData {
            what: "num",
            index: 0,
            reason: "improper L (numerator degree above the denominator's): \
                     1 + k L has more roots for k ≠ 0 than poles at k = 0",
        });
    }
    if l.den().len() < 2 {
        return Err(Error::InvalidData {
            what: "den",
            index: 0,
            reason: "L is a static gain: there is no closed-loop pole to move",
        });
    }
    Ok((l.num().to_vec(), l.den().to_vec()))
}

/// The locus' parts that do not depend on the gains.
struct Parts {
    poles: Vec<Complex<f64>>,
    zeros: Vec<Complex<f64>>,
    asymptotes: Option<Asymptotes>,
    breakaways: Vec<Breakaway>,
    crossings: Vec<BoundaryCrossing>,
    period: Option<f64>,
}

fn parts<D: Domain>(l: &TransferFunction<D>, num: &[f64], den: &[f64]) -> Result<Parts, Error> {
    Ok(Parts {
        poles: poly::roots(den)?,
        zeros: poly::roots(num)?,
        asymptotes: special::asymptotes(num, den),
        breakaways: special::breakaways(num, den)?,
        crossings: special::boundary_crossings(l)?,
        period: period_of(&l.domain()),
    })
}

/// The root locus over a gain range chosen automatically (MATLAB's
/// `rlocus(sys)`, python-control's `root_locus_map(sys)`): `k` from 0 to
/// a gain at which the branches that go to infinity are four times the
/// pole-zero pattern's size from the centroid (`|L(s)|⁻¹` there, as
/// python-control chooses it), raised until every finite zero has a pole
/// within 2 % of that distance, and to 1.5 times every breakaway and
/// crossing gain. The grid starts at 49 gains spaced logarithmically
/// over six decades below that gain, 24 linearly and the breakaway and
/// crossing gains, and is refined by midpoints wherever a pole moves more
/// than 8 % of its distance to the nearest pole, zero or special point
/// (at least 0.4 % of the shown region), or more than 0.45 of its
/// distance to another pole, so that the branches are smooth and cannot
/// swap; at most [`MAX_GAINS`] gains, 64 passes. Branches are matched
/// from gain to gain by nearest distance.
///
/// `L` is any SISO model: [`TransferFunction`], [`Zpk`](super::Zpk),
/// [`StateSpace`](crate::StateSpace) or [`DynStateSpace`](crate::DynStateSpace)
/// (through its transfer function, nothing cancelled), continuous or
/// discrete. For a state-feedback gain the relation is
/// `eig(A − B (K₀ + k cᵀ)) = roots of 1 + k cᵀ (sI − A + B K₀)⁻¹ B`, the
/// locus of `L = (A − B K₀, B, cᵀ, 0)`.
///
/// # Errors
///
/// [`Error::DimensionMismatch`] for a model that is not SISO;
/// [`Error::InvalidData`] for `L ≡ 0` (`"num"`), an improper `L`
/// (`"num"`) or a static gain (`"den"`); [`Error::Overflow`] if the gain
/// range overflows; the errors of the polynomial roots.
///
/// # Examples
///
/// ```
/// use ctrlab::{Error, freq::{TransferFunction, root_locus}};
///
/// let l = TransferFunction::continuous(&[1.0], &[1.0, 6.0, 11.0, 6.0])?;
/// let locus = root_locus(&l)?;
/// assert_eq!(locus.branches.len(), 3);
/// assert!(*locus.gains.last().unwrap() > 60.0);
/// assert!(matches!(root_locus(&TransferFunction::continuous(&[1.0, 0.0, 0.0], &[1.0, 1.0])?),
///                  Err(Error::InvalidData { what: "num", .. })));
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[doc(alias = "rlocus")]
#[doc(alias = "root_locus_map")]
pub fn root_locus(l: &impl FrequencyDomain) -> Result<RootLocus, Error> {
    let l = siso_transfer_function(l)?;
    let (num, den) = open_loop(&l)?;
    let parts = parts(&l, &num, &den)?;
    let scale = scale_of(&parts);
    let kmax = gain_range(&num, &den, &parts, &scale)?;
    let mut start: Vec<f64> = vec![0.0];
    start.extend((0..=48).map(|i| kmax * 10f64.powf(-6.0 + f64::from(i) / 8.0)));
    start.extend((1..=24).map(|i| kmax * f64::from(i) / 24.0));
    start.extend(parts.breakaways.iter().map(|b| b.gain));
    start.extend(parts.crossings.iter().map(|c| c.gain));
    start.retain(|k| k.is_finite() && *k <= kmax);
    start.sort_by(f64::total_cmp);
    start.dedup();
    let (gains, roots) = refined(&num, &den, &start, &scale)?;
    Ok(assemble(gains, roots, parts, num, den))
}

/// The closed-loop poles at the given gains (MATLAB's `rlocus(sys, k)`,
/// python-control's `root_locus_map(sys, gains)`), branches matched from
/// each gain to the next in the order given; any finite gains, negative
/// ones included. Breakaways and crossings are those with a gain between
/// the smallest and the largest given.
///
/// # Errors
///
/// As [`root_locus`]; [`Error::InvalidData`] (`"gains"`) for an empty
/// list or a non-finite gain, [`Error::InvalidParameter`] (`"gains"`) for
/// more than [`MAX_GAINS`]; [`Error::Singular`] at a gain where a branch
/// is at infinity (`d₀ + k n₀ = 0` for a biproper `L`).
///
/// # Examples
///
/// ```
/// use ctrlab::{Error, freq::{TransferFunction, root_locus_at}};
///
/// let l = TransferFunction::continuous(&[1.0], &[1.0, 2.0, 0.0])?;
/// let locus = root_locus_at(&l, &[0.0, 1.0, 2.0])?;
/// assert_eq!(locus.gains, [0.0, 1.0, 2.0]);
/// assert!(matches!(root_locus_at(&l, &[f64::NAN]), Err(Error::InvalidData { what: "gains", .. })));
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[doc(alias = "rlocus")]
#[doc(alias = "root_locus_map")]
pub fn root_locus_at(l: &impl FrequencyDomain, gains: &[f64]) -> Result<RootLocus, Error> {
    if gains.len() > MAX_GAINS {
        return Err(Error::InvalidParameter {
            name: "gains",
            value: gains.len() as f64,
            reason: "more gains than freq::MAX_GAINS",
        });
    }
    if gains.is_empty() {
        return Err(Error::InvalidData {
            what: "gains",
            index: 0,
            reason: "no gain given",
        });
    }
    if let Some(index) = gains.iter().position(|k| !k.is_finite()) {
        return Err(Error::InvalidData {
            what: "gains",
            index,
            reason: "gain is not finite",
        });
    }
    let l = siso_transfer_function(l)?;
    let (num, den) = open_loop(&l)?;
    let mut parts = parts(&l, &num, &den)?;
    let lo = gains.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = gains.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    parts.breakaways.retain(|b| b.gain >= lo && b.gain <= hi);
    parts.crossings.retain(|c| c.gain >= lo && c.gain <= hi);
    let mut roots = Vec::with_capacity(gains.len());
    for &k in gains {
        roots.push(roots_at(&num, &den, k)?.ok_or(AT_INFINITY)?);
    }
    track(&mut roots);
    Ok(assemble(gains.to_vec(), roots, parts, num, den))
}

/// Root sets per gain turned into branches.
fn assemble(
    gains: Vec<f64>,
    roots: Vec<Vec<Complex<f64>>>,
    parts: Parts,
    num: Vec<f64>,
    den: Vec<f64>,
) -> RootLocus {
    let n = parts.poles.len();
    let branches = (0..n)
        .map(|b| roots.iter().map(|r| r[b]).collect())
        .collect();
    RootLocus {
        gains,
        branches,
        poles: parts.poles,
        zeros: parts.zeros,
        asymptotes: parts.asymptotes,
        breakaways: parts.breakaways,
        crossings: parts.crossings,
        period: parts.period,
        num,
        den,
    }
}

/// The region the refinement works in: centred on the centroid (or the
/// landmarks' mean), four times the landmarks' spread around it (twice
/// without asymptotes), at least 1 wide where every landmark coincides.
fn scale_of(parts: &Parts) -> Scale {
    scale(
        &parts.poles,
        &parts.zeros,
        &parts.breakaways,
        &parts.crossings,
        parts.asymptotes.as_ref(),
    )
}

fn scale(
    poles: &[Complex<f64>],
    zeros: &[Complex<f64>],
    breakaways: &[Breakaway],
    crossings: &[BoundaryCrossing],
    asymptotes: Option<&Asymptotes>,
) -> Scale {
    let mut landmarks: Vec<Complex<f64>> = poles.to_vec();
    landmarks.extend(zeros);
    landmarks.extend(breakaways.iter().map(|b| b.point));
    landmarks.extend(crossings.iter().map(|c| c.point));
    let centre = match asymptotes {
        Some(a) => Complex::new(a.centroid, 0.0),
        None => Complex::new(
            landmarks.iter().map(|p| p.re).sum::<f64>() / landmarks.len() as f64,
            0.0,
        ),
    };
    let spread = landmarks
        .iter()
        .map(|p| (p - centre).norm())
        .fold(0.0, f64::max);
    let spread = if spread > 0.0 && spread.is_finite() {
        spread
    } else {
        centre.norm().max(1.0)
    };
    let factor = if asymptotes.is_some() { 4.0 } else { 2.0 };
    if let Some(a) = asymptotes {
        landmarks.push(Complex::new(a.centroid, 0.0));
    }
    Scale {
        centre,
        radius: factor * spread,
        landmarks,
    }
}

/// The largest gain of [`root_locus`] (see there).
fn gain_range(num: &[f64], den: &[f64], parts: &Parts, scale: &Scale) -> Result<f64, Error> {
    let mut kmax: f64 = match &parts.asymptotes {
        Some(a) => {
            let far = scale.centre + Complex::from_polar(scale.radius, a.angles[0]);
            poly::eval_ratio(den, num, far).map_or(0.0, |g| g.norm())
        }
        // Biproper: python-control's 3 |d₀ / n₀|.
        None => 3.0 * (den[0] / num[0]).abs(),
    };
    for k in parts.breakaways.iter().map(|b| b.gain) {
        kmax = kmax.max(1.5 * k);
    }
    for k in parts.crossings.iter().map(|c| c.gain) {
        kmax = kmax.max(1.5 * k);
    }
    if kmax.is_nan() || kmax <= 0.0 {
        kmax = 1.0;
    }
    // Raise until each finite zero has a closed-loop pole near it.
    let near = 0.02 * scale.radius;
    for _ in 0..24 {
        let Some(r) = roots_at(num, den, kmax)? else {
            kmax *= 1.5;
            continue;
        };
        let reached = parts
            .zeros
            .iter()
            .all(|z| r.iter().any(|p| (p - z).norm() <= near));
        if reached {
            break;
        }
        kmax *= 4.0;
    }
    if kmax.is_finite() {
        Ok(kmax)
    } else {
        Err(Error::Overflow {
            operation: "root locus gain range",
        })
    }
}
