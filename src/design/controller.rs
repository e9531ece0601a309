//! The [`Controller`] seam: what simulation and hardware both drive.

use nalgebra::SVector;

/// A discrete control law, as a real one runs: each period it sees the
/// measured outputs `y` (`P` of them) and the reference `r` (`R` values),
/// and returns the input `u` (`M` values); afterwards it is told the input
/// that was actually applied (after saturation and the drive's
/// quantisation), which observers and anti-windup need.
///
/// One object runs unchanged in the sampled-data simulator
/// ([`sim::run_sampled`](crate::sim::run_sampled)) and on any rig
/// ([`hw::run`](crate::hw::run)). Per period both call, in order:
/// [`update`](Self::update) with the measurements taken at the sampling
/// instant, then [`applied`](Self::applied) with what the actuator really
/// got. [`reset`](Self::reset) is called once before each run.
///
/// Only `update` is required. Implementations must not allocate in
/// `update` or `applied` (the 2 ms loop on the rig depends on that); the
/// crate's own controllers are pinned allocation-free by a test. `&mut C`
/// is a controller too, so a loop can borrow one and keep it afterwards.
///
/// Units are the plant's: SI for the crate's models (m, m/s), V or N for the
/// input.
///
/// # Examples
///
/// A PI controller written outside the crate, on one measured output:
///
/// ```
/// use ctrlab::Controller;
/// use ctrlab::nalgebra::{SVector, vector};
///
/// struct Pi { kp: f64, ki: f64, dt: f64, integral: f64 }
/// impl Controller<1, 1, 1> for Pi {
///     fn update(&mut self, y: &SVector<f64, 1>, r: &SVector<f64, 1>) -> SVector<f64, 1> {
///         let e = r[0] - y[0];
///         self.integral += e * self.dt;
///         vector![self.kp * e + self.ki * self.integral]
///     }
///     fn reset(&mut self) { self.integral = 0.0; }
///     fn period(&self) -> Option<f64> { Some(self.dt) }
/// }
///
/// let mut pi = Pi { kp: 2.0, ki: 10.0, dt: 0.01, integral: 0.0 };
/// assert_eq!(pi.update(&vector![0.5], &vector![1.0]), vector![1.0 + 0.05]);
/// pi.reset();
/// // `&mut C` is a controller too, so a loop can borrow one.
/// fn drive(mut c: impl Controller<1, 1, 1>) -> f64 { c.update(&vector![0.0], &vector![0.0])[0] }
/// assert_eq!(drive(&mut pi), 0.0);
/// ```
pub trait Controller<const P: usize, const R: usize, const M: usize> {
    /// One control step at a sampling instant: measurements `y` and
    /// reference `r` in, the input to apply out. Allocates nothing.
    fn update(&mut self, y: &SVector<f64, P>, r: &SVector<f64, R>) -> SVector<f64, M>;

    /// Tells the controller the input that was actually applied after its
    /// last [`update`](Self::update) (saturated, quantised; on a halted rig,
    /// zero). The default ignores it, which is right for a static law.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{Controller, OpenLoop};
    /// use ctrlab::nalgebra::{SVector, vector};
    /// let mut c = OpenLoop;
    /// let u: SVector<f64, 1> = Controller::<2, 1, 1>::update(&mut c, &vector![0.0, 0.0], &vector![30.0]);
    /// Controller::<2, 1, 1>::applied(&mut c, &vector![24.0]); // saturated: nothing to remember
    /// assert_eq!(u, vector![30.0]);
    /// ```
    #[inline]
    fn applied(&mut self, _u: &SVector<f64, M>) {}

    /// Clears internal state (integrators, observer states, filters) before
    /// a new run. The default does nothing, which is right for a static law.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{Controller, StateFeedback};
    /// use ctrlab::nalgebra::{matrix, vector};
    ///
    /// let mut c = StateFeedback::new(matrix![1.0, 0.0], vector![1.0])?;
    /// let before = c.update(&vector![0.01, 0.0], &vector![0.02]);
    /// c.reset(); // a static law has nothing to forget
    /// assert_eq!(c.update(&vector![0.01, 0.0], &vector![0.02]), before);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[inline]
    fn reset(&mut self) {}

    /// The sampling period the controller was designed for, s, or `None` for
    /// a law that works at any period (a static gain). The simulator and the
    /// rig's loop refuse to run a controller at another period.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{Controller, StateFeedback};
    /// use ctrlab::nalgebra::{matrix, vector};
    /// let c = StateFeedback::new(matrix![1.0], vector![1.0])?;
    /// assert_eq!(c.period(), None);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[inline]
    fn period(&self) -> Option<f64> {
        None
    }
}

impl<T, const P: usize, const R: usize, const M: usize> Controller<P, R, M> for &mut T
where
    T: Controller<P, R, M> + ?Sized,
{
    #[inline]
    fn update(&mut self, y: &SVector<f64, P>, r: &SVector<f64, R>) -> SVector<f64, M> {
        (**self).update(y, r)
    }

    #[inline]
    fn applied(&mut self, u: &SVector<f64, M>) {
        (**self).applied(u)
    }

    #[inline]
    fn reset(&mut self) {
        (**self).reset()
    }

    #[inline]
    fn period(&self) -> Option<f64> {
        (**self).period()
    }
}

/// The open-loop "controller": passes the reference through as the input,
/// `u = r` (so `R = M`), ignoring the measurements.
///
/// It lets open-loop experiments (an identification run's square wave, a
/// constant push) go through the same loop, recording and safety as the
/// closed-loop ones: the reference function *is* the input signal (V on the
/// rig, N in simulation).
///
/// # Examples
///
/// ```
/// use ctrlab::{Controller, OpenLoop};
/// use ctrlab::nalgebra::{SVector, vector};
///
/// let mut open = OpenLoop;
/// let u: SVector<f64, 1> = open.update(&vector![0.1, 0.0, 0.2, 0.0], &vector![2.0]);
/// assert_eq!(u, vector![2.0]);
/// ```
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct OpenLoop;

impl<const P: usize, const M: usize> Controller<P, M, M> for OpenLoop {
    #[inline]
    fn update(&mut self, _y: &SVector<f64, P>, r: &SVector<f64, M>) -> SVector<f64, M> {
        *r
    }
}
