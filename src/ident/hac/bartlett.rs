//! The Bartlett sum `Σ_t v_t v_tᵀ` of moving sums.

use super::running::{Step, running};
use super::{Scales, Scratch, Series, powers, rescale_lower};
use crate::kernels::reduce::{dot, max_abs};

/// Rows handled at a time: the block's columns stay in the cache between
/// the running sums and the products.
const BLOCK: usize = 2048;

/// `Σ_t v_t v_tᵀ` over every segment of the `p` columns of `x`
/// (`bounds`: `[0, segment starts…, n]`), with `v_t` the sum of the rows
/// `t − L … t` of the segment (zero outside it), `t` running to `L` rows
/// past its end: `(L + 1) (Γ₀ + Σ_{l=1}^{L} w_l (Γ_l + Γ_lᵀ))` with the
/// Bartlett weights, exactly. Returns the lower triangle, row by row, of
/// the columns divided by the returned powers of two.
///
/// `v` is formed [`BLOCK`] rows at a time as the running sum of `x_t −
/// x_{t−L−1}` (carried from block to block), and each block's products are
/// summed before the next. The columns' powers of two come from the
/// series' stats when known, else are found on the way. A segment of `len ≤ L` rows has `v_t =
/// v_{len−1}` for every `t` from `len − 1` to `L`: that row is counted
/// once, with its weight.
pub(crate) fn bartlett(
    x: Series<'_>,
    p: usize,
    bounds: &[usize],
    lags: usize,
    scratch: &mut Scratch,
) -> (Vec<f64>, Vec<f64>) {
    let work = &mut scratch.work;
    let known = x.stats.map(|s| powers(&s.max));
    let fixed = known.is_some();
    let mut scales = known.unwrap_or_else(|| Scales::new(p));
    let mut s = vec![0.0; p * (p + 1) / 2];
    let mut carry = vec![0.0; p];
    work.resize(BLOCK * p, 0.0);
    let v = &mut work[..BLOCK * p];
    for w in bounds.windows(2) {
        let (start, len) = (w[0], w[1] - w[0]);
        // Rows `from .. to` of the segment's column `j`.
        let col = |j: usize, from: usize, to: usize| x.col(j, start + from, start + to);
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
                if add && !fixed {
                    for (j, carry) in carry.iter_mut().enumerate() {
                        if let Some(f) = scales.raise(j, max_abs(col(j, a, a + rows))) {
                            *carry *= f;
                            rescale_lower(&mut s, p, j, f);
                        }
                    }
                }
                for (j, carry) in carry.iter_mut().enumerate() {
                    let step = match (add, sub) {
                        (true, false) => Step::Add(col(j, a, a + rows)),
                        (true, true) => Step::Replace(
                            col(j, a, a + rows),
                            col(j, a - lags - 1, a - lags - 1 + rows),
                        ),
                        _ => Step::Drop(col(j, a - lags - 1, a - lags - 1 + rows)),
                    };
                    let out = &mut v[j * BLOCK..j * BLOCK + rows];
                    *carry = running(step, scales.inverse[j], *carry, out);
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
