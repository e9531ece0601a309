//! The O(N³) kernels of the Riccati solvers, on faer matrices: LU with the
//! crate's singularity test, the structure-preserving doubling, and the
//! Lyapunov and Stein solves of the Newton refinement.

use faer::linalg::matmul::matmul;
use faer::linalg::solvers::{DenseSolveCore, PartialPivLu, Solve};
use faer::{Accum, Mat, MatRef, Par};

use crate::error::Error;

/// Doubling steps allowed; quadratic convergence needs far fewer (about
/// `log2` of the ratio of the fastest to the slowest closed-loop mode, +6).
pub(super) const MAX_ITERATIONS: usize = 100;
/// Stop when a doubling step changes `H` by less than this, relative.
const STEP_RTOL: f64 = 1e-15;
/// Sign-function steps allowed for one Lyapunov solve; with norm scaling
/// the iteration needs about 10–20, even for a condition number of 1e12.
const SIGN_ITERATIONS: usize = 60;
/// Squared-Smith steps allowed for one Stein solve: after `k` steps the
/// series has `2^k` terms, so 64 covers any spectral radius below `1 − 2⁻⁵⁸`.
const SMITH_ITERATIONS: usize = 64;

/// `P A = L U`, refused (as [`crate::kernels::linalg::Lu`] refuses) when the
/// smallest pivot is negligible against the largest (`≤ N ε max`) or any is
/// not finite: the matrix is singular to working precision.
pub(super) fn lu(a: MatRef<'_, f64>, operation: &'static str) -> Result<PartialPivLu<f64>, Error> {
    let lu = PartialPivLu::new(a);
    let n = a.nrows();
    let (mut max_pivot, mut min_pivot) = (0.0f64, f64::INFINITY);
    for i in 0..n {
        let p = lu.U()[(i, i)].abs();
        if !p.is_finite() {
            return Err(Error::Singular { operation });
        }
        max_pivot = max_pivot.max(p);
        min_pivot = min_pivot.min(p);
    }
    if n > 0 && (min_pivot <= n as f64 * f64::EPSILON * max_pivot || max_pivot == 0.0) {
        return Err(Error::Singular { operation });
    }
    Ok(lu)
}

/// `m ← (m + mᵀ) / 2`, in place.
pub(super) fn symmetrize(m: &mut Mat<f64>) {
    let n = m.nrows();
    for j in 0..n {
        for i in 0..j {
            let v = 0.5 * (m[(i, j)] + m[(j, i)]);
            m[(i, j)] = v;
            m[(j, i)] = v;
        }
    }
}

/// `dst ← alpha · lhs · rhs` (or `dst += …` with `Accum::Add`), single-threaded.
pub(super) fn gemm(
    dst: &mut Mat<f64>,
    accum: Accum,
    lhs: MatRef<'_, f64>,
    rhs: MatRef<'_, f64>,
    alpha: f64,
) {
    matmul(dst.as_mut(), accum, lhs, rhs, alpha, Par::Seq);
}

pub(super) fn finite(m: MatRef<'_, f64>) -> bool {
    (0..m.ncols()).all(|j| (0..m.nrows()).all(|i| m[(i, j)].is_finite()))
}

/// The structure-preserving doubling algorithm of Chu, Fan and Lin (2005)
/// on `(E, G, H)`:
///
/// ```text
/// W = I + G H,  E ← E W⁻¹ E,  G ← G + E W⁻¹ G Eᵀ,  H ← H + Eᵀ H W⁻¹ E
/// ```
///
/// returning `H` at convergence and the steps taken. One LU of `W` and one
/// solve with `2N` right-hand sides per step; the products go to buffers
/// allocated once.
pub(super) fn sda(
    mut e: Mat<f64>,
    mut g: Mat<f64>,
    mut h: Mat<f64>,
) -> Result<(Mat<f64>, usize), Error> {
    let n = e.nrows();
    let mut w = Mat::<f64>::zeros(n, n);
    let mut rhs = Mat::<f64>::zeros(n, 2 * n);
    let mut tmp = Mat::<f64>::zeros(n, n);
    let mut h_next = Mat::<f64>::zeros(n, n);
    for it in 1..=MAX_ITERATIONS {
        // W = I + G H: nonsingular for G, H positive semidefinite.
        gemm(&mut w, Accum::Replace, g.as_ref(), h.as_ref(), 1.0);
        for i in 0..n {
            w[(i, i)] += 1.0;
        }
        let w_lu = lu(w.as_ref(), "Riccati doubling (I + G H)")?;
        // [W⁻¹ E, W⁻¹ G] in one solve.
        rhs.as_mut().subcols_mut(0, n).copy_from(&e);
        rhs.as_mut().subcols_mut(n, n).copy_from(&g);
        w_lu.solve_in_place(rhs.as_mut());
        let (w_e, w_g) = (rhs.as_ref().subcols(0, n), rhs.as_ref().subcols(n, n));
        // H + Eᵀ (H W⁻¹ E)
        gemm(&mut tmp, Accum::Replace, h.as_ref(), w_e, 1.0);
        h_next.copy_from(&h);
        gemm(&mut h_next, Accum::Add, e.transpose(), tmp.as_ref(), 1.0);
        symmetrize(&mut h_next);
        // G + E (W⁻¹ G Eᵀ)
        gemm(&mut tmp, Accum::Replace, w_g, e.transpose(), 1.0);
        let e_old = e.clone();
        gemm(&mut g, Accum::Add, e_old.as_ref(), tmp.as_ref(), 1.0);
        symmetrize(&mut g);
        // E W⁻¹ E
        gemm(&mut e, Accum::Replace, e_old.as_ref(), w_e, 1.0);
        let step = (&h_next - &h).norm_l2();
        std::mem::swap(&mut h, &mut h_next);
        // Only H must stay finite: E (and G) may grow without bound on a
        // mode the input cannot reach while H still converges, and the
        // caller's stability check then names that mode.
        if !finite(h.as_ref()) {
            return Err(Error::Overflow {
                operation: "Riccati doubling",
            });
        }
        if step <= STEP_RTOL * h.norm_l2() {
            return Ok((h, it));
        }
    }
    Err(Error::NoConvergence {
        operation: "Riccati doubling",
        iterations: MAX_ITERATIONS,
    })
}

/// The solution `X` of the Lyapunov equation `Aᵀ X + X A + C = 0` for a
/// stable `A`, by the Newton iteration for the matrix sign function of
/// `Z = [Aᵀ C; 0 −A]` (Roberts, 1971): its blocks evolve as
/// `E ← (c E + E⁻¹/c)/2`, `F ← (c F + E⁻¹ F E⁻ᵀ/c)/2` from `E = Aᵀ`, `F = C`,
/// `sign(Z) = [−I 2X; 0 I]`. One inverse and two products per step,
/// norm-scaled (`c = √(‖E⁻¹‖/‖E‖)`) until near convergence. `None` if `A` is
/// singular, not stable (`E` does not tend to `−I`), or the steps run out.
pub(super) fn lyapunov(a: MatRef<'_, f64>, c: MatRef<'_, f64>) -> Option<Mat<f64>> {
    let n = a.nrows();
    let mut e = a.transpose().to_owned();
    let mut f = c.to_owned();
    let mut tmp = Mat::<f64>::zeros(n, n);
    let mut f_next = Mat::<f64>::zeros(n, n);
    let mut scaled = true;
    let mut last = false;
    for _ in 0..SIGN_ITERATIONS {
        let e_inv = lu(e.as_ref(), "Lyapunov sign iteration").ok()?.inverse();
        let k = if scaled {
            (e_inv.norm_l2() / e.norm_l2()).sqrt()
        } else {
            1.0
        };
        if !k.is_finite() || k == 0.0 {
            return None;
        }
        gemm(&mut tmp, Accum::Replace, e_inv.as_ref(), f.as_ref(), 1.0);
        f_next.copy_from(&f);
        for j in 0..n {
            for i in 0..n {
                f_next[(i, j)] *= 0.5 * k;
            }
        }
        gemm(
            &mut f_next,
            Accum::Add,
            tmp.as_ref(),
            e_inv.transpose(),
            0.5 / k,
        );
        std::mem::swap(&mut f, &mut f_next);
        let mut change = 0.0;
        for j in 0..n {
            for i in 0..n {
                let next = 0.5 * (k * e[(i, j)] + e_inv[(i, j)] / k);
                change += (next - e[(i, j)]).powi(2);
                e[(i, j)] = next;
            }
        }
        let change = change.sqrt();
        if !finite(f.as_ref()) || !change.is_finite() {
            return None;
        }
        if last {
            break;
        }
        // Quadratic convergence: once a step is below √ε, one more
        // (unscaled) step reaches rounding level.
        if change <= 1e-2 * e.norm_l2() {
            scaled = false;
        }
        last = change <= 1e-8 * e.norm_l2();
    }
    // sign(Aᵀ) = −I exactly when A is stable.
    let mut off = 0.0;
    for j in 0..n {
        for i in 0..n {
            let target = if i == j { -1.0 } else { 0.0 };
            off += (e[(i, j)] - target).powi(2);
        }
    }
    if !last || off.sqrt() > 1e-6 * (n as f64).sqrt() {
        return None;
    }
    let mut x = f * faer::Scale(0.5);
    symmetrize(&mut x);
    Some(x)
}

/// The solution `X` of the Stein equation `X − Aᵀ X A = C` for `A` with
/// spectral radius below 1, by squared Smith (doubling):
/// `X = Σ (Aᵀ)ᵏ C Aᵏ` summed as `X ← X + Tᵀ X T`, `T ← T²`. `None` if the
/// series has not converged after [`SMITH_ITERATIONS`] steps or overflows.
pub(super) fn stein(a: MatRef<'_, f64>, c: MatRef<'_, f64>) -> Option<Mat<f64>> {
    let n = a.nrows();
    let mut x = c.to_owned();
    let mut t = a.to_owned();
    let mut tmp = Mat::<f64>::zeros(n, n);
    let mut update = Mat::<f64>::zeros(n, n);
    for _ in 0..SMITH_ITERATIONS {
        gemm(&mut tmp, Accum::Replace, x.as_ref(), t.as_ref(), 1.0);
        gemm(
            &mut update,
            Accum::Replace,
            t.transpose(),
            tmp.as_ref(),
            1.0,
        );
        x += &update;
        let (u, s) = (update.norm_l2(), x.norm_l2());
        if !u.is_finite() || !s.is_finite() {
            return None;
        }
        if u <= f64::EPSILON * s {
            symmetrize(&mut x);
            return Some(x);
        }
        gemm(&mut tmp, Accum::Replace, t.as_ref(), t.as_ref(), 1.0);
        std::mem::swap(&mut t, &mut tmp);
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lyapunov_and_stein_solve_their_equations() {
        let a = Mat::from_fn(3, 3, |i, j| {
            [[-2.0, 1.0, 0.0], [0.0, -1.0, 3.0], [0.5, 0.0, -4.0]][i][j]
        });
        let c = Mat::from_fn(3, 3, |i, j| if i == j { 1.0 + i as f64 } else { 0.2 });
        let x = lyapunov(a.as_ref(), c.as_ref()).unwrap();
        let res = a.transpose() * &x + &x * &a + &c;
        assert!(res.norm_l2() < 1e-13 * c.norm_l2(), "{res:?}");
        // Unstable A: no solution by this route.
        let unstable = &a * faer::Scale(-1.0);
        assert!(lyapunov(unstable.as_ref(), c.as_ref()).is_none());

        let d = &a * faer::Scale(0.2);
        let x = stein(d.as_ref(), c.as_ref()).unwrap();
        let res = &x - d.transpose() * &x * &d - &c;
        assert!(res.norm_l2() < 1e-14 * c.norm_l2(), "{res:?}");
        let big = &a * faer::Scale(2.0);
        assert!(stein(big.as_ref(), c.as_ref()).is_none());
    }
}
