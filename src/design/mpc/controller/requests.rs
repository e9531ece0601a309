//! What a user asks of a designed controller besides its ticks: a new
//! output limit mid-run, and the move at a known state.

use nalgebra::SVector;

use super::Mpc;
use crate::error::Error;

impl<const N: usize, const M: usize, const Q: usize, const R: usize> Mpc<N, M, Q, R> {
    /// Changes output limit `index` (in the order of the design's
    /// [`output_limits`](MpcDesign::output_limits)) from the next tick on,
    /// keeping its kind: an operator's request ("keep cart 2 below 20 mm").
    /// A hard limit the state already violates makes the next QPs
    /// infeasible: the controller then falls back and counts it.
    ///
    /// # Errors
    ///
    /// [`Error::OutOfRange`] for an index past the limits,
    /// [`Error::InvalidParameter`] for `min > max` or a NaN.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::StateSpace;
    /// use ctrlab::design::mpc::{Estimation, Mpc, MpcDesign, OutputLimit, Row};
    /// use ctrlab::nalgebra::matrix;
    /// let model = StateSpace::discrete(matrix![1.0, 0.1; 0.0, 1.0], matrix![0.005; 0.1],
    ///                                  matrix![1.0, 0.0], matrix![0.0], 0.1)?;
    /// let mut design = MpcDesign::new(10, matrix![1.0, 0.0; 0.0, 0.0], matrix![0.1]);
    /// design.output_limits.push(OutputLimit { output: matrix![1.0, 0.0], min: -2.0, max: 2.0, kind: Row::Hard });
    /// let estimation = Estimation { input_noise: matrix![1e-2], disturbance_noise: matrix![1e-4],
    ///                               output_disturbance_noise: 0.0,
    ///                               measurement_noise: matrix![1e-6] };
    /// let mut mpc = Mpc::new(&model, &matrix![1.0], &design, &estimation)?;
    /// mpc.set_output_limit(0, -1.0, 1.0)?;
    /// assert!(mpc.set_output_limit(1, 0.0, 1.0).is_err());
    /// assert!(mpc.set_output_limit(0, 1.0, 0.0).is_err());
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn set_output_limit(&mut self, index: usize, min: f64, max: f64) -> Result<(), Error> {
        let len = self.outputs.lower.len();
        if index >= len {
            return Err(Error::OutOfRange {
                what: "output limit",
                index,
                len,
            });
        }
        if min.is_nan() || max.is_nan() || min > max {
            return Err(Error::InvalidParameter {
                name: "min",
                value: min,
                reason: "an output limit must satisfy min ≤ max (not NaN)",
            });
        }
        self.outputs.lower[index] = min;
        self.outputs.upper[index] = max;
        Ok(())
    }

    /// The input the controller applies at the known state `x` for the
    /// reference `r`, the input last applied being `u_prev`: the state
    /// feedback MPC is as a law (MATLAB's `mpcmove` given the state,
    /// python-control's MPC as a state-feedback system). The estimator is
    /// set to `x` with no disturbance; the plan, warm start and counts
    /// move as on a tick, the integral action does not.
    ///
    /// # Errors
    ///
    /// [`Error::InvalidData`] for a non-finite `x`, `r` or `u_prev`.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::StateSpace;
    /// use ctrlab::design::{dlqr, mpc::{Estimation, Mpc, MpcDesign}};
    /// use ctrlab::nalgebra::{matrix, vector};
    /// let model = StateSpace::discrete(matrix![1.0, 0.1; 0.0, 1.0], matrix![0.005; 0.1],
    ///                                  matrix![1.0, 0.0], matrix![0.0], 0.1)?;
    /// let (q, r) = (matrix![1.0, 0.0; 0.0, 0.1], matrix![0.1]);
    /// let estimation = Estimation { input_noise: matrix![1.0], disturbance_noise: matrix![0.0],
    ///                               output_disturbance_noise: 0.0, measurement_noise: matrix![1e-6] };
    /// let mut mpc = Mpc::new(&model, &matrix![1.0], &MpcDesign::new(10, q, r), &estimation)?;
    /// // No limit binds: the LQR law of the same weights.
    /// let u = mpc.move_at(&vector![0.2, -0.1], &vector![0.0], &vector![0.0])?;
    /// let lqr = dlqr(&model, &q, &r)?;
    /// assert!((u[0] + (lqr.gain * vector![0.2, -0.1])[0]).abs() < 1e-9);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn move_at(
        &mut self,
        x: &SVector<f64, N>,
        r: &SVector<f64, R>,
        u_prev: &SVector<f64, M>,
    ) -> Result<SVector<f64, M>, Error> {
        for (what, v) in [
            ("x", x.as_slice()),
            ("r", r.as_slice()),
            ("u_prev", u_prev.as_slice()),
        ] {
            if let Some(index) = v.iter().position(|v| !v.is_finite()) {
                return Err(Error::InvalidData {
                    what,
                    index,
                    reason: "must be finite",
                });
            }
        }
        self.estimate.fill(0.0);
        self.estimate.rows_mut(0, N).copy_from_slice(x.as_slice());
        self.u_prev = *u_prev;
        self.stats.ticks += 1;
        Ok(self.tick(r))
    }
}
