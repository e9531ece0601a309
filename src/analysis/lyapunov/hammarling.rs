//! Hammarling's method (1982) for the factor of a stable Lyapunov
//! equation's solution, `A X + X Aᵀ + B Bᵀ = 0` with `X = Rᵀ R`, on the
//! complex Schur form (MATLAB's `rsf2csf` of the real one), so that every
//! diagonal block is 1×1; `O(n³ + n² m)`.

use nalgebra::{Complex, DMatrix};

use super::bartels_stewart::Schur;

type C64 = Complex<f64>;

/// `(U, S)`: the complex Schur form `A = U S Uᴴ` (`S` upper triangular)
/// of the real one, each 2×2 block split by a rotation (`rsf2csf`).
fn complex_schur(real: &Schur) -> (DMatrix<C64>, DMatrix<C64>) {
    let n = real.t.nrows();
    let mut t = real.t.map(|v| C64::new(v, 0.0));
    let mut u = real.u.map(|v| C64::new(v, 0.0));
    for &(i, size) in real.blocks.iter().rev() {
        if size != 2 {
            continue;
        }
        let m = i + 1;
        let (a, b, c, d) = (t[(i, i)], t[(i, m)], t[(m, i)], t[(m, m)]);
        let half = (a - d) * 0.5;
        let eig = (a + d) * 0.5 + (half * half + b * c).sqrt();
        let mu = eig - d;
        let r = (mu.norm_sqr() + c.norm_sqr()).sqrt();
        if r == 0.0 {
            continue;
        }
        let (cs, sn) = (mu / r, c / r);
        // T ← G T Gᴴ with G = [c̄ s; −s c], U ← U Gᴴ.
        for j in i..n {
            let (x, y) = (t[(i, j)], t[(m, j)]);
            t[(i, j)] = cs.conj() * x + sn * y;
            t[(m, j)] = -sn * x + cs * y;
        }
        for r in 0..=m {
            let (x, y) = (t[(r, i)], t[(r, m)]);
            t[(r, i)] = x * cs + y * sn.conj();
            t[(r, m)] = -x * sn.conj() + y * cs.conj();
        }
        for r in 0..n {
            let (x, y) = (u[(r, i)], u[(r, m)]);
            u[(r, i)] = x * cs + y * sn.conj();
            u[(r, m)] = -x * sn.conj() + y * cs.conj();
        }
        t[(m, i)] = C64::new(0.0, 0.0);
    }
    (u, t)
}

/// Row `k`'s first `m` entries of `c` moved into its last column by a
/// Householder reflection from the right, applied to rows `0..=k`;
/// returns the entry left there.
fn reflect_row(c: &mut DMatrix<C64>, k: usize) -> C64 {
    let m = c.ncols();
    let last = m - 1;
    // x = (row k)ᴴ; H x = α e_last with H = I − 2 w wᴴ / (wᴴ w).
    let norm = (0..m).map(|j| c[(k, j)].norm_sqr()).sum::<f64>().sqrt();
    if norm == 0.0 || m == 1 {
        return c[(k, last)];
    }
    let xl = c[(k, last)].conj();
    let phase = if xl.norm() == 0.0 {
        C64::new(1.0, 0.0)
    } else {
        xl / xl.norm()
    };
    let alpha = -phase * norm;
    let mut w: Vec<C64> = (0..m).map(|j| c[(k, j)].conj()).collect();
    w[last] -= alpha;
    let ww: f64 = w.iter().map(|v| v.norm_sqr()).sum();
    if ww == 0.0 {
        return c[(k, last)];
    }
    for r in 0..=k {
        // row ← row − 2 (row w) wᴴ / (wᴴ w)
        let dot: C64 = (0..m).map(|j| c[(r, j)] * w[j]).sum();
        let f = dot * (2.0 / ww);
        for (j, wj) in w.iter().enumerate() {
            c[(r, j)] -= f * wj.conj();
        }
    }
    for j in 0..last {
        c[(k, j)] = C64::new(0.0, 0.0);
    }
    alpha.conj()
}

/// The factor `R` (upper triangular, non-negative diagonal) with
/// `X = Rᵀ R` solving `A X + X Aᵀ + B Bᵀ = 0`, from the real Schur form
/// of `A`, whose eigenvalues all have negative real parts; `b` is
/// `n × m`, `m ≥ 1`.
pub(super) fn factor(schur: &Schur, b: &DMatrix<f64>) -> DMatrix<f64> {
    let n = schur.t.nrows();
    let (q, s) = complex_schur(schur);
    // S Y + Y Sᴴ + C Cᴴ = 0 with Y = Qᴴ X Q, C = Qᴴ B; Y = U Uᴴ.
    let mut c = q.adjoint() * b.map(|v| C64::new(v, 0.0));
    let mut u = DMatrix::<C64>::zeros(n, n);
    let last = c.ncols() - 1;
    for k in (0..n).rev() {
        let lambda = s[(k, k)];
        let rho = (-2.0 * lambda.re).sqrt();
        let gamma = reflect_row(&mut c, k);
        let nu = gamma.norm() / rho;
        let omega = if gamma.norm() == 0.0 {
            C64::new(1.0, 0.0)
        } else {
            gamma / gamma.norm()
        };
        // (S₁₁ + λ̄ I) u = −(s ν + c ω̄ ρ), back-substitution.
        let mut col = vec![C64::new(0.0, 0.0); k];
        for i in (0..k).rev() {
            let mut v = -(s[(i, k)] * nu + c[(i, last)] * omega.conj() * rho);
            for (j, cj) in col.iter().enumerate().skip(i + 1) {
                v -= s[(i, j)] * cj;
            }
            col[i] = v / (s[(i, i)] + lambda.conj());
        }
        for (i, ui) in col.iter().enumerate() {
            u[(i, k)] = *ui;
            // The next right side: y = c − ω ρ u.
            c[(i, last)] -= omega * rho * ui;
        }
        u[(k, k)] = C64::new(nu, 0.0);
    }
    // X = Z Zᴴ with Z = Q U, real: X = P Pᵀ + W Wᵀ for Z = P + i W,
    // so X = Mᵀ M with M = [Pᵀ; Wᵀ], and R is M's triangular factor.
    let z = q * u;
    let mut m = DMatrix::<f64>::zeros(2 * n, n);
    for i in 0..n {
        for j in 0..n {
            m[(j, i)] = z[(i, j)].re;
            m[(n + j, i)] = z[(i, j)].im;
        }
    }
    let mut r = m.qr().r();
    for i in 0..n {
        if r[(i, i)] < 0.0 {
            r.row_mut(i).neg_mut();
        }
    }
    r
}
