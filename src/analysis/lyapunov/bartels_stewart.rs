//! The Bartels–Stewart method on run-time-sized matrices: a real Schur
//! form, then block back-substitution over its quasi-triangular factor
//! (1×1 and 2×2 diagonal blocks, each a Kronecker system of at most four
//! unknowns solved by Gaussian elimination with complete pivoting, as
//! LAPACK's `dlasy2`). Every step is `O(N³)`; the only iteration is the
//! Schur decomposition's, with a cap.

use nalgebra::{Complex, DMatrix};

use super::francis;
use crate::error::Error;

/// Iteration cap of each Schur iteration, per matrix dimension (at least
/// ten dimensions): LAPACK's `dlahqr` allows 30.
const ITERATIONS_PER_DIM: usize = 30;

/// Singularity threshold, in units of `n ε` times the scale of the
/// eigenvalues: two eigenvalues closer than this to the equation's
/// singularity condition are taken to meet it.
const SINGULAR_FACTOR: f64 = 100.0;

/// A real Schur decomposition `A = U T Uᵀ` with the positions of `T`'s
/// diagonal blocks and their eigenvalues.
pub(super) struct Schur {
    pub(super) u: DMatrix<f64>,
    pub(super) t: DMatrix<f64>,
    /// `(first row, size)` of each diagonal block, size 1 or 2, in order.
    pub(super) blocks: Vec<(usize, usize)>,
    /// The eigenvalues, block by block (one per row).
    pub(super) eigenvalues: Vec<Complex<f64>>,
}

/// The real Schur decomposition of a square, finite `a`.
pub(super) fn schur(a: &DMatrix<f64>) -> Result<Schur, Error> {
    let n = a.nrows();
    let iterations = ITERATIONS_PER_DIM * n.max(10);
    let failed = Error::NoConvergence {
        operation: "Schur decomposition",
        iterations,
    };
    // nalgebra's Francis iteration first; where it stalls (it has no
    // exceptional shifts), EISPACK's with them.
    let (u, mut t) = match a.clone().try_schur(f64::EPSILON, iterations) {
        Some(s) => s.unpack(),
        None => francis::schur(a, iterations).ok_or(failed.clone())?,
    };
    let mut blocks = Vec::with_capacity(n);
    let mut eigenvalues = Vec::with_capacity(n);
    let mut i = 0;
    while i < n {
        let size = if i + 1 < n && t[(i + 1, i)] != 0.0 {
            2
        } else {
            1
        };
        // A 2×2 block must not run into the next one (the iteration
        // would not have converged).
        if size == 2 && i + 2 < n && t[(i + 2, i + 1)] != 0.0 {
            return Err(failed);
        }
        blocks.push((i, size));
        eigenvalues.extend_from_slice(&block_eigenvalues(&t, i, size)[..size]);
        i += size;
    }
    // Everything below the blocks is zero (the iteration's rounding is
    // not read, but cleared so products with `T` are exact).
    for c in 0..n {
        for r in c + 1..n {
            let in_block = r == c + 1 && blocks.iter().any(|&(s, k)| s == c && k == 2);
            if !in_block {
                t[(r, c)] = 0.0;
            }
        }
    }
    if !(u.iter().all(|v| v.is_finite()) && t.iter().all(|v| v.is_finite())) {
        return Err(Error::Overflow {
            operation: "Schur decomposition",
        });
    }
    Ok(Schur {
        u,
        t,
        blocks,
        eigenvalues,
    })
}

/// The eigenvalues of the diagonal block of `t` at `(i, i)` of `size` 1
/// or 2 (the second is unused for size 1).
fn block_eigenvalues(t: &DMatrix<f64>, i: usize, size: usize) -> [Complex<f64>; 2] {
    if size == 1 {
        return [Complex::new(t[(i, i)], 0.0); 2];
    }
    let (a, b, c, d) = (t[(i, i)], t[(i, i + 1)], t[(i + 1, i)], t[(i + 1, i + 1)]);
    let mean = 0.5 * (a + d);
    let half = 0.5 * (a - d);
    let disc = half * half + b * c;
    if disc >= 0.0 {
        let r = disc.sqrt();
        [Complex::new(mean + r, 0.0), Complex::new(mean - r, 0.0)]
    } else {
        let r = (-disc).sqrt();
        [Complex::new(mean, r), Complex::new(mean, -r)]
    }
}

/// Which singularity condition an equation has.
#[derive(Clone, Copy)]
pub(super) enum Condition {
    /// `λ + μ = 0` (continuous Lyapunov, Sylvester).
    Sum,
    /// `λ μ = 1` (discrete Lyapunov).
    Product,
}

/// The pair `(λ, μ)` that comes closest to the singularity condition, if
/// within the threshold: `100 n ε` times `‖T₁‖_F + ‖T₂‖_F` for a sum,
/// times `(1 + ‖T₁‖_F)(1 + ‖T₂‖_F)` for a product, where `n` is the larger
/// size.
pub(super) fn singular_pair(
    first: &Schur,
    second: &Schur,
    condition: Condition,
) -> Option<(Complex<f64>, Complex<f64>)> {
    let n = first.t.nrows().max(second.t.nrows()) as f64;
    let (s1, s2) = (first.t.norm(), second.t.norm());
    let scale = match condition {
        Condition::Sum => s1 + s2,
        Condition::Product => (1.0 + s1) * (1.0 + s2),
    };
    let tol = SINGULAR_FACTOR * n * f64::EPSILON * scale;
    let mut worst: Option<(f64, Complex<f64>, Complex<f64>)> = None;
    for &l in &first.eigenvalues {
        for &m in &second.eigenvalues {
            let gap = match condition {
                Condition::Sum => (l + m).norm(),
                Condition::Product => (l * m - 1.0).norm(),
            };
            if gap <= tol && worst.is_none_or(|(g, _, _)| gap < g) {
                worst = Some((gap, l, m));
            }
        }
    }
    worst.map(|(_, l, m)| (l, m))
}

/// Solves `K z = rhs` for the `k × k` (k ≤ 4) system in the leading part
/// of `m` (row-major) by Gaussian elimination with complete pivoting,
/// replacing pivots below `smin` by `smin` as LAPACK's `dlasy2` does (the
/// callers have already refused singular spectra). The answer is left in
/// `rhs`.
fn solve_small(m: &mut [[f64; 4]; 4], rhs: &mut [f64; 4], k: usize) {
    let big = (0..k)
        .flat_map(|r| (0..k).map(move |c| (r, c)))
        .fold(0.0f64, |acc, (r, c)| acc.max(m[r][c].abs()));
    let smin = (f64::EPSILON * big).max(f64::MIN_POSITIVE);
    let mut perm = [0usize, 1, 2, 3];
    for p in 0..k {
        // Complete pivoting: the largest entry of the trailing block.
        let (mut pr, mut pc, mut best) = (p, p, -1.0);
        for (r, row) in m.iter().enumerate().take(k).skip(p) {
            for (c, v) in row.iter().enumerate().take(k).skip(p) {
                if v.abs() > best {
                    (pr, pc, best) = (r, c, v.abs());
                }
            }
        }
        m.swap(p, pr);
        rhs.swap(p, pr);
        for row in m.iter_mut().take(k) {
            row.swap(p, pc);
        }
        perm.swap(p, pc);
        if m[p][p].abs() < smin {
            m[p][p] = smin;
        }
        let (pivot, b) = (m[p], rhs[p]);
        for (row, v) in m.iter_mut().zip(rhs.iter_mut()).take(k).skip(p + 1) {
            let f = row[p] / pivot[p];
            for (x, y) in row[p..k].iter_mut().zip(&pivot[p..k]) {
                *x -= f * y;
            }
            *v -= f * b;
        }
    }
    let mut z = [0.0; 4];
    for p in (0..k).rev() {
        let mut v = rhs[p];
        for c in p + 1..k {
            v -= m[p][c] * z[c];
        }
        z[p] = v / m[p][p];
    }
    for p in 0..k {
        rhs[perm[p]] = z[p];
    }
}

/// `S Z M + σ Z = G` for one `p × q` block `Z` (p, q ≤ 2), column-major in
/// `g`: `S` the `p × p` block of `s` at `(i, i)`, `M` the `q × q` block
/// of `t` at `(j, j)` (transposed if `t_transposed`); `product` chooses
/// between `S Z + Z M = G` (false; σ unused) and `S Z M − Z = G` (true).
#[allow(clippy::too_many_arguments)]
fn solve_block(
    s: &DMatrix<f64>,
    (i, p): (usize, usize),
    t: &DMatrix<f64>,
    (j, q): (usize, usize),
    t_transposed: bool,
    product: bool,
    g: &mut [f64; 4],
) {
    let sv = |r: usize, c: usize| s[(i + r, i + c)];
    let mv = |r: usize, c: usize| {
        if t_transposed {
            t[(j + c, j + r)]
        } else {
            t[(j + r, j + c)]
        }
    };
    // vec(S Z) = (I ⊗ S) vec Z, vec(Z M) = (Mᵀ ⊗ I) vec Z,
    // vec(S Z M) = (Mᵀ ⊗ S) vec Z; unknown (r, c) is entry r + p c.
    let mut k = [[0.0; 4]; 4];
    for c1 in 0..q {
        for r1 in 0..p {
            let row = r1 + p * c1;
            for c2 in 0..q {
                for r2 in 0..p {
                    let col = r2 + p * c2;
                    k[row][col] = if product {
                        sv(r1, r2) * mv(c2, c1) - f64::from(u8::from(row == col))
                    } else {
                        f64::from(u8::from(c1 == c2)) * sv(r1, r2)
                            + f64::from(u8::from(r1 == r2)) * mv(c2, c1)
                    };
                }
            }
        }
    }
    solve_small(&mut k, g, p * q);
}

/// Solves `S Y + Y op(T) = F` in place (`f` becomes `Y`), `S` (`m × m`)
/// and `T` (`n × n`) quasi-upper-triangular with diagonal blocks
/// `s_blocks` and `t_blocks`; `op(T) = Tᵀ` if `t_transposed`. LAPACK's
/// `dtrsyl`: the columns of `Y` block by block (forward for `T`, backward
/// for `Tᵀ`), each by back-substitution over the row blocks of `S`.
pub(super) fn quasi_sylvester(
    s: &DMatrix<f64>,
    s_blocks: &[(usize, usize)],
    t: &DMatrix<f64>,
    t_blocks: &[(usize, usize)],
    t_transposed: bool,
    f: &mut DMatrix<f64>,
) {
    let (m, n) = f.shape();
    let order: Vec<(usize, usize)> = if t_transposed {
        t_blocks.iter().rev().copied().collect()
    } else {
        t_blocks.to_vec()
    };
    for (j, q) in order {
        // F_j −= Σ_k Y_k op(T)_kj over the columns already solved.
        let solved = if t_transposed { j + q..n } else { 0..j };
        for c in j..j + q {
            for k in solved.clone() {
                let tkc = if t_transposed { t[(c, k)] } else { t[(k, c)] };
                if tkc != 0.0 {
                    for r in 0..m {
                        f[(r, c)] -= f[(r, k)] * tkc;
                    }
                }
            }
        }
        for &(i, p) in s_blocks.iter().rev() {
            let mut g = [0.0; 4];
            for c in 0..q {
                for r in 0..p {
                    // G_i = F_i − Σ_{k below the block} S_ik Z_k.
                    let mut v = f[(i + r, j + c)];
                    for k in i + p..m {
                        v -= s[(i + r, k)] * f[(k, j + c)];
                    }
                    g[r + p * c] = v;
                }
            }
            solve_block(s, (i, p), t, (j, q), t_transposed, false, &mut g);
            for c in 0..q {
                for r in 0..p {
                    f[(i + r, j + c)] = g[r + p * c];
                }
            }
        }
    }
}

/// Solves `S Y Tᵀ − Y + F = 0` in place (`f`, `m × n`, becomes `Y`), `S`
/// (`m × m`) and `T` (`n × n`) quasi-upper-triangular with diagonal blocks
/// `s_blocks` and `t_blocks`: the columns of `Y` block by block from the
/// last, each by back-substitution over the row blocks (Barraud's 1977
/// analogue of Bartels–Stewart, `O(m n (m + n))` in all). `T = S` is the
/// discrete Lyapunov equation.
pub(super) fn quasi_stein(
    s: &DMatrix<f64>,
    s_blocks: &[(usize, usize)],
    t: &DMatrix<f64>,
    t_blocks: &[(usize, usize)],
    f: &mut DMatrix<f64>,
) {
    let (m, n) = f.shape();
    let mut w = DMatrix::<f64>::zeros(m, 2);
    let mut sw = DMatrix::<f64>::zeros(m, 2);
    let mut h = DMatrix::<f64>::zeros(m, 2);
    for &(j, q) in t_blocks.iter().rev() {
        // W = Σ_{l after the block} Y_l T_jlᵀ, then rhs −F_j − S W.
        w.fill(0.0);
        for c in 0..q {
            for l in j + q..n {
                let tjl = t[(j + c, l)];
                if tjl != 0.0 {
                    for r in 0..m {
                        w[(r, c)] += f[(r, l)] * tjl;
                    }
                }
            }
        }
        sw.fill(0.0);
        for c in 0..q {
            for k in 0..m {
                let wk = w[(k, c)];
                if wk != 0.0 {
                    // S is quasi-upper: rows up to k + 1.
                    for r in 0..(k + 2).min(m) {
                        sw[(r, c)] += s[(r, k)] * wk;
                    }
                }
            }
        }
        // S Z M − Z = −F_j − S W with M = T_jjᵀ; H_i = Σ_{k>i} S_ik Z_k
        // is formed row block by row block as Z is found.
        h.fill(0.0);
        for &(i, p) in s_blocks.iter().rev() {
            let mut g = [0.0; 4];
            for c in 0..q {
                for r in 0..p {
                    let mut hz = 0.0;
                    for k in i + p..m {
                        hz += s[(i + r, k)] * f[(k, j + c)];
                    }
                    h[(i + r, c)] = hz;
                }
            }
            for c in 0..q {
                for r in 0..p {
                    // (H M)_rc with M = T_jjᵀ: Σ_e H_re T_jj[c, e].
                    let mut hm = 0.0;
                    for e in 0..q {
                        hm += h[(i + r, e)] * t[(j + c, j + e)];
                    }
                    g[r + p * c] = -f[(i + r, j + c)] - sw[(i + r, c)] - hm;
                }
            }
            solve_block(s, (i, p), t, (j, q), true, true, &mut g);
            for c in 0..q {
                for r in 0..p {
                    f[(i + r, j + c)] = g[r + p * c];
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::dmatrix;

    #[test]
    fn small_solve_with_complete_pivoting() {
        let mut m = [[0.0; 4]; 4];
        m[0] = [0.0, 2.0, 0.0, 0.0];
        m[1] = [3.0, 1.0, 0.0, 0.0];
        let mut rhs = [4.0, 5.0, 0.0, 0.0];
        solve_small(&mut m, &mut rhs, 2);
        // 2 y = 4, 3 x + y = 5.
        assert!((rhs[0] - 1.0).abs() < 1e-15 && (rhs[1] - 2.0).abs() < 1e-15);
    }

    #[test]
    fn quasi_triangular_equations_hold() {
        // A 2×2 block (eigenvalues −1 ± 2i) above a 1×1 one.
        let s = dmatrix![-1.0, 2.0, 0.5; -2.0, -1.0, 0.3; 0.0, 0.0, -3.0];
        let blocks = [(0, 2), (2, 1)];
        let f = dmatrix![1.0, 2.0, 3.0; 4.0, 5.0, 6.0; 7.0, 8.0, 9.5];
        for transposed in [false, true] {
            let mut y = f.clone();
            quasi_sylvester(&s, &blocks, &s, &blocks, transposed, &mut y);
            let op = if transposed { s.transpose() } else { s.clone() };
            assert!((&s * &y + &y * op - &f).amax() < 1e-13);
        }
        let s = &s * 0.3;
        let mut y = f.clone();
        quasi_stein(&s, &blocks, &s, &blocks, &mut y);
        assert!((&s * &y * s.transpose() - &y + &f).amax() < 1e-13);
        // Two different factors, 3 × 3 and 2 × 2 (a 2×2 block), F 3 × 2.
        let t = dmatrix![0.2, 0.9; -0.4, 0.1];
        let f = f.columns(0, 2).into_owned();
        let mut y = f.clone();
        quasi_stein(&s, &blocks, &t, &[(0, 2)], &mut y);
        assert!((&s * &y * t.transpose() - &y + &f).amax() < 1e-13);
    }
}
