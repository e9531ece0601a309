//! The optimiser's arrays and MINPACK's linear algebra on them: the QR
//! factorisation with column pivoting (`qrfac`), the Levenberg–Marquardt
//! parameter (`lmpar`) and the regularised solve (`qrsolv`).

use nalgebra::DMatrix;

use super::{DWARF, EPSMCH, enorm, scaled_norm};

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// The optimiser's arrays, named as in MINPACK: the Jacobian `jac` (after
/// [`Work::factor`], its Householder vectors), `R` in `r` (upper triangle,
/// `rdiag` on the diagonal; `qrsolv` keeps `S` below it, `sdiag` on its
/// diagonal), the pivots `ipvt` (column `j` of `J P` is column `ipvt[j]`
/// of `J`), the column norms `acnorm`, `Qᵀ f` (`qtf`, through `fwork`),
/// the scaling `D` (`diag`), and work vectors.
pub(super) struct Work {
    pub(super) jac: DMatrix<f64>,
    pub(super) r: DMatrix<f64>,
    pub(super) ipvt: Vec<usize>,
    pub(super) rdiag: Vec<f64>,
    pub(super) acnorm: Vec<f64>,
    pub(super) qtf: Vec<f64>,
    pub(super) diag: Vec<f64>,
    pub(super) sdiag: Vec<f64>,
    pub(super) wa1: Vec<f64>,
    pub(super) wa2: Vec<f64>,
    pub(super) wa3: Vec<f64>,
    pub(super) wa4: Vec<f64>,
    pub(super) fwork: Vec<f64>,
}

impl Work {
    pub(super) fn new(m: usize, n: usize) -> Work {
        Work {
            jac: DMatrix::zeros(m, n),
            r: DMatrix::zeros(n, n),
            ipvt: (0..n).collect(),
            rdiag: vec![0.0; n],
            acnorm: vec![0.0; n],
            qtf: vec![0.0; n],
            diag: vec![1.0; n],
            sdiag: vec![0.0; n],
            wa1: vec![0.0; n],
            wa2: vec![0.0; n],
            wa3: vec![0.0; n],
            wa4: vec![0.0; n],
            fwork: vec![0.0; m],
        }
    }

    /// `qrfac` with column pivoting on the Jacobian, then `Qᵀ f` and `R`.
    pub(super) fn factor(&mut self, f: &[f64]) {
        let (m, n) = self.jac.shape();
        let a = self.jac.as_mut_slice();
        for j in 0..n {
            self.acnorm[j] = enorm(&a[j * m..(j + 1) * m]);
            self.rdiag[j] = self.acnorm[j];
            self.wa2[j] = self.rdiag[j];
            self.ipvt[j] = j;
        }
        for j in 0..n {
            // The column of largest remaining norm to the pivot.
            let kmax = (j..n).fold(j, |kmax, k| {
                if self.rdiag[k] > self.rdiag[kmax] {
                    k
                } else {
                    kmax
                }
            });
            if kmax != j {
                let (left, right) = a.split_at_mut(kmax * m);
                left[j * m..(j + 1) * m].swap_with_slice(&mut right[..m]);
                self.rdiag[kmax] = self.rdiag[j];
                self.wa2[kmax] = self.wa2[j];
                self.ipvt.swap(j, kmax);
            }
            // The reflection taking column j below the diagonal to a
            // multiple of the unit vector, applied to the columns after.
            let (head, tail) = a.split_at_mut((j + 1) * m);
            let v = &mut head[j * m + j..];
            let mut ajnorm = enorm(v);
            if ajnorm != 0.0 {
                if v[0] < 0.0 {
                    ajnorm = -ajnorm;
                }
                for x in v.iter_mut() {
                    *x /= ajnorm;
                }
                v[0] += 1.0;
                for (k, column) in (j + 1..n).zip(tail.chunks_exact_mut(m)) {
                    let c = &mut column[j..];
                    let temp = dot(v, c) / v[0];
                    for (ci, vi) in c.iter_mut().zip(v.iter()) {
                        *ci -= temp * vi;
                    }
                    // Downdate the column's remaining norm, recomputing it
                    // when cancellation has eaten its accuracy.
                    if self.rdiag[k] != 0.0 {
                        let temp = c[0] / self.rdiag[k];
                        self.rdiag[k] *= (1.0 - temp * temp).max(0.0).sqrt();
                        if 0.05 * (self.rdiag[k] / self.wa2[k]).powi(2) <= EPSMCH {
                            self.rdiag[k] = enorm(&c[1..]);
                            self.wa2[k] = self.rdiag[k];
                        }
                    }
                }
            }
            self.rdiag[j] = -ajnorm;
        }
        // Qᵀ f, its first n entries kept.
        self.fwork.copy_from_slice(f);
        for j in 0..n {
            let v = &a[j * m + j..(j + 1) * m];
            if v[0] != 0.0 {
                let temp = -dot(v, &self.fwork[j..]) / v[0];
                for (fi, vi) in self.fwork[j..].iter_mut().zip(v) {
                    *fi += vi * temp;
                }
            }
            self.qtf[j] = self.fwork[j];
        }
        self.r.fill(0.0);
        for j in 0..n {
            for i in 0..j {
                self.r[(i, j)] = a[j * m + i];
            }
            self.r[(j, j)] = self.rdiag[j];
        }
    }

    /// `lmpar`: the parameter `par` for which the step `x` solving
    /// `min ‖J p + f‖² + par ‖D p‖²` has `‖D x‖` within 10 % of `delta`
    /// (or `par = 0` when the Gauss–Newton step is shorter), by at most 10
    /// safeguarded Newton steps from `par`. The step is left in `wa1`.
    pub(super) fn lmpar(&mut self, delta: f64, par: f64) -> f64 {
        let n = self.ipvt.len();
        // The Gauss–Newton step; a least-squares one if R is singular.
        let mut nsing = n;
        for j in 0..n {
            self.wa3[j] = self.qtf[j];
            if self.r[(j, j)] == 0.0 && nsing == n {
                nsing = j;
            }
            if nsing < n {
                self.wa3[j] = 0.0;
            }
        }
        for j in (0..nsing).rev() {
            self.wa3[j] /= self.r[(j, j)];
            let temp = self.wa3[j];
            for i in 0..j {
                self.wa3[i] -= self.r[(i, j)] * temp;
            }
        }
        for (&l, &v) in self.ipvt.iter().zip(&self.wa3) {
            self.wa1[l] = v;
        }
        let mut dxnorm = scaled_norm(&self.diag, &self.wa1, &mut self.wa2);
        let mut fp = dxnorm - delta;
        if fp <= 0.1 * delta {
            return 0.0;
        }
        // A lower bound from the Newton step (none if R is singular).
        let mut parl = 0.0;
        if nsing == n {
            self.newton_rhs(dxnorm);
            for j in 0..n {
                let sum: f64 = (0..j).map(|i| self.r[(i, j)] * self.wa3[i]).sum();
                self.wa3[j] = (self.wa3[j] - sum) / self.r[(j, j)];
            }
            let temp = enorm(&self.wa3);
            parl = ((fp / delta) / temp) / temp;
        }
        // An upper bound, ‖D⁻¹ Jᵀ f‖ / delta.
        for j in 0..n {
            let sum: f64 = (0..=j).map(|i| self.r[(i, j)] * self.qtf[i]).sum();
            self.wa3[j] = sum / self.diag[self.ipvt[j]];
        }
        let gnorm = enorm(&self.wa3);
        let mut paru = gnorm / delta;
        if paru == 0.0 {
            paru = DWARF / delta.min(0.1);
        }
        let mut par = par.max(parl).min(paru);
        if par == 0.0 {
            par = gnorm / dxnorm;
        }
        for iteration in 1..=10 {
            if par == 0.0 {
                par = DWARF.max(1e-3 * paru);
            }
            let temp = par.sqrt();
            for j in 0..n {
                self.wa4[j] = temp * self.diag[j];
            }
            self.qrsolv();
            dxnorm = scaled_norm(&self.diag, &self.wa1, &mut self.wa2);
            let previous = fp;
            fp = dxnorm - delta;
            if fp.abs() <= 0.1 * delta
                || (parl == 0.0 && fp <= previous && previous < 0.0)
                || iteration == 10
            {
                break;
            }
            // The Newton correction, from S with Sᵀ S = Pᵀ (JᵀJ + par D²) P.
            self.newton_rhs(dxnorm);
            for j in 0..n {
                self.wa3[j] /= self.sdiag[j];
                let temp = self.wa3[j];
                for i in j + 1..n {
                    self.wa3[i] -= self.r[(i, j)] * temp;
                }
            }
            let temp = enorm(&self.wa3);
            let parc = ((fp / delta) / temp) / temp;
            if fp > 0.0 {
                parl = parl.max(par);
            }
            if fp < 0.0 {
                paru = paru.min(par);
            }
            par = parl.max(par + parc);
        }
        par
    }

    /// `wa3 = Pᵀ D (D x) / ‖D x‖`, with `D x` in `wa2`.
    pub(super) fn newton_rhs(&mut self, dxnorm: f64) {
        for j in 0..self.ipvt.len() {
            let l = self.ipvt[j];
            self.wa3[j] = self.diag[l] * (self.wa2[l] / dxnorm);
        }
    }

    /// `qrsolv`: the least-squares solution `wa1` of `J p ≈ −f`,
    /// `√par D p ≈ 0` (with `√par D` in `wa4`), from `R` and `Qᵀ f`:
    /// Givens rotations eliminate the diagonal rows from `R`, leaving the
    /// lower triangle `S` (strict part in `r`'s lower triangle, diagonal in
    /// `sdiag`); `R`'s upper triangle and diagonal are kept.
    pub(super) fn qrsolv(&mut self) {
        let n = self.ipvt.len();
        let r = &mut self.r;
        let (sdiag, wa) = (&mut self.sdiag, &mut self.wa3);
        for j in 0..n {
            for i in j..n {
                r[(i, j)] = r[(j, i)];
            }
            wa[j] = self.qtf[j];
        }
        for j in 0..n {
            let d = self.wa4[self.ipvt[j]];
            if d != 0.0 {
                sdiag[j..].fill(0.0);
                sdiag[j] = d;
                // The rotations also carry the extra row of (Qᵀ f, 0).
                let mut qtbpj = 0.0;
                for k in j..n {
                    if sdiag[k] == 0.0 {
                        continue;
                    }
                    let (sin, cos) = if r[(k, k)].abs() < sdiag[k].abs() {
                        let cotan = r[(k, k)] / sdiag[k];
                        let sin = 0.5 / (0.25 + 0.25 * cotan * cotan).sqrt();
                        (sin, sin * cotan)
                    } else {
                        let tan = sdiag[k] / r[(k, k)];
                        let cos = 0.5 / (0.25 + 0.25 * tan * tan).sqrt();
                        (cos * tan, cos)
                    };
                    r[(k, k)] = cos * r[(k, k)] + sin * sdiag[k];
                    let temp = cos * wa[k] + sin * qtbpj;
                    qtbpj = -sin * wa[k] + cos * qtbpj;
                    wa[k] = temp;
                    for i in k + 1..n {
                        let temp = cos * r[(i, k)] + sin * sdiag[i];
                        sdiag[i] = -sin * r[(i, k)] + cos * sdiag[i];
                        r[(i, k)] = temp;
                    }
                }
            }
            sdiag[j] = r[(j, j)];
            r[(j, j)] = self.rdiag[j];
        }
        // Back substitution in S; a least-squares solution if singular.
        let nsing = sdiag.iter().position(|s| *s == 0.0).unwrap_or(n);
        wa[nsing..].fill(0.0);
        for j in (0..nsing).rev() {
            let sum: f64 = (j + 1..nsing).map(|i| r[(i, j)] * wa[i]).sum();
            wa[j] = (wa[j] - sum) / sdiag[j];
        }
        for (&l, &v) in self.ipvt.iter().zip(wa.iter()) {
            self.wa1[l] = v;
        }
    }
}
