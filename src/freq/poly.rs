//! Real polynomials in descending powers (`[c0, c1, …, cn]` is
//! `c0 sⁿ + … + cn`, as NumPy, python-control and MATLAB write them): the
//! crate-private arithmetic behind transfer functions and margins.

use nalgebra::{Complex, DMatrix};

use crate::analysis::eigenvalues_dyn;
use crate::error::Error;
use crate::kernels::reduce::pow2_floor;

/// The polynomial without its leading exact zeros (`[0]` for the zero
/// polynomial, `[]` stays `[]`).
pub(crate) fn trim(p: &[f64]) -> &[f64] {
    match p.iter().position(|&c| c != 0.0) {
        Some(i) => &p[i..],
        None => &p[p.len().saturating_sub(1)..],
    }
}

/// Horner's rule at a complex point.
pub(crate) fn eval(p: &[f64], s: Complex<f64>) -> Complex<f64> {
    let mut acc = Complex::new(0.0, 0.0);
    for &c in p {
        acc = acc * s + c;
    }
    acc
}

/// `num(s) / den(s)`; for `|s| > 1` through the reversed polynomials in
/// `1/s`, which keeps the powers of `s` from overflowing before they
/// cancel. `None` where `den(s) = 0` exactly.
pub(crate) fn eval_ratio(num: &[f64], den: &[f64], s: Complex<f64>) -> Option<Complex<f64>> {
    let (num, den) = (trim(num), trim(den));
    if s.norm() <= 1.0 {
        let d = eval(den, s);
        if d == Complex::new(0.0, 0.0) {
            return None;
        }
        return Some(div(eval(num, s), d));
    }
    let w = s.inv();
    let rev = |p: &[f64]| {
        let mut acc = Complex::new(0.0, 0.0);
        for &c in p.iter().rev() {
            acc = acc * w + c;
        }
        acc
    };
    let d = rev(den);
    if d == Complex::new(0.0, 0.0) {
        return None;
    }
    // num(s)/den(s) = s^(deg num − deg den) · rev_num(1/s) / rev_den(1/s).
    let excess = num.len() as i32 - den.len() as i32;
    Some(div(rev(num), d) * s.powi(excess))
}

/// `a / b` for `b ≠ 0`, `b` first scaled by a power of two (exactly) so
/// that `|b|²` can neither overflow nor underflow: num-complex's division
/// squares `|b|`, and `1e160 / 1e160` came out NaN (issue 28).
pub(crate) fn div(a: Complex<f64>, b: Complex<f64>) -> Complex<f64> {
    let f = pow2_floor(b.re.abs().max(b.im.abs()));
    let b = b / f;
    a * b.conj() / b.norm_sqr() / f
}

/// The product of two polynomials.
pub(crate) fn mul(a: &[f64], b: &[f64]) -> Vec<f64> {
    if a.is_empty() || b.is_empty() {
        return Vec::new();
    }
    let mut out = vec![0.0; a.len() + b.len() - 1];
    for (i, &x) in a.iter().enumerate() {
        for (j, &y) in b.iter().enumerate() {
            out[i + j] += x * y;
        }
    }
    out
}

/// `a − k·b`, aligned at the constant term.
pub(crate) fn sub_scaled(a: &[f64], k: f64, b: &[f64]) -> Vec<f64> {
    let n = a.len().max(b.len());
    let mut out = vec![0.0; n];
    for (i, &x) in a.iter().rev().enumerate() {
        out[n - 1 - i] += x;
    }
    for (i, &x) in b.iter().rev().enumerate() {
        out[n - 1 - i] -= k * x;
    }
    out
}

/// The monic real polynomial with the given roots, which must come in
/// conjugate pairs (the imaginary parts of the product, rounding noise,
/// are dropped).
pub(crate) fn from_roots(roots: &[Complex<f64>]) -> Vec<f64> {
    let mut p = vec![Complex::new(1.0, 0.0)];
    for &r in roots {
        p.push(Complex::new(0.0, 0.0));
        for i in (1..p.len()).rev() {
            let prev = p[i - 1];
            p[i] -= r * prev;
        }
    }
    p.iter().map(|c| c.re).collect()
}

/// The roots of a polynomial (leading zeros ignored): the eigenvalues of
/// its companion matrix, after scaling the variable by a power of two so
/// that the leading and constant coefficients match (NumPy's `roots`
/// relies on LAPACK's balancing for the same effect). Roots at zero are
/// split off exactly. Sorted as poles are (real part, then imaginary).
pub(crate) fn roots(p: &[f64]) -> Result<Vec<Complex<f64>>, Error> {
    let p = trim(p);
    if p.len() <= 1 {
        return Ok(Vec::new());
    }
    let zeros_at_origin = p.iter().rev().take_while(|&&c| c == 0.0).count();
    let q = &p[..p.len() - zeros_at_origin];
    let n = q.len() - 1;
    let mut out = vec![Complex::new(0.0, 0.0); zeros_at_origin];
    if n > 0 {
        // q(σ x) = Σ q_k σ^(n−k) x^(n−k): choose σ ≈ |q_n / q_0|^(1/n).
        let sigma = pow2_floor((q[n] / q[0]).abs().powf(1.0 / n as f64));
        let sigma = if sigma.is_finite() && sigma > 0.0 {
            sigma
        } else {
            1.0
        };
        let mut scaled = vec![0.0; n + 1];
        for (k, &c) in q.iter().enumerate() {
            scaled[k] = c * sigma.powi((n - k) as i32);
        }
        if scaled.iter().any(|c| !c.is_finite()) || scaled[0] == 0.0 {
            return Err(Error::Overflow {
                operation: "polynomial roots (scaling)",
            });
        }
        let mut companion = DMatrix::zeros(n, n);
        for k in 0..n {
            companion[(0, k)] = -scaled[k + 1] / scaled[0];
            if k + 1 < n {
                companion[(k + 1, k)] = 1.0;
            }
        }
        if companion.iter().any(|c| !c.is_finite()) {
            return Err(Error::Overflow {
                operation: "polynomial roots (companion matrix)",
            });
        }
        out.extend(eigenvalues_dyn(&companion)?.into_iter().map(|x| x * sigma));
    }
    if out.iter().any(|r| !(r.re.is_finite() && r.im.is_finite())) {
        return Err(Error::Overflow {
            operation: "polynomial roots",
        });
    }
    out.sort_by(|x, y| x.re.total_cmp(&y.re).then(x.im.total_cmp(&y.im)));
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn roots_of_a_product_are_its_factors() {
        // (s + 1)(s² + 2s + 5) s
        let p = mul(&mul(&[1.0, 1.0], &[1.0, 2.0, 5.0]), &[1.0, 0.0]);
        let r = roots(&p).unwrap();
        let want = [
            Complex::new(-1.0, -2.0),
            Complex::new(-1.0, 0.0),
            Complex::new(-1.0, 2.0),
            Complex::new(0.0, 0.0),
        ];
        assert_eq!(r.len(), 4);
        for w in want {
            assert!(r.iter().any(|r| (r - w).norm() < 1e-12), "{w} not in {r:?}");
        }
        let back = from_roots(&r);
        for (a, b) in back.iter().zip(&p) {
            assert!((a - b).abs() < 1e-12);
        }
    }

    #[test]
    fn ratio_at_large_s_does_not_overflow() {
        let num = [1.0; 40];
        let den = [1.0; 41];
        let s = Complex::new(1e10, 0.0);
        let g = eval_ratio(&num, &den, s).unwrap();
        assert!((g.re * 1e10 - 1.0).abs() < 1e-9);
        assert!(eval_ratio(&[1.0], &[1.0, 0.0], Complex::new(0.0, 0.0)).is_none());
    }

    #[test]
    fn trim_and_subtract() {
        assert_eq!(trim(&[0.0, 0.0, 2.0, 1.0]), &[2.0, 1.0]);
        assert_eq!(trim(&[0.0, 0.0]), &[0.0]);
        assert_eq!(
            sub_scaled(&[1.0, 2.0, 3.0], 2.0, &[1.0, 1.0]),
            vec![1.0, 0.0, 1.0]
        );
    }
}
