//! Fixed-step ODE integration: the [`Rk4`] and [`Euler`] steppers for any
//! [`Dynamics`] (the plant trait, in [`model`](crate::model)).
//!
//! Steppers hold the input constant over a step (a zero-order hold, as a
//! sampled-data controller applies it). Stage vectors live on the stack, so a
//! step allocates nothing.

use nalgebra::SVector;

use crate::model::Dynamics;

/// A fixed-step integrator. The input `u` is held constant over the step.
///
/// `step_mut` advances the state in place; `step` returns the new state.
///
/// # Examples
///
/// One simulation loop for either stepper: over 1 s of `ẋ = −x` at
/// 0.1 s steps, RK4 is within 1e-6 of `e⁻¹`, Euler 2 % off.
///
/// ```
/// use ctrlab::integrate::{Euler, Integrator, Rk4};
/// use ctrlab::nalgebra::{SVector, vector};
///
/// fn at_one_second(method: &impl Integrator) -> f64 {
///     let decay = |_t: f64, x: &SVector<f64, 1>, _u: &SVector<f64, 1>| -x;
///     let mut x = vector![1.0];
///     (0..10).for_each(|k| method.step_mut(&decay, k as f64 * 0.1, 0.1, &mut x, &vector![0.0]));
///     x[0]
/// }
/// let exact = (-1.0f64).exp();
/// assert!((at_one_second(&Rk4) - exact).abs() < 1e-6);
/// assert!((at_one_second(&Euler) - exact).abs() > 0.01);
/// ```
pub trait Integrator {
    /// Advances `x` from time `t` by `h` seconds under dynamics `f` and input
    /// `u`, in place.
    fn step_mut<const N: usize, const M: usize, F: Dynamics<N, M> + ?Sized>(
        &self,
        f: &F,
        t: f64,
        h: f64,
        x: &mut SVector<f64, N>,
        u: &SVector<f64, M>,
    );

    /// The state after one step of `h` seconds from `x` at time `t`; the
    /// returning twin of [`step_mut`](Self::step_mut).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::integrate::{Euler, Integrator};
    /// use ctrlab::nalgebra::{SVector, vector};
    /// let decay = |_t: f64, x: &SVector<f64, 1>, _u: &SVector<f64, 1>| -x;
    /// assert_eq!(Euler.step(&decay, 0.0, 0.1, &vector![1.0], &vector![0.0]), vector![0.9]);
    /// ```
    #[inline]
    #[must_use]
    fn step<const N: usize, const M: usize, F: Dynamics<N, M> + ?Sized>(
        &self,
        f: &F,
        t: f64,
        h: f64,
        x: &SVector<f64, N>,
        u: &SVector<f64, M>,
    ) -> SVector<f64, N> {
        let mut next = *x;
        self.step_mut(f, t, h, &mut next, u);
        next
    }
}

/// The classical fourth-order Runge–Kutta method: local error O(h⁵), global
/// error O(h⁴). Four derivative evaluations per step; allocates nothing.
///
/// # Examples
///
/// ```
/// use ctrlab::integrate::{Integrator, Rk4};
/// use ctrlab::nalgebra::{SVector, vector};
///
/// // x' = -x from 1: after 1 s, e^-1, to 1e-9 with 100 steps.
/// let decay = |_t: f64, x: &SVector<f64, 1>, _u: &SVector<f64, 1>| -x;
/// let mut x = vector![1.0];
/// for k in 0..100 {
///     Rk4.step_mut(&decay, k as f64 * 0.01, 0.01, &mut x, &vector![0.0]);
/// }
/// assert!((x[0] - (-1.0f64).exp()).abs() < 1e-9);
/// ```
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Rk4;

impl Integrator for Rk4 {
    #[inline]
    fn step_mut<const N: usize, const M: usize, F: Dynamics<N, M> + ?Sized>(
        &self,
        f: &F,
        t: f64,
        h: f64,
        x: &mut SVector<f64, N>,
        u: &SVector<f64, M>,
    ) {
        let half = 0.5 * h;
        let k1 = f.derivative(t, x, u);
        let k2 = f.derivative(t + half, &(*x + k1 * half), u);
        let k3 = f.derivative(t + half, &(*x + k2 * half), u);
        let k4 = f.derivative(t + h, &(*x + k3 * h), u);
        *x += (k1 + (k2 + k3) * 2.0 + k4) * (h / 6.0);
    }
}

/// Forward Euler: `x ← x + h f(t, x, u)`. First order; for comparison and for
/// very cheap sub-stepping.
///
/// # Examples
///
/// ```
/// use ctrlab::integrate::{Euler, Integrator};
/// use ctrlab::nalgebra::{SVector, vector};
/// let ramp = |_t: f64, _x: &SVector<f64, 1>, u: &SVector<f64, 1>| *u;
/// let mut x = vector![0.0];
/// Euler.step_mut(&ramp, 0.0, 0.5, &mut x, &vector![2.0]);
/// assert_eq!(x, vector![1.0]);
/// ```
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Euler;

impl Integrator for Euler {
    #[inline]
    fn step_mut<const N: usize, const M: usize, F: Dynamics<N, M> + ?Sized>(
        &self,
        f: &F,
        t: f64,
        h: f64,
        x: &mut SVector<f64, N>,
        u: &SVector<f64, M>,
    ) {
        *x += f.derivative(t, x, u) * h;
    }
}
