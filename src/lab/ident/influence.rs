//! A stage's influence series for the Newey–West sums: each row's
//! `(ΦᵀΦ)⁻¹ φ_t e_t` at its place among the segments' rows (zero at a row
//! the stage left out), stage 2's with stage 1's influence on `k2`
//! carried through `g` (or, cart 2's mass free, mapped to `[K, b2, m2,
//! (F2)]`), made in place of the stage's equilibrated copy.

use nalgebra::DMatrix;

use super::regressors::{Differences, Out, Spec};
use super::stages::MAX_STAGE2;
use crate::ident::{Sink, Source, Triangular, influence_into, pow2};
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
/// [`carry`] by `g`, each column's largest magnitude and sum of squares
/// (as [`max_ss`](crate::kernels::reduce::max_ss)) found on the way: one
/// pass over the series instead of two.
pub(super) fn carry_max_ss(
    out: &mut [f64],
    stride: usize,
    k2: &[f64],
    g: &[f64],
    max: &mut Vec<f64>,
    ss: &mut Vec<f64>,
) {
    const LANES: usize = 8;
    let len = k2.len();
    max.clear();
    ss.clear();
    for (j, &g) in g.iter().enumerate() {
        let col = &mut out[j * stride..j * stride + len];
        let (mut top, mut squares) = ([0.0f64; LANES], [0.0f64; LANES]);
        let mut chunks = col.chunks_exact_mut(LANES);
        let mut ks = k2.chunks_exact(LANES);
        for (c, k) in (&mut chunks).zip(&mut ks) {
            for i in 0..LANES {
                let v = c[i] + g * k[i];
                c[i] = v;
                let a = v.abs();
                top[i] = if a > top[i] { a } else { top[i] };
                squares[i] += v * v;
            }
        }
        let (mut worst, mut sum) = (top.iter().fold(0.0f64, |m, &v| m.max(v)), 0.0);
        for (v, &k) in chunks.into_remainder().iter_mut().zip(ks.remainder()) {
            *v += g * k;
            worst = worst.max(v.abs());
            sum += *v * *v;
        }
        max.push(worst);
        ss.push(squares.iter().sum::<f64>() + sum);
    }
}

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
    let factors: Vec<f64> = exponents.iter().map(|&e| pow2(-e)).collect();
    let d: Vec<i32> = (0..p).map(|j| exponents[p] - exponents[j]).collect();
    let mut out = vec![0.0; m * p];
    let source = Source {
        cols: block,
        stride: m,
        factors: &factors,
    };
    let sink = Sink {
        cols: &mut out,
        stride: m,
        z: None,
        stats: None,
    };
    influence_into(source, m, &tri.theta, &tri.rinv, &d, sink);
    first_non_finite(&out).is_some()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kernels::reduce::max_ss;

    /// The fused pass is `carry` then `max_ss`, bit for bit (a NaN left
    /// out of the maximum as there), at lengths around the lanes.
    #[test]
    fn carrying_finds_the_stats_of_carry_then_max_ss() {
        for len in [0, 1, 7, 8, 9, 31, 1000] {
            let k2: Vec<f64> = (0..len).map(|i| ((i * 37) % 11) as f64 - 5.3).collect();
            let mut series: Vec<f64> = (0..2 * len)
                .map(|i| ((i * 13) % 17) as f64 * 0.37 - 3.0)
                .collect();
            if len > 3 {
                series[3] = f64::NAN;
            }
            let g = [0.75, -1e3];
            let mut want = series.clone();
            carry(&mut want, len, 2, &k2, &Carry::Sensitivity(&g));
            let (mut max, mut ss) = (Vec::new(), Vec::new());
            carry_max_ss(&mut series, len, &k2, &g, &mut max, &mut ss);
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&series), bits(&want), "{len}");
            for j in 0..2 {
                let (m, s) = max_ss(&want[j * len..(j + 1) * len]);
                assert_eq!(
                    (max[j].to_bits(), ss[j].to_bits()),
                    (m.to_bits(), s.to_bits())
                );
            }
        }
    }
}
