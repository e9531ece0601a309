//! [`StopSignal`]: a request to stop a running loop, from Ctrl-C, SIGTERM,
//! a closed terminal (SIGHUP), Ctrl-\\ (SIGQUIT), Ctrl-Z (SIGTSTP) or code.

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex, PoisonError};

/// The process's interrupt flag, once [`StopSignal::on_interrupt`] has
/// registered the handlers that raise it.
static INTERRUPT: Mutex<Option<Arc<AtomicBool>>> = Mutex::new(None);

/// How many control loops (or probes) are driving a rig now: a second
/// signal ends the process only when none is.
static RUNNING: AtomicUsize = AtomicUsize::new(0);

/// A control loop driving a rig, from [`enter`](Self::enter) to its drop:
/// while one lives, a second interrupt does not end the process (see
/// [`StopSignal::on_interrupt`]).
#[derive(Debug)]
pub(crate) struct Running(());

impl Running {
    /// Counts a loop in, until the guard drops (panics included).
    pub(crate) fn enter() -> Self {
        RUNNING.fetch_add(1, Ordering::SeqCst);
        Self(())
    }
}

impl Drop for Running {
    fn drop(&mut self) {
        RUNNING.fetch_sub(1, Ordering::SeqCst);
    }
}

/// What a handler does with a signal: raises `flag` and, when it was
/// already raised and no loop is running, says the process should end.
/// Only atomics: safe in a signal handler.
fn on_signal(flag: &AtomicBool) -> bool {
    let again = flag.swap(true, Ordering::SeqCst);
    again && RUNNING.load(Ordering::SeqCst) == 0
}

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

    /// The process's interrupt flag, raised by the signals that ask a
    /// program to stop: on Unix SIGINT (Ctrl-C), SIGTERM (`kill`), SIGHUP
    /// (the terminal closed, an SSH session dropped), SIGQUIT (Ctrl-\\)
    /// and SIGTSTP (Ctrl-Z); elsewhere Ctrl-C, Ctrl-Break and the console
    /// closing (through the `ctrlc` crate).
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
    /// card's watchdog.)
    ///
    /// The handlers are registered once, by the first call; every call
    /// returns a handle on the same process-wide flag (so
    /// [`clear`](Self::clear) on one clears it for all).
    ///
    /// # A second signal
    ///
    /// The first signal asks to stop gracefully. A second one while the
    /// flag is still raised (nobody has [`clear`](Self::clear)ed it) and no
    /// control loop is running ([`run`](super::run), or a
    /// [`Probe`](super::probe::Probe) driving the card) ends the process at once,
    /// with exit status 128 + the signal's number (130 for SIGINT), as a
    /// shell reports a process a signal killed: a program busy between
    /// runs (analysing, writing a report) does not make its user wait, or
    /// reach for `kill -9`. Nothing is written or flushed then, and no
    /// destructor runs (the motor is already halted: a run halts the rig
    /// when it ends). While a loop runs, a second signal only raises the
    /// flag again: the loop halts the rig at its next tick, and ending the
    /// process before that could leave the motor at its last duty.
    ///
    /// # Errors
    ///
    /// The operating system's error, saying which signal failed, when a
    /// handler cannot be registered (on non-Unix platforms, also when
    /// the `ctrlc` crate's handler cannot be set); none is left registered
    /// then, and the next call tries again.
    ///
    /// # Examples
    ///
    /// ```no_run
    /// use ctrlab::hw::StopSignal;
    /// let stop = StopSignal::on_interrupt()?;
    /// assert!(!stop.is_requested()); // until Ctrl-C, Ctrl-Z, a closed terminal, …
    /// assert_eq!(StopSignal::on_interrupt()?, stop); // registered once: one flag
    /// // … pass `Some(stop.clone())` in `LoopConfig::stop`; Ctrl-C now halts the rig.
    /// # Ok::<(), std::io::Error>(())
    /// ```
    pub fn on_interrupt() -> Result<Self, std::io::Error> {
        let mut registered = INTERRUPT.lock().unwrap_or_else(PoisonError::into_inner);
        if let Some(flag) = registered.as_ref() {
            return Ok(Self {
                flag: Arc::clone(flag),
            });
        }
        let flag = Arc::new(AtomicBool::new(false));
        platform::register(&flag)?;
        *registered = Some(Arc::clone(&flag));
        Ok(Self { flag })
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

    /// Raises `flag` on each of [`SIGNALS`], and ends the process on a
    /// second one outside a loop ([`super::on_signal`]); on a failure,
    /// unregisters those already registered.
    pub(super) fn register(flag: &Arc<AtomicBool>) -> Result<(), std::io::Error> {
        let mut ids = Vec::with_capacity(SIGNALS.len());
        for (signal, name) in SIGNALS {
            let flag = Arc::clone(flag);
            let handler = move || {
                if super::on_signal(&flag) {
                    // 128 + the signal, as a shell reports a process the
                    // signal killed; `_exit`, safe in a handler.
                    signal_hook::low_level::exit(128 + signal);
                }
            };
            // SAFETY: the handler only touches atomics (`on_signal`) and
            // calls `_exit` (signal_hook's `exit`), all async-signal-safe;
            // it allocates nothing and takes no lock.
            #[allow(unsafe_code)]
            let registered = unsafe { signal_hook::low_level::register(signal, handler) };
            match registered {
                Ok(id) => ids.push(id),
                Err(source) => {
                    for id in ids {
                        signal_hook::low_level::unregister(id);
                    }
                    return Err(std::io::Error::new(
                        source.kind(),
                        format!("registering a stop handler for {name} failed: {source}"),
                    ));
                }
            }
        }
        Ok(())
    }
}

/// Ctrl-C, Ctrl-Break and the console closing, through the `ctrlc` crate,
/// whose one handler (it can be set only once per process, and
/// [`StopSignal::on_interrupt`] sets it once) raises the flag.
#[cfg(not(unix))]
mod platform {
    use std::sync::Arc;
    use std::sync::atomic::AtomicBool;

    /// Sets the handler raising `flag` (and ending the process on a second
    /// Ctrl-C outside a loop, [`super::on_signal`]).
    pub(super) fn register(flag: &Arc<AtomicBool>) -> Result<(), std::io::Error> {
        let flag = Arc::clone(flag);
        // The handler runs on ctrlc's own thread, not in a signal context.
        ctrlc::set_handler(move || {
            if super::on_signal(&flag) {
                // 128 + SIGINT, as on Unix.
                std::process::exit(130);
            }
        })
        .map_err(|source| {
            std::io::Error::other(format!(
                "registering a stop handler for Ctrl-C failed: {source}"
            ))
        })
    }
}
