//! The lab's regressors: the two-cart plant's parameters from a recording
//! (LAB.md section 2.2, equations (4)–(11)).
//!
//! Both carts' equations of motion are linear in the unknowns once the
//! masses are known. The identification runs in two stages, as in the lab:
//!
//! 1. cart 1, `m1 x1'' + b1 x1' + k1 x1 + k2 (x1 − x2) = 0`, gives the
//!    springs and `b1`;
//! 2. cart 2, `m2 x2'' + b2 x2' + k2 (x2 − x1) = K u`, with `k2` from stage
//!    1, gives the motor gain `K` and `b2`.
//!
//! The recording must hold the channels `u` (the input), `x1` and `x2`
//! (positions, m), uniformly sampled: the lab's [`schema`](super::schema),
//! or the lab's own CSV logs (`t_s,u,x1_mm,x2_mm`).
//!
//! Every row is multiplied by `T²` as in the lab's code (equations (6), (9));
//! that scaling does not change the estimate. The standard errors of stage
//! 2 treat `k2` as exact.

use super::{Cart, MassSpring};
use crate::data::Recording;
use crate::error::Error;
use crate::ident::{DEFAULT_MAX_CONDITION, LeastSquaresFit, solve_augmented};
use crate::kernels::reduce::pow2_floor;
use crate::model::{Continuous, StateSpace};

/// How derivatives and the input are taken from the samples.
///
/// Row `k` uses samples `k − 1`, `k`, `k + 1` for `k = 1 … N − 2`; the
/// acceleration is always the central second difference
/// `[x(k+1) − 2x(k) + x(k−1)] / T²` (equation (5)).
///
/// # Examples
///
/// ```
/// use ctrlab::lab::ident::Scheme;
/// assert_ne!(Scheme::Lab, Scheme::Central);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Scheme {
    /// The lab's formulas exactly (equations (6)–(11)): backward-difference
    /// velocity `[x(k) − x(k−1)] / T` and input `u(k)`. Reproduces the
    /// lab's MATLAB numbers, biases included (about 1 % on `k12`, 2–5 % on
    /// `K` and `b2`: the velocity is half a sample late, and under a
    /// zero-order hold the second difference at `k` sees the mean of
    /// `u(k−1)` and `u(k)`).
    Lab,
    /// Central-difference velocity `[x(k+1) − x(k−1)] / (2T)`, the input
    /// averaged over the two hold intervals the second difference spans,
    /// `[u(k−1) + u(k)] / 2`, and the spring terms on the Numerov-weighted
    /// position `[x(k−1) + 10 x(k) + x(k+1)] / 12`: removes the half-sample
    /// bias and the O(T²) spring bias (within 0.03 % of the truth on the
    /// shipped fixture, 0.5 % on plausible plants with quantised encoders).
    Central,
}

/// One identified parameter and its standard error (same unit).
///
/// # Examples
///
/// ```
/// # use ctrlab::lab::ident::Estimate;
/// let k = Estimate { value: 950.0, std_error: 1.9 };
/// assert!((k.relative_error() - 0.002).abs() < 1e-15);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Estimate {
    /// The estimate.
    pub value: f64,
    /// Its standard error from the least-squares covariance.
    pub std_error: f64,
}

impl Estimate {
    /// `std_error / |value|`.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::lab::ident::Estimate;
    /// assert_eq!(Estimate { value: -2.0, std_error: 0.5 }.relative_error(), 0.25);
    /// ```
    pub fn relative_error(&self) -> f64 {
        self.std_error / self.value.abs()
    }
}

/// The parameters identified by [`identify`] (equal springs `k1 = k2 = k12`).
///
/// # Examples
///
/// ```
/// use ctrlab::{Recording, lab::ident::{identify, Scheme}};
///
/// let rec = Recording::read_csv(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ident_square_wave.csv"))?;
/// let est = identify(&rec, 1.3, 0.7, Scheme::Central)?;
/// assert!((est.k12.value - 950.0).abs() < 0.003 * 950.0);
/// let sys = est.state_space()?; // the identified model, output cart 2
/// assert!((sys.b()[(3, 0)] - est.gain.value / 0.7).abs() < 1e-12);
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct MassSpringEstimate {
    /// Spring constant `k1 = k2`, N/m.
    pub k12: Estimate,
    /// Viscous friction of cart 1, N·s/m.
    pub b1: Estimate,
    /// Motor gain `K`, N per input unit (N/V on the rig).
    pub gain: Estimate,
    /// Viscous friction of cart 2, N·s/m.
    pub b2: Estimate,
    /// Mass of cart 1 used, kg.
    pub m1: f64,
    /// Mass of cart 2 used, kg.
    pub m2: f64,
    /// Sampling period of the recording, s.
    pub dt: f64,
    /// The scheme used.
    pub scheme: Scheme,
    /// Stage 1 fit (`θ = [k12, b1]`): fit %, R², condition number, ….
    pub first: LeastSquaresFit,
    /// Stage 2 fit (`θ = [K, b2]`).
    pub second: LeastSquaresFit,
}

impl MassSpringEstimate {
    /// The identified plant as [`MassSpring`] parameters.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::{Recording, lab::ident::{identify, Scheme}};
    /// # let rec = Recording::read_csv(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ident_square_wave.csv"))?;
    /// let p = identify(&rec, 1.3, 0.7, Scheme::Lab)?.plant();
    /// assert_eq!(p.k1, p.k2);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn plant(&self) -> MassSpring {
        MassSpring {
            m1: self.m1,
            m2: self.m2,
            k1: self.k12.value,
            k2: self.k12.value,
            b1: self.b1.value,
            b2: self.b2.value,
            gain: self.gain.value,
        }
    }

    /// The identified continuous model (equation (3)), output the position
    /// of cart 2, input in the recording's input unit.
    ///
    /// # Errors
    ///
    /// [`Error::InvalidParameter`] when an estimate is negative (e.g. a
    /// friction estimate from a run with too little motion).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::{Recording, lab::ident::{identify, Scheme}};
    /// # let rec = Recording::read_csv(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ident_square_wave.csv"))?;
    /// let est = identify(&rec, 1.3, 0.7, Scheme::Central)?;
    /// let a = *est.state_space()?.a();
    /// assert_eq!(a[(1, 0)], -2.0 * est.k12.value / 1.3);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn state_space(&self) -> Result<StateSpace<4, 1, 1, Continuous>, Error> {
        self.plant().state_space(Cart::Two)
    }

    /// Warning-level checks of the inputs (empty when all is plausible): a
    /// cart mass outside [`PLAUSIBLE_MASS_KG`] is most likely in grams or
    /// tonnes, and every estimate scales with it.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::{Recording, lab::ident::{identify, Scheme}};
    /// # let rec = Recording::read_csv(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ident_square_wave.csv"))?;
    /// assert!(identify(&rec, 1.3, 0.7, Scheme::Lab)?.warnings().is_empty());
    /// assert_eq!(identify(&rec, 1300.0, 700.0, Scheme::Lab)?.warnings().len(), 2);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn warnings(&self) -> Vec<Warning> {
        mass_warnings(self.m1, self.m2)
    }
}

/// The range of cart masses (kg) the lab's identification takes as
/// plausible; a mass outside it is most likely in the wrong unit (grams,
/// tonnes) and is reported by [`MassSpringEstimate::warnings`].
///
/// # Examples
///
/// ```
/// use ctrlab::lab::ident::PLAUSIBLE_MASS_KG;
/// let (lo, hi) = PLAUSIBLE_MASS_KG;
/// assert!(lo < 0.7 && 1.3 < hi && hi < 700.0);
/// ```
pub const PLAUSIBLE_MASS_KG: (f64, f64) = (0.01, 100.0);

/// A warning-level finding about an identification's inputs: the numbers
/// were computed, but a value is implausible for the lab and probably in
/// the wrong unit.
///
/// # Examples
///
/// ```
/// use ctrlab::{Recording, lab::ident::{identify, Scheme}};
///
/// let rec = Recording::read_csv(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ident_square_wave.csv"))?;
/// // Cart 1's mass given in grams.
/// let est = identify(&rec, 1300.0, 0.7, Scheme::Central)?;
/// let w = &est.warnings()[0];
/// assert_eq!((w.parameter, w.value), ("m1", 1300.0));
/// assert!(w.to_string().contains("grams"));
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct Warning {
    /// The parameter (`"m1"`, `"m2"`).
    pub parameter: &'static str,
    /// Its value, in the unit the API documents (kg for masses).
    pub value: f64,
    /// What is implausible and the likely mix-up.
    pub reason: &'static str,
}

impl std::fmt::Display for Warning {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "`{}` = {}: {}", self.parameter, self.value, self.reason)
    }
}

/// Warnings for cart masses outside [`PLAUSIBLE_MASS_KG`].
fn mass_warnings(m1: f64, m2: f64) -> Vec<Warning> {
    let (lo, hi) = PLAUSIBLE_MASS_KG;
    [("m1", m1), ("m2", m2)]
        .into_iter()
        .filter_map(|(parameter, value)| {
            let reason = if value > hi {
                "implausibly heavy for a lab cart: masses are in kg (was it given in grams?)"
            } else if value < lo {
                "implausibly light for a lab cart: masses are in kg (was it given in tonnes?)"
            } else {
                return None;
            };
            Some(Warning {
                parameter,
                value,
                reason,
            })
        })
        .collect()
}

/// The parameters identified by [`identify_separate_springs`] (`k1 ≠ k2`).
///
/// # Examples
///
/// ```
/// use ctrlab::{Recording, lab::ident::{identify_separate_springs, Scheme}};
///
/// let rec = Recording::read_csv(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ident_square_wave.csv"))?;
/// let est = identify_separate_springs(&rec, 1.3, 0.7, Scheme::Central)?;
/// // The fixture's springs are equal: both estimates find 950 N/m.
/// assert!((est.k1.value / est.k2.value - 1.0).abs() < 0.01);
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct SeparateSpringsEstimate {
    /// Spring between the wall and cart 1, N/m.
    pub k1: Estimate,
    /// Spring between the carts, N/m.
    pub k2: Estimate,
    /// Viscous friction of cart 1, N·s/m.
    pub b1: Estimate,
    /// Motor gain `K`, N per input unit.
    pub gain: Estimate,
    /// Viscous friction of cart 2, N·s/m.
    pub b2: Estimate,
    /// Mass of cart 1 used, kg.
    pub m1: f64,
    /// Mass of cart 2 used, kg.
    pub m2: f64,
    /// Sampling period of the recording, s.
    pub dt: f64,
    /// The scheme used.
    pub scheme: Scheme,
    /// Stage 1 fit (`θ = [k1, k2, b1]`).
    pub first: LeastSquaresFit,
    /// Stage 2 fit (`θ = [K, b2]`).
    pub second: LeastSquaresFit,
}

impl SeparateSpringsEstimate {
    /// The identified plant as [`MassSpring`] parameters.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::{Recording, lab::ident::{identify_separate_springs, Scheme}};
    /// # let rec = Recording::read_csv(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ident_square_wave.csv"))?;
    /// let est = identify_separate_springs(&rec, 1.3, 0.7, Scheme::Central)?;
    /// assert_eq!(est.plant().k2, est.k2.value);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn plant(&self) -> MassSpring {
        MassSpring {
            m1: self.m1,
            m2: self.m2,
            k1: self.k1.value,
            k2: self.k2.value,
            b1: self.b1.value,
            b2: self.b2.value,
            gain: self.gain.value,
        }
    }

    /// The identified continuous model, output the position of cart 2.
    ///
    /// # Errors
    ///
    /// [`Error::InvalidParameter`] when an estimate is negative.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::{Recording, lab::ident::{identify_separate_springs, Scheme}};
    /// # let rec = Recording::read_csv(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ident_square_wave.csv"))?;
    /// let est = identify_separate_springs(&rec, 1.3, 0.7, Scheme::Central)?;
    /// assert_eq!(est.state_space()?.a()[(3, 0)], est.k2.value / 0.7);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn state_space(&self) -> Result<StateSpace<4, 1, 1, Continuous>, Error> {
        self.plant().state_space(Cart::Two)
    }

    /// Warning-level checks of the inputs (empty when all is plausible): a
    /// cart mass outside [`PLAUSIBLE_MASS_KG`] is most likely in grams or
    /// tonnes, and every estimate scales with it.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::{Recording, lab::ident::{identify_separate_springs, Scheme}};
    /// # let rec = Recording::read_csv(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ident_square_wave.csv"))?;
    /// assert!(identify_separate_springs(&rec, 1.3, 0.7, Scheme::Lab)?.warnings().is_empty());
    /// assert_eq!(identify_separate_springs(&rec, 1300.0, 700.0, Scheme::Lab)?.warnings().len(), 2);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn warnings(&self) -> Vec<Warning> {
        mass_warnings(self.m1, self.m2)
    }
}

/// Fewest samples the identifiers can use: three unknowns, one residual
/// degree of freedom, and the two samples the finite differences consume.
///
/// # Examples
///
/// ```
/// use ctrlab::{Error, data::{Recording, Schema}, lab::ident::{MIN_SAMPLES, Scheme, identify}};
/// let mut rec = Recording::new(ctrlab::lab::schema());
/// for k in 0..MIN_SAMPLES - 1 {
///     rec.push(k as f64 * 0.002, &[1.0], &[0.0, 0.0, 0.0, 0.0])?;
/// }
/// assert!(matches!(identify(&rec, 1.3, 0.7, Scheme::Lab), Err(Error::TooFewSamples { needed: 6, .. })));
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub const MIN_SAMPLES: usize = 6;

/// Validated inputs shared by both identifiers: the channels `u`, `x1`,
/// `x2` of the recording.
struct Prepared<'a> {
    u: &'a [f64],
    x1: &'a [f64],
    x2: &'a [f64],
    dt: f64,
    rows: usize,
}

fn prepare<'a>(rec: &'a Recording, m1: f64, m2: f64) -> Result<Prepared<'a>, Error> {
    for (name, value) in [("m1", m1), ("m2", m2)] {
        if !(value.is_finite() && value > 0.0) {
            return Err(Error::InvalidParameter {
                name,
                value,
                reason: "mass must be finite and > 0 kg",
            });
        }
    }
    let (u, x1, x2) = (rec.channel("u")?, rec.channel("x1")?, rec.channel("x2")?);
    // A unitless position column (millimetres, say) must not pass as metres.
    for channel in rec.schema().channels() {
        if matches!(channel.name.as_str(), "x1" | "x2") && channel.unit != "m" {
            return Err(Error::Channel {
                name: channel.name.clone(),
                reason: format!(
                    "positions must be in m (a CSV header x1_m or x1_mm), found unit `{}`",
                    channel.unit
                ),
            });
        }
    }
    if rec.len() < MIN_SAMPLES {
        return Err(Error::TooFewSamples {
            what: "mass-spring identification",
            needed: MIN_SAMPLES,
            got: rec.len(),
        });
    }
    let dt = rec.sample_period()?;
    Ok(Prepared {
        u,
        x1,
        x2,
        dt,
        rows: rec.len() - 2,
    })
}

/// The finite differences of a [`Scheme`], as monomorphised kernels: a
/// runtime `match` on the scheme inside the per-sample column loops keeps
/// them from vectorising (measured: 50 µs → 80 µs for 5000 samples).
trait Differences {
    /// `T ·` velocity at a row from `[x(k−1), x(k), x(k+1)]`: the velocity
    /// regressor of equations (6)/(9), in position units.
    fn vel(x: [f64; 3]) -> f64;
    /// The position the spring terms use, from `[x(k−1), x(k), x(k+1)]`.
    fn pos(x: [f64; 3]) -> f64;
    /// The input the second difference at `k` sees, from `u(k−1)`, `u(k)`.
    fn input(previous: f64, current: f64) -> f64;
}

/// `[x(k−1), x(k), x(k+1)]` for the rows `k = 1 … len − 2`, from shifted
/// slices: no bounds check per sample, so the column loops vectorise.
fn triples(x: &[f64]) -> impl Iterator<Item = [f64; 3]> + '_ {
    let m = x.len().saturating_sub(2);
    x[..m]
        .iter()
        .zip(&x[1..m + 1])
        .zip(&x[2..m + 2])
        .map(|((&a, &b), &c)| [a, b, c])
}

/// `(u(k−1), u(k))` for the same rows.
fn input_pairs(u: &[f64]) -> impl Iterator<Item = (f64, f64)> + '_ {
    let m = u.len().saturating_sub(2);
    u[..m].iter().zip(&u[1..m + 1]).map(|(&a, &b)| (a, b))
}

/// `x(k+1) − 2 x(k) + x(k−1)`.
#[inline(always)]
fn second_difference(x: [f64; 3]) -> f64 {
    x[2] - 2.0 * x[1] + x[0]
}

/// [`Scheme::Lab`]: equations (6)–(11) as written.
struct LabDifferences;

impl Differences for LabDifferences {
    #[inline(always)]
    fn vel(x: [f64; 3]) -> f64 {
        x[1] - x[0]
    }
    #[inline(always)]
    fn pos(x: [f64; 3]) -> f64 {
        x[1]
    }
    #[inline(always)]
    fn input(_previous: f64, current: f64) -> f64 {
        current
    }
}

/// [`Scheme::Central`].
struct CentralDifferences;

impl Differences for CentralDifferences {
    #[inline(always)]
    fn vel(x: [f64; 3]) -> f64 {
        0.5 * (x[2] - x[0])
    }
    /// The central second difference is exactly the triangle-weighted mean
    /// of `x''` over `[t(k−1), t(k+1)]`, so the spring forces it balances are
    /// that mean of `x` too, `(x(k−1) + 10 x(k) + x(k+1)) / 12` to O(T⁴); the
    /// plain `x(k)` is off by `T² x''/12`, an error in phase with the springs
    /// that otherwise leaks into the small damping `b2` (0.5 % seen on
    /// plausible plants).
    #[inline(always)]
    fn pos(x: [f64; 3]) -> f64 {
        (x[0] + 10.0 * x[1] + x[2]) / 12.0
    }
    #[inline(always)]
    fn input(previous: f64, current: f64) -> f64 {
        0.5 * (previous + current)
    }
}

/// The columns of equation (6) that do not depend on the spring model:
/// cart 1's velocity regressor (for `b1`) and `λ`, appended to `buf`.
fn push_cart1_friction_and_lambda<D: Differences>(x1: &[f64], t: f64, m1: f64, buf: &mut Vec<f64>) {
    buf.extend(triples(x1).map(|x| t * D::vel(x)));
    // The lab's own order of operations, as its MATLAB `lamda`.
    buf.extend(triples(x1).map(|x| m1 * (2.0 * x[1] - x[0] - x[2])));
}

/// Stage 2 (equations (9)–(11)): `[K, b2]` given the coupling spring `k2`.
fn stage2<D: Differences>(
    p: &Prepared<'_>,
    m2: f64,
    k2: f64,
    buf: &mut Vec<f64>,
) -> Result<LeastSquaresFit, Error> {
    let (x1, x2, u) = (p.x1, p.x2, p.u);
    let (t, m) = (p.dt, p.rows);
    let t2 = t * t;
    buf.clear();
    buf.reserve(3 * m);
    buf.extend(input_pairs(u).map(|(a, b)| t2 * D::input(a, b)));
    buf.extend(triples(x2).map(|x| -t * D::vel(x)));
    buf.extend(
        triples(x2)
            .zip(triples(x1))
            .map(|(x2, x1)| m2 * second_difference(x2) + k2 * t2 * (D::pos(x2) - D::pos(x1))),
    );
    solve_augmented(buf, m, 2, DEFAULT_MAX_CONDITION)
}

fn estimates<const P: usize>(fit: &LeastSquaresFit) -> [Estimate; P] {
    std::array::from_fn(|i| Estimate {
        value: fit.theta[i],
        std_error: fit.std_errors[i],
    })
}

/// Identifies `k12 = k1 = k2`, `b1`, `K` and `b2` from a recording with
/// known masses `m1`, `m2` (kg), by the lab's two-stage least squares.
///
/// # Errors
///
/// - [`Error::InvalidParameter`] for a mass that is not finite and > 0;
/// - [`Error::Channel`] for a recording without a channel `u`, `x1` or
///   `x2` (the message lists those it has), or positions not in m;
/// - [`Error::TooFewSamples`] for fewer than [`MIN_SAMPLES`]
///   samples;
/// - [`Error::InvalidRecording`] for mismatched columns, non-finite values
///   or an irregular time column;
/// - [`Error::RankDeficient`] when the run does not excite the plant (e.g.
///   the carts never move).
///
/// # Examples
///
/// ```
/// use ctrlab::{Recording, lab::ident::{identify, Scheme}};
///
/// let rec = Recording::read_csv(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ident_square_wave.csv"))?;
/// let lab = identify(&rec, 1.3, 0.7, Scheme::Lab)?;
/// let central = identify(&rec, 1.3, 0.7, Scheme::Central)?;
/// // The true gain is 8.5 N/V: the lab's formula is biased low by 2 %.
/// assert!((lab.gain.value / 8.5 - 1.0).abs() > 0.01);
/// assert!((central.gain.value / 8.5 - 1.0).abs() < 0.003);
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub fn identify(
    recording: &Recording,
    m1: f64,
    m2: f64,
    scheme: Scheme,
) -> Result<MassSpringEstimate, Error> {
    match scheme {
        Scheme::Lab => identify_with::<LabDifferences>(recording, m1, m2, scheme),
        Scheme::Central => identify_with::<CentralDifferences>(recording, m1, m2, scheme),
    }
}

fn identify_with<D: Differences>(
    recording: &Recording,
    m1: f64,
    m2: f64,
    scheme: Scheme,
) -> Result<MassSpringEstimate, Error> {
    let p = prepare(recording, m1, m2)?;
    let (x1, x2) = (p.x1, p.x2);
    let (t, m) = (p.dt, p.rows);
    let t2 = t * t;
    // Column-major [Φ | λ], rows k = 1 … N − 2.
    let mut buf = Vec::with_capacity(3 * m);
    buf.extend(
        triples(x1)
            .zip(triples(x2))
            .map(|(x1, x2)| t2 * (2.0 * D::pos(x1) - D::pos(x2))),
    );
    push_cart1_friction_and_lambda::<D>(x1, t, m1, &mut buf);
    let first = solve_augmented(&mut buf, m, 2, DEFAULT_MAX_CONDITION)?;
    let [k12, b1] = estimates::<2>(&first);
    let second = stage2::<D>(&p, m2, k12.value, &mut buf)?;
    let [gain, b2] = estimates::<2>(&second);
    Ok(MassSpringEstimate {
        k12,
        b1,
        gain,
        b2,
        m1,
        m2,
        dt: t,
        scheme,
        first,
        second,
    })
}

/// Identifies unequal springs `k1`, `k2` with `b1` from cart 1's equation
/// (three unknowns), then `K` and `b2` from cart 2's with that `k2`. Real
/// springs are never exactly equal; this needs a run that moves the carts
/// in both modes (a square wave does).
///
/// # Errors
///
/// As [`identify`].
///
/// # Examples
///
/// ```
/// use ctrlab::{Recording, lab::ident::{identify_separate_springs, Scheme}};
///
/// let rec = Recording::read_csv(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ident_square_wave.csv"))?;
/// let est = identify_separate_springs(&rec, 1.3, 0.7, Scheme::Central)?;
/// assert!((est.k1.value / 950.0 - 1.0).abs() < 0.01);
/// assert!((est.k2.value / 950.0 - 1.0).abs() < 0.01);
/// assert_eq!(est.first.theta.len(), 3);
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub fn identify_separate_springs(
    recording: &Recording,
    m1: f64,
    m2: f64,
    scheme: Scheme,
) -> Result<SeparateSpringsEstimate, Error> {
    match scheme {
        Scheme::Lab => separate_with::<LabDifferences>(recording, m1, m2, scheme),
        Scheme::Central => separate_with::<CentralDifferences>(recording, m1, m2, scheme),
    }
}

fn separate_with<D: Differences>(
    recording: &Recording,
    m1: f64,
    m2: f64,
    scheme: Scheme,
) -> Result<SeparateSpringsEstimate, Error> {
    let p = prepare(recording, m1, m2)?;
    let (x1, x2) = (p.x1, p.x2);
    let (t, m) = (p.dt, p.rows);
    let t2 = t * t;
    let mut buf = Vec::with_capacity(4 * m);
    buf.extend(triples(x1).map(|x| t2 * D::pos(x)));
    buf.extend(
        triples(x1)
            .zip(triples(x2))
            .map(|(x1, x2)| t2 * (D::pos(x1) - D::pos(x2))),
    );
    push_cart1_friction_and_lambda::<D>(x1, t, m1, &mut buf);
    let first = solve_augmented(&mut buf, m, 3, DEFAULT_MAX_CONDITION)?;
    let [k1, k2, b1] = estimates::<3>(&first);
    let second = stage2::<D>(&p, m2, k2.value, &mut buf)?;
    let [gain, b2] = estimates::<2>(&second);
    Ok(SeparateSpringsEstimate {
        k1,
        k2,
        b1,
        gain,
        b2,
        m1,
        m2,
        dt: t,
        scheme,
        first,
        second,
    })
}

/// Mean and sample standard deviation (divisor `n − 1`) of one parameter
/// over repeated runs.
///
/// # Examples
///
/// ```
/// # use ctrlab::lab::ident::Spread;
/// let s = Spread { mean: 950.0, std_dev: 4.0 };
/// assert_eq!(s.mean, 950.0);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Spread {
    /// Mean over the runs.
    pub mean: f64,
    /// Sample standard deviation over the runs (same unit).
    pub std_dev: f64,
}

/// The averages of Tables 3 and 4: each parameter's mean and spread over
/// repeated identification runs.
///
/// # Examples
///
/// ```
/// # use ctrlab::{Recording, lab::ident::{average, identify, Scheme}};
/// # let rec = Recording::read_csv(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ident_square_wave.csv"))?;
/// let est = identify(&rec, 1.3, 0.7, Scheme::Central)?;
/// let avg = average(&[est.clone(), est.clone()])?;
/// assert_eq!((avg.runs, avg.k12.mean, avg.k12.std_dev), (2, est.k12.value, 0.0));
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MassSpringAverage {
    /// Spring constant, N/m.
    pub k12: Spread,
    /// Friction of cart 1, N·s/m.
    pub b1: Spread,
    /// Motor gain, N per input unit.
    pub gain: Spread,
    /// Friction of cart 2, N·s/m.
    pub b2: Spread,
    /// Number of runs averaged.
    pub runs: usize,
}

impl Spread {
    /// Mean and sample standard deviation of `values` (e.g. one parameter of
    /// [`SeparateSpringsEstimate`] over several runs).
    ///
    /// # Errors
    ///
    /// [`Error::TooFewSamples`] for fewer than two values;
    /// [`Error::InvalidData`] for a NaN or infinite value;
    /// [`Error::Overflow`] when the standard deviation exceeds `f64::MAX`.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::{Error, lab::ident::Spread};
    /// let s = Spread::of(&[948.0, 950.0, 952.0])?;
    /// assert_eq!((s.mean, s.std_dev), (950.0, 2.0));
    /// assert!(Spread::of(&[1.0]).is_err());
    /// // Values near f64::MAX do not overflow on the way.
    /// assert_eq!(Spread::of(&[1e308, 1e308])?.mean, 1e308);
    /// assert!(matches!(Spread::of(&[f64::NAN, 1.0]), Err(Error::InvalidData { index: 0, .. })));
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn of(values: &[f64]) -> Result<Self, Error> {
        if values.len() < 2 {
            return Err(Error::TooFewSamples {
                what: "mean and sample standard deviation",
                needed: 2,
                got: values.len(),
            });
        }
        if let Some(index) = values.iter().position(|v| !v.is_finite()) {
            return Err(Error::InvalidData {
                what: "values",
                index,
                reason: "value is not finite",
            });
        }
        spread(values.iter().copied(), values.len())
    }
}

/// Mean and sample standard deviation of `n ≥ 2` finite values, computed
/// on the values divided by a power of two near their largest magnitude so
/// that neither the sum nor the squares overflow or underflow.
fn spread(values: impl Iterator<Item = f64> + Clone, n: usize) -> Result<Spread, Error> {
    let scale = pow2_floor(values.clone().fold(0.0f64, |m, v| m.max(v.abs())));
    let scaled = values.map(|v| v / scale);
    let mean = scaled.clone().sum::<f64>() / n as f64;
    let var = scaled.map(|v| (v - mean) * (v - mean)).sum::<f64>() / (n - 1) as f64;
    let (mean, std_dev) = (mean * scale, var.sqrt() * scale);
    if !std_dev.is_finite() {
        return Err(Error::Overflow {
            operation: "sample standard deviation",
        });
    }
    Ok(Spread { mean, std_dev })
}

/// Mean and sample standard deviation of each parameter over repeated runs
/// (the "average" rows of Tables 3 and 4).
///
/// # Errors
///
/// [`Error::TooFewSamples`] for fewer than two runs (a sample standard
/// deviation needs two); [`Error::Overflow`] for a spread beyond `f64::MAX`.
///
/// # Examples
///
/// ```
/// # use ctrlab::{Error, lab::ident::average};
/// assert!(matches!(average(&[]), Err(Error::TooFewSamples { needed: 2, got: 0, .. })));
/// ```
pub fn average(runs: &[MassSpringEstimate]) -> Result<MassSpringAverage, Error> {
    let n = runs.len();
    if n < 2 {
        return Err(Error::TooFewSamples {
            what: "averaging identification runs",
            needed: 2,
            got: n,
        });
    }
    Ok(MassSpringAverage {
        k12: spread(runs.iter().map(|r| r.k12.value), n)?,
        b1: spread(runs.iter().map(|r| r.b1.value), n)?,
        gain: spread(runs.iter().map(|r| r.gain.value), n)?,
        b2: spread(runs.iter().map(|r| r.b2.value), n)?,
        runs: n,
    })
}
