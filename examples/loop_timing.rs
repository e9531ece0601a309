//! Measures the control loop's timing on this machine, cyclictest-style:
//! the lab's cart-2 controller at T = 2 ms on the simulated card, on the
//! wall clock, then a summary of the lateness (p50, p99, p99.9, max),
//! overruns and skipped ticks.
//!
//! ```text
//! cargo run --release --example loop_timing                      # 10 s, normal scheduling
//! cargo run --release --example loop_timing -- 60                # 60 s
//! cargo run --release --example loop_timing -- 10 --rt-priority 80 --cpu 1
//! ```
//!
//! `--rt-priority N` runs the loop with SCHED_FIFO priority N and all memory
//! locked (needs an rtprio limit, CAP_SYS_NICE or root: the error says how
//! to grant it); `--cpu K` pins it to CPU K. A stock kernel is not a
//! real-time kernel: without SCHED_FIFO expect a p99 of tens of µs and
//! millisecond outliers under load. The numbers say how much of the 2 ms
//! period is left on a given PC.

use ctrlab::hw::{Clock, LoopConfig, RealTime, run};
use ctrlab::lab::LabGains;
use ctrlab::lab::{Cart, SimulatedRig};
use ctrlab::nalgebra::vector;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut seconds = 10.0;
    let mut realtime: Option<RealTime> = None;
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
            "-h" | "--help" => {
                println!("usage: loop_timing [SECONDS] [--rt-priority N] [--cpu K]");
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
    let ctrl = LabGains::new([0.0, 0.0, 10.0, 0.05], Cart::Two).state_feedback()?;
    let config = LoopConfig {
        duration: seconds,
        realtime,
        // Measure, do not stop: every fault is counted instead.
        max_timing_faults: usize::MAX,
        max_gap: Some(f64::INFINITY),
        ..LoopConfig::default()
    };
    println!(
        "running {seconds} s of the 2 ms loop on the wall clock, {}…",
        match &realtime {
            Some(rt) => format!(
                "SCHED_FIFO priority {}, memory locked{}",
                rt.priority,
                rt.cpu.map(|c| format!(", CPU {c}")).unwrap_or_default()
            ),
            None => "normal scheduling".to_owned(),
        }
    );
    match run(rig, ctrl, |_| vector![0.030], &Clock::RealTime, &config) {
        Ok(out) => println!("{}", out.stats),
        Err(e) => {
            println!("{}", e.stats);
            return Err(e.into());
        }
    }
    Ok(())
}
