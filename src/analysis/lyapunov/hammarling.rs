//! Hammarling's method (1982) for the factor of a stable Lyapunov
//! equation's solution, `A X + X Aᵀ + B Bᵀ = 0` with `X = Rᵀ R`, on the
//! complex Schur form (MATLAB's `rsf2csf` of the real one), so that every
//! diagonal block is 1×1; `O(n³ + n² m)`.

use nalgebra::{Complex, DMatrix};

use super::bartels_stewart::{Condition, Schur, schur, singular_pair};
use super::{FactorOperands, LyapunovFactor, refuse, relative, sealed, unscale};
use crate::error::{Error, check_finite_dyn, check_shape};
use crate::kernels::reduce::pow2_floor;

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

/// Which equation [`factor`] solves.
#[derive(Clone, Copy)]
pub(super) enum Time {
    /// `A X + X Aᵀ + B Bᵀ = 0`, every eigenvalue with `Re λ < 0`.
    Continuous,
    /// `A X Aᵀ − X + B Bᵀ = 0`, every eigenvalue with `|λ| < 1`.
    Discrete,
}

/// The factor `R` (upper triangular, non-negative diagonal) with
/// `X = Rᵀ R` solving the `time` equation for `A` given by its real Schur
/// form, whose eigenvalues are all stable (`Re λ < 0`, or `|λ| < 1`);
/// `b` is `n × m`, `m ≥ 1`.
///
/// Both by Hammarling's recursion on the complex Schur form
/// `S Y + Y Sᴴ + C Cᴴ = 0` (or `S Y Sᴴ − Y + C Cᴴ = 0`), `Y = U Uᴴ`, `U`
/// upper triangular, from its last column back: with `λ = S_kk`, row `k`
/// of `C` reflected into `[0 … 0 γ]` and `c` the rest of that column,
/// `ρ = √(−2 Re λ)` (or `√(1 − |λ|²)`), `ν = |γ| / ρ`, `γ = ν ρ ω`:
///
/// - continuous: `(S₁₁ + λ̄ I) u = −(s ν + ρ ω̄ c)`, next `c ← c − ρ ω u`;
/// - discrete: `(λ̄ S₁₁ − I) u = −(λ̄ ν s + ρ ω̄ c)`, next
///   `c ← ρ ω (S₁₁ u + s ν) − λ c` (the rank-one term
///   `c cᴴ + w wᴴ − u uᴴ`, `w = S₁₁ u + s ν`, equals `y yᴴ` for this
///   `y`, since `u = λ̄ w + ρ ω̄ c`; Hammarling 1982, section 6).
pub(super) fn factor(schur: &Schur, b: &DMatrix<f64>, time: Time) -> DMatrix<f64> {
    let n = schur.t.nrows();
    let (q, s) = complex_schur(schur);
    // The equation for Y = Qᴴ X Q, C = Qᴴ B; Y = U Uᴴ.
    let mut c = q.adjoint() * b.map(|v| C64::new(v, 0.0));
    let mut u = DMatrix::<C64>::zeros(n, n);
    let last = c.ncols() - 1;
    for k in (0..n).rev() {
        let lambda = s[(k, k)];
        let rho = match time {
            Time::Continuous => (-2.0 * lambda.re).sqrt(),
            // 1 − |λ|² without the cancellation of 1 − |λ|·|λ| near 1.
            Time::Discrete => ((1.0 - lambda.norm()) * (1.0 + lambda.norm())).sqrt(),
        };
        let gamma = reflect_row(&mut c, k);
        let nu = gamma.norm() / rho;
        let omega = if gamma.norm() == 0.0 {
            C64::new(1.0, 0.0)
        } else {
            gamma / gamma.norm()
        };
        let lc = lambda.conj();
        // Back-substitution on the triangular system for u.
        let mut col = vec![C64::new(0.0, 0.0); k];
        for i in (0..k).rev() {
            let rhs = -(c[(i, last)] * omega.conj() * rho);
            let (mut v, diag) = match time {
                Time::Continuous => (rhs - s[(i, k)] * nu, s[(i, i)] + lc),
                Time::Discrete => (rhs - lc * s[(i, k)] * nu, lc * s[(i, i)] - 1.0),
            };
            for (j, cj) in col.iter().enumerate().skip(i + 1) {
                v -= match time {
                    Time::Continuous => s[(i, j)] * cj,
                    Time::Discrete => lc * s[(i, j)] * cj,
                };
            }
            col[i] = v / diag;
        }
        for (i, ui) in col.iter().enumerate() {
            u[(i, k)] = *ui;
        }
        match time {
            Time::Continuous => {
                for (i, ui) in col.iter().enumerate() {
                    c[(i, last)] -= omega * rho * ui;
                }
            }
            Time::Discrete => {
                for i in 0..k {
                    let w: C64 = s[(i, k)] * nu + (i..k).map(|j| s[(i, j)] * col[j]).sum::<C64>();
                    c[(i, last)] = omega * rho * w - lambda * c[(i, last)];
                }
            }
        }
        u[(k, k)] = C64::new(nu, 0.0);
    }
    real_factor(&(q * u))
}

/// The real upper-triangular `R` (non-negative diagonal) with
/// `Rᵀ R = Z Zᴴ` for a complex `Z` whose `Z Zᴴ` is real:
/// `X = P Pᵀ + W Wᵀ` for `Z = P + i W`, so `X = Mᵀ M` with
/// `M = [Pᵀ; Wᵀ]`, and `R` is `M`'s triangular factor.
fn real_factor(z: &DMatrix<C64>) -> DMatrix<f64> {
    let n = z.nrows();
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

/// `(A, B)` on the heap.
pub(super) type Operands = (DMatrix<f64>, DMatrix<f64>);

/// `A` and `B` of [`lyapchol`](super::lyapchol) and [`dlyapchol`] on the
/// heap, checked (square `A`, `B` with its rows, finite), or `None` when
/// there is nothing to solve (no states or no inputs: `R = 0`).
pub(super) fn operands<A, B>(a: &A, b: &B) -> Result<Option<Operands>, Error>
where
    A: FactorOperands<B>,
    B: sealed::Matrix,
{
    let (a, b) = (a.to_heap(), b.to_heap());
    let n = a.nrows();
    check_shape("A", &a, n, n)?;
    check_shape("B", &b, n, b.ncols())?;
    check_finite_dyn("A", &a)?;
    check_finite_dyn("B", &b)?;
    Ok((n > 0 && b.ncols() > 0).then_some((a, b)))
}

/// The zero factor of [`operands`]' `None`, of `a`'s size.
pub(super) fn trivial<A: sealed::Matrix>(a: &A) -> LyapunovFactor<A> {
    let n = a.to_heap().nrows();
    LyapunovFactor {
        factor: A::from_heap(DMatrix::zeros(n, n)),
        residual: 0.0,
    }
}

/// The Cholesky factor `R` of the solution of the discrete Lyapunov
/// (Stein) equation `A X Aᵀ − X + B Bᵀ = 0` for a Schur-stable `A` (every
/// eigenvalue inside the unit circle): `X = Rᵀ R`, `R` upper triangular
/// with a non-negative diagonal, MATLAB's `dlyapchol(A, B)`; `X` is then
/// the discrete controllability Gramian `Σₖ Aᵏ B Bᵀ (Aᵀ)ᵏ` of `(A, B)`
/// (in the units of `B` squared).
///
/// The discrete form of Hammarling's method (1982) on the complex Schur
/// form of `A`, `O(n³ + n² m)` for `B` `n × m`, as
/// [`lyapchol`](super::lyapchol): the factor directly, without forming
/// `B Bᵀ` or `X`. `B` is scaled by a power of two (exact); `A` is not
/// (the equation is not homogeneous in `A`).
///
/// # Errors
///
/// [`Error::DimensionMismatch`] for a non-square `A` or a `B` with
/// another number of rows (run-time sizes only); [`Error::NonFinite`];
/// [`Error::Unstable`] naming an eigenvalue of `A` with `|λ| ≥ 1`,
/// [`Error::SingularEquation`] for a stable pair within rounding of
/// `λ μ = 1` (as [`dlyap`](super::dlyap)); [`Error::NoConvergence`] if the
/// Schur iteration fails; [`Error::Overflow`] if `R` does not fit in
/// `f64`.
///
/// # Examples
///
/// ```
/// use ctrlab::analysis::{dlyap, dlyapchol};
/// use ctrlab::nalgebra::matrix;
///
/// // x[k+1] = 0.5 x[k] + u[k]: X = 1 / (1 − 0.25), R = √(4/3).
/// let r = dlyapchol(&matrix![0.5], &matrix![1.0])?;
/// assert!((r.factor[(0, 0)] - (4.0f64 / 3.0).sqrt()).abs() < 1e-15);
///
/// // A lightly damped sampled mode; RᵀR is dlyap's X.
/// let a = matrix![0.9, 0.3; -0.3, 0.9];
/// let b = matrix![0.0; 1.0];
/// let r = dlyapchol(&a, &b)?;
/// let x = dlyap(&a, &(b * b.transpose()))?.x;
/// assert!((r.factor.transpose() * r.factor - x).amax() < 1e-13);
/// assert!(r.residual < 1e-14);
///
/// // An integrator (z = 1) is refused.
/// assert!(matches!(dlyapchol(&matrix![1.0], &matrix![1.0]),
///                  Err(ctrlab::Error::Unstable { .. })));
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[doc(alias = "hammarling")]
pub fn dlyapchol<A, B>(a: &A, b: &B) -> Result<LyapunovFactor<A>, Error>
where
    A: FactorOperands<B>,
    B: sealed::Matrix,
{
    const OPERATION: &str = "discrete Lyapunov factor (dlyapchol)";
    let Some((a, b)) = operands(a, b)? else {
        return Ok(trivial(a));
    };
    // Scaled by 2^j (exact): R scales by 2^j.
    let beta = pow2_floor(b.amax());
    let b = b / beta;
    let s = schur(&a)?;
    if let Some(p) = s.eigenvalues.iter().find(|p| p.norm() >= 1.0) {
        return Err(Error::Unstable {
            operation: OPERATION,
            re: p.re,
            im: p.im,
        });
    }
    if let Some(pair) = singular_pair(&s, &s, Condition::Product) {
        return Err(refuse(
            "discrete Lyapunov equation A X Aᵀ − X + B Bᵀ = 0",
            "λ μ = 1",
            pair,
            1.0,
        ));
    }
    let r = factor(&s, &b, Time::Discrete);
    let x = r.transpose() * &r;
    let bb = &b * b.transpose();
    let axa = &a * &x * a.transpose();
    let res = (&axa - &x + &bb).norm();
    let residual = relative(res, &[axa.norm(), x.norm(), bb.norm()]);
    Ok(LyapunovFactor {
        factor: A::from_heap(unscale(r, beta, 1.0, OPERATION)?),
        residual,
    })
}
