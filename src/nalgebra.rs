//! The nalgebra this crate's matrices and vectors are, re-exported so that a
//! user need not depend on it, nor match its version.
//!
//! Everything of [nalgebra](https://docs.rs/nalgebra/0.35)'s is here under
//! `ctrlab::nalgebra`, but its construction macros are this crate's own:
//! nalgebra's `matrix!`, `vector!`, `dmatrix!`, `dvector!` and `point!`
//! are procedural macros whose expansion names `nalgebra::…`,
//! which resolves only in a crate that depends on nalgebra itself, so in a
//! crate that depends on ctrlab alone `ctrlab::nalgebra::vector![1.0]` would
//! not compile.
//!
//! The ones here take the same syntax (a
//! `,` between the entries of a row, a `;` between rows), produce the same
//! types (`SMatrix<T, R, C>`, `SVector<T, N>`, `DMatrix<T>`, `DVector<T>`,
//! `Point<T, N>`) with the entries evaluated in the same (column-major)
//! order, and name `ctrlab::nalgebra::…`; as nalgebra's, [`matrix!`],
//! [`vector!`] and [`point!`] work in `const` items. They also spare the
//! core nalgebra's proc-macro crate: ctrlab builds nalgebra without its
//! `macros` feature. (nalgebra's `stack!` is not offered: a crate that
//! wants it depends on nalgebra with that feature.)
//!
//! # Examples
//!
//! A crate that depends on ctrlab alone:
//!
//! ```
//! use ctrlab::nalgebra::{DMatrix, Matrix2, SMatrix, Vector2, dmatrix, matrix, vector};
//!
//! // The state-space matrices of a damped oscillator, and its state.
//! let a: SMatrix<f64, 2, 2> = matrix![0.0, 1.0; -4.0, -0.4];
//! let x = vector![1.0, 0.0];
//! assert_eq!(a * x, Vector2::new(0.0, -4.0));
//! assert_eq!(a, Matrix2::new(0.0, 1.0, -4.0, -0.4));
//!
//! // The same, sized at run time.
//! let d: DMatrix<f64> = dmatrix![0.0, 1.0; -4.0, -0.4];
//! assert_eq!(d, DMatrix::from_row_slice(2, 2, &[0.0, 1.0, -4.0, -0.4]));
//! ```
//!
//! `ctrlab::nalgebra` is the nalgebra of ctrlab's own types; values from it
//! are what [`StateSpace`](crate::StateSpace) and the rest take:
//!
//! ```
//! use ctrlab::StateSpace;
//! use ctrlab::nalgebra::matrix;
//!
//! let integrator = StateSpace::continuous(matrix![0.0], matrix![1.0], matrix![1.0], matrix![0.0])?;
//! assert_eq!(integrator.poles()?[0].re, 0.0);
//! # Ok::<(), ctrlab::Error>(())
//! ```

// Shown in the docs as nalgebra's items themselves (rustdoc inlines a glob
// re-export); nalgebra's six procedural construction macros that come with
// the glob are shadowed by the explicit re-exports below.
pub use ::nalgebra::*;

#[doc(inline)]
pub use crate::__ctrlab_dmatrix as dmatrix;
#[doc(inline)]
pub use crate::__ctrlab_dvector as dvector;
#[doc(inline)]
pub use crate::__ctrlab_matrix as matrix;
#[doc(inline)]
pub use crate::__ctrlab_point as point;
#[doc(inline)]
pub use crate::__ctrlab_vector as vector;

/// What the construction macros expand to and need at run time; not API.
#[doc(hidden)]
pub mod __private {
    use ::nalgebra::{Const, DMatrix, DVector, Dyn, VecStorage};

    /// A `DMatrix` of `R` rows and `C` columns from its columns, as
    /// `dmatrix!` builds it (nalgebra's expands to a column-major `vec!`).
    #[inline]
    pub fn dmatrix_from_columns<T, const R: usize, const C: usize>(
        columns: [[T; R]; C],
    ) -> DMatrix<T> {
        let data: Vec<T> = columns.into_iter().flatten().collect();
        DMatrix::from_vec_storage(VecStorage::new(Dyn(R), Dyn(C), data))
    }

    /// A `DVector` from its entries, as `dvector!` builds it.
    #[inline]
    pub fn dvector_from_array<T, const N: usize>(entries: [T; N]) -> DVector<T> {
        DVector::from_vec_storage(VecStorage::new(Dyn(N), Const::<1>, Vec::from(entries)))
    }
}

/// Construct a fixed-size matrix from its entries: `ctrlab::nalgebra::matrix!`.
///
/// nalgebra's [`matrix!`](https://docs.rs/nalgebra/0.35/nalgebra/macro.matrix.html),
/// usable where nalgebra is not a dependency (see [the module](crate::nalgebra)). A `,`
/// separates the entries of a row and a `;` the rows; every row has the same
/// number of entries, a row has no trailing `,`, the last row may have a
/// trailing `;`, and `matrix![]` is the 0 × 0 matrix. The entries are any
/// expressions of one type `T`; the result is an `SMatrix<T, R, C>`
/// (`Matrix<T, Const<R>, Const<C>, ArrayStorage<T, R, C>>`). Usable in
/// `const` items. Unlike nalgebra's, a matrix of two or more rows and more
/// than about 960 columns needs a `#![recursion_limit]` above the default.
///
/// # Examples
///
/// ```
/// use ctrlab::nalgebra::{Matrix2x3, SMatrix, matrix};
///
/// let m = matrix![1.0, 2.0, 3.0;
///                 4.0, 5.0, 6.0];
/// assert_eq!(m, Matrix2x3::new(1.0, 2.0, 3.0, 4.0, 5.0, 6.0));
/// assert_eq!(m[(1, 0)], 4.0); // row 1, column 0
///
/// // Any expressions; a trailing `;` after the last row.
/// let theta = 0.5f64;
/// let rotation = matrix![theta.cos(), -theta.sin();
///                        theta.sin(),  theta.cos();];
/// assert!((rotation.determinant() - 1.0).abs() < 1e-15);
///
/// // In a constant, and the empty matrix.
/// const B: SMatrix<f64, 2, 1> = matrix![0.0; 2.0];
/// assert_eq!(B.sum(), 2.0);
/// let empty: SMatrix<f64, 0, 0> = matrix![];
/// assert!(empty.is_empty());
/// ```
#[doc(hidden)]
#[macro_export]
macro_rules! __ctrlab_matrix {
    () => {
        $crate::nalgebra::SMatrix::<_, 0, 0>::from_array_storage($crate::nalgebra::ArrayStorage([]))
    };
    ($($($entry:expr),+);+ $(;)?) => {
        $crate::nalgebra::SMatrix::from_array_storage($crate::nalgebra::ArrayStorage(
            $crate::__ctrlab_columns!($([$($entry),+])+)
        ))
    };
}

/// Construct a matrix sized at run time from its entries:
/// `ctrlab::nalgebra::dmatrix!`.
///
/// nalgebra's [`dmatrix!`](https://docs.rs/nalgebra/0.35/nalgebra/macro.dmatrix.html),
/// usable where nalgebra is not a dependency (see [the module](crate::nalgebra)): the
/// syntax of [`matrix!`](crate::nalgebra::matrix) (`dmatrix![]` is 0 × 0, and
/// the same limit of about 960 columns), a `DMatrix<T>` as the result.
///
/// # Examples
///
/// ```
/// use ctrlab::nalgebra::{DMatrix, dmatrix};
///
/// let m = dmatrix![1.0, 2.0, 3.0;
///                  4.0, 5.0, 6.0];
/// assert_eq!(m.shape(), (2, 3));
/// assert_eq!(m, DMatrix::from_row_slice(2, 3, &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0]));
///
/// let empty: DMatrix<f64> = dmatrix![];
/// assert_eq!(empty.shape(), (0, 0));
/// ```
#[doc(hidden)]
#[macro_export]
macro_rules! __ctrlab_dmatrix {
    () => {
        $crate::nalgebra::__private::dmatrix_from_columns::<_, 0, 0>([])
    };
    ($($($entry:expr),+);+ $(;)?) => {
        $crate::nalgebra::__private::dmatrix_from_columns($crate::__ctrlab_columns!($([$($entry),+])+))
    };
}

/// Construct a fixed-size column vector from its entries:
/// `ctrlab::nalgebra::vector!`.
///
/// nalgebra's [`vector!`](https://docs.rs/nalgebra/0.35/nalgebra/macro.vector.html),
/// usable where nalgebra is not a dependency (see [the module](crate::nalgebra)): the
/// entries separated by `,`, with an optional trailing `,` (as `vec!`);
/// `vector![]` has none. The result is an `SVector<T, N>`. Usable in `const`
/// items.
///
/// # Examples
///
/// ```
/// use ctrlab::nalgebra::{SVector, Vector3, vector};
///
/// let v = vector![1.0, 2.0, 3.0,];
/// assert_eq!(v, Vector3::new(1.0, 2.0, 3.0));
/// assert_eq!(v.dot(&v), 14.0);
///
/// const X0: SVector<f64, 2> = vector![0.0, 0.0];
/// assert_eq!(X0.norm(), 0.0);
/// let none: SVector<f64, 0> = vector![];
/// assert!(none.is_empty());
/// ```
#[doc(hidden)]
#[macro_export]
macro_rules! __ctrlab_vector {
    () => {
        $crate::nalgebra::SVector::from_array_storage($crate::nalgebra::ArrayStorage([[]]))
    };
    ($($entry:expr),+ $(,)?) => {
        $crate::nalgebra::SVector::from_array_storage($crate::nalgebra::ArrayStorage([[$($entry),+]]))
    };
}

/// Construct a column vector sized at run time from its entries:
/// `ctrlab::nalgebra::dvector!`.
///
/// nalgebra's [`dvector!`](https://docs.rs/nalgebra/0.35/nalgebra/macro.dvector.html),
/// usable where nalgebra is not a dependency (see [the module](crate::nalgebra)): the
/// syntax of [`vector!`](crate::nalgebra::vector), a `DVector<T>` as the
/// result.
///
/// # Examples
///
/// ```
/// use ctrlab::nalgebra::{DVector, dvector};
///
/// let v = dvector![1.0, 2.0, 3.0];
/// assert_eq!(v.len(), 3);
/// assert_eq!(v, DVector::from_vec(vec![1.0, 2.0, 3.0]));
///
/// let none: DVector<f64> = dvector![];
/// assert!(none.is_empty());
/// ```
#[doc(hidden)]
#[macro_export]
macro_rules! __ctrlab_dvector {
    () => {
        $crate::nalgebra::__private::dvector_from_array([])
    };
    ($($entry:expr),+ $(,)?) => {
        $crate::nalgebra::__private::dvector_from_array([$($entry),+])
    };
}

/// Construct a fixed-size point from its coordinates:
/// `ctrlab::nalgebra::point!`.
///
/// nalgebra's [`point!`](https://docs.rs/nalgebra/0.35/nalgebra/macro.point.html),
/// usable where nalgebra is not a dependency (see [the module](crate::nalgebra)): the
/// syntax of [`vector!`](crate::nalgebra::vector), a `Point<T, N>` as the
/// result. Usable in `const` items.
///
/// # Examples
///
/// ```
/// use ctrlab::nalgebra::{Point, Point2, point, vector};
///
/// let p = point![3.0, 4.0];
/// assert_eq!(p, Point2::new(3.0, 4.0));
/// assert_eq!(p - Point2::origin(), vector![3.0, 4.0]);
///
/// const ORIGIN: Point<f64, 3> = point![0.0, 0.0, 0.0];
/// assert_eq!(ORIGIN.coords.norm(), 0.0);
/// ```
#[doc(hidden)]
#[macro_export]
macro_rules! __ctrlab_point {
    () => {
        $crate::nalgebra::Point { coords: $crate::__ctrlab_vector![] }
    };
    ($($entry:expr),+ $(,)?) => {
        $crate::nalgebra::Point { coords: $crate::__ctrlab_vector![$($entry),+] }
    };
}

/// The columns `[[a, c], [b, d]]` of the rows `[a, b] [c, d]`: the
/// column-major nested array nalgebra's `matrix!` builds, in the same order.
/// Eight columns a step, so that a matrix of two or more rows stays within
/// the default recursion limit (128) up to about 960 columns; a single row
/// needs no step.
#[doc(hidden)]
#[macro_export]
macro_rules! __ctrlab_columns {
    (@columns [$($columns:tt)*] $([])+) => {
        [$($columns)*]
    };
    (@columns [$($columns:tt)*] $([
        $c0:expr, $c1:expr, $c2:expr, $c3:expr, $c4:expr, $c5:expr, $c6:expr, $c7:expr
        $(, $rest:expr)*
    ])+) => {
        $crate::__ctrlab_columns!(@columns [$($columns)*
            [$($c0),+], [$($c1),+], [$($c2),+], [$($c3),+],
            [$($c4),+], [$($c5),+], [$($c6),+], [$($c7),+],
        ] $([$($rest),*])+)
    };
    (@columns [$($columns:tt)*] $([$first:expr $(, $rest:expr)*])+) => {
        $crate::__ctrlab_columns!(@columns [$($columns)* [$($first),+],] $([$($rest),*])+)
    };
    (@columns $columns:tt $($rows:tt)+) => {
        ::core::compile_error!("every row of a matrix must have the same number of entries")
    };
    ([$($entry:expr),+]) => {
        [$([$entry]),+]
    };
    ($($rows:tt)+) => {
        $crate::__ctrlab_columns!(@columns [] $($rows)+)
    };
}

/// What nalgebra's macros refuse, these refuse too (the twins that compile
/// are in `tests/nalgebra_facade.rs`).
///
/// A row with a trailing `,`:
/// ```compile_fail
/// let _: ctrlab::nalgebra::SMatrix<i32, 1, 2> = ctrlab::nalgebra::matrix![1, 2,];
/// ```
/// Rows of different lengths:
/// ```compile_fail
/// let _: ctrlab::nalgebra::DMatrix<i32> = ctrlab::nalgebra::dmatrix![1, 2; 3];
/// ```
/// A row without entries:
/// ```compile_fail
/// let _: ctrlab::nalgebra::SMatrix<i32, 2, 1> = ctrlab::nalgebra::matrix![1;; 2];
/// ```
/// A `,` without entries:
/// ```compile_fail
/// let _: ctrlab::nalgebra::SVector<i32, 0> = ctrlab::nalgebra::vector![,];
/// ```
#[cfg(doctest)]
pub struct RefusedSyntax;
