//! A least-squares problem streamed in blocks of rows ([`Tsqr`]): the
//! triangular factor of `[Φ | λ]` updated block by block, so that no
//! column is ever held whole.
//!
//! Each block is factored under the `R` of the rows before it, as
//! [`householder_blocked`](super::solve) does with a stored problem, and
//! each column is equilibrated by the power of two of its largest entry
//! so far: when a block raises it, `R`'s column is rescaled, exactly (a
//! reflection mixes no column into those before it, and scaling a column
//! by a power of two scales every sum it enters without changing a bit).
//! The factor is then the one the stored problem's equilibration and
//! blocked QR give, bit for bit (barring entries below `f64::MIN_POSITIVE`
//! after scaling, which the stored problem would have rounded), with
//! blocks of [`BLOCK_ROWS`] rows from the first row.

use super::solve::{BLOCK_ROWS, NARROW, binary_exponent, householder_narrow, pow2, scale_column};
use crate::kernels::reduce::{finite_max_abs, sum_by};

/// A block held a non-finite entry; the caller finds which (the stored
/// problem's error names the first, column by column).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct NonFiniteBlock;

/// The streamed factorisation of `[Φ | λ]`, `n` columns, `λ` the last.
#[derive(Debug, Clone)]
pub(crate) struct Tsqr {
    n: usize,
    /// `R`, column-major `n × n`, in the current scales.
    r: [f64; NARROW * NARROW],
    /// Each column's exponent so far; `None` while it has been all zeros.
    exponents: [Option<i32>; NARROW],
    rows: usize,
    /// `λ`'s mean and sum of squares about it, in its current scale
    /// (blocks combined as Chan, Golub and LeVeque's pairwise update).
    mean: f64,
    m2: f64,
    /// The block under `R`, column-major, `n + BLOCK_ROWS` rows a column
    /// (`n + rows` once a short block is pushed): the caller writes the
    /// block's rows in place ([`staging`](Tsqr::staging)).
    w: Vec<f64>,
}

/// What [`Tsqr::finish`] gives: `R` (column-major `n × n`), each column's
/// exponent, the rows and `λ`'s spread.
#[derive(Debug, Clone)]
pub(crate) struct Factored {
    pub r: [f64; NARROW * NARROW],
    pub n: usize,
    pub exponents: Vec<i32>,
    pub rows: usize,
    pub sst: f64,
}

impl Factored {
    /// `R[i, j]`.
    pub fn r(&self, i: usize, j: usize) -> f64 {
        self.r[j * self.n + i]
    }
}

impl Tsqr {
    /// An empty problem of `n ≤ NARROW` columns, `[Φ | λ]`.
    pub fn new(n: usize) -> Self {
        debug_assert!(n <= NARROW && n > 0);
        Self {
            n,
            r: [0.0; NARROW * NARROW],
            exponents: [None; NARROW],
            rows: 0,
            mean: 0.0,
            m2: 0.0,
            w: vec![0.0; (n + BLOCK_ROWS) * n],
        }
    }

    /// Where the next block's rows go: row `i` of column `j` at
    /// `[j * stride + i]` of the slice returned with `stride`.
    pub fn staging(&mut self) -> (&mut [f64], usize) {
        let n = self.n;
        (&mut self.w[n..], n + BLOCK_ROWS)
    }

    /// Adds `rows ≤ BLOCK_ROWS` rows, written to [`staging`](Self::staging)
    /// and equilibrated there.
    ///
    /// # Errors
    ///
    /// [`NonFiniteBlock`] when a column holds a non-finite value.
    pub fn push_staged(&mut self, rows: usize) -> Result<(), NonFiniteBlock> {
        debug_assert!(rows <= BLOCK_ROWS);
        if rows == 0 {
            return Ok(());
        }
        let n = self.n;
        let stride = n + BLOCK_ROWS;
        for j in 0..n {
            let col = &mut self.w[j * stride + n..j * stride + n + rows];
            let largest = finite_max_abs(col).ok_or(NonFiniteBlock)?;
            if largest > 0.0 {
                let e = binary_exponent(largest);
                match self.exponents[j] {
                    Some(now) if now >= e => {}
                    Some(now) => {
                        // Earlier rows were divided by 2^now: bring R's
                        // column (and λ's moments) to 2^e.
                        let f = pow2(now - e);
                        self.r[j * n..(j + 1) * n].iter_mut().for_each(|v| *v *= f);
                        if j + 1 == n {
                            self.mean *= f;
                            self.m2 *= f * f;
                        }
                        self.exponents[j] = Some(e);
                    }
                    None => self.exponents[j] = Some(e),
                }
            }
            scale_column(col, self.exponents[j].unwrap_or(0));
        }
        // λ's moments, this block's about its own mean, then combined.
        let lam = &self.w[(n - 1) * stride + n..(n - 1) * stride + n + rows];
        let mean = sum_by(lam, |v| v) / rows as f64;
        let m2 = sum_by(lam, |v| (v - mean) * (v - mean));
        let (na, nb) = (self.rows as f64, rows as f64);
        let delta = mean - self.mean;
        let total = na + nb;
        self.mean += delta * (nb / total);
        self.m2 += m2 + delta * delta * (na * nb / total);
        // This block under R, factored (as householder_blocked): columns
        // of n + rows.
        let ld = n + rows;
        for j in 0..n {
            if ld < stride && j > 0 {
                self.w
                    .copy_within(j * stride + n..j * stride + ld, j * ld + n);
            }
            for i in 0..n {
                self.w[j * ld + i] = if i <= j { self.r[j * n + i] } else { 0.0 };
            }
        }
        householder_narrow(&mut self.w[..ld * n], ld, n);
        for j in 0..n {
            self.r[j * n..=j * n + j].copy_from_slice(&self.w[j * ld..=j * ld + j]);
        }
        self.rows += rows;
        Ok(())
    }

    /// The factor of all rows pushed.
    pub fn finish(&self) -> Factored {
        Factored {
            r: self.r,
            n: self.n,
            exponents: self.exponents[..self.n]
                .iter()
                .map(|e| e.unwrap_or(0))
                .collect(),
            rows: self.rows,
            sst: self.m2,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ident::solve::{equilibrate, householder_blocked, spread};

    /// Adds `rows` rows: column `j` at `block[j * stride..]`.
    fn push(
        tsqr: &mut Tsqr,
        block: &[f64],
        stride: usize,
        rows: usize,
    ) -> Result<(), NonFiniteBlock> {
        let n = tsqr.n;
        let (to, ld) = tsqr.staging();
        for j in 0..n {
            to[j * ld..j * ld + rows].copy_from_slice(&block[j * stride..j * stride + rows]);
        }
        tsqr.push_staged(rows)
    }

    /// The streamed factor is the stored problem's (equilibrated, then
    /// blocked QR) bit for bit, with columns whose magnitude rises along
    /// the rows and a column of zeros at first.
    #[test]
    fn the_streamed_factor_is_the_stored_one_bit_for_bit() {
        let (m, n) = (BLOCK_ROWS * 131 + 77, 3);
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut noise = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let mut a = vec![0.0; m * n];
        for i in 0..m {
            let x = i as f64 / m as f64;
            let grow = 10f64.powi((i / 9000) as i32);
            a[i] = 1e-7 * (1.0 + x) * grow;
            a[m + i] = if i < 3000 {
                0.0
            } else {
                3e5 * (40.0 * x).sin()
            };
            a[2 * m + i] = 0.3 * a[i] - 2e-12 * a[m + i] + 1e-9 * noise();
        }
        let mut stored = a.clone();
        let mut exponents = vec![0; n];
        equilibrate(&mut stored, m, &mut exponents).unwrap();
        let want_sst = spread(&stored[2 * m..]);
        householder_blocked(&mut stored, m, n);
        let mut tsqr = Tsqr::new(n);
        let mut block = vec![0.0; n * BLOCK_ROWS];
        let mut at = 0;
        while at < m {
            let rows = BLOCK_ROWS.min(m - at);
            for j in 0..n {
                block[j * BLOCK_ROWS..j * BLOCK_ROWS + rows]
                    .copy_from_slice(&a[j * m + at..j * m + at + rows]);
            }
            push(&mut tsqr, &block, BLOCK_ROWS, rows).unwrap();
            at += rows;
        }
        let f = tsqr.finish();
        assert_eq!(f.exponents, exponents);
        for j in 0..n {
            for i in 0..=j {
                let want = stored[j * m + i].to_bits();
                assert_eq!(f.r(i, j).to_bits(), want, "R[{i}, {j}]");
            }
        }
        // λ's spread, combined block by block, to rounding.
        assert!(
            (f.sst - want_sst).abs() <= 1e-13 * want_sst,
            "{} vs {want_sst}",
            f.sst
        );
        assert_eq!(f.rows, m);
    }

    #[test]
    fn a_non_finite_entry_is_reported() {
        let mut tsqr = Tsqr::new(2);
        let block = [1.0, 2.0, 3.0, 4.0, 5.0, 7.0];
        push(&mut tsqr, &block, 3, 3).unwrap();
        for bad in [f64::NAN, f64::INFINITY] {
            let block = [1.0, bad, 3.0, 4.0, 5.0, 7.0];
            assert_eq!(push(&mut tsqr, &block, 3, 3), Err(NonFiniteBlock));
        }
    }
}
