//! Time responses of run-time-sized models ([`DynStateSpace`]): the same
//! simulation code as the fixed-size functions (one ZOH loop, one discrete
//! loop, one time grid), returning a [`DynResponse`].

use nalgebra::{DVector, Dyn};

use super::responses::grid;
use super::{MAX_SAMPLES, check_grid, discrete_feedback, lsim_zoh};
use crate::error::Error;
use crate::model::{Continuous, Discrete, Domain, DynStateSpace, period_of};
#[cfg(doc)]
use crate::sim::{Response, time_grid};

/// A simulated time response of a [`DynStateSpace`]: sample times (s),
/// states and outputs in the model's units, one entry per sample, each
/// state and output a [`DVector`] of the model's size. The run-time-sized
/// counterpart of [`Response`].
///
/// # Examples
///
/// ```
/// use ctrlab::{DynStateSpace, StepInfoOptions, step_info};
/// use nalgebra::dmatrix;
///
/// // A lag, τ = 0.1 s: its step response and the figures of it.
/// let sys = DynStateSpace::continuous(dmatrix![-10.0], dmatrix![10.0], dmatrix![1.0], dmatrix![0.0])?;
/// let r = sys.step_response(2.0, 0.001)?;
/// assert_eq!((r.len(), r.x[0].len(), r.y[0].len()), (2001, 1, 1));
/// let info = step_info(&r.t, &r.output(0)?, &StepInfoOptions::default())?;
/// assert!((info.rise_time - 0.1 * 9f64.ln()).abs() < 1e-6);
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct DynResponse {
    /// Sample times, s.
    pub t: Vec<f64>,
    /// State at each sample (`n` entries each).
    pub x: Vec<DVector<f64>>,
    /// Output at each sample (`p` entries each).
    pub y: Vec<DVector<f64>>,
}

impl DynResponse {
    /// Number of samples.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::{DynStateSpace, MassSpring, Cart};
    /// let sys = DynStateSpace::from(MassSpring::nominal().state_space(Cart::Two)?);
    /// assert_eq!(sys.step_response(1.0, 0.01)?.len(), 101);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn len(&self) -> usize {
        self.t.len()
    }

    /// True when there are no samples.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::{DynStateSpace, MassSpring, Cart};
    /// let sys = DynStateSpace::from(MassSpring::nominal().state_space(Cart::Two)?);
    /// assert!(!sys.step_response(1.0, 0.01)?.is_empty());
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }

    /// Output channel `i` as a plain vector, e.g. to hand to
    /// [`step_info`](crate::step_info).
    ///
    /// # Errors
    ///
    /// [`Error::OutOfRange`] unless `i` is below the number of outputs (of
    /// the first sample; an empty response has none).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::{DynStateSpace, Error, MassSpring, Cart};
    /// let sys = DynStateSpace::from(MassSpring::nominal().state_space(Cart::Two)?);
    /// let r = sys.step_response(1.0, 0.01)?;
    /// assert_eq!(r.output(0)?.len(), r.len());
    /// assert!(matches!(r.output(1), Err(Error::OutOfRange { index: 1, len: 1, .. })));
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn output(&self, i: usize) -> Result<Vec<f64>, Error> {
        let outputs = self.y.first().map_or(0, |y| y.len());
        if i >= outputs {
            return Err(Error::OutOfRange {
                what: "output",
                index: i,
                len: outputs,
            });
        }
        Ok(self.y.iter().map(|y| y[i]).collect())
    }
}

impl<D: Domain> DynStateSpace<D> {
    /// The model with input `j` alone (`B`'s and `D`'s column `j`), e.g. to
    /// take the step response of one input of a multi-input model.
    ///
    /// # Errors
    ///
    /// [`Error::OutOfRange`] unless `j < m`.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::DynStateSpace;
    /// use nalgebra::dmatrix;
    ///
    /// let sys = DynStateSpace::continuous(dmatrix![-1.0], dmatrix![1.0, 2.0], dmatrix![1.0], dmatrix![0.0, 0.5])?;
    /// let second = sys.select_input(1)?;
    /// assert_eq!((second.b(), second.d()), (&dmatrix![2.0], &dmatrix![0.5]));
    /// assert!(sys.select_input(2).is_err());
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn select_input(&self, j: usize) -> Result<Self, Error> {
        if j >= self.inputs() {
            return Err(Error::OutOfRange {
                what: "input",
                index: j,
                len: self.inputs(),
            });
        }
        Ok(Self::from_parts_unchecked(
            self.a().clone(),
            self.b().columns(j, 1).into_owned(),
            self.c().clone(),
            self.d().columns(j, 1).into_owned(),
            self.domain(),
        ))
    }

    /// The unit step response of a single-input model from rest, on
    /// [`time_grid`]`(t_end, dt)` (s): [`step_response`](crate::sim::step_response)'s
    /// definition and code. For a discrete model `dt` must be its period.
    ///
    /// # Errors
    ///
    /// [`Error::DimensionMismatch`] named `"B"` unless the model has one
    /// input (pick one with [`select_input`](Self::select_input)); as
    /// [`step_response`](crate::sim::step_response) otherwise.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{DynStateSpace, Discretization};
    /// use nalgebra::dmatrix;
    ///
    /// // First-order lag, τ = 0.5 s: y(τ) = 1 − e^−1.
    /// let sys = DynStateSpace::continuous(dmatrix![-2.0], dmatrix![2.0], dmatrix![1.0], dmatrix![0.0])?;
    /// let r = sys.step_response(1.0, 0.5)?;
    /// assert!((r.y[1][0] - (1.0 - (-1.0f64).exp())).abs() < 1e-14);
    /// // Its exact discretisation has the same response at the samples.
    /// let d = sys.discretize(0.5, Discretization::Zoh)?;
    /// assert!((d.step_response(1.0, 0.5)?.y[1][0] - r.y[1][0]).abs() < 1e-14);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[doc(alias = "step")]
    pub fn step_response(&self, t_end: f64, dt: f64) -> Result<DynResponse, Error> {
        self.single_input()?;
        self.respond(t_end, dt, DVector::zeros(self.states()), |_| 1.0)
    }

    /// The impulse response of a single-input model from rest, as
    /// [`impulse_response`](crate::sim::impulse_response) defines it
    /// (python-control's: the free response from `x(0) = B` in continuous
    /// time, the response to the unit-area pulse `u[0] = 1/dt` in discrete
    /// time).
    ///
    /// # Errors
    ///
    /// As [`step_response`](Self::step_response); [`Error::Overflow`] for a
    /// period so short that `1/dt` overflows.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::DynStateSpace;
    /// use nalgebra::dmatrix;
    ///
    /// // A lag 1/(τ s + 1), τ = 0.5 s: g(t) = e^{−t/τ} / τ.
    /// let sys = DynStateSpace::continuous(dmatrix![-2.0], dmatrix![2.0], dmatrix![1.0], dmatrix![0.0])?;
    /// let r = sys.impulse_response(1.0, 0.5)?;
    /// assert!((r.y[1][0] - 2.0 * (-1.0f64).exp()).abs() < 1e-14);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[doc(alias = "impulse")]
    pub fn impulse_response(&self, t_end: f64, dt: f64) -> Result<DynResponse, Error> {
        self.single_input()?;
        match period_of(&self.domain()) {
            None => self.respond(t_end, dt, self.b().column(0).into_owned(), |_| 0.0),
            Some(period) => {
                let pulse = 1.0 / period;
                if !pulse.is_finite() {
                    return Err(Error::Overflow {
                        operation: "impulse response (the unit-area pulse 1/dt)",
                    });
                }
                let zero = DVector::zeros(self.states());
                self.respond(t_end, dt, zero, |k| if k == 0 { pulse } else { 0.0 })
            }
        }
    }

    /// The free response from the state `x0` with every input held at
    /// zero, as [`initial_response`](crate::sim::initial_response).
    ///
    /// # Errors
    ///
    /// As [`step_response`](Self::step_response) (any number of inputs);
    /// [`Error::LengthMismatch`] unless `x0` has `n` entries;
    /// [`Error::NonFinite`] named `"x0"` for a non-finite entry.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::DynStateSpace;
    /// use nalgebra::{dmatrix, dvector};
    ///
    /// // An undamped oscillator, ω = 2 rad/s, released from x = 1: cos 2t.
    /// let sys = DynStateSpace::continuous(dmatrix![0.0, 1.0; -4.0, 0.0], dmatrix![0.0; 1.0],
    ///                                     dmatrix![1.0, 0.0], dmatrix![0.0])?;
    /// let r = sys.initial_response(1.0, 0.25, &dvector![1.0, 0.0])?;
    /// assert!((r.y[4][0] - 2f64.cos()).abs() < 1e-12);
    /// assert!(sys.initial_response(1.0, 0.25, &dvector![1.0]).is_err());
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[doc(alias = "initial")]
    pub fn initial_response(
        &self,
        t_end: f64,
        dt: f64,
        x0: &DVector<f64>,
    ) -> Result<DynResponse, Error> {
        self.check_state(x0)?;
        self.respond(t_end, dt, x0.clone(), |_| 0.0)
    }

    /// The response from `x0` (checked) to the input whose every entry is
    /// `input(k)` at sample `k` (held between samples in continuous time).
    fn respond(
        &self,
        t_end: f64,
        dt: f64,
        x0: DVector<f64>,
        input: impl Fn(usize) -> f64,
    ) -> Result<DynResponse, Error> {
        check_finite_state(&x0)?;
        let t = grid(&self.domain(), t_end, dt)?;
        let m = self.inputs();
        let (a, b, c, d) = (self.a(), self.b(), self.c(), self.d());
        match period_of(&self.domain()) {
            None => {
                // The input is asked for once per grid time, in order.
                let mut k = 0;
                let (x, y) = lsim_zoh(a, b, c, d, &t, x0, |_t| {
                    k += 1;
                    DVector::from_element(m, input(k - 1))
                })?;
                Ok(DynResponse { t, x, y })
            }
            Some(period) => {
                let (t, x, y) = discrete_feedback((a, b, c, d), period, x0, t.len(), |k, _x| {
                    DVector::from_element(m, input(k))
                })?;
                Ok(DynResponse { t, x, y })
            }
        }
    }

    fn single_input(&self) -> Result<(), Error> {
        if self.inputs() == 1 {
            Ok(())
        } else {
            Err(Error::DimensionMismatch {
                matrix: "B",
                expected_rows: self.states(),
                expected_cols: 1,
                found_rows: self.states(),
                found_cols: self.inputs(),
            })
        }
    }

    fn check_state(&self, x0: &DVector<f64>) -> Result<(), Error> {
        if x0.len() != self.states() {
            return Err(Error::LengthMismatch {
                what: "x0",
                expected: self.states(),
                found: x0.len(),
            });
        }
        check_finite_state(x0)
    }
}

/// [`Error::NonFinite`] named `"x0"` for the first non-finite entry.
fn check_finite_state(x0: &DVector<f64>) -> Result<(), Error> {
    match x0.iter().position(|v| !v.is_finite()) {
        None => Ok(()),
        Some(row) => Err(Error::NonFinite {
            matrix: "x0",
            row,
            col: 0,
            value: x0[row],
        }),
    }
}

impl DynStateSpace<Continuous> {
    /// Simulates the model over the time grid `t` (s, strictly increasing)
    /// from state `x0`, the input `input(t)` sampled at each grid time and
    /// held until the next, exactly (ZOH): [`simulate`](crate::sim::simulate)
    /// with [`Solver::Zoh`](crate::sim::Solver::Zoh), the same code.
    ///
    /// # Errors
    ///
    /// As [`simulate`](crate::sim::simulate); [`Error::LengthMismatch`]
    /// named `"x0"` or `"input"` for a vector of the wrong length.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{DynStateSpace, MassSpring, Cart, sim::time_grid};
    /// use nalgebra::{DVector, dvector};
    ///
    /// let sys = DynStateSpace::from(MassSpring::nominal().state_space(Cart::Two)?);
    /// let t = time_grid(10.0, 0.002)?;
    /// let r = sys.simulate(&t, &DVector::zeros(4), |_t| dvector![10.0])?;
    /// // 10 N on cart 2 settles at 20 mm.
    /// assert!((r.y.last().unwrap()[0] - 0.020).abs() < 1e-9);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[doc(alias = "lsim")]
    pub fn simulate(
        &self,
        t: &[f64],
        x0: &DVector<f64>,
        input: impl FnMut(f64) -> DVector<f64>,
    ) -> Result<DynResponse, Error> {
        check_grid(t)?;
        self.check_state(x0)?;
        let (x, y) = lsim_zoh(self.a(), self.b(), self.c(), self.d(), t, x0.clone(), input)?;
        Ok(DynResponse {
            t: t.to_vec(),
            x,
            y,
        })
    }
}

impl DynStateSpace<Discrete> {
    /// Simulates the model for `steps` samples with the input computed from
    /// the sample index and current state, `u[k] = control(k, &x[k])`:
    /// [`simulate_discrete_feedback`](crate::sim::simulate_discrete_feedback),
    /// the same code. Open loop: ignore the state.
    ///
    /// # Errors
    ///
    /// As [`simulate_discrete_feedback`](crate::sim::simulate_discrete_feedback);
    /// [`Error::LengthMismatch`] named `"x0"` or `"input"` for a vector of
    /// the wrong length.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::DynStateSpace;
    /// use nalgebra::{dmatrix, dvector};
    ///
    /// // x[k+1] = x + u with u = −x/2 halves the state every sample.
    /// let sys = DynStateSpace::discrete(dmatrix![1.0], dmatrix![1.0], dmatrix![1.0], dmatrix![0.0], 0.1)?;
    /// let r = sys.simulate_feedback(&dvector![8.0], 4, |_k, x| -0.5 * x)?;
    /// assert_eq!(r.output(0)?, vec![8.0, 4.0, 2.0, 1.0]);
    /// assert!((r.t[3] - 0.3).abs() < 1e-15);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn simulate_feedback(
        &self,
        x0: &DVector<f64>,
        steps: usize,
        control: impl FnMut(usize, &DVector<f64>) -> DVector<f64>,
    ) -> Result<DynResponse, Error> {
        if steps > MAX_SAMPLES {
            return Err(Error::InvalidParameter {
                name: "steps",
                value: steps as f64,
                reason: "more samples than MAX_SAMPLES",
            });
        }
        self.check_state(x0)?;
        let (t, x, y) = discrete_feedback::<Dyn, Dyn, Dyn>(
            (self.a(), self.b(), self.c(), self.d()),
            self.dt(),
            x0.clone(),
            steps,
            control,
        )?;
        Ok(DynResponse { t, x, y })
    }
}
