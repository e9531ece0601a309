//! [`RealTimeError`]: real-time scheduling was asked for and not granted.

/// The category of a [`RealTimeError`].
///
/// `#[non_exhaustive]`: match with a wildcard arm.
///
/// # Examples
///
/// ```
/// use ctrlab::hw::{RealTimeError, RealTimeErrorKind};
/// assert_eq!(RealTimeError::Unsupported.kind(), RealTimeErrorKind::Unsupported);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum RealTimeErrorKind {
    /// The loop's thread could not be pinned to the CPU asked for.
    Affinity,
    /// Memory could not be locked (`mlockall`).
    LockMemory,
    /// SCHED_FIFO at the priority asked for was refused.
    Priority,
    /// This platform has no real-time scheduling the crate can set.
    Unsupported,
}

/// Real-time scheduling ([`RealTime`](crate::hw::RealTime)) was asked for and
/// could not be set up; [`run`](crate::hw::run) then runs nothing. Each message
/// says how to grant what was refused.
///
/// `#[non_exhaustive]`: match with a wildcard arm, or on [`kind`](Self::kind).
///
/// # Examples
///
/// ```
/// use ctrlab::hw::{RealTimeError, RealTimeErrorKind};
/// let e = RealTimeError::Priority {
///     priority: 80,
///     source: std::io::Error::from_raw_os_error(1),
/// };
/// assert_eq!(e.kind(), RealTimeErrorKind::Priority);
/// assert!(e.to_string().starts_with("cannot set SCHED_FIFO priority 80: "));
/// assert!(e.to_string().contains("rtprio"));
/// ```
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum RealTimeError {
    /// Pinning the loop's thread to a CPU was refused.
    #[error("cannot pin the loop to CPU {cpu}: {source}. {}", HINT_CPU)]
    Affinity {
        /// The CPU asked for.
        cpu: usize,
        /// The operating system's answer.
        #[source]
        source: std::io::Error,
    },
    /// Locking memory was refused.
    #[error("cannot lock memory (mlockall): {source}. {}", HINT_MEMORY)]
    LockMemory {
        /// The operating system's answer.
        #[source]
        source: std::io::Error,
    },
    /// SCHED_FIFO at the priority asked for was refused.
    #[error(
        "cannot set SCHED_FIFO priority {priority}: {source}. {}",
        HINT_PRIORITY
    )]
    Priority {
        /// The priority asked for.
        priority: i32,
        /// The operating system's answer.
        #[source]
        source: std::io::Error,
    },
    /// Real-time scheduling is only implemented on Linux.
    #[error("cannot set real-time scheduling: only implemented on Linux. Run without `realtime`")]
    Unsupported,
}

impl RealTimeError {
    /// The category of this error.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::{RealTimeError, RealTimeErrorKind};
    /// let e = RealTimeError::LockMemory { source: std::io::Error::from_raw_os_error(12) };
    /// assert_eq!(e.kind(), RealTimeErrorKind::LockMemory);
    /// ```
    pub fn kind(&self) -> RealTimeErrorKind {
        match self {
            RealTimeError::Affinity { .. } => RealTimeErrorKind::Affinity,
            RealTimeError::LockMemory { .. } => RealTimeErrorKind::LockMemory,
            RealTimeError::Priority { .. } => RealTimeErrorKind::Priority,
            RealTimeError::Unsupported => RealTimeErrorKind::Unsupported,
        }
    }
}

// What to do when each request is refused, appended to the message.
const HINT_PRIORITY: &str = "Grant real-time priority: raise the rtprio limit (`ulimit -r 99`, or `@realtime - rtprio 99` in /etc/security/limits.conf and add the user to group realtime), give the binary CAP_SYS_NICE (`sudo setcap cap_sys_nice,cap_ipc_lock+ep <binary>`), or run as root";
const HINT_MEMORY: &str = "Grant memory locking: raise the memlock limit (`ulimit -l unlimited`, or `@realtime - memlock unlimited` in /etc/security/limits.conf), give the binary CAP_IPC_LOCK, or set `lock_memory: false`";
const HINT_CPU: &str = "Pick a CPU this process may run on (see `nproc` and `taskset -p $$`)";
