//! A real Schur decomposition by the Francis double-shift QR iteration
//! with exceptional shifts (EISPACK's `hqr2`, as JAMA writes it, without
//! the eigenvector back-substitution): the fallback for nalgebra's Schur,
//! whose iteration has no exceptional shifts and stalls on repeated,
//! non-defective eigenvalues under a rotation (`Q diag(−1, −2, −1, …) Qᵀ`).

use nalgebra::DMatrix;

/// `(U, T)` with `A = U T Uᵀ`, `U` orthogonal and `T` upper
/// quasi-triangular (1×1 blocks and 2×2 blocks of complex pairs, exact
/// zeros elsewhere below the diagonal), or `None` if the iteration takes
/// more than `max_iterations` double steps in all.
pub(super) fn schur(
    a: &DMatrix<f64>,
    max_iterations: usize,
) -> Option<(DMatrix<f64>, DMatrix<f64>)> {
    let nn = a.nrows();
    let (mut v, mut h) = a.clone().hessenberg().unpack();
    for j in 0..nn {
        for i in j + 2..nn {
            h[(i, j)] = 0.0;
        }
    }
    if nn == 0 {
        return Some((v, h));
    }
    let eps = f64::EPSILON;
    let mut norm = 0.0;
    for i in 0..nn {
        for j in i.saturating_sub(1)..nn {
            norm += h[(i, j)].abs();
        }
    }
    let mut n = nn as isize - 1;
    let mut exshift = 0.0;
    let mut iter = 0usize;
    let mut total = 0usize;
    while n >= 0 {
        let nu = n as usize;
        // A single small subdiagonal entry.
        let mut l = nu;
        while l > 0 {
            let mut s = h[(l - 1, l - 1)].abs() + h[(l, l)].abs();
            if s == 0.0 {
                s = norm;
            }
            if h[(l, l - 1)].abs() <= eps * s {
                h[(l, l - 1)] = 0.0;
                break;
            }
            l -= 1;
        }
        if l == nu {
            // One root.
            h[(nu, nu)] += exshift;
            n -= 1;
            iter = 0;
        } else if l + 1 == nu {
            // Two roots.
            let w = h[(nu, nu - 1)] * h[(nu - 1, nu)];
            let p = (h[(nu - 1, nu - 1)] - h[(nu, nu)]) / 2.0;
            let q = p * p + w;
            h[(nu, nu)] += exshift;
            h[(nu - 1, nu - 1)] += exshift;
            if q >= 0.0 {
                // A real pair: split by a rotation.
                let z = if p >= 0.0 { p + q.sqrt() } else { p - q.sqrt() };
                let x = h[(nu, nu - 1)];
                let s = x.abs() + z.abs();
                // (s = 0 only for a zero block, already triangular.)
                let (p, q) = if s == 0.0 { (0.0, 1.0) } else { (x / s, z / s) };
                let r = (p * p + q * q).sqrt();
                let (p, q) = (p / r, q / r);
                for j in nu - 1..nn {
                    let z = h[(nu - 1, j)];
                    h[(nu - 1, j)] = q * z + p * h[(nu, j)];
                    h[(nu, j)] = q * h[(nu, j)] - p * z;
                }
                for i in 0..=nu {
                    let z = h[(i, nu - 1)];
                    h[(i, nu - 1)] = q * z + p * h[(i, nu)];
                    h[(i, nu)] = q * h[(i, nu)] - p * z;
                }
                for i in 0..nn {
                    let z = v[(i, nu - 1)];
                    v[(i, nu - 1)] = q * z + p * v[(i, nu)];
                    v[(i, nu)] = q * v[(i, nu)] - p * z;
                }
                h[(nu, nu - 1)] = 0.0;
            }
            n -= 2;
            iter = 0;
        } else {
            total += 1;
            if total > max_iterations {
                return None;
            }
            // The shift.
            let mut x = h[(nu, nu)];
            let mut y = h[(nu - 1, nu - 1)];
            let mut w = h[(nu, nu - 1)] * h[(nu - 1, nu)];
            if iter == 10 {
                // Wilkinson's exceptional shift.
                exshift += x;
                for i in 0..=nu {
                    h[(i, i)] -= x;
                }
                let s = h[(nu, nu - 1)].abs() + h[(nu - 1, nu - 2)].abs();
                x = 0.75 * s;
                y = x;
                w = -0.4375 * s * s;
            }
            if iter == 30 {
                // MATLAB's exceptional shift.
                let s = (y - x) / 2.0;
                let s = s * s + w;
                if s > 0.0 {
                    let s = if y < x { -s.sqrt() } else { s.sqrt() };
                    let s = x - w / ((y - x) / 2.0 + s);
                    for i in 0..=nu {
                        h[(i, i)] -= s;
                    }
                    exshift += s;
                    x = 0.964;
                    y = x;
                    w = x;
                }
            }
            iter += 1;
            double_step(&mut h, &mut v, l, nu, (x, y, w));
        }
    }
    // The bulges leave rounding errors below the subdiagonal (EISPACK
    // never reads them): zeros.
    for j in 0..nn {
        for i in j + 2..nn {
            h[(i, j)] = 0.0;
        }
    }
    Some((v, h))
}

/// One Francis double step on rows and columns `l..=n` of `h` (the
/// whole rows and columns updated, the transformations accumulated in
/// `v`), with the shift's `(x, y, w)`.
fn double_step(
    h: &mut DMatrix<f64>,
    v: &mut DMatrix<f64>,
    l: usize,
    n: usize,
    (x, y, w): (f64, f64, f64),
) {
    let nn = h.nrows();
    let eps = f64::EPSILON;
    // Two consecutive small subdiagonal entries.
    let mut m = n - 2;
    let (mut p, mut q, mut r);
    loop {
        let z = h[(m, m)];
        let (rr, ss) = (x - z, y - z);
        p = (rr * ss - w) / h[(m + 1, m)] + h[(m, m + 1)];
        q = h[(m + 1, m + 1)] - z - rr - ss;
        r = h[(m + 2, m + 1)];
        let s = p.abs() + q.abs() + r.abs();
        p /= s;
        q /= s;
        r /= s;
        if m == l {
            break;
        }
        if h[(m, m - 1)].abs() * (q.abs() + r.abs())
            < eps * (p.abs() * (h[(m - 1, m - 1)].abs() + z.abs() + h[(m + 1, m + 1)].abs()))
        {
            break;
        }
        m -= 1;
    }
    for i in m + 2..=n {
        h[(i, i - 2)] = 0.0;
        if i > m + 2 {
            h[(i, i - 3)] = 0.0;
        }
    }
    for k in m..n {
        let notlast = k != n - 1;
        let mut xk = 0.0;
        if k != m {
            p = h[(k, k - 1)];
            q = h[(k + 1, k - 1)];
            r = if notlast { h[(k + 2, k - 1)] } else { 0.0 };
            xk = p.abs() + q.abs() + r.abs();
            if xk == 0.0 {
                continue;
            }
            p /= xk;
            q /= xk;
            r /= xk;
        }
        let mut s = (p * p + q * q + r * r).sqrt();
        if p < 0.0 {
            s = -s;
        }
        if s == 0.0 {
            continue;
        }
        if k != m {
            h[(k, k - 1)] = -s * xk;
        } else if l != m {
            h[(k, k - 1)] = -h[(k, k - 1)];
        }
        p += s;
        let (x, y, z) = (p / s, q / s, r / s);
        let (q, r) = (q / p, r / p);
        for j in k..nn {
            let mut p = h[(k, j)] + q * h[(k + 1, j)];
            if notlast {
                p += r * h[(k + 2, j)];
                h[(k + 2, j)] -= p * z;
            }
            h[(k, j)] -= p * x;
            h[(k + 1, j)] -= p * y;
        }
        for i in 0..=n.min(k + 3) {
            let mut p = x * h[(i, k)] + y * h[(i, k + 1)];
            if notlast {
                p += z * h[(i, k + 2)];
                h[(i, k + 2)] -= p * r;
            }
            h[(i, k)] -= p;
            h[(i, k + 1)] -= p * q;
        }
        for i in 0..nn {
            let mut p = x * v[(i, k)] + y * v[(i, k + 1)];
            if notlast {
                p += z * v[(i, k + 2)];
                v[(i, k + 2)] -= p * r;
            }
            v[(i, k)] -= p;
            v[(i, k + 1)] -= p * q;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::signal::Rng;

    #[test]
    fn repeated_eigenvalues_under_a_rotation_converge() {
        for seed in 0..40u64 {
            let mut rng = Rng::new(seed);
            let n = 3 + (seed as usize % 30);
            let g = DMatrix::from_fn(n, n, |_, _| rng.gaussian());
            let q = g.qr().q();
            let d = DMatrix::from_fn(n, n, |i, j| match (i == j, i % 2) {
                (true, 0) => -1.0,
                (true, _) => -2.0,
                _ => 0.0,
            });
            let mut jordan = DMatrix::from_fn(n, n, |i, j| f64::from(u8::from(j == i + 1)));
            jordan.fill_diagonal(-0.5);
            let general = DMatrix::from_fn(n, n, |_, _| rng.gaussian());
            for a in [&q * d * q.transpose(), &q * jordan * q.transpose(), general] {
                let (u, t) = schur(&a, 200 * n).expect("converges");
                assert!(
                    (&u * &t * u.transpose() - &a).amax() < 1e-12 * a.amax().max(1.0) * n as f64
                );
                assert!((u.transpose() * &u - DMatrix::identity(n, n)).amax() < 1e-13 * n as f64);
                for j in 0..n {
                    for i in j + 2..n {
                        assert_eq!(t[(i, j)], 0.0);
                    }
                    if j + 2 < n {
                        assert!(
                            t[(j + 1, j)] == 0.0 || t[(j + 2, j + 1)] == 0.0,
                            "{seed}: {t}"
                        );
                    }
                }
            }
        }
    }
}
