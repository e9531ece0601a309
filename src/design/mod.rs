//! Controllers and their design: the [`Controller`] trait that simulation and
//! hardware both drive, [`StateFeedback`] in the lab's and the textbook's
//! form, pole placement by [`acker`], and optimal gains by [`lqr`] / [`dlqr`].
//!
//! # Examples
//!
//! ```
//! use ctrlab::{Controller, MassSpring, Output, design::StateFeedback};
//! use nalgebra::vector;
//!
//! // The lab's Kf = [0 0 10 0.1] per millimetre, cart 2.
//! let mut ctrl = StateFeedback::from_lab_gains([0.0, 0.0, 10.0, 0.1], Output::Cart2)?;
//! // At rest 10 mm short of a 30 mm setpoint: u = 10 V/mm · 10 mm.
//! let u = ctrl.update(0.030, &vector![0.0, 0.0, 0.020, 0.0]);
//! assert!((u[0] - 100.0).abs() < 1e-9);
//!
//! let plant = MassSpring::nominal().state_space(Output::Cart2)?;
//! assert!(ctrl.closed_loop(&plant)?.is_stable()?);
//! # Ok::<(), ctrlab::Error>(())
//! ```

use nalgebra::SVector;

mod feedback;
mod lqr;
mod place;

pub use feedback::StateFeedback;
pub use lqr::{Lqr, dlqr, lqr};
pub use place::acker;

/// A control law that maps a scalar reference and the measured state to the
/// plant input. One object runs unchanged in simulation and on the rig.
///
/// [`update`](Self::update) is called once per sample; implementations must
/// not allocate in it (the 2 ms loop on the rig depends on that).
///
/// # Examples
///
/// ```
/// use ctrlab::Controller;
/// use nalgebra::{SVector, vector};
///
/// /// Proportional control of the first state.
/// struct P(f64);
/// impl Controller<2, 1> for P {
///     fn update(&mut self, reference: f64, state: &SVector<f64, 2>) -> SVector<f64, 1> {
///         vector![self.0 * (reference - state[0])]
///     }
/// }
///
/// let mut p = P(2.0);
/// assert_eq!(p.update(1.0, &vector![0.25, 0.0]), vector![1.5]);
/// // `&mut C` is a controller too, so a loop can borrow one.
/// fn drive(mut c: impl Controller<2, 1>) -> f64 { c.update(0.0, &vector![1.0, 0.0])[0] }
/// assert_eq!(drive(&mut p), -2.0);
/// ```
pub trait Controller<const N: usize, const M: usize> {
    /// One control step: `reference` in SI (m for the lab), `state` in SI;
    /// returns the plant input (N or V for the lab). Allocates nothing.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{Controller, Output, StateFeedback};
    /// use nalgebra::vector;
    ///
    /// let mut c = StateFeedback::from_lab_gains([1.0, 0.0, 0.0, 0.0], Output::Cart1)?;
    /// // 15 mm setpoint, cart 1 at 10 mm: 1 per mm · 5 mm.
    /// let u = c.update(0.015, &vector![0.010, 0.0, 0.0, 0.0]);
    /// assert!((u[0] - 5.0).abs() < 1e-12);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    fn update(&mut self, reference: f64, state: &SVector<f64, N>) -> SVector<f64, M>;

    /// Clears internal state (integrators, filters) before a new run. The
    /// default does nothing, which is right for a static law.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{Controller, Output, StateFeedback};
    /// use nalgebra::vector;
    ///
    /// let mut c = StateFeedback::from_lab_gains([0.0, 0.0, 1.0, 0.0], Output::Cart2)?;
    /// let x = vector![0.0, 0.0, 0.01, 0.0];
    /// let before = c.update(0.02, &x);
    /// c.reset(); // a static law has nothing to forget
    /// assert_eq!(c.update(0.02, &x), before);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    fn reset(&mut self) {}
}

impl<T: Controller<N, M> + ?Sized, const N: usize, const M: usize> Controller<N, M> for &mut T {
    #[inline]
    fn update(&mut self, reference: f64, state: &SVector<f64, N>) -> SVector<f64, M> {
        (**self).update(reference, state)
    }

    #[inline]
    fn reset(&mut self) {
        (**self).reset()
    }
}

/// The open-loop "controller": passes the reference through as the input,
/// `u = reference` on every input channel, ignoring the state.
///
/// It lets open-loop experiments (an identification run's square wave, a
/// constant push) go through the same loop, recording and safety as the
/// closed-loop ones: the reference function *is* the input signal (V on the
/// rig, N in simulation).
///
/// # Examples
///
/// ```
/// use ctrlab::{Controller, design::OpenLoop};
/// use nalgebra::{SVector, vector};
///
/// let mut open = OpenLoop;
/// let u: SVector<f64, 1> = open.update(2.0, &vector![0.1, 0.0, 0.2, 0.0]);
/// assert_eq!(u, vector![2.0]);
/// ```
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct OpenLoop;

impl<const N: usize, const M: usize> Controller<N, M> for OpenLoop {
    #[inline]
    fn update(&mut self, reference: f64, _state: &SVector<f64, N>) -> SVector<f64, M> {
        SVector::from_element(reference)
    }
}
