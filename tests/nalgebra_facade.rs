//! `ctrlab::nalgebra`'s construction macros against nalgebra's own: the same
//! types, values and order of evaluation for the same input. (That they work
//! without nalgebra as a dependency is what `scripts/readme-examples` checks:
//! its programs depend on ctrlab alone.)

use ctrlab::nalgebra as facade;
use std::cell::RefCell;

/// Compiles only if both arguments have the same type.
fn same_type<T>(_: &T, _: &T) {}

/// Each macro's result equals nalgebra's, and has its type.
macro_rules! check {
    ($name:ident [$($input:tt)*]) => {{
        let ours = facade::$name![$($input)*];
        let theirs = nalgebra::$name![$($input)*];
        same_type(&ours, &theirs);
        assert_eq!(ours, theirs, "{}![{}]", stringify!($name), stringify!($($input)*));
    }};
}

#[test]
fn fixed_and_dynamic_matrices_equal_nalgebras() {
    check!(matrix[1]);
    check!(matrix[1, 2]);
    check!(matrix[1; 2]);
    check!(matrix[1, 2;]);
    check!(matrix[1, 2; 3, 4]);
    check!(matrix[1, 2, 3; 4, 5, 6;]);
    check!(matrix[1.5, -2.0 * 3.0; { let x = 4.0; x + 1.0 }, if true { 6.0 } else { 0.0 }]);
    // More than one step of eight columns, and a remainder.
    check!(matrix[1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16, 17;
                  18, 19, 20, 21, 22, 23, 24, 25, 26, 27, 28, 29, 30, 31, 32, 33, 34;
                  35, 36, 37, 38, 39, 40, 41, 42, 43, 44, 45, 46, 47, 48, 49, 50, 51]);
    check!(matrix[1, 2, 3, 4, 5, 6, 7, 8; 9, 10, 11, 12, 13, 14, 15, 16]);
    check!(dmatrix[1]);
    check!(dmatrix[1, 2]);
    check!(dmatrix[1; 2]);
    check!(dmatrix[1, 2; 3, 4;]);
    check!(dmatrix[1, 2, 3, 4, 5, 6, 7, 8, 9; 10, 11, 12, 13, 14, 15, 16, 17, 18]);

    let (ours, theirs): (facade::SMatrix<f64, 0, 0>, _) = (facade::matrix![], nalgebra::matrix![]);
    same_type(&ours, &theirs);
    let (ours, theirs): (facade::DMatrix<f64>, _) = (facade::dmatrix![], nalgebra::dmatrix![]);
    same_type(&ours, &theirs);
    assert_eq!(ours, theirs);
}

#[test]
fn vectors_and_points_equal_nalgebras() {
    check!(vector[1]);
    check!(vector[1, 2, 3]);
    check!(vector[1, 2, 3,]);
    check!(dvector[1.0, 2.0]);
    check!(dvector[1.0, 2.0,]);
    check!(point[1.0]);
    check!(point[1.0, 2.0, 3.0,]);

    let (ours, theirs): (facade::SVector<f64, 0>, _) = (facade::vector![], nalgebra::vector![]);
    same_type(&ours, &theirs);
    let (ours, theirs): (facade::DVector<f64>, _) = (facade::dvector![], nalgebra::dvector![]);
    same_type(&ours, &theirs);
    assert_eq!(ours, theirs);
    let (ours, theirs): (facade::Point<f64, 0>, _) = (facade::point![], nalgebra::point![]);
    same_type(&ours, &theirs);
}

#[test]
fn entries_are_evaluated_in_nalgebras_order() {
    // Column by column, as nalgebra's expansion lists them.
    let order = RefCell::new(Vec::new());
    let at = |i: i32| {
        order.borrow_mut().push(i);
        i
    };
    macro_rules! order_of {
        ($name:ident) => {{
            order.borrow_mut().clear();
            let _ = $name![at(1), at(2), at(3); at(4), at(5), at(6)];
            order.take()
        }};
    }
    let expected = {
        use nalgebra::matrix;
        order_of!(matrix)
    };
    assert_eq!(expected, [1, 4, 2, 5, 3, 6]);
    {
        use facade::matrix;
        assert_eq!(order_of!(matrix), expected);
    }
    {
        use facade::dmatrix;
        assert_eq!(order_of!(dmatrix), expected);
    }
}

#[test]
fn usable_in_constants() {
    const M: facade::SMatrix<f64, 2, 3> = facade::matrix![1.0, 2.0, 3.0; 4.0, 5.0, 6.0];
    const V: facade::SVector<f64, 2> = facade::vector![1.0, 2.0];
    const P: facade::Point<f64, 2> = facade::point![1.0, 2.0];
    assert_eq!(M, nalgebra::matrix![1.0, 2.0, 3.0; 4.0, 5.0, 6.0]);
    assert_eq!(V, nalgebra::vector![1.0, 2.0]);
    assert_eq!(P, nalgebra::point![1.0, 2.0]);
}

/// Entries that are not `Copy`, nor even `PartialEq`: the fixed-size
/// macros ask no more of `T` than nalgebra's.
#[test]
fn any_entry_type() {
    struct Opaque(u8);
    let m = facade::matrix![Opaque(1), Opaque(2); Opaque(3), Opaque(4)];
    assert_eq!(m[(1, 0)].0, 3);
    let d = facade::dmatrix![Opaque(1), Opaque(2); Opaque(3), Opaque(4)];
    assert_eq!(d[(0, 1)].0, 2);
    let v = facade::dvector![Opaque(5), Opaque(6)];
    assert_eq!(v[1].0, 6);
}
