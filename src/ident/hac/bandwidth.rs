//! Newey and West's (1994) automatic bandwidth for the Bartlett kernel.

use super::running::prefix_sums;
use super::{Scratch, Series};
use crate::kernels::reduce::{SumLanes, max_abs, pow2_floor, sum_by};

/// The lanes of [`SumLanes`].
const LANES: usize = 8;

/// Rows per block: the running sums start afresh every block, which bounds
/// their rounding.
const SUB: usize = 512;

/// Newey and West's (1994) automatic bandwidth for the Bartlett kernel
/// over the columns of `x` (`bounds`: `[0, segment starts…, n]`),
/// with `pre` the pre-bandwidth ([`newey_west_lags`](crate::ident::newey_west_lags)
/// of the rows fitted) and `rows` the rows fitted: `⌊1.1447 (s⁽¹⁾ /
/// s⁽⁰⁾)^(2/3) rows^(1/3)⌋`, `usize::MAX` when `s⁽⁰⁾ ≤ 0`; see
/// [`Covariance::NeweyWest`](crate::ident::Covariance::NeweyWest).
///
/// With `h_t = Σ_j c_j x_tj` (`c_j` one over column `j`'s root sum of
/// squares) and `σ_k = Σ_t h_t h_{t−k}` within segments, `s⁽⁰⁾ = σ₀ + 2
/// Σ_{k=1}^{pre} σ_k` and `s⁽¹⁾ = 2 Σ_k k σ_k`. Neither needs the lags one
/// by one: the Bartlett sums `B(L) = Σ_t W_t(L)²` of the moving sums
/// `W_t(L) = Σ_{k=0}^{L} h_{t−k}` are `Σ_{|k|≤L} (L + 1 − |k|) σ_k` (as in
/// [`bartlett`](super::bartlett)), so `s⁽⁰⁾ = B(pre) − B(pre − 1)` and
/// `s⁽¹⁾ = (pre + 1) s⁽⁰⁾ − B(pre)`: one running sum and two differences
/// of it a row, `O(rows)` whatever `pre`, where the lags one by one cost
/// `O(rows · pre)` (measured: the two sums within 1e-14 of `σ₀` of the
/// lag-by-lag ones).
/// `c` comes from the series' [`Stats`](super::Stats) when known, else
/// from a pass over its columns; `h` is formed a block at a time.
pub(crate) fn automatic_lags(
    x: Series<'_>,
    bounds: &[usize],
    pre: usize,
    rows: usize,
    scratch: &mut Scratch,
) -> usize {
    if pre == 0 {
        return 0;
    }
    let (s0, s1) = bandwidth_sums(x, bounds, pre, scratch);
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

/// The moving sums of one block: its rows of `h` with the `pre + 1`
/// before them (`y`, zeros outside the segment) and their running sum
/// (`pp`, one longer).
struct Windows<'w> {
    y: &'w mut [f64],
    pp: &'w mut [f64],
}

/// The room [`Windows`] needs.
fn room(pre: usize) -> usize {
    2 * (pre + 2 + SUB)
}

impl<'w> Windows<'w> {
    fn split(col: &'w mut [f64], pre: usize) -> Self {
        let (y, pp) = col.split_at_mut(pre + 2 + SUB);
        Self { y, pp }
    }

    /// With `y[..rows + pre + 1]` set (rows `a − pre − 1 … a + rows`):
    /// `Σ W(pre)²` and `Σ W(pre − 1)²` over the block's `rows` rows, each
    /// summed in the lanes of [`sum_by`] (the same sums, bit for bit, as
    /// the two windows stored and summed).
    fn sums(&mut self, rows: usize, pre: usize) -> (f64, f64) {
        let n = rows + pre + 1;
        self.pp[0] = 0.0;
        prefix_sums(&self.y[..n], 1.0, &mut self.pp[1..=n]);
        // Row i of the block is y's row i + pre + 1: W(pre) = pp[i + pre +
        // 2] − pp[i + 1], W(pre − 1) = pp[i + pre + 2] − pp[i + 2].
        let (at, back1, back2) = (
            &self.pp[pre + 2..=n],
            &self.pp[1..=rows],
            &self.pp[2..rows + 2],
        );
        let (mut s1, mut s2) = (SumLanes::new(), SumLanes::new());
        let whole = rows / LANES * LANES;
        for c in (0..whole).step_by(LANES) {
            let (at, b1, b2) = (
                &at[c..c + LANES],
                &back1[c..c + LANES],
                &back2[c..c + LANES],
            );
            for k in 0..LANES {
                let (w1, w2) = (at[k] - b1[k], at[k] - b2[k]);
                s1.add(k, w1 * w1);
                s2.add(k, w2 * w2);
            }
        }
        for i in whole..rows {
            let (w1, w2) = (at[i] - back1[i], at[i] - back2[i]);
            s1.add_tail(w1 * w1);
            s2.add_tail(w2 * w2);
        }
        (s1.total(), s2.total())
    }
}

/// `(s⁽⁰⁾, s⁽¹⁾)` from `B(pre)` and `B(pre − 1)`.
fn from_windows(b1: f64, b2: f64, pre: usize) -> (f64, f64) {
    let s0 = b1 - b2;
    (s0, (pre + 1) as f64 * s0 - b1)
}

/// `(s⁽⁰⁾, s⁽¹⁾)` of [`automatic_lags`] (`pre ≥ 1`): `h` a block at a time
/// with the `pre + 1` rows before it.
pub(super) fn bandwidth_sums(
    series: Series<'_>,
    bounds: &[usize],
    pre: usize,
    scratch: &mut Scratch,
) -> (f64, f64) {
    let Series { x, n, .. } = series;
    let work = &mut scratch.work;
    let c = weights(series);
    let stride = room(pre);
    work.resize(stride, 0.0);
    let mut m = Windows::split(&mut work[..stride], pre);
    let (mut b1, mut b2) = (0.0, 0.0);
    for w in bounds.windows(2) {
        let (start, len) = (w[0], w[1] - w[0]);
        // t runs to pre rows past the end, where only earlier rows enter.
        let mut a = 0;
        while a < len + pre {
            let b = (a + SUB).min(len + pre);
            let rows = b - a;
            let y = &mut m.y[..rows + pre + 1];
            // y's row k is the segment's row a − pre − 1 + k: zero outside
            // the segment, else `0 + Σ c_j x_j` (columns with c_j = 0
            // left out), added a column at a time.
            let (lo, hi) = (a.saturating_sub(pre + 1), b.min(len));
            let (head, rest) = y.split_at_mut((lo + pre + 1).saturating_sub(a).min(y.len()));
            head.fill(0.0);
            let (h, tail) = rest.split_at_mut(hi.saturating_sub(lo).min(rest.len()));
            tail.fill(0.0);
            let mut first = true;
            for (col, &c) in x.chunks_exact(n).zip(&c) {
                if c != 0.0 && !h.is_empty() {
                    let col = &col[start + lo..start + hi];
                    if first {
                        h.iter_mut().zip(col).for_each(|(h, &v)| *h = 0.0 + c * v);
                    } else {
                        h.iter_mut().zip(col).for_each(|(h, &v)| *h += c * v);
                    }
                    first = false;
                }
            }
            if first {
                h.fill(0.0);
            }
            let (w1, w2) = m.sums(rows, pre);
            b1 += w1;
            b2 += w2;
            a = b;
        }
    }
    from_windows(b1, b2, pre)
}

/// One over each column's root sum of squares (0 for a column of zeros):
/// from `stats` when they are known and their sums neither overflowed nor
/// fell below the normal range, else from the columns, each divided first
/// by its power of two.
fn weights(Series { x, n, stats }: Series<'_>) -> Vec<f64> {
    let known = stats.filter(|s| {
        s.ss.iter()
            .all(|&v| v == 0.0 || (v.is_finite() && v >= f64::MIN_POSITIVE))
    });
    match known {
        Some(s) => {
            s.ss.iter()
                .map(|&v| if v > 0.0 { 1.0 / v.sqrt() } else { 0.0 })
                .collect()
        }
        None => x
            .chunks_exact(n)
            .map(|col| {
                let inverse = 1.0 / pow2_floor(max_abs(col));
                let ss = sum_by(col, |v| (v * inverse) * (v * inverse));
                if ss > 0.0 { inverse / ss.sqrt() } else { 0.0 }
            })
            .collect(),
    }
}
