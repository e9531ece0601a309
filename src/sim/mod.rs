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

mod responses;
mod sampled;

pub use responses::{impulse_response, initial_response, step_response};
pub use sampled::{SampledConfig, Sensor, run_sampled};

use crate::discretize::{Held, zoh};
use crate::error::{Error, check_dt, check_finite_dyn, check_len};
use crate::kernels::reduce::max_step_deviation;
use crate::model::{
    Continuous, Discrete, Domain, DynStateSpace, LinearSystem, StateSpace, Token, period_of,
};
use responses::Test;

/// Largest number of samples a simulation will allocate for (10⁷, about
/// 0.5 GB for the lab's 4-state plant); a longer request is almost certainly
/// a unit mistake (ms for s) and is refused rather than exhausting memory.
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

/// Simulates a continuous model over the time grid `t` (s, strictly
/// increasing) from state `x0`.
///
/// The input is sampled at each grid time and held until the next, as a
/// digital controller applies it; use a finer grid for a smooth input.
/// [`Solver::Zoh`] is exact for that input, [`Solver::Rk4`] integrates it.
/// A grid whose intervals agree to within the rounding of its times (any
/// `k·dt` or accumulated grid) is simulated with one discretisation.
///
/// # Errors
///
/// [`Error::InvalidParameter`] named `"t"` for an empty, non-finite or
/// non-increasing grid (or more than [`MAX_SAMPLES`] points), named
/// `"substeps"` for zero RK4 sub-steps or more than [`MAX_RK4_STEPS`] in all,
/// named `"input"` for a non-finite input sample; [`Error::NonFinite`] named
/// `"x0"` for a non-finite initial state; [`Error::LengthMismatch`] named
/// `"x0"` or `"input"` for a vector of the wrong length (a run-time-sized
/// model); [`Error::Overflow`] when the response diverges past `f64::MAX`;
/// errors of [`discretize`](StateSpace::discretize).
///
/// # Examples
///
/// ```
/// use ctrlab::{DynStateSpace, MassSpring, Cart, sim::{simulate, time_grid, Solver}};
/// use ctrlab::nalgebra::{DVector, dvector, vector};
///
/// let sys = MassSpring::nominal().state_space(Cart::Two)?;
/// let t = time_grid(10.0, 0.002)?;
/// let r = simulate(&sys, &t, vector![0.0, 0.0, 0.0, 0.0], |_t| vector![10.0], Solver::Zoh)?;
/// // 10 N on cart 2 settles at 20 mm.
/// assert!((r.y.last().unwrap()[0] - 0.020).abs() < 1e-9);
///
/// // The same model sized at run time.
/// let dynamic = DynStateSpace::from(&sys);
/// let d = simulate(&dynamic, &t, DVector::zeros(4), |_t| dvector![10.0], Solver::Zoh)?;
/// assert_eq!(d.output(0)?, r.output(0)?);
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[doc(alias = "lsim")]
pub fn simulate<S: Simulate<Domain = Continuous>>(
    sys: &S,
    t: &[f64],
    x0: S::State,
    input: impl FnMut(f64) -> S::Input,
    solver: Solver,
) -> Result<S::Response, Error> {
    sys.lsim(Token(()), t, x0, input, solver)
}

/// [`simulate`] on the matrices of a continuous model (`period` is `None`).
fn lsim<N: Dim, M: Dim, P: Dim>(
    (a, b, c, d): Abcd<'_, N, M, P>,
    period: Option<f64>,
    t: &[f64],
    x0: OVector<f64, N>,
    mut input: impl FnMut(f64) -> OVector<f64, M>,
    solver: Solver,
) -> Result<Response<N, P>, Error>
where
    DefaultAllocator: Allocator<N, N> + Allocator<N, M> + Allocator<P, N> + Allocator<P, M>,
    DefaultAllocator: Allocator<N> + Allocator<M> + Allocator<P>,
{
    if period.is_some() {
        return Err(wrong_domain(
            "a discrete model is simulated by simulate_discrete",
        ));
    }
    check_grid(t)?;
    check_state(&x0, a.nrows())?;
    if let Solver::Rk4 { substeps } = solver {
        let bad = |reason| Error::InvalidParameter {
            name: "substeps",
            value: substeps as f64,
            reason,
        };
        if substeps == 0 {
            return Err(bad("RK4 needs at least one sub-step per interval"));
        }
        match substeps.checked_mul(t.len() - 1) {
            Some(total) if total <= MAX_RK4_STEPS => {}
            _ => return Err(bad("more than sim::MAX_RK4_STEPS RK4 steps in all")),
        }
    }
    let Solver::Rk4 { substeps } = solver else {
        let (x, y) = lsim_zoh(a, b, c, d, t, x0, input)?;
        return Ok(Response {
            t: t.to_vec(),
            x,
            y,
        });
    };
    let mut xs = Vec::with_capacity(t.len());
    let mut ys = Vec::with_capacity(t.len());
    let mut x = x0;
    let uniform = uniform_step(t, grid_rounding(t));
    for (k, &tk) in t.iter().enumerate() {
        let u = input(tk);
        check_input(&u, b.ncols())?;
        ys.push(c * &x + d * &u);
        xs.push(x.clone());
        let Some(&next) = t.get(k + 1) else { break };
        let h = uniform.unwrap_or(next - tk);
        let hs = h / substeps as f64;
        for _ in 0..substeps {
            rk4_step(a, b, hs, &mut x, &u);
        }
    }
    let finite = |v: &[f64]| v.iter().fold(true, |ok, v| ok & v.is_finite());
    if !xs
        .iter()
        .zip(&ys)
        .all(|(x, y)| finite(x.as_slice()) & finite(y.as_slice()))
    {
        return Err(Error::Overflow {
            operation: DIVERGED_CONTINUOUS,
        });
    }
    Ok(Response {
        t: t.to_vec(),
        x: xs,
        y: ys,
    })
}

/// One classical RK4 step of `x' = A x + B u` with `u` held: the
/// arithmetic of [`Rk4`](crate::integrate::Rk4) on a linear model, for
/// matrices of either size (nothing allocated for fixed sizes).
fn rk4_step<N: Dim, M: Dim>(
    a: &OMatrix<f64, N, N>,
    b: &OMatrix<f64, N, M>,
    h: f64,
    x: &mut OVector<f64, N>,
    u: &OVector<f64, M>,
) where
    DefaultAllocator: Allocator<N, N> + Allocator<N, M> + Allocator<N> + Allocator<M>,
{
    let half = 0.5 * h;
    let f = |x: &OVector<f64, N>| a * x + b * u;
    let k1 = f(x);
    let k2 = f(&(&*x + &k1 * half));
    let k3 = f(&(&*x + &k2 * half));
    let k4 = f(&(&*x + &k3 * h));
    *x += (k1 + (k2 + k3) * 2.0 + k4) * (h / 6.0);
}

/// The error of a simulation asked of a model in the other time domain
/// (the public functions' bounds make it unreachable).
fn wrong_domain(reason: &'static str) -> Error {
    Error::InvalidParameter {
        name: "dt",
        value: f64::NAN,
        reason,
    }
}

/// [`Error::LengthMismatch`] unless `x0` has `states` entries,
/// [`Error::NonFinite`] named `"x0"` for its first non-finite entry.
fn check_state<N: Dim>(x0: &OVector<f64, N>, states: usize) -> Result<(), Error>
where
    DefaultAllocator: Allocator<N>,
{
    check_len("x0", states, x0.len())?;
    check_finite_dyn("x0", x0)
}

/// What a continuous simulation that overflows reports.
const DIVERGED_CONTINUOUS: &str = "simulation (the response diverged past f64::MAX)";

/// The states and outputs of `(A, B, C, D)` over the grid `t` (checked)
/// from `x0` (checked) under the input `input(t)` held between grid times,
/// by exact ZOH steps: the one implementation behind [`simulate`] (both
/// model sizes) and the continuous standard responses. For fixed-size
/// matrices nothing in the loop allocates.
pub(crate) fn lsim_zoh<N: Dim, M: Dim, P: Dim>(
    a: &OMatrix<f64, N, N>,
    b: &OMatrix<f64, N, M>,
    c: &OMatrix<f64, P, N>,
    d: &OMatrix<f64, P, M>,
    t: &[f64],
    x0: OVector<f64, N>,
    mut input: impl FnMut(f64) -> OVector<f64, M>,
) -> Result<States<N, P>, Error>
where
    DefaultAllocator: Allocator<N, N> + Allocator<N, M> + Allocator<P, N> + Allocator<P, M>,
    DefaultAllocator: Allocator<N> + Allocator<M> + Allocator<P>,
{
    let mut xs = Vec::with_capacity(t.len());
    let mut ys = Vec::with_capacity(t.len());
    let mut x = x0;
    // Intervals that differ by no more than the rounding of the grid's
    // times are one interval: a uniform grid is one discretisation with its
    // mean step (no drift), however its times were rounded.
    let tol = grid_rounding(t);
    let uniform = uniform_step(t, tol);
    if let Some(h) = uniform {
        // One discretisation for the whole grid, and a loop that holds
        // only the recursion and the stores.
        let (ad, bd) = zoh(a, b, h)?;
        // The finite check folded into the loop: once a state component is
        // not finite, every component of every later state is not (`A x`
        // sums every column, and 0·∞ and 0·NaN are NaN), so the last state
        // stands for all; each output is probed with `0·v` (0, or NaN for ±∞ and NaN).
        let mut probe = 0.0;
        for &tk in t {
            let u = input(tk);
            check_input(&u, b.ncols())?;
            let y = c * &x + d * &u;
            probe += y.iter().map(|v| v * 0.0).sum::<f64>();
            let next = &ad * &x + &bd * &u;
            xs.push(x);
            ys.push(y);
            x = next;
        }
        let last = xs.last().is_none_or(|x| x.iter().all(|v| v.is_finite()));
        if !(last && probe == 0.0) {
            return Err(Error::Overflow {
                operation: DIVERGED_CONTINUOUS,
            });
        }
        return Ok((xs, ys));
    }
    // ZOH matrices, recomputed only when the interval length changes.
    let mut cached: Option<(f64, Held<N, M>)> = None;
    for (k, &tk) in t.iter().enumerate() {
        let u = input(tk);
        check_input(&u, b.ncols())?;
        let y = c * &x + d * &u;
        let next = match t.get(k + 1) {
            None => None,
            Some(&next) => {
                let h = next - tk;
                let same = matches!(&cached, Some((hc, ..)) if (hc - h).abs() <= tol);
                if !same {
                    cached = Some((h, zoh(a, b, h)?));
                }
                cached.as_ref().map(|(_, (ad, bd))| ad * &x + bd * &u)
            }
        };
        xs.push(x);
        ys.push(y);
        match next {
            Some(next) => x = next,
            None => break,
        }
    }
    let finite = |v: &[f64]| v.iter().fold(true, |ok, v| ok & v.is_finite());
    if xs
        .iter()
        .zip(&ys)
        .all(|(x, y)| finite(x.as_slice()) & finite(y.as_slice()))
    {
        Ok((xs, ys))
    } else {
        Err(Error::Overflow {
            operation: DIVERGED_CONTINUOUS,
        })
    }
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

/// What a discrete simulation that overflows reports.
const DIVERGED: &str = "discrete simulation (the response diverged past f64::MAX)";

/// Refuses an input sample that is not finite or does not have `inputs`
/// entries (a closure's vector, sized at run time).
fn check_input<M: Dim>(u: &OVector<f64, M>, inputs: usize) -> Result<(), Error>
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

/// Simulates a discrete model open loop: one sample per input, `t[k] = k dt`,
/// `y[k] = C x[k] + D u[k]`, then `x[k+1] = A x[k] + B u[k]`.
///
/// # Errors
///
/// As [`simulate_discrete_feedback`].
///
/// # Examples
///
/// ```
/// use ctrlab::{DynStateSpace, StateSpace, sim::simulate_discrete};
/// use ctrlab::nalgebra::{dvector, matrix, vector};
///
/// let sys = StateSpace::discrete(matrix![0.5], matrix![1.0], matrix![1.0], matrix![0.0], 0.1)?;
/// let r = simulate_discrete(&sys, vector![0.0], &[vector![1.0]; 3])?;
/// assert_eq!(r.output(0)?, vec![0.0, 1.0, 1.5]);
/// let d = simulate_discrete(&DynStateSpace::from(&sys), dvector![0.0], &vec![dvector![1.0]; 3])?;
/// assert_eq!(d.output(0)?, vec![0.0, 1.0, 1.5]);
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub fn simulate_discrete<S: Simulate<Domain = Discrete>>(
    sys: &S,
    x0: S::State,
    inputs: &[S::Input],
) -> Result<S::Response, Error> {
    sys.dsim(Token(()), x0, inputs.len(), |k, _x| inputs[k].clone())
}

/// Simulates a discrete model for `steps` samples with the input computed
/// from the current sample index and state, `u[k] = control(k, &x[k])`: a
/// closed loop around any controller.
///
/// # Errors
///
/// [`Error::InvalidParameter`] named `"steps"` for more than
/// [`MAX_SAMPLES`] samples, `"x0"` for a non-finite initial state, `"input"`
/// for a non-finite input sample; [`Error::LengthMismatch`] named `"x0"` or
/// `"input"` for a vector of the wrong length (a run-time-sized model);
/// [`Error::Overflow`] when the response diverges past `f64::MAX`.
///
/// # Examples
///
/// ```
/// use ctrlab::{DynStateSpace, Error, StateSpace, sim::simulate_discrete_feedback};
/// use ctrlab::nalgebra::{dvector, matrix, vector};
///
/// // x[k+1] = x + u with u = -0.5 x halves the state every sample.
/// let sys = StateSpace::discrete(matrix![1.0], matrix![1.0], matrix![1.0], matrix![0.0], 0.1)?;
/// let r = simulate_discrete_feedback(&sys, vector![8.0], 4, |_k, x| -0.5 * x)?;
/// assert_eq!(r.output(0)?, vec![8.0, 4.0, 2.0, 1.0]);
/// // u = x doubles the state every sample: past f64::MAX within 30 samples
/// // from 1e300, an error, not infinities.
/// let diverging = simulate_discrete_feedback(&sys, vector![1e300], 40, |_k, x| *x);
/// assert!(matches!(diverging, Err(Error::Overflow { .. })));
///
/// // The same loop on the model sized at run time.
/// let d = simulate_discrete_feedback(&DynStateSpace::from(&sys), dvector![8.0], 4, |_k, x| -0.5 * x)?;
/// assert_eq!(d.output(0)?, r.output(0)?);
/// assert!((d.t[3] - 0.3).abs() < 1e-15);
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub fn simulate_discrete_feedback<S: Simulate<Domain = Discrete>>(
    sys: &S,
    x0: S::State,
    steps: usize,
    control: impl FnMut(usize, &S::State) -> S::Input,
) -> Result<S::Response, Error> {
    sys.dsim(Token(()), x0, steps, control)
}

/// [`simulate_discrete_feedback`] on the matrices of a discrete model
/// (`period` is its period).
fn dsim<N: Dim, M: Dim, P: Dim>(
    abcd: Abcd<'_, N, M, P>,
    period: Option<f64>,
    x0: OVector<f64, N>,
    steps: usize,
    control: impl FnMut(usize, &OVector<f64, N>) -> OVector<f64, M>,
) -> Result<Response<N, P>, Error>
where
    DefaultAllocator: Allocator<N, N> + Allocator<N, M> + Allocator<P, N> + Allocator<P, M>,
    DefaultAllocator: Allocator<N> + Allocator<M> + Allocator<P>,
{
    let Some(dt) = period else {
        return Err(wrong_domain("a continuous model is simulated by simulate"));
    };
    if steps > MAX_SAMPLES {
        return Err(Error::InvalidParameter {
            name: "steps",
            value: steps as f64,
            reason: "more samples than MAX_SAMPLES",
        });
    }
    check_len("x0", abcd.0.nrows(), x0.len())?;
    if let Some(&value) = x0.iter().find(|v| !v.is_finite()) {
        return Err(Error::InvalidParameter {
            name: "x0",
            value,
            reason: "the initial state must be finite",
        });
    }
    let (t, x, y) = discrete_feedback(abcd, dt, x0, steps, control)?;
    Ok(Response { t, x, y })
}

/// The times (`k dt`), states and outputs of the discrete `(A, B, C, D)`
/// with period `dt` for `steps` samples from `x0` under
/// `u[k] = control(k, &x[k])`: the one implementation behind
/// [`simulate_discrete`], [`simulate_discrete_feedback`] and the discrete
/// standard responses, for both model sizes. `steps` and `x0` are the
/// caller's to check. For fixed-size matrices nothing in the
/// loop allocates.
pub(crate) fn discrete_feedback<N: Dim, M: Dim, P: Dim>(
    (a, b, c, d): Abcd<'_, N, M, P>,
    dt: f64,
    x0: OVector<f64, N>,
    steps: usize,
    mut control: impl FnMut(usize, &OVector<f64, N>) -> OVector<f64, M>,
) -> Result<Sampled<N, P>, Error>
where
    DefaultAllocator: Allocator<N, N> + Allocator<N, M> + Allocator<P, N> + Allocator<P, M>,
    DefaultAllocator: Allocator<N> + Allocator<M> + Allocator<P>,
{
    // The times grow with k: the last one finite makes every one finite.
    if steps > 0 && !((steps - 1) as f64 * dt).is_finite() {
        return Err(Error::InvalidParameter {
            name: "dt",
            value: dt,
            reason: "the last sample time (steps − 1) · dt exceeds f64::MAX s",
        });
    }
    let mut ts = Vec::with_capacity(steps);
    let mut xs = Vec::with_capacity(steps);
    let mut ys = Vec::with_capacity(steps);
    let mut x = x0;
    for k in 0..steps {
        let u = control(k, &x);
        if u.len() != b.ncols() {
            check_input(&u, b.ncols())?;
        }
        let y = c * &x + d * &u;
        let next = a * &x + b * &u;
        // Stop at the first overflow: a controller would otherwise see
        // infinities and the error would blame its input. A non-finite
        // input makes every entry of the next state non-finite, so this
        // one check also catches it (but for a model without states); then
        // the input is blamed.
        if next.iter().chain(y.iter()).any(|v| !v.is_finite())
            || (x.is_empty() && u.iter().any(|v| !v.is_finite()))
        {
            check_input(&u, b.ncols())?;
            return Err(Error::Overflow {
                operation: DIVERGED,
            });
        }
        // Everything inside the loop, whose speed is the latency of
        // `control` and `A x + B u`: a pass after it would cost more.
        ts.push(k as f64 * dt);
        xs.push(x);
        ys.push(y);
        x = next;
    }
    Ok((ts, xs, ys))
}
