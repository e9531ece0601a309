//! Pole placement for single-input systems, Ackermann's formula, and the
//! validation of target poles that [`place`](super::place) shares.

use nalgebra::{Complex, DMatrix, SMatrix};

use crate::analysis::rank;
use crate::error::Error;
use crate::kernels::linalg::Lu;
use crate::model::{Domain, StateSpace};

/// Relative distance within which two targets count as a conjugate pair.
const CONJUGATE_RTOL: f64 = 1e-10;

/// The state gain `K` that puts the poles of `A − B K` at `poles`, by
/// Ackermann's formula `K = [0 … 0 1] 𝒞⁻¹ φ(A)` with `𝒞` the
/// controllability matrix and `φ` the target characteristic polynomial.
///
/// Works for continuous (`s`, rad/s) and discrete (`z`) models alike.
/// Complex targets must come in conjugate pairs (matched to 1e-10 relative;
/// the pair is then used as exactly conjugate), so the gain is real. Like
/// python-control's `acker`, the formula is numerically fragile for large
/// `N` or a poorly conditioned `𝒞`; it is exact enough for the lab's four
/// states.
///
/// # Errors
///
/// [`Error::Uncontrollable`] with the numerical rank when `(A, B)` is not
/// controllable ([`rank`] with its default tolerance);
/// [`Error::InvalidParameter`] named `"poles"` for a non-finite target or
/// targets not closed under conjugation.
///
/// # Examples
///
/// ```
/// use ctrlab::{MassSpring, Cart, design::{StateFeedback, acker}};
/// use nalgebra::Complex;
///
/// let plant = MassSpring::nominal().state_space(Cart::Two)?;
/// let targets = [
///     Complex::new(-30.0, 30.0), Complex::new(-30.0, -30.0),
///     Complex::new(-40.0, 0.0), Complex::new(-50.0, 0.0),
/// ];
/// let k = acker(&plant, &targets)?;
/// let cl = StateFeedback::with_prefilter(&plant, k)?.closed_loop(&plant)?;
/// let p = cl.poles()?;
/// assert!((p[0] - Complex::new(-50.0, 0.0)).norm() < 1e-8);
/// assert!((p[3] - Complex::new(-30.0, 30.0)).norm() < 1e-8);
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub fn acker<const N: usize, const P: usize, D: Domain>(
    sys: &StateSpace<N, 1, P, D>,
    poles: &[Complex<f64>; N],
) -> Result<SMatrix<f64, 1, N>, Error> {
    let coeffs = real_polynomial(poles)?;
    let (a, b) = (sys.a(), sys.b());
    // Controllability matrix [B, A B, …, A^(N−1) B].
    let mut ctrb = SMatrix::<f64, N, N>::zeros();
    let mut col = *b;
    for j in 0..N {
        ctrb.set_column(j, &col);
        col = a * col;
    }
    if ctrb.iter().any(|v| !v.is_finite()) {
        return Err(Error::Overflow {
            operation: "controllability matrix",
        });
    }
    let r = rank(&DMatrix::from_fn(N, N, |i, j| ctrb[(i, j)]), None)?;
    if r < N {
        return Err(Error::Uncontrollable { rank: r, states: N });
    }
    // φ(A) by Horner: coeffs are monic, highest power first.
    let mut phi = SMatrix::<f64, N, N>::identity();
    for &c in &coeffs[1..] {
        phi = a * phi + SMatrix::<f64, N, N>::identity() * c;
    }
    let mut last = SMatrix::<f64, 1, N>::zeros();
    if N > 0 {
        last[N - 1] = 1.0;
    }
    // The rank test passed, so a failure here is the LU's stricter pivot
    // test on a nearly uncontrollable pair: say so, not "rank N of N".
    let row = Lu::solve_right(&ctrb, &last, "Ackermann (controllability matrix)")?;
    let k = row * phi;
    if k.iter().all(|v| v.is_finite()) {
        Ok(k)
    } else {
        Err(Error::Overflow {
            operation: "Ackermann gain",
        })
    }
}

/// Monic real polynomial with the given roots, highest power first
/// (`N + 1` coefficients, returned in a `Vec`: design time, not a hot loop).
fn real_polynomial<const N: usize>(poles: &[Complex<f64>; N]) -> Result<Vec<f64>, Error> {
    let paired = conjugate_pairs(poles)?;
    let mut coeffs = vec![1.0];
    let mul = |coeffs: &mut Vec<f64>, factor: &[f64]| {
        let mut out = vec![0.0; coeffs.len() + factor.len() - 1];
        for (i, &c) in coeffs.iter().enumerate() {
            for (j, &f) in factor.iter().enumerate() {
                out[i + j] += c * f;
            }
        }
        *coeffs = out;
    };
    let mut i = 0;
    while i < N {
        let p = paired[i];
        if p.im == 0.0 {
            mul(&mut coeffs, &[1.0, -p.re]);
            i += 1;
        } else {
            // (s − p)(s − p̄) = s² − 2 Re p s + |p|².
            mul(&mut coeffs, &[1.0, -2.0 * p.re, p.norm_sqr()]);
            i += 2;
        }
    }
    Ok(coeffs)
}

/// The targets validated and arranged for a real gain: all finite, closed
/// under conjugation (a partner matched to 1e-10 relative). Real targets
/// come out with an imaginary part of exactly 0; each complex pair comes out
/// adjacent, the one with positive imaginary part first and its exact
/// conjugate second.
pub(crate) fn conjugate_pairs<const N: usize>(
    poles: &[Complex<f64>; N],
) -> Result<[Complex<f64>; N], Error> {
    let bad = |value: f64, reason| Error::InvalidParameter {
        name: "poles",
        value,
        reason,
    };
    if let Some(p) = poles
        .iter()
        .find(|p| !(p.re.is_finite() && p.im.is_finite()))
    {
        return Err(bad(
            if p.re.is_finite() { p.im } else { p.re },
            "target poles must be finite",
        ));
    }
    let mut used = [false; N];
    let mut out = [Complex::new(0.0, 0.0); N];
    let mut next = 0;
    for i in 0..N {
        if used[i] {
            continue;
        }
        used[i] = true;
        let p = poles[i];
        let scale = p.norm().max(f64::MIN_POSITIVE);
        if p.im.abs() <= CONJUGATE_RTOL * scale {
            out[next] = Complex::new(p.re, 0.0);
            next += 1;
            continue;
        }
        // Closest unused partner to the conjugate.
        let partner = (i + 1..N)
            .filter(|&j| !used[j])
            .min_by(|&x, &y| {
                (poles[x] - p.conj())
                    .norm()
                    .total_cmp(&(poles[y] - p.conj()).norm())
            })
            .filter(|&j| (poles[j] - p.conj()).norm() <= CONJUGATE_RTOL * scale);
        let Some(j) = partner else {
            return Err(bad(
                p.im,
                "complex target poles must come in conjugate pairs",
            ));
        };
        used[j] = true;
        let upper = Complex::new(p.re, p.im.abs());
        out[next] = upper;
        out[next + 1] = upper.conj();
        next += 2;
    }
    Ok(out)
}
