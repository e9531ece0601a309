//! Time responses: continuous simulation on a time grid ([`simulate`]),
//! discrete simulation open or closed loop ([`simulate_discrete`],
//! [`simulate_discrete_feedback`]), a model's [`step_response`],
//! [`impulse_response`] and [`initial_response`] in either time domain, and the
//! sampled-data simulator [`run_sampled`]: any continuous plant under a
//! discrete [`Controller`](crate::Controller) with zero-order hold, input
//! delay, saturation and measurement quantisation and noise, producing the
//! same [`Recording`](crate::Recording) as the rig's loop.
//!
//! Every simulation of a linear model takes either model type through the
//! sealed trait [`Simulate`] (see [`LinearSystem`] for the calling style)
//! and returns one [`Response`] type, written over nalgebra's dimensions:
//! `Response<Const<N>, Const<P>>` with `SVector`s for a `StateSpace`,
//! [`DynResponse`] (`Response<Dyn, Dyn>`) with `DVector`s for a
//! `DynStateSpace`. Both run the same loops, generic over the matrices'
//! dimensions.
//!
//! For a fixed-size model the inner loops (the recursion
//! `x ← A x + B u` of [`StateSpace::advance_mut`], and the RK4 step of
//! [`Integrator::step_mut`](crate::integrate::Integrator::step_mut)) allocate
//! nothing; the functions here allocate only their output, once, up front.
//!
//! # Examples
//!
//! ```
//! use ctrlab::{DynStateSpace, StateSpace, sim::step_response};
//! use ctrlab::nalgebra::matrix;
//!
//! // A first-order lag, τ = 0.5 s, as either model type: one call, one result type.
//! let fixed = StateSpace::continuous(matrix![-2.0], matrix![2.0], matrix![1.0], matrix![0.0])?;
//! let dynamic = DynStateSpace::from(&fixed);
//! let (f, d) = (step_response(&fixed, 1.0, 0.5)?, step_response(&dynamic, 1.0, 0.5)?);
//! assert_eq!(f.t, d.t);
//! assert_eq!(f.output(0)?, d.output(0)?);
//! # Ok::<(), ctrlab::Error>(())
//! ```

use nalgebra::{Const, DefaultAllocator, Dim, Dyn, OMatrix, OVector, allocator::Allocator};

mod continuous;
mod discrete;
mod responses;
mod sampled;

use continuous::lsim;
pub(crate) use continuous::lsim_zoh;
pub use continuous::simulate;
use discrete::{discrete_feedback, dsim};
pub use discrete::{simulate_discrete, simulate_discrete_feedback};
pub use responses::{impulse_response, initial_response, step_response};
pub use sampled::{SampledConfig, Sensor, run_sampled};

use crate::error::{Error, check_dt, check_finite_dyn, check_len};
use crate::kernels::reduce::max_step_deviation;
use crate::model::{Domain, DynStateSpace, LinearSystem, StateSpace, Token, period_of};
use responses::Test;

/// Largest number of samples a simulation will allocate for (10⁷, about
/// 0.5 GB for the lab's 4-state plant); a longer request is almost certainly
/// a unit mistake (ms for s) and is refused rather than exhausting memory.
///
/// # Examples
///
/// 20 s at 2 ms is 10 001 samples; 20 s written in ms, as 20 000 s, is
/// 10⁷ and refused:
///
/// ```
/// use ctrlab::sim::{MAX_SAMPLES, time_grid};
/// assert_eq!(time_grid(20.0, 0.002)?.len(), 10_001);
/// assert_eq!(20_000.0 / 0.002, MAX_SAMPLES as f64);
/// assert!(time_grid(20_000.0, 0.002).is_err());
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub const MAX_SAMPLES: usize = 10_000_000;

/// Largest number of RK4 steps one simulation will take, over all its
/// intervals (10⁸, seconds of work for a small plant): more sub-steps than
/// that are a mistake, refused rather than run for hours.
///
/// # Examples
///
/// ```
/// use ctrlab::{Error, StateSpace, sim::{MAX_RK4_STEPS, Solver, simulate}};
/// use ctrlab::nalgebra::{matrix, vector};
///
/// let sys = StateSpace::continuous(matrix![-1.0], matrix![1.0], matrix![1.0], matrix![0.0])?;
/// let solver = Solver::Rk4 { substeps: MAX_RK4_STEPS + 1 };
/// let err = simulate(&sys, &[0.0, 1.0], vector![0.0], |_| vector![1.0], solver).unwrap_err();
/// assert!(matches!(err, Error::InvalidParameter { name: "substeps", .. }));
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub const MAX_RK4_STEPS: usize = 100_000_000;

/// A simulated time response: sample times (s), states and outputs, in the
/// model's units (SI for the crate's own models). All three have one entry
/// per sample.
///
/// One type for both model sizes, written over nalgebra's dimensions: the
/// states and outputs of a `StateSpace<N, M, P, _>` are `SVector`s
/// (`Response<Const<N>, Const<P>>`), those of a `DynStateSpace` `DVector`s
/// ([`DynResponse`], `Response<Dyn, Dyn>`).
///
/// # Examples
///
/// ```
/// use ctrlab::{StateSpace, StepInfoOptions, step_info, sim::step_response};
/// use ctrlab::nalgebra::{Const, matrix};
///
/// // A lag, τ = 0.1 s: its step response and the figures of it.
/// let sys = StateSpace::continuous(matrix![-10.0], matrix![10.0], matrix![1.0], matrix![0.0])?;
/// let r: ctrlab::sim::Response<Const<1>, Const<1>> = step_response(&sys, 2.0, 0.001)?;
/// assert_eq!((r.len(), r.x[0].len(), r.y[0].len()), (2001, 1, 1));
/// let info = step_info(&r.t, &r.output(0)?, &StepInfoOptions::default())?;
/// assert!((info.rise_time - 0.1 * 9f64.ln()).abs() < 1e-6);
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct Response<N: Dim, P: Dim>
where
    DefaultAllocator: Allocator<N> + Allocator<P>,
{
    /// Sample times, s.
    pub t: Vec<f64>,
    /// State at each sample (`n` entries each).
    pub x: Vec<OVector<f64, N>>,
    /// Output at each sample (`p` entries each).
    pub y: Vec<OVector<f64, P>>,
}

/// The [`Response`] of a model sized at run time, its states and outputs
/// `DVector`s.
///
/// # Examples
///
/// ```
/// use ctrlab::{DynStateSpace, sim::{DynResponse, step_response}};
/// use ctrlab::nalgebra::dmatrix;
///
/// let sys = DynStateSpace::continuous(dmatrix![-10.0], dmatrix![10.0], dmatrix![1.0], dmatrix![0.0])?;
/// let r: DynResponse = step_response(&sys, 1.0, 0.01)?;
/// assert_eq!((r.len(), r.x[0].len()), (101, 1));
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub type DynResponse = Response<Dyn, Dyn>;

impl<N: Dim, P: Dim> Response<N, P>
where
    DefaultAllocator: Allocator<N> + Allocator<P>,
{
    /// Number of samples.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::{MassSpring, Cart, sim::step_response};
    /// let r = step_response(&MassSpring::nominal().state_space(Cart::Two)?, 1.0, 0.01)?;
    /// assert_eq!(r.len(), 101);
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
    /// # use ctrlab::{MassSpring, Cart, sim::step_response};
    /// let r = step_response(&MassSpring::nominal().state_space(Cart::Two)?, 1.0, 0.01)?;
    /// assert!(!r.is_empty());
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }

    /// Output channel `i` as a plain vector, e.g. to hand to step metrics.
    ///
    /// # Errors
    ///
    /// [`Error::OutOfRange`] unless `i` is below the number of outputs (`P`
    /// for a fixed-size model; for a run-time-sized one, the first
    /// sample's, so an empty response has none).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::{DynStateSpace, Error, MassSpring, Cart, sim::step_response};
    /// let plant = MassSpring::nominal().state_space(Cart::Two)?;
    /// let r = step_response(&plant, 1.0, 0.01)?;
    /// assert_eq!(r.output(0)?.len(), r.len());
    /// assert!(matches!(r.output(1), Err(Error::OutOfRange { index: 1, len: 1, .. })));
    /// // The same for the model sized at run time.
    /// let d = step_response(&DynStateSpace::from(&plant), 1.0, 0.01)?;
    /// assert_eq!(d.output(0)?, r.output(0)?);
    /// assert!(matches!(d.output(1), Err(Error::OutOfRange { index: 1, len: 1, .. })));
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn output(&self, i: usize) -> Result<Vec<f64>, Error> {
        let outputs = P::try_to_usize().unwrap_or_else(|| self.y.first().map_or(0, |y| y.len()));
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

/// A linear model that can be simulated: [`StateSpace`] and
/// [`DynStateSpace`], in either time domain. [`simulate`],
/// [`simulate_discrete`], [`simulate_discrete_feedback`],
/// [`step_response`], [`impulse_response`] and [`initial_response`] take
/// one; [`Response`](Self::Response) is what they return.
///
/// Sealed: implemented by the two model types only.
///
/// # Examples
///
/// ```
/// use ctrlab::{DynStateSpace, StateSpace, sim::{Simulate, initial_response}};
/// use ctrlab::nalgebra::matrix;
///
/// // Written once, for either model size.
/// fn final_output<S: Simulate<Response = R>, R>(sys: &S, x0: S::State) -> Result<R, ctrlab::Error> {
///     initial_response(sys, 1.0, 0.5, x0)
/// }
/// let sys = StateSpace::continuous(matrix![-1.0], matrix![1.0], matrix![1.0], matrix![0.0])?;
/// let r = final_output(&sys, matrix![1.0])?;
/// assert!((r.y[2][0] - (-1.0f64).exp()).abs() < 1e-15);
/// let d = final_output(&DynStateSpace::from(&sys), ctrlab::nalgebra::dvector![1.0])?;
/// assert_eq!(d.y[2][0], r.y[2][0]);
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub trait Simulate: LinearSystem {
    /// The response: [`Response<Const<N>, Const<P>>`](Response) for a
    /// `StateSpace<N, M, P, _>`, [`DynResponse`] for a `DynStateSpace`.
    type Response: std::fmt::Debug + Clone;

    /// A standard test response on the grid of `(t_end, dt)`.
    #[doc(hidden)]
    fn respond(
        &self,
        _: Token,
        test: Test<Self::State>,
        t_end: f64,
        dt: f64,
    ) -> Result<Self::Response, Error>;

    /// A continuous simulation over the grid `t`.
    #[doc(hidden)]
    fn lsim<F: FnMut(f64) -> Self::Input>(
        &self,
        _: Token,
        t: &[f64],
        x0: Self::State,
        input: F,
        solver: Solver,
    ) -> Result<Self::Response, Error>;

    /// A discrete simulation of `steps` samples, closed loop.
    #[doc(hidden)]
    fn dsim<F: FnMut(usize, &Self::State) -> Self::Input>(
        &self,
        _: Token,
        x0: Self::State,
        steps: usize,
        control: F,
    ) -> Result<Self::Response, Error>;
}

/// The simulations of both model types: the same code, each on its own
/// matrices (the types are all that differ).
macro_rules! simulate_for {
    ($([$($generics:tt)*] $model:ty => $response:ty),* $(,)?) => {$(
        impl<$($generics)*> Simulate for $model {
            type Response = $response;

            fn respond(
                &self,
                _: Token,
                test: Test<Self::State>,
                t_end: f64,
                dt: f64,
            ) -> Result<Self::Response, Error> {
                let abcd = (self.a(), self.b(), self.c(), self.d());
                responses::respond(abcd, self.domain(), test, t_end, dt)
            }

            fn lsim<F: FnMut(f64) -> Self::Input>(
                &self,
                _: Token,
                t: &[f64],
                x0: Self::State,
                input: F,
                solver: Solver,
            ) -> Result<Self::Response, Error> {
                let abcd = (self.a(), self.b(), self.c(), self.d());
                lsim(abcd, period_of(&self.domain()), t, x0, input, solver)
            }

            fn dsim<F: FnMut(usize, &Self::State) -> Self::Input>(
                &self,
                _: Token,
                x0: Self::State,
                steps: usize,
                control: F,
            ) -> Result<Self::Response, Error> {
                let abcd = (self.a(), self.b(), self.c(), self.d());
                dsim(abcd, period_of(&self.domain()), x0, steps, control)
            }
        }
    )*};
}

simulate_for! {
    [const N: usize, const M: usize, const P: usize, D: Domain] StateSpace<N, M, P, D>
        => Response<Const<N>, Const<P>>,
    [D: Domain] DynStateSpace<D> => DynResponse,
}

/// How [`simulate`] advances a continuous model between grid points.
///
/// # Examples
///
/// A unit step into `ẋ = −x + u`: at 1 s, `1 − e⁻¹`, exactly (ZOH) or
/// to RK4's accuracy.
///
/// ```
/// use ctrlab::{StateSpace, sim::{Solver, simulate}};
/// use ctrlab::nalgebra::{matrix, vector};
///
/// let sys = StateSpace::continuous(matrix![-1.0], matrix![1.0], matrix![1.0], matrix![0.0])?;
/// let exact = 1.0 - (-1.0f64).exp();
/// for solver in [Solver::Zoh, Solver::Rk4 { substeps: 10 }] {
///     let r = simulate(&sys, &[0.0, 1.0], vector![0.0], |_| vector![1.0], solver)?;
///     assert!((r.y[1][0] - exact).abs() < 1e-6, "{solver:?}");
/// }
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum Solver {
    /// Exact for the held input: one ZOH discretisation per distinct interval
    /// length (once for a uniform grid).
    #[default]
    Zoh,
    /// `substeps` RK4 steps per grid interval (≥ 1; at most
    /// [`MAX_RK4_STEPS`] over the whole grid).
    Rk4 {
        /// RK4 steps per interval.
        substeps: usize,
    },
}

/// A uniform time grid `0, dt, 2 dt, …, n dt` with `n = round(t_end / dt)`, s.
///
/// # Errors
///
/// [`Error::InvalidParameter`] for a bad `dt` (finite, > 0), a `t_end` that is
/// not finite or shorter than one step, or more than [`MAX_SAMPLES`] samples.
///
/// # Examples
///
/// ```
/// # use ctrlab::sim::time_grid;
/// let t = time_grid(0.01, 0.002)?;
/// assert_eq!(t.len(), 6);
/// assert!((t[5] - 0.01).abs() < 1e-15);
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub fn time_grid(t_end: f64, dt: f64) -> Result<Vec<f64>, Error> {
    check_dt(dt)?;
    if !(t_end.is_finite() && t_end >= dt) {
        return Err(Error::InvalidParameter {
            name: "t_end",
            value: t_end,
            reason: "must be finite and at least one time step, s",
        });
    }
    let n = (t_end / dt).round();
    if n >= MAX_SAMPLES as f64 {
        return Err(Error::InvalidParameter {
            name: "t_end",
            value: t_end,
            reason: "t_end / dt exceeds MAX_SAMPLES",
        });
    }
    // Rounding `t_end / dt` up can put the last sample past f64::MAX.
    if !(n * dt).is_finite() {
        return Err(Error::InvalidParameter {
            name: "t_end",
            value: t_end,
            reason: "the grid's last time, round(t_end / dt)·dt, overflows",
        });
    }
    Ok((0..=n as usize).map(|k| k as f64 * dt).collect())
}

/// The error of a simulation asked of a model in the other time domain
/// (the public functions' bounds make it unreachable).
pub(super) fn wrong_domain(reason: &'static str) -> Error {
    Error::InvalidParameter {
        name: "dt",
        value: f64::NAN,
        reason,
    }
}

/// [`Error::LengthMismatch`] unless `x0` has `states` entries,
/// [`Error::NonFinite`] named `"x0"` for its first non-finite entry.
pub(super) fn check_state<N: Dim>(x0: &OVector<f64, N>, states: usize) -> Result<(), Error>
where
    DefaultAllocator: Allocator<N>,
{
    check_len("x0", states, x0.len())?;
    check_finite_dyn("x0", x0)
}

/// The states and outputs of a simulation, one per sample.
pub(crate) type States<N, P> = (Vec<OVector<f64, N>>, Vec<OVector<f64, P>>);

/// The matrices `(A, B, C, D)` of a model, borrowed.
pub(crate) type Abcd<'a, N, M, P> = (
    &'a OMatrix<f64, N, N>,
    &'a OMatrix<f64, N, M>,
    &'a OMatrix<f64, P, N>,
    &'a OMatrix<f64, P, M>,
);

/// Sample times (s), states and outputs of a discrete simulation.
pub(crate) type Sampled<N, P> = (Vec<f64>, Vec<OVector<f64, N>>, Vec<OVector<f64, P>>);

/// How far apart two of the grid's intervals may be and still be the same
/// interval: `2 ε max|t|`, two units in the last place of its largest time
/// (each time is rounded once, `k·dt` or `t + dt`, so each interval is off
/// by at most one such unit).
pub(crate) fn grid_rounding(t: &[f64]) -> f64 {
    let (first, last) = (t[0], t[t.len() - 1]);
    2.0 * f64::EPSILON * first.abs().max(last.abs())
}

/// The grid's mean step when every interval is within `tol` of it.
pub(crate) fn uniform_step(t: &[f64], tol: f64) -> Option<f64> {
    let n = t.len().checked_sub(1).filter(|&n| n > 0)?;
    let mean = (t[n] - t[0]) / n as f64;
    (mean.is_finite() && max_step_deviation(t, mean) <= tol).then_some(mean)
}

pub(super) fn check_grid(t: &[f64]) -> Result<(), Error> {
    let bad = |value: f64, reason| Error::InvalidParameter {
        name: "t",
        value,
        reason,
    };
    if t.is_empty() {
        return Err(bad(f64::NAN, "time grid is empty"));
    }
    if t.len() > MAX_SAMPLES {
        return Err(bad(t.len() as f64, "time grid longer than MAX_SAMPLES"));
    }
    // Folds without early exit, which vectorise; the search for the
    // offending time only on failure.
    let finite = t.iter().fold(true, |ok, v| ok & v.is_finite());
    let increasing = t.iter().zip(&t[1..]).fold(true, |ok, (a, b)| ok & (b > a));
    if !finite && let Some(&v) = t.iter().find(|v| !v.is_finite()) {
        return Err(bad(v, "time grid must be finite"));
    }
    if !increasing && let Some(w) = t.windows(2).find(|w| w[1] <= w[0]) {
        return Err(bad(w[1], "time grid must be strictly increasing"));
    }
    Ok(())
}

/// Refuses an input sample that is not finite or does not have `inputs`
/// entries (a closure's vector, sized at run time).
pub(super) fn check_input<M: Dim>(u: &OVector<f64, M>, inputs: usize) -> Result<(), Error>
where
    DefaultAllocator: Allocator<M>,
{
    check_len("input", inputs, u.len())?;
    match u.iter().find(|v| !v.is_finite()) {
        Some(&value) => Err(Error::InvalidParameter {
            name: "input",
            value,
            reason: "input samples must be finite",
        }),
        None => Ok(()),
    }
}
