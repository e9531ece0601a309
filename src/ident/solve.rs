//! The QR solve behind [`LeastSquares`](super::LeastSquares) and the lab's
//! two-stage identification, with the covariance of the estimate.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::qr::no_pivoting::factor::{qr_in_place, qr_in_place_scratch};
use faer::{MatMut, Par};
use nalgebra::{DMatrix, DVector};

use super::covariance::newey_west;
use super::hac::Scratch;
use super::influence::{Sink, Source, influence_into};
use super::{Covariance, LeastSquaresFit};
use crate::error::Error;
use crate::kernels::reduce::{dot, finite_max_abs, first_non_finite, pow2_floor, sum_by};

/// How [`solve_augmented`] solves and what it reports.
#[derive(Debug, Clone, Copy)]
pub(crate) struct SolveOptions<'a> {
    /// Largest accepted column-equilibrated condition number.
    pub max_condition: f64,
    /// How the covariance is estimated.
    pub covariance: Covariance,
    /// Rows where a new segment starts (increasing): the Newey–West sums
    /// do not pair rows across them. 0 and rows ≥ `m` are ignored.
    pub segment_starts: &'a [usize],
}

/// The buffers of the covariance, kept between solves.
#[derive(Debug, Clone, Default)]
pub(crate) struct Workspace {
    /// The equilibrated `[Φ | λ]`, then the influence series and `e`.
    pub copy: Vec<f64>,
    /// The Newey–West sums' buffers.
    pub scratch: Scratch,
}

/// Up to this many columns (the lab's regressors have 2 to 5, with `λ`)
/// [`householder_narrow`] factors, not faer's QR: at 5000 × 3 faer's
/// general kernel took two thirds of the whole identification.
pub(crate) const NARROW: usize = 8;

/// Householder QR of the column-major `m × n` `a` in place, for tall and
/// narrow problems: leaves `R` in the upper triangle (what lies below it
/// is overwritten with the reflectors, which nobody reads). Each column is
/// one pass for its norm and one dot product and one update per later
/// column, over contiguous memory (eight-lane sums; the update
/// vectorises). The columns are equilibrated (entries below 2), so the
/// plain sums of squares cannot overflow.
pub(crate) fn householder_narrow(a: &mut [f64], m: usize, n: usize) {
    for j in 0..n.min(m) {
        let (left, right) = a.split_at_mut((j + 1) * m);
        let v = &mut left[j * m + j..];
        let norm = sum_by(v, |x| x * x).sqrt();
        if norm == 0.0 {
            continue;
        }
        // x − α e₁ with α = −sign(x₀) ‖x‖, so that x₀ − α never cancels;
        // then vᵀv = 2 ‖x‖ |v₀|.
        let x0 = v[0];
        let alpha = if x0 >= 0.0 { -norm } else { norm };
        v[0] = x0 - alpha;
        let scale = 1.0 / (norm * v[0].abs());
        for k in 0..n - j - 1 {
            let c = &mut right[k * m + j..(k + 1) * m];
            let d = dot(v, c) * scale;
            for (ci, vi) in c.iter_mut().zip(v.iter()) {
                *ci -= d * vi;
            }
        }
        v[0] = alpha;
    }
}

/// From this many rows [`householder_blocked`] factors, not
/// [`householder_narrow`]: the latter passes over every column once per
/// later column, and above about 64 k rows of the lab's 3 columns those
/// passes no longer fit in the cache (at 500 000 rows they were a third of
/// the identification's time). Below it the factorisation, and so every
/// figure, is the unblocked one's, bit for bit.
pub(crate) const BLOCKED_FROM_ROWS: usize = 1 << 16;

/// Rows per block of [`householder_blocked`]: with the `R` above them, a
/// few dozen kB, in the L1/L2 cache.
pub(crate) const BLOCK_ROWS: usize = 512;

/// The triangular factor of the column-major `m × n` `a` (`n ≤ NARROW`),
/// left in its upper triangle like [`householder_narrow`], by a blocked
/// (TSQR) reduction: each block of rows, under the `R` of the rows before
/// it, is factored by [`householder_narrow`] in a small buffer, so that the
/// data are read once. The same `R` up to rounding and the signs of its
/// rows, which nothing downstream depends on (θ, `R⁻¹R⁻ᵀ`, `ρ²` and the
/// singular values are invariant under them).
pub(crate) fn householder_blocked(a: &mut [f64], m: usize, n: usize) {
    let mut r = [0.0; NARROW * NARROW];
    // One buffer per solve, not per block.
    let mut w = vec![0.0; (BLOCK_ROWS + n) * n];
    let mut start = 0;
    while start < m {
        let rows = BLOCK_ROWS.min(m - start);
        let ld = n + rows;
        let w = &mut w[..ld * n];
        for (j, col) in w.chunks_exact_mut(ld).enumerate() {
            for (i, v) in col[..n].iter_mut().enumerate() {
                *v = if i <= j { r[j * n + i] } else { 0.0 };
            }
            col[n..].copy_from_slice(&a[j * m + start..j * m + start + rows]);
        }
        householder_narrow(w, ld, n);
        for (j, col) in w.chunks_exact(ld).enumerate() {
            r[j * n..j * n + j + 1].copy_from_slice(&col[..=j]);
        }
        start += rows;
    }
    for j in 0..n {
        a[j * m..j * m + j + 1].copy_from_slice(&r[j * n..j * n + j + 1]);
    }
}

/// Divides every column of the column-major `a` (`m` rows) by a power of
/// two, so that its largest entry is in [1, 2), and returns the powers'
/// exponents: exact, and then no norm, product or square in the QR or the
/// statistics can overflow or underflow, whatever the units (a column of
/// 1e308, another of 1e-200). The results are unscaled at the end.
pub(crate) fn equilibrate(a: &mut [f64], m: usize, exponents: &mut [i32]) -> Result<(), Error> {
    for (j, (col, e)) in a.chunks_exact_mut(m).zip(exponents.iter_mut()).enumerate() {
        *e = column_exponent(col, j)?;
        scale_column(col, *e);
    }
    Ok(())
}

/// [`equilibrate`] of `src` into `dst` (as long), `src` left as it is:
/// the same values and errors, with no copy made first.
#[cfg(feature = "lab")]
pub(crate) fn equilibrate_into(
    src: &[f64],
    dst: &mut [f64],
    m: usize,
    exponents: &mut [i32],
) -> Result<(), Error> {
    let cols = src.chunks_exact(m).zip(dst.chunks_exact_mut(m));
    for (j, ((col, out), e)) in cols.zip(exponents.iter_mut()).enumerate() {
        *e = column_exponent(col, j)?;
        let f = pow2(-*e);
        if *e == 0 {
            out.copy_from_slice(col);
        } else {
            out.iter_mut().zip(col).for_each(|(o, &v)| *o = v * f);
        }
    }
    Ok(())
}

/// The exponent [`equilibrate`] divides column `j` by, or the error naming
/// its first non-finite entry.
fn column_exponent(col: &[f64], j: usize) -> Result<i32, Error> {
    // One pass for both: the maximum and whether every entry is finite.
    let Some(largest) = finite_max_abs(col) else {
        let i = first_non_finite(col).unwrap_or(0);
        return Err(Error::NonFinite {
            matrix: "regressor",
            row: i,
            col: j,
            value: col[i],
        });
    };
    Ok(binary_exponent(largest))
}

/// `col` divided by `2^e` (unchanged for `e = 0`).
pub(crate) fn scale_column(col: &mut [f64], e: i32) {
    if e != 0 {
        let f = pow2(-e);
        col.iter_mut().for_each(|v| *v *= f);
    }
}

/// The sum of squares of `λ` about its mean.
pub(crate) fn spread(lam: &[f64]) -> f64 {
    let mean = sum_by(lam, |v| v) / lam.len() as f64;
    sum_by(lam, |v| (v - mean) * (v - mean))
}

/// Factors the column-major `m × n` `a` in place: leaves `R` in its upper
/// triangle.
fn factor(a: &mut [f64], m: usize, n: usize) {
    if n <= NARROW && m >= BLOCKED_FROM_ROWS {
        householder_blocked(a, m, n);
    } else if n <= NARROW {
        householder_narrow(a, m, n);
    } else {
        // Wider problems: faer's QR. Unblocked, as these are still tall.
        let bs = 1;
        let mut h = vec![0.0; bs * n];
        let mut mem = MemBuffer::new(qr_in_place_scratch::<f64>(
            m,
            n,
            bs,
            Par::Seq,
            Default::default(),
        ));
        qr_in_place(
            MatMut::from_column_major_slice_mut(a, m, n),
            MatMut::from_column_major_slice_mut(&mut h, bs, n),
            Par::Seq,
            MemStack::new(&mut mem),
            Default::default(),
        );
    }
}

/// What the triangular factor `[R z; 0 ρ]` of an equilibrated `[Φ | λ]`
/// gives: the equilibrated estimate, `R⁻¹`, `ρ² = ‖r‖²` and the
/// condition number.
#[derive(Debug, Clone)]
pub(crate) struct Triangular {
    pub theta: DVector<f64>,
    pub rinv: DMatrix<f64>,
    pub ssr: f64,
    pub condition: f64,
}

/// Solves the triangular factor `r(i, j)` of a problem with `p`
/// parameters (`r(p, p)` is `ρ`).
///
/// # Errors
///
/// [`Error::RankDeficient`] above `max_condition`; [`Error::NoConvergence`]
/// when the singular values do not converge.
pub(crate) fn triangular(
    r: impl Fn(usize, usize) -> f64,
    p: usize,
    max_condition: f64,
) -> Result<Triangular, Error> {
    // Householder QR commutes with column scaling, so the equilibrated
    // regressor Φ D⁻¹ (unit columns) has the triangular factor R D⁻¹, with
    // ‖Φ_j‖ = ‖R_j‖: its singular values give a unit-free condition number.
    let mut rmat = DMatrix::from_fn(p, p, |i, j| if i <= j { r(i, j) } else { 0.0 });
    for j in 0..p {
        let norm = rmat.column(j).norm();
        if norm > 0.0 {
            rmat.column_mut(j).unscale_mut(norm);
        }
    }
    let iterations = 200 * p;
    let sv = rmat
        .try_svd_unordered(false, false, f64::EPSILON, iterations)
        .ok_or(Error::NoConvergence {
            operation: "least squares (singular values of R)",
            iterations,
        })?
        .singular_values;
    let smax = sv.max();
    let smin = sv.min();
    let condition = if smin > 0.0 {
        smax / smin
    } else {
        f64::INFINITY
    };
    if condition.is_nan() || condition > max_condition {
        let rank = sv.iter().filter(|&&s| s * max_condition > smax).count();
        return Err(Error::RankDeficient { rank, condition });
    }

    // Back substitution R θ' = z, then undo the scaling.
    let mut theta = DVector::zeros(p);
    for i in (0..p).rev() {
        let mut s = r(i, p);
        for j in i + 1..p {
            s -= r(i, j) * theta[j];
        }
        theta[i] = s / r(i, i);
    }
    // R⁻¹ by back substitution, column by column.
    let mut rinv = DMatrix::zeros(p, p);
    for c in 0..p {
        for i in (0..=c).rev() {
            let mut s = if i == c { 1.0 } else { 0.0 };
            for j in i + 1..=c {
                s -= r(i, j) * rinv[(j, c)];
            }
            rinv[(i, c)] = s / r(i, i);
        }
    }
    Ok(Triangular {
        theta,
        rinv,
        ssr: r(p, p) * r(p, p),
        condition,
    })
}

/// The classical covariance `σ̂² (ΦᵀΦ)⁻¹` of the equilibrated problem.
pub(crate) fn classical(t: &Triangular, m: usize, p: usize) -> DMatrix<f64> {
    &t.rinv * t.rinv.transpose() * (t.ssr / (m - p) as f64)
}

/// The fit of an equilibrated problem (`m` rows, `p` parameters, columns
/// divided by `2^exponents[j]`, `λ`'s last; `sst` its spread) from its
/// triangular solve and `covariance` (equilibrated, of kind `kind`), in
/// the parameters' units.
///
/// # Errors
///
/// [`Error::Overflow`] when the estimate or its covariance exceeds
/// `f64::MAX` once unscaled.
pub(crate) fn fit_from(
    t: &Triangular,
    mut covariance: DMatrix<f64>,
    covariance_kind: Covariance,
    m: usize,
    exponents: &[i32],
    sst: f64,
) -> Result<LeastSquaresFit, Error> {
    let p = t.theta.len();
    let (ssr, e_lambda) = (t.ssr, exponents[p]);
    let mut theta = t.theta.clone();
    // A positive semi-definite covariance's diagonal is ≥ 0; rounding
    // could leave a vanishing variance a hair below.
    let mut std_errors = covariance.diagonal().map(|v| v.max(0.0).sqrt());
    let (r_squared, fit_percent) = if sst > 0.0 {
        (1.0 - ssr / sst, (1.0 - (ssr / sst).sqrt()) * 100.0)
    } else if ssr == 0.0 {
        (1.0, 100.0)
    } else {
        (f64::NEG_INFINITY, f64::NEG_INFINITY)
    };
    // Undo the equilibration: θ_j and its standard error in λ's units per
    // column j's, the covariance in their products.
    for j in 0..p {
        let d = e_lambda - exponents[j];
        theta[j] = scale_pow2(theta[j], d);
        std_errors[j] = scale_pow2(std_errors[j], d);
        for i in 0..p {
            covariance[(i, j)] =
                scale_pow2(scale_pow2(covariance[(i, j)], d), e_lambda - exponents[i]);
        }
    }
    let residual_rms = scale_pow2((ssr / m as f64).sqrt(), e_lambda);
    let finite = |v: &[f64]| v.iter().all(|v| v.is_finite());
    if !(finite(theta.as_slice())
        && finite(std_errors.as_slice())
        && finite(covariance.as_slice())
        && residual_rms.is_finite())
    {
        return Err(Error::Overflow {
            operation: "least squares (the estimate or its covariance exceeds f64::MAX)",
        });
    }
    Ok(LeastSquaresFit {
        theta,
        covariance,
        std_errors,
        residual_rms,
        r_squared,
        fit_percent,
        condition: t.condition,
        rows: m,
        covariance_kind,
    })
}

/// Solves `Φ θ ≈ λ` by QR, given column-major `a = [Φ | λ]` (`m` rows, `p + 1`
/// columns), destroying `a`. With a Newey–West covariance,
/// `workspace.copy` receives a copy of the equilibrated `a` (its allocation
/// is reused), then the influence series: row `t` is `(ΦᵀΦ)⁻¹ φ_t e_t`.
pub(crate) fn solve_augmented(
    a: &mut [f64],
    m: usize,
    p: usize,
    options: &SolveOptions<'_>,
    workspace: &mut Workspace,
) -> Result<LeastSquaresFit, Error> {
    let hac = &mut workspace.copy;
    debug_assert_eq!(a.len(), m * (p + 1));
    if p == 0 || m <= p {
        return Err(Error::TooFewSamples {
            what: "least squares (more rows than parameters)",
            needed: p.max(1) + 1,
            got: m,
        });
    }
    let mut exponents = vec![0i32; p + 1];
    equilibrate(a, m, &mut exponents)?;
    let newey_west_lags = match options.covariance {
        Covariance::Classical => None,
        Covariance::NeweyWest { lags } => Some(lags),
    };
    if newey_west_lags.is_some() {
        // The equilibrated problem, which QR is about to overwrite.
        hac.clear();
        hac.extend_from_slice(a);
    }
    // Spread of λ about its mean, before QR overwrites it.
    let sst = spread(&a[p * m..]);
    factor(a, m, p + 1);
    // The upper triangle of `a` now holds R_aug = [R z; 0 ρ], |ρ| = ‖r‖.
    let t = triangular(|i, j| a[j * m + i], p, options.max_condition)?;
    let (covariance, kind) = match newey_west_lags {
        None => (classical(&t, m, p), options.covariance),
        Some(lags) => {
            // Each row's influence, in the equilibrated units (unscaled
            // with the covariance), where the spent factor was.
            let ones = vec![1.0; p + 1];
            let source = Source {
                cols: hac,
                stride: m,
                factors: &ones,
            };
            let sink = Sink {
                cols: &mut a[..m * p],
                stride: m,
                z: None,
                stats: None,
            };
            influence_into(source, m, &t.theta, &t.rinv, &vec![0; p], sink);
            let (cov, used) = newey_west(
                &a[..m * p],
                m,
                p,
                options.segment_starts,
                m,
                lags,
                &mut workspace.scratch,
            );
            (cov, Covariance::NeweyWest { lags: Some(used) })
        }
    };
    fit_from(&t, covariance, kind, m, &exponents, sst)
}

/// `e` with `2^e ≤ x < 2^(e+1)` for a finite `x > 0` (0 for `x = 0`).
pub(crate) fn binary_exponent(x: f64) -> i32 {
    pow2_floor(x).log2() as i32
}

/// `2^e` for `|e| ≤ 1022`, exactly.
pub(crate) fn pow2(e: i32) -> f64 {
    2f64.powi(e)
}

/// `v · 2^d` for `|d| ≤ 2046`, in two exact halves: no intermediate
/// overflows unless the result does.
pub(crate) fn scale_pow2(v: f64, d: i32) -> f64 {
    let half = d / 2;
    v * pow2(half) * pow2(d - half)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The blocked factor is the unblocked one up to rounding and the signs
    /// of its rows, on a tall problem of the lab's shape (a ramp, a
    /// sinusoid, and their mix with noise), a last block short.
    #[test]
    fn blocked_qr_matches_unblocked() {
        let (m, n) = (3 * BLOCK_ROWS * 41 + 17, 3);
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut noise = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let mut a = vec![0.0; m * n];
        for i in 0..m {
            let x = i as f64 / m as f64;
            a[i] = 1.0 + x;
            a[m + i] = (40.0 * x).sin();
            a[2 * m + i] = 0.3 * a[i] - 2.0 * a[m + i] + 1e-3 * noise();
        }
        let mut plain = a.clone();
        householder_narrow(&mut plain, m, n);
        householder_blocked(&mut a, m, n);
        for i in 0..n {
            let sign = (a[i * m + i] * plain[i * m + i]).signum();
            for j in i..n {
                let (b, u) = (a[j * m + i], plain[j * m + i]);
                let scale = plain[j * m + j].abs().max(u.abs());
                assert!(
                    (sign * b - u).abs() <= 1e-12 * scale,
                    "R[{i}, {j}]: blocked {b} vs {u}"
                );
            }
        }
    }
}
