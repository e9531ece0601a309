//! Real-time scheduling for the control loop on Linux: SCHED_FIFO, locked
//! memory, CPU affinity and absolute-deadline sleeps.
//!
//! This is the crate's one file of `unsafe` code for the scheduler and
//! clock system calls (the parallel port has its own, `ppdev.rs`, and
//! `stop.rs` one block registering the stop signals' handler); each block
//! says why it is sound. On other systems asking for [`RealTime`] is
//! an error and sleeps fall back to `std::thread::sleep`.
#![allow(unsafe_code)]

use std::time::{Duration, Instant};

use super::{RealTimeError, RigError};

/// Opt-in real-time settings for [`run`](super::run)'s thread, as
/// cyclictest uses them: SCHED_FIFO at `priority`, all memory locked
/// (`mlockall`), optionally pinned to one CPU. The loop then sleeps to each
/// absolute deadline with `clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME)`
/// and spins only the last `spin`. Everything is restored when the run
/// ends.
///
/// Needs the right to do so: an `rtprio` limit (`ulimit -r`, or
/// `@realtime - rtprio 99` and `memlock unlimited` in
/// `/etc/security/limits.conf`), `CAP_SYS_NICE` and `CAP_IPC_LOCK`
/// (`setcap cap_sys_nice,cap_ipc_lock+ep` on the binary), or root. Without
/// it [`run`](super::run) refuses to start with a [`RealTimeError`], which
/// says how to grant it.
///
/// A SCHED_FIFO thread that never sleeps starves everything else on its
/// CPU; the loop sleeps every period, and a stock kernel still throttles
/// real-time threads to 95 % of each second (`sched_rt_runtime_us`).
///
/// # Examples
///
/// ```
/// use ctrlab::hw::{LoopConfig, RealTime};
/// let config = LoopConfig { realtime: Some(RealTime { priority: 80, cpu: Some(1), ..RealTime::default() }), ..LoopConfig::default() };
/// assert!(config.realtime.unwrap().lock_memory);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RealTime {
    /// SCHED_FIFO priority, 1–99 (default 80; cyclictest's usual 80–95).
    pub priority: i32,
    /// Lock all current and future memory (default true), so no page fault
    /// stalls a tick.
    pub lock_memory: bool,
    /// Pin the loop's thread to this CPU (default none).
    pub cpu: Option<usize>,
    /// How long before each deadline to stop sleeping and spin (default
    /// 200 µs, as without real-time scheduling: a wake-up from
    /// `clock_nanosleep` is some 10–100 µs late on a stock or virtualised
    /// kernel even under SCHED_FIFO, and the spin absorbs it; 10 % of a
    /// 2 ms period).
    pub spin: Duration,
}

impl Default for RealTime {
    fn default() -> Self {
        Self {
            priority: 80,
            lock_memory: true,
            cpu: None,
            spin: Duration::from_micros(200),
        }
    }
}

/// The CPUs a `cpu_set_t` can name: glibc's `CPU_SETSIZE`.
const CPU_SET_SIZE: usize = 1024;

impl RealTime {
    /// Checks the settings against the loop's `period` (s), before
    /// anything runs: [`run`](super::run) calls it first.
    ///
    /// # Errors
    ///
    /// [`ConfigError::Invalid`](super::ConfigError::Invalid) naming the
    /// field: `priority` outside 1–99, `cpu` at or beyond 1024 (what a
    /// Linux CPU set can name), `spin` longer than the period (the loop
    /// would never sleep).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::RealTime;
    /// use std::time::Duration;
    /// assert!(RealTime::default().validate(0.002).is_ok());
    /// let bad = RealTime { cpu: Some(1024), ..RealTime::default() };
    /// assert_eq!(bad.validate(0.002).unwrap_err().key(), "cpu");
    /// let bad = RealTime { spin: Duration::MAX, ..RealTime::default() };
    /// assert_eq!(bad.validate(0.002).unwrap_err().key(), "spin");
    /// ```
    pub fn validate(&self, period: f64) -> Result<(), super::ConfigError> {
        use super::ConfigError;
        if !(1..=99).contains(&self.priority) {
            return Err(ConfigError::invalid(
                "priority",
                f64::from(self.priority),
                "SCHED_FIFO priority must be within 1–99",
            ));
        }
        if let Some(cpu) = self.cpu
            && cpu >= CPU_SET_SIZE
        {
            return Err(ConfigError::invalid(
                "cpu",
                cpu as f64,
                "must be below 1024, the CPUs a Linux CPU set can name",
            ));
        }
        // Compared in seconds: Duration::MAX is finite as f64 (1.8e19 s).
        if self.spin.as_secs_f64() > period {
            return Err(ConfigError::invalid(
                "spin",
                self.spin.as_secs_f64(),
                "must be at most the loop's period (s): the loop would never sleep",
            ));
        }
        Ok(())
    }
}

/// What [`enter`] changed, restored on drop.
#[derive(Debug)]
pub(crate) struct Guard {
    #[cfg(target_os = "linux")]
    policy: libc::c_int,
    #[cfg(target_os = "linux")]
    param: libc::sched_param,
    #[cfg(target_os = "linux")]
    affinity: Option<libc::cpu_set_t>,
    #[cfg(target_os = "linux")]
    locked: bool,
}

/// Applies `rt` to the calling thread; the guard undoes it. `rt` was
/// checked by [`RealTime::validate`] (priority 1–99, Linux's SCHED_FIFO
/// range) before the loop started.
#[cfg(target_os = "linux")]
pub(crate) fn enter(rt: &RealTime) -> Result<Guard, RigError> {
    // SAFETY: sched_getscheduler and sched_getparam only read the calling
    // thread's (pid 0) attributes into a sched_param we own.
    let (policy, param) = unsafe {
        let mut param: libc::sched_param = std::mem::zeroed();
        (libc::sched_getscheduler(0), {
            libc::sched_getparam(0, &mut param);
            param
        })
    };
    let mut guard = Guard {
        policy,
        param,
        affinity: None,
        locked: false,
    };
    if let Some(cpu) = rt.cpu {
        // SAFETY: cpu_set_t is plain data; CPU_ZERO/CPU_SET write within it
        // (CPU_SET only for a cpu within its bit count); sched_[gs]etaffinity
        // read and write exactly size_of::<cpu_set_t>() bytes of sets we own.
        let applied = unsafe {
            let mut old: libc::cpu_set_t = std::mem::zeroed();
            let size = std::mem::size_of::<libc::cpu_set_t>();
            let ok = libc::sched_getaffinity(0, size, &mut old) == 0;
            let mut set: libc::cpu_set_t = std::mem::zeroed();
            libc::CPU_ZERO(&mut set);
            // libc's CPU_SET indexes a fixed array and panics past its end,
            // which cannot unwind out of this thread: check first.
            let fits = cpu < 8 * size;
            if fits {
                libc::CPU_SET(cpu, &mut set);
            }
            if ok && fits && libc::sched_setaffinity(0, size, &set) == 0 {
                Some(old)
            } else {
                None
            }
        };
        match applied {
            Some(old) => guard.affinity = Some(old),
            None => {
                return Err(RealTimeError::Affinity {
                    cpu,
                    source: std::io::Error::last_os_error(),
                }
                .into());
            }
        }
    }
    if rt.lock_memory {
        // SAFETY: mlockall takes flags only.
        if unsafe { libc::mlockall(libc::MCL_CURRENT | libc::MCL_FUTURE) } != 0 {
            return Err(RealTimeError::LockMemory {
                source: std::io::Error::last_os_error(),
            }
            .into());
        }
        guard.locked = true;
    }
    let fifo = libc::sched_param {
        sched_priority: rt.priority,
    };
    // SAFETY: sets the calling thread's policy from a sched_param we own.
    if unsafe { libc::sched_setscheduler(0, libc::SCHED_FIFO, &fifo) } != 0 {
        return Err(RealTimeError::Priority {
            priority: rt.priority,
            source: std::io::Error::last_os_error(),
        }
        .into());
    }
    Ok(guard)
}

#[cfg(not(target_os = "linux"))]
pub(crate) fn enter(_rt: &RealTime) -> Result<Guard, RigError> {
    Err(RealTimeError::Unsupported.into())
}

#[cfg(target_os = "linux")]
impl Drop for Guard {
    fn drop(&mut self) {
        // SAFETY: restores the calling thread's attributes saved in
        // `enter` from values we own; failures leave the (harmless)
        // real-time setting in place, and there is no one to tell.
        unsafe {
            libc::sched_setscheduler(0, self.policy, &self.param);
            if let Some(old) = &self.affinity {
                libc::sched_setaffinity(0, std::mem::size_of::<libc::cpu_set_t>(), old);
            }
            if self.locked {
                libc::munlockall();
            }
        }
    }
}

/// Sleeps until `deadline`, the last `spin` by spinning. On Linux the sleep
/// is `clock_nanosleep` to the absolute deadline on CLOCK_MONOTONIC (the
/// clock `Instant` reads), so a late wake-up does not shift later ticks.
pub(crate) fn sleep_until(deadline: Instant, spin: Duration) {
    let now = Instant::now();
    // checked: a spin as long as Duration::MAX must not overflow the clock.
    if now.checked_add(spin).is_some_and(|wake| deadline > wake) {
        sleep_absolute(deadline - spin, now);
    }
    while Instant::now() < deadline {
        std::hint::spin_loop();
    }
}

#[cfg(target_os = "linux")]
fn sleep_absolute(wake: Instant, now: Instant) {
    // SAFETY: clock_gettime writes one timespec we own.
    let mut ts = unsafe {
        let mut ts: libc::timespec = std::mem::zeroed();
        libc::clock_gettime(libc::CLOCK_MONOTONIC, &mut ts);
        ts
    };
    let ahead = wake.saturating_duration_since(now);
    let nanos = ts.tv_nsec as u64 + u64::from(ahead.subsec_nanos());
    ts.tv_sec += ahead.as_secs() as libc::time_t + (nanos / 1_000_000_000) as libc::time_t;
    ts.tv_nsec = (nanos % 1_000_000_000) as libc::c_long;
    // SAFETY: reads the timespec we own; a null remainder is allowed with
    // TIMER_ABSTIME. Retried on EINTR (a signal), bounded by the deadline.
    for _ in 0..1000 {
        let rc = unsafe {
            libc::clock_nanosleep(
                libc::CLOCK_MONOTONIC,
                libc::TIMER_ABSTIME,
                &ts,
                std::ptr::null_mut(),
            )
        };
        if rc != libc::EINTR {
            break;
        }
    }
}

#[cfg(not(target_os = "linux"))]
fn sleep_absolute(wake: Instant, now: Instant) {
    std::thread::sleep(wake.saturating_duration_since(now));
}
