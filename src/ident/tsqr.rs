//! A least-squares problem streamed in blocks of rows ([`Tsqr`]): the
//! triangular factor of `[Φ | λ]` (and of further columns, as `z` whose
//! least-squares fit on `Φ` is wanted too) updated block by block, so that
//! no column is ever held whole.
//!
//! Each block is factored under the `R` of the rows before it, as
//! [`householder_blocked`](super::solve) does with a stored problem, and
//! each column is equilibrated by the power of two of its largest entry
//! so far: when a block raises it, `R`'s column is rescaled, exactly. The
//! factor is then the one the stored problem's equilibration and blocked
//! QR give, bit for bit (barring entries below `f64::MIN_POSITIVE` after
//! scaling, which the stored problem would have rounded), with blocks of
//! [`BLOCK_ROWS`] rows from the first row.

use super::solve::{
    BLOCK_ROWS, NARROW, binary_exponent, householder_narrow_with, pow2, scale_column,
};
use crate::kernels::reduce::{finite_max_abs, sum_by};

/// A block held a non-finite entry in one of the checked columns; the
/// caller finds which (the stored problem's error names the first, column
/// by column).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct NonFiniteBlock;

/// The streamed factorisation of `[Φ | λ]` (`checked` columns, which must
/// be finite; `λ` the last) and further columns (`n` in all), each of
/// those taken through the reflectors of `[Φ | λ]` without entering them:
/// the factor of `[Φ | λ]` is the same with them or without, bit for bit.
#[derive(Debug, Clone)]
pub(crate) struct Tsqr {
    n: usize,
    checked: usize,
    /// `R`, column-major `n × n` (rows `0 … checked` of the further
    /// columns: `Qᵀ` times them), in the current scales.
    r: [f64; NARROW * NARROW],
    /// Each column's exponent so far; `None` while it has been all zeros.
    exponents: [Option<i32>; NARROW],
    /// Whether every unchecked column was finite.
    extra_finite: bool,
    rows: usize,
    /// `λ`'s mean and sum of squares about it, in its current scale
    /// (blocks combined as Chan, Golub and LeVeque's pairwise update).
    mean: f64,
    m2: f64,
    /// The block under `R`, column-major, `checked + BLOCK_ROWS` rows a
    /// column (`checked + rows` once a short block is pushed): the caller
    /// writes the block's rows in place ([`staging`](Tsqr::staging)).
    w: Vec<f64>,
}

/// What [`Tsqr::finish`] gives: `R` (column-major `n × n`), each column's
/// exponent, the rows, `λ`'s spread, and whether the unchecked columns
/// were finite.
#[derive(Debug, Clone)]
pub(crate) struct Factored {
    pub r: [f64; NARROW * NARROW],
    pub n: usize,
    pub exponents: Vec<i32>,
    pub rows: usize,
    pub sst: f64,
    pub extra_finite: bool,
}

impl Factored {
    /// `R[i, j]`.
    pub fn r(&self, i: usize, j: usize) -> f64 {
        self.r[j * self.n + i]
    }
}

impl Tsqr {
    /// An empty problem of `n ≤ NARROW` columns, the first `checked` of
    /// them `[Φ | λ]`.
    pub fn new(n: usize, checked: usize) -> Self {
        debug_assert!(n <= NARROW && checked <= n && checked > 0);
        Self {
            n,
            checked,
            r: [0.0; NARROW * NARROW],
            exponents: [None; NARROW],
            extra_finite: true,
            rows: 0,
            mean: 0.0,
            m2: 0.0,
            w: vec![0.0; (checked + BLOCK_ROWS) * n],
        }
    }

    /// Where the next block's rows go: row `i` of column `j` at
    /// `[j * stride + i]` of the slice returned with `stride`.
    pub fn staging(&mut self) -> (&mut [f64], usize) {
        let k = self.checked;
        (&mut self.w[k..], k + BLOCK_ROWS)
    }

    /// Adds `rows` rows, written to [`staging`](Self::staging) and
    /// equilibrated there.
    ///
    /// # Errors
    ///
    /// [`NonFiniteBlock`] when a checked column holds a non-finite value.
    pub fn push_staged(&mut self, rows: usize) -> Result<(), NonFiniteBlock> {
        debug_assert!(rows <= BLOCK_ROWS);
        if rows == 0 {
            return Ok(());
        }
        let (n, k) = (self.n, self.checked);
        let stride = k + BLOCK_ROWS;
        for j in 0..n {
            let col = &mut self.w[j * stride + k..j * stride + k + rows];
            let largest = match finite_max_abs(col) {
                Some(largest) => largest,
                None if j < k => return Err(NonFiniteBlock),
                None => {
                    self.extra_finite = false;
                    col.fill(0.0);
                    0.0
                }
            };
            if largest > 0.0 {
                let e = binary_exponent(largest);
                match self.exponents[j] {
                    Some(now) if now >= e => {}
                    Some(now) => {
                        // Earlier rows were divided by 2^now: bring R's
                        // column (and λ's moments) to 2^e.
                        let f = pow2(now - e);
                        self.r[j * n..(j + 1) * n].iter_mut().for_each(|v| *v *= f);
                        if j + 1 == k {
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
        let lam = &self.w[(k - 1) * stride + k..(k - 1) * stride + k + rows];
        let mean = sum_by(lam, |v| v) / rows as f64;
        let m2 = sum_by(lam, |v| (v - mean) * (v - mean));
        let (na, nb) = (self.rows as f64, rows as f64);
        let delta = mean - self.mean;
        let total = na + nb;
        self.mean += delta * (nb / total);
        self.m2 += m2 + delta * delta * (na * nb / total);
        // This block under R, factored (as householder_blocked), the
        // further columns under their rows of Qᵀ: columns of k + rows.
        let ld = k + rows;
        for j in 0..n {
            if ld < stride && j > 0 {
                self.w
                    .copy_within(j * stride + k..j * stride + ld, j * ld + k);
            }
            for i in 0..k {
                self.w[j * ld + i] = if i <= j { self.r[j * n + i] } else { 0.0 };
            }
        }
        let (main, further) = self.w[..ld * n].split_at_mut(ld * k);
        householder_narrow_with(main, ld, k, further);
        for j in 0..n {
            let top = (j + 1).min(k);
            self.r[j * n..j * n + top].copy_from_slice(&self.w[j * ld..j * ld + top]);
        }
        self.rows += rows;
        Ok(())
    }

    /// Adds `rows` rows: column `j` at `block[j * stride..]`.
    #[cfg(test)]
    pub fn push(
        &mut self,
        block: &[f64],
        stride: usize,
        rows: usize,
    ) -> Result<(), NonFiniteBlock> {
        let n = self.n;
        let (to, ld) = self.staging();
        for j in 0..n {
            to[j * ld..j * ld + rows].copy_from_slice(&block[j * stride..j * stride + rows]);
        }
        self.push_staged(rows)
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
            extra_finite: self.extra_finite,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ident::solve::{equilibrate, householder_blocked};

    /// The streamed factor is the stored problem's (equilibrated, then
    /// blocked QR) bit for bit, with columns whose magnitude rises along
    /// the rows and a column of zeros at first.
    #[test]
    fn the_streamed_factor_is_the_stored_one_bit_for_bit() {
        let (m, n) = (BLOCK_ROWS * 131 + 77, 4);
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
            a[3 * m + i] = 1e3 * noise() * grow;
        }
        let mut stored = a.clone();
        let mut exponents = vec![0; n];
        equilibrate(&mut stored, m, &mut exponents).unwrap();
        let lam = stored[2 * m..3 * m].to_vec();
        let mut stored_plain = stored[..3 * m].to_vec();
        householder_blocked(&mut stored, m, n);
        householder_blocked(&mut stored_plain, m, 3);
        // Streamed: Φ = columns 0, 1; λ = column 2; column 3 unchecked.
        let mut tsqr = Tsqr::new(n, 3);
        let mut plain = Tsqr::new(3, 3);
        let mut block = vec![0.0; n * BLOCK_ROWS];
        let mut at = 0;
        while at < m {
            let rows = BLOCK_ROWS.min(m - at);
            for j in 0..n {
                block[j * BLOCK_ROWS..j * BLOCK_ROWS + rows]
                    .copy_from_slice(&a[j * m + at..j * m + at + rows]);
            }
            tsqr.push(&block, BLOCK_ROWS, rows).unwrap();
            plain.push(&block, BLOCK_ROWS, rows).unwrap();
            at += rows;
        }
        let f = tsqr.finish();
        assert_eq!(f.exponents, exponents);
        let bare = plain.finish();
        for j in 0..3 {
            for i in 0..=j {
                let want = stored_plain[j * m + i].to_bits();
                assert_eq!(f.r(i, j).to_bits(), want, "R[{i}, {j}]");
                assert_eq!(bare.r(i, j).to_bits(), want, "R[{i}, {j}]");
            }
        }
        // The further column: its rows of Qᵀ a₃ on Φ (those a fit of it on
        // Φ uses), as the stored four-column factor has them (to rounding:
        // its sums' lanes differ). Its row on λ's reflector is left out:
        // λ is Φ's combination to 1e-9 here, so that reflector's
        // direction, and that row, are fixed only to about 1e-7.
        for i in 0..2 {
            let (got, want) = (f.r(i, 3), stored[3 * m + i]);
            assert!(
                (got - want).abs() <= 1e-12 * want.abs().max(1.0),
                "{got} vs {want}"
            );
        }
        let want = crate::ident::solve::spread(&lam);
        assert!((f.sst - want).abs() <= 1e-13 * want, "{} vs {want}", f.sst);
        assert_eq!(f.rows, m);
    }

    #[test]
    fn a_non_finite_entry_is_reported_and_unchecked_columns_flagged() {
        let mut tsqr = Tsqr::new(3, 2);
        let block = [1.0, 2.0, 3.0, 4.0, 5.0, 7.0, 0.5, f64::INFINITY, 1.0];
        tsqr.push(&block, 3, 3).unwrap();
        assert!(!tsqr.finish().extra_finite);
        let block = [1.0, f64::NAN, 3.0, 4.0, 5.0, 7.0, 0.5, 1.0, 1.0];
        assert_eq!(tsqr.push(&block, 3, 3), Err(NonFiniteBlock));
    }
}
