//! Small dense kernels written once for fixed-size and run-time-sized
//! matrices: generic over nalgebra's [`Dim`] (`Const<N>` for a `SMatrix`,
//! `Dyn` for a `DMatrix`), so a fixed-size caller gets stack matrices and
//! no allocation, and a run-time-sized caller the same arithmetic on the
//! heap. nalgebra's own `lu()` needs `DimMin` bounds that a plain
//! `const N: usize` cannot state, hence these.

use nalgebra::{
    Complex, DefaultAllocator, Dim, Dyn, Matrix, OMatrix, OVector, Storage, U1, Vector,
    allocator::Allocator,
};

use crate::error::Error;

/// The allocations a system with `N` states and `M` inputs needs for its
/// matrices and vectors (of any element type): one bound instead of six,
/// met by every pair of dimensions nalgebra can allocate, `Const` (stack)
/// or `Dyn` (heap). Placement and the Riccati solvers are written over it.
pub(crate) trait SystemAlloc<N: Dim, M: Dim>:
    Allocator<N, N> + Allocator<N, M> + Allocator<M, N> + Allocator<M, M> + Allocator<N> + Allocator<M>
{
}

impl<N: Dim, M: Dim, T> SystemAlloc<N, M> for T where
    T: Allocator<N, N>
        + Allocator<N, M>
        + Allocator<M, N>
        + Allocator<M, M>
        + Allocator<N>
        + Allocator<M>
{
}

/// LU factors with partial pivoting, `P A = L U`, packed in one matrix.
#[derive(Debug, Clone)]
pub(crate) struct Lu<N: Dim>
where
    DefaultAllocator: Allocator<N, N> + Allocator<N>,
{
    lu: OMatrix<f64, N, N>,
    perm: OVector<usize, N>,
}

impl<N: Dim> Lu<N>
where
    DefaultAllocator: Allocator<N, N> + Allocator<N>,
{
    /// Factors `a`; refuses a matrix whose smallest pivot is negligible
    /// against its largest (`≤ N·ε·max`), i.e. singular to working precision.
    pub(crate) fn new(a: &OMatrix<f64, N, N>, operation: &'static str) -> Result<Self, Error> {
        Self::with_pivot_ratio(a, operation, f64::EPSILON)
    }

    /// Factors `a`, refusing only a zero or non-finite pivot: for a matrix
    /// nonsingular by construction however ill-conditioned (the doubling's
    /// `I + G H` with `G`, `H` positive semidefinite has every eigenvalue
    /// at least 1), where the solves stay accurate in the directions that
    /// matter and a pivot ratio below `N·ε` is no sign of singularity.
    pub(crate) fn structurally(
        a: &OMatrix<f64, N, N>,
        operation: &'static str,
    ) -> Result<Self, Error> {
        Self::with_pivot_ratio(a, operation, 0.0)
    }

    /// Factors `a`, refusing a smallest pivot at or below `N·ratio` times
    /// the largest.
    fn with_pivot_ratio(
        a: &OMatrix<f64, N, N>,
        operation: &'static str,
        ratio: f64,
    ) -> Result<Self, Error> {
        let mut lu = a.clone();
        let (dim, _) = lu.shape_generic();
        let n = dim.value();
        let mut perm = OVector::<usize, N>::from_fn_generic(dim, U1, |i, _| i);
        let mut max_pivot = 0.0f64;
        let mut min_pivot = f64::INFINITY;
        for k in 0..n {
            let mut p = k;
            for i in k + 1..n {
                if lu[(i, k)].abs() > lu[(p, k)].abs() {
                    p = i;
                }
            }
            if p != k {
                lu.swap_rows(p, k);
                perm.swap_rows(p, k);
            }
            let pivot = lu[(k, k)];
            max_pivot = max_pivot.max(pivot.abs());
            min_pivot = min_pivot.min(pivot.abs());
            if pivot == 0.0 || !pivot.is_finite() {
                return Err(Error::Singular { operation });
            }
            // Column-major storage: the multipliers (column k below the
            // diagonal), then the rank-one update one column at a time, so
            // the inner loop runs down contiguous memory.
            let data = lu.as_mut_slice();
            let (left, right) = data.split_at_mut((k + 1) * n);
            let multipliers = &mut left[k * n + k + 1..];
            for l in multipliers.iter_mut() {
                *l /= pivot;
            }
            for column in right.chunks_exact_mut(n) {
                let u = column[k];
                for (x, l) in column[k + 1..].iter_mut().zip(multipliers.iter()) {
                    *x -= l * u;
                }
            }
        }
        if n > 0 && min_pivot <= (n as f64) * ratio * max_pivot {
            return Err(Error::Singular { operation });
        }
        Ok(Self { lu, perm })
    }

    /// Solves `A X = B` for `X`.
    pub(crate) fn solve<K: Dim>(&self, b: &OMatrix<f64, N, K>) -> OMatrix<f64, N, K>
    where
        DefaultAllocator: Allocator<N, K>,
    {
        let n = self.perm.len();
        let (rows, cols) = b.shape_generic();
        let mut x = OMatrix::<f64, N, K>::zeros_generic(rows, cols);
        for (i, &p) in self.perm.iter().enumerate() {
            x.set_row(i, &b.row(p));
        }
        let lu = self.lu.as_slice();
        for x in x.as_mut_slice().chunks_exact_mut(n.max(1)) {
            // Forward substitution with unit-diagonal L, then back
            // substitution with U, both by columns of the factors
            // (contiguous in column-major storage).
            for j in 0..n {
                let xj = x[j];
                let (_, below) = x.split_at_mut(j + 1);
                for (xi, l) in below.iter_mut().zip(&lu[j * n + j + 1..(j + 1) * n]) {
                    *xi -= l * xj;
                }
            }
            for j in (0..n).rev() {
                let xj = x[j] / lu[j * n + j];
                x[j] = xj;
                for (xi, u) in x[..j].iter_mut().zip(&lu[j * n..j * n + j]) {
                    *xi -= u * xj;
                }
            }
        }
        x
    }

    /// The determinant of the factored matrix: the product of the pivots,
    /// signed by the row permutation.
    pub(crate) fn det(&self) -> f64 {
        let n = self.perm.len();
        let mut det: f64 = (0..n).map(|i| self.lu[(i, i)]).product();
        // The permutation's sign from its cycle decomposition.
        let mut seen =
            OVector::<bool, N>::from_element_generic(self.perm.shape_generic().0, U1, false);
        for start in 0..n {
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
    pub(crate) fn solve_right<K: Dim>(
        a: &OMatrix<f64, N, N>,
        b: &OMatrix<f64, K, N>,
        operation: &'static str,
    ) -> Result<OMatrix<f64, K, N>, Error>
    where
        DefaultAllocator: Allocator<K, N> + Allocator<N, K>,
    {
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
pub(crate) fn householder_q<N: Dim>(
    a: &OMatrix<Complex<f64>, N, N>,
    k: usize,
) -> OMatrix<Complex<f64>, N, N>
where
    DefaultAllocator: Allocator<N, N> + Allocator<N>,
{
    let (dim, _) = a.shape_generic();
    let n = dim.value();
    let mut r = a.clone();
    let mut q = OMatrix::<Complex<f64>, N, N>::identity_generic(dim, dim);
    let mut v = OVector::<Complex<f64>, N>::zeros_generic(dim, U1);
    for j in 0..k.min(n) {
        let norm = (j..n).map(|i| r[(i, j)].norm_sqr()).sum::<f64>().sqrt();
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
        for i in j..n {
            v[i] = r[(i, j)];
        }
        v[j] += phase * norm;
        let v_norm = (j..n).map(|i| v[i].norm_sqr()).sum::<f64>().sqrt();
        for i in j..n {
            v[i] /= v_norm;
        }
        // R ← H R and Q ← Q H with H = I − 2 v vᴴ.
        // The sums as plain loops: `Sum for Complex` is not inlined, and
        // was a sixth of `place`'s time. Same terms, same order.
        for c in 0..n {
            let mut dot = Complex::new(0.0, 0.0);
            for i in j..n {
                dot += v[i].conj() * r[(i, c)];
            }
            for i in j..n {
                r[(i, c)] -= v[i] * dot * 2.0;
            }
        }
        for row in 0..n {
            let mut dot = Complex::new(0.0, 0.0);
            for i in j..n {
                dot += q[(row, i)] * v[i];
            }
            for i in j..n {
                q[(row, i)] -= dot * v[i].conj() * 2.0;
            }
        }
    }
    q
}

/// `a b` by the product nalgebra runs on run-time-sized matrices
/// (matrixmultiply's when every side exceeds 5, else a column loop), into a
/// stack matrix for fixed sizes: nalgebra's fixed-size product sums in
/// another order above 5, and a caller written once should give a
/// fixed-size model the run-time-sized result to the bit.
pub(crate) fn mul<R: Dim, K: Dim, C: Dim>(
    a: &OMatrix<f64, R, K>,
    b: &OMatrix<f64, K, C>,
) -> OMatrix<f64, R, C>
where
    DefaultAllocator: Allocator<R, K> + Allocator<K, C> + Allocator<R, C>,
{
    let ((r, k), c) = (a.shape(), b.ncols());
    let mut out = OMatrix::zeros_generic(a.shape_generic().0, b.shape_generic().1);
    out.generic_view_mut((0, 0), (Dyn(r), Dyn(c))).gemm(
        1.0,
        &a.generic_view((0, 0), (Dyn(r), Dyn(k))),
        &b.generic_view((0, 0), (Dyn(k), Dyn(c))),
        0.0,
    );
    out
}

/// `aᴴ b` by nalgebra's run-time-sized loop, for the reason of [`mul`]:
/// its fixed-size 4-vector case sums in another order.
pub(crate) fn dotc<R: Dim, S1, S2>(
    a: &Vector<Complex<f64>, R, S1>,
    b: &Vector<Complex<f64>, R, S2>,
) -> Complex<f64>
where
    S1: Storage<Complex<f64>, R>,
    S2: Storage<Complex<f64>, R>,
{
    let rows = Dyn(a.nrows());
    a.rows_generic(0, rows).dotc(&b.rows_generic(0, rows))
}

/// `‖v‖ = √(vᴴ v)` as nalgebra's `norm` computes it, summed as [`dotc`].
pub(crate) fn norm<R: Dim, S: Storage<Complex<f64>, R>>(v: &Vector<Complex<f64>, R, S>) -> f64 {
    dotc(v, v).re.sqrt()
}

/// `‖m‖_F` without overflowing early (nalgebra's `norm` squares the
/// entries): the matrix is divided by the power of two at its largest
/// entry (exact) first.
pub(crate) fn frobenius(m: &nalgebra::DMatrix<f64>) -> f64 {
    let s = crate::kernels::reduce::pow2_floor(m.amax());
    (m / s).norm() * s
}

/// The 1-norm (largest column sum of magnitudes).
pub(crate) fn norm1<R: Dim, C: Dim, S: Storage<f64, R, C>>(m: &Matrix<f64, R, C, S>) -> f64 {
    m.column_iter()
        .map(|c| c.iter().map(|v| v.abs()).sum::<f64>())
        .fold(0.0, f64::max)
}

/// How close to the stability boundary a computed pole of `a` must be to
/// count as *on* it: eigenvalues are computed to about `ε ‖A‖`, so a pole
/// within `100 N ε max(1, ‖A‖₁)` of the boundary (a rigid-body mode whose
/// exact value is 0, say) is marginal, not stable.
pub(crate) fn boundary_tolerance<N: Dim, S: Storage<f64, N, N>>(a: &Matrix<f64, N, N, S>) -> f64 {
    100.0 * a.nrows() as f64 * f64::EPSILON * norm1(a).max(1.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{DMatrix, DVector, SMatrix, dmatrix, matrix};

    #[test]
    fn run_time_sized_factors_match_fixed_size_ones_bit_for_bit() {
        let a = matrix![0.0, 2.0, 1.0; 1.0, 1.0, 0.0; 3.0, 0.0, 1.0];
        let b = matrix![1.0, -2.0; 2.0, 0.5; -1.0, 3.0];
        let ad = DMatrix::from_column_slice(3, 3, a.as_slice());
        let bd = DMatrix::from_column_slice(3, 2, b.as_slice());
        let (fixed, dynamic) = (Lu::new(&a, "t").unwrap(), Lu::new(&ad, "t").unwrap());
        assert_eq!(fixed.solve(&b).as_slice(), dynamic.solve(&bd).as_slice());
        assert_eq!(fixed.det(), dynamic.det());
        assert!(Lu::new(&dmatrix![1.0, 2.0; 2.0, 4.0], "t").is_err());
        // An empty matrix factors (nothing to pivot) and solves to nothing.
        let empty = Lu::new(&DMatrix::<f64>::zeros(0, 0), "t").unwrap();
        assert_eq!(empty.solve(&DMatrix::zeros(0, 2)).shape(), (0, 2));
        assert_eq!(empty.det(), 1.0);
    }

    #[test]
    fn products_and_dot_products_match_run_time_sized_ones_bit_for_bit() {
        // Data for which nalgebra 0.35's fixed-size `a * b`, `v.norm()` and
        // `v.dotc(&(1.7 v))` differ from the run-time-sized ones in the last
        // bit. 6 × 6: the run-time-sized product is matrixmultiply's.
        let a = SMatrix::<f64, 6, 6>::from_fn(|i, j| ((i * 7 + j * 3) % 11) as f64 / 7.0 - 0.6);
        let b = SMatrix::<f64, 6, 6>::from_fn(|i, j| ((i * 5 + j * 2) % 13) as f64 / 3.0 - 1.9);
        let (ad, bd) = (
            DMatrix::from_column_slice(6, 6, a.as_slice()),
            DMatrix::from_column_slice(6, 6, b.as_slice()),
        );
        assert_eq!(mul(&a, &b).as_slice(), (&ad * &bd).as_slice());
        // 4-vectors: nalgebra's fixed-size dot product pairs the terms.
        let v = SMatrix::<Complex<f64>, 4, 1>::from_fn(|i, _| {
            Complex::new(0.1 + i as f64 / 3.0, 1.0 / (i as f64 + 1.5))
        });
        let vd = DVector::from_column_slice(v.as_slice());
        assert_eq!(dotc(&v, &v.map(|c| c * 1.7)), vd.dotc(&vd.map(|c| c * 1.7)));
        assert_eq!(norm(&v), vd.norm());
    }

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
