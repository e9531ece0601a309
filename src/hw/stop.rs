//! [`StopSignal`]: a request to stop a running loop, from Ctrl-C, SIGTERM,
//! a closed terminal (SIGHUP), Ctrl-\\ (SIGQUIT), Ctrl-Z (SIGTSTP) or code.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

/// A shared flag that stops [`run`](super::run) at its next tick: the rig is
/// halted and the run returns [`LoopFault::Interrupted`](super::LoopFault::Interrupted) with everything
/// recorded so far. Clones share the flag.
///
/// [`on_interrupt`](Self::on_interrupt) sets it on SIGINT (Ctrl-C),
/// SIGTERM, SIGHUP (the terminal closed), SIGQUIT (Ctrl-\\) and SIGTSTP
/// (Ctrl-Z), so stopping a lab run from the terminal in any of these ways
/// halts the motor and keeps the data, instead of killing the process (or
/// freezing it) with the PWM at its last duty.
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

    /// A flag raised by the signals that ask a program to stop: on Unix
    /// SIGINT (Ctrl-C), SIGTERM (`kill`), SIGHUP (the terminal closed, an
    /// SSH session dropped), SIGQUIT (Ctrl-\\) and SIGTSTP (Ctrl-Z); elsewhere
    /// Ctrl-C, Ctrl-Break and the console closing (through the `ctrlc`
    /// crate).
    ///
    /// Registering replaces those signals' default actions for the whole
    /// process, for as long as it runs: the loop stops at its next tick,
    /// halts the rig and returns its recording, and the caller decides what
    /// to do next (write the data, exit). That is intended for each of
    /// them, SIGTSTP included: Ctrl-Z no longer suspends the process, which
    /// would freeze the loop with the motor at its last duty (the card's
    /// watchdog, if it has one, is all that would stop it), but stops the
    /// run cleanly; and SIGQUIT no longer dumps core. (SIGKILL and SIGSTOP
    /// cannot be caught: `kill -9` and `kill -STOP` leave the motor to the
    /// card's watchdog.) Each call registers a new flag; every registered
    /// flag is raised by each of these signals.
    ///
    /// # Errors
    ///
    /// The operating system's error, saying which signal failed, when a
    /// handler cannot be registered (on non-Unix platforms, also when
    /// the `ctrlc` crate's handler cannot be set).
    ///
    /// # Examples
    ///
    /// ```no_run
    /// use ctrlab::hw::StopSignal;
    /// let stop = StopSignal::on_interrupt()?;
    /// assert!(!stop.is_requested()); // until Ctrl-C, Ctrl-Z, a closed terminal, …
    /// // … pass `Some(stop.clone())` in `LoopConfig::stop`; Ctrl-C now halts the rig.
    /// # Ok::<(), std::io::Error>(())
    /// ```
    pub fn on_interrupt() -> Result<Self, std::io::Error> {
        let stop = Self::new();
        platform::register(&stop.flag)?;
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

/// The signals [`StopSignal::on_interrupt`] registers on Unix, with their
/// names for error messages.
#[cfg(unix)]
mod platform {
    use std::sync::Arc;
    use std::sync::atomic::AtomicBool;

    use signal_hook::consts::{SIGHUP, SIGINT, SIGQUIT, SIGTERM, SIGTSTP};

    /// Every signal that asks the program to stop, by name.
    pub(super) const SIGNALS: [(i32, &str); 5] = [
        (SIGINT, "SIGINT"),
        (SIGTERM, "SIGTERM"),
        (SIGHUP, "SIGHUP"),
        (SIGQUIT, "SIGQUIT"),
        (SIGTSTP, "SIGTSTP"),
    ];

    /// Raises `flag` on each of [`SIGNALS`].
    pub(super) fn register(flag: &Arc<AtomicBool>) -> Result<(), std::io::Error> {
        for (signal, name) in SIGNALS {
            signal_hook::flag::register(signal, Arc::clone(flag)).map_err(|source| {
                std::io::Error::new(
                    source.kind(),
                    format!("registering a stop handler for {name} failed: {source}"),
                )
            })?;
        }
        Ok(())
    }
}

/// Ctrl-C, Ctrl-Break and the console closing, through the `ctrlc` crate,
/// whose one handler (it can be set only once per process) raises every
/// flag registered.
#[cfg(not(unix))]
mod platform {
    use std::sync::atomic::{AtomicBool, Ordering};
    use std::sync::{Arc, Mutex, PoisonError};

    /// The flags to raise; empty until the first registration.
    static FLAGS: Mutex<Vec<Arc<AtomicBool>>> = Mutex::new(Vec::new());

    /// Adds `flag` to those the handler raises, setting the handler on the
    /// first call.
    pub(super) fn register(flag: &Arc<AtomicBool>) -> Result<(), std::io::Error> {
        let mut flags = FLAGS.lock().unwrap_or_else(PoisonError::into_inner);
        if flags.is_empty() {
            // The handler runs on ctrlc's own thread, not in a signal
            // context: it may lock.
            ctrlc::set_handler(|| {
                let flags = FLAGS.lock().unwrap_or_else(PoisonError::into_inner);
                for flag in flags.iter() {
                    flag.store(true, Ordering::SeqCst);
                }
            })
            .map_err(|source| {
                std::io::Error::other(format!(
                    "registering a stop handler for Ctrl-C failed: {source}"
                ))
            })?;
        }
        flags.push(Arc::clone(flag));
        Ok(())
    }
}
