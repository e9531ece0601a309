//! The two least-squares stages. A stage is built by ranges of rows
//! ([`Spec::fill`]). Under [`BLOCKED_FROM_ROWS`] rows it is built whole and
//! solved as stored; a longer one is streamed, its rows built
//! [`BLOCK_ROWS`] at a time and factored under the `R` of the rows before
//! ([`Tsqr`]): the stored problem's factor, bit for bit, with no column
//! of the recording's length held. With Newey–West a streamed stage is
//! then built again, a block at a time, into each row's influence (the
//! stored stage's, bit for bit): the one series of the recording's length
//! the sums need. A stored stage becomes that influence where its spent
//! factor was. With Newey–West on a streamed recording, stage 1's influence
//! and sums run on a thread beside stage 2 ([`both_beside`]).

mod beside;
mod factor;
mod series;

pub(super) use self::beside::{both_beside, one_after_the_other};

use nalgebra::{DMatrix, DVector};

use super::influence::{Carry, carry, carry_max_ss, overflows};
use super::regressors::{Differences, Kind, Spec};
use crate::error::Error;
use crate::ident::{
    BLOCKED_FROM_ROWS, Covariance, LeastSquaresFit, Scratch, Series, Stats, Triangular, classical,
    fit_from, newey_west_of,
};
use crate::kernels::reduce::max_ss;

/// Most parameters of stage 2: `K`, `b2`, `m2`, `F2`.
pub(super) const MAX_STAGE2: usize = 4;

/// What stage 2's Newey–West errors need of stage 1: its influence on
/// `k2` at every row of the segments (zero where it used none).
pub(super) struct FirstStage {
    pub k2: Vec<f64>,
}

/// A stage factored, its classical fit made: what its Newey–West errors
/// start from.
pub(super) struct Head {
    pub fit: LeastSquaresFit,
    f: Factored,
    m: usize,
    streamed: bool,
    /// The Newey–West lags asked for (`None`: classical errors).
    lags: Option<Option<usize>>,
}

/// A stage with each row's influence made: its fit, and unless its
/// errors are classical what its Newey–West sums need.
pub(super) struct Influenced {
    fit: LeastSquaresFit,
    series: Option<Pending>,
}

/// What a stage's Newey–West sums need besides its fit.
struct Pending {
    f: Factored,
    m: usize,
    lags: Option<usize>,
    g: Option<Vec<f64>>,
    map: Option<(DMatrix<f64>, [f64; MAX_STAGE2])>,
    found: bool,
}

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
    /// A stage's series scattered to every row, when it keeps some.
    series: Vec<f64>,
    /// The cold path's rows.
    block: Vec<f64>,
    scratch: Scratch,
    stats: Stats,
    starts: Vec<usize>,
    /// Stages of at least this many rows are streamed.
    stream_from: usize,
    /// Whether stage 1's Newey–West work runs on a thread of its own
    /// beside stage 2 (`None`: when it is long and a second CPU is there).
    beside: Option<bool>,
}

impl Solver {
    pub fn new(covariance: Covariance) -> Self {
        Self {
            covariance,
            buf: Vec::new(),
            series: Vec::new(),
            block: Vec::new(),
            scratch: Scratch::default(),
            stats: Stats::default(),
            starts: Vec::new(),
            stream_from: BLOCKED_FROM_ROWS,
            beside: None,
        }
    }

    /// A solver as this one (covariance, streaming) with buffers of its
    /// own: stage 2's while stage 1's sums run beside it.
    pub fn sibling(&self) -> Self {
        Self {
            stream_from: self.stream_from,
            beside: self.beside,
            ..Self::new(self.covariance)
        }
    }

    /// Whether stage 1's rest (`head`) should run on a thread beside stage
    /// 2: Newey–West on a streamed stage (at least 65 536 rows, some
    /// milliseconds of work against a thread's start of some 50 µs), with
    /// a second CPU to run it.
    pub fn beside(&self, head: &Head) -> bool {
        head.lags.is_some()
            && head.streamed
            && self
                .beside
                .unwrap_or_else(|| std::thread::available_parallelism().is_ok_and(|n| n.get() > 1))
    }

    /// A solver that always (`true`) or never runs stage 1's streamed
    /// Newey–West work beside stage 2, whatever the CPUs (tests compare).
    #[cfg(test)]
    pub fn with_beside(mut self, beside: bool) -> Self {
        self.beside = Some(beside);
        self
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
        let head = self.head::<D>(spec)?;
        let influenced = self.influence::<D>(spec, head)?;
        self.sums::<D>(spec, influenced, k2_index, first)
    }

    /// [`solve`](Self::solve)'s first part: the stage factored and its
    /// classical fit.
    pub fn head<D: Differences>(&mut self, spec: &Spec<'_, '_>) -> Result<Head, Error> {
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
        let fit = fit_from(
            &f.tri,
            classical(&f.tri, m, p),
            Covariance::Classical,
            m,
            &f.exponents,
            f.sst,
        )?;
        Ok(Head {
            fit,
            f,
            m,
            streamed,
            lags,
        })
    }

    /// [`solve`](Self::solve)'s second part: each row's influence (and
    /// stage 2's sensitivity `g`), or with classical errors the fit.
    pub fn influence<D: Differences>(
        &mut self,
        spec: &Spec<'_, '_>,
        head: Head,
    ) -> Result<Influenced, Error> {
        let Head {
            mut fit,
            f,
            m,
            streamed,
            lags,
        } = head;
        let p = spec.p;
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
            return finite(fit).map(|fit| Influenced { fit, series: None });
        };
        let want_z = matches!(spec.kind, Kind::Second { .. });
        let Factored {
            tri,
            exponents,
            raw_at,
            z_at,
            ..
        } = &f;
        // Stage 1's series is its influence: its stats are found on the
        // way, unless the rows kept are scattered (a stored stage sums
        // the scattered series).
        let stage1 = matches!(spec.kind, Kind::First { .. });
        let found = stage1 && (streamed || spec.keep.is_none());
        let g = if streamed {
            self.influence_streamed::<D>(spec, m, tri, exponents, want_z, found)
        } else {
            self.influence_stored(m, p, tri, exponents, want_z, *raw_at, *z_at, found)
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
        Ok(Influenced {
            fit,
            series: Some(Pending {
                f,
                m,
                lags,
                g,
                map,
                found,
            }),
        })
    }

    /// [`solve`](Self::solve)'s last part: the series carried (stage 2,
    /// with stage 1's `first`) and its Newey–West sums; stage 1 returns its
    /// influence on `k2` (parameter `k2_index`).
    pub fn sums<D: Differences>(
        &mut self,
        spec: &Spec<'_, '_>,
        influenced: Influenced,
        k2_index: usize,
        first: Option<&FirstStage>,
    ) -> Result<(LeastSquaresFit, Option<FirstStage>), Error> {
        let Influenced { mut fit, series } = influenced;
        let Some(Pending {
            f,
            m,
            lags,
            g,
            map,
            found,
        }) = series
        else {
            return Ok((fit, None));
        };
        let (data, p) = (spec.data, spec.p);
        let n = data.rows;
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
        let how = match (first, &g, &map) {
            (None, ..) => None,
            (Some(first), Some(g), _) => Some((&first.k2, Carry::Sensitivity(g))),
            (Some(first), None, Some(map)) => Some((&first.k2, Carry::FreeMass(map))),
            (Some(_), None, None) => None,
        };
        // Each column's largest entry and sum of squares, for the sums.
        if let Some((k2, Carry::Sensitivity(g))) = &how {
            let (max, ss) = (&mut self.stats.max, &mut self.stats.ss);
            carry_max_ss(series, n, k2, g, max, ss);
        } else if found {
            // Found with the influence (the scattered rows' zeros add
            // none to a streamed stage's, found block by block).
        } else {
            if let Some((k2, how)) = &how {
                carry(series, n, p, k2, how);
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
        let Factored { tri, exponents, .. } = &f;
        // Not finite: the stored solve's error if a row's own influence
        // was not (else the sums overflow, which `finite` reports).
        if !known && overflows::<D>(spec, tri, exponents, &mut self.block) {
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
        // Stage 1 hands its influence on k2 to stage 2.
        let state = matches!(spec.kind, Kind::First { .. }).then(|| {
            let series = match spec.keep {
                None => &self.buf[..n * p],
                Some(_) => &self.series[..n * p],
            };
            FirstStage {
                k2: series[k2_index * n..(k2_index + 1) * n].to_vec(),
            }
        });
        Ok((fit, state))
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
