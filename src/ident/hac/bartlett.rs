//! The Bartlett sum `Σ_t v_t v_tᵀ` of moving sums.

use super::running::{Step, running};
use super::view::{Direct, View, Windowed};
use super::{Scales, Scratch, Series, powers, rescale_lower};
use crate::kernels::reduce::{dot, max_abs};

/// Rows handled at a time: the block's columns stay in the cache between
/// the running sums and the products.
const BLOCK: usize = 2048;

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
    if let Some((x, n, stats)) = source.stored() {
        let mut view = Direct { x, n, start: 0 };
        let known = stats.map(|s| powers(&s.max));
        return sums(&mut view, p, bounds, lags, work, known);
    }
    // Room for a block and the L + 1 rows before it, and a block ahead.
    let cap = lags + 1 + 2 * BLOCK;
    let mut view = Windowed {
        source,
        window,
        p,
        cap,
    };
    sums(&mut view, p, bounds, lags, work, None)
}

/// [`bartlett`] through `view`, with the columns' powers of two `known`
/// or found on the way.
fn sums(
    view: &mut impl View,
    p: usize,
    bounds: &[usize],
    lags: usize,
    work: &mut Vec<f64>,
    known: Option<Scales>,
) -> (Vec<f64>, Vec<f64>) {
    let fixed = known.is_some();
    let mut scales = known.unwrap_or_else(|| Scales::new(p));
    let mut s = vec![0.0; p * (p + 1) / 2];
    let mut carry = vec![0.0; p];
    work.resize(BLOCK * p, 0.0);
    let v = &mut work[..BLOCK * p];
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
                if add && !fixed {
                    for (j, carry) in carry.iter_mut().enumerate() {
                        if let Some(f) = scales.raise(j, max_abs(view.col(j, a, a + rows))) {
                            *carry *= f;
                            rescale_lower(&mut s, p, j, f);
                        }
                    }
                }
                for (j, carry) in carry.iter_mut().enumerate() {
                    let step = match (add, sub) {
                        (true, false) => Step::Add(view.col(j, a, a + rows)),
                        (true, true) => Step::Replace(
                            view.col(j, a, a + rows),
                            view.col(j, a - lags - 1, a - lags - 1 + rows),
                        ),
                        _ => Step::Drop(view.col(j, a - lags - 1, a - lags - 1 + rows)),
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
