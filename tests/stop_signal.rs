//! `StopSignal::on_interrupt`: the handlers registered once (every call
//! the same flag), one signal halts a run, and a second signal while no
//! loop runs ends the process (checked in a child process: this test
//! binary run again, on one test).

#![cfg(all(unix, feature = "lab"))]

mod common;

use std::process::Command;

use common::loop_config;
use ctrlab::OpenLoop;
use ctrlab::hw::{Clock, LoopConfig, LoopFault, RigError, StopSignal, VirtualClock, run};
use ctrlab::lab::SimulatedRig;
use ctrlab::nalgebra::vector;
use signal_hook::consts::SIGINT;

/// Set in the child process: run the second-signal scenario.
const CHILD: &str = "CTRLAB_STOP_SIGNAL_CHILD";

/// A 1 s open-loop run at 3 V that raises `signal` `times` times at
/// 0.1 s, stopping at `stop`: the run's error.
fn run_raising(stop: &StopSignal, times: usize) -> RigError {
    let clock = VirtualClock::new();
    let rig = SimulatedRig::default()
        .rig(&Clock::Virtual(clock.clone()))
        .unwrap();
    let config = LoopConfig {
        stop: Some(stop.clone()),
        ..loop_config(1.0)
    };
    let mut raised = false;
    let err = run(
        rig,
        OpenLoop,
        |t| {
            if t >= 0.1 - 1e-9 && !raised {
                raised = true;
                for _ in 0..times {
                    // To this thread: the handler has run when raise returns.
                    signal_hook::low_level::raise(SIGINT).unwrap();
                }
            }
            vector![3.0]
        },
        &Clock::Virtual(clock),
        &config,
    )
    .expect_err("the signal stops the run");
    err.error
}

#[test]
fn registered_once_one_signal_halts_and_a_second_in_a_run_does_not_end_the_process() {
    if std::env::var_os(CHILD).is_some() {
        return; // the child runs only the other test
    }
    // Registering replaces SIGINT's default action for the whole binary;
    // this test and the child's are the only ones that raise it.
    let first = StopSignal::on_interrupt().expect("registered");
    let second = StopSignal::on_interrupt().expect("registered again: a no-op");
    assert_eq!(first, second, "one process-wide flag");
    first.clear();
    // One SIGINT: the run halts, through either handle.
    let error = run_raising(&second, 1);
    assert!(
        matches!(error, RigError::Fault(LoopFault::Interrupted { .. })),
        "{error}"
    );
    assert!(first.is_requested());
    // Two in a run: still only the flag (the loop halts the rig); this
    // process goes on to the assertion.
    first.clear();
    let error = run_raising(&first, 2);
    assert!(
        matches!(error, RigError::Fault(LoopFault::Interrupted { .. })),
        "{error}"
    );
    first.clear();
}

#[test]
fn a_second_signal_outside_a_run_ends_the_process_with_130() {
    if std::env::var_os(CHILD).is_some() {
        // The child: the first SIGINT outside a run only raises the flag
        // (as while lab5 analyses); the second ends the process.
        let stop = StopSignal::on_interrupt().unwrap();
        signal_hook::low_level::raise(SIGINT).unwrap();
        assert!(stop.is_requested(), "the first only raises the flag");
        println!("first signal survived");
        signal_hook::low_level::raise(SIGINT).unwrap();
        // Not reached: exit status 130, not a test failure's 101.
        std::process::exit(3);
    }
    let out = Command::new(std::env::current_exe().unwrap())
        .args([
            "--exact",
            "a_second_signal_outside_a_run_ends_the_process_with_130",
            "--nocapture",
            "--test-threads=1",
        ])
        .env(CHILD, "1")
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("first signal survived"), "{stdout}");
    assert_eq!(out.status.code(), Some(130), "{out:?}");
}
