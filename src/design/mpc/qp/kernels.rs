//! The solver's dense and sparse kernels: `G` in compressed rows, the
//! Ruiz equilibration, an in-place Cholesky and an in-place LU, all on
//! buffers allocated once.

use nalgebra::{DMatrix, DVector};

use super::QpSettings;
use crate::error::Error;

/// OSQP's bounds on a Ruiz scaling factor, and its number of passes.
const MIN_SCALING: f64 = 1e-4;
const MAX_SCALING: f64 = 1e4;
const RUIZ_PASSES: usize = 10;

/// The compressed rows of `G` (scaled): row `i`'s entries are
/// `values[start[i]..start[i + 1]]` in columns `cols[..]`.
#[derive(Debug, Clone)]
pub(super) struct SparseRows {
    pub(super) start: Vec<usize>,
    pub(super) cols: Vec<usize>,
    pub(super) values: Vec<f64>,
}

impl SparseRows {
    pub(super) fn of(g: &DMatrix<f64>) -> Self {
        let mut start = Vec::with_capacity(g.nrows() + 1);
        let (mut cols, mut values) = (Vec::new(), Vec::new());
        start.push(0);
        for i in 0..g.nrows() {
            for j in 0..g.ncols() {
                let v = g[(i, j)];
                if v != 0.0 {
                    cols.push(j);
                    values.push(v);
                }
            }
            start.push(cols.len());
        }
        Self {
            start,
            cols,
            values,
        }
    }

    /// `out = G x`.
    pub(super) fn mul(&self, x: &DVector<f64>, out: &mut DVector<f64>) {
        for (i, o) in out.iter_mut().enumerate() {
            let (a, b) = (self.start[i], self.start[i + 1]);
            *o = self.cols[a..b]
                .iter()
                .zip(&self.values[a..b])
                .map(|(&j, &v)| v * x[j])
                .sum();
        }
    }

    /// `out += Gᵀ y`.
    pub(super) fn add_tr_mul(&self, y: &DVector<f64>, out: &mut DVector<f64>) {
        for (i, &yi) in y.iter().enumerate() {
            if yi == 0.0 {
                continue;
            }
            let (a, b) = (self.start[i], self.start[i + 1]);
            for (&j, &v) in self.cols[a..b].iter().zip(&self.values[a..b]) {
                out[j] += v * yi;
            }
        }
    }
}

/// Ruiz equilibration of `[P Gᵀ; G 0]` in place, then a cost scaling:
/// returns `(D, E, c)` with `P ← c D P D`, `G ← E G D`.
pub(super) fn equilibrate(
    p: &mut DMatrix<f64>,
    g: &mut DMatrix<f64>,
) -> (DVector<f64>, DVector<f64>, f64) {
    let (n, m) = (p.nrows(), g.nrows());
    let mut d = DVector::from_element(n, 1.0);
    let mut e = DVector::from_element(m, 1.0);
    let limit = |norm: f64| {
        if norm < MIN_SCALING {
            1.0
        } else {
            1.0 / norm.min(MAX_SCALING).sqrt()
        }
    };
    let mut dd = DVector::zeros(n);
    let mut de = DVector::zeros(m);
    for _ in 0..RUIZ_PASSES {
        for j in 0..n {
            let col = p.column(j).amax().max(g.column(j).amax());
            dd[j] = limit(col);
        }
        for i in 0..m {
            de[i] = limit(g.row(i).amax());
        }
        for j in 0..n {
            for i in 0..n {
                p[(i, j)] *= dd[i] * dd[j];
            }
            for i in 0..m {
                g[(i, j)] *= de[i] * dd[j];
            }
        }
        d.component_mul_assign(&dd);
        e.component_mul_assign(&de);
    }
    // The cost scaling (OSQP's, without q, which changes every solve).
    let mean = if n == 0 {
        1.0
    } else {
        (0..n).map(|j| p.column(j).amax()).sum::<f64>() / n as f64
    };
    let c = if mean < MIN_SCALING {
        1.0
    } else {
        1.0 / mean.min(MAX_SCALING)
    };
    *p *= c;
    (d, e, c)
}

/// Cholesky `A = L Lᵀ` of the lower triangle of `a`, in place (the upper
/// triangle is zeroed); false unless every pivot is positive and finite.
pub(super) fn cholesky_in_place(a: &mut DMatrix<f64>) -> bool {
    let n = a.nrows();
    for j in 0..n {
        let mut diag = a[(j, j)];
        for k in 0..j {
            diag -= a[(j, k)] * a[(j, k)];
        }
        if !(diag > 0.0 && diag.is_finite()) {
            return false;
        }
        let ljj = diag.sqrt();
        a[(j, j)] = ljj;
        for i in j + 1..n {
            let mut v = a[(i, j)];
            for k in 0..j {
                v -= a[(i, k)] * a[(j, k)];
            }
            a[(i, j)] = v / ljj;
        }
        for i in 0..j {
            a[(i, j)] = 0.0;
        }
    }
    true
}

/// LU with partial pivoting of the leading `k × k` block of `a` (column
/// major, leading dimension `lda`), in place; `perm` receives the row
/// order. False if a pivot is zero or not finite, or below `tiny` times
/// the largest entry (singular to working precision).
pub(super) fn lu_in_place(a: &mut [f64], lda: usize, k: usize, perm: &mut [usize]) -> bool {
    let largest = (0..k)
        .flat_map(|j| (0..k).map(move |i| (i, j)))
        .fold(0.0f64, |m, (i, j)| m.max(a[i + j * lda].abs()));
    if !(largest > 0.0 && largest.is_finite()) {
        return false;
    }
    let tiny = largest * k as f64 * f64::EPSILON;
    for (i, p) in perm.iter_mut().enumerate().take(k) {
        *p = i;
    }
    for j in 0..k {
        let (mut pivot, mut best) = (j, a[j + j * lda].abs());
        for i in j + 1..k {
            let v = a[i + j * lda].abs();
            if v > best {
                (pivot, best) = (i, v);
            }
        }
        if !(best > tiny && best.is_finite()) {
            return false;
        }
        if pivot != j {
            for c in 0..k {
                a.swap(j + c * lda, pivot + c * lda);
            }
            perm.swap(j, pivot);
        }
        let d = a[j + j * lda];
        for i in j + 1..k {
            a[i + j * lda] /= d;
        }
        for c in j + 1..k {
            let f = a[j + c * lda];
            if f != 0.0 {
                for i in j + 1..k {
                    a[i + c * lda] -= a[i + j * lda] * f;
                }
            }
        }
    }
    true
}

/// Solves `A x = b` in place in `b` (`k` entries) with the factors of
/// [`lu_in_place`]; `work` is `k` entries of scratch.
pub(super) fn lu_solve(
    a: &[f64],
    lda: usize,
    k: usize,
    perm: &[usize],
    b: &mut [f64],
    work: &mut [f64],
) {
    for i in 0..k {
        work[i] = b[perm[i]];
    }
    for j in 0..k {
        let v = work[j];
        if v != 0.0 {
            for i in j + 1..k {
                work[i] -= a[i + j * lda] * v;
            }
        }
    }
    for j in (0..k).rev() {
        work[j] /= a[j + j * lda];
        let v = work[j];
        if v != 0.0 {
            for i in 0..j {
                work[i] -= a[i + j * lda] * v;
            }
        }
    }
    b[..k].copy_from_slice(&work[..k]);
}

/// Each setting within its range, named if not.
pub(super) fn validate_settings(s: &QpSettings) -> Result<(), Error> {
    let checks: [(&'static str, f64, bool, &'static str); 6] = [
        (
            "max_iterations",
            s.max_iterations as f64,
            s.max_iterations >= 1,
            "at least one iteration",
        ),
        (
            "eps_abs",
            s.eps_abs,
            s.eps_abs > 0.0,
            "must be finite and > 0",
        ),
        (
            "eps_rel",
            s.eps_rel,
            s.eps_rel >= 0.0,
            "must be finite and ≥ 0",
        ),
        (
            "eps_infeasible",
            s.eps_infeasible,
            s.eps_infeasible > 0.0,
            "must be finite and > 0",
        ),
        ("rho", s.rho, s.rho > 0.0, "must be finite and > 0"),
        ("sigma", s.sigma, s.sigma > 0.0, "must be finite and > 0"),
    ];
    for (name, value, ok, reason) in checks {
        if !(ok && value.is_finite()) {
            return Err(Error::InvalidParameter {
                name,
                value,
                reason,
            });
        }
    }
    if !(s.alpha > 0.0 && s.alpha < 2.0) {
        return Err(Error::InvalidParameter {
            name: "alpha",
            value: s.alpha,
            reason: "over-relaxation must lie in (0, 2)",
        });
    }
    Ok(())
}
