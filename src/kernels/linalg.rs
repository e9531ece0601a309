//! Small dense kernels on fixed-size matrices that nalgebra offers only behind
//! typenum bounds for a generic `N` (its `lu()` needs `Const<N>: DimMin`).
//! Keeping them here lets the public API take plain `const N: usize`.

use nalgebra::{Complex, DMatrix, SMatrix};

use crate::error::Error;

/// LU factors with partial pivoting, `P A = L U`, packed in one matrix.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Lu<const N: usize> {
    lu: SMatrix<f64, N, N>,
    perm: [usize; N],
}

impl<const N: usize> Lu<N> {
    /// Factors `a`; refuses a matrix whose smallest pivot is negligible
    /// against its largest (`≤ N·ε·max`), i.e. singular to working precision.
    pub(crate) fn new(a: &SMatrix<f64, N, N>, operation: &'static str) -> Result<Self, Error> {
        let mut lu = *a;
        let mut perm = [0usize; N];
        for (i, p) in perm.iter_mut().enumerate() {
            *p = i;
        }
        let mut max_pivot = 0.0f64;
        let mut min_pivot = f64::INFINITY;
        for k in 0..N {
            let mut p = k;
            for i in k + 1..N {
                if lu[(i, k)].abs() > lu[(p, k)].abs() {
                    p = i;
                }
            }
            if p != k {
                lu.swap_rows(p, k);
                perm.swap(p, k);
            }
            let pivot = lu[(k, k)];
            max_pivot = max_pivot.max(pivot.abs());
            min_pivot = min_pivot.min(pivot.abs());
            if pivot == 0.0 || !pivot.is_finite() {
                return Err(Error::Singular { operation });
            }
            for i in k + 1..N {
                let l = lu[(i, k)] / pivot;
                lu[(i, k)] = l;
                for j in k + 1..N {
                    lu[(i, j)] -= l * lu[(k, j)];
                }
            }
        }
        if N > 0 && min_pivot <= (N as f64) * f64::EPSILON * max_pivot {
            return Err(Error::Singular { operation });
        }
        Ok(Self { lu, perm })
    }

    /// Solves `A X = B` for `X`.
    pub(crate) fn solve<const K: usize>(&self, b: &SMatrix<f64, N, K>) -> SMatrix<f64, N, K> {
        let mut x = SMatrix::<f64, N, K>::zeros();
        for (i, &p) in self.perm.iter().enumerate() {
            x.set_row(i, &b.row(p));
        }
        for c in 0..K {
            // Forward substitution with unit-diagonal L.
            for i in 0..N {
                let mut s = x[(i, c)];
                for j in 0..i {
                    s -= self.lu[(i, j)] * x[(j, c)];
                }
                x[(i, c)] = s;
            }
            // Back substitution with U.
            for i in (0..N).rev() {
                let mut s = x[(i, c)];
                for j in i + 1..N {
                    s -= self.lu[(i, j)] * x[(j, c)];
                }
                x[(i, c)] = s / self.lu[(i, i)];
            }
        }
        x
    }

    /// The determinant of the factored matrix: the product of the pivots,
    /// signed by the row permutation.
    pub(crate) fn det(&self) -> f64 {
        let mut det: f64 = (0..N).map(|i| self.lu[(i, i)]).product();
        // The permutation's sign from its cycle decomposition.
        let mut seen = [false; N];
        for start in 0..N {
            let mut i = start;
            let mut length = 0;
            while !seen[i] {
                seen[i] = true;
                i = self.perm[i];
                length += 1;
            }
            if length % 2 == 0 && length > 0 {
                det = -det;
            }
        }
        det
    }

    /// Solves `X A = B` for `X` (a row-vector system), via `Aᵀ Xᵀ = Bᵀ`.
    pub(crate) fn solve_right<const K: usize>(
        a: &SMatrix<f64, N, N>,
        b: &SMatrix<f64, K, N>,
        operation: &'static str,
    ) -> Result<SMatrix<f64, K, N>, Error> {
        Ok(Lu::new(&a.transpose(), operation)?
            .solve(&b.transpose())
            .transpose())
    }
}

/// The full unitary factor `Q` (N × N) of a Householder QR of the first
/// `k` columns of `a` (`a[:, ..k] = Q R`): its last `N − k` columns are an
/// orthonormal basis of the orthogonal complement of those columns' span
/// (or of a subspace of it when they are dependent: a zero column is
/// skipped). Complex, so it serves complex eigenvector bases too.
pub(crate) fn householder_q<const N: usize>(
    a: &SMatrix<Complex<f64>, N, N>,
    k: usize,
) -> SMatrix<Complex<f64>, N, N> {
    let mut r = *a;
    let mut q = SMatrix::<Complex<f64>, N, N>::identity();
    let mut v = [Complex::new(0.0, 0.0); N];
    for j in 0..k.min(N) {
        let norm = (j..N).map(|i| r[(i, j)].norm_sqr()).sum::<f64>().sqrt();
        if norm == 0.0 {
            continue;
        }
        // v = x − α e₁ with α = −e^{i arg x₀} ‖x‖: no cancellation.
        let x0 = r[(j, j)];
        let phase = if x0.norm() > 0.0 {
            x0 / x0.norm()
        } else {
            Complex::new(1.0, 0.0)
        };
        for i in j..N {
            v[i] = r[(i, j)];
        }
        v[j] += phase * norm;
        let v_norm = (j..N).map(|i| v[i].norm_sqr()).sum::<f64>().sqrt();
        for vi in &mut v[j..] {
            *vi /= v_norm;
        }
        // R ← H R and Q ← Q H with H = I − 2 v vᴴ.
        for c in 0..N {
            let dot: Complex<f64> = (j..N).map(|i| v[i].conj() * r[(i, c)]).sum();
            for i in j..N {
                r[(i, c)] -= v[i] * dot * 2.0;
            }
        }
        for row in 0..N {
            let dot: Complex<f64> = (j..N).map(|i| q[(row, i)] * v[i]).sum();
            for i in j..N {
                q[(row, i)] -= dot * v[i].conj() * 2.0;
            }
        }
    }
    q
}

/// How close to the stability boundary a computed pole of `a` must be to
/// count as *on* it: eigenvalues are computed to about `ε ‖A‖`, so a pole
/// within `100 N ε max(1, ‖A‖₁)` of the boundary (a rigid-body mode whose
/// exact value is 0, say) is marginal, not stable.
pub(crate) fn boundary_tolerance_dyn(a: &DMatrix<f64>) -> f64 {
    // The 1-norm: largest column sum of magnitudes.
    let norm1 = a
        .column_iter()
        .map(|c| c.iter().map(|v| v.abs()).sum::<f64>())
        .fold(0.0, f64::max);
    100.0 * a.nrows() as f64 * f64::EPSILON * norm1.max(1.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::matrix;

    #[test]
    fn solves_with_pivoting() {
        // A zero in the (0,0) position forces a row swap.
        let a = matrix![0.0, 2.0, 1.0; 1.0, 1.0, 0.0; 3.0, 0.0, 1.0];
        let x_true = matrix![1.0, -2.0; 2.0, 0.5; -1.0, 3.0];
        let b = a * x_true;
        let x = Lu::new(&a, "test").unwrap().solve(&b);
        assert!((x - x_true).norm() < 1e-14);
        let xr = Lu::solve_right(&a, &x_true.transpose(), "test").unwrap();
        assert!((xr * a - x_true.transpose()).norm() < 1e-14);
    }

    #[test]
    fn determinant_with_row_swaps() {
        let a = matrix![0.0, 2.0, 1.0; 1.0, 1.0, 0.0; 3.0, 0.0, 1.0];
        // Expanded by the first row: 0 − 2 (1 − 0) + 1 (0 − 3) = −5.
        assert!((Lu::new(&a, "test").unwrap().det() + 5.0).abs() < 1e-14);
        let swap = matrix![0.0, 1.0; 1.0, 0.0];
        assert_eq!(Lu::new(&swap, "test").unwrap().det(), -1.0);
    }

    #[test]
    fn householder_q_is_unitary_and_spans_the_complement() {
        let c = |re, im| Complex::new(re, im);
        let a = matrix![c(1.0, 1.0), c(0.0, 2.0), c(0.0, 0.0);
                        c(2.0, 0.0), c(1.0, -1.0), c(0.0, 0.0);
                        c(0.5, 0.0), c(3.0, 0.0), c(0.0, 0.0)];
        let q = householder_q(&a, 2);
        assert!((q.adjoint() * q - SMatrix::<Complex<f64>, 3, 3>::identity()).norm() < 1e-14);
        // The last column is orthogonal to the two factored columns.
        let last = q.column(2);
        for j in 0..2 {
            assert!(last.dotc(&a.column(j)).norm() < 1e-14);
        }
        // A zero column is skipped, not divided by.
        let q0 = householder_q(&SMatrix::<Complex<f64>, 3, 3>::zeros(), 3);
        assert_eq!(q0, SMatrix::<Complex<f64>, 3, 3>::identity());
    }

    #[test]
    fn refuses_singular() {
        let a = matrix![1.0, 2.0; 2.0, 4.0];
        assert_eq!(
            Lu::new(&a, "op").unwrap_err(),
            Error::Singular { operation: "op" }
        );
        let z = SMatrix::<f64, 3, 3>::zeros();
        assert!(Lu::new(&z, "op").is_err());
    }
}
