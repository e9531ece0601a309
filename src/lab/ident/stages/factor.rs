//! A stage factored: built whole and factored in place (stored), or
//! streamed through [`Tsqr`] a block at a time.

use super::super::regressors::{Differences, Out, Spec};
use super::{Factored, MAX_STAGE2, Solver};
use crate::error::Error;
use crate::ident::{
    BLOCK_ROWS, DEFAULT_MAX_CONDITION, NARROW, Tsqr, equilibrate, equilibrate_into,
    householder_narrow, spread, triangular,
};

impl Solver {
    /// Builds the stage whole (`m` rows, then stage 2's `z` with
    /// `want_z`) and factors it as the stored solve does, equilibrated
    /// then factored in place; with `keep_raw` (Newey–West), built after
    /// the room of its equilibrated copy and kept as built for the
    /// influence (`[A | raw [Φ | λ] | z]`), so no copy is made.
    pub(super) fn factor_stored<D: Differences>(
        &mut self,
        spec: &Spec<'_, '_>,
        m: usize,
        keep_raw: bool,
        want_z: bool,
    ) -> Result<Factored, Error> {
        let (p, n) = (spec.p, spec.data.rows);
        let width = spec.width();
        let filled = width + usize::from(want_z);
        let raw_at = if keep_raw { m * width } else { 0 };
        let len = raw_at + m * filled;
        // Every entry is written, so stage 2 reuses stage 1's room
        // unzeroed; stage 1 reserves what either stage can need (untouched
        // pages cost nothing), as growing would copy.
        let most = n * (2 * (MAX_STAGE2 + 1) + 1);
        self.buf.truncate(len);
        self.buf.reserve(len.max(most) - self.buf.len());
        self.buf.resize(len, 0.0);
        let (a, raw) = self.buf.split_at_mut(raw_at);
        let rows = spec.fill::<D>((0, n), true, want_z, Out::Slices(raw, m));
        debug_assert_eq!(rows, m);
        let mut exponents = vec![0; width];
        let a = if keep_raw {
            equilibrate_into(&raw[..m * width], a, m, &mut exponents)?;
            a
        } else {
            let a = &mut raw[..m * width];
            equilibrate(a, m, &mut exponents)?;
            a
        };
        let sst = spread(&a[p * m..width * m]);
        assert!(width <= NARROW, "the lab's stages have at most six columns");
        householder_narrow(a, m, width);
        let tri = triangular(|i, j| a[j * m + i], p, DEFAULT_MAX_CONDITION)?;
        Ok(Factored {
            tri,
            exponents,
            sst,
            raw_at,
            z_at: raw_at + m * width,
        })
    }

    /// Streams the stage (`m` rows) through [`Tsqr`] in blocks of
    /// [`BLOCK_ROWS`] kept rows, built in place.
    pub(in crate::lab::ident) fn factor_streamed<D: Differences>(
        &mut self,
        spec: &Spec<'_, '_>,
        m: usize,
    ) -> Result<Factored, Error> {
        let (p, n) = (spec.p, spec.data.rows);
        let width = spec.width();
        let mut tsqr = Tsqr::new(width);
        let (mut from, mut have) = (0, 0);
        while from < n {
            let to = (from + BLOCK_ROWS - have).min(n);
            let (staging, stride) = tsqr.staging();
            have += spec.fill::<D>(
                (from, to),
                true,
                false,
                Out::Slices(&mut staging[have..], stride),
            );
            from = to;
            if have == BLOCK_ROWS || (from == n && have > 0) {
                if tsqr.push_staged(have).is_err() {
                    return Err(self.first_non_finite::<D>(spec, m));
                }
                have = 0;
            }
        }
        let f = tsqr.finish();
        debug_assert_eq!(f.rows, m);
        let tri = triangular(|i, j| f.r(i, j), p, DEFAULT_MAX_CONDITION)?;
        Ok(Factored {
            tri,
            exponents: f.exponents,
            sst: f.sst,
            raw_at: 0,
            z_at: 0,
        })
    }

    /// The error of the first non-finite entry of the stage's `[Φ | λ]`,
    /// column by column (as the stored solve names it).
    #[cold]
    fn first_non_finite<D: Differences>(&mut self, spec: &Spec<'_, '_>, m: usize) -> Error {
        self.buf.clear();
        spec.fill::<D>((0, spec.data.rows), true, false, Out::Push(&mut self.buf));
        let mut exponents = vec![0; spec.width()];
        match equilibrate(&mut self.buf, m, &mut exponents) {
            Err(e) => e,
            Ok(()) => Error::Overflow {
                operation: "least squares (a regressor is not finite)",
            },
        }
    }
}
