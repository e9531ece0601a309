//! Measures the real-time control loop's timing on this machine: 10 s of the
//! lab's cart-2 controller at T = 2 ms on the simulated card, on the wall
//! clock, and prints the lateness percentiles and overruns.
//!
//! ```text
//! cargo run --release --example loop_timing            # 10 s
//! cargo run --release --example loop_timing -- 60      # 60 s
//! ```
//!
//! A stock kernel is not a real-time kernel: expect a p99 of tens of µs and
//! occasional millisecond outliers under load. The numbers say how much of
//! the 2 ms period is left on a given PC.

use ctrlab::StateFeedback;
use ctrlab::hw::{Clock, LoopConfig, run};
use ctrlab::lab::{Cart, SimulatedRig};
use ctrlab::nalgebra::vector;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let seconds: f64 = match std::env::args().nth(1) {
        Some(s) => s
            .parse()
            .map_err(|_| format!("not a duration in s: `{s}`"))?,
        None => 10.0,
    };
    let rig = SimulatedRig::default().rig(&Clock::RealTime)?;
    let ctrl = StateFeedback::from_lab_gains([0.0, 0.0, 10.0, 0.05], Cart::Two)?;
    let config = LoopConfig {
        duration: seconds,
        ..LoopConfig::default()
    };
    println!("running {seconds} s of the 2 ms loop on the wall clock…");
    let out = run(rig, ctrl, |_| vector![0.030], &Clock::RealTime, &config)?;
    let s = out.stats;
    println!(
        "ticks {}, overruns {} (longest run {}), lateness p50 {:.1} µs, p99 {:.1} µs, max {:.1} µs",
        s.ticks,
        s.overruns,
        s.max_consecutive_overruns,
        s.lateness_p50 * 1e6,
        s.lateness_p99 * 1e6,
        s.lateness_max * 1e6
    );
    Ok(())
}
