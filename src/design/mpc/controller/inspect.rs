//! What an [`Mpc`] shows of itself between ticks: its counts, the last
//! tick's status and solver report, the estimates and the plan.

use nalgebra::SVector;

use super::Mpc;
use crate::design::mpc::qp::QpReport;
use crate::design::mpc::{MpcStats, TickStatus};

impl<const N: usize, const M: usize, const Q: usize, const R: usize> Mpc<N, M, Q, R> {
    /// The counts and extremes of the ticks since the last
    /// [`reset`](crate::design::Controller::reset).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::{Controller, StateSpace};
    /// # use ctrlab::design::mpc::{Estimation, Mpc, MpcDesign};
    /// # use ctrlab::nalgebra::{matrix, vector};
    /// # let model = StateSpace::discrete(matrix![1.0, 0.1; 0.0, 1.0], matrix![0.005; 0.1],
    /// #                                  matrix![1.0, 0.0], matrix![0.0], 0.1)?;
    /// # let design = MpcDesign::new(20, matrix![10.0, 0.0; 0.0, 1.0], matrix![0.1]);
    /// # let estimation = Estimation { input_noise: matrix![1e-2], disturbance_noise: matrix![1e-4],
    /// #                               output_disturbance_noise: 0.0, measurement_noise: matrix![1e-6] };
    /// # let mut mpc = Mpc::new(&model, &matrix![1.0], &design, &estimation)?;
    /// for _ in 0..3 {
    ///     let u = mpc.update(&vector![0.0], &vector![1.0]);
    ///     mpc.applied(&u);
    /// }
    /// let stats = mpc.stats();
    /// assert_eq!((stats.ticks, stats.solved, stats.fallbacks()), (3, 3, 0));
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn stats(&self) -> &MpcStats {
        &self.stats
    }

    /// How the last tick's input was found.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::{Controller, StateSpace};
    /// # use ctrlab::design::mpc::{Estimation, Mpc, MpcDesign};
    /// # use ctrlab::nalgebra::{matrix, vector};
    /// # let model = StateSpace::discrete(matrix![1.0, 0.1; 0.0, 1.0], matrix![0.005; 0.1],
    /// #                                  matrix![1.0, 0.0], matrix![0.0], 0.1)?;
    /// # let design = MpcDesign::new(20, matrix![10.0, 0.0; 0.0, 1.0], matrix![0.1]);
    /// # let estimation = Estimation { input_noise: matrix![1e-2], disturbance_noise: matrix![1e-4],
    /// #                               output_disturbance_noise: 0.0, measurement_noise: matrix![1e-6] };
    /// # let mut mpc = Mpc::new(&model, &matrix![1.0], &design, &estimation)?;
    /// use ctrlab::design::mpc::TickStatus;
    /// assert_eq!(mpc.last_status(), TickStatus::NotStarted);
    /// mpc.update(&vector![0.0], &vector![1.0]);
    /// assert!(mpc.last_status().is_solved());
    /// mpc.update(&vector![f64::NAN], &vector![1.0]); // a bad measurement: input held
    /// assert_eq!(mpc.last_status(), TickStatus::InvalidInput);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn last_status(&self) -> TickStatus {
        self.last
    }

    /// The solver's report of the last tick (`None` before the first, or
    /// when the tick's data were refused).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::{Controller, StateSpace};
    /// # use ctrlab::design::mpc::{Estimation, Mpc, MpcDesign};
    /// # use ctrlab::nalgebra::{matrix, vector};
    /// # let model = StateSpace::discrete(matrix![1.0, 0.1; 0.0, 1.0], matrix![0.005; 0.1],
    /// #                                  matrix![1.0, 0.0], matrix![0.0], 0.1)?;
    /// # let design = MpcDesign::new(20, matrix![10.0, 0.0; 0.0, 1.0], matrix![0.1]);
    /// # let estimation = Estimation { input_noise: matrix![1e-2], disturbance_noise: matrix![1e-4],
    /// #                               output_disturbance_noise: 0.0, measurement_noise: matrix![1e-6] };
    /// # let mut mpc = Mpc::new(&model, &matrix![1.0], &design, &estimation)?;
    /// assert!(mpc.last_report().is_none());
    /// mpc.update(&vector![0.0], &vector![1.0]);
    /// let report = mpc.last_report().expect("a tick was solved");
    /// assert!(report.status.is_solved() && report.primal_residual < 1e-6);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn last_report(&self) -> Option<QpReport> {
        self.report
    }

    /// The current estimate of the state (after the last measurement).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::{Controller, StateSpace};
    /// # use ctrlab::design::mpc::{Estimation, Mpc, MpcDesign};
    /// # use ctrlab::nalgebra::{matrix, vector};
    /// # let model = StateSpace::discrete(matrix![1.0, 0.1; 0.0, 1.0], matrix![0.005; 0.1],
    /// #                                  matrix![1.0, 0.0], matrix![0.0], 0.1)?;
    /// # let design = MpcDesign::new(20, matrix![10.0, 0.0; 0.0, 1.0], matrix![0.1]);
    /// # let estimation = Estimation { input_noise: matrix![1e-2], disturbance_noise: matrix![1e-4],
    /// #                               output_disturbance_noise: 0.0, measurement_noise: matrix![1e-6] };
    /// # let mut mpc = Mpc::new(&model, &matrix![1.0], &design, &estimation)?;
    /// // Held at 0.3 m, at rest: the estimate settles there.
    /// for _ in 0..100 {
    ///     let u = mpc.update(&vector![0.3], &vector![0.3]);
    ///     mpc.applied(&u);
    /// }
    /// let x = mpc.state_estimate();
    /// assert!((x[0] - 0.3).abs() < 1e-3 && x[1].abs() < 1e-2); // m, m/s
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn state_estimate(&self) -> SVector<f64, N> {
        SVector::from_fn(|i, _| self.estimate[i])
    }

    /// The current estimate of the input disturbance `d_u`, in the
    /// input's units (V on the rig: the drive friction and model error
    /// take).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::{Controller, StateSpace};
    /// # use ctrlab::design::mpc::{Estimation, Mpc, MpcDesign};
    /// # use ctrlab::nalgebra::{matrix, vector};
    /// # let model = StateSpace::discrete(matrix![1.0, 0.1; 0.0, 1.0], matrix![0.005; 0.1],
    /// #                                  matrix![1.0, 0.0], matrix![0.0], 0.1)?;
    /// # let design = MpcDesign::new(20, matrix![10.0, 0.0; 0.0, 1.0], matrix![0.1]);
    /// # let estimation = Estimation { input_noise: matrix![1e-2], disturbance_noise: matrix![1e-4],
    /// #                               output_disturbance_noise: 0.0, measurement_noise: matrix![1e-6] };
    /// # let mut mpc = Mpc::new(&model, &matrix![1.0], &design, &estimation)?;
    /// // The plant gets 0.2 N more than it is sent: estimated and countered.
    /// let mut x = vector![0.0, 0.0];
    /// for _ in 0..400 {
    ///     let u = mpc.update(&(model.c() * x), &vector![1.0]);
    ///     mpc.applied(&u);
    ///     x = model.advance(&x, &(u + vector![0.2]));
    /// }
    /// assert!((mpc.disturbance_estimate()[0] - 0.2).abs() < 1e-3);
    /// assert!((x[0] - 1.0).abs() < 1e-3); // no offset
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn disturbance_estimate(&self) -> SVector<f64, M> {
        if self.input_disturbances {
            SVector::from_fn(|i, _| self.estimate[N + i])
        } else {
            SVector::zeros()
        }
    }

    /// The inputs planned by the last solved tick over the horizon
    /// (`u₀, u₁, …`, `M` per step), absolute.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::{Controller, StateSpace};
    /// # use ctrlab::design::mpc::{Estimation, Mpc, MpcDesign};
    /// # use ctrlab::nalgebra::{matrix, vector};
    /// # let model = StateSpace::discrete(matrix![1.0, 0.1; 0.0, 1.0], matrix![0.005; 0.1],
    /// #                                  matrix![1.0, 0.0], matrix![0.0], 0.1)?;
    /// # let design = MpcDesign::new(20, matrix![10.0, 0.0; 0.0, 1.0], matrix![0.1]);
    /// # let estimation = Estimation { input_noise: matrix![1e-2], disturbance_noise: matrix![1e-4],
    /// #                               output_disturbance_noise: 0.0, measurement_noise: matrix![1e-6] };
    /// # let mut mpc = Mpc::new(&model, &matrix![1.0], &design, &estimation)?;
    /// let u = mpc.update(&vector![0.0], &vector![1.0]);
    /// assert_eq!(mpc.plan().len(), 20); // M = 1 input × 20 steps
    /// assert_eq!(mpc.plan()[0], u[0]); // the first step is applied
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn plan(&self) -> &[f64] {
        self.plan.as_slice()
    }

    /// The horizon, in periods.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::{Controller, StateSpace};
    /// # use ctrlab::design::mpc::{Estimation, Mpc, MpcDesign};
    /// # use ctrlab::nalgebra::{matrix, vector};
    /// # let model = StateSpace::discrete(matrix![1.0, 0.1; 0.0, 1.0], matrix![0.005; 0.1],
    /// #                                  matrix![1.0, 0.0], matrix![0.0], 0.1)?;
    /// # let design = MpcDesign::new(20, matrix![10.0, 0.0; 0.0, 1.0], matrix![0.1]);
    /// # let estimation = Estimation { input_noise: matrix![1e-2], disturbance_noise: matrix![1e-4],
    /// #                               output_disturbance_noise: 0.0, measurement_noise: matrix![1e-6] };
    /// # let mut mpc = Mpc::new(&model, &matrix![1.0], &design, &estimation)?;
    /// assert_eq!(mpc.horizon(), design.horizon);
    /// assert_eq!(mpc.horizon() as f64 * model.dt(), 2.0); // s predicted
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn horizon(&self) -> usize {
        self.problem.horizon
    }
}
