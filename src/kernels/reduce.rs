//! Vectorisable reductions over long columns.
//!
//! A plain `iter().sum()` over `f64` is one long chain of dependent adds
//! (the compiler may not reassociate floating point), about four cycles per
//! element. Eight independent accumulators let it use SIMD lanes; the result
//! differs from the sequential sum only by rounding (pairwise-like, usually
//! more accurate).

const LANES: usize = 8;

/// The accumulators of [`sum_by`] and [`dot`]: lane `2 j + l` of a chunk
/// goes to `[j][l]`. Written as pairs, because with a flat `[f64; 8]` the
/// compiler's SSE2 code paired lanes `i` and `i + 4` and shuffled every
/// load into place (two `unpck` per pair of loads; measured 5 % of the
/// lab's identification).
type Pairs = [[f64; 2]; LANES / 2];

/// The sum of the accumulators, pairwise.
#[inline(always)]
fn total(p: &Pairs) -> f64 {
    let s: [f64; 2] = std::array::from_fn(|l| (p[0][l] + p[1][l]) + (p[2][l] + p[3][l]));
    s[0] + s[1]
}

/// `Σ f(x)` with eight independent accumulators.
#[inline]
pub(crate) fn sum_by(x: &[f64], f: impl Fn(f64) -> f64) -> f64 {
    let mut acc: Pairs = [[0.0; 2]; LANES / 2];
    let chunks = x.chunks_exact(LANES);
    let rest = chunks.remainder();
    for c in chunks {
        for (j, p) in acc.iter_mut().enumerate() {
            for (l, v) in p.iter_mut().enumerate() {
                *v += f(c[2 * j + l]);
            }
        }
    }
    let mut tail = 0.0;
    for &v in rest {
        tail += f(v);
    }
    total(&acc) + tail
}

/// `Σ a[k] b[k]` over the shorter length, with eight independent
/// accumulators.
#[inline]
pub(crate) fn dot(a: &[f64], b: &[f64]) -> f64 {
    zip_sum(a, b, |a, b| a * b)
}

/// `Σ f(a[k], b[k])` over the shorter length, with eight independent
/// accumulators.
#[inline]
pub(crate) fn zip_sum(a: &[f64], b: &[f64], f: impl Fn(f64, f64) -> f64) -> f64 {
    let n = a.len().min(b.len());
    let (a, b) = (&a[..n], &b[..n]);
    let mut acc: Pairs = [[0.0; 2]; LANES / 2];
    let (ca, cb) = (a.chunks_exact(LANES), b.chunks_exact(LANES));
    let tail: f64 = ca
        .remainder()
        .iter()
        .zip(cb.remainder())
        .map(|(&a, &b)| f(a, b))
        .sum();
    for (a, b) in ca.zip(cb) {
        for (j, p) in acc.iter_mut().enumerate() {
            for (l, v) in p.iter_mut().enumerate() {
                *v += f(a[2 * j + l], b[2 * j + l]);
            }
        }
    }
    total(&acc) + tail
}

/// `max_k |(x[k+1] − x[k]) − step|` over consecutive pairs, with eight
/// independent lanes (the `if` form compiles to SIMD max). NaN differences
/// are ignored, so check finiteness separately.
#[inline]
pub(crate) fn max_step_deviation(x: &[f64], step: f64) -> f64 {
    if x.len() < 2 {
        return 0.0;
    }
    let (a, b) = (&x[..x.len() - 1], &x[1..]);
    let mut acc = [0.0f64; LANES];
    let (ca, cb) = (a.chunks_exact(LANES), b.chunks_exact(LANES));
    let (ra, rb) = (ca.remainder(), cb.remainder());
    for (pa, pb) in ca.zip(cb) {
        for i in 0..LANES {
            let d = (pb[i] - pa[i] - step).abs();
            acc[i] = if d > acc[i] { d } else { acc[i] };
        }
    }
    let mut worst = acc.iter().fold(0.0f64, |m, &v| m.max(v));
    for (va, vb) in ra.iter().zip(rb) {
        worst = worst.max((vb - va - step).abs());
    }
    worst
}

/// `max |x|` with eight independent lanes (0 for an empty slice). NaN
/// values are ignored, so check finiteness separately.
#[inline]
pub(crate) fn max_abs(x: &[f64]) -> f64 {
    let mut acc = [0.0f64; LANES];
    let chunks = x.chunks_exact(LANES);
    let rest = chunks.remainder();
    for c in chunks {
        for i in 0..LANES {
            let v = c[i].abs();
            acc[i] = if v > acc[i] { v } else { acc[i] };
        }
    }
    let worst = acc.iter().fold(0.0f64, |m, &v| m.max(v));
    rest.iter().fold(worst, |m, v| m.max(v.abs()))
}

/// [`max_abs`] of a slice whose entries are all finite, `None` otherwise,
/// in one pass: `x · 0` is 0 only for a finite `x`, and the test is an
/// integer "and" across lanes.
#[inline]
pub(crate) fn finite_max_abs(x: &[f64]) -> Option<f64> {
    let mut acc = [0.0f64; LANES];
    let mut finite = [true; LANES];
    let chunks = x.chunks_exact(LANES);
    let rest = chunks.remainder();
    for c in chunks {
        for i in 0..LANES {
            let v = c[i].abs();
            acc[i] = if v > acc[i] { v } else { acc[i] };
            finite[i] &= c[i] * 0.0 == 0.0;
        }
    }
    let worst = acc.iter().fold(0.0f64, |m, &v| m.max(v));
    let worst = rest.iter().fold(worst, |m, v| m.max(v.abs()));
    let finite = finite.iter().all(|&f| f) && rest.iter().all(|v| v.is_finite());
    finite.then_some(worst)
}

/// `(max |x|, Σ x²)` in one pass (eight lanes each): both finite only if
/// every entry is (a NaN is left out of the maximum, not of the sum).
#[inline]
pub(crate) fn max_ss(x: &[f64]) -> (f64, f64) {
    let mut acc = [0.0f64; LANES];
    let mut squares = [0.0f64; LANES];
    let chunks = x.chunks_exact(LANES);
    let rest = chunks.remainder();
    for c in chunks {
        for i in 0..LANES {
            let v = c[i].abs();
            acc[i] = if v > acc[i] { v } else { acc[i] };
            squares[i] += c[i] * c[i];
        }
    }
    let worst = acc.iter().fold(0.0f64, |m, &v| m.max(v));
    let worst = rest.iter().fold(worst, |m, v| m.max(v.abs()));
    let ss = squares.iter().sum::<f64>() + rest.iter().map(|v| v * v).sum::<f64>();
    (worst, ss)
}

/// [`zip_sum`]'s eight accumulators filled a value at a time, for a
/// kernel that makes the values itself: the value of position `k` of a
/// chunk of eight goes to lane `k`, the rows past the last whole chunk to
/// a tail summed in order, so that [`total`](Self::total) is `zip_sum`'s
/// result bit for bit.
#[derive(Debug, Clone, Copy)]
pub(crate) struct SumLanes {
    acc: Pairs,
    tail: f64,
}

impl SumLanes {
    pub fn new() -> Self {
        // `Sum`'s neutral element for the tail, as `zip_sum`'s `.sum()`.
        Self {
            acc: [[0.0; 2]; LANES / 2],
            tail: -0.0,
        }
    }

    /// Adds `v` at position `k < 8` of a whole chunk.
    #[inline(always)]
    pub fn add(&mut self, k: usize, v: f64) {
        self.acc[k / 2][k % 2] += v;
    }

    /// Adds `v`, a row past the last whole chunk (in order).
    #[inline(always)]
    pub fn add_tail(&mut self, v: f64) {
        self.tail += v;
    }

    pub fn total(&self) -> f64 {
        total(&self.acc) + self.tail
    }
}

/// [`max_ss`]'s lanes filled a value at a time (as [`SumLanes`]): the
/// same `(max |x|, Σ x²)` bit for bit.
#[derive(Debug, Clone, Copy)]
pub(crate) struct MaxSsLanes {
    top: [f64; LANES],
    squares: [f64; LANES],
    rest_top: f64,
    rest_squares: f64,
}

impl MaxSsLanes {
    pub fn new() -> Self {
        Self {
            top: [0.0; LANES],
            squares: [0.0; LANES],
            rest_top: 0.0,
            rest_squares: -0.0,
        }
    }

    /// Takes `v` at position `k < 8` of a whole chunk.
    #[inline(always)]
    pub fn add(&mut self, k: usize, v: f64) {
        let a = v.abs();
        self.top[k] = if a > self.top[k] { a } else { self.top[k] };
        self.squares[k] += v * v;
    }

    /// Takes `v`, a row past the last whole chunk (in order).
    #[inline(always)]
    pub fn add_tail(&mut self, v: f64) {
        self.rest_top = self.rest_top.max(v.abs());
        self.rest_squares += v * v;
    }

    /// `(max |x|, Σ x²)`.
    pub fn finish(&self) -> (f64, f64) {
        let worst = self.top.iter().fold(0.0f64, |m, &v| m.max(v));
        let squares = self.squares.iter().sum::<f64>();
        (worst.max(self.rest_top), squares + self.rest_squares)
    }
}

/// The power of two `s` with `s ≤ x < 2 s`, from the exponent bits of a
/// finite `x > 0` (no `log2`: cheap enough for inner loops); the smallest
/// normal number for a subnormal `x`, and 1 for `x = 0`. Dividing by it is
/// exact, so it equilibrates a vector or matrix (largest entry in [1, 2))
/// without changing any digit.
#[inline]
pub(crate) fn pow2_floor(x: f64) -> f64 {
    if x == 0.0 {
        return 1.0;
    }
    let s = f64::from_bits(x.abs().to_bits() & 0x7ff0_0000_0000_0000);
    if s == 0.0 { f64::MIN_POSITIVE } else { s }
}

/// `β / t` for a complex `t ≠ 0`, `t` first scaled by a power of two
/// (exactly) so that `|t|²` can neither overflow nor underflow: the
/// textbook `β conj(t) / |t|²`, num-complex's division too, squares `|t|`
/// and returned 0 for `|t| ≈ 1e160` (issue 28). Rounded as the unscaled
/// formula wherever that one is finite.
#[inline(always)]
pub(crate) fn real_over(beta: f64, tr: f64, ti: f64) -> (f64, f64) {
    let f = pow2_floor(tr.abs().max(ti.abs()));
    let (r, i) = (tr / f, ti / f);
    let size = r * r + i * i;
    ((beta * r / size) / f, (-(beta * i) / size) / f)
}

/// Index of the first non-finite value, if any. The fast path is one
/// vectorised pass (`0 · x` is NaN exactly for NaN and ±∞).
#[inline]
pub(crate) fn first_non_finite(x: &[f64]) -> Option<usize> {
    if sum_by(x, |v| v * 0.0) == 0.0 {
        None
    } else {
        x.iter().position(|v| !v.is_finite())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The lanes filled a value at a time are `zip_sum` and `max_ss`, bit
    /// for bit, at lengths around the chunks (a NaN left out of the
    /// maximum as there).
    #[test]
    fn lanes_filled_one_at_a_time_are_the_slice_reductions() {
        for len in [0, 1, 7, 8, 9, 15, 16, 17, 61, 1000] {
            let a: Vec<f64> = (0..len)
                .map(|i| ((i * 37) % 11) as f64 * 0.3 - 1.7)
                .collect();
            let c: Vec<f64> = (0..len)
                .map(|i| ((i * 13) % 17) as f64 * 1e-3 - 7e-3)
                .collect();
            let mut b = c.clone();
            if len > 9 {
                b[9] = f64::NAN;
            }
            let (mut sum, mut stats) = (SumLanes::new(), MaxSsLanes::new());
            let whole = len / LANES * LANES;
            for i in 0..len {
                let (v, w) = (a[i] * c[i], b[i] * 0.5);
                if i < whole {
                    sum.add(i % LANES, v);
                    stats.add(i % LANES, w);
                } else {
                    sum.add_tail(v);
                    stats.add_tail(w);
                }
            }
            let want = zip_sum(&a, &c, |x, y| x * y);
            assert_eq!(sum.total().to_bits(), want.to_bits(), "{len}");
            let half: Vec<f64> = b.iter().map(|v| v * 0.5).collect();
            let (m, s) = max_ss(&half);
            let (gm, gs) = stats.finish();
            assert_eq!(
                (gm.to_bits(), gs.to_bits()),
                (m.to_bits(), s.to_bits()),
                "{len}"
            );
        }
    }

    #[test]
    fn sums_and_finds_non_finite() {
        let x: Vec<f64> = (1..=21).map(f64::from).collect();
        assert_eq!(sum_by(&x, |v| v), 231.0);
        assert_eq!(sum_by(&x, |v| v * v), 3311.0);
        assert_eq!(first_non_finite(&x), None);
        assert_eq!(finite_max_abs(&x), Some(21.0));
        assert_eq!(max_ss(&x), (21.0, 3311.0));
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            let mut y = x.clone();
            y[13] = bad;
            assert_eq!(finite_max_abs(&y), None);
            let (max, ss) = max_ss(&y);
            assert!(!(max.is_finite() && ss.is_finite()));
            y[13] = 1.0;
            y[20] = bad;
            assert_eq!(finite_max_abs(&y), None);
            y[20] = 21.0;
            y[13] = bad;
            assert_eq!(first_non_finite(&y), Some(13));
        }
        assert_eq!(first_non_finite(&[]), None);
        assert_eq!(max_abs(&x), 21.0);
        assert_eq!(max_abs(&[-3.0, 2.0]), 3.0);
        assert_eq!(max_abs(&[]), 0.0);
        assert_eq!(pow2_floor(3.0), 2.0);
        assert_eq!(pow2_floor(-0.75), 0.5);
        assert_eq!(pow2_floor(f64::MAX), 2f64.powi(1023));
        assert_eq!(pow2_floor(1e-320), f64::MIN_POSITIVE);
        assert_eq!(pow2_floor(0.0), 1.0);
        let mut t: Vec<f64> = (0..21).map(|k| f64::from(k) * 0.5).collect();
        assert_eq!(max_step_deviation(&t, 0.5), 0.0);
        t[17] += 0.125; // intervals 16→17 and 17→18 are off by 0.125
        assert_eq!(max_step_deviation(&t, 0.5), 0.125);
        t[20] += 0.25; // in the remainder
        assert_eq!(max_step_deviation(&t, 0.5), 0.25);
    }
}
