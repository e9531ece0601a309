//! The regressor columns of equations (6) and (9), per [`Scheme`](super::Scheme),
//! built segment by segment, and the two least-squares stages.

use super::SpringModel;
use super::timing::Segment;
use crate::error::Error;
use crate::ident::{
    Covariance, DEFAULT_MAX_CONDITION, LeastSquaresFit, SolveOptions, Workspace, newey_west,
    solve_augmented,
};

/// The finite differences of a [`Scheme`](super::Scheme), as monomorphised
/// kernels: a runtime `match` on the scheme inside the per-sample column
/// loops keeps them from vectorising (measured: 50 µs → 80 µs for 5000
/// samples).
pub(super) trait Differences {
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

/// [`Scheme::Lab`](super::Scheme::Lab): equations (6)–(11) as written.
pub(super) struct LabDifferences;

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

/// [`Scheme::Central`](super::Scheme::Central).
pub(super) struct CentralDifferences;

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
    /// plausible plants). Times the rounded `1/12` rather than divided by
    /// 12: a division per row and column was a fifth of the
    /// identification's time, and the product is within an ulp of it.
    #[inline(always)]
    fn pos(x: [f64; 3]) -> f64 {
        (x[0] + 10.0 * x[1] + x[2]) * (1.0 / 12.0)
    }
    #[inline(always)]
    fn input(previous: f64, current: f64) -> f64 {
        0.5 * (previous + current)
    }
}

/// The validated channels and the segments their rows come from.
pub(super) struct Data<'a> {
    pub u: &'a [f64],
    pub x1: &'a [f64],
    pub x2: &'a [f64],
    pub segments: Vec<Segment>,
    /// Rows over all segments.
    pub rows: usize,
}

/// Per row, the direction (+1 or −1) in which a cart clearly moves
/// throughout the row's window `[t(k−1), t(k+1)]`, or 0 where it does not.
pub(super) struct Motion {
    pub direction: Vec<f64>,
    /// Rows with a direction.
    pub moving: usize,
}

/// Where position `x` clearly moves through a row's window: it moves the
/// same way faster than `min_speed` over the sampling interval just before
/// the window, `[t(k−3), t(k−2)]`, and the one just after it,
/// `[t(k+2), t(k+3)]`.
///
/// Those four samples are not among the row's own `k−1, k, k+1`, so which
/// rows are kept does not depend on the rows' measurement noise: choosing
/// on the row's own samples (its end speeds) selects rows by the noise in
/// their second difference, and on the simulated rig that biased `K` by
/// +0.2 % and the springs by −0.1 to −0.3 %. A cart moving the same way
/// 10 ms apart (at 2 ms) has neither stopped nor reversed in between: that
/// would take two reversals, far above the plant's modes. Rows within three
/// samples of a segment's ends have no such intervals and are left out.
pub(super) fn motion(x: &[f64], data: &Data<'_>, min_speed: f64) -> Motion {
    let mut direction = Vec::with_capacity(data.rows);
    for seg in &data.segments {
        let threshold = min_speed * seg.dt;
        let x = &x[seg.start..seg.end];
        // Row k = 1 … len − 2 of the segment.
        direction.extend((1..x.len() - 1).map(|k| {
            if k < 3 || k + 3 >= x.len() {
                return 0.0;
            }
            let (before, after) = (x[k - 2] - x[k - 3], x[k + 3] - x[k + 2]);
            if before > threshold && after > threshold {
                1.0
            } else if before < -threshold && after < -threshold {
                -1.0
            } else {
                0.0
            }
        }));
    }
    let moving = direction.iter().filter(|&&d| d != 0.0).count();
    Motion { direction, moving }
}

/// Appends one column: `rows(segment)` for every segment, in order; with
/// `keep`, only the rows whose direction is not 0.
fn column<I: Iterator<Item = f64>>(
    buf: &mut Vec<f64>,
    data: &Data<'_>,
    keep: Option<&Motion>,
    mut rows: impl FnMut(&Segment) -> I,
) {
    for seg in &data.segments {
        let values = rows(seg);
        match keep {
            None => buf.extend(values),
            Some(motion) => {
                let direction = &motion.direction[seg.row0..seg.row0 + seg.rows()];
                buf.extend(
                    values
                        .zip(direction)
                        .filter(|&(_, &d)| d != 0.0)
                        .map(|(v, _)| v),
                );
            }
        }
    }
}

/// Which stage [`Solver::solve`] solves.
#[derive(Debug, Clone, Copy)]
enum Stage {
    /// Stage 1: its influence series is kept for stage 2.
    First,
    /// Stage 2, whose `λ` holds `k2 z` with `k2` from stage 1's parameter
    /// `k2_index`.
    Second { k2_index: usize },
    /// Stage 2 with cart 2's mass free, solved divided by it for
    /// `θ' = [K, b2, k2, (F2)] / m2` and mapped to `θ = [K, b2, m2, (F2)]`
    /// with `k2` (value `k2`, stage 1's parameter `k2_index`).
    FreeMass { k2_index: usize, k2: f64 },
}

/// The columns of a stage, `[Φ | λ]` column-major, and how they are solved.
pub(super) struct Solver {
    /// How the covariance is estimated.
    covariance: Covariance,
    /// The stage's columns.
    buf: Vec<f64>,
    /// Stage 2's `z`, the column multiplying `k2` in its `λ`.
    z: Vec<f64>,
    /// The solve's copy of `buf`, then its influence series; the sums'
    /// buffer.
    hac: Workspace,
    /// Stage 1's influence series on all rows of the segments (zero where
    /// it used none), column-major.
    first: Vec<f64>,
    /// The same for stage 2, with stage 1's carried through `k2`.
    second: Vec<f64>,
    /// Rows where a segment starts.
    starts: Vec<usize>,
}

impl Solver {
    pub fn new(covariance: Covariance) -> Self {
        Self {
            covariance,
            buf: Vec::new(),
            z: Vec::new(),
            hac: Workspace::default(),
            first: Vec::new(),
            second: Vec::new(),
            starts: Vec::new(),
        }
    }

    /// Solves the `m × p` stage in `buf`, whose rows are those of `data`'s
    /// segments, or with `keep` those where a cart moves.
    ///
    /// With Newey–West, each row's influence `(ΦᵀΦ)⁻¹ φ_t e_t` is placed
    /// at its sample in the segments (zero at the rows left out, so that
    /// lags count samples), and stage 2's carries stage 1's error in `k2`:
    /// `θ̂₂` is affine in `k2`, `∂θ̂₂/∂k2 = g` solves `Φ₂ g ≈ z`, so a row's
    /// influence on `θ̂₂` is its own plus `g` times its influence on `k̂2`.
    /// The covariance is the Newey–West sum of those series, within the
    /// segments.
    fn solve(
        &mut self,
        data: &Data<'_>,
        keep: Option<&Motion>,
        m: usize,
        p: usize,
        stage: Stage,
    ) -> Result<LeastSquaresFit, Error> {
        let Covariance::NeweyWest { lags } = self.covariance else {
            let options = SolveOptions {
                max_condition: DEFAULT_MAX_CONDITION,
                covariance: Covariance::Classical,
                segment_starts: &[],
                influence: false,
                also: None,
            };
            let mut fit = solve_augmented(&mut self.buf, m, p, &options, &mut self.hac)?.fit;
            if let Stage::FreeMass { k2, .. } = stage {
                let (jacobian, _) = free_mass(&mut fit.theta, k2)?;
                fit.covariance = &jacobian * &fit.covariance * jacobian.transpose();
                fit.std_errors = fit.covariance.diagonal().map(|v| v.max(0.0).sqrt());
            }
            return finite(fit);
        };
        let second = matches!(stage, Stage::Second { .. });
        let options = SolveOptions {
            max_condition: DEFAULT_MAX_CONDITION,
            covariance: Covariance::Classical,
            segment_starts: &[],
            influence: true,
            also: second.then_some(self.z.as_slice()),
        };
        let solved = solve_augmented(&mut self.buf, m, p, &options, &mut self.hac)?;
        let mut fit = solved.fit;
        let n = data.rows;
        let series = match stage {
            Stage::First => &mut self.first,
            Stage::Second { .. } | Stage::FreeMass { .. } => &mut self.second,
        };
        series.clear();
        series.resize(n * p, 0.0);
        for (from, to) in self.hac.copy[..m * p]
            .chunks_exact(m)
            .zip(series.chunks_exact_mut(n))
        {
            match keep {
                None => to.copy_from_slice(from),
                Some(motion) => {
                    let rows = motion
                        .direction
                        .iter()
                        .enumerate()
                        .filter(|(_, d)| **d != 0.0);
                    for (&v, (r, _)) in from.iter().zip(rows) {
                        to[r] = v;
                    }
                }
            }
        }
        if let (Stage::Second { k2_index }, Some(g)) = (stage, &solved.also) {
            let k2 = &self.first[k2_index * n..(k2_index + 1) * n];
            for (j, col) in self.second.chunks_exact_mut(n).enumerate() {
                col.iter_mut().zip(k2).for_each(|(v, &k)| *v += g[j] * k);
            }
        }
        if let Stage::FreeMass { k2_index, k2 } = stage {
            // θ = k2 h(θ'): a row's influence on θ is J times its
            // influence on θ' plus ∂θ/∂k2 = θ/k2 times its influence on k2.
            let (jacobian, per_k2) = free_mass(&mut fit.theta, k2)?;
            let k2_series = &self.first[k2_index * n..(k2_index + 1) * n];
            let mut own = [0.0; MAX_STAGE2];
            for (r, &k) in k2_series.iter().enumerate() {
                for (i, v) in own[..p].iter_mut().enumerate() {
                    *v = self.second[i * n + r];
                }
                for j in 0..p {
                    let mapped: f64 = (0..p).map(|i| jacobian[(j, i)] * own[i]).sum();
                    self.second[j * n + r] = mapped + per_k2[j] * k;
                }
            }
        }
        let series = match stage {
            Stage::First => &self.first,
            Stage::Second { .. } | Stage::FreeMass { .. } => &self.second,
        };
        self.starts.clear();
        self.starts.extend(data.segments.iter().map(|s| s.row0));
        let (covariance, used) =
            newey_west(series, n, p, &self.starts, m, lags, &mut self.hac.scratch);
        fit.std_errors = covariance.diagonal().map(|v| v.max(0.0).sqrt());
        fit.covariance = covariance;
        fit.covariance_kind = Covariance::NeweyWest { lags: Some(used) };
        finite(fit)
    }
}

/// `fit`, unless a covariance or standard error overflowed.
fn finite(fit: LeastSquaresFit) -> Result<LeastSquaresFit, Error> {
    if fit.covariance.iter().all(|v| v.is_finite()) && fit.std_errors.iter().all(|v| v.is_finite())
    {
        Ok(fit)
    } else {
        Err(Error::Overflow {
            operation: "identification (a standard error exceeds f64::MAX)",
        })
    }
}

/// Most parameters of stage 2: `K`, `b2`, `m2`, `F2`.
const MAX_STAGE2: usize = 4;

/// Maps stage 2's normalised estimate `θ' = [K, b2, k2, (F2)] / m2` in
/// place to `θ = [K, b2, m2, (F2)]` with the coupling spring `k2`: `m2 =
/// k2 / θ'₂`, the others `k2 θ'ᵢ / θ'₂`. Returns `J = ∂θ/∂θ'` and
/// `∂θ/∂k2 = θ / k2`.
fn free_mass(
    theta: &mut nalgebra::DVector<f64>,
    k2: f64,
) -> Result<(nalgebra::DMatrix<f64>, [f64; MAX_STAGE2]), Error> {
    let p = theta.len();
    let c = theta[2];
    let m2 = k2 / c;
    if !(m2.is_finite() && m2 > 0.0) {
        return Err(Error::InvalidParameter {
            name: "m2 (fitted)",
            value: m2,
            reason: "cart 2's fitted mass is not finite and > 0 kg: the run does not \
                     identify it (see Options::free_m2)",
        });
    }
    let mut jacobian = nalgebra::DMatrix::zeros(p, p);
    let mut per_k2 = [0.0; MAX_STAGE2];
    for i in 0..p {
        let ratio = if i == 2 { 1.0 } else { theta[i] };
        // θᵢ = k2 ratio / c.
        jacobian[(i, 2)] = -k2 * ratio / (c * c);
        if i != 2 {
            jacobian[(i, i)] = k2 / c;
        }
        per_k2[i] = ratio / c;
        theta[i] = k2 * ratio / c;
    }
    Ok((jacobian, per_k2))
}

/// The rows a stage uses: all, or those where its cart moves.
fn row_count(data: &Data<'_>, coulomb: Option<&Motion>) -> usize {
    coulomb.map_or(data.rows, |m| m.moving)
}

/// The Coulomb column `sign · T²` (times `scale`) over the kept rows.
fn push_coulomb(buf: &mut Vec<f64>, data: &Data<'_>, motion: &Motion, scale: f64) {
    column(buf, data, Some(motion), |seg| {
        let t2 = seg.dt * seg.dt;
        motion.direction[seg.row0..seg.row0 + seg.rows()]
            .iter()
            .map(move |&d| scale * t2 * d)
    });
}

/// The columns of equation (6) that do not depend on the spring model:
/// cart 1's velocity regressor (for `b1`), the optional Coulomb column,
/// and `λ`, appended to `buf`.
fn push_cart1_friction_and_lambda<D: Differences>(
    data: &Data<'_>,
    m1: f64,
    coulomb: Option<&Motion>,
    buf: &mut Vec<f64>,
) {
    let x1 = data.x1;
    column(buf, data, coulomb, |seg| {
        let t = seg.dt;
        triples(&x1[seg.start..seg.end]).map(move |x| t * D::vel(x))
    });
    if let Some(motion) = coulomb {
        push_coulomb(buf, data, motion, 1.0);
    }
    // The lab's own order of operations, as its MATLAB `lamda`.
    column(buf, data, coulomb, |seg| {
        triples(&x1[seg.start..seg.end]).map(|x| m1 * (2.0 * x[1] - x[0] - x[2]))
    });
}

/// Stage 1 (equation (6)): the springs (`[k12]` equal, `[k1, k2]`
/// separate), `b1`, then `F1` with the Coulomb column.
pub(super) fn stage1<D: Differences>(
    data: &Data<'_>,
    m1: f64,
    springs: SpringModel,
    coulomb: Option<&Motion>,
    solver: &mut Solver,
) -> Result<LeastSquaresFit, Error> {
    let buf = &mut solver.buf;
    let (x1, x2) = (data.x1, data.x2);
    let m = row_count(data, coulomb);
    let p = springs.parameters() + 1 + usize::from(coulomb.is_some());
    buf.clear();
    buf.reserve(m * (p + 1));
    match springs {
        // `k12 T² [2x1(k) − x2(k)]`.
        SpringModel::Equal => column(buf, data, coulomb, |seg| {
            let t2 = seg.dt * seg.dt;
            let (x1, x2) = (&x1[seg.start..seg.end], &x2[seg.start..seg.end]);
            triples(x1)
                .zip(triples(x2))
                .map(move |(x1, x2)| t2 * (2.0 * D::pos(x1) - D::pos(x2)))
        }),
        // `k1 T² x1(k) + k2 T² [x1(k) − x2(k)]`.
        SpringModel::Separate => {
            column(buf, data, coulomb, |seg| {
                let t2 = seg.dt * seg.dt;
                triples(&x1[seg.start..seg.end]).map(move |x| t2 * D::pos(x))
            });
            column(buf, data, coulomb, |seg| {
                let t2 = seg.dt * seg.dt;
                let (x1, x2) = (&x1[seg.start..seg.end], &x2[seg.start..seg.end]);
                triples(x1)
                    .zip(triples(x2))
                    .map(move |(x1, x2)| t2 * (D::pos(x1) - D::pos(x2)))
            });
        }
    }
    push_cart1_friction_and_lambda::<D>(data, m1, coulomb, buf);
    solver.solve(data, coulomb, m, p, Stage::First)
}

/// Stage 2 (equations (9)–(11)): `[K, b2]` given the coupling spring `k2`
/// (stage 1's parameter `k2_index`), then `F2` with the Coulomb column.
///
/// With cart 2's mass free (`m2` is `None`) the equation is divided by
/// `m2`: `λ` is the bare second difference and the columns fit `[K, b2,
/// k2, (F2)] / m2`, mapped to `[K, b2, m2, (F2)]` with `k2`. Fitting `m2`
/// on a column `−Δ²x2` instead would put the encoder's noise, amplified
/// by the second difference, into a regressor, and least squares shrinks
/// the coefficient of a noisy regressor (on the simulated rig, `m2` 3 to
/// 7 % low).
pub(super) fn stage2<D: Differences>(
    data: &Data<'_>,
    m2: Option<f64>,
    (k2, k2_index): (f64, usize),
    coulomb: Option<&Motion>,
    solver: &mut Solver,
) -> Result<LeastSquaresFit, Error> {
    let (x1, x2) = (data.x1, data.x2);
    // `T² (x2 − x1)` at the spring terms' positions: ∂λ/∂k2 with `m2`
    // given, the `k2 / m2` column with it free.
    let spring = |seg: &Segment| {
        let t2 = seg.dt * seg.dt;
        let (x1, x2) = (&x1[seg.start..seg.end], &x2[seg.start..seg.end]);
        triples(x2)
            .zip(triples(x1))
            .map(move |(x2, x1)| t2 * (D::pos(x2) - D::pos(x1)))
    };
    if m2.is_some() && matches!(solver.covariance, Covariance::NeweyWest { .. }) {
        solver.z.clear();
        column(&mut solver.z, data, coulomb, spring);
    }
    let buf = &mut solver.buf;
    let u = data.u;
    let m = row_count(data, coulomb);
    let p = 2 + usize::from(m2.is_none()) + usize::from(coulomb.is_some());
    buf.clear();
    buf.reserve(m * (p + 1));
    column(buf, data, coulomb, |seg| {
        let t2 = seg.dt * seg.dt;
        input_pairs(&u[seg.start..seg.end]).map(move |(a, b)| t2 * D::input(a, b))
    });
    column(buf, data, coulomb, |seg| {
        let t = seg.dt;
        triples(&x2[seg.start..seg.end]).map(move |x| -t * D::vel(x))
    });
    let Some(m2) = m2 else {
        column(buf, data, coulomb, |seg| spring(seg).map(|v| -v));
        if let Some(motion) = coulomb {
            push_coulomb(buf, data, motion, -1.0);
        }
        column(buf, data, coulomb, |seg| {
            triples(&x2[seg.start..seg.end]).map(second_difference)
        });
        return solver.solve(data, coulomb, m, p, Stage::FreeMass { k2_index, k2 });
    };
    if let Some(motion) = coulomb {
        push_coulomb(buf, data, motion, -1.0);
    }
    column(buf, data, coulomb, |seg| {
        let t2 = seg.dt * seg.dt;
        let (x1, x2) = (&x1[seg.start..seg.end], &x2[seg.start..seg.end]);
        triples(x2)
            .zip(triples(x1))
            .map(move |(x2, x1)| m2 * second_difference(x2) + k2 * t2 * (D::pos(x2) - D::pos(x1)))
    });
    solver.solve(data, coulomb, m, p, Stage::Second { k2_index })
}
