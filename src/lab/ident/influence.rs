//! A stage's influence series for the Newey–West sums: each row's
//! `(ΦᵀΦ)⁻¹ φ_t e_t` at its place among the segments' rows (zero at a row
//! the stage left out), stage 2's with stage 1's influence on `k2`
//! carried through `g` (or, cart 2's mass free, mapped to `[K, b2, m2,
//! (F2)]`), made in place of the stage's equilibrated copy.

use nalgebra::DMatrix;

use super::regressors::{Differences, Out, Spec};
use super::stages::MAX_STAGE2;
use crate::ident::{Triangular, influence_rows, scale_column};
use crate::kernels::reduce::first_non_finite;

/// What stage 2's own influence becomes: plus `g` times stage 1's
/// influence on `k2` (`m2` given), or mapped by `J = ∂θ/∂θ'` plus `∂θ/∂k2`
/// times it (cart 2's mass free).
pub(super) enum Carry<'g> {
    Sensitivity(&'g [f64]),
    FreeMass(&'g (DMatrix<f64>, [f64; MAX_STAGE2])),
}

/// Stage 2's own influence in `out` (`p` columns `stride` apart, `k2.len()`
/// rows) made its series with stage 1's influence on `k2`.
pub(super) fn carry(out: &mut [f64], stride: usize, p: usize, k2: &[f64], how: &Carry<'_>) {
    let len = k2.len();
    match how {
        Carry::Sensitivity(g) => {
            for (j, &g) in g.iter().enumerate() {
                let col = &mut out[j * stride..j * stride + len];
                col.iter_mut().zip(k2).for_each(|(v, &k)| *v += g * k);
            }
        }
        Carry::FreeMass((jacobian, per_k2)) => {
            // θ = k2 h(θ'): a row's influence on θ is J times its influence
            // on θ' plus ∂θ/∂k2 = θ/k2 times its influence on k2.
            let mut own = [0.0; MAX_STAGE2];
            for (r, &k) in k2.iter().enumerate() {
                for (i, v) in own[..p].iter_mut().enumerate() {
                    *v = out[i * stride + r];
                }
                for j in 0..p {
                    let mapped: f64 = (0..p).map(|i| jacobian[(j, i)] * own[i]).sum();
                    out[j * stride + r] = mapped + per_k2[j] * k;
                }
            }
        }
    }
}

/// Whether a row the stage `spec` kept has an influence that is not
/// finite (the stored solve's error), the rows built, equilibrated with
/// `exponents` and solved as `tri` again in `block`: the cold path once
/// the series came out non-finite, which a carry can also make it.
#[cold]
pub(super) fn overflows<D: Differences>(
    spec: &Spec<'_, '_>,
    tri: &Triangular,
    exponents: &[i32],
    block: &mut Vec<f64>,
) -> bool {
    let p = spec.p;
    block.clear();
    let m = spec.fill::<D>((0, spec.data.rows), true, false, Out::Push(block));
    for (col, &e) in block.chunks_exact_mut(m).zip(exponents) {
        scale_column(col, e);
    }
    let d: Vec<i32> = (0..p).map(|j| exponents[p] - exponents[j]).collect();
    influence_rows(block, m, m, &tri.theta, &tri.rinv, &d);
    first_non_finite(&block[..m * p]).is_some()
}
