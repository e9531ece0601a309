//! A stage's influence series for the Newey–West sums, handed out block by
//! block ([`Series`]): each row's `(ΦᵀΦ)⁻¹ φ_t e_t` at its place among the
//! segments' rows (zero at a row the stage left out), stage 2's with
//! stage 1's influence on `k2` carried through `g` (or, cart 2's mass
//! free, mapped to `[K, b2, m2, (F2)]`).
//!
//! A stage solved whole has its rows' influence stored, and made the
//! series in place ([`carry_and_map`]); a streamed one has it computed
//! again from the samples for each block ([`Influence`], [`regen`]): its
//! rows built, equilibrated with the solve's powers of two, and taken
//! through the same residual, `Φ R⁻¹` and `U R⁻ᵀ` steps as the stored
//! solve's, row by row, so that every value is the one the stored series
//! would hold.

use std::marker::PhantomData;

use nalgebra::DMatrix;

use super::regressors::{Differences, Out, Spec};
use super::stages::MAX_STAGE2;
use crate::ident::{Series, Triangular, influence_rows, scale_column};
use crate::kernels::reduce::first_non_finite;

/// A streamed stage's own influence, computed again from the samples.
pub(super) struct Own<'s, 'a> {
    pub spec: &'s Spec<'s, 'a>,
    pub tri: &'s Triangular,
    pub exponents: &'s [i32],
}

/// Where stage 1's influence on `k2` comes from, for stage 2.
pub(super) enum K2<'s, 'a> {
    /// Stored at every row of the segments.
    Whole(&'s [f64]),
    /// Computed again from the samples (its parameter `k2_index`).
    Regen {
        spec: &'s Spec<'s, 'a>,
        tri: &'s Triangular,
        exponents: &'s [i32],
        k2_index: usize,
    },
}

/// A stage's influence series, rows `0 … n` of the segments.
pub(super) struct Influence<'s, 'a, D> {
    own: Own<'s, 'a>,
    p: usize,
    k2: Option<K2<'s, 'a>>,
    /// Stage 2's `∂θ̂₂/∂k2` (carried, with `m2` given).
    g: Option<Vec<f64>>,
    /// Cart 2's mass free: `J = ∂θ/∂θ'` and `∂θ/∂k2`.
    map: Option<(DMatrix<f64>, [f64; MAX_STAGE2])>,
    /// A block of rows being computed, and stage 1's influence on `k2`.
    block: Vec<f64>,
    k2_rows: Vec<f64>,
    differences: PhantomData<D>,
}

impl<'s, 'a, D: Differences> Influence<'s, 'a, D> {
    pub fn new(
        own: Own<'s, 'a>,
        p: usize,
        k2: Option<K2<'s, 'a>>,
        g: Option<Vec<f64>>,
        map: Option<(DMatrix<f64>, [f64; MAX_STAGE2])>,
    ) -> Self {
        Self {
            own,
            p,
            k2,
            g,
            map,
            block: Vec::new(),
            k2_rows: Vec::new(),
            differences: PhantomData,
        }
    }
}

/// Rows `from .. from + len` of the influence of the stage `spec`, solved
/// as `tri` with the powers `exponents`, into `block` (`p` columns, `len`
/// apart; `block` holds `[Φ | λ]` first), in the parameters' units and
/// zero at the rows it left out.
pub(super) fn regen<D: Differences>(
    spec: &Spec<'_, '_>,
    tri: &Triangular,
    exponents: &[i32],
    (from, len): (usize, usize),
    block: &mut Vec<f64>,
) {
    let p = spec.p;
    block.clear();
    spec.fill::<D>((from, from + len), false, false, Out::Push(block));
    for (col, &e) in block.chunks_exact_mut(len).zip(exponents) {
        scale_column(col, e);
    }
    let d: [i32; MAX_STAGE2 + 1] = std::array::from_fn(|j| {
        if j < p {
            exponents[p] - exponents[j]
        } else {
            0
        }
    });
    influence_rows(block, len, len, &tri.theta, &tri.rinv, &d[..p]);
    if let Some(keep) = spec.keep {
        let direction = &keep.direction[from..from + len];
        for col in block[..len * p].chunks_exact_mut(len) {
            col.iter_mut()
                .zip(direction)
                .filter(|(_, d)| **d == 0.0)
                .for_each(|(v, _)| *v = 0.0);
        }
    }
}

/// Whether a row the stage `spec` kept has an influence that is not
/// finite (the stored solve's error), all its rows computed again: the
/// cold path once a sum came out non-finite.
#[cold]
pub(super) fn overflows<D: Differences>(
    spec: &Spec<'_, '_>,
    tri: &Triangular,
    exponents: &[i32],
    block: &mut Vec<f64>,
) -> bool {
    let (n, p) = (spec.data.rows, spec.p);
    let mut from = 0;
    while from < n {
        let len = 4096.min(n - from);
        regen::<D>(spec, tri, exponents, (from, len), block);
        if first_non_finite(&block[..len * p]).is_some() {
            return true;
        }
        from += len;
    }
    false
}

impl K2<'_, '_> {
    /// Rows `from .. from + len` of stage 1's influence on `k2` into `out`
    /// (`block` a buffer).
    pub fn rows<D: Differences>(
        &self,
        (from, len): (usize, usize),
        block: &mut Vec<f64>,
        out: &mut Vec<f64>,
    ) {
        out.clear();
        match self {
            K2::Whole(stored) => out.extend_from_slice(&stored[from..from + len]),
            K2::Regen {
                spec,
                tri,
                exponents,
                k2_index,
            } => {
                // Stage 1's own overflow was its error, before stage 2.
                regen::<D>(spec, tri, exponents, (from, len), block);
                out.extend_from_slice(&block[k2_index * len..(k2_index + 1) * len]);
            }
        }
    }
}

/// Stage 2's own influence in `out` (`p` columns `stride` apart, `k2.len()`
/// rows) made its series: plus `g` times stage 1's influence on `k2` (`m2`
/// given), or mapped to `[K, b2, m2, (F2)]` (cart 2's mass free).
pub(super) fn carry_and_map(
    out: &mut [f64],
    stride: usize,
    p: usize,
    k2: &[f64],
    g: Option<&[f64]>,
    map: Option<&(DMatrix<f64>, [f64; MAX_STAGE2])>,
) {
    let len = k2.len();
    if let Some(g) = g {
        for (j, &g) in g.iter().enumerate() {
            let col = &mut out[j * stride..j * stride + len];
            col.iter_mut().zip(k2).for_each(|(v, &k)| *v += g * k);
        }
    }
    if let Some((jacobian, per_k2)) = map {
        // θ = k2 h(θ'): a row's influence on θ is J times its influence on
        // θ' plus ∂θ/∂k2 = θ/k2 times its influence on k2.
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

impl<D: Differences> Series for Influence<'_, '_, D> {
    fn fill(&mut self, from: usize, len: usize, out: &mut [f64], stride: usize) {
        let p = self.p;
        let Own {
            spec,
            tri,
            exponents,
        } = &self.own;
        regen::<D>(spec, tri, exponents, (from, len), &mut self.block);
        for j in 0..p {
            out[j * stride..j * stride + len].copy_from_slice(&self.block[j * len..(j + 1) * len]);
        }
        if let Some(k2) = &self.k2 {
            k2.rows::<D>((from, len), &mut self.block, &mut self.k2_rows);
            carry_and_map(
                out,
                stride,
                p,
                &self.k2_rows,
                self.g.as_deref(),
                self.map.as_ref(),
            );
        }
    }
}
