//! Each row's influence into the solver's series: a stored stage's from
//! its rows as built, a streamed stage's built again a block at a time.

use nalgebra::DVector;

use super::super::regressors::{Differences, Out, Spec};
use super::Solver;
use crate::ident::{
    BLOCK_ROWS, Sink, Source, Triangular, binary_exponent, influence_into, pow2, scale_pow2,
};
use crate::kernels::reduce::max_abs;

impl Solver {
    /// Each row's influence in place of the stored stage's spent factor
    /// (at the buffer's start), from its rows as built at `raw_at`
    /// equilibrated as they are read (stage 2's `g` from `U = Φ R⁻¹` and
    /// `z` at `z_at` on the way; with `found`, the series' stats).
    #[allow(clippy::too_many_arguments)]
    pub(in crate::lab::ident) fn influence_stored(
        &mut self,
        m: usize,
        p: usize,
        tri: &Triangular,
        exponents: &[i32],
        want_z: bool,
        raw_at: usize,
        z_at: usize,
        found: bool,
    ) -> Option<Vec<f64>> {
        let factors: Vec<f64> = exponents.iter().map(|&e| pow2(-e)).collect();
        let (series, rest) = self.buf.split_at_mut(raw_at);
        let rest = &rest[..z_at - raw_at + usize::from(want_z) * m];
        let z = want_z.then(|| {
            let z = &rest[z_at - raw_at..];
            (z, binary_exponent(max_abs(z)))
        });
        let e_z = z.map_or(0, |(_, e)| e);
        let mut stats = vec![(0.0, 0.0); p];
        let sink = Sink {
            cols: &mut series[..m * p],
            stride: m,
            z: z.map(|(z, e_z)| (z, pow2(-e_z))),
            stats: found.then_some(&mut stats[..p]),
        };
        let source = Source {
            cols: rest,
            stride: m,
            factors: &factors,
        };
        let qz = influence_into(source, m, &tri.theta, &tri.rinv, &units(exponents, p), sink);
        if found {
            self.keep_stats(&stats[..p], false);
        }
        qz.map(|qz| unscaled(&(&tri.rinv * qz), e_z, exponents))
    }

    /// Takes `stats` as the series' (`add`: as one more block's).
    fn keep_stats(&mut self, stats: &[(f64, f64)], add: bool) {
        let (max, ss) = (&mut self.stats.max, &mut self.stats.ss);
        if !add {
            max.clear();
            max.resize(stats.len(), 0.0);
            ss.clear();
            ss.resize(stats.len(), 0.0);
        }
        for ((max, ss), &(m, s)) in max.iter_mut().zip(ss.iter_mut()).zip(stats) {
            *max = max.max(m);
            *ss += s;
        }
    }

    /// Each row's influence into the buffer (`m × p`, as the stored
    /// stage's), the stage built again a block at a time after its
    /// factor: the same rows, equilibrated by the same powers of two as
    /// they are read, so the same influence bit for bit. Stage 2's `g` sums
    /// each block's part, `z` divided by the power of two of its largest
    /// entry so far (the sums rescaled exactly when a later block raises
    /// it); with `found`, the series' stats are summed block by block.
    pub(in crate::lab::ident) fn influence_streamed<D: Differences>(
        &mut self,
        spec: &Spec<'_, '_>,
        m: usize,
        tri: &Triangular,
        exponents: &[i32],
        want_z: bool,
        found: bool,
    ) -> Option<Vec<f64>> {
        let (p, n) = (spec.p, spec.data.rows);
        let width = spec.width();
        let stride = BLOCK_ROWS;
        let mut block = std::mem::take(&mut self.block);
        block.clear();
        block.resize((width + usize::from(want_z)) * stride, 0.0);
        // Every entry is written below: stage 2 reuses stage 1's without
        // clearing it.
        self.buf.truncate(m * p);
        self.buf.resize(m * p, 0.0);
        let d = units(exponents, p);
        let factors: Vec<f64> = exponents.iter().map(|&e| pow2(-e)).collect();
        let mut qz = DVector::<f64>::zeros(p);
        let mut e_z: Option<i32> = None;
        let mut stats = vec![(0.0, 0.0); p];
        if found {
            self.keep_stats(&stats, false);
        }
        let (mut from, mut have, mut at) = (0, 0, 0);
        while from < n {
            let to = (from + BLOCK_ROWS - have).min(n);
            have += spec.fill::<D>(
                (from, to),
                true,
                want_z,
                Out::Slices(&mut block[have..], stride),
            );
            from = to;
            if have < BLOCK_ROWS && !(from == n && have > 0) {
                continue;
            }
            let (rows, z) = block.split_at(width * stride);
            let mut z_f = None;
            if want_z {
                let z = &z[..have];
                let largest = max_abs(z);
                if largest > 0.0 {
                    let e = binary_exponent(largest);
                    match e_z {
                        Some(now) if now >= e => {}
                        Some(now) => {
                            let f = pow2(now - e);
                            qz.iter_mut().for_each(|v| *v *= f);
                            e_z = Some(e);
                        }
                        None => e_z = Some(e),
                    }
                    z_f = Some((z, pow2(-e_z.unwrap_or(0))));
                }
            }
            let source = Source {
                cols: rows,
                stride,
                factors: &factors,
            };
            let sink = Sink {
                cols: &mut self.buf[at..],
                stride: m,
                z: z_f,
                stats: found.then_some(&mut stats[..]),
            };
            if let Some(sums) = influence_into(source, have, &tri.theta, &tri.rinv, &d, sink) {
                qz += sums;
            }
            if found {
                self.keep_stats(&stats, true);
            }
            at += have;
            have = 0;
        }
        debug_assert_eq!(at, m);
        self.block = block;
        want_z.then(|| unscaled(&(&tri.rinv * qz), e_z.unwrap_or(0), exponents))
    }
}

/// Each parameter's power of two in the influence: `λ`'s column's
/// exponent less the parameter's column's (`exponents` has `p + 1`).
fn units(exponents: &[i32], p: usize) -> Vec<i32> {
    (0..p).map(|j| exponents[p] - exponents[j]).collect()
}

/// Stage 2's sensitivity `g` in the parameters' units, from its sums of
/// the equilibrated columns with `z` divided by `2^e_z`.
fn unscaled(gz: &DVector<f64>, e_z: i32, exponents: &[i32]) -> Vec<f64> {
    gz.iter()
        .zip(exponents)
        .map(|(&g, &e)| scale_pow2(g, e_z - e))
        .collect()
}
