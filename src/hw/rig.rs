//! The [`Rig`] trait: a plant a controller can run against.

use nalgebra::SVector;

use super::RigError;
use crate::data::Schema;

/// A plant a controller can run against, with `M` inputs and `P`
/// measurements, sampled at a fixed period: read the measurements, apply
/// the inputs, halt.
///
/// [`run`](super::run) drives any `Rig` with any
/// [`Controller`](crate::Controller) of matching sizes. The lab's two-cart
/// rig on the PC104 card is [`lab::MassSpringRig`](crate::lab::MassSpringRig)
/// (`M = 1` volt, `P = 4`: `[x1, v1, x2, v2]`); `&mut R` is a rig for any
/// rig `R`.
///
/// # Examples
///
/// A rig written outside the crate: a heater whose temperature rises with
/// the power applied.
///
/// ```
/// use ctrlab::hw::{Rig, RigError};
/// use ctrlab::nalgebra::{SVector, vector};
///
/// struct Heater { temperature: f64, power: f64 }
/// impl Rig<1, 1> for Heater {
///     fn read(&mut self) -> Result<SVector<f64, 1>, RigError> {
///         self.temperature += 0.1 * self.power; // one period of heating
///         Ok(vector![self.temperature])
///     }
///     fn apply(&mut self, u: &SVector<f64, 1>) -> Result<SVector<f64, 1>, RigError> {
///         self.power = u[0].clamp(0.0, 100.0);
///         Ok(vector![self.power])
///     }
///     fn halt(&mut self) -> Result<(), RigError> { self.power = 0.0; Ok(()) }
///     fn period(&self) -> f64 { 1.0 }
/// }
///
/// let mut heater = Heater { temperature: 20.0, power: 0.0 };
/// assert_eq!(heater.apply(&vector![150.0])?, vector![100.0]); // saturated
/// assert_eq!(heater.read()?, vector![30.0]);
/// # Ok::<(), RigError>(())
/// ```
pub trait Rig<const M: usize, const P: usize> {
    /// Samples the measurements now, in the units of
    /// [`schema`](Self::schema) (SI). Called once per period.
    ///
    /// # Errors
    ///
    /// [`RigError::Port`] for port errors, and whatever the rig checks
    /// ([`RigError::Fault`]: travel limits, …), after halting.
    fn read(&mut self) -> Result<SVector<f64, P>, RigError>;

    /// Applies the inputs `u` (saturated and quantised to what the rig can
    /// do) and returns the inputs actually applied, which is what a
    /// recording and the controller's anti-windup should see.
    ///
    /// # Errors
    ///
    /// Port errors; [`PortError::InvalidCommand`](super::PortError::InvalidCommand)
    /// (after halting) for a non-finite input.
    fn apply(&mut self, u: &SVector<f64, M>) -> Result<SVector<f64, M>, RigError>;

    /// Stops the actuators (zero input).
    ///
    /// # Errors
    ///
    /// Port errors.
    fn halt(&mut self) -> Result<(), RigError>;

    /// The sampling period the rig runs at, s: the loop runs at this
    /// period (it is given once, to the rig).
    fn period(&self) -> f64;

    /// Names and units of the inputs and measurements, for the recording.
    /// The default numbers them without units ([`Schema::numbered`]).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::{Clock, Rig};
    /// use ctrlab::lab::SimulatedRig;
    /// let rig = SimulatedRig::default().rig(&Clock::RealTime)?;
    /// assert_eq!(rig.schema().measurements()[2].name, "x2");
    /// # Ok::<(), ctrlab::hw::RigError>(())
    /// ```
    fn schema(&self) -> Schema {
        Schema::numbered_const::<M, P>()
    }

    /// Forgets the previous sample, so the next [`read`](Self::read) starts
    /// any differenced estimate (a speed from counts) afresh instead of
    /// differencing against a sample from long ago. The control loop calls
    /// it at the start of every run. The default does nothing.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::{Clock, Rig, VirtualClock};
    /// use ctrlab::lab::SimulatedRig;
    ///
    /// let clock = VirtualClock::new();
    /// let mut rig = SimulatedRig::default().rig(&Clock::Virtual(clock.clone()))?;
    /// rig.read_state()?;
    /// rig.apply_voltage(6.0)?;
    /// clock.advance(0.5)?; // a long pause, as between two runs
    /// rig.restart();
    /// let x = rig.read_state()?;
    /// assert!(x[2] > 0.0 && x[3] == 0.0); // moved, but no speed from a 0.5 s gap
    /// # Ok::<(), ctrlab::hw::RigError>(())
    /// ```
    fn restart(&mut self) {}

    /// The rig's watchdog timeout, s, if it has a watchdog: the loop halts
    /// before half of it passes without a sample. The default is `None`.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::{Clock, Rig};
    /// use ctrlab::lab::SimulatedRig;
    /// let rig = SimulatedRig::default().rig(&Clock::RealTime)?;
    /// assert_eq!(rig.watchdog_timeout(), Some(0.1));
    /// # Ok::<(), ctrlab::hw::RigError>(())
    /// ```
    fn watchdog_timeout(&self) -> Option<f64> {
        None
    }

    /// Tells the rig's watchdog the controller is alive. The default does
    /// nothing (for rigs without a watchdog, or whose
    /// [`read`](Self::read) already kicks it).
    ///
    /// # Errors
    ///
    /// Port errors.
    fn kick_watchdog(&mut self) -> Result<(), RigError> {
        Ok(())
    }
}

impl<R: Rig<M, P> + ?Sized, const M: usize, const P: usize> Rig<M, P> for &mut R {
    #[inline]
    fn read(&mut self) -> Result<SVector<f64, P>, RigError> {
        (**self).read()
    }
    #[inline]
    fn apply(&mut self, u: &SVector<f64, M>) -> Result<SVector<f64, M>, RigError> {
        (**self).apply(u)
    }
    #[inline]
    fn halt(&mut self) -> Result<(), RigError> {
        (**self).halt()
    }
    #[inline]
    fn period(&self) -> f64 {
        (**self).period()
    }
    fn schema(&self) -> Schema {
        (**self).schema()
    }
    fn watchdog_timeout(&self) -> Option<f64> {
        (**self).watchdog_timeout()
    }
    #[inline]
    fn restart(&mut self) {
        (**self).restart()
    }
    #[inline]
    fn kick_watchdog(&mut self) -> Result<(), RigError> {
        (**self).kick_watchdog()
    }
}
