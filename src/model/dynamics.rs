//! [`Dynamics`]: any continuous-time plant `x' = f(t, x, u)`, linear or not.

use nalgebra::SVector;

use super::{Continuous, StateSpace};

/// A continuous-time plant `x' = f(t, x, u)` with `N` states and `M` inputs.
///
/// Linear models ([`StateSpace`] in [`Continuous`] time), the lab's
/// [`MassSpring`](crate::lab::MassSpring) and any nonlinear plant (Coulomb
/// friction, saturation, …) implement it; so do closures of the right shape.
/// The steppers in [`integrate`](crate::integrate), the sampled-data
/// simulator [`sim::run_sampled`](crate::sim::run_sampled) and the
/// [`SimulatedCard`](crate::hw::SimulatedCard) all take one.
///
/// A plant with discontinuities that a fixed-step integrator cannot resolve
/// on its own (stick–slip friction: a cart's speed must stop at exactly zero
/// and stay there) also overrides [`update_mode`](Self::update_mode), which
/// the simulators call between integration steps.
///
/// # Examples
///
/// ```
/// use ctrlab::Dynamics;
/// use ctrlab::integrate::{Integrator, Rk4};
/// use ctrlab::nalgebra::{SVector, vector};
///
/// // A pendulum, x = [angle (rad), rate (rad/s)], u = torque/inertia (rad/s²).
/// let pendulum = |_t: f64, x: &SVector<f64, 2>, u: &SVector<f64, 1>| {
///     vector![x[1], -9.81 * x[0].sin() + u[0]]
/// };
/// let mut x = vector![0.1, 0.0];
/// Rk4.step_mut(&pendulum, 0.0, 1e-3, &mut x, &vector![0.0]);
/// assert!(x[0] < 0.1 && x[1] < 0.0);
/// ```
pub trait Dynamics<const N: usize, const M: usize> {
    /// The state derivative at time `t` (s), state `x`, input `u`.
    fn derivative(&self, t: f64, x: &SVector<f64, N>, u: &SVector<f64, M>) -> SVector<f64, N>;

    /// Updates the plant's discrete mode between integration steps and may
    /// project the state onto it: called by the simulators before the first
    /// step and after every step, with the input held over the next one.
    /// The default does nothing, which is right for any smooth plant.
    ///
    /// A stick–slip friction model, for example, decides here whether a cart
    /// whose speed crossed zero sticks (its speed is set to exactly zero and
    /// held by [`derivative`](Self::derivative)) or slides on.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::Dynamics;
    /// use ctrlab::nalgebra::{SVector, vector};
    ///
    /// /// x' = u, but x never goes below zero (a hard stop).
    /// struct Stop;
    /// impl Dynamics<1, 1> for Stop {
    ///     fn derivative(&self, _t: f64, _x: &SVector<f64, 1>, u: &SVector<f64, 1>) -> SVector<f64, 1> { *u }
    ///     fn update_mode(&mut self, _t: f64, x: &mut SVector<f64, 1>, _u: &SVector<f64, 1>) {
    ///         x[0] = x[0].max(0.0);
    ///     }
    /// }
    /// let mut x = vector![-0.5];
    /// Stop.update_mode(0.0, &mut x, &vector![0.0]);
    /// assert_eq!(x[0], 0.0);
    /// ```
    #[inline]
    fn update_mode(&mut self, _t: f64, _x: &mut SVector<f64, N>, _u: &SVector<f64, M>) {}
}

impl<const N: usize, const M: usize, const P: usize> Dynamics<N, M>
    for StateSpace<N, M, P, Continuous>
{
    #[inline]
    fn derivative(&self, _t: f64, x: &SVector<f64, N>, u: &SVector<f64, M>) -> SVector<f64, N> {
        StateSpace::derivative(self, x, u)
    }
}

impl<const N: usize, const M: usize, F> Dynamics<N, M> for F
where
    F: Fn(f64, &SVector<f64, N>, &SVector<f64, M>) -> SVector<f64, N>,
{
    #[inline]
    fn derivative(&self, t: f64, x: &SVector<f64, N>, u: &SVector<f64, M>) -> SVector<f64, N> {
        self(t, x, u)
    }
}
