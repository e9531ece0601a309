//! The Newey–West sums over a series handed out in blocks ([`Series`]):
//! stored (a fit's influence series) or computed again block by block from
//! the samples (the lab's two stages), so that no copy of a long series is
//! needed. Two passes at most: the automatic bandwidth's sums
//! ([`automatic_lags`]), then the Bartlett sum ([`bartlett`]).
//!
//! Each column is divided by a power of two near its largest entry, so
//! that no sum can overflow or underflow. The power is the largest seen so
//! far, and the sums so far are rescaled (exactly, by a power of two) when
//! a later block raises it: the sums are then those the final powers give,
//! bit for bit, without a pass to find them first.

use crate::kernels::reduce::{dot, max_abs, pow2_floor, sum_by};

/// A series of `p`-vectors, rows `0 … n`, handed out in blocks.
pub(crate) trait Series {
    /// Writes rows `from .. from + len`: column `j` to
    /// `out[j * stride..][..len]`.
    fn fill(&mut self, from: usize, len: usize, out: &mut [f64], stride: usize);

    /// The whole series, column-major, and its length, when it is stored:
    /// then it is read in place, not copied block by block.
    fn stored(&self) -> Option<(&[f64], usize)> {
        None
    }
}

/// A stored column-major series (`n` rows).
pub(crate) struct Stored<'a> {
    pub x: &'a [f64],
    pub n: usize,
}

impl Series for Stored<'_> {
    fn fill(&mut self, from: usize, len: usize, out: &mut [f64], stride: usize) {
        for (j, col) in self.x.chunks_exact(self.n).enumerate() {
            out[j * stride..j * stride + len].copy_from_slice(&col[from..from + len]);
        }
    }

    fn stored(&self) -> Option<(&[f64], usize)> {
        Some((self.x, self.n))
    }
}

/// How the passes see one segment of a series at a time: rows `from ..
/// to` of a column, made present first by [`ensure`](Self::ensure).
trait View {
    fn begin(&mut self, start: usize, len: usize);
    /// Makes rows `from .. to` of the segment present (`from` never less
    /// than an earlier call's, `to − from` at most the window's room).
    fn ensure(&mut self, from: usize, to: usize);
    fn col(&self, j: usize, from: usize, to: usize) -> &[f64];
}

/// A stored series, read in place.
struct Direct<'a> {
    x: &'a [f64],
    n: usize,
    start: usize,
}

impl View for Direct<'_> {
    fn begin(&mut self, start: usize, _len: usize) {
        self.start = start;
    }
    fn ensure(&mut self, _from: usize, _to: usize) {}
    fn col(&self, j: usize, from: usize, to: usize) -> &[f64] {
        let at = j * self.n + self.start;
        &self.x[at + from..at + to]
    }
}

/// A series handed out in blocks, through a [`Window`] of `cap` rows.
struct Windowed<'a, S> {
    source: &'a mut S,
    window: &'a mut Window,
    p: usize,
    cap: usize,
}

impl<S: Series> View for Windowed<'_, S> {
    fn begin(&mut self, start: usize, len: usize) {
        self.window.begin(self.p, self.cap, start, len);
    }
    fn ensure(&mut self, from: usize, to: usize) {
        self.window.ensure(self.source, from, to);
    }
    fn col(&self, j: usize, from: usize, to: usize) -> &[f64] {
        self.window.col(j, from, to)
    }
}

/// Rows handled at a time by the Bartlett sum: the block's columns stay in
/// the cache between the running sums and the products.
const BLOCK: usize = 2048;

/// Rows per block of the automatic bandwidth's sums: their running sums
/// start afresh every block, which bounds their rounding.
const SUB: usize = 512;

/// The buffers of the sums, kept between calls: all of a block's size,
/// none of the series'.
#[derive(Debug, Clone, Default)]
pub(crate) struct Scratch {
    window: Window,
    /// Differences, running sums and their products' operands.
    work: Vec<f64>,
}

/// Rows `lo .. hi` of one segment of a series, per column (`cap` rows
/// each), read ahead from the source as far as they fit.
#[derive(Debug, Clone, Default)]
struct Window {
    buf: Vec<f64>,
    p: usize,
    cap: usize,
    lo: usize,
    hi: usize,
    /// The segment: its first row in the series, and its length.
    start: usize,
    len: usize,
}

impl Window {
    fn begin(&mut self, p: usize, cap: usize, start: usize, len: usize) {
        self.buf.resize(p * cap, 0.0);
        (self.p, self.cap, self.start, self.len) = (p, cap, start, len);
        (self.lo, self.hi) = (0, 0);
    }

    /// Makes rows `from .. to` of the segment present (`from` never less
    /// than an earlier call's, `to − from ≤ cap`).
    fn ensure(&mut self, source: &mut impl Series, from: usize, to: usize) {
        debug_assert!(from >= self.lo && to <= self.len && to - from <= self.cap);
        if to <= self.hi {
            return;
        }
        if to > self.lo + self.cap {
            let keep = from.min(self.hi);
            for j in 0..self.p {
                let at = j * self.cap;
                self.buf
                    .copy_within(at + keep - self.lo..at + self.hi - self.lo, at);
            }
            self.lo = keep;
        }
        let end = self.len.min(self.lo + self.cap);
        let offset = self.hi - self.lo;
        source.fill(
            self.start + self.hi,
            end - self.hi,
            &mut self.buf[offset..],
            self.cap,
        );
        self.hi = end;
    }

    /// Rows `from .. to` of column `j`.
    fn col(&self, j: usize, from: usize, to: usize) -> &[f64] {
        &self.buf[j * self.cap + from - self.lo..j * self.cap + to - self.lo]
    }
}

/// The power of two each column is divided by, and its inverse: the
/// largest seen so far.
struct Scales {
    scale: Vec<f64>,
    inverse: Vec<f64>,
}

impl Scales {
    fn new(p: usize) -> Self {
        Self {
            scale: vec![0.0; p],
            inverse: vec![1.0; p],
        }
    }

    /// Raises column `j`'s power to cover `largest` (a block's largest
    /// magnitude); returns the factor (a power of two ≤ 1) the sums so far
    /// in that column must be multiplied by, or `None` when unchanged.
    fn raise(&mut self, j: usize, largest: f64) -> Option<f64> {
        if largest == 0.0 {
            return None;
        }
        let s = pow2_floor(largest);
        if s <= self.scale[j] {
            return None;
        }
        let factor = if self.scale[j] == 0.0 {
            1.0
        } else {
            self.scale[j] / s
        };
        self.scale[j] = s;
        self.inverse[j] = 1.0 / s;
        Some(factor)
    }

    /// The final powers (1 for a column of zeros, as `pow2_floor(0)`).
    fn last(&self) -> Vec<f64> {
        self.scale
            .iter()
            .map(|&s| if s == 0.0 { 1.0 } else { s })
            .collect()
    }
}

/// `x` (`p × p`, row-major) with row and column `j` times `factor`.
fn rescale_square(x: &mut [f64], p: usize, j: usize, factor: f64) {
    for i in 0..p {
        x[i * p + j] *= factor;
        x[j * p + i] *= factor;
    }
}

/// `s` (the lower triangle, row by row) with row and column `j` times
/// `factor`.
fn rescale_lower(s: &mut [f64], p: usize, j: usize, factor: f64) {
    let mut k = 0;
    for i in 0..p {
        for l in 0..=i {
            if i == j {
                s[k] *= factor;
            }
            if l == j {
                s[k] *= factor;
            }
            k += 1;
        }
    }
}

/// Newey and West's (1994) automatic bandwidth for the Bartlett kernel
/// over the `p` columns of `source` (`bounds`: `[0, segment starts…, n]`),
/// with `pre` the pre-bandwidth ([`newey_west_lags`](super::newey_west_lags)
/// of the rows fitted) and `rows` the rows fitted: `⌊1.1447 (s⁽¹⁾ /
/// s⁽⁰⁾)^(2/3) rows^(1/3)⌋`, `usize::MAX` when `s⁽⁰⁾ ≤ 0`; see
/// [`Covariance::NeweyWest`](super::Covariance::NeweyWest).
///
/// With `h_t = Σ_j c_j x_tj` (`c_j` one over column `j`'s root sum of
/// squares) and `σ_k = Σ_t h_t h_{t−k}` within segments, `s⁽⁰⁾ = σ₀ + 2
/// Σ_{k=1}^{pre} σ_k` and `s⁽¹⁾ = 2 Σ_k k σ_k`. Neither needs the lags one
/// by one: `s⁽⁰⁾ = Σ_t h_t (2 W_t − h_t)` and `s⁽¹⁾ = 2 Σ_t h_t V_t` with the
/// moving sums `W_t = Σ_{k=0}^{pre} h_{t−k}`, `V_t = Σ_{k=1}^{pre} k
/// h_{t−k}`, both differences of running sums. And `c`, which needs a pass
/// of its own, enters only at the end: `s⁽⁰⁾ = cᵀ X₀ c`, `s⁽¹⁾ = 2 cᵀ X₁ c`
/// with `X₀ = Σ_t x_t (2 W_t − x_t)ᵀ` and `X₁ = Σ_t x_t V_tᵀ` of the
/// columns' own moving sums. One pass, `O(rows · p²)` whatever `pre`.
pub(crate) fn automatic_lags(
    source: &mut impl Series,
    p: usize,
    bounds: &[usize],
    pre: usize,
    rows: usize,
    scratch: &mut Scratch,
) -> usize {
    if pre == 0 {
        return 0;
    }
    let (s0, s1) = bandwidth_sums(source, p, bounds, pre, scratch);
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

/// `(s⁽⁰⁾, s⁽¹⁾)` of [`automatic_lags`] (`pre ≥ 1`).
fn bandwidth_sums(
    source: &mut impl Series,
    p: usize,
    bounds: &[usize],
    pre: usize,
    scratch: &mut Scratch,
) -> (f64, f64) {
    let Scratch { window, work } = scratch;
    if let Some((x, n)) = source.stored() {
        let mut view = Direct { x, n, start: 0 };
        return moving_sums(&mut view, p, bounds, pre, work);
    }
    let cap = pre + 1 + 2 * SUB;
    let mut view = Windowed {
        source,
        window,
        p,
        cap,
    };
    moving_sums(&mut view, p, bounds, pre, work)
}

/// [`bandwidth_sums`] through `view`.
fn moving_sums(
    view: &mut impl View,
    p: usize,
    bounds: &[usize],
    pre: usize,
    work: &mut Vec<f64>,
) -> (f64, f64) {
    let mut scales = Scales::new(p);
    let mut ss = vec![0.0; p];
    let mut x0 = vec![0.0; p * p];
    let mut x1 = vec![0.0; p * p];
    // Per column: the block's rows with `pre + 1` before them (y), their
    // running sums (P, then Q of P, one longer), and per row of the block
    // 2 W − y and V.
    let ny = pre + 1 + SUB;
    let (zat, vat) = (3 * (ny + 1), 3 * (ny + 1) + SUB);
    let stride = vat + SUB;
    work.clear();
    work.resize(p * stride, 0.0);
    for w in bounds.windows(2) {
        let (start, len) = (w[0], w[1] - w[0]);
        view.begin(start, len);
        let mut a = 0;
        while a < len {
            let b = (a + SUB).min(len);
            let from = a.saturating_sub(pre + 1);
            let pad = (pre + 1).saturating_sub(a);
            view.ensure(from, b);
            for (j, ss) in ss.iter_mut().enumerate() {
                if let Some(f) = scales.raise(j, max_abs(view.col(j, a, b))) {
                    *ss *= f * f;
                    rescale_square(&mut x0, p, j, f);
                    rescale_square(&mut x1, p, j, f);
                }
            }
            let n = pad + (b - from);
            let rows_here = b - a;
            for j in 0..p {
                let col = &mut work[j * stride..(j + 1) * stride];
                let (y, rest) = col.split_at_mut(ny + 1);
                let (pp, rest) = rest.split_at_mut(ny + 1);
                let (q, rest) = rest.split_at_mut(ny + 1);
                let (zv, vv) = rest.split_at_mut(SUB);
                y[..pad].fill(0.0);
                y[pad..n].copy_from_slice(view.col(j, from, b));
                // pp[i] = Σ_{r<i} y_r / scale, q[i] = Σ_{r<i} pp[r].
                pp[0] = 0.0;
                prefix_sums(&y[..n], scales.inverse[j], &mut pp[1..=n]);
                q[0] = 0.0;
                prefix_sums(&pp[..n], 1.0, &mut q[1..=n]);
                for r in 0..rows_here {
                    let i = pre + 1 + r;
                    let yi = y[i] * scales.inverse[j];
                    let w = pp[i + 1] - pp[i - pre];
                    zv[r] = 2.0 * w - yi;
                    vv[r] = (q[i + 1] - q[i + 1 - pre]) - pre as f64 * pp[i - pre];
                    // The block's own rows, scaled, moved to the front for
                    // the products (row i > r is read after row r is set).
                    y[r] = yi;
                }
            }
            // Products: x_i with (2W − x)_j and V_j, each over the block.
            for i in 0..p {
                let yi = &work[i * stride..i * stride + rows_here];
                ss[i] += sum_by(yi, |v| v * v);
                for j in 0..p {
                    let col = &work[j * stride..(j + 1) * stride];
                    let (z, v) = (&col[zat..zat + rows_here], &col[vat..vat + rows_here]);
                    x0[i * p + j] += dot(yi, z);
                    x1[i * p + j] += dot(yi, v);
                }
            }
            a = b;
        }
    }
    let c: Vec<f64> = ss
        .iter()
        .map(|&s| if s > 0.0 { 1.0 / s.sqrt() } else { 0.0 })
        .collect();
    let form = |x: &[f64]| -> f64 {
        let mut s = 0.0;
        for i in 0..p {
            for j in 0..p {
                s += c[i] * c[j] * x[i * p + j];
            }
        }
        s
    };
    (form(&x0), 2.0 * form(&x1))
}

/// `Σ_t v_t v_tᵀ` over every segment of the `p` columns of `source`
/// (`bounds`: `[0, segment starts…, n]`), with `v_t` the sum of the rows
/// `t − L … t` of the segment (zero outside it), `t` running to `L` rows
/// past its end: `(L + 1) (Γ₀ + Σ_{l=1}^{L} w_l (Γ_l + Γ_lᵀ))` with the
/// Bartlett weights, exactly. Returns the lower triangle, row by row, of
/// the columns divided by the returned powers of two.
///
/// `v` is formed [`BLOCK`] rows at a time as the running sum of `x_t −
/// x_{t−L−1}` (carried from block to block), and each block's products are
/// summed before the next. A segment of `len ≤ L` rows has `v_t =
/// v_{len−1}` for every `t` from `len − 1` to `L`: that row is counted
/// once, with its weight.
pub(crate) fn bartlett(
    source: &mut impl Series,
    p: usize,
    bounds: &[usize],
    lags: usize,
    scratch: &mut Scratch,
) -> (Vec<f64>, Vec<f64>) {
    let Scratch { window, work } = scratch;
    if let Some((x, n)) = source.stored() {
        let mut view = Direct { x, n, start: 0 };
        return bartlett_sums(&mut view, p, bounds, lags, work);
    }
    // Room for a block and the L + 1 rows before it, and a block ahead.
    let cap = lags + 1 + 2 * BLOCK;
    let mut view = Windowed {
        source,
        window,
        p,
        cap,
    };
    bartlett_sums(&mut view, p, bounds, lags, work)
}

/// [`bartlett`] through `view`.
fn bartlett_sums(
    view: &mut impl View,
    p: usize,
    bounds: &[usize],
    lags: usize,
    work: &mut Vec<f64>,
) -> (Vec<f64>, Vec<f64>) {
    let mut scales = Scales::new(p);
    let mut s = vec![0.0; p * (p + 1) / 2];
    let mut carry = vec![0.0; p];
    work.clear();
    work.resize(2 * BLOCK * p, 0.0);
    let (diffs, v) = work.split_at_mut(BLOCK * p);
    for w in bounds.windows(2) {
        let (start, len) = (w[0], w[1] - w[0]);
        view.begin(start, len);
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
                let first = if sub { a - lags - 1 } else { a };
                let last = if add { a + rows } else { a - lags - 1 + rows };
                view.ensure(first, last);
                if add {
                    for (j, carry) in carry.iter_mut().enumerate() {
                        if let Some(f) = scales.raise(j, max_abs(view.col(j, a, a + rows))) {
                            *carry *= f;
                            rescale_lower(&mut s, p, j, f);
                        }
                    }
                }
                for j in 0..p {
                    let d = &mut diffs[j * BLOCK..j * BLOCK + rows];
                    match (add, sub) {
                        (true, false) => d.copy_from_slice(view.col(j, a, a + rows)),
                        (true, true) => d
                            .iter_mut()
                            .zip(view.col(j, a, a + rows))
                            .zip(view.col(j, a - lags - 1, a - lags - 1 + rows))
                            .for_each(|((d, &x), &old)| *d = x - old),
                        _ => d
                            .iter_mut()
                            .zip(view.col(j, a - lags - 1, a - lags - 1 + rows))
                            .for_each(|(d, &old)| *d = -old),
                    }
                    let out = &mut v[j * BLOCK..j * BLOCK + rows];
                    let total = prefix_sums(d, scales.inverse[j], out);
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
    (s, scales.last())
}

/// The running sums `out[k] = Σ_{i ≤ k} x[i] · scale` (`out` as long as
/// `x`), returning the total. Four blocks are summed as four interleaved
/// chains, then each block is offset by the totals before it: one chain of
/// dependent adds would cost about four cycles per element.
pub(crate) fn prefix_sums(x: &[f64], scale: f64, out: &mut [f64]) -> f64 {
    const CHAINS: usize = 4;
    let block = x.len() / CHAINS;
    let (head, rest) = x.split_at(CHAINS * block);
    let (out_head, out_rest) = out.split_at_mut(CHAINS * block);
    let mut sums = [0.0; CHAINS];
    let mut chunks = out_head.chunks_exact_mut(block.max(1));
    let mut outs: [&mut [f64]; CHAINS] = std::array::from_fn(|_| chunks.next().unwrap_or_default());
    for i in 0..block {
        for c in 0..CHAINS {
            sums[c] += head[c * block + i] * scale;
            outs[c][i] = sums[c];
        }
    }
    let mut offset = 0.0;
    for (c, out) in outs.iter_mut().enumerate() {
        if c > 0 {
            out.iter_mut().for_each(|v| *v += offset);
        }
        offset += sums[c];
    }
    for (v, &x) in out_rest.iter_mut().zip(rest) {
        offset += x * scale;
        *v = offset;
    }
    offset
}

#[cfg(test)]
mod reference;
#[cfg(test)]
mod tests;
