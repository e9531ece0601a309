//! How [`validate_with`](super::validate_with) and
//! [`refine_with`](super::refine_with) simulate the rig between samples
//! ([`SimulationModel`]), and the simulation itself: the recorded input
//! through the drive's delay into the two-cart plant with stick–slip
//! friction, sub-step by sub-step as the simulated card does it.

use crate::nalgebra::{SMatrix, SVector, U3, U4, vector};

use crate::data::Recording;
use crate::discretize::zoh;
use crate::error::Error;
use crate::integrate::{Integrator, Rk4};
use crate::lab::{FrictionPlant, MassSpring};
use crate::model::Dynamics;
use crate::sim::{grid_rounding, uniform_step};

/// Fewest samples a run must have: three times the residual tests' lags.
const MIN_SAMPLES: usize = 3 * super::RESIDUAL_LAGS;
/// Most sub-steps per sampling interval: bounds a simulation's work.
const MAX_SUBSTEPS_PER_SAMPLE: f64 = 1000.0;

/// How the rig is simulated between samples for validation and output-error
/// refinement: the structure of the model, which the refined parameters
/// cannot make up for if it is wrong.
///
/// Each input `u_k` takes effect `input_delay` after its sample's actual
/// instant `t_k` and holds until the next input takes effect: with a delay
/// shorter than the interval, `[t_k, t_k+1]` holds the previous input until
/// `t_k + input_delay`, then `u_k`; after a late sample, whose next
/// interval can be shorter than the delay, `u_k` is replaced by `u_k+1`
/// before taking effect (the drive keeps only its newest pending command,
/// as the simulated card's does), and an interval holds whichever inputs
/// take effect within it, in order. Each part
/// is integrated in equal sub-steps of at most `max_substep`, and each
/// cart's stick or slip is decided between sub-steps ([`FrictionPlant`]'s rules, with breakaway
/// force `stiction_ratio × ` its Coulomb force). This is how the simulated
/// card ([`SimulatedRig`](crate::lab::SimulatedRig)) moves its plant, so
/// [`SimulatedRig::simulation_model`](crate::lab::SimulatedRig::simulation_model)
/// gives the structure that reproduces it; on a real rig, the drive's
/// delay and the breakaway ratio come from its data sheet or a separate
/// test (a slow force ramp).
///
/// Why it matters: refined with one integration step per 2 ms sample and
/// stick decisions only at samples, the simulated card's default run gave
/// K 1.3 % and F2 8 % high at K = 0.8 N/V; with the card's structure the
/// same runs come within 0.1 % (`tests/ident_refine.rs`).
///
/// # Examples
///
/// ```
/// use ctrlab::lab::ident::SimulationModel;
/// let m = SimulationModel::default();
/// assert_eq!((m.max_substep, m.input_delay, m.stiction_ratio), (0.25e-3, 0.0, [1.0, 1.0]));
/// assert!(m.validate().is_ok());
/// assert!(SimulationModel { stiction_ratio: [0.9, 1.0], ..m }.validate().is_err());
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SimulationModel {
    /// Longest integration sub-step, s (> 0; default 0.25 ms, the
    /// simulated card's). Stick and slip are decided between sub-steps.
    pub max_substep: f64,
    /// Time from a sample to its input taking effect, s (≥ 0 and shorter
    /// than the recording's median interval; default 0). It may be longer
    /// than some of the recording's intervals (a late sample's next
    /// interval): each input takes effect this long after its own sample's
    /// actual instant.
    pub input_delay: f64,
    /// Each cart's breakaway (static) friction over its Coulomb friction
    /// (≥ 1; default 1, no stiction above the Coulomb force).
    pub stiction_ratio: [f64; 2],
}

impl Default for SimulationModel {
    fn default() -> Self {
        Self {
            max_substep: 0.25e-3,
            input_delay: 0.0,
            stiction_ratio: [1.0; 2],
        }
    }
}

impl SimulationModel {
    /// Checks the fields on their own (the delay against the recording's
    /// median interval is checked when a recording is simulated).
    ///
    /// # Errors
    ///
    /// [`Error::InvalidParameter`] naming the first bad field.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{Error, lab::ident::SimulationModel};
    /// let bad = SimulationModel { max_substep: 0.0, ..Default::default() };
    /// assert!(matches!(bad.validate(), Err(Error::InvalidParameter { name: "max_substep", .. })));
    /// ```
    pub fn validate(&self) -> Result<(), Error> {
        let bad = |name, value, reason| {
            Err(Error::InvalidParameter {
                name,
                value,
                reason,
            })
        };
        if !(self.max_substep.is_finite() && self.max_substep > 0.0) {
            return bad(
                "max_substep",
                self.max_substep,
                "the sub-step must be finite and > 0, s",
            );
        }
        if !(self.input_delay.is_finite() && self.input_delay >= 0.0) {
            return bad(
                "input_delay",
                self.input_delay,
                "the input delay must be finite and >= 0, s",
            );
        }
        if let Some(&r) = self
            .stiction_ratio
            .iter()
            .find(|r| !(r.is_finite() && **r >= 1.0))
        {
            return bad(
                "stiction_ratio",
                r,
                "breakaway over Coulomb friction must be finite and >= 1",
            );
        }
        Ok(())
    }
}

/// The recording's input and positions, checked against a model.
pub(super) struct Run<'a> {
    pub(super) t: &'a [f64],
    pub(super) u: &'a [f64],
    pub(super) x1: &'a [f64],
    pub(super) x2: &'a [f64],
    model: SimulationModel,
    /// The sampling interval when the grid is uniform (to rounding), s.
    uniform: Option<f64>,
}

impl<'a> Run<'a> {
    pub(super) fn of(rec: &'a Recording, model: &SimulationModel) -> Result<Self, Error> {
        model.validate()?;
        let run = Run {
            t: rec.time(),
            u: rec.channel("u")?,
            x1: rec.channel("x1")?,
            x2: rec.channel("x2")?,
            model: *model,
            uniform: None,
        };
        if run.t.len() < MIN_SAMPLES {
            return Err(Error::InvalidParameter {
                name: "recording",
                value: run.t.len() as f64,
                reason: "validation needs at least 75 samples",
            });
        }
        // A recording's times increase strictly (`Recording` checks).
        let longest = run.t.windows(2).map(|w| w[1] - w[0]).fold(0.0, f64::max);
        // The delay against the recording's typical interval, not its
        // shortest: after a late sample an interval can be a few µs, and
        // its input is then replaced before taking effect, as on the rig;
        // a delay of a typical interval or more would replace every input.
        let mut intervals: Vec<f64> = run.t.windows(2).map(|w| w[1] - w[0]).collect();
        let mid = intervals.len() / 2;
        let median = *intervals.select_nth_unstable_by(mid, f64::total_cmp).1;
        // (To rounding: a grid of 2 ms in ns has intervals of 2 ms ± 1 ulp.)
        if model.input_delay >= median * (1.0 - 1e-9) {
            return Err(Error::InvalidParameter {
                name: "input_delay",
                value: model.input_delay,
                reason: "the input delay must be shorter than the recording's median interval, s",
            });
        }
        if longest / model.max_substep > MAX_SUBSTEPS_PER_SAMPLE {
            return Err(Error::InvalidParameter {
                name: "max_substep",
                value: model.max_substep,
                reason: "more than 1000 sub-steps in one of the recording's intervals",
            });
        }
        // The exact sub-steps of a uniform grid split each interval in two
        // at the delay; a delay of an interval or more is simulated as on
        // any grid.
        let uniform =
            uniform_step(run.t, grid_rounding(run.t)).filter(|&dt| model.input_delay < dt);
        Ok(Run { uniform, ..run })
    }

    /// Simulates `plant` with Coulomb forces `coulomb` (N) from the recorded
    /// input, starting at rest at the first positions with a zero input
    /// held until the first sample's takes effect, and hands each sample's
    /// positions to `sample(k, x1, x2)` (m). `false` if the simulation left
    /// the rig's scale (more than 1 m: a diverging candidate) or the
    /// plant's sub-step cannot be discretised; the samples after that are
    /// not visited.
    ///
    /// On a uniform grid (with a delay shorter than its interval) each
    /// sub-step is the exact ZOH step of the plant's linear part in its
    /// stick structure (the card's RK4 sub-steps agree with it to about
    /// 1e-11 at 0.25 ms); otherwise RK4 sub-steps of each part of each
    /// interval as it is, the parts split wherever an input takes effect
    /// (`t_j + input_delay`, on the actual instants).
    pub(super) fn simulate(
        &self,
        plant: &MassSpring,
        coulomb: [f64; 2],
        mut sample: impl FnMut(usize, f64, f64),
    ) -> bool {
        let m = &self.model;
        let stiction = [0, 1].map(|c| coulomb[c] * m.stiction_ratio[c]);
        let mut model = FrictionPlant::new(*plant, coulomb).with_stiction(stiction);
        let delay = m.input_delay;
        let exact = match self.uniform {
            Some(interval) => {
                match [(delay, 0.0), (interval - delay, delay)].map(|(span, _)| {
                    Steps::new(plant, coulomb, span, substeps(span, m.max_substep))
                }) {
                    [Some(a), Some(b)] => Some([a, b]),
                    _ => return false,
                }
            }
            None => None,
        };
        let mut x: SVector<f64, 4> = vector![self.x1[0], 0.0, self.x2[0], 0.0];
        // The input in effect, and the next sample whose input has not
        // taken effect yet.
        let mut held = 0.0;
        let mut pending = 0;
        for (k, &t) in self.t.iter().enumerate() {
            sample(k, x[0], x[2]);
            if !(x[0].abs() <= 1.0 && x[2].abs() <= 1.0) {
                return false;
            }
            let Some(&next) = self.t.get(k + 1) else {
                break;
            };
            let interval = self.uniform.unwrap_or(next - t);
            // The parts of the interval: from `offset` (s after `t`) to the
            // next input's taking effect, or to the interval's end. The
            // offset of `u_j` is `t_j − t + delay`: exactly `delay` for
            // `u_k`, as on a uniform grid.
            let mut offset = 0.0;
            loop {
                // Inputs that take effect at or before this part's start,
                // and those replaced before taking effect (the drive keeps
                // only its newest pending command, as the card's does).
                while pending <= k {
                    if self.t[pending + 1] < self.t[pending] + delay {
                        pending += 1;
                    } else if self.t[pending] - t + delay <= offset {
                        held = self.u[pending];
                        pending += 1;
                    } else {
                        break;
                    }
                }
                let end = if pending <= k {
                    (self.t[pending] - t + delay).min(interval)
                } else {
                    interval
                };
                let span = end - offset;
                if span > 0.0 {
                    let u = vector![held];
                    let steps = substeps(span, m.max_substep);
                    let h = span / steps as f64;
                    let start = t + offset;
                    // On a uniform grid: the part before `u_k` takes effect,
                    // or the part after.
                    let part = usize::from(pending > k);
                    // As the card: the mode first (a stuck cart may break
                    // away under the new input), then after each sub-step.
                    model.update_mode(start, &mut x, &u);
                    for s in 0..steps {
                        match &exact {
                            Some(exact) => exact[part].step(&model, &mut x, u[0]),
                            None => Rk4.step_mut(&model, start + s as f64 * h, h, &mut x, &u),
                        }
                        model.update_mode(start + (s + 1) as f64 * h, &mut x, &u);
                    }
                }
                if end >= interval {
                    break;
                }
                offset = end;
            }
        }
        true
    }
}

/// Equal sub-steps no longer than `max_substep` covering `span` (at least
/// one); the tolerance keeps `T / (T / 8)` at 8 despite rounding.
fn substeps(span: f64, max_substep: f64) -> usize {
    ((span / max_substep) * (1.0 - 1e-12)).ceil().max(1.0) as usize
}

/// One sub-step's exact ZOH matrices for each stick structure (index: bit
/// 0 cart 1 stuck, bit 1 cart 2 stuck), on the affine input
/// `[u, direction₁, direction₂]`: the motor and each cart's Coulomb force
/// `−F sign(v)`.
struct Steps {
    phi: [SMatrix<f64, 4, 4>; 4],
    gamma: [SMatrix<f64, 4, 3>; 4],
}

impl Steps {
    /// `None` when a structure cannot be discretised (an overflowing
    /// candidate) or `span` is empty.
    fn new(plant: &MassSpring, coulomb: [f64; 2], span: f64, steps: usize) -> Option<Self> {
        let h = span / steps as f64;
        if span <= 0.0 {
            // Never stepped: the part is skipped.
            return Some(Self {
                phi: [SMatrix::identity(); 4],
                gamma: [SMatrix::zeros(); 4],
            });
        }
        let a = plant.a_matrix();
        let mut b = SMatrix::<f64, 4, 3>::zeros();
        b[(3, 0)] = plant.gain / plant.m2;
        b[(1, 1)] = -coulomb[0] / plant.m1;
        b[(3, 2)] = -coulomb[1] / plant.m2;
        let mut phi = [SMatrix::zeros(); 4];
        let mut gamma = [SMatrix::zeros(); 4];
        for s in 0..4 {
            let (mut a, mut b) = (a, b);
            for cart in 0..2 {
                if s & (1 << cart) != 0 {
                    a.fixed_rows_mut::<2>(2 * cart).fill(0.0);
                    b.fixed_rows_mut::<2>(2 * cart).fill(0.0);
                }
            }
            let (p, g) = zoh::<U4, U3>(&a, &b, h).ok()?;
            phi[s] = p;
            gamma[s] = g;
        }
        Some(Self { phi, gamma })
    }

    /// One sub-step of `model` in its current stick structure, input `u`.
    #[inline]
    fn step(&self, model: &FrictionPlant, x: &mut SVector<f64, 4>, u: f64) {
        let friction = model.friction();
        let d = model.directions();
        let stuck = |c: usize| usize::from(friction[c] > 0.0 && d[c] == 0.0) << c;
        let s = stuck(0) | stuck(1);
        *x = self.phi[s] * *x + self.gamma[s] * vector![u, d[0], d[1]];
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lab::schema;

    /// A 2 s recording at 2 ms: a ±9 V square wave (0.1 s half period) for
    /// 1 s, then 0 V (the carts ring down and stick); the positions are all
    /// zero (only the input matters here).
    fn recording() -> Recording {
        let t: Vec<f64> = (0..1000).map(|k| k as f64 * 0.002).collect();
        let u = t
            .iter()
            .map(|&t| match (t / 0.1) as u64 {
                half @ 0..10 if half.is_multiple_of(2) => 9.0,
                0..10 => -9.0,
                _ => 0.0,
            })
            .collect();
        let zeros = vec![0.0; t.len()];
        Recording::from_columns(
            schema(),
            t,
            vec![u, zeros.clone(), zeros.clone(), zeros.clone(), zeros],
        )
        .unwrap()
    }

    /// The exact ZOH sub-steps of a uniform grid and the RK4 sub-steps of
    /// any grid are the same simulation: stick–slip decisions alike, and
    /// positions within 1e-9 m over 2 s of sticking and sliding.
    #[test]
    fn exact_substeps_are_the_rk4_substeps() {
        let rec = recording();
        let model = SimulationModel {
            input_delay: 0.15e-3,
            stiction_ratio: [1.2, 1.3],
            ..SimulationModel::default()
        };
        let exact = Run::of(&rec, &model).unwrap();
        assert_eq!(exact.uniform, Some(0.002));
        let rk4 = Run {
            uniform: None,
            ..Run::of(&rec, &model).unwrap()
        };
        let plant = MassSpring {
            k2: 1020.0,
            b1: 12.0,
            b2: 5.5,
            gain: 1.11,
            ..MassSpring::nominal()
        };
        let collect = |run: &Run| {
            let mut out = vec![[0.0; 2]; rec.len()];
            assert!(run.simulate(&plant, [1.0, 2.0], |k, x1, x2| out[k] = [x1, x2]));
            out
        };
        let (a, b) = (collect(&exact), collect(&rk4));
        let moved = a.iter().filter(|x| x[1].abs() > 1e-3).count();
        let still = a.windows(2).filter(|w| w[0][0] == w[1][0]).count();
        assert!(moved > 300 && still > 200, "{moved} moving, {still} stuck");
        let worst = a
            .iter()
            .zip(&b)
            .map(|(a, b)| (a[0] - b[0]).abs().max((a[1] - b[1]).abs()))
            .fold(0.0, f64::max);
        assert!(worst < 1e-9, "{worst:e} m");
    }
}
