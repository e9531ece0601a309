//! The two least-squares stages. A stage is built by ranges of rows
//! ([`Spec::fill`]). Under [`BLOCKED_FROM_ROWS`] rows it is built whole and
//! solved as stored; a longer one is streamed, its rows built
//! [`BLOCK_ROWS`] at a time and factored under the `R` of the rows before
//! ([`Tsqr`]): the stored problem's factor, bit for bit, with no column
//! of the recording's length held. With Newey–West a streamed stage is
//! then built again, a block at a time, into each row's influence (the
//! stored stage's, bit for bit): the one series of the recording's length
//! the sums need. A stored stage becomes that influence in place of an
//! equilibrated copy.

use nalgebra::{DMatrix, DVector};

use super::influence::{Carry, carry, carry_max_ss, overflows};
use super::regressors::{Differences, Kind, Out, Spec};
use crate::error::Error;
use crate::ident::{
    BLOCK_ROWS, BLOCKED_FROM_ROWS, Covariance, DEFAULT_MAX_CONDITION, LeastSquaresFit, NARROW,
    Scratch, Series, Sink, Source, Stats, Triangular, Tsqr, binary_exponent, classical,
    equilibrate, equilibrate_into, fit_from, householder_narrow, influence_into, newey_west_of,
    pow2, scale_pow2, spread, triangular,
};
use crate::kernels::reduce::{max_abs, max_ss};

/// Most parameters of stage 2: `K`, `b2`, `m2`, `F2`.
pub(super) const MAX_STAGE2: usize = 4;

/// What stage 2's Newey–West errors need of stage 1 besides its influence
/// on `k2` (kept in the [`Solver`]).
pub(super) struct FirstStage;

/// A stage's factorisation: its triangular solve, the columns' exponents,
/// `λ`'s spread, and with Newey–West where the stored stage's rows as
/// built (and stage 2's `z`) lie in the solver's buffer.
pub(super) struct Factored {
    pub tri: Triangular,
    pub exponents: Vec<i32>,
    pub sst: f64,
    pub raw_at: usize,
    pub z_at: usize,
}

/// The buffers of the stages, kept between them.
pub(super) struct Solver {
    covariance: Covariance,
    /// A stored stage's equilibrated `[Φ | λ]` (factored in place, then
    /// the influence series) and, with Newey–West, its rows as built and
    /// `z`; a streamed stage's influence series.
    buf: Vec<f64>,
    /// Stage 1's influence on `k2` at every row of the segments (zero
    /// where it used none).
    k2: Vec<f64>,
    /// A stage's series scattered to every row, when it keeps some.
    series: Vec<f64>,
    /// The cold path's rows.
    block: Vec<f64>,
    scratch: Scratch,
    stats: Stats,
    starts: Vec<usize>,
    /// Stages of at least this many rows are streamed.
    stream_from: usize,
}

impl Solver {
    pub fn new(covariance: Covariance) -> Self {
        Self {
            covariance,
            buf: Vec::new(),
            k2: Vec::new(),
            series: Vec::new(),
            block: Vec::new(),
            scratch: Scratch::default(),
            stats: Stats::default(),
            starts: Vec::new(),
            stream_from: BLOCKED_FROM_ROWS,
        }
    }

    /// A solver that streams stages of at least `rows` rows (tests compare
    /// the streamed and the stored stages on short recordings).
    #[cfg(test)]
    pub fn streaming_from(covariance: Covariance, rows: usize) -> Self {
        Self {
            stream_from: rows.max(1),
            ..Self::new(covariance)
        }
    }

    /// The stage's buffer (`[Φ | λ (| z)]`, or the influence series).
    #[cfg(test)]
    pub fn buf_for_tests(&mut self) -> &mut Vec<f64> {
        &mut self.buf
    }

    /// Solves the stage `spec`. Stage 1 (`k2_index`: its parameter `k2`)
    /// returns what stage 2's errors need; stage 2 takes it as `first`.
    ///
    /// With Newey–West, each row's influence `(ΦᵀΦ)⁻¹ φ_t e_t` is placed
    /// at its sample in the segments (zero at the rows left out, so that
    /// lags count samples), and stage 2's carries stage 1's error in `k2`:
    /// `θ̂₂` is affine in `k2`, `∂θ̂₂/∂k2 = g` solves `Φ₂ g ≈ z`, so a row's
    /// influence on `θ̂₂` is its own plus `g` times its influence on `k̂2`.
    /// The covariance is the Newey–West sum of those series, within the
    /// segments. With cart 2's mass free, stage 2 is solved divided by it
    /// for `θ' = [K, b2, k2, (F2)] / m2` and mapped to `θ = [K, b2, m2,
    /// (F2)]` with `k2`.
    pub fn solve<D: Differences>(
        &mut self,
        spec: &Spec<'_, '_>,
        k2_index: usize,
        first: Option<&FirstStage>,
    ) -> Result<(LeastSquaresFit, Option<FirstStage>), Error> {
        let data = spec.data;
        let (m, p) = (spec.keep.map_or(data.rows, |k| k.moving), spec.p);
        if m <= p {
            return Err(Error::TooFewSamples {
                what: "least squares (more rows than parameters)",
                needed: p + 1,
                got: m,
            });
        }
        let lags = match self.covariance {
            Covariance::Classical => None,
            Covariance::NeweyWest { lags } => Some(lags),
        };
        let want_z = lags.is_some() && matches!(spec.kind, Kind::Second { .. });
        let streamed = m >= self.stream_from;
        let f = if streamed {
            self.factor_streamed::<D>(spec, m)?
        } else {
            self.factor_stored::<D>(spec, m, lags.is_some(), want_z)?
        };
        let Factored {
            tri,
            exponents,
            sst,
            raw_at,
            z_at,
        } = f;
        let mut fit = fit_from(
            &tri,
            classical(&tri, m, p),
            Covariance::Classical,
            m,
            &exponents,
            sst,
        )?;
        let k2_value = match spec.kind {
            Kind::FreeMass { k2 } => Some(k2),
            _ => None,
        };
        let Some(lags) = lags else {
            if let Some(k2) = k2_value {
                let (jacobian, _) = free_mass(&mut fit.theta, k2)?;
                fit.covariance = &jacobian * &fit.covariance * jacobian.transpose();
                fit.std_errors = fit.covariance.diagonal().map(|v| v.max(0.0).sqrt());
            }
            return finite(fit).map(|fit| (fit, None));
        };
        let n = data.rows;
        // Stage 1's series is its influence: its stats are found on the
        // way, unless the rows kept are scattered (a stored stage sums
        // the scattered series).
        let found = first.is_none() && (streamed || spec.keep.is_none());
        let g = if streamed {
            self.influence_streamed::<D>(spec, m, &tri, &exponents, want_z, found)
        } else {
            self.influence_stored(m, p, &tri, &exponents, want_z, raw_at, z_at, found)
        };
        if let Some(g) = &g
            && !g.iter().all(|v| v.is_finite())
        {
            return Err(Error::Overflow {
                operation: "least squares (a sensitivity exceeds f64::MAX)",
            });
        }
        let map = match k2_value {
            Some(k2) => Some(free_mass(&mut fit.theta, k2)?),
            None => None,
        };
        // The series at every row of the segments, scattered when the
        // stage keeps some, then carried or mapped.
        let series: &mut [f64] = match spec.keep {
            None => &mut self.buf[..n * p],
            Some(keep) => {
                self.series.clear();
                self.series.resize(n * p, 0.0);
                for j in 0..p {
                    let h = &self.buf[j * m..(j + 1) * m];
                    let to = &mut self.series[j * n..(j + 1) * n];
                    let rows = keep
                        .direction
                        .iter()
                        .enumerate()
                        .filter(|(_, d)| **d != 0.0);
                    for (&v, (r, _)) in h.iter().zip(rows) {
                        to[r] = v;
                    }
                }
                &mut self.series
            }
        };
        let how = match (&g, &map) {
            _ if first.is_none() => None,
            (Some(g), _) => Some(Carry::Sensitivity(g)),
            (None, Some(map)) => Some(Carry::FreeMass(map)),
            (None, None) => None,
        };
        // Each column's largest entry and sum of squares, for the sums.
        if let Some(Carry::Sensitivity(g)) = how {
            let (max, ss) = (&mut self.stats.max, &mut self.stats.ss);
            carry_max_ss(series, n, &self.k2, g, max, ss);
        } else if found {
            // Found with the influence (the scattered rows' zeros add
            // none to a streamed stage's, found block by block).
        } else {
            if let Some(how) = &how {
                carry(series, n, p, &self.k2, how);
            }
            self.stats.max.clear();
            self.stats.ss.clear();
            for col in series.chunks_exact(n) {
                let (max, ss) = max_ss(col);
                self.stats.max.push(max);
                self.stats.ss.push(ss);
            }
        }
        let known = (self.stats.max.iter().chain(&self.stats.ss)).all(|v| v.is_finite());
        // Not finite: the stored solve's error if a row's own influence
        // was not (else the sums overflow, which `finite` reports).
        if !known && overflows::<D>(spec, &tri, &exponents, &mut self.block) {
            return Err(Error::Overflow {
                operation: "least squares (the influence of a row exceeds f64::MAX)",
            });
        }
        self.starts.clear();
        self.starts.extend(data.segments.iter().map(|s| s.row0));
        let x = Series {
            x: series,
            n,
            stats: known.then_some(&self.stats),
        };
        let (covariance, used) = newey_west_of(x, p, &self.starts, m, lags, &mut self.scratch);
        fit.std_errors = covariance.diagonal().map(|v| v.max(0.0).sqrt());
        fit.covariance = covariance;
        fit.covariance_kind = Covariance::NeweyWest { lags: Some(used) };
        let fit = finite(fit)?;
        // Stage 1 keeps its influence on k2 for stage 2.
        let state = matches!(spec.kind, Kind::First { .. }).then(|| {
            let series = match spec.keep {
                None => &self.buf[..n * p],
                Some(_) => &self.series[..n * p],
            };
            self.k2.clear();
            self.k2
                .extend_from_slice(&series[k2_index * n..(k2_index + 1) * n]);
            FirstStage
        });
        Ok((fit, state))
    }

    /// Each row's influence in place of the stored stage's spent factor
    /// (at the buffer's start), from its rows as built at `raw_at`
    /// equilibrated as they are read (stage 2's `g` from `U = Φ R⁻¹` and
    /// `z` at `z_at` on the way; with `found`, the series' stats).
    #[allow(clippy::too_many_arguments)]
    pub(super) fn influence_stored(
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
    pub(super) fn influence_streamed<D: Differences>(
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

    /// Builds the stage whole (`m` rows, then stage 2's `z` with
    /// `want_z`) and factors it as the stored solve does, equilibrated
    /// then factored in place; with `keep_raw` (Newey–West), built after
    /// the room of its equilibrated copy and kept as built for the
    /// influence (`[A | raw [Φ | λ] | z]`), so no copy is made.
    fn factor_stored<D: Differences>(
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
    pub(super) fn factor_streamed<D: Differences>(
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

/// `fit`, unless a covariance or standard error overflowed.
fn finite(fit: LeastSquaresFit) -> Result<LeastSquaresFit, Error> {
    if fit.covariance.iter().all(|v| v.is_finite()) && fit.std_errors.iter().all(|v| v.is_finite())
    {
        Ok(fit)
    } else {
        Err(Error::Overflow {
            operation: "identification (a standard error exceeds f64::MAX)",
        })
    }
}

/// Maps stage 2's normalised estimate `θ' = [K, b2, k2, (F2)] / m2` in
/// place to `θ = [K, b2, m2, (F2)]` with the coupling spring `k2`: `m2 =
/// k2 / θ'₂`, the others `k2 θ'ᵢ / θ'₂`. Returns `J = ∂θ/∂θ'` and
/// `∂θ/∂k2 = θ / k2`.
pub(super) fn free_mass(
    theta: &mut DVector<f64>,
    k2: f64,
) -> Result<(DMatrix<f64>, [f64; MAX_STAGE2]), Error> {
    let p = theta.len();
    let c = theta[2];
    let m2 = k2 / c;
    if !(m2.is_finite() && m2 > 0.0) {
        return Err(Error::InvalidParameter {
            name: "m2 (fitted)",
            value: m2,
            reason: "cart 2's fitted mass is not finite and > 0 kg: the run does not \
                     identify it (see Options::free_m2)",
        });
    }
    let mut jacobian = DMatrix::zeros(p, p);
    let mut per_k2 = [0.0; MAX_STAGE2];
    for i in 0..p {
        let ratio = if i == 2 { 1.0 } else { theta[i] };
        // θᵢ = k2 ratio / c.
        jacobian[(i, 2)] = -k2 * ratio / (c * c);
        if i != 2 {
            jacobian[(i, i)] = k2 / c;
        }
        per_k2[i] = ratio / c;
        theta[i] = k2 * ratio / c;
    }
    Ok((jacobian, per_k2))
}
