//! Each row's influence on a least-squares estimate, `(ΦᵀΦ)⁻¹ φ_t e_t`,
//! from the equilibrated problem and its triangular factor: what the
//! Newey–West covariance sums. Column by column ([`residuals`], [`to_u`],
//! [`to_h`]), or row by row in one pass ([`influence_rows`]), the same
//! operations in the same order.

use nalgebra::{DMatrix, DVector};

#[cfg(feature = "lab")]
use super::solve::binary_exponent;
use super::solve::{pow2, scale_pow2};
#[cfg(feature = "lab")]
use crate::kernels::reduce::{max_abs, zip_sum};

/// Each row's influence `R⁻¹ R⁻ᵀ φ_t e_t` of the equilibrated `[Φ | λ]` in
/// `a` (`rows` rows, columns `stride` apart, `p = θ.len()`), times `2^d_j`
/// for column `j` (the parameters' units), in place of `Φ`: what
/// [`residuals`], [`to_u`] and [`to_h`] and the unscaling compute column
/// by column, in one pass, each row's operations in the same order (the
/// same values, bit for bit).
pub(crate) fn influence_rows(
    a: &mut [f64],
    stride: usize,
    rows: usize,
    theta: &DVector<f64>,
    rinv: &DMatrix<f64>,
    d: &[i32],
) {
    let p = theta.len();
    // A zero in R⁻¹ is skipped, not added (as the column passes do): a
    // case for them.
    let dense = (0..p).all(|j| (0..=j).all(|k| rinv[(k, j)] != 0.0));
    match p {
        1 if dense => influence_kernel::<1>(a, stride, rows, theta, rinv, d),
        2 if dense => influence_kernel::<2>(a, stride, rows, theta, rinv, d),
        3 if dense => influence_kernel::<3>(a, stride, rows, theta, rinv, d),
        4 if dense => influence_kernel::<4>(a, stride, rows, theta, rinv, d),
        5 if dense => influence_kernel::<5>(a, stride, rows, theta, rinv, d),
        _ => {
            let (phi, lambda) = a.split_at_mut(p * stride);
            let lambda = &mut lambda[..rows];
            residuals(phi, lambda, stride, theta);
            to_u(phi, stride, rows, rinv);
            to_h(phi, lambda, stride, rows, rinv);
            for (j, &d) in d.iter().enumerate().take(p) {
                let col = &mut phi[j * stride..j * stride + rows];
                col.iter_mut().for_each(|v| *v = scale_pow2(*v, d));
            }
        }
    }
}

/// [`influence_rows`] for `P` parameters and an `R⁻¹` without zeros.
fn influence_kernel<const P: usize>(
    a: &mut [f64],
    stride: usize,
    rows: usize,
    theta: &DVector<f64>,
    rinv: &DMatrix<f64>,
    d: &[i32],
) {
    let th: [f64; P] = std::array::from_fn(|j| theta[j]);
    let ri: [[f64; P]; P] = std::array::from_fn(|k| std::array::from_fn(|j| rinv[(k, j)]));
    // scale_pow2's two exact factors.
    let halves: [(f64, f64); P] = std::array::from_fn(|j| (pow2(d[j] / 2), pow2(d[j] - d[j] / 2)));
    let (phi, lambda) = a.split_at_mut(P * stride);
    let lambda = &lambda[..rows];
    let mut cols = phi.chunks_mut(stride);
    let h: [&mut [f64]; P] = std::array::from_fn(|_| {
        let col = cols.next().unwrap_or_default();
        let len = col.len().min(rows);
        &mut col[..len]
    });
    for (i, &lam) in lambda.iter().enumerate() {
        let x: [f64; P] = std::array::from_fn(|j| h[j][i]);
        let mut e = lam;
        for j in 0..P {
            e -= th[j] * x[j];
        }
        let mut u = [0.0; P];
        for j in 0..P {
            let mut v = x[j] * ri[j][j];
            for k in 0..j {
                v += ri[k][j] * x[k];
            }
            u[j] = v;
        }
        for j in 0..P {
            let mut v = u[j] * ri[j][j];
            for k in j + 1..P {
                v += ri[j][k] * u[k];
            }
            h[j][i] = v * e * halves[j].0 * halves[j].1;
        }
    }
}

/// `g = R⁻¹ Uᵀ z` of the equilibrated `Φ` in `a` (`rows` rows, columns
/// `stride` apart), `U = Φ R⁻¹` formed a column at a time in `u` (as
/// [`to_u`] forms it), and `z` divided by `2^e_z` (returned with `e_z`):
/// the sensitivity of stage 2 of the lab's identification to `k2`.
#[cfg(feature = "lab")]
pub(crate) fn sensitivity_of(
    a: &[f64],
    stride: usize,
    rows: usize,
    rinv: &DMatrix<f64>,
    z: &[f64],
    u: &mut Vec<f64>,
) -> (DVector<f64>, i32) {
    let e_z = binary_exponent(max_abs(z));
    let qz = sensitivity_sums(a, stride, rows, rinv, z, pow2(-e_z), u);
    (rinv * qz, e_z)
}

/// `Uᵀ (z f)` of the rows in `a` (as [`sensitivity_of`]): a block's part
/// of the sums, `f` a power of two that keeps `z f` at most 2 in size.
#[cfg(feature = "lab")]
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
