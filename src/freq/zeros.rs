//! Invariant zeros of a state-space model, and the numerator of each
//! transfer-function entry (its zeros and gain), on which `ss2tf` and
//! `ss2zpk` are built.
//!
//! Square systems (as many inputs as outputs) only. With a feedthrough `D`
//! of full rank the zeros are the eigenvalues of `A − B D⁻¹ C`. With
//! `D = 0` and a first non-zero Markov parameter `L = C A^(r−1) B` of full
//! rank (uniform relative degree `r`: every SISO model, most MIMO ones)
//! they are the eigenvalues of the zero dynamics, `(I − B L⁻¹ C A^(r−1)) A`
//! restricted to the kernel of `[C; C A; …; C A^(r−1)]`: exactly
//! `n − r·m` of them, no spurious ones from the infinite zeros. Otherwise
//! (a singular `D` or `L`, mixed relative degrees) the finite generalized
//! eigenvalues of the Rosenbrock pencil `[A − sI, B; C, D]` are returned
//! through faer's QZ (`gevd`), as python-control does without Slycot; an
//! eigenvalue counts as infinite where `|α| > |β| ‖[A B; C D]‖_F / √ε`.

use nalgebra::{Complex, DMatrix};

use crate::analysis::{eigenvalues_dyn, rank};
use crate::error::Error;
use crate::kernels::reduce::pow2_floor;

/// Markov parameters `C A^k B` with their rounding scale `|C| |A|^k |B|`:
/// the index `k` (relative degree − 1) and the matrix of the first one not
/// zero to rounding (every entry within `64 (n + 1) ε` of its scale, the
/// bound on the rounding of forming the product), or `None` if all of the
/// first `n` are zero (the transfer matrix is `D`).
///
/// `A^k B` and its scale carry a common power-of-two factor (exact), so
/// neither overflows while the test is made (`B = 1e220` with `C A B` of
/// 1e440 was judged zero against an infinite scale, giving `G ≡ 0`).
///
/// # Errors
///
/// [`Error::Overflow`] if the first non-zero Markov parameter itself is not
/// a finite number, or its scale overflows.
fn first_markov(
    a: &DMatrix<f64>,
    b: &DMatrix<f64>,
    c: &DMatrix<f64>,
) -> Result<Option<(usize, DMatrix<f64>)>, Error> {
    let overflow = Error::Overflow {
        operation: "ss2tf (Markov parameter C A^k B)",
    };
    let n = a.nrows();
    let tol = 64.0 * (n as f64 + 1.0) * f64::EPSILON;
    let abs_a = a.abs();
    let abs_c = c.abs();
    let (mut x, mut w) = (b.clone(), b.abs());
    // x = 2^(−e) A^k B, w = 2^(−e) |A|^k |B|.
    let mut e: i32 = 0;
    for k in 0..n {
        let f = pow2_floor(w.amax());
        if !f.is_finite() {
            return Err(overflow);
        }
        x /= f;
        w /= f;
        e += exponent(f);
        let markov = c * &x;
        let scale = &abs_c * &w;
        if markov.iter().chain(scale.iter()).any(|v| !v.is_finite()) {
            return Err(overflow);
        }
        let nonzero = markov
            .iter()
            .zip(scale.iter())
            .any(|(m, s)| m.abs() > tol * s);
        if nonzero {
            let markov = markov.map(|m| times_pow2(m, e));
            if markov.iter().any(|v| !v.is_finite()) {
                return Err(overflow);
            }
            return Ok(Some((k, markov)));
        }
        x = a * x;
        w = &abs_a * w;
    }
    Ok(None)
}

/// The exponent of a power of two (normal or `f64::MIN_POSITIVE`).
fn exponent(f: f64) -> i32 {
    ((f.to_bits() >> 52) & 0x7ff) as i32 - 1023
}

/// `m · 2^e`, in steps that cannot overflow or underflow on the way.
fn times_pow2(mut m: f64, mut e: i32) -> f64 {
    while e > 1000 {
        m *= 2f64.powi(1000);
        e -= 1000;
    }
    while e < -1000 {
        m *= 2f64.powi(-1000);
        e += 1000;
    }
    m * 2f64.powi(e)
}

/// The invariant zeros of `(A, B, C, D)`, sorted by real then imaginary
/// part. Square systems only (see the module documentation).
pub(crate) fn invariant_zeros(
    a: &DMatrix<f64>,
    b: &DMatrix<f64>,
    c: &DMatrix<f64>,
    d: &DMatrix<f64>,
) -> Result<Vec<Complex<f64>>, Error> {
    let (n, m, p) = (a.nrows(), b.ncols(), c.nrows());
    if m != p {
        return Err(Error::InvalidMatrix {
            matrix: "D",
            reason: "invariant zeros are computed for square systems only \
                     (as many inputs as outputs); select a square subsystem",
        });
    }
    if n == 0 || m == 0 {
        return Ok(Vec::new());
    }
    let mut zeros = if rank(d, None)? == m {
        // x' = A x + B u with u = −D⁻¹ C x keeps y = 0.
        let lu = d.clone().lu();
        let k = lu.solve(c).ok_or(Error::Singular {
            operation: "invariant zeros (D⁻¹ C)",
        })?;
        eigenvalues_dyn(&(a - b * k))?
    } else if d.iter().all(|&v| v == 0.0) {
        match first_markov(a, b, c)? {
            // G ≡ 0: every s is a zero of the pencil's normal rank; none
            // is reported (python-control's QZ reports an arbitrary set).
            None => Vec::new(),
            Some((k, l)) if rank(&l, None)? == m => zero_dynamics(a, b, c, k, &l)?,
            Some(_) => pencil_zeros(a, b, c, d)?,
        }
    } else {
        pencil_zeros(a, b, c, d)?
    };
    zeros.sort_by(|x, y| x.re.total_cmp(&y.re).then(x.im.total_cmp(&y.im)));
    Ok(zeros)
}

/// Eigenvalues of the zero dynamics for a uniform relative degree `k + 1`
/// with decoupling matrix `l = C A^k B` of full rank.
fn zero_dynamics(
    a: &DMatrix<f64>,
    b: &DMatrix<f64>,
    c: &DMatrix<f64>,
    k: usize,
    l: &DMatrix<f64>,
) -> Result<Vec<Complex<f64>>, Error> {
    let (n, m) = (a.nrows(), b.ncols());
    let rows = (k + 1) * m;
    if rows >= n {
        return Ok(Vec::new());
    }
    // O = [C; C A; …; C A^k], each block row scaled to unit size (the
    // kernel does not change), and C A^k kept for the projector.
    let mut o = DMatrix::zeros(rows, n);
    let mut ca = c.clone();
    for j in 0..=k {
        if j > 0 {
            ca = &ca * a;
        }
        // Scaled by a power of two: the norm of an entry of 1e160 is no
        // longer infinite (which made this block row zero).
        let f = 1.0 / pow2_floor(ca.amax());
        o.rows_mut(j * m, m).copy_from(&(&ca * f));
    }
    let projector_rhs = l.clone().lu().solve(&ca).ok_or(Error::Singular {
        operation: "invariant zeros (decoupling matrix)",
    })?;
    let p = DMatrix::identity(n, n) - b * projector_rhs;
    // Orthonormal basis of ker O: the last n − rows columns of the full Q
    // of Oᵀ = Q R.
    let qr = o.transpose().qr();
    let mut qt = DMatrix::identity(n, n);
    qr.q_tr_mul(&mut qt);
    let v = qt.rows(rows, n - rows).transpose();
    let az = v.transpose() * p * a * &v;
    if az.iter().any(|x| !x.is_finite()) {
        return Err(Error::Overflow {
            operation: "invariant zeros (zero dynamics)",
        });
    }
    eigenvalues_dyn(&az)
}

/// Finite generalized eigenvalues of `[A B; C D] − s [I 0; 0 0]` (QZ).
fn pencil_zeros(
    a: &DMatrix<f64>,
    b: &DMatrix<f64>,
    c: &DMatrix<f64>,
    d: &DMatrix<f64>,
) -> Result<Vec<Complex<f64>>, Error> {
    let (n, m) = (a.nrows(), b.ncols());
    let size = n + m;
    let mut big = DMatrix::zeros(size, size);
    big.view_mut((0, 0), (n, n)).copy_from(a);
    big.view_mut((0, n), (n, m)).copy_from(b);
    big.view_mut((n, 0), (m, n)).copy_from(c);
    big.view_mut((n, n), (m, m)).copy_from(d);
    let mut e = DMatrix::zeros(size, size);
    e.view_mut((0, 0), (n, n)).fill_with_identity();
    let fa = faer::MatRef::from_column_major_slice(big.as_slice(), size, size);
    let fe = faer::MatRef::from_column_major_slice(e.as_slice(), size, size);
    let gevd = fa.generalized_eigen(fe).map_err(|_| Error::NoConvergence {
        operation: "QZ (invariant zeros)",
        iterations: 0,
    })?;
    let limit = big.norm() / f64::EPSILON.sqrt();
    let (sa, sb) = (gevd.S_a(), gevd.S_b());
    let mut out = Vec::new();
    for i in 0..size {
        let (alpha, beta) = (sa[i], sb[i]);
        let (alpha, beta) = (
            Complex::new(alpha.re, alpha.im),
            Complex::new(beta.re, beta.im),
        );
        if beta.norm() > 0.0 && alpha.norm() <= beta.norm() * limit {
            out.push(alpha / beta);
        }
    }
    if out.iter().any(|z| !(z.re.is_finite() && z.im.is_finite())) {
        return Err(Error::Overflow {
            operation: "invariant zeros (QZ)",
        });
    }
    Ok(out)
}

/// The numerator of the SISO channel `(output, input)` over the
/// characteristic polynomial of `A`: its zeros and its leading coefficient
/// (`D` if non-zero, else the first non-zero Markov parameter), so that
/// `G(s) = gain · ∏(s − zᵢ) / det(sI − A)`.
pub(crate) fn siso_numerator(
    a: &DMatrix<f64>,
    b: &DMatrix<f64>,
    c: &DMatrix<f64>,
    d: &DMatrix<f64>,
    output: usize,
    input: usize,
) -> Result<(Vec<Complex<f64>>, f64), Error> {
    let b = b.columns(input, 1).into_owned();
    let c = c.rows(output, 1).into_owned();
    let dv = d[(output, input)];
    let d = DMatrix::from_element(1, 1, dv);
    if dv != 0.0 {
        return Ok((invariant_zeros(a, &b, &c, &d)?, dv));
    }
    match first_markov(a, &b, &c)? {
        None => Ok((Vec::new(), 0.0)),
        Some((k, l)) => Ok((zero_dynamics(a, &b, &c, k, &l)?, l[(0, 0)])),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::dmatrix;

    #[test]
    fn zero_dynamics_and_pencil_agree_on_a_siso_model() {
        // (s + 3) / ((s + 1)(s + 2)(s + 4)) in controllable form.
        let a = dmatrix![-7.0, -14.0, -8.0; 1.0, 0.0, 0.0; 0.0, 1.0, 0.0];
        let b = dmatrix![1.0; 0.0; 0.0];
        let c = dmatrix![0.0, 1.0, 3.0];
        let d = dmatrix![0.0];
        let z = invariant_zeros(&a, &b, &c, &d).unwrap();
        assert_eq!(z.len(), 1);
        assert!((z[0] - Complex::new(-3.0, 0.0)).norm() < 1e-12);
        let q = pencil_zeros(&a, &b, &c, &d).unwrap();
        assert_eq!(q.len(), 1, "{q:?}");
        assert!((q[0] - Complex::new(-3.0, 0.0)).norm() < 1e-9);
        let (zs, gain) = siso_numerator(&a, &b, &c, &d, 0, 0).unwrap();
        assert_eq!(gain, 1.0);
        assert_eq!(zs.len(), 1);
    }
}
