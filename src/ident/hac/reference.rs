//! The Newey–West sums as they were before they were streamed (issue
//! 30): the whole series in memory, its scales found first, and the
//! automatic bandwidth's autocovariances lag by lag, the running sums
//! offset after them. The tests check the present sums against them.

use super::running::prefix_sums;
use crate::ident::newey_west_lags;
use crate::kernels::reduce::{dot, max_abs, pow2_floor, sum_by};

/// The columns' powers of two (`pow2_floor` of their largest entry) and
/// their inverses.
pub(super) fn scales(x: &[f64], n: usize) -> (Vec<f64>, Vec<f64>) {
    let scales: Vec<f64> = x.chunks_exact(n).map(|c| pow2_floor(max_abs(c))).collect();
    let inverses = scales.iter().map(|s| 1.0 / s).collect();
    (scales, inverses)
}

/// Rows of `v` (and of the autocovariances' series) handled at a time:
/// the block's columns stay in the cache between the running sums and the
/// products, so the work is one pass over the series however long it is.
const BLOCK: usize = 2048;

/// `Σ_t v_t v_tᵀ` over every segment, with `v_t` the sum of the rows
/// `t − L … t` of the segment (zero outside it), `t` running to `L` rows
/// past its end: `(L + 1) (Γ₀ + Σ_{l=1}^{L} w_l (Γ_l + Γ_lᵀ))` with the
/// Bartlett weights, exactly. The lower triangle, row by row.
///
/// Column `j` of `x` is taken times `inverses[j]`, a power of two that
/// brings its largest entry into [1, 2). `v` is formed [`BLOCK`] rows at
/// a time in `buf` as the running sum of `x_t − x_{t−L−1}` (carried from
/// block to block), and each block's products are summed before the next:
/// no copy of the series. A segment of `len ≤ L` rows has `v_t =
/// v_{len−1}` for every `t` from `len − 1` to `L`: that row is counted
/// once, with its weight.
pub(super) fn bartlett(
    x: &[f64],
    n: usize,
    inverses: &[f64],
    bounds: &[usize],
    lags: usize,
    buf: &mut Vec<f64>,
) -> Vec<f64> {
    let p = inverses.len();
    let mut s = vec![0.0; p * (p + 1) / 2];
    let mut carry = vec![0.0; p];
    buf.clear();
    buf.resize(2 * BLOCK * p, 0.0);
    let (diffs, v) = buf.split_at_mut(BLOCK * p);
    for w in bounds.windows(2) {
        let (start, len) = (w[0], w[1] - w[0]);
        carry.fill(0.0);
        // The rows t of v, in three runs where the same rows of x enter:
        // x_t alone (t ≤ L), x_t − x_{t−L−1}, then −x_{t−L−1} past the end.
        let runs = [
            (0, len.min(lags + 1), true, false),
            (lags + 1, len, true, true),
            (len.max(lags + 1), len + lags, false, true),
        ];
        for (run, &(from, to, add, sub)) in runs.iter().enumerate() {
            let mut a = from;
            while a < to {
                let rows = (to - a).min(BLOCK);
                for j in 0..p {
                    let col = &x[j * n + start..j * n + start + len];
                    let d = &mut diffs[j * BLOCK..j * BLOCK + rows];
                    match (add, sub) {
                        (true, false) => d.copy_from_slice(&col[a..a + rows]),
                        (true, true) => d
                            .iter_mut()
                            .zip(&col[a..a + rows])
                            .zip(&col[a - lags - 1..])
                            .for_each(|((d, &x), &old)| *d = x - old),
                        _ => d
                            .iter_mut()
                            .zip(&col[a - lags - 1..])
                            .for_each(|(d, &old)| *d = -old),
                    }
                    let out = &mut v[j * BLOCK..j * BLOCK + rows];
                    let total = prefix_sums(d, inverses[j], out);
                    let c = carry[j];
                    if c != 0.0 {
                        out.iter_mut().for_each(|v| *v += c);
                    }
                    carry[j] = c + total;
                }
                let mut k = 0;
                for i in 0..p {
                    let vi = &v[i * BLOCK..i * BLOCK + rows];
                    for j in 0..=i {
                        s[k] += dot(vi, &v[j * BLOCK..j * BLOCK + rows]);
                        k += 1;
                    }
                }
                a += rows;
            }
            // A segment no longer than L: v_{len−1} (the carry after the
            // first run) stands for L − len + 2 rows, counted once above.
            if run == 0 && len > 0 && len <= lags {
                let extra = (lags + 1 - len) as f64;
                let mut k = 0;
                for i in 0..p {
                    for j in 0..=i {
                        s[k] += extra * carry[i] * carry[j];
                        k += 1;
                    }
                }
            }
        }
    }
    s
}

/// Newey and West's (1994) automatic bandwidth for the Bartlett kernel:
/// with `h_t` the sum of the series' columns, each divided by its root sum
/// of squares, and `σ_j = Σ_t h_t h_{t−j}` within segments, `s⁽⁰⁾ = σ_0 +
/// 2 Σ_{j=1}^{m} σ_j`, `s⁽¹⁾ = 2 Σ_{j=1}^{m} j σ_j` with the pre-bandwidth
/// `m` = [`newey_west_lags`]`(rows)`, the bandwidth is
/// `⌊1.1447 (s⁽¹⁾ / s⁽⁰⁾)^(2/3) rows^(1/3)⌋`; `usize::MAX` (then capped)
/// when `s⁽⁰⁾ ≤ 0`. Columns scaled by `inverses` as in [`bartlett`]; `h` is
/// a buffer.
pub(super) fn automatic_lags(
    x: &[f64],
    n: usize,
    inverses: &[f64],
    bounds: &[usize],
    rows: usize,
    h: &mut Vec<f64>,
    sums: &mut (f64, f64),
) -> usize {
    let pre = newey_west_lags(rows);
    if pre == 0 {
        return 0;
    }
    h.clear();
    h.resize(n, 0.0);
    for (c, &inverse) in x.chunks_exact(n).zip(inverses) {
        let ss = sum_by(c, |v| (v * inverse) * (v * inverse));
        if ss > 0.0 {
            // Each column scaled to a root sum of squares of one: |h_t| ≤ p.
            let w = 1.0 / ss.sqrt();
            h.iter_mut()
                .zip(c)
                .for_each(|(h, v)| *h += (v * inverse) * w);
        }
    }
    // σ_j over blocks of t, every lag per block: the block and the `pre`
    // rows before it stay in the cache (one pass over h, not pre + 1).
    let mut sigma = vec![0.0; pre + 1];
    for w in bounds.windows(2) {
        let seg = &h[w[0]..w[1]];
        let mut a = 0;
        while a < seg.len() {
            let b = (a + BLOCK).min(seg.len());
            for (j, sj) in sigma.iter_mut().enumerate().take(b) {
                let lo = a.max(j);
                *sj += dot(&seg[lo..b], &seg[lo - j..b - j]);
            }
            a = b;
        }
    }
    let s0 = sigma[0] + 2.0 * sigma[1..].iter().sum::<f64>();
    let s1 = 2.0
        * sigma
            .iter()
            .enumerate()
            .map(|(j, s)| j as f64 * s)
            .sum::<f64>();
    *sums = (s0, s1);
    if s0 <= 0.0 {
        return usize::MAX;
    }
    let gamma = 1.1447 * (s1 / s0).abs().powf(2.0 / 3.0);
    let lags = (gamma * (rows as f64).cbrt()).floor();
    if lags.is_finite() && lags < usize::MAX as f64 {
        lags as usize
    } else {
        usize::MAX
    }
}
