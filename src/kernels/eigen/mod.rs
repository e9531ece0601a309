//! Eigenvalues of small dense matrices (up to [`SMALL`] rows) on the stack:
//! balancing (isolated eigenvalues permuted out, the rest scaled by powers
//! of two, as LAPACK's `dgebal`), reduction to Hessenberg form by stabilised
//! elimination, and the Francis double-shift QR iteration (EISPACK's
//! `balanc`, `elmhes` and `hqr`, as in *Numerical Recipes*, §11.5–11.6).
//!
//! Why not nalgebra's `Schur`: at the lab's four states it is general code
//! with a heap copy, a `hypot` per rotation and the Schur vectors it does
//! not need, and it took two thirds of `acker` (whose closed-loop pole
//! check calls it) and a third of `dlqr`. This kernel does only what the
//! eigenvalues need, on a fixed array. It gives up (`false`) rather than
//! guess, after [`ITERATIONS`] QR sweeps for one eigenvalue or on any
//! non-finite entry or result, and the caller then falls back to
//! nalgebra's and faer's iterations.

use nalgebra::Complex;

/// The largest matrix this kernel takes.
pub(crate) const SMALL: usize = 8;

/// QR sweeps allowed per eigenvalue, with an exceptional shift every 10
/// (EISPACK stops at 30, after shifts at 10 and 20; a random 6 × 6 with
/// zeros found by the proptest below needed a third).
const ITERATIONS: usize = 60;

/// Balancing sweeps allowed (each sweep rescales rows and columns by
/// powers of two; two or three suffice in practice).
const BALANCE_SWEEPS: usize = 64;

/// A 1-based `(SMALL + 1)²` work array, so the loops below read as the
/// published algorithm does.
struct Work {
    a: [f64; (SMALL + 1) * (SMALL + 1)],
}

impl Work {
    #[inline(always)]
    fn at(&self, i: usize, j: usize) -> f64 {
        self.a[i * (SMALL + 1) + j]
    }
    #[inline(always)]
    fn set(&mut self, i: usize, j: usize, v: f64) {
        self.a[i * (SMALL + 1) + j] = v;
    }
    #[inline(always)]
    fn sub(&mut self, i: usize, j: usize, v: f64) {
        self.a[i * (SMALL + 1) + j] -= v;
    }
}

/// The eigenvalues of the `n × n` matrix stored column-major in `a`
/// (`n ≤ SMALL`), written to `out[..n]` in no particular order (complex
/// pairs adjacent, positive imaginary part first). `false`, with `out`
/// unspecified, when the matrix has a non-finite entry, an intermediate
/// overflows, or the iteration does not converge.
pub(crate) fn small_eigenvalues(a: &[f64], n: usize, out: &mut [Complex<f64>]) -> bool {
    small_eigenvalues_near(a, n, &[], out)
}

/// [`small_eigenvalues`] of a matrix whose eigenvalues are expected near
/// `guesses` (a pole placement's targets): the first two QR sweeps after
/// each deflation use two of the guesses not yet matched as their shifts
/// (a conjugate pair, or two real ones) instead of the trailing 2 × 2
/// block's eigenvalues. Exact shifts deflate a pair in about one sweep,
/// so a placement that hit its targets is confirmed in about `n / 2`
/// sweeps instead of `2 n`. The shifts change the speed only: every sweep
/// is a similarity, so wrong guesses give the same eigenvalues, later.
pub(crate) fn small_eigenvalues_near(
    a: &[f64],
    n: usize,
    guesses: &[Complex<f64>],
    out: &mut [Complex<f64>],
) -> bool {
    debug_assert!(n <= SMALL && a.len() == n * n && out.len() >= n);
    eigenvalues_and_sweeps(a, n, guesses, out).is_some()
}

/// [`small_eigenvalues_near`], with the number of QR sweeps it took.
fn eigenvalues_and_sweeps(
    a: &[f64],
    n: usize,
    guesses: &[Complex<f64>],
    out: &mut [Complex<f64>],
) -> Option<usize> {
    if n > SMALL || a.iter().any(|v| !v.is_finite()) {
        return None;
    }
    let mut w = Work {
        a: [0.0; (SMALL + 1) * (SMALL + 1)],
    };
    for j in 1..=n {
        for i in 1..=n {
            w.set(i, j, a[(j - 1) * n + (i - 1)]);
        }
    }
    balance(&mut w, n);
    hessenberg(&mut w, n);
    let guesses =
        if guesses.len() <= SMALL && guesses.iter().all(|g| g.re.is_finite() && g.im.is_finite()) {
            guesses
        } else {
            &[]
        };
    let sweeps = hqr(&mut w, n, guesses, out)?;
    out[..n]
        .iter()
        .all(|z| z.re.is_finite() && z.im.is_finite())
        .then_some(sweeps)
}

/// Swaps rows and columns `i` and `j` of the leading `n × n` (a
/// permutation similarity).
fn swap(w: &mut Work, n: usize, i: usize, j: usize) {
    if i == j {
        return;
    }
    for k in 1..=n {
        let (p, q) = (w.at(i, k), w.at(j, k));
        w.set(i, k, q);
        w.set(j, k, p);
    }
    for k in 1..=n {
        let (p, q) = (w.at(k, i), w.at(k, j));
        w.set(k, i, q);
        w.set(k, j, p);
    }
}

/// EISPACK `balanc`'s (and LAPACK `dgebal`'s) permutation: rows with no
/// off-diagonal entry in the active columns go to the bottom, then columns
/// with none in the active rows to the left; each isolates its diagonal
/// entry as an eigenvalue. The active block, `low..=igh` (1-based).
fn isolate(w: &mut Work, n: usize) -> (usize, usize) {
    let (mut low, mut igh) = (1, n);
    while let Some(i) = (1..=igh)
        .rev()
        .find(|&i| (1..=igh).all(|j| j == i || w.at(i, j) == 0.0))
    {
        swap(w, n, i, igh);
        if igh == 1 {
            return (1, 0);
        }
        igh -= 1;
    }
    while let Some(j) = (low..=igh).find(|&j| (low..=igh).all(|i| i == j || w.at(i, j) == 0.0)) {
        swap(w, n, j, low);
        low += 1;
    }
    (low, igh)
}

/// Isolated eigenvalues permuted out of the way ([`isolate`]), then
/// similarity scaling of the rest by powers of two (exact) so that each
/// row and the matching column have comparable norms: the eigenvalues
/// then come out with an error relative to the balanced matrix's norm,
/// not to that of an arbitrarily scaled one (LAPACK's `dgeev` balances by
/// default too, with the same two steps).
fn balance(w: &mut Work, n: usize) {
    const RADIX: f64 = 2.0;
    const SQRDX: f64 = RADIX * RADIX;
    let (low, igh) = isolate(w, n);
    for _ in 0..BALANCE_SWEEPS {
        let mut done = true;
        for i in low..=igh {
            let (mut c, mut r) = (0.0, 0.0);
            for j in low..=igh {
                if j != i {
                    c += w.at(j, i).abs();
                    r += w.at(i, j).abs();
                }
            }
            // A zero row or column is already decoupled; a sum that
            // overflows leaves this row as it is.
            if c == 0.0 || r == 0.0 || !(c + r).is_finite() {
                continue;
            }
            let s = c + r;
            let mut f = 1.0;
            let mut g = r / RADIX;
            // Each loop ends within ~1100 passes (c moves by 4 between
            // the smallest and largest normal numbers).
            while c < g && f < 1e150 {
                f *= RADIX;
                c *= SQRDX;
            }
            g = r * RADIX;
            while c > g && f > 1e-150 {
                f /= RADIX;
                c /= SQRDX;
            }
            if (c + r) / f < 0.95 * s {
                done = false;
                let g = 1.0 / f;
                for j in 1..=n {
                    w.set(i, j, w.at(i, j) * g);
                    w.set(j, i, w.at(j, i) * f);
                }
            }
        }
        if done {
            break;
        }
    }
}

/// Reduction to upper Hessenberg form by Gaussian elimination with
/// partial pivoting (a similarity; the multipliers are left below the
/// subdiagonal, where [`hqr`] does not look).
fn hessenberg(w: &mut Work, n: usize) {
    for m in 2..n {
        let mut x: f64 = 0.0;
        let mut i = m;
        for j in m..=n {
            if w.at(j, m - 1).abs() > x.abs() {
                x = w.at(j, m - 1);
                i = j;
            }
        }
        if i != m {
            for j in (m - 1)..=n {
                let (p, q) = (w.at(i, j), w.at(m, j));
                w.set(i, j, q);
                w.set(m, j, p);
            }
            for j in 1..=n {
                let (p, q) = (w.at(j, i), w.at(j, m));
                w.set(j, i, q);
                w.set(j, m, p);
            }
        }
        if x != 0.0 {
            for i in (m + 1)..=n {
                let mut y = w.at(i, m - 1);
                if y != 0.0 {
                    y /= x;
                    w.set(i, m - 1, y);
                    for j in m..=n {
                        let v = y * w.at(m, j);
                        w.sub(i, j, v);
                    }
                    for j in 1..=n {
                        let v = y * w.at(j, i);
                        w.set(j, m, w.at(j, m) + v);
                    }
                }
            }
        }
    }
}

/// The sum and product of the next two unmatched guesses: the first one
/// and its conjugate if complex, else the first two real ones (one real
/// guess alone is used twice). `None` when every guess is matched.
fn shift_pair(guesses: &[Complex<f64>], matched: &[bool; SMALL]) -> Option<(f64, f64)> {
    let mut free = (0..guesses.len()).filter(|&i| !matched[i]);
    let first = guesses[free.next()?];
    if first.im != 0.0 {
        return Some((2.0 * first.re, first.norm_sqr()));
    }
    let second = free
        .map(|i| guesses[i])
        .find(|g| g.im == 0.0)
        .map_or(first.re, |g| g.re);
    Some((first.re + second, first.re * second))
}

/// Stores eigenvalue `k` (1-based) and marks the nearest unmatched guess.
fn put(
    out: &mut [Complex<f64>],
    matched: &mut [bool; SMALL],
    guesses: &[Complex<f64>],
    k: usize,
    re: f64,
    im: f64,
) {
    let z = Complex::new(re, im);
    out[k - 1] = z;
    let nearest = (0..guesses.len())
        .filter(|&i| !matched[i])
        .min_by(|&i, &j| {
            (guesses[i] - z)
                .norm_sqr()
                .total_cmp(&(guesses[j] - z).norm_sqr())
        });
    if let Some(i) = nearest {
        matched[i] = true;
    }
}

/// `|a|` with the sign of `b` (Fortran's `SIGN`).
#[inline(always)]
fn sign(a: f64, b: f64) -> f64 {
    if b >= 0.0 { a.abs() } else { -a.abs() }
}

/// The Francis double-shift QR iteration on the upper Hessenberg matrix
/// in `w`, deflating 1×1 and 2×2 blocks from the bottom; eigenvalues into
/// `out[..n]`. `false` after [`ITERATIONS`] sweeps without a deflation.
#[allow(clippy::many_single_char_names)]
fn hqr(
    w: &mut Work,
    n: usize,
    guesses: &[Complex<f64>],
    out: &mut [Complex<f64>],
) -> Option<usize> {
    let mut anorm = 0.0;
    for i in 1..=n {
        for j in (i.max(2) - 1)..=n {
            anorm += w.at(i, j).abs();
        }
    }
    if !anorm.is_finite() {
        return None;
    }
    let mut sweeps = 0;
    // Which guesses a deflated eigenvalue has matched (the nearest one).
    let mut matched = [false; SMALL];
    let mut nn = n;
    let mut t = 0.0;
    while nn >= 1 {
        let mut its = 0;
        loop {
            // Look for a single small subdiagonal element.
            let mut l = nn;
            while l >= 2 {
                let mut s = w.at(l - 1, l - 1).abs() + w.at(l, l).abs();
                if s == 0.0 {
                    s = anorm;
                }
                if w.at(l, l - 1).abs() + s == s {
                    w.set(l, l - 1, 0.0);
                    break;
                }
                l -= 1;
            }
            let mut x = w.at(nn, nn);
            if l == nn {
                // One root found.
                put(out, &mut matched, guesses, nn, x + t, 0.0);
                nn -= 1;
            } else {
                let mut y = w.at(nn - 1, nn - 1);
                let mut ww = w.at(nn, nn - 1) * w.at(nn - 1, nn);
                if l == nn - 1 {
                    // Two roots found.
                    let p = 0.5 * (y - x);
                    let q = p * p + ww;
                    let mut z = q.abs().sqrt();
                    x += t;
                    if q >= 0.0 {
                        z = p + sign(z, p);
                        let high = x + z;
                        let low = if z != 0.0 { x - ww / z } else { high };
                        put(out, &mut matched, guesses, nn - 1, high, 0.0);
                        put(out, &mut matched, guesses, nn, low, 0.0);
                    } else {
                        put(out, &mut matched, guesses, nn - 1, x + p, z);
                        put(out, &mut matched, guesses, nn, x + p, -z);
                    }
                    nn -= 2;
                } else {
                    if its == ITERATIONS {
                        return None;
                    }
                    if its % 10 == 0 && its > 0 {
                        // Exceptional shift.
                        t += x;
                        for i in 1..=nn {
                            w.sub(i, i, x);
                        }
                        let s = w.at(nn, nn - 1).abs() + w.at(nn - 1, nn - 2).abs();
                        x = 0.75 * s;
                        y = x;
                        ww = -0.4375 * s * s;
                    }
                    if its < 2
                        && let Some((sum, product)) = shift_pair(guesses, &matched)
                    {
                        // The double shift's trace x + y and determinant
                        // x y − ww, for the matrix shifted by t so far.
                        let trace = sum - 2.0 * t;
                        let det = product - t * sum + t * t;
                        x = 0.5 * trace;
                        y = x;
                        ww = x * x - det;
                    }
                    its += 1;
                    sweeps += 1;
                    // Form the shift and look for two consecutive small
                    // subdiagonal elements.
                    let mut m = nn - 2;
                    let (mut p, mut q, mut r, mut z);
                    loop {
                        z = w.at(m, m);
                        r = x - z;
                        let s = y - z;
                        p = (r * s - ww) / w.at(m + 1, m) + w.at(m, m + 1);
                        q = w.at(m + 1, m + 1) - z - r - s;
                        r = w.at(m + 2, m + 1);
                        // Scaled to avoid overflow: by a reciprocal, since
                        // divisions are most of this kernel's time.
                        let inv = 1.0 / (p.abs() + q.abs() + r.abs());
                        p *= inv;
                        q *= inv;
                        r *= inv;
                        if m == l {
                            break;
                        }
                        let u = w.at(m, m - 1).abs() * (q.abs() + r.abs());
                        let v = p.abs()
                            * (w.at(m - 1, m - 1).abs() + z.abs() + w.at(m + 1, m + 1).abs());
                        if u + v == v {
                            break;
                        }
                        m -= 1;
                    }
                    for i in (m + 2)..=nn {
                        w.set(i, i - 2, 0.0);
                        if i != m + 2 {
                            w.set(i, i - 3, 0.0);
                        }
                    }
                    // The double QR step on rows l..nn, columns m..nn.
                    for k in m..nn {
                        if k != m {
                            p = w.at(k, k - 1);
                            q = w.at(k + 1, k - 1);
                            r = if k != nn - 1 { w.at(k + 2, k - 1) } else { 0.0 };
                            x = p.abs() + q.abs() + r.abs();
                            if x != 0.0 {
                                let inv = 1.0 / x;
                                p *= inv;
                                q *= inv;
                                r *= inv;
                            }
                        }
                        let s = sign((p * p + q * q + r * r).sqrt(), p);
                        if s != 0.0 {
                            if k == m {
                                if l != m {
                                    w.set(k, k - 1, -w.at(k, k - 1));
                                }
                            } else {
                                w.set(k, k - 1, -s * x);
                            }
                            p += s;
                            let (inv_s, inv_p) = (1.0 / s, 1.0 / p);
                            x = p * inv_s;
                            y = q * inv_s;
                            z = r * inv_s;
                            q *= inv_p;
                            r *= inv_p;
                            for j in k..=nn {
                                p = w.at(k, j) + q * w.at(k + 1, j);
                                if k != nn - 1 {
                                    p += r * w.at(k + 2, j);
                                    w.sub(k + 2, j, p * z);
                                }
                                w.sub(k + 1, j, p * y);
                                w.sub(k, j, p * x);
                            }
                            let mmin = nn.min(k + 3);
                            for i in l..=mmin {
                                p = x * w.at(i, k) + y * w.at(i, k + 1);
                                if k != nn - 1 {
                                    p += z * w.at(i, k + 2);
                                    w.sub(i, k + 2, p * r);
                                }
                                w.sub(i, k + 1, p * q);
                                w.sub(i, k, p);
                            }
                        }
                    }
                }
            }
            if nn < 2 || l + 1 >= nn {
                break;
            }
        }
    }
    Some(sweeps)
}

#[cfg(test)]
mod tests;
