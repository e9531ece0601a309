//! The O(N³) kernels of the Riccati solvers, written once over nalgebra's
//! [`Dim`]: a fixed-size caller (`Const<N>`) works on stack matrices and
//! allocates nothing here, a run-time-sized one (`Dyn`) gets the same
//! arithmetic on the heap, with nalgebra's cache-blocked `gemm`
//! (matrixmultiply) for products above 5 × 5. The structure-preserving
//! doubling, and the Lyapunov and Stein solves of the Newton refinement.

use nalgebra::{DefaultAllocator, Dim, OMatrix, allocator::Allocator};

use crate::error::Error;
use crate::kernels::linalg::Lu;

/// Doubling steps allowed; quadratic convergence needs far fewer (about
/// `log2` of the ratio of the fastest to the slowest closed-loop mode, +6).
pub(super) const MAX_ITERATIONS: usize = 100;
/// Stop when a doubling step changes `H` by less than this, relative…
const STEP_RTOL: f64 = 1e-15;
/// …and `‖E‖` is below this: every mode contracts, so no direction of `H`
/// is still growing. A small step alone is not convergence: `H` along a
/// mode with a tiny weight (`Q = diag(1e9, 1e-9)`) starts below
/// `STEP_RTOL ‖H‖` and grows by `‖E‖²` a step until the mode is stabilised
/// (with `‖E‖` above 1, growing, meanwhile).
const E_TOL: f64 = 1e-3;
/// Sign-function steps allowed for one Lyapunov solve; with norm scaling
/// the iteration needs about 10–20, even for a condition number of 1e12.
const SIGN_ITERATIONS: usize = 60;
/// Squared-Smith steps allowed for one Stein solve: after `k` steps the
/// series has `2^k` terms, so 64 covers any spectral radius below `1 − 2⁻⁵⁸`.
const SMITH_ITERATIONS: usize = 64;

/// The square matrices of one Riccati problem with `N` states.
pub(super) type Square<N> = OMatrix<f64, N, N>;

/// `m ← (m + mᵀ) / 2`, in place.
pub(super) fn symmetrize<N: Dim>(m: &mut Square<N>)
where
    DefaultAllocator: Allocator<N, N>,
{
    let n = m.nrows();
    for j in 0..n {
        for i in 0..j {
            let v = 0.5 * (m[(i, j)] + m[(j, i)]);
            m[(i, j)] = v;
            m[(j, i)] = v;
        }
    }
}

/// Every entry finite.
pub(super) fn finite<R: Dim, C: Dim>(m: &OMatrix<f64, R, C>) -> bool
where
    DefaultAllocator: Allocator<R, C>,
{
    m.iter().all(|v| v.is_finite())
}

/// The Frobenius norm; rescaled by the largest entry where the plain sum
/// of squares overflows or underflows (entries near `f64::MAX`, or tiny
/// ones), which nalgebra's `norm` does not do.
pub(super) fn fro<R: Dim, C: Dim>(m: &OMatrix<f64, R, C>) -> f64
where
    DefaultAllocator: Allocator<R, C>,
{
    let plain: f64 = m.iter().map(|v| v * v).sum();
    if plain.is_finite() && plain >= f64::MIN_POSITIVE {
        return plain.sqrt();
    }
    let max = m.amax();
    if max == 0.0 || !max.is_finite() {
        return max;
    }
    let s: f64 = m.iter().map(|v| (v / max).powi(2)).sum();
    max * s.sqrt()
}

/// `‖a − b‖_F`, without forming `a − b`; rescaled as [`fro`] rescales only
/// where the plain sum of squares overflows or underflows.
fn fro_diff<N: Dim>(a: &Square<N>, b: &Square<N>) -> f64
where
    DefaultAllocator: Allocator<N, N>,
{
    let plain: f64 = a.iter().zip(b.iter()).map(|(x, y)| (x - y) * (x - y)).sum();
    if plain.is_finite() && plain >= f64::MIN_POSITIVE {
        return plain.sqrt();
    }
    let max = a
        .iter()
        .zip(b.iter())
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
    if max == 0.0 || !max.is_finite() {
        return max;
    }
    let s: f64 = a
        .iter()
        .zip(b.iter())
        .map(|(x, y)| ((x - y) / max).powi(2))
        .sum();
    max * s.sqrt()
}

/// `dst ← alpha · lhsᵀ · rhs + beta · dst`. The transpose is formed first
/// so a run-time-sized product goes through the blocked `gemm`, not
/// nalgebra's column-dot `gemm_tr`.
fn gemm_tn<N: Dim>(dst: &mut Square<N>, alpha: f64, lhs: &Square<N>, rhs: &Square<N>, beta: f64)
where
    DefaultAllocator: Allocator<N, N>,
{
    dst.gemm(alpha, &lhs.transpose(), rhs, beta);
}

/// `a⁻¹`, refused as [`Lu::new`] refuses a singular matrix.
pub(super) fn inverse<N: Dim>(a: &Square<N>, operation: &'static str) -> Result<Square<N>, Error>
where
    DefaultAllocator: Allocator<N, N> + Allocator<N>,
{
    let (dim, _) = a.shape_generic();
    Ok(Lu::new(a, operation)?.solve(&Square::<N>::identity_generic(dim, dim)))
}

/// The structure-preserving doubling algorithm of Chu, Fan and Lin (2005)
/// on `(E, G, H)`:
///
/// ```text
/// W = I + G H,  E ← E W⁻¹ E,  G ← G + E W⁻¹ G Eᵀ,  H ← H + Eᵀ H W⁻¹ E
/// ```
///
/// returning `H` at convergence and the steps taken. Converged means a
/// step below [`STEP_RTOL`] with `‖E‖` below [`E_TOL`] (`E` tends to zero
/// exactly when the solution is stabilising); if `E` never gets there
/// (a mode on the stability boundary, or one `H` never sees, where `E`
/// overflows) but `H` has stopped changing, the last settled `H` is
/// returned and the caller's stability check names the mode. One LU of `W` and solves for `W⁻¹ E`,
/// `W⁻¹ G` per step; the products go to buffers allocated once.
pub(super) fn sda<N: Dim>(
    mut e: Square<N>,
    mut g: Square<N>,
    mut h: Square<N>,
) -> Result<(Square<N>, usize), Error>
where
    DefaultAllocator: Allocator<N, N> + Allocator<N>,
{
    let n = e.nrows();
    let (dim, _) = e.shape_generic();
    let mut w = Square::<N>::zeros_generic(dim, dim);
    let mut tmp = Square::<N>::zeros_generic(dim, dim);
    let mut h_next = Square::<N>::zeros_generic(dim, dim);
    let mut settled = false;
    for it in 1..=MAX_ITERATIONS {
        // W = I + G H: nonsingular for G, H positive semidefinite (every
        // eigenvalue at least 1), however ill-conditioned; while a mode of
        // tiny weight is being stabilised G H grows to 1e18 and more, and
        // a pivot-ratio test would refuse it (an indefinite H that makes W
        // singular shows as a zero or non-finite pivot, or a non-finite H).
        w.gemm(1.0, &g, &h, 0.0);
        for i in 0..n {
            w[(i, i)] += 1.0;
        }
        let w_lu = match Lu::structurally(&w, "Riccati doubling (I + G H)") {
            Ok(lu) => lu,
            // G H non-finite: as an overflowing H below.
            Err(_) if settled => return Ok((h, it - 1)),
            Err(e) => return Err(e),
        };
        let (w_e, w_g) = (w_lu.solve(&e), w_lu.solve(&g));
        // H + Eᵀ (H W⁻¹ E)
        tmp.gemm(1.0, &h, &w_e, 0.0);
        h_next.copy_from(&h);
        gemm_tn(&mut h_next, 1.0, &e, &tmp, 1.0);
        symmetrize(&mut h_next);
        // G + E (W⁻¹ G Eᵀ), with the old E.
        tmp.gemm(1.0, &w_g, &e.transpose(), 0.0);
        g.gemm(1.0, &e, &tmp, 1.0);
        symmetrize(&mut g);
        // E W⁻¹ E
        tmp.gemm(1.0, &e, &w_e, 0.0);
        std::mem::swap(&mut e, &mut tmp);
        let step = fro_diff(&h_next, &h);
        std::mem::swap(&mut h, &mut h_next);
        // E (and G) may grow on a mode that is not stabilised yet. On one
        // that H never sees (unreachable, or of zero weight) they overflow
        // and H with them: an H that had settled before is returned, and
        // the caller's stability check (or `explain`) names that mode.
        if !finite(&h) {
            if settled {
                return Ok((h_next, it - 1));
            }
            return Err(Error::Overflow {
                operation: "Riccati doubling",
            });
        }
        settled = step <= STEP_RTOL * fro(&h);
        if settled && fro(&e) <= E_TOL {
            return Ok((h, it));
        }
    }
    if settled {
        return Ok((h, MAX_ITERATIONS));
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
pub(super) fn lyapunov<N: Dim>(a: &Square<N>, c: &Square<N>) -> Option<Square<N>>
where
    DefaultAllocator: Allocator<N, N> + Allocator<N>,
{
    let n = a.nrows();
    let (dim, _) = a.shape_generic();
    let mut e = a.transpose();
    let mut f = c.clone();
    let mut tmp = Square::<N>::zeros_generic(dim, dim);
    let mut scaled = true;
    let mut last = false;
    for _ in 0..SIGN_ITERATIONS {
        let e_inv = inverse(&e, "Lyapunov sign iteration").ok()?;
        let k = if scaled {
            (fro(&e_inv) / fro(&e)).sqrt()
        } else {
            1.0
        };
        if !k.is_finite() || k == 0.0 {
            return None;
        }
        // F ← (k F + E⁻¹ F E⁻ᵀ / k) / 2
        tmp.gemm(1.0, &e_inv, &f, 0.0);
        f.gemm(0.5 / k, &tmp, &e_inv.transpose(), 0.5 * k);
        let mut change = 0.0;
        for (e, inv) in e.iter_mut().zip(e_inv.iter()) {
            let next = 0.5 * (k * *e + inv / k);
            change += (next - *e).powi(2);
            *e = next;
        }
        let change = change.sqrt();
        if !finite(&f) || !change.is_finite() {
            return None;
        }
        if last {
            break;
        }
        // Quadratic convergence: once a step is below √ε, one more
        // (unscaled) step reaches rounding level.
        if change <= 1e-2 * fro(&e) {
            scaled = false;
        }
        last = change <= 1e-8 * fro(&e);
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
    let mut x = f * 0.5;
    symmetrize(&mut x);
    Some(x)
}

/// The solution `X` of the Stein equation `X − Aᵀ X A = C` for `A` with
/// spectral radius below 1, by squared Smith (doubling):
/// `X = Σ (Aᵀ)ᵏ C Aᵏ` summed as `X ← X + Tᵀ X T`, `T ← T²`. `None` if the
/// series has not converged after [`SMITH_ITERATIONS`] steps or overflows.
pub(super) fn stein<N: Dim>(a: &Square<N>, c: &Square<N>) -> Option<Square<N>>
where
    DefaultAllocator: Allocator<N, N>,
{
    let (dim, _) = a.shape_generic();
    let mut x = c.clone();
    let mut t = a.clone();
    let mut tmp = Square::<N>::zeros_generic(dim, dim);
    let mut update = Square::<N>::zeros_generic(dim, dim);
    for _ in 0..SMITH_ITERATIONS {
        tmp.gemm(1.0, &x, &t, 0.0);
        gemm_tn(&mut update, 1.0, &t, &tmp, 0.0);
        x += &update;
        let (u, s) = (fro(&update), fro(&x));
        if !u.is_finite() || !s.is_finite() {
            return None;
        }
        if u <= f64::EPSILON * s {
            symmetrize(&mut x);
            return Some(x);
        }
        tmp.gemm(1.0, &t, &t, 0.0);
        std::mem::swap(&mut t, &mut tmp);
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{DMatrix, matrix};

    #[test]
    fn lyapunov_and_stein_solve_their_equations() {
        let a = matrix![-2.0, 1.0, 0.0; 0.0, -1.0, 3.0; 0.5, 0.0, -4.0];
        let c = nalgebra::Matrix3::from_fn(|i, j| if i == j { 1.0 + i as f64 } else { 0.2 });
        let x = lyapunov(&a, &c).unwrap();
        let res = a.transpose() * x + x * a + c;
        assert!(res.norm() < 1e-13 * c.norm(), "{res:?}");
        // Unstable A: no solution by this route.
        assert!(lyapunov(&(-a), &c).is_none());

        let d = a * 0.2;
        let x = stein(&d, &c).unwrap();
        let res = x - d.transpose() * x * d - c;
        assert!(res.norm() < 1e-14 * c.norm(), "{res:?}");
        assert!(stein(&(a * 2.0), &c).is_none());

        // The same solves sized at run time give the same numbers.
        let heap = |m: &nalgebra::Matrix3<f64>| DMatrix::from_column_slice(3, 3, m.as_slice());
        let x_dyn = lyapunov(&heap(&a), &heap(&c)).unwrap();
        assert_eq!(x_dyn.as_slice(), lyapunov(&a, &c).unwrap().as_slice());
    }

    #[test]
    fn fro_does_not_overflow_near_f64_max() {
        let m = matrix![f64::MAX, f64::MAX; 0.0, 0.0];
        assert!(fro(&m).is_infinite()); // √2 · MAX exceeds MAX.
        let m = matrix![1e300, 1e300; 0.0, 0.0];
        assert!((fro(&m) / (1e300 * 2f64.sqrt()) - 1.0).abs() < 1e-15);
        let m = matrix![3e-300, 4e-300; 0.0, 0.0];
        assert!((fro(&m) / 5e-300 - 1.0).abs() < 1e-15);
        assert_eq!(fro(&matrix![3.0, 4.0]), 5.0);
    }
}
