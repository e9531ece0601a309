//! Balancing before the eigenvalue iterations, as LAPACK's `dgebal`
//! (`job = 'B'`, LAPACK ≥ 3.5) does it for NumPy's `eigvals` and SciPy:
//! rows and columns that isolate an eigenvalue are permuted out of the
//! way, then the rest is scaled by powers of two (exact) until each row
//! and the matching column have comparable 2-norms (Parlett and Reinsch,
//! 1969). The eigenvalues then come out with an error relative to the
//! balanced matrix's norm, not to that of an arbitrarily scaled one: a
//! badly scaled model (python-control's issue #935, coefficients from
//! 1e-31 to 1e-5) keeps its slow stable poles stable.

use nalgebra::DMatrix;

/// The radix of the scaling (exact in binary floating point).
const RADIX: f64 = 2.0;

/// A scaling step is taken when it shrinks `c + r` below this fraction.
const FACTOR: f64 = 0.95;

/// Scaling sweeps allowed (LAPACK loops until no row changes; a sweep
/// changes each scale by at least a factor 2, within the exponent range).
const SWEEPS: usize = 4096;

/// `a`, balanced by a permutation and a diagonal scaling (a similarity, so
/// the eigenvalues are `a`'s), and the range `lo..hi` of rows and columns
/// still coupled: outside it the matrix is upper triangular, its diagonal
/// entries are eigenvalues, and the eigenvalues of the block
/// `a[lo..hi, lo..hi]` are the others.
pub(super) fn balance(mut a: DMatrix<f64>) -> (DMatrix<f64>, usize, usize) {
    let n = a.nrows();
    let (mut lo, mut hi) = (0, n);
    // A row with no off-diagonal entry in the active columns isolates its
    // diagonal entry: move it to the bottom.
    while let Some(i) = (0..hi)
        .rev()
        .find(|&i| (0..hi).all(|j| j == i || a[(i, j)] == 0.0))
    {
        swap(&mut a, i, hi - 1);
        hi -= 1;
    }
    // A column with no off-diagonal entry in the active rows: to the left.
    while let Some(j) = (lo..hi).find(|&j| (lo..hi).all(|i| i == j || a[(i, j)] == 0.0)) {
        swap(&mut a, j, lo);
        lo += 1;
    }
    scale(&mut a, lo, hi);
    (a, lo, hi)
}

/// Swaps rows and columns `i` and `j` (a permutation similarity).
fn swap(a: &mut DMatrix<f64>, i: usize, j: usize) {
    if i != j {
        a.swap_rows(i, j);
        a.swap_columns(i, j);
    }
}

/// `dgebal`'s scaling loop on the block `lo..hi`.
fn scale(a: &mut DMatrix<f64>, lo: usize, hi: usize) {
    let n = a.nrows();
    let sfmin1 = f64::MIN_POSITIVE / (2.0 * f64::EPSILON);
    let sfmax1 = 1.0 / sfmin1;
    let sfmin2 = sfmin1 * RADIX;
    let sfmax2 = 1.0 / sfmin2;
    let mut scales = vec![1.0f64; n];
    for _ in 0..SWEEPS {
        let mut converged = true;
        for i in lo..hi {
            let norm = |v: &mut dyn Iterator<Item = f64>| v.map(|x| x * x).sum::<f64>().sqrt();
            let mut c = norm(&mut (lo..hi).map(|k| a[(k, i)]));
            let mut r = norm(&mut (lo..hi).map(|k| a[(i, k)]));
            let mut ca = (0..hi).map(|k| a[(k, i)].abs()).fold(0.0, f64::max);
            let mut ra = (lo..n).map(|k| a[(i, k)].abs()).fold(0.0, f64::max);
            if c == 0.0 || r == 0.0 || !(c + r).is_finite() {
                continue;
            }
            let s = c + r;
            let mut f: f64 = 1.0;
            let mut g = r / RADIX;
            while c < g && f.max(c).max(ca) < sfmax2 && r.min(g).min(ra) > sfmin2 {
                f *= RADIX;
                c *= RADIX;
                ca *= RADIX;
                r /= RADIX;
                g /= RADIX;
                ra /= RADIX;
            }
            g = c / RADIX;
            while g >= r && r.max(ra) < sfmax2 && f.min(c).min(g).min(ca) > sfmin2 {
                f /= RADIX;
                c /= RADIX;
                g /= RADIX;
                ca /= RADIX;
                r *= RADIX;
                ra *= RADIX;
            }
            if c + r >= FACTOR * s
                || (f < 1.0 && scales[i] < 1.0 && f * scales[i] <= sfmin1)
                || (f > 1.0 && scales[i] > 1.0 && scales[i] >= sfmax1 / f)
            {
                continue;
            }
            scales[i] *= f;
            converged = false;
            for k in lo..n {
                a[(i, k)] /= f;
            }
            for k in 0..hi {
                a[(k, i)] *= f;
            }
        }
        if converged {
            break;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::dmatrix;

    #[test]
    fn isolated_eigenvalues_are_permuted_out() {
        // Row 0 has no off-diagonal entry: eigenvalue 5 isolated.
        let a = dmatrix![5.0, 0.0, 0.0; 1.0, 2.0, 3.0; 4.0, 6.0, 7.0];
        let (b, lo, hi) = balance(a);
        assert_eq!((lo, hi), (0, 2));
        assert_eq!(b[(2, 2)], 5.0);
        assert_eq!((b[(2, 0)], b[(2, 1)]), (0.0, 0.0));
    }

    #[test]
    fn scaling_is_by_powers_of_two_and_evens_the_norms() {
        let a = dmatrix![1.0, 1e6; 1e-6, 2.0];
        let (b, lo, hi) = balance(a.clone());
        assert_eq!((lo, hi), (0, 2));
        assert_eq!(b.trace(), a.trace());
        let ratio = b[(0, 1)].abs() / b[(1, 0)].abs();
        assert!((0.25..=4.0).contains(&ratio), "{b}");
        // Exact: the products across the diagonal are unchanged.
        assert_eq!(b[(0, 1)] * b[(1, 0)], a[(0, 1)] * a[(1, 0)]);
    }
}
