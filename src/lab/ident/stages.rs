//! The two least-squares stages. A stage of fewer than
//! [`BLOCKED_FROM_ROWS`] rows is built whole and solved as stored; a
//! longer one is streamed: its rows built [`BLOCK_ROWS`] at a time and
//! factored under the `R` of the rows before ([`Tsqr`]), the same factor
//! bit for bit. With Newey–West, each row's influence is computed again
//! block by block from the samples ([`influence`]) and handed to the sums,
//! so that no column of the recording's length is held.

use nalgebra::{DMatrix, DVector};

use super::influence::{Influence, K2, Own, carry_and_map, overflows};
use super::regressors::{Differences, Kind, Out, Spec};
use crate::error::Error;
use crate::ident::{
    BLOCK_ROWS, BLOCKED_FROM_ROWS, Covariance, DEFAULT_MAX_CONDITION, LeastSquaresFit, Scratch,
    Stats, Stored, Triangular, Tsqr, classical, equilibrate, fit_from, householder_narrow,
    influence_rows, newey_west_of, scale_pow2, sensitivity_of, spread, triangular,
};
use crate::kernels::reduce::max_ss;

/// Most parameters of stage 2: `K`, `b2`, `m2`, `F2`.
pub(super) const MAX_STAGE2: usize = 4;

/// What stage 2's Newey–West errors need of stage 1: its solve, and its
/// influence on `k2` at every row when it was solved whole.
pub(super) struct FirstStage {
    pub tri: Triangular,
    pub exponents: Vec<i32>,
    pub k2_index: usize,
    pub whole: bool,
}

/// The buffers of the stages, kept between them.
pub(super) struct Solver {
    covariance: Covariance,
    /// A stage's `[Φ | λ (| z)]`, whole or a block of it.
    buf: Vec<f64>,
    /// Stage 1's influence on `k2` at every row of the segments (zero
    /// where it used none), when it was solved whole.
    k2: Vec<f64>,
    /// A whole stage's series scattered to every row, when it keeps some.
    series: Vec<f64>,
    /// A block of stage 1's rows, and its influence on `k2`.
    block: Vec<f64>,
    k2_rows: Vec<f64>,
    scratch: Scratch,
    stats: Stats,
    starts: Vec<usize>,
}

impl Solver {
    pub fn new(covariance: Covariance) -> Self {
        Self {
            covariance,
            buf: Vec::new(),
            k2: Vec::new(),
            series: Vec::new(),
            block: Vec::new(),
            k2_rows: Vec::new(),
            scratch: Scratch::default(),
            stats: Stats::default(),
            starts: Vec::new(),
        }
    }

    /// Solves the stage `spec`. Stage 1 (`k2_index`: its parameter `k2`)
    /// returns what stage 2's errors need; stage 2 takes it as `first`
    /// (with stage 1's `Spec`).
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
        first: Option<(&Spec<'_, '_>, &FirstStage)>,
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
        let whole = m < BLOCKED_FROM_ROWS;
        let (tri, exponents, sst, mut g) = if whole {
            self.factor_whole::<D>(spec, m, lags.is_some(), want_z)?
        } else {
            self.factor_streamed::<D>(spec, m, want_z)?
        };
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
        // Where a whole stage's copy, then its series, lies in `buf`.
        let copy_at = m * (spec.width() + usize::from(want_z));
        if whole {
            // The equilibrated problem, copied before the QR, then each
            // row's influence in its place (and stage 2's g from z), as the
            // stored solve.
            let (head, work) = self.buf.split_at_mut(m * (p + 1 + usize::from(want_z)));
            let work = &mut work[..m * (p + 1)];
            if want_z {
                let z = &head[m * (p + 1)..];
                let (gz, e_z) = sensitivity_of(work, m, m, &tri.rinv, z, &mut self.block);
                g = Some(
                    (0..p)
                        .map(|j| scale_pow2(gz[j], e_z - exponents[j]))
                        .collect(),
                );
            }
            let d: Vec<i32> = (0..p).map(|j| exponents[p] - exponents[j]).collect();
            influence_rows(work, m, m, &tri.theta, &tri.rinv, &d);
        }
        if let Some(g) = &g
            && !g.iter().all(|v| v.is_finite())
        {
            return Err(sensitivity());
        }
        let map = match k2_value {
            Some(k2) => Some(free_mass(&mut fit.theta, k2)?),
            None => None,
        };
        self.starts.clear();
        self.starts.extend(data.segments.iter().map(|s| s.row0));
        let k2 = first.map(|(spec1, stage1)| {
            if stage1.whole {
                K2::Whole(&self.k2)
            } else {
                K2::Regen {
                    spec: spec1,
                    tri: &stage1.tri,
                    exponents: &stage1.exponents,
                    k2_index: stage1.k2_index,
                }
            }
        });
        let (covariance, used) = if whole {
            // The series in place (scattered to every row when the stage
            // keeps some), carried or mapped, then summed as stored.
            let series: &mut [f64] = match spec.keep {
                None => &mut self.buf[copy_at..copy_at + n * p],
                Some(keep) => {
                    self.series.clear();
                    self.series.resize(n * p, 0.0);
                    for j in 0..p {
                        let h = &self.buf[copy_at + j * m..copy_at + (j + 1) * m];
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
            if let Some(k2) = &k2 {
                let mut from = 0;
                while from < n {
                    let len = BLOCK_ROWS.min(n - from);
                    k2.rows::<D>((from, len), &mut self.block, &mut self.k2_rows);
                    carry_and_map(
                        &mut series[from..],
                        n,
                        p,
                        &self.k2_rows,
                        g.as_deref(),
                        map.as_ref(),
                    );
                    from += len;
                }
            }
            // Each column's largest entry and sum of squares, for the sums.
            self.stats.max.clear();
            self.stats.ss.clear();
            let mut known = true;
            for col in series.chunks_exact(n) {
                let (max, ss) = max_ss(col);
                known &= max.is_finite() && ss.is_finite();
                self.stats.max.push(max);
                self.stats.ss.push(ss);
            }
            // Not finite: the stored solve's error if a row's own influence
            // was not (else the sums overflow, which `finite` reports).
            if !known && overflows::<D>(spec, &tri, &exponents, &mut self.block) {
                return Err(influence_overflow());
            }
            let mut stored = Stored {
                x: series,
                n,
                stats: known.then_some(&self.stats),
            };
            newey_west_of(&mut stored, n, p, &self.starts, m, lags, &mut self.scratch)
        } else {
            let own = Own {
                spec,
                tri: &tri,
                exponents: &exponents,
            };
            let mut source = Influence::<D>::new(own, p, k2, g, map);
            let result = newey_west_of(&mut source, n, p, &self.starts, m, lags, &mut self.scratch);
            drop(source);
            if result.0.iter().any(|v| !v.is_finite())
                && overflows::<D>(spec, &tri, &exponents, &mut self.block)
            {
                return Err(influence_overflow());
            }
            result
        };
        fit.std_errors = covariance.diagonal().map(|v| v.max(0.0).sqrt());
        fit.covariance = covariance;
        fit.covariance_kind = Covariance::NeweyWest { lags: Some(used) };
        let fit = finite(fit)?;
        // Stage 1 keeps its influence on k2 for stage 2.
        let state = matches!(spec.kind, Kind::First { .. }).then(|| {
            if whole {
                let series = match spec.keep {
                    None => &self.buf[copy_at..copy_at + n * p],
                    Some(_) => &self.series[..n * p],
                };
                self.k2.clear();
                self.k2
                    .extend_from_slice(&series[k2_index * n..(k2_index + 1) * n]);
            }
            FirstStage {
                tri,
                exponents,
                k2_index,
                whole,
            }
        });
        Ok((fit, state))
    }

    /// Builds the stage whole (`m` rows) and factors it as the stored
    /// solve does; returns the triangular solve, the exponents, `λ`'s
    /// spread and no `g` (the whole path finds it with the influence).
    /// With `copy` (Newey–West), the equilibrated `[Φ | λ]` is also left
    /// after the factor (and after stage 2's `z`, with `want_z`), for the
    /// rows' influence.
    #[allow(clippy::type_complexity)]
    fn factor_whole<D: Differences>(
        &mut self,
        spec: &Spec<'_, '_>,
        m: usize,
        copy: bool,
        want_z: bool,
    ) -> Result<(Triangular, Vec<i32>, f64, Option<Vec<f64>>), Error> {
        let (p, n) = (spec.p, spec.data.rows);
        let width = spec.width();
        let filled = width + usize::from(want_z);
        self.buf.clear();
        let rows = spec.fill::<D>((0, n), true, want_z, Out::Push(&mut self.buf));
        debug_assert_eq!((rows, self.buf.len()), (m, m * filled));
        let mut exponents = vec![0; width];
        equilibrate(&mut self.buf[..m * width], m, &mut exponents)?;
        let sst = spread(&self.buf[p * m..width * m]);
        if copy {
            self.buf.extend_from_within(..m * width);
        }
        if width <= crate::ident::NARROW {
            householder_narrow(&mut self.buf[..m * width], m, width);
        } else {
            unreachable!("the lab's stages have at most six columns");
        }
        let buf = &self.buf;
        let tri = triangular(|i, j| buf[j * m + i], p, DEFAULT_MAX_CONDITION)?;
        Ok((tri, exponents, sst, None))
    }

    /// Streams the stage (`m` rows) through [`Tsqr`] in blocks of
    /// [`BLOCK_ROWS`] kept rows; with `want_z` stage 2's `z` rides along
    /// as a last column, and `g` is its least-squares fit on `Φ`.
    #[allow(clippy::type_complexity)]
    fn factor_streamed<D: Differences>(
        &mut self,
        spec: &Spec<'_, '_>,
        m: usize,
        want_z: bool,
    ) -> Result<(Triangular, Vec<i32>, f64, Option<Vec<f64>>), Error> {
        let (p, n) = (spec.p, spec.data.rows);
        let width = spec.width() + usize::from(want_z);
        let mut tsqr = Tsqr::new(width, p + 1);
        let (mut from, mut have) = (0, 0);
        while from < n {
            let to = (from + BLOCK_ROWS - have).min(n);
            let (staging, stride) = tsqr.staging();
            have += spec.fill::<D>(
                (from, to),
                true,
                want_z,
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
        let mut exponents = f.exponents.clone();
        let g = want_z.then(|| {
            // R g' = (Qᵀ z)'s first p entries, then unscaled.
            let mut g = DVector::zeros(p);
            for i in (0..p).rev() {
                let mut s = f.r(i, p + 1);
                for j in i + 1..p {
                    s -= f.r(i, j) * g[j];
                }
                g[i] = s / f.r(i, i);
            }
            let e_z = f.exponents[p + 1];
            if !f.extra_finite {
                g.fill(f64::NAN);
            }
            (0..p)
                .map(|j| scale_pow2(g[j], e_z - f.exponents[j]))
                .collect()
        });
        exponents.truncate(p + 1);
        Ok((tri, exponents, f.sst, g))
    }

    /// The error of the first non-finite entry of the stage's `[Φ | λ]`,
    /// column by column (as the stored solve names it).
    #[cold]
    fn first_non_finite<D: Differences>(&mut self, spec: &Spec<'_, '_>, m: usize) -> Error {
        let (p, n) = (spec.p, spec.data.rows);
        let width = spec.width();
        self.buf.resize(width * BLOCK_ROWS, 0.0);
        for col in 0..=p {
            let (mut from, mut row) = (0, 0);
            while from < n {
                let to = (from + BLOCK_ROWS).min(n);
                let rows = spec.fill::<D>(
                    (from, to),
                    true,
                    false,
                    Out::Slices(&mut self.buf, BLOCK_ROWS),
                );
                let values = &self.buf[col * BLOCK_ROWS..col * BLOCK_ROWS + rows];
                if let Some(i) = values.iter().position(|v| !v.is_finite()) {
                    return Error::NonFinite {
                        matrix: "regressor",
                        row: row + i,
                        col,
                        value: values[i],
                    };
                }
                (from, row) = (to, row + rows);
            }
        }
        debug_assert!(false, "a block held a non-finite entry: {m} rows");
        Error::Overflow {
            operation: "least squares (a regressor is not finite)",
        }
    }
}

fn influence_overflow() -> Error {
    Error::Overflow {
        operation: "least squares (the influence of a row exceeds f64::MAX)",
    }
}

fn sensitivity() -> Error {
    Error::Overflow {
        operation: "least squares (a sensitivity exceeds f64::MAX)",
    }
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
