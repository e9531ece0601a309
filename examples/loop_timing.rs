//! Measures the control loop's timing on this machine, cyclictest-style:
//! the lab's cart-2 controller at T = 2 ms on the simulated card, on the
//! wall clock, then a summary of the lateness (p50, p99, p99.9, max),
//! overruns and skipped ticks.
//!
//! ```text
//! cargo run --release --example loop_timing                      # 10 s, normal scheduling
//! cargo run --release --example loop_timing -- 60                # 60 s
//! cargo run --release --example loop_timing -- 10 --rt-priority 80 --cpu 1
//! cargo run --release --example loop_timing -- 30 --scope         # drawn live
//! ```
//!
//! `--rt-priority N` runs the loop with SCHED_FIFO priority N and all memory
//! locked (needs an rtprio limit, CAP_SYS_NICE or root: the error says how
//! to grant it); `--cpu K` pins it to CPU K. A stock kernel is not a
//! real-time kernel: without SCHED_FIFO expect a p99 of tens of µs and
//! millisecond outliers under load. The numbers say how much of the 2 ms
//! period is left on a given PC.
//!
//! `--scope` draws the run live with the experiment's scope
//! (examples/experiment/scope.rs, the same code), to measure what drawing
//! costs the loop: q, Esc or Ctrl-C stop the run early, and the summary is
//! printed once the terminal is restored. A run stopped early exits with
//! status 1, as any run that does not complete.

#[path = "experiment/scope.rs"]
mod scope;

use std::process::ExitCode;
use std::rc::Rc;

use ctrlab::Controller;
use ctrlab::hw::{Clock, EppPort, LoopConfig, LoopStats, RealTime, RunError, StopSignal, run};
use ctrlab::lab::tables::Experiment;
use ctrlab::lab::{Cart, LabGains, MassSpringRig, SimulatedRig};
use ctrlab::nalgebra::{SVector, vector};

/// The loop measured: the lab's cart-2 law, to 30 mm.
const KF: [f64; 4] = [0.0, 0.0, 10.0, 0.05];
const SETPOINT_MM: f64 = 30.0;

fn main() -> ExitCode {
    match loop_timing() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("loop_timing: {e}");
            ExitCode::FAILURE
        }
    }
}

fn loop_timing() -> Result<(), Box<dyn std::error::Error>> {
    let mut seconds = 10.0;
    let mut realtime: Option<RealTime> = None;
    let mut scope = false;
    let mut args = std::env::args().skip(1);
    while let Some(arg) = args.next() {
        match arg.as_str() {
            "--rt-priority" => {
                let n = args.next().ok_or("--rt-priority needs a priority 1-99")?;
                realtime = Some(RealTime {
                    priority: n.parse().map_err(|_| format!("not a priority: `{n}`"))?,
                    ..realtime.unwrap_or_default()
                });
            }
            "--cpu" => {
                let n = args.next().ok_or("--cpu needs a CPU number")?;
                let cpu = n.parse().map_err(|_| format!("not a CPU: `{n}`"))?;
                realtime = Some(RealTime {
                    cpu: Some(cpu),
                    ..realtime.unwrap_or_default()
                });
            }
            "--scope" => scope = true,
            "-h" | "--help" => {
                println!("usage: loop_timing [SECONDS] [--rt-priority N] [--cpu K] [--scope]");
                return Ok(());
            }
            s => {
                seconds = s
                    .parse()
                    .map_err(|_| format!("not a duration in s: `{s}`"))?
            }
        }
    }
    let rig = SimulatedRig::default().rig(&Clock::RealTime)?;
    let ctrl = LabGains::new(KF, Cart::Two).state_feedback()?;
    let config = LoopConfig {
        duration: seconds,
        realtime,
        // Measure, do not stop: every fault is counted instead.
        max_timing_faults: usize::MAX,
        max_gap: Some(f64::INFINITY),
        ..LoopConfig::default()
    };
    println!(
        "running {seconds} s of the 2 ms loop on the wall clock, {}{}…",
        match &realtime {
            Some(rt) => format!(
                "SCHED_FIFO priority {}, memory locked{}",
                rt.priority,
                rt.cpu.map(|c| format!(", CPU {c}")).unwrap_or_default()
            ),
            None => "normal scheduling".to_owned(),
        },
        if scope { ", drawn live" } else { "" }
    );
    let reference = |_| vector![SETPOINT_MM * 1e-3];
    let outcome = if scope {
        scoped(rig, ctrl, reference, seconds, config)?
    } else {
        run(rig, ctrl, reference, &Clock::RealTime, &config).map(|out| out.stats)
    };
    match outcome {
        Ok(stats) => println!("{stats}"),
        Err(e) => {
            println!("{}", e.stats);
            return Err(e.error.into());
        }
    }
    Ok(())
}

/// The run drawn by the experiment's scope: the controller tapped, the
/// terminal taken before the run and given back before the summary.
fn scoped(
    rig: MassSpringRig<impl EppPort>,
    ctrl: impl Controller<4, 1, 1>,
    reference: impl FnMut(f64) -> SVector<f64, 1>,
    seconds: f64,
    config: LoopConfig,
) -> Result<Result<LoopStats, Box<RunError>>, Box<dyn std::error::Error>> {
    let cal = *rig.calibration();
    // Also SIGTERM or SIGHUP stop the run, so the terminal is restored.
    let stop = StopSignal::on_interrupt()?;
    let (producer, consumer) = scope::queue();
    let now = scope::Now::default();
    let tap = scope::Tap::new(ctrl, producer, Rc::clone(&now));
    let dropped = tap.dropped();
    let frame = scope::Frame {
        experiment: Experiment {
            cart: Cart::Two,
            gains: LabGains::new(KF, Cart::Two),
            setpoint_mm: SETPOINT_MM,
            duration: seconds,
        },
        volts_full_scale: cal.volts_full_scale,
        travel_mm: cal.travel_limits[1] * 1e3,
    };
    let drawing = scope::Scope::start(consumer, stop.clone(), frame)
        .map_err(|e| format!("--scope needs a terminal: {e}"))?;
    let config = LoopConfig {
        stop: Some(stop),
        ..config
    };
    let outcome = run(
        rig,
        tap,
        scope::timed(reference, now),
        &Clock::RealTime,
        &config,
    );
    if let Err(e) = drawing.finish() {
        eprintln!("loop_timing: the scope failed ({e}); the measurement is whole");
    }
    let dropped = dropped.load(std::sync::atomic::Ordering::Relaxed);
    if dropped > 0 {
        println!("scope: {dropped} samples not drawn");
    }
    Ok(outcome.map(|out| out.stats))
}
