use super::*;
use nalgebra::dmatrix;

/// A 4-state model with 2 inputs, 3 outputs and some feedthrough.
fn mimo() -> (DMatrix<f64>, DMatrix<f64>, DMatrix<f64>, DMatrix<f64>) {
    (
        dmatrix![-1.0, 2.0, 0.5, 0.0; -3.0, -0.2, 1.0, 4.0; 0.1, 0.0, -2.0, 1.0; 1.0, 1.0, -1.0, -0.5],
        dmatrix![1.0, 0.0; 0.0, 1.0; 1.0, 1.0; 0.5, -1.0],
        dmatrix![1.0, 0.0, 0.0, 1.0; 0.0, 2.0, -1.0, 0.0; 1.0, 1.0, 1.0, 1.0],
        dmatrix![0.0, 0.1; 0.2, 0.0; 0.0, 0.0],
    )
}

#[test]
fn matches_a_direct_solve() {
    let (a, b, c, d) = mimo();
    let mut ev = Evaluator::new(&a, &b, &c, &d);
    assert!(ev.columns.is_some());
    let s = C64::new(0.3, 1.7);
    let mut out = vec![C64::new(0.0, 0.0); 6];
    ev.eval(s, &mut out).unwrap();
    let mut pivoted = vec![C64::new(0.0, 0.0); 6];
    ev.pivoted.eval(s, &mut pivoted).unwrap();
    for (x, y) in out.iter().zip(&pivoted) {
        assert!((x - y).norm() < 1e-13, "{x} vs {y}");
    }
    // An input that reaches only part of the state: H decouples and the
    // pivoted solve takes over.
    let decoupled = Evaluator::new(
        &dmatrix![-1.0, 0.0; 0.0, -2.0],
        &dmatrix![1.0; 0.0],
        &dmatrix![1.0, 1.0],
        &dmatrix![0.0],
    );
    assert!(decoupled.columns.is_none());
    let ac = a.map(|v| C64::new(v, 0.0));
    let m = DMatrix::<C64>::identity(4, 4) * s - ac;
    let x = m.lu().solve(&b.map(|v| C64::new(v, 0.0))).unwrap();
    let g = c.map(|v| C64::new(v, 0.0)) * x + d.map(|v| C64::new(v, 0.0));
    for i in 0..3 {
        for j in 0..2 {
            assert!((g[(i, j)] - out[i * 2 + j]).norm() < 1e-12);
        }
    }
    // Exactly at a pole: a typed error, not a NaN.
    let mut ev = Evaluator::new(
        &dmatrix![0.0],
        &dmatrix![1.0],
        &dmatrix![1.0],
        &dmatrix![0.0],
    );
    let mut out = [C64::new(0.0, 0.0)];
    assert!(matches!(
        ev.eval(C64::new(0.0, 0.0), &mut out),
        Err(Error::Singular { .. })
    ));
}

/// `eval_many` is `eval` run eight points at a time: the same numbers
/// bit for bit, including at points `eval` hands to its rescaling or to
/// the pivoted solve, and the same first error.
#[test]
fn eval_many_is_eval_bit_for_bit() {
    let (a, b, c, d) = mimo();
    // 21 points (two full chunks and a short one): imaginary-axis and
    // unit-circle points, and 1e120 j, where the recurrence rescales.
    let mut s: Vec<C64> = (0..19)
        .map(|k| C64::new(0.0, 0.1 * f64::from(k)))
        .chain((0..1).map(|_| C64::from_polar(1.0, 0.7)))
        .collect();
    s.insert(9, C64::new(0.0, 1e120));
    let decoupled = (
        dmatrix![-1.0, 0.0; 0.0, -2.0],
        dmatrix![1.0; 0.0],
        dmatrix![1.0, 1.0],
        dmatrix![0.0],
    );
    for (a, b, c, d) in [(a, b, c, d), decoupled] {
        let (m, p) = (b.ncols(), c.nrows());
        let mut ev = Evaluator::new(&a, &b, &c, &d);
        let mut many = vec![C64::new(0.0, 0.0); p * m * s.len()];
        ev.eval_many(&s, &mut many).unwrap();
        let mut one = vec![C64::new(0.0, 0.0); p * m];
        for (k, &sk) in s.iter().enumerate() {
            ev.eval(sk, &mut one).unwrap();
            for (ch, g) in one.iter().enumerate() {
                let h = many[ch * s.len() + k];
                assert_eq!(
                    (g.re.to_bits(), g.im.to_bits()),
                    (h.re.to_bits(), h.im.to_bits())
                );
            }
        }
    }
    // A pole on the grid: the error eval gives there.
    let mut ev = Evaluator::new(
        &dmatrix![0.0, 1.0; 0.0, 0.0],
        &dmatrix![0.0; 1.0],
        &dmatrix![1.0, 0.0],
        &dmatrix![0.0],
    );
    let mut out = vec![C64::new(0.0, 0.0); 3];
    let points = [C64::new(0.0, 1.0), C64::new(0.0, 0.0), C64::new(0.0, 2.0)];
    assert!(matches!(
        ev.eval_many(&points, &mut out),
        Err(Error::Singular { .. })
    ));
}
