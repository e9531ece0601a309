//! Small dense kernels on fixed-size matrices that nalgebra offers only behind
//! typenum bounds for a generic `N` (its `lu()` needs `Const<N>: DimMin`).
//! Keeping them here lets the public API take plain `const N: usize`.

use nalgebra::SMatrix;

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

/// The 1-norm (largest column sum of magnitudes).
pub(crate) fn norm1<const R: usize, const C: usize>(m: &SMatrix<f64, R, C>) -> f64 {
    m.column_iter()
        .map(|c| c.iter().map(|v| v.abs()).sum::<f64>())
        .fold(0.0, f64::max)
}

/// How close to the stability boundary a computed pole of `a` must be to
/// count as *on* it: eigenvalues are computed to about `ε ‖A‖`, so a pole
/// within `100 N ε max(1, ‖A‖₁)` of the boundary (a rigid-body mode whose
/// exact value is 0, say) is marginal, not stable.
pub(crate) fn boundary_tolerance<const N: usize>(a: &SMatrix<f64, N, N>) -> f64 {
    100.0 * N as f64 * f64::EPSILON * norm1(a).max(1.0)
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
