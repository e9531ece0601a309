//! Controllability and observability: the Krylov matrices and the
//! scale-independent rank test, on run-time-sized matrices (the one
//! implementation behind both model types).

use nalgebra::DMatrix;

use super::rank;
use crate::error::Error;
use crate::kernels::reduce::pow2_floor;

/// The block `[M, A M, A² M, …, A^(N−1) M]` (controllability when
/// `M = B`), N × (N·K).
pub(crate) fn krylov(
    a: &DMatrix<f64>,
    m: &DMatrix<f64>,
    name: &'static str,
) -> Result<DMatrix<f64>, Error> {
    let (n, k) = m.shape();
    let mut out = DMatrix::zeros(n, n * k);
    let mut block = m.clone();
    for p in 0..n {
        for c in 0..k {
            for r in 0..n {
                let v = block[(r, c)];
                if !v.is_finite() {
                    return Err(Error::Overflow { operation: name });
                }
                out[(r, p * k + c)] = v;
            }
        }
        block = a * block;
    }
    Ok(out)
}

/// The numerical rank of the Krylov matrix `[M, A M, …, A^(N−1) M]`,
/// independent of the units of the states, inputs and time: the rank of
/// `R C S` with `C` the Krylov matrix and `R`, `S` diagonal (powers of two),
/// which does not change the exact rank. Each column `A^k m` is scaled by
/// the size of the terms it sums, the matching column of
/// `[|M|, |A| |M|, …]` (so rounding noise in a column that cancels to
/// nearly zero stays noise, while a column that is small because of the
/// units is brought to size), and each row by that magnitude's largest
/// entry in it (a state in µm next to one in km). Powers are scaled as they
/// are formed, so nothing overflows.
pub(crate) fn scaled_krylov_rank(a: &DMatrix<f64>, m: &DMatrix<f64>) -> Result<usize, Error> {
    let (n, k) = m.shape();
    let abs_a = a.abs();
    let mut out = DMatrix::zeros(n, n * k);
    let mut size = DMatrix::zeros(n, n * k);
    for c in 0..k {
        let (mut v, mut w) = (m.column(c).into_owned(), m.column(c).abs());
        for p in 0..n {
            let f = 1.0 / pow2_floor(w.amax());
            v *= f;
            w *= f;
            if v.iter().chain(w.iter()).any(|x| !x.is_finite()) {
                return Err(Error::Overflow {
                    operation: "Krylov matrix (rank test)",
                });
            }
            out.column_mut(p * k + c).copy_from(&v);
            size.column_mut(p * k + c).copy_from(&w);
            v = a * v;
            w = &abs_a * w;
        }
    }
    for i in 0..n {
        let f = 1.0 / pow2_floor(size.row(i).amax());
        out.row_mut(i).scale_mut(f);
    }
    rank(&out, None)
}
