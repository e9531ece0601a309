//! The identification runs: those that completed and those the rig halted
//! because the input was too big ([`IdentRuns`]).

use super::input_too_big;
use crate::Recording;
use crate::hw::{RigError, RunError};

/// An identification run that completed: its seed (its number in the
/// lab's order, from 1) and recording.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::ident_input::CompletedRun;
/// let run = CompletedRun { seed: 1, recording: ctrlab::Recording::new(ctrlab::lab::schema()) };
/// assert_eq!(run.seed, 1);
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct CompletedRun {
    /// The run's seed (its number, from 1).
    pub seed: u64,
    /// Its recording.
    pub recording: Recording,
}

/// An identification run the rig halted because its input was too big
/// ([`input_too_big`]: a travel limit, the drive saturated too long): its
/// seed, the loop's error and what it recorded up to the fault.
///
/// # Examples
///
/// ```
/// use ctrlab::hw::{LoopFault, RigError};
/// use ctrlab::lab::ident_input::HaltedRun;
/// let run = HaltedRun {
///     seed: 3,
///     error: RigError::Fault(LoopFault::TravelLimit { axis: 2, position: 0.0501, limit: 0.05 }),
///     recording: ctrlab::Recording::new(ctrlab::lab::schema()),
/// };
/// assert!(run.error.to_string().contains("beyond its travel limit"));
/// ```
#[derive(Debug)]
pub struct HaltedRun {
    /// The run's seed (its number, from 1).
    pub seed: u64,
    /// Why the rig halted it (a [`LoopFault::TravelLimit`] names the cart's
    /// axis, its position and the limit, m).
    ///
    /// [`LoopFault::TravelLimit`]: crate::hw::LoopFault::TravelLimit
    pub error: RigError,
    /// Every sample before the fault.
    pub recording: Recording,
}

/// The identification runs on a rig: those that completed, which the
/// identification averages, and those the rig halted because the input was
/// too big for it ([`input_too_big`]), which it leaves out. Such a run
/// does not stop the others; any other fault does.
///
/// # Examples
///
/// ```
/// use ctrlab::hw::{LoopFault, RigError, RunError, LoopStats};
/// use ctrlab::lab::ident_input::IdentRuns;
/// use ctrlab::Recording;
/// let runs = IdentRuns::collect(1..=3, |seed| {
///     let recording = Recording::new(ctrlab::lab::schema());
///     Ok::<_, Box<dyn std::error::Error>>(if seed == 2 {
///         let error = RigError::Fault(LoopFault::TravelLimit { axis: 2, position: 0.051, limit: 0.05 });
///         Err(Box::new(RunError { error, recording, last_measurement: None, stats: LoopStats::default() }))
///     } else {
///         Ok(recording)
///     })
/// })?;
/// assert_eq!(runs.completed.iter().map(|r| r.seed).collect::<Vec<_>>(), [1, 3]);
/// assert_eq!(runs.halted[0].seed, 2);
/// assert!(runs.enough().is_ok());
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Default)]
pub struct IdentRuns {
    /// The runs that completed, in order.
    pub completed: Vec<CompletedRun>,
    /// The runs the rig halted, in order.
    pub halted: Vec<HaltedRun>,
}

impl IdentRuns {
    /// Runs `run` for each of `seeds` (bounded by the iterator) and sorts
    /// the outcomes: a run the rig halted because the input was too big
    /// for it ([`input_too_big`]: a travel limit, the drive saturated for
    /// too long) goes to [`halted`](Self::halted), with what it recorded,
    /// and the next run goes on; a run halted by any other fault stops
    /// here ([`RunFault`]: a bus fault, a dead encoder or a motor not
    /// responding says the rig is not fit to measure, and a gap, Ctrl-C or
    /// a panic that the runs should stop); so does `run`'s outer error (a
    /// set-up failure).
    ///
    /// # Errors
    ///
    /// [`RunFault`] (into `E`) for a run halted by a fault other than the
    /// input's size; `run`'s outer error.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::{LoopFault, LoopStats, RigError, RunError};
    /// use ctrlab::lab::ident_input::{IdentRuns, RunFault};
    /// use ctrlab::Recording;
    /// let runs = IdentRuns::collect(1..=2, |_| Ok::<_, RunFault>(Ok(Recording::new(ctrlab::lab::schema()))))?;
    /// assert_eq!((runs.completed.len(), runs.halted.len()), (2, 0));
    /// // A dead encoder in run 2: run 3 is not made.
    /// let mut made = Vec::new();
    /// let err = IdentRuns::collect(1..=3, |seed| {
    ///     made.push(seed);
    ///     let recording = Recording::new(ctrlab::lab::schema());
    ///     Ok::<_, RunFault>(if seed == 2 {
    ///         let error = RigError::Fault(LoopFault::NotResponding { volts: 6.0, seconds: 0.5, counts: 3 });
    ///         Err(Box::new(RunError { error, recording, last_measurement: None, stats: LoopStats::default() }))
    ///     } else {
    ///         Ok(recording)
    ///     })
    /// })
    /// .unwrap_err();
    /// assert_eq!((err.seed, made), (2, vec![1, 2]));
    /// # Ok::<(), RunFault>(())
    /// ```
    pub fn collect<E: From<RunFault>>(
        seeds: impl IntoIterator<Item = u64>,
        mut run: impl FnMut(u64) -> Result<Result<Recording, Box<RunError>>, E>,
    ) -> Result<Self, E> {
        let mut runs = Self::default();
        for seed in seeds {
            match run(seed)? {
                Ok(recording) => runs.completed.push(CompletedRun { seed, recording }),
                Err(e) => {
                    let RunError {
                        error, recording, ..
                    } = *e;
                    if !input_too_big(&error) {
                        return Err(RunFault {
                            seed,
                            error,
                            recording,
                        }
                        .into());
                    }
                    runs.halted.push(HaltedRun {
                        seed,
                        error,
                        recording,
                    });
                }
            }
        }
        Ok(runs)
    }

    /// The completed runs' recordings, in order, for
    /// [`summarize`](crate::lab::ident::summarize).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::ident_input::IdentRuns;
    /// assert_eq!(IdentRuns::default().recordings().count(), 0);
    /// ```
    pub fn recordings(&self) -> impl Iterator<Item = &Recording> {
        self.completed.iter().map(|r| &r.recording)
    }

    /// Whether enough runs completed for the averages (and a fresh run
    /// for the validation): at least two.
    ///
    /// # Errors
    ///
    /// [`TooFewRuns`], naming each halted run and why.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::ident_input::IdentRuns;
    /// let err = IdentRuns::default().enough().unwrap_err();
    /// assert_eq!((err.completed, err.total), (0, 0));
    /// assert!(err.to_string().starts_with("only 0 of 0 identification runs completed"), "{err}");
    /// ```
    pub fn enough(&self) -> Result<(), TooFewRuns> {
        if self.completed.len() >= 2 {
            return Ok(());
        }
        Err(TooFewRuns {
            completed: self.completed.len(),
            total: self.completed.len() + self.halted.len(),
            halted: self
                .halted
                .iter()
                .map(|h| format!("run {}: {}", h.seed, h.error))
                .collect(),
        })
    }
}

/// Fewer than two identification runs completed: the averages (and the
/// validation on a fresh run) need two.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::ident_input::TooFewRuns;
/// let e = TooFewRuns { completed: 1, total: 5, halted: vec!["run 2: beyond its travel limit".into()] };
/// assert!(e.to_string().contains("only 1 of 5") && e.to_string().contains("run 2: beyond"));
/// ```
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error(
    "only {completed} of {total} identification runs completed (halted: {}); the averages and the validation on a fresh run need at least two: lower the amplitude",
    halted.join("; ")
)]
pub struct TooFewRuns {
    /// Runs that completed.
    pub completed: usize,
    /// Runs tried.
    pub total: usize,
    /// Each halted run and why, as `run 3: <the loop's error>`.
    pub halted: Vec<String>,
}

/// An identification run halted by a fault other than the input's size
/// (see [`input_too_big`]): a bus fault, a dead encoder, a motor not
/// responding, a timing gap, Ctrl-C, a panic, a port error. The runs stop
/// at it: a rig that is not fit to measure gives no run worth averaging.
///
/// # Examples
///
/// ```
/// use ctrlab::hw::{LoopFault, RigError};
/// use ctrlab::lab::ident_input::RunFault;
/// let e = RunFault {
///     seed: 2,
///     error: RigError::Fault(LoopFault::Interrupted { at: 1.5 }),
///     recording: ctrlab::Recording::new(ctrlab::lab::schema()),
/// };
/// assert!(e.to_string().starts_with("identification run 2 was halted"), "{e}");
/// ```
#[derive(Debug, thiserror::Error)]
#[error(
    "identification run {seed} was halted by a fault a smaller input would not avoid, so the runs stop here: {error}"
)]
pub struct RunFault {
    /// The run's seed (its number, from 1).
    pub seed: u64,
    /// The loop's error.
    pub error: RigError,
    /// Every sample before the fault.
    pub recording: Recording,
}
