//! [`StopSignal`]: a request to stop a running loop, from Ctrl-C, SIGTERM
//! or code.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

/// A shared flag that stops [`run`](super::run) at its next tick: the rig is
/// halted and the run returns [`LoopFault::Interrupted`](super::LoopFault::Interrupted) with everything
/// recorded so far. Clones share the flag.
///
/// [`on_interrupt`](Self::on_interrupt) sets it on SIGINT (Ctrl-C) and
/// SIGTERM, so stopping a lab run from the terminal halts the motor and
/// keeps the data instead of killing the process with the PWM at its last
/// duty.
///
/// # Examples
///
/// ```
/// use ctrlab::hw::{Clock, LoopConfig, LoopFaultKind, StopSignal, VirtualClock, run};
/// use ctrlab::{OpenLoop, lab::SimulatedRig, nalgebra::vector};
///
/// let stop = StopSignal::new();
/// let clock = VirtualClock::new();
/// let rig = SimulatedRig::default().rig(&Clock::Virtual(clock.clone()))?;
/// let config = LoopConfig { stop: Some(stop.clone()), ..LoopConfig::default() };
/// let trigger = stop.clone();
/// // The reference asks to stop after 0.1 s, as a user's Ctrl-C would.
/// let err = run(rig, OpenLoop, move |t| {
///     if t >= 0.1 { trigger.request() }
///     vector![1.0]
/// }, &Clock::Virtual(clock), &config).unwrap_err();
/// assert_eq!(err.error.kind(), LoopFaultKind::Interrupted);
/// assert_eq!(err.recording.len(), 51); // 0 … 0.1 s, kept
/// # Ok::<(), ctrlab::hw::RigError>(())
/// ```
#[derive(Debug, Clone, Default)]
pub struct StopSignal {
    flag: Arc<AtomicBool>,
}

impl PartialEq for StopSignal {
    /// Two handles are equal when they share one flag.
    fn eq(&self, other: &Self) -> bool {
        Arc::ptr_eq(&self.flag, &other.flag)
    }
}

impl StopSignal {
    /// A flag nobody has raised yet.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::hw::StopSignal;
    /// assert!(!StopSignal::new().is_requested());
    /// ```
    pub fn new() -> Self {
        Self::default()
    }

    /// A flag raised by SIGINT (Ctrl-C) and SIGTERM. Registering replaces
    /// those signals' default action (ending the process) for the whole
    /// process: the loop stops, halts the rig and returns its recording,
    /// and the caller decides what to do next (write the data, exit).
    ///
    /// # Errors
    ///
    /// The operating system's error, saying what failed, when the handlers
    /// cannot be registered (or on a platform without Unix signals).
    ///
    /// # Examples
    ///
    /// ```no_run
    /// use ctrlab::hw::StopSignal;
    /// let stop = StopSignal::on_interrupt()?;
    /// assert!(!stop.is_requested()); // until Ctrl-C
    /// // … pass `Some(stop.clone())` in `LoopConfig::stop`; Ctrl-C now halts the rig.
    /// # Ok::<(), std::io::Error>(())
    /// ```
    pub fn on_interrupt() -> Result<Self, std::io::Error> {
        let stop = Self::new();
        let refused = |source: std::io::Error| {
            std::io::Error::new(
                source.kind(),
                format!("register SIGINT/SIGTERM on signal handler failed: {source}"),
            )
        };
        #[cfg(unix)]
        for signal in [signal_hook::consts::SIGINT, signal_hook::consts::SIGTERM] {
            signal_hook::flag::register(signal, Arc::clone(&stop.flag)).map_err(refused)?;
        }
        #[cfg(not(unix))]
        return Err(refused(std::io::Error::other(
            "no Unix signals on this platform",
        )));
        #[cfg(unix)]
        Ok(stop)
    }

    /// Asks the loop to stop at its next tick.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::hw::StopSignal;
    /// let s = StopSignal::new();
    /// s.clone().request();
    /// assert!(s.is_requested());
    /// ```
    pub fn request(&self) {
        self.flag.store(true, Ordering::SeqCst);
    }

    /// True once a stop was requested (or a registered signal arrived).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::hw::StopSignal;
    /// let s = StopSignal::new();
    /// assert!(!s.is_requested());
    /// ```
    pub fn is_requested(&self) -> bool {
        self.flag.load(Ordering::SeqCst)
    }

    /// Lowers the flag again, for the next run.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::hw::StopSignal;
    /// let s = StopSignal::new();
    /// s.request();
    /// s.clear();
    /// assert!(!s.is_requested());
    /// ```
    pub fn clear(&self) {
        self.flag.store(false, Ordering::SeqCst);
    }
}
