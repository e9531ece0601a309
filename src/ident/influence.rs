//! Each row's influence on a least-squares estimate, `(ΦᵀΦ)⁻¹ φ_t e_t`,
//! from the equilibrated problem and its triangular factor: what the
//! Newey–West covariance sums. Column by column ([`residuals`], [`to_u`],
//! [`to_h`]), or row by row in one pass ([`influence_into`]), the same
//! operations in the same order.

use nalgebra::{DMatrix, DVector};

use super::solve::{pow2, scale_pow2};
use crate::kernels::reduce::{MaxSsLanes, SumLanes, max_ss, zip_sum};

/// The lanes of [`SumLanes`] and [`MaxSsLanes`].
const LANES: usize = 8;

/// The rows of `[Φ | λ]` an influence is made from: `p + 1` columns
/// `stride` apart, column `j` multiplied by `factors[j]` as it is read (a
/// power of two, the column's equilibration: exact, so the same values as
/// an equilibrated copy).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Source<'a> {
    pub cols: &'a [f64],
    pub stride: usize,
    pub factors: &'a [f64],
}

/// Where each row's influence goes (`p` columns `stride` apart) and what
/// is summed on the way.
#[derive(Debug)]
pub(crate) struct Sink<'a> {
    pub cols: &'a mut [f64],
    pub stride: usize,
    /// Stage 2's `z` and the power of two `f` it is multiplied by: the
    /// sums `Uᵀ (z f)` of [`sensitivity_sums`] are returned.
    pub z: Option<(&'a [f64], f64)>,
    /// Each column's `(max |h|, Σ h²)`, as
    /// [`max_ss`](crate::kernels::reduce::max_ss) finds them.
    pub stats: Option<&'a mut [(f64, f64)]>,
}

/// Each row's influence `R⁻¹ R⁻ᵀ φ_t e_t` of the equilibrated `[Φ | λ]`
/// (`rows` rows of `src`, `p = θ.len()`), times `2^d_j` for column `j`
/// (the parameters' units), into `sink`: what [`residuals`], [`to_u`] and
/// [`to_h`] and the unscaling compute column by column, in one pass, each
/// row's operations in the same order (the same values, bit for bit).
/// With `sink.z`, returns [`sensitivity_sums`]' sums and with
/// `sink.stats` fills them, both in the same order as those passes (bit
/// for bit), from the values at hand.
pub(crate) fn influence_into(
    src: Source<'_>,
    rows: usize,
    theta: &DVector<f64>,
    rinv: &DMatrix<f64>,
    d: &[i32],
    sink: Sink<'_>,
) -> Option<DVector<f64>> {
    let p = theta.len();
    // A zero in R⁻¹ is skipped, not added (as the column passes do): a
    // case for them.
    let dense = (0..p).all(|j| (0..=j).all(|k| rinv[(k, j)] != 0.0));
    macro_rules! kernel {
        ($p:literal) => {
            match (sink.z.is_some(), sink.stats.is_some()) {
                (false, false) => {
                    influence_kernel::<$p, false, false>(src, rows, theta, rinv, d, sink)
                }
                (true, false) => {
                    influence_kernel::<$p, true, false>(src, rows, theta, rinv, d, sink)
                }
                (false, true) => {
                    influence_kernel::<$p, false, true>(src, rows, theta, rinv, d, sink)
                }
                (true, true) => influence_kernel::<$p, true, true>(src, rows, theta, rinv, d, sink),
            }
        };
    }
    match p {
        1 if dense => kernel!(1),
        2 if dense => kernel!(2),
        3 if dense => kernel!(3),
        4 if dense => kernel!(4),
        5 if dense => kernel!(5),
        _ => influence_by_columns(src, rows, theta, rinv, d, sink),
    }
}

/// [`influence_into`] by the column passes, on an equilibrated copy.
#[cold]
fn influence_by_columns(
    src: Source<'_>,
    rows: usize,
    theta: &DVector<f64>,
    rinv: &DMatrix<f64>,
    d: &[i32],
    mut sink: Sink<'_>,
) -> Option<DVector<f64>> {
    let p = theta.len();
    let mut a = Vec::with_capacity((p + 1) * rows);
    for (j, &f) in src.factors.iter().enumerate().take(p + 1) {
        let col = &src.cols[j * src.stride..j * src.stride + rows];
        a.extend(col.iter().map(|&v| if f == 1.0 { v } else { v * f }));
    }
    let qz = sink
        .z
        .map(|(z, f)| sensitivity_sums(&a, rows, rows, rinv, z, f, &mut Vec::new()));
    let (phi, lambda) = a.split_at_mut(p * rows);
    residuals(phi, lambda, rows, theta);
    to_u(phi, rows, rows, rinv);
    to_h(phi, lambda, rows, rows, rinv);
    for (j, &d) in d.iter().enumerate().take(p) {
        let col = &phi[j * rows..(j + 1) * rows];
        let out = &mut sink.cols[j * sink.stride..j * sink.stride + rows];
        for (o, &v) in out.iter_mut().zip(col) {
            *o = scale_pow2(v, d);
        }
        if let Some(stats) = sink.stats.as_deref_mut() {
            stats[j] = max_ss(out);
        }
    }
    qz
}

/// [`influence_into`] for `P` parameters and an `R⁻¹` without zeros; `Z`:
/// with `z`'s sums, `S`: with the columns' stats.
#[inline(never)]
fn influence_kernel<const P: usize, const Z: bool, const S: bool>(
    src: Source<'_>,
    rows: usize,
    theta: &DVector<f64>,
    rinv: &DMatrix<f64>,
    d: &[i32],
    sink: Sink<'_>,
) -> Option<DVector<f64>> {
    let th: [f64; P] = std::array::from_fn(|j| theta[j]);
    let ri: [[f64; P]; P] = std::array::from_fn(|k| std::array::from_fn(|j| rinv[(k, j)]));
    // scale_pow2's two exact factors.
    let halves: [(f64, f64); P] = std::array::from_fn(|j| (pow2(d[j] / 2), pow2(d[j] - d[j] / 2)));
    let f: [f64; P] = std::array::from_fn(|j| src.factors[j]);
    let f_lambda = src.factors[P];
    let xs: [&[f64]; P] = std::array::from_fn(|j| &src.cols[j * src.stride..][..rows]);
    let lambda = &src.cols[P * src.stride..][..rows];
    let Sink {
        cols,
        stride,
        z,
        stats,
    } = sink;
    let mut out = cols.chunks_mut(stride);
    let h: [&mut [f64]; P] = std::array::from_fn(|_| {
        let col = out.next().unwrap_or_default();
        let len = col.len().min(rows);
        &mut col[..len]
    });
    let (z, f_z) = z.map_or((&[][..], 1.0), |(z, f)| (&z[..rows], f));
    let mut sums = [SumLanes::new(); P];
    let mut found = [MaxSsLanes::new(); P];
    let k = Kernel {
        xs,
        lambda,
        f,
        f_lambda,
        th,
        ri,
        halves,
    };
    // A chunk of eight rows two at a time, each pair of lanes `2q, 2q + 1`
    // of the lanes' sums; the rows past the last chunk one at a time.
    let whole = rows / LANES * LANES;
    for c in (0..whole).step_by(LANES) {
        for q in 0..LANES / 2 {
            let i = c + 2 * q;
            let (u, v) = k.rows::<2>(i);
            for j in 0..P {
                h[j][i..i + 2].copy_from_slice(&v[j]);
                for l in 0..2 {
                    if Z {
                        sums[j].add(2 * q + l, u[j][l] * (z[i + l] * f_z));
                    }
                    if S {
                        found[j].add(2 * q + l, v[j][l]);
                    }
                }
            }
        }
    }
    for i in whole..rows {
        let (u, v) = k.rows::<1>(i);
        for j in 0..P {
            h[j][i] = v[j][0];
            if Z {
                sums[j].add_tail(u[j][0] * (z[i] * f_z));
            }
            if S {
                found[j].add_tail(v[j][0]);
            }
        }
    }
    if let Some(stats) = stats {
        for (s, found) in stats.iter_mut().zip(&found) {
            *s = found.finish();
        }
    }
    Z.then(|| DVector::from_fn(P, |j, _| sums[j].total()))
}

/// What [`influence_kernel`] reads, and its rows' operations.
struct Kernel<'a, const P: usize> {
    xs: [&'a [f64]; P],
    lambda: &'a [f64],
    f: [f64; P],
    f_lambda: f64,
    th: [f64; P],
    ri: [[f64; P]; P],
    halves: [(f64, f64); P],
}

impl<const P: usize> Kernel<'_, P> {
    /// Rows `i .. i + W`: each one's `u = R⁻ᵀ φ` and influence, a lane
    /// at a time (two lanes pair into SIMD).
    #[inline(always)]
    fn rows<const W: usize>(&self, i: usize) -> ([[f64; W]; P], [[f64; W]; P]) {
        let (th, ri, halves) = (&self.th, &self.ri, &self.halves);
        let x: [[f64; W]; P] =
            std::array::from_fn(|j| std::array::from_fn(|l| self.xs[j][i + l] * self.f[j]));
        let mut e: [f64; W] = std::array::from_fn(|l| self.lambda[i + l] * self.f_lambda);
        for j in 0..P {
            for l in 0..W {
                e[l] -= th[j] * x[j][l];
            }
        }
        let mut u = [[0.0; W]; P];
        for j in 0..P {
            for l in 0..W {
                let mut v = x[j][l] * ri[j][j];
                for k in 0..j {
                    v += ri[k][j] * x[k][l];
                }
                u[j][l] = v;
            }
        }
        let mut out = [[0.0; W]; P];
        for j in 0..P {
            for l in 0..W {
                let mut v = u[j][l] * ri[j][j];
                for k in j + 1..P {
                    v += ri[j][k] * u[k][l];
                }
                out[j][l] = v * e[l] * halves[j].0 * halves[j].1;
            }
        }
        (u, out)
    }
}

/// `Uᵀ (z f)` of the equilibrated `Φ` in `a` (`rows` rows, columns
/// `stride` apart), `U = Φ R⁻¹` formed a column at a time in `u` (as
/// [`to_u`] forms it), `f` a power of two that keeps `z f` at most 2 in
/// size: stage 2's sensitivity to `k2` is `g = R⁻¹ Uᵀ z`.
pub(crate) fn sensitivity_sums(
    a: &[f64],
    stride: usize,
    rows: usize,
    rinv: &DMatrix<f64>,
    z: &[f64],
    f: f64,
    u: &mut Vec<f64>,
) -> DVector<f64> {
    let p = rinv.ncols();
    DVector::from_fn(p, |j, _| {
        u.clear();
        u.extend_from_slice(&a[j * stride..j * stride + rows]);
        let d = rinv[(j, j)];
        u.iter_mut().for_each(|v| *v *= d);
        for k in 0..j {
            let c = rinv[(k, j)];
            if c != 0.0 {
                let other = &a[k * stride..k * stride + rows];
                u.iter_mut().zip(other).for_each(|(v, &x)| *v += c * x);
            }
        }
        zip_sum(u, &z[..rows], |q, z| q * (z * f))
    })
}

/// `e = λ − Φ θ` in place of `λ` (`rows` of them; `Φ`'s columns `stride`
/// apart), column by column.
pub(crate) fn residuals(phi: &[f64], lambda: &mut [f64], stride: usize, theta: &DVector<f64>) {
    let rows = lambda.len();
    for (j, &t) in theta.iter().enumerate() {
        let col = &phi[j * stride..j * stride + rows];
        lambda.iter_mut().zip(col).for_each(|(e, &x)| *e -= t * x);
    }
}

/// `U = Φ R⁻¹` (the thin Q) in place of `Φ` (`rows` rows, columns
/// `stride` apart): column j needs columns 0 … j of Φ (R⁻¹ is upper
/// triangular), so go down.
pub(crate) fn to_u(phi: &mut [f64], stride: usize, rows: usize, rinv: &DMatrix<f64>) {
    for j in (0..rinv.ncols()).rev() {
        let (before, rest) = phi.split_at_mut(j * stride);
        let col = &mut rest[..rows];
        let d = rinv[(j, j)];
        col.iter_mut().for_each(|v| *v *= d);
        for (k, other) in before.chunks(stride).enumerate() {
            let c = rinv[(k, j)];
            if c != 0.0 {
                col.iter_mut().zip(other).for_each(|(v, &x)| *v += c * x);
            }
        }
    }
}

/// `diag(e) U R⁻ᵀ` in place of `U`: column j of `U R⁻ᵀ` is
/// `Σ_{k ≥ j} U_k R⁻¹[j, k]`, so go up.
pub(crate) fn to_h(u: &mut [f64], e: &[f64], stride: usize, rows: usize, rinv: &DMatrix<f64>) {
    let p = rinv.ncols();
    for j in 0..p {
        let (head, tail) = u.split_at_mut((j + 1) * stride);
        let col = &mut head[j * stride..j * stride + rows];
        let d = rinv[(j, j)];
        col.iter_mut().for_each(|v| *v *= d);
        for (k, other) in tail.chunks(stride).take(p - j - 1).enumerate() {
            let c = rinv[(j, j + 1 + k)];
            if c != 0.0 {
                col.iter_mut().zip(other).for_each(|(v, &x)| *v += c * x);
            }
        }
        col.iter_mut().zip(e).for_each(|(v, &e)| *v *= e);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::signal::Rng;

    /// The one-pass influence (with `z`'s sums and the columns' stats) is
    /// the column passes on an equilibrated copy, bit for bit, for every
    /// kernel size and the column path (six parameters, or a zero in
    /// R⁻¹), at lengths around the lanes.
    #[test]
    fn the_one_pass_influence_is_the_column_passes() {
        let mut rng = Rng::new(7);
        for p in 1..=6 {
            for zero in [false, true] {
                for rows in [1, 7, 8, 9, 17, 100] {
                    let stride = rows + 3;
                    let raw: Vec<f64> = (0..(p + 1) * stride)
                        .map(|_| (rng.uniform() - 0.5) * 40.0)
                        .collect();
                    let factors: Vec<f64> = (0..=p).map(|j| pow2(-(j as i32) * 3 + 2)).collect();
                    let theta = DVector::from_fn(p, |_, _| rng.uniform() - 0.3);
                    let mut rinv =
                        DMatrix::from_fn(
                            p,
                            p,
                            |i, j| {
                                if i <= j { rng.uniform() + 0.1 } else { 0.0 }
                            },
                        );
                    if zero && p > 1 {
                        rinv[(0, p - 1)] = 0.0;
                    }
                    let d: Vec<i32> = (0..p).map(|j| j as i32 - 2).collect();
                    let z: Vec<f64> = (0..rows).map(|_| rng.uniform() * 1.5).collect();
                    let f_z = 0.25;
                    // The column passes on an equilibrated copy.
                    let mut a = Vec::new();
                    for j in 0..=p {
                        let col = &raw[j * stride..j * stride + rows];
                        a.extend(col.iter().map(|v| v * factors[j]));
                    }
                    let want_qz = sensitivity_sums(&a, rows, rows, &rinv, &z, f_z, &mut Vec::new());
                    let (phi, lambda) = a.split_at_mut(p * rows);
                    residuals(phi, lambda, rows, &theta);
                    to_u(phi, rows, rows, &rinv);
                    to_h(phi, lambda, rows, rows, &rinv);
                    for j in 0..p {
                        for v in &mut phi[j * rows..(j + 1) * rows] {
                            *v = scale_pow2(*v, d[j]);
                        }
                    }
                    let mut out = vec![0.0; p * stride];
                    let mut stats = vec![(0.0, 0.0); p];
                    let source = Source {
                        cols: &raw,
                        stride,
                        factors: &factors,
                    };
                    let sink = Sink {
                        cols: &mut out,
                        stride,
                        z: Some((&z, f_z)),
                        stats: Some(&mut stats),
                    };
                    let qz = influence_into(source, rows, &theta, &rinv, &d, sink).unwrap();
                    let case = format!("p {p} zero {zero} rows {rows}");
                    for j in 0..p {
                        let want = &phi[j * rows..(j + 1) * rows];
                        let got = &out[j * stride..j * stride + rows];
                        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                        assert_eq!(bits(got), bits(want), "{case} column {j}");
                        assert_eq!(qz[j].to_bits(), want_qz[j].to_bits(), "{case} g {j}");
                        let (m, s) = max_ss(want);
                        assert_eq!(stats[j], (m, s), "{case} stats {j}");
                    }
                }
            }
        }
    }
}
