//! The lab's regressors: the two-cart plant's parameters from a recording
//! (the lab handout's section 2.2, equations (4)–(11), restated in
//! `docs/lab.md`).
//!
//! Both carts' equations of motion are linear in the unknowns once the
//! masses are known. The identification runs in two stages, as in the lab:
//!
//! 1. cart 1, `m1 x1'' + b1 x1' + k1 x1 + k2 (x1 − x2) = 0`, gives the
//!    springs and `b1`;
//! 2. cart 2, `m2 x2'' + b2 x2' + k2 (x2 − x1) = K u`, with `k2` from stage
//!    1, gives the motor gain `K` and `b2`.
//!
//! # Springs
//!
//! The lab takes the two springs as equal, `k1 = k2 = k12` (equations
//! (4)–(11)): that is the default ([`SpringModel::Equal`], stage 1 fits
//! `[k12, b1]`). Separate springs ([`SpringModel::Separate`], stage 1
//! fits `[k1, k2, b1]` from the same equation) are a case of the same
//! estimate, not another pipeline: one [`identify_with`] whose
//! [`Options::springs`] chooses, one [`MassSpringEstimate`] whose
//! [`Springs`] say which were fitted (with [`k1`](MassSpringEstimate::k1)
//! and [`k2`](MassSpringEstimate::k2) for either, `k12` for both when
//! equal), one [`average`] of runs of either model (never mixed), and one
//! [`refine`] from either (it works in `k1`, `k2`, starting equal springs
//! at `k12` for both).
//!
//! Optionally ([`Options::coulomb`]) each equation gets a Coulomb friction
//! term `F sign(v)`, fitted only over the rows where that cart clearly
//! moves (see [`Options::min_speed`] for why).
//! With [`Options::free_m2`] cart 2's effective mass is fitted in stage 2
//! too (the motor's inertia adds to the weighed cart), the equation then
//! divided by it so that the noisy second difference stays out of the
//! regressors.
//!
//! The recording must hold the channels `u` (the input), `x1` and `x2`
//! (positions, m): the lab's [`schema`](super::schema), or the lab's own
//! CSV logs (`t_s,u,x1_mm,x2_mm`).
//!
//! # Timing
//!
//! The time stamps are the actual sampling instants (as [`hw::run`]
//! records them), so a missed tick leaves a gap and the intervals jitter.
//! The recording is split into segments at every interval longer than
//! [`GAP_RATIO`] times the median interval (and at every interval shorter
//! than half the median, which follows a sample taken over half a period
//! late); each segment is fitted with its own mean period `T`, no row spans
//! a split, and all segments' rows are solved together. Within a segment
//! every interval must be within [`Options::max_jitter`] (default 5 %) of
//! that mean. What was found is reported in the estimate's [`Timing`]. A
//! uniformly sampled recording is one segment and gives exactly the rows
//! (and numbers) of equations (6)–(11).
//!
//! Validation, refinement and the bootstrap simulate the rig on the same
//! actual instants, gaps and short intervals included: each input takes
//! effect [`SimulationModel::input_delay`] after its own sample, so an
//! interval of a few µs after a late sample (the loop's policy for late
//! ticks, see [`hw::run`]) is simulated as the rig ran it, never refused.
//!
//! Every row is multiplied by its segment's `T²` as in the lab's code
//! (equations (6), (9)): within a segment that scaling does not change the
//! estimate, and across segments it keeps every row in the unit of `λ` (a
//! position difference), in which the encoder's noise is the same for all
//! rows whatever their period. Under the default Newey–West covariance the
//! standard errors of stage 2 carry stage 1's error in `k2`; the classical
//! ones treat `k2` as exact (see [`Options::covariance`]). On a recording of
//! 65 536 rows or more, with a second CPU, stage 1's Newey–West work runs on
//! a thread of its own while stage 2 is solved: the same operations, so the
//! same figures bit for bit.
//!
//! [`hw::run`]: crate::hw::run

mod average;
mod bootstrap;
mod estimates;
mod influence;
mod options;
mod refine;
mod regressors;
mod simulation;
mod stages;
mod summary;
mod timing;

#[cfg(test)]
mod streamed_tests;

pub use average::{AverageError, MassSpringAverage, Mismatch, Spread, average};
pub use bootstrap::{Bootstrap, MAX_RESAMPLES, RefinedStdErrors, bootstrap};
pub use estimates::{Estimate, MassSpringEstimate, PLAUSIBLE_MASS_KG, Springs, Warning};
pub use options::{DEFAULT_MIN_SPEED, Options, SpringModel};
pub use refine::{
    RESIDUAL_LAGS, Refined, ResidualTest, Validation, refine, refine_with, validate, validate_with,
};
pub use simulation::SimulationModel;
pub use summary::{
    EqualSprings, Parameter, SEPARATE_SPRINGS, Summary, SummaryError, Uncertainty, summarize,
};
pub use timing::{DEFAULT_MAX_JITTER, GAP_RATIO, Timing};

use self::regressors::{
    CentralDifferences, Data, Differences, Kind, LabDifferences, Motion, Spec, motion,
};
use self::stages::{Solver, both_beside, one_after_the_other};
use crate::data::Recording;
use crate::error::Error;
use crate::ident::LeastSquaresFit;
use crate::kernels::reduce::first_non_finite;

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

/// Checks the masses, the options and the recording, and splits it into
/// segments.
fn prepare<'a>(
    rec: &'a Recording,
    m1: f64,
    m2: f64,
    options: &Options,
) -> Result<(Data<'a>, Timing, f64), Error> {
    for (name, value) in [("m1", m1), ("m2", m2)] {
        if !(value.is_finite() && value > 0.0) {
            return Err(Error::InvalidParameter {
                name,
                value,
                reason: "mass must be finite and > 0 kg",
            });
        }
    }
    options.validate()?;
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
    // Every value finite, time included (as `Recording::sample_period`);
    // `u`, `x1` and `x2` later, by the stages, when they read them all.
    let deferred: &[&str] = if reads_every_sample(options) {
        &["u", "x1", "x2"]
    } else {
        &[]
    };
    if let Some(e) = non_finite(rec, deferred) {
        return Err(first_error(rec, options, e));
    }
    let checked = |e: Error| first_error(rec, options, e);
    let (segments, timing, dt) =
        timing::segments(rec.time(), options.max_jitter).map_err(checked)?;
    // Three unknowns and a residual degree of freedom, as MIN_SAMPLES.
    if timing.rows < MIN_SAMPLES - 2 {
        return Err(checked(Error::TooFewSamples {
            what: "mass-spring identification: rows within segments between gaps",
            needed: MIN_SAMPLES - 2,
            got: timing.rows,
        }));
    }
    let data = Data {
        u,
        x1,
        x2,
        segments,
        rows: timing.rows,
    };
    Ok((data, timing, dt))
}

/// Whether the stages read every sample of `u`, `x1` and `x2` that a
/// row can read: when they keep every row (no Coulomb columns). A row's
/// columns are then not all finite when a sample it reads is not (each
/// sample enters some column through sums and products with finite,
/// non-zero factors), so a stage's error, or a sample no row reads,
/// stands for a non-finite value, and [`prepare`] leaves those three to
/// the stages: one pass over them less.
fn reads_every_sample(options: &Options) -> bool {
    !options.coulomb
}

/// The first value of the recording that is not finite, time first, then
/// the channels in the schema's order, but those in `skip`.
fn non_finite(rec: &Recording, skip: &[&str]) -> Option<Error> {
    let channels = rec.schema().channels().map(|c| c.name.as_str());
    for name in std::iter::once("t").chain(channels) {
        if skip.contains(&name) {
            continue;
        }
        let column = if name == "t" {
            rec.time()
        } else {
            rec.channel(name).ok()?
        };
        if let Some(k) = first_non_finite(column) {
            return Some(Error::InvalidRecording {
                index: k,
                reason: format!("{name} = {} is not finite", column[k]),
            });
        }
    }
    None
}

/// The error the identification reports: a value that is not finite
/// before `e`, as if every value had been checked first.
#[cold]
fn first_error(rec: &Recording, options: &Options, e: Error) -> Error {
    if reads_every_sample(options) {
        non_finite(rec, &[]).unwrap_or(e)
    } else {
        e
    }
}

/// Whether the samples of `u`, `x1`, `x2` that no row reads (a
/// segment's last input, the first with the lab's differences, every
/// sample of a segment too short for a row) are finite.
fn unread_finite(data: &Data<'_>, scheme: Scheme) -> bool {
    let n = data.x1.len();
    // The samples from..to, when there are any, all finite.
    let finite = |x: &[f64], from: usize, to: usize| {
        from >= to || first_non_finite(&x[from..to.min(n)]).is_none()
    };
    // The segments in order: the samples between what they read are not.
    let (mut x_at, mut u_at, mut ok) = (0, 0, true);
    for seg in data.segments.iter().filter(|s| s.end - s.start >= 3) {
        let (u_from, u_to) = match scheme {
            Scheme::Lab => (seg.start + 1, seg.end - 1),
            Scheme::Central => (seg.start, seg.end - 1),
        };
        ok &= finite(data.x1, x_at, seg.start) && finite(data.x2, x_at, seg.start);
        ok &= finite(data.u, u_at, u_from);
        x_at = x_at.max(seg.end);
        u_at = u_at.max(u_to);
    }
    ok && finite(data.x1, x_at, n) && finite(data.x2, x_at, n) && finite(data.u, u_at, n)
}

/// Where each cart moves, for the Coulomb columns; `None` without them.
fn motions(
    data: &Data<'_>,
    options: &Options,
    stage1_parameters: usize,
) -> Result<Option<[Motion; 2]>, Error> {
    if !options.coulomb {
        return Ok(None);
    }
    let carts = [
        (
            motion(data.x1, data, options.min_speed),
            stage1_parameters,
            "Coulomb friction: rows where cart 1 moves faster than min_speed",
        ),
        (
            motion(data.x2, data, options.min_speed),
            3 + usize::from(options.free_m2),
            "Coulomb friction: rows where cart 2 moves faster than min_speed",
        ),
    ];
    for (m, parameters, what) in &carts {
        if m.moving <= *parameters {
            return Err(Error::TooFewSamples {
                what,
                needed: parameters + 1,
                got: m.moving,
            });
        }
    }
    let [(first, ..), (second, ..)] = carts;
    Ok(Some([first, second]))
}

fn estimates<const P: usize>(fit: &LeastSquaresFit) -> [Estimate; P] {
    std::array::from_fn(|i| Estimate {
        value: fit.theta[i],
        std_error: fit.std_errors[i],
    })
}

/// The Coulomb forces, the last parameter of each stage, when fitted.
fn coulomb_forces(
    coulomb: bool,
    first: &LeastSquaresFit,
    second: &LeastSquaresFit,
) -> Option<[Estimate; 2]> {
    let last = |fit: &LeastSquaresFit| {
        let i = fit.theta.len() - 1;
        Estimate {
            value: fit.theta[i],
            std_error: fit.std_errors[i],
        }
    };
    coulomb.then(|| [last(first), last(second)])
}

/// Cart 2's effective mass, stage 2's third parameter, when fitted.
fn fitted_m2(free: bool, second: &LeastSquaresFit) -> Option<Estimate> {
    free.then(|| Estimate {
        value: second.theta[2],
        std_error: second.std_errors[2],
    })
}

/// Identifies `k12 = k1 = k2`, `b1`, `K` and `b2` from a recording with
/// known masses `m1`, `m2` (kg), by the lab's two-stage least squares:
/// [`identify_with`] with the default [`Options`] and `scheme` (the lab's
/// equal springs, no Coulomb friction, 5 % jitter tolerated, split at
/// gaps).
///
/// # Errors
///
/// - [`Error::InvalidParameter`] for a mass that is not finite and > 0;
/// - [`Error::Channel`] for a recording without a channel `u`, `x1` or
///   `x2` (the message lists those it has), or positions not in m;
/// - [`Error::TooFewSamples`] for fewer than [`MIN_SAMPLES`]
///   samples, or fewer than `MIN_SAMPLES − 2` rows within the segments
///   between gaps;
/// - [`Error::InvalidRecording`] for a non-finite value, a time that does
///   not increase, or an interval off its segment's mean period by more
///   than the jitter tolerance (naming the sample);
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
/// assert_eq!(central.coulomb, None);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn identify(
    recording: &Recording,
    m1: f64,
    m2: f64,
    scheme: Scheme,
) -> Result<MassSpringEstimate, Error> {
    identify_with(recording, m1, m2, &Options::with_scheme(scheme))
}

/// [`identify`] with [`Options`], the one identification pipeline: the
/// lab's equal springs or separate ones ([`Options::springs`]; stage 1
/// then fits `[k1, k2, b1]`, and stage 2 takes `k2`), optionally each
/// cart's Coulomb friction force (a last column in each stage) and cart
/// 2's effective mass, another jitter tolerance.
///
/// # Errors
///
/// As [`identify`]; [`Error::InvalidParameter`] for options out of range
/// (`min_speed`, `max_jitter`); with Coulomb friction,
/// [`Error::TooFewSamples`] when a cart moves in too few rows.
///
/// # Examples
///
/// ```
/// use ctrlab::{Recording, lab::ident::{Options, SpringModel, identify_with}};
///
/// let rec = Recording::read_csv(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ident_square_wave.csv"))?;
/// // The fixture's plant has no dry friction: the Coulomb forces come out
/// // near zero (−0.017 N and 0.019 N, standard errors 0.012 N each).
/// let est = identify_with(&rec, 1.3, 0.7, &Options { coulomb: true, ..Options::default() })?;
/// let [f1, f2] = est.coulomb.unwrap();
/// assert!(f1.value.abs() < 0.1 && f2.value.abs() < 0.1, "{f1:?} {f2:?}");
/// assert!((est.k12().unwrap().value / 950.0 - 1.0).abs() < 0.005);
/// assert!(est.first.rows < est.timing.rows); // rows at rest are left out
///
/// // Separate springs, with Coulomb friction: stage 1 fits [k1, k2, b1, F1].
/// let options = Options { springs: SpringModel::Separate, coulomb: true, ..Options::default() };
/// let est = identify_with(&rec, 1.3, 0.7, &options)?;
/// assert_eq!((est.first.theta.len(), est.second.theta.len()), (4, 3));
/// assert!((est.k2().value / 950.0 - 1.0).abs() < 0.01);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn identify_with(
    recording: &Recording,
    m1: f64,
    m2: f64,
    options: &Options,
) -> Result<MassSpringEstimate, Error> {
    match options.scheme {
        Scheme::Lab => identify_by::<LabDifferences>(recording, m1, m2, options, None),
        Scheme::Central => identify_by::<CentralDifferences>(recording, m1, m2, options, None),
    }
}

/// [`identify_with`] with the differences of its scheme.
/// `solver`: the default (`None`) or, in tests, one that streams from
/// another length.
fn identify_by<D: Differences>(
    recording: &Recording,
    m1: f64,
    m2: f64,
    options: &Options,
    solver: Option<Solver>,
) -> Result<MassSpringEstimate, Error> {
    let (data, timing, dt) = prepare(recording, m1, m2, options)?;
    let estimate = stages::<D>(&data, timing, dt, m1, m2, options, solver)
        .map_err(|e| first_error(recording, options, e))?;
    // A sample no row read is not finite: the first such value is named.
    if reads_every_sample(options)
        && !unread_finite(&data, options.scheme)
        && let Some(e) = non_finite(recording, &[])
    {
        return Err(e);
    }
    Ok(estimate)
}

/// Both stages on the prepared data.
#[allow(clippy::too_many_arguments)]
fn stages<D: Differences>(
    data: &Data<'_>,
    timing: Timing,
    dt: f64,
    m1: f64,
    m2: f64,
    options: &Options,
    solver: Option<Solver>,
) -> Result<MassSpringEstimate, Error> {
    let fixed_m2 = (!options.free_m2).then_some(m2);
    // Stage 1's parameters with the Coulomb column: the springs, b1, F1.
    let model = options.springs;
    let motion = motions(data, options, model.parameters() + 2)?;
    let [cart1, cart2] = match &motion {
        Some([a, b]) => [Some(a), Some(b)],
        None => [None, None],
    };
    // Stage 1: the springs, b1 (and F1).
    let mut solver = solver.unwrap_or_else(|| Solver::new(options.covariance));
    let first_spec = Spec {
        kind: Kind::First { springs: model, m1 },
        data,
        keep: cart1,
        p: model.parameters() + 1 + usize::from(cart1.is_some()),
    };
    let k2_index = model.parameters() - 1;
    let head = solver.head::<D>(&first_spec)?;
    // Stage 2 takes the spring between the carts, stage 1's last spring
    // (its value: the Newey–West errors leave the estimates as they are).
    let k2 = head.fit.theta[k2_index];
    let kind = match fixed_m2 {
        Some(m2) => Kind::Second { m2, k2 },
        None => Kind::FreeMass { k2 },
    };
    let second_spec = Spec {
        kind,
        data,
        keep: cart2,
        p: 2 + usize::from(fixed_m2.is_none()) + usize::from(cart2.is_some()),
    };
    let specs = [&first_spec, &second_spec];
    let ((first, _), (second, _)) = if solver.beside(&head) {
        let spare = solver.sibling();
        match both_beside::<D>(solver, spare.sibling(), head, specs, k2_index) {
            Some(both) => both?,
            // No thread: stage 1 again, on this one.
            None => one_after_the_other::<D>(spare, None, specs, k2_index)?,
        }
    } else {
        one_after_the_other::<D>(solver, Some(head), specs, k2_index)?
    };
    let (springs, b1) = match model {
        SpringModel::Equal => {
            let [k12, b1] = estimates::<2>(&first);
            (Springs::Equal { k12 }, b1)
        }
        SpringModel::Separate => {
            let [k1, k2, b1] = estimates::<3>(&first);
            (Springs::Separate { k1, k2 }, b1)
        }
    };
    let [gain, b2] = estimates::<2>(&second);
    let m2_estimate = fitted_m2(options.free_m2, &second);
    Ok(MassSpringEstimate {
        springs,
        b1,
        gain,
        b2,
        coulomb: coulomb_forces(options.coulomb, &first, &second),
        m2_estimate,
        m1,
        m2: m2_estimate.map_or(m2, |e| e.value),
        dt,
        scheme: options.scheme,
        timing,
        first,
        second,
    })
}
