//! The scans behind [`step_info`](super::step_info): one fused pass for the
//! extremes and the last sample outside the settling band, and early-exit
//! searches that test eight samples at a time. Eight lanes with a
//! branch-free test per block let the compiler vectorise what a
//! sample-by-sample `position` cannot (it exits per sample).

/// Samples per block.
const LANES: usize = 8;

/// The first `i` in `from..y.len()` with `pred(y[i])`.
#[inline]
pub(super) fn first_where(y: &[f64], from: usize, pred: impl Fn(f64) -> bool) -> Option<usize> {
    let tail = y.get(from..)?;
    let mut blocks = tail.chunks_exact(LANES);
    for (b, block) in blocks.by_ref().enumerate() {
        if block.iter().fold(false, |any, &v| any | pred(v)) {
            let i = block.iter().position(|&v| pred(v))?;
            return Some(from + b * LANES + i);
        }
    }
    let rest = blocks.remainder();
    let i = rest.iter().position(|&v| pred(v))?;
    Some(y.len() - rest.len() + i)
}

/// The last `i < y.len()` with `pred(y[i])`.
#[inline]
pub(super) fn last_where(y: &[f64], pred: impl Fn(f64) -> bool) -> Option<usize> {
    let mut blocks = y.rchunks_exact(LANES);
    for (b, block) in blocks.by_ref().enumerate() {
        if block.iter().fold(false, |any, &v| any | pred(v)) {
            let i = block.iter().rposition(|&v| pred(v))?;
            return Some(y.len() - (b + 1) * LANES + i);
        }
    }
    blocks.remainder().iter().rposition(|&v| pred(v))
}

/// What [`sweep`] finds.
#[derive(Debug, Clone, Copy)]
pub(super) struct Sweep {
    /// Extremes of all samples.
    pub min: f64,
    pub max: f64,
    /// Extremes of the samples from `from` on (±∞ when there are none).
    pub tail_min: f64,
    pub tail_max: f64,
    /// The last sample with `|y − yf| > band`.
    pub last_outside: Option<usize>,
}

/// One pass over finite `y`: its extremes, those of `y[from..]`, and the
/// last sample outside `band` about `yf`.
pub(super) fn sweep(y: &[f64], from: usize, yf: f64, band: f64) -> Sweep {
    let from = from.min(y.len());
    let (head, tail) = y.split_at(from);
    let (head_min, head_max, head_out) = extremes_and_outside(head, yf, band);
    let (tail_min, tail_max, tail_out) = extremes_and_outside(tail, yf, band);
    Sweep {
        min: head_min.min(tail_min),
        max: head_max.max(tail_max),
        tail_min,
        tail_max,
        last_outside: tail_out.map(|i| from + i).or(head_out),
    }
}

/// Extremes of `y` and its last sample with `|y − yf| > band`, in one pass:
/// per lane minima and maxima, and per block only whether any sample is
/// outside; the sample itself is found in the last such block afterwards.
fn extremes_and_outside(y: &[f64], yf: f64, band: f64) -> (f64, f64, Option<usize>) {
    let mut lo = [f64::INFINITY; LANES];
    let mut hi = [f64::NEG_INFINITY; LANES];
    let mut last_block = None;
    let mut blocks = y.chunks_exact(LANES);
    for (b, block) in blocks.by_ref().enumerate() {
        let mut outside = false;
        // Plain selects, not `f64::min`: the samples are finite, and its
        // NaN handling doubles the loop's work.
        for ((l, h), &v) in lo.iter_mut().zip(hi.iter_mut()).zip(block) {
            *l = if v < *l { v } else { *l };
            *h = if v > *h { v } else { *h };
            outside |= (v - yf).abs() > band;
        }
        if outside {
            last_block = Some(b);
        }
    }
    let rest = blocks.remainder();
    let mut min = lo.iter().fold(f64::INFINITY, |m, &v| m.min(v));
    let mut max = hi.iter().fold(f64::NEG_INFINITY, |m, &v| m.max(v));
    for &v in rest {
        min = min.min(v);
        max = max.max(v);
    }
    let is_outside = |v: f64| (v - yf).abs() > band;
    let last = match rest.iter().rposition(|&v| is_outside(v)) {
        Some(i) => Some(y.len() - rest.len() + i),
        None => last_block.and_then(|b| {
            let block = &y[b * LANES..(b + 1) * LANES];
            block
                .iter()
                .rposition(|&v| is_outside(v))
                .map(|i| b * LANES + i)
        }),
    };
    (min, max, last)
}

/// Whether all of `t` and `y` (equal lengths) are finite and `t` strictly
/// increases, in one branch-free pass.
#[allow(clippy::eq_op)] // `x − x` is the finiteness test, on purpose.
pub(super) fn all_valid(t: &[f64], y: &[f64]) -> bool {
    let Some((&t0, later)) = t.split_first() else {
        return true;
    };
    let y_later = y.get(1..).unwrap_or_default();
    t0.is_finite()
        && y.first().is_none_or(|v| v.is_finite())
        && t.iter()
            .zip(later)
            .zip(y_later)
            // `b − b + v − v` is 0 exactly when both are finite (else NaN):
            // two operations where `is_finite` takes four each.
            .fold(true, |ok, ((&a, &b), &v)| {
                ok & ((b - b) + (v - v) == 0.0) & (b > a)
            })
}

/// The means of `w` (at least 2 samples), of its first `half` samples and
/// of its last `half`, each bit for bit as `step_info`'s `mean` of
/// that slice, in one pass: the whole sum passes through the first half's
/// (a left fold from the same start), and the last half's runs alongside.
pub(super) fn window_means(w: &[f64], half: usize) -> [f64; 3] {
    // The start value of `Iterator::sum` (−0 or +0, by Rust version).
    let zero: f64 = std::iter::empty::<f64>().sum();
    let (first, rest) = w.split_at(half);
    let (middle, last) = rest.split_at(rest.len() - half);
    let s_first = first.iter().fold(zero, |a, &v| a + v);
    let s_middle = middle.iter().fold(s_first, |a, &v| a + v);
    let (s_all, s_last) = last
        .iter()
        .fold((s_middle, zero), |(a, b), &v| (a + v, b + v));
    let finish = |sum: f64, s: &[f64]| {
        let n = s.len() as f64;
        if sum.is_finite() {
            sum / n
        } else {
            s.iter().map(|v| v / n).sum()
        }
    };
    [
        finish(s_all, w),
        finish(s_first, first),
        finish(s_last, last),
    ]
}
