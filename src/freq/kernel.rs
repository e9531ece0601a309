//! The frequency-response kernel of a state-space model: `A` reduced once
//! to upper Hessenberg form `H = Qᵀ A Q` (with `Qᵀ B`, `C Q`), then each
//! point `G(s) = C Q (sI − H)⁻¹ Qᵀ B + D` is one Hessenberg solve with
//! partial pivoting, `O(n² m)` flops, in a workspace allocated once.

use nalgebra::{Complex, DMatrix};

use crate::error::Error;

type C64 = Complex<f64>;

/// A model prepared for repeated evaluation at complex points.
#[derive(Debug, Clone)]
pub(crate) struct Evaluator {
    n: usize,
    m: usize,
    p: usize,
    /// `H`, column-major `n × n`.
    h: Vec<f64>,
    /// `Qᵀ B`, column-major `n × m`.
    b: Vec<f64>,
    /// `C Q`, column-major `p × n`.
    c: Vec<f64>,
    /// `D`, column-major `p × m`.
    d: Vec<f64>,
    /// Workspace: `sI − H` (column-major) and the right-hand sides.
    work: Vec<C64>,
    x: Vec<C64>,
}

impl Evaluator {
    /// Reduces the model (whose shapes and entries the caller has checked).
    pub(crate) fn new(
        a: &DMatrix<f64>,
        b: &DMatrix<f64>,
        c: &DMatrix<f64>,
        d: &DMatrix<f64>,
    ) -> Self {
        let (n, m, p) = (a.nrows(), b.ncols(), c.nrows());
        let (h, qtb, cq) = if n <= 2 {
            // Already Hessenberg.
            (a.clone(), b.clone(), c.clone())
        } else {
            let (q, h) = nalgebra::linalg::Hessenberg::new(a.clone()).unpack();
            (h, q.transpose() * b, c * q)
        };
        Self {
            n,
            m,
            p,
            h: h.as_slice().to_vec(),
            b: qtb.as_slice().to_vec(),
            c: cq.as_slice().to_vec(),
            d: d.as_slice().to_vec(),
            work: vec![C64::new(0.0, 0.0); n * n],
            x: vec![C64::new(0.0, 0.0); n * m],
        }
    }

    /// `G(s)` into `out` (`p × m`, row-major: entry `(i, j)` at `i m + j`).
    ///
    /// # Errors
    ///
    /// [`Error::Singular`] if `s` is an eigenvalue of `A` exactly (a zero
    /// pivot); [`Error::Overflow`] if an entry is not finite.
    pub(crate) fn eval(&mut self, s: C64, out: &mut [C64]) -> Result<(), Error> {
        let (n, m, p) = (self.n, self.m, self.p);
        debug_assert_eq!(out.len(), p * m);
        let w = &mut self.work;
        for j in 0..n {
            for i in 0..n {
                w[i + j * n] = C64::new(-self.h[i + j * n], 0.0);
            }
            w[j + j * n] += s;
        }
        let x = &mut self.x;
        for (xi, &bi) in x.iter_mut().zip(&self.b) {
            *xi = C64::new(bi, 0.0);
        }
        // Elimination: only the subdiagonal entry below each pivot.
        for k in 0..n.saturating_sub(1) {
            if w[k + 1 + k * n].norm_sqr() > w[k + k * n].norm_sqr() {
                for j in k..n {
                    w.swap(k + j * n, k + 1 + j * n);
                }
                for r in 0..m {
                    x.swap(k + r * n, k + 1 + r * n);
                }
            }
            let pivot = w[k + k * n];
            if pivot == C64::new(0.0, 0.0) {
                return Err(singular());
            }
            let l = w[k + 1 + k * n] / pivot;
            if l != C64::new(0.0, 0.0) {
                for j in k + 1..n {
                    let t = w[k + j * n];
                    w[k + 1 + j * n] -= l * t;
                }
                for r in 0..m {
                    let t = x[k + r * n];
                    x[k + 1 + r * n] -= l * t;
                }
            }
        }
        // Back substitution.
        for k in (0..n).rev() {
            let pivot = w[k + k * n];
            if pivot == C64::new(0.0, 0.0) {
                return Err(singular());
            }
            for r in 0..m {
                let mut acc = x[k + r * n];
                for j in k + 1..n {
                    acc -= w[k + j * n] * x[j + r * n];
                }
                x[k + r * n] = acc / pivot;
            }
        }
        for i in 0..p {
            for r in 0..m {
                let mut acc = C64::new(self.d[i + r * p], 0.0);
                for k in 0..n {
                    acc += x[k + r * n] * self.c[i + k * p];
                }
                if !(acc.re.is_finite() && acc.im.is_finite()) {
                    return Err(Error::Overflow {
                        operation: "frequency response (s near a pole)",
                    });
                }
                out[i * m + r] = acc;
            }
        }
        Ok(())
    }
}

fn singular() -> Error {
    Error::Singular {
        operation: "frequency response (s is a pole of the model)",
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::dmatrix;

    #[test]
    fn matches_a_direct_solve() {
        let a = dmatrix![-1.0, 2.0, 0.5, 0.0; -3.0, -0.2, 1.0, 4.0; 0.1, 0.0, -2.0, 1.0; 1.0, 1.0, -1.0, -0.5];
        let b = dmatrix![1.0, 0.0; 0.0, 1.0; 1.0, 1.0; 0.5, -1.0];
        let c = dmatrix![1.0, 0.0, 0.0, 1.0; 0.0, 2.0, -1.0, 0.0; 1.0, 1.0, 1.0, 1.0];
        let d = dmatrix![0.0, 0.1; 0.2, 0.0; 0.0, 0.0];
        let mut ev = Evaluator::new(&a, &b, &c, &d);
        let s = C64::new(0.3, 1.7);
        let mut out = vec![C64::new(0.0, 0.0); 6];
        ev.eval(s, &mut out).unwrap();
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
}
