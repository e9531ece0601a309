//! The frequency-response kernel of a state-space model, in a workspace
//! allocated once.
//!
//! For each input `j`, `(A, b_j)` is reduced once to controller-Hessenberg
//! form: an orthogonal `T` with `Tᵀ b_j = β e₁` and `H = Tᵀ A T` upper
//! Hessenberg. At each point, `(sI − H) x = t e₁` is solved from the last
//! row up with `x_n = 1` (Hyman's recurrence: no pivoting, the subdiagonal
//! of `H` inverted once, rescaled by powers of two against overflow), and
//! `G(s) e_j = C T x β / t + D e_j`: `O(n²)` real-by-complex products and
//! one complex division per input. Where `H` has a subdiagonal entry that
//! is zero to rounding (`(A, b_j)` decouples), and at any point where the
//! recurrence breaks down (`t = 0`, overflow), the point is solved instead
//! by Gaussian elimination with partial pivoting on the plain Hessenberg
//! form of `A`, which decides whether `s` is a pole.

use nalgebra::{Complex, DMatrix};

use crate::error::Error;
use crate::kernels::reduce::{pow2_floor, real_over};

type C64 = Complex<f64>;

/// A model prepared for repeated evaluation at complex points.
#[derive(Debug, Clone)]
pub(crate) struct Evaluator {
    n: usize,
    m: usize,
    p: usize,
    /// `D`, column-major `p × m`.
    d: Vec<f64>,
    /// One reduction per input, or `None` where the recurrence cannot be
    /// used.
    columns: Option<Vec<Column>>,
    /// Workspace: the recurrence's vector.
    x: Vec<C64>,
    pivoted: Pivoted,
}

/// `(A, b_j)` in controller-Hessenberg form.
#[derive(Debug, Clone)]
struct Column {
    /// `H`, column-major `n × n`.
    h: Vec<f64>,
    /// `1 / H[k+1, k]`.
    inv_sub: Vec<f64>,
    /// `β`, with `Tᵀ b_j = β e₁`.
    beta: f64,
    /// `C T`, column-major `p × n`.
    c: Vec<f64>,
}

impl Column {
    /// The reduction of `(a, b)`, `None` if a subdiagonal entry of `H` is
    /// zero to rounding (`≤ n ε ‖H‖_F`).
    fn new(a: &DMatrix<f64>, b: &DMatrix<f64>, c: &DMatrix<f64>) -> Option<Self> {
        let n = a.nrows();
        // Householder reflection P with P b = β e₁.
        let norm = b.norm();
        let mut u = b.clone();
        let alpha = if b[0] >= 0.0 { -norm } else { norm };
        u[0] -= alpha;
        let uu = u.norm_squared();
        let p = if uu > 0.0 {
            DMatrix::identity(n, n) - &u * u.transpose() * (2.0 / uu)
        } else {
            DMatrix::identity(n, n)
        };
        let a1 = &p * a * &p;
        let (t, h) = if n <= 2 {
            (p, a1)
        } else {
            let (q, h) = nalgebra::linalg::Hessenberg::new(a1).unpack();
            (&p * q, h)
        };
        let beta = (t.transpose() * b)[0];
        let tol = n as f64 * f64::EPSILON * h.norm();
        let mut inv_sub = Vec::with_capacity(n.saturating_sub(1));
        for k in 0..n.saturating_sub(1) {
            let sub = h[(k + 1, k)];
            if sub.abs() <= tol || sub.is_nan() {
                return None;
            }
            inv_sub.push(1.0 / sub);
        }
        let ct = c * t;
        if h.iter()
            .chain(ct.iter())
            .chain(&inv_sub)
            .any(|v| !v.is_finite())
            || !beta.is_finite()
        {
            return None;
        }
        Some(Self {
            h: h.as_slice().to_vec(),
            inv_sub,
            beta,
            c: ct.as_slice().to_vec(),
        })
    }
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
        let columns = if n == 0 {
            Some(Vec::new())
        } else {
            (0..m)
                .map(|j| Column::new(a, &b.columns(j, 1).into_owned(), c))
                .collect::<Option<Vec<_>>>()
        };
        Self {
            n,
            m,
            p,
            d: d.as_slice().to_vec(),
            columns,
            x: vec![C64::new(0.0, 0.0); n],
            pivoted: Pivoted::new(a, b, c, d),
        }
    }

    /// `G(s)` into `out` (`p × m`, row-major: entry `(i, j)` at `i m + j`).
    ///
    /// # Errors
    ///
    /// [`Error::Singular`] if `s` is an eigenvalue of `A` exactly (a zero
    /// pivot); [`Error::Overflow`] if an entry is not finite.
    pub(crate) fn eval(&mut self, s: C64, out: &mut [C64]) -> Result<(), Error> {
        let Some(columns) = &self.columns else {
            return self.pivoted.eval(s, out);
        };
        let (n, m, p) = (self.n, self.m, self.p);
        if n == 0 {
            for i in 0..p {
                for j in 0..m {
                    out[i * m + j] = C64::new(self.d[i + j * p], 0.0);
                }
            }
            return Ok(());
        }
        let x = &mut self.x[..n];
        for (j, col) in columns.iter().enumerate() {
            let h = &col.h[..n * n];
            x[n - 1] = C64::new(1.0, 0.0);
            let mut ok = true;
            for k in (1..n).rev() {
                let mut acc = (s - h[k + k * n]) * x[k];
                for (jj, xj) in x.iter().enumerate().skip(k + 1) {
                    acc -= xj * h[k + jj * n];
                }
                let v = acc * col.inv_sub[k - 1];
                x[k - 1] = v;
                let size = v.re.abs().max(v.im.abs());
                if size > 1e100 {
                    // Scale the computed part by a power of two: t scales
                    // with it and the ratio x / t does not change.
                    let f = 1.0 / pow2_floor(size);
                    for xj in &mut x[k - 1..] {
                        *xj *= f;
                    }
                } else if !size.is_finite() {
                    ok = false;
                    break;
                }
            }
            let mut t = (s - h[0]) * x[0];
            for (jj, xj) in x.iter().enumerate().skip(1) {
                t -= xj * h[jj * n];
            }
            if !ok || t == C64::new(0.0, 0.0) || !(t.re.is_finite() && t.im.is_finite()) {
                return self.pivoted.eval(s, out);
            }
            let (sr, si) = real_over(col.beta, t.re, t.im);
            let scale = C64::new(sr, si);
            for i in 0..p {
                let mut acc = C64::new(0.0, 0.0);
                for (k, xk) in x.iter().enumerate() {
                    acc += xk * col.c[i + k * p];
                }
                let g = acc * scale + self.d[i + j * p];
                if !(g.re.is_finite() && g.im.is_finite()) {
                    return self.pivoted.eval(s, out);
                }
                out[i * m + j] = g;
            }
        }
        Ok(())
    }
}

/// Points [`Evaluator::eval_many`] runs through the recurrence together.
const LANES: usize = 8;

/// The recurrence's vectors for [`LANES`] points, split into real and
/// imaginary parts so the compiler can vectorise across points.
#[derive(Debug, Clone)]
struct LaneWork {
    re: Vec<[f64; LANES]>,
    im: Vec<[f64; LANES]>,
}

impl Evaluator {
    /// `G(s)` at every point of `s` into `values` (channel-major: entry
    /// `(i, j)` at point `k` is `values[(i m + j) · s.len() + k]`).
    ///
    /// The same arithmetic as [`eval`](Self::eval), in the same order, run
    /// [`LANES`] points at a time (about twice as fast on the lab plant);
    /// a point that would need the recurrence's rescaling or the pivoted
    /// solve is handed to `eval`, so the result is `eval`'s bit for bit.
    ///
    /// # Errors
    ///
    /// As [`eval`](Self::eval), for the first point that fails.
    pub(crate) fn eval_many(&mut self, s: &[C64], values: &mut [C64]) -> Result<(), Error> {
        let (n, m, p) = (self.n, self.m, self.p);
        let len = s.len();
        debug_assert_eq!(values.len(), p * m * len);
        let mut at = vec![C64::new(0.0, 0.0); p * m];
        let mut lanes = LaneWork {
            re: vec![[0.0; LANES]; n],
            im: vec![[0.0; LANES]; n],
        };
        let mut g = vec![[C64::new(0.0, 0.0); LANES]; p * m];
        for start in (0..len).step_by(LANES) {
            let count = LANES.min(len - start);
            // A short last chunk repeats its last point in the spare lanes.
            let points: [C64; LANES] = std::array::from_fn(|q| s[start + q.min(count - 1)]);
            let mut bad = [self.columns.is_none() || n == 0; LANES];
            if let Some(columns) = &self.columns
                && n > 0
            {
                for (j, col) in columns.iter().enumerate() {
                    lanes_column(
                        col,
                        n,
                        p,
                        &self.d[j * p..(j + 1) * p],
                        &points,
                        &mut lanes,
                        &mut bad,
                        |i, q, v| {
                            g[i * m + j][q] = v;
                        },
                    );
                }
            }
            for q in 0..count {
                if bad[q] {
                    self.eval(points[q], &mut at)?;
                    for (ch, v) in at.iter().enumerate() {
                        values[ch * len + start + q] = *v;
                    }
                } else {
                    for (ch, v) in g.iter().enumerate() {
                        values[ch * len + start + q] = v[q];
                    }
                }
            }
        }
        Ok(())
    }
}

/// Column `j` of `G` (its `D` column `d`) at [`LANES`] points by the
/// recurrence of [`Evaluator::eval`], written through `store(i, lane, g)`;
/// a lane where `eval` would rescale, fall back or find a non-finite value
/// is marked in `bad` instead.
#[allow(clippy::too_many_arguments)]
fn lanes_column(
    col: &Column,
    n: usize,
    p: usize,
    d: &[f64],
    s: &[C64; LANES],
    w: &mut LaneWork,
    bad: &mut [bool; LANES],
    mut store: impl FnMut(usize, usize, C64),
) {
    let h = &col.h[..n * n];
    let (xr, xi) = (&mut w.re[..n], &mut w.im[..n]);
    xr[n - 1] = [1.0; LANES];
    xi[n - 1] = [0.0; LANES];
    for k in (1..n).rev() {
        let (ar, ai) = lanes_row(h, n, k, s, xr, xi);
        let inv = col.inv_sub[k - 1];
        for q in 0..LANES {
            let (vr, vi) = (ar[q] * inv, ai[q] * inv);
            xr[k - 1][q] = vr;
            xi[k - 1][q] = vi;
            // `eval` rescales above 1e100 and gives up on a non-finite size.
            let size = vr.abs().max(vi.abs());
            bad[q] |= size > 1e100 || !size.is_finite();
        }
    }
    let (tr, ti) = lanes_row(h, n, 0, s, xr, xi);
    // β / t, as `eval` divides.
    let mut scale_re = [0.0; LANES];
    let mut scale_im = [0.0; LANES];
    for q in 0..LANES {
        bad[q] |= (tr[q] == 0.0 && ti[q] == 0.0) || !(tr[q].is_finite() && ti[q].is_finite());
        (scale_re[q], scale_im[q]) = real_over(col.beta, tr[q], ti[q]);
    }
    for (i, &d) in d.iter().enumerate().take(p) {
        let mut acc_re = [0.0; LANES];
        let mut acc_im = [0.0; LANES];
        for k in 0..n {
            let c = col.c[i + k * p];
            for q in 0..LANES {
                acc_re[q] += xr[k][q] * c;
                acc_im[q] += xi[k][q] * c;
            }
        }
        for q in 0..LANES {
            let g = C64::new(
                acc_re[q] * scale_re[q] - acc_im[q] * scale_im[q] + d,
                acc_re[q] * scale_im[q] + acc_im[q] * scale_re[q],
            );
            if g.re.is_finite() && g.im.is_finite() {
                store(i, q, g);
            } else {
                bad[q] = true;
            }
        }
    }
}

/// `(s − H[k, k]) x_k − Σ_{j>k} H[k, j] x_j` at [`LANES`] points: row `k`
/// of `(sI − H) x`, in `eval`'s order of operations.
#[inline(always)]
fn lanes_row(
    h: &[f64],
    n: usize,
    k: usize,
    s: &[C64; LANES],
    xr: &[[f64; LANES]],
    xi: &[[f64; LANES]],
) -> ([f64; LANES], [f64; LANES]) {
    let hkk = h[k + k * n];
    let mut ar = [0.0; LANES];
    let mut ai = [0.0; LANES];
    for q in 0..LANES {
        let (sr, si) = (s[q].re - hkk, s[q].im);
        ar[q] = sr * xr[k][q] - si * xi[k][q];
        ai[q] = sr * xi[k][q] + si * xr[k][q];
    }
    for jj in k + 1..n {
        let hv = h[k + jj * n];
        for q in 0..LANES {
            ar[q] -= xr[jj][q] * hv;
            ai[q] -= xi[jj][q] * hv;
        }
    }
    (ar, ai)
}

/// The pivoted solve on the Hessenberg form of `A`.
#[derive(Debug, Clone)]
struct Pivoted {
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
    /// Workspace: the inverted pivots.
    inv: Vec<C64>,
}

impl Pivoted {
    fn new(a: &DMatrix<f64>, b: &DMatrix<f64>, c: &DMatrix<f64>, d: &DMatrix<f64>) -> Self {
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
            inv: vec![C64::new(0.0, 0.0); n],
        }
    }

    /// As [`Evaluator::eval`].
    fn eval(&mut self, s: C64, out: &mut [C64]) -> Result<(), Error> {
        let (n, m, p) = (self.n, self.m, self.p);
        debug_assert_eq!(out.len(), p * m);
        let w = &mut self.work[..n * n];
        for (wi, &hi) in w.iter_mut().zip(&self.h[..n * n]) {
            *wi = C64::new(-hi, 0.0);
        }
        for j in 0..n {
            w[j * (n + 1)] += s;
        }
        let x = &mut self.x[..n * m];
        for (xi, &bi) in x.iter_mut().zip(&self.b[..n * m]) {
            *xi = C64::new(bi, 0.0);
        }
        let inv = &mut self.inv[..n];
        // Elimination with partial pivoting: only the subdiagonal entry
        // below each pivot is non-zero. Pivots are inverted once (one real
        // division each) and multiplied.
        for k in 0..n {
            if k + 1 < n && w[k + 1 + k * n].norm_sqr() > w[k + k * n].norm_sqr() {
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
            let (ir, ii) = real_over(1.0, pivot.re, pivot.im);
            inv[k] = C64::new(ir, ii);
            if k + 1 == n {
                break;
            }
            let l = w[k + 1 + k * n] * inv[k];
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
        // Back substitution, column by column of the right-hand side.
        for r in 0..m {
            let xr = &mut x[r * n..(r + 1) * n];
            for k in (0..n).rev() {
                let mut acc = xr[k];
                for j in k + 1..n {
                    acc -= w[k + j * n] * xr[j];
                }
                xr[k] = acc * inv[k];
            }
        }
        for i in 0..p {
            for r in 0..m {
                let xr = &x[r * n..(r + 1) * n];
                let mut acc = C64::new(self.d[i + r * p], 0.0);
                for (k, xk) in xr.iter().enumerate() {
                    acc += xk * self.c[i + k * p];
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
mod tests;
