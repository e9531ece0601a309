//! One experiment of Lab 5 at a time, as a student runs it at the rig: set
//! the gains, run, read POT, settling time and steady-state error, fill a
//! row, decide the next gain. Where `lab5` runs every row of Tables 5 and 6
//! back to back, this runs one: which cart, the lab's `Kf` (or a saved
//! design with its `G`), the setpoint and the duration.
//!
//! ```text
//! cargo run --release --example experiment -- --cart 2 --kf 0,0,10,0.1 --setpoint 30mm
//! cargo run --release --example experiment -- --cart 1 --kf 1,0,0,0.05 --setpoint 15mm --duration 5
//! cargo run --release --example experiment -- --cart 2 --gains-file design.toml
//! cargo run --release --example experiment --features ppdev -- --cart 2 --kf 0,0,10,0.1 \
//!     --port /dev/parport0 --card card.toml
//! ```
//!
//! The run is the library's `lab::tables::Experiment`, the same controller,
//! reference and metrics as lab5's batch gives a table row; a row of Table
//! 5 or 6 run here on the simulated rig gets that row's noise seed, so it
//! prints the batch's numbers (tests/lab_tables.rs and tests/experiment.rs
//! check it). The recording is saved under a name that says what ran
//! (`target/experiment/cart2_kf_0_0_10_0.1_to_30mm.csv`; `--out DIR`),
//! with units in its header (`t_s,u_V,x1_m,v1_m_s,x2_m,v2_m_s`).
//!
//! On the real card it prints the port, the card file and what will be
//! driven (the PWM channel, ±V, how long, the travel limits), reads the
//! card's ID (a read only), and asks before anything is driven (`--yes`
//! for scripts). Ctrl-C (and SIGTERM, SIGHUP, SIGQUIT, Ctrl-Z) halts the
//! rig and keeps the recording. With `--scope` the run is drawn live in the
//! terminal (the cart's position against the setpoint, and the drive; on
//! the simulated rig in wall-clock time), and q, Esc or Ctrl-C stop it. A run the rig halts (a fault, a travel
//! limit) prints what halted it; any halt but a travel limit, which is an
//! outcome of the gains, exits with status 1.

#[cfg(all(feature = "ppdev", target_os = "linux"))]
#[path = "../lab5/card.rs"]
mod card;
mod cli;
#[path = "../lab5/paths.rs"]
mod paths;
mod scope;

use std::path::PathBuf;
use std::process::ExitCode;
use std::rc::Rc;
use std::sync::atomic::Ordering;

use clap::Parser;
use ctrlab::hw::{
    self, Clock, EppPort, LoopConfig, LoopFault, RealTime, RigError, StopSignal, VirtualClock,
};
use ctrlab::lab::protocol::PERIOD;
use ctrlab::lab::tables::{Experiment, ExperimentRun, Halt, RigOutcome, kf_display};
use ctrlab::lab::{CardSettings, MassSpringRig, SimulatedRig};

fn main() -> ExitCode {
    let args = cli::Args::parse();
    match experiment(&args) {
        Ok(Ended::Measured) => ExitCode::SUCCESS,
        Ok(Ended::Halted) => ExitCode::FAILURE,
        Err(e) => {
            eprintln!("experiment: {e}");
            ExitCode::FAILURE
        }
    }
}

/// How a run ended, for the exit status.
enum Ended {
    /// Completed, halted at a travel limit (the gains' outcome), or not
    /// started (declined).
    Measured,
    /// Halted by a fault of the rig or the loop, or a stop request.
    Halted,
}

fn experiment(args: &cli::Args) -> Result<Ended, Box<dyn std::error::Error>> {
    let experiment = args.experiment()?;
    let realtime = args.rt_priority.map(|priority| RealTime {
        priority,
        ..RealTime::default()
    });
    match &args.port {
        None => simulated(args, &experiment, realtime),
        #[cfg(all(feature = "ppdev", target_os = "linux"))]
        Some(port) => real_card(args, port, &experiment, realtime),
        #[cfg(not(all(feature = "ppdev", target_os = "linux")))]
        Some(_) => Err(
            "--port needs the `ppdev` feature on Linux: cargo run --release --example \
             experiment --features ppdev -- --port /dev/parport0 --card card.toml ..."
                .into(),
        ),
    }
}

/// On the simulated rig (`--truth`, or the default), with the matching
/// table row's seed unless `--seed`.
fn simulated(
    args: &cli::Args,
    experiment: &Experiment,
    realtime: Option<RealTime>,
) -> Result<Ended, Box<dyn std::error::Error>> {
    let sim = match &args.truth {
        Some(path) => SimulatedRig::read_toml(path)?,
        None => SimulatedRig::default(),
    };
    sim.validate()?;
    experiment.validate(&sim.calibration)?;
    let seed = args.seed.unwrap_or_else(|| experiment.seed());
    // As lab5 runs a row: the rig's card with this run's seed, at the
    // lab's period.
    let sim = SimulatedRig {
        card: CardSettings { seed, ..sim.card },
        period: PERIOD,
        ..sim
    };
    // The scope shows the run as it happens: in wall-clock time.
    let real_time = args.real_time || args.scope;
    let clock = if real_time {
        Clock::RealTime
    } else {
        Clock::Virtual(VirtualClock::new())
    };
    let rig_name = args
        .truth
        .as_ref()
        .map_or("the default truth".into(), |p| p.display().to_string());
    println!("{}", describe(experiment));
    println!(
        "rig: the simulated rig ({rig_name}), noise seed {seed}, {}",
        if real_time {
            "on the wall clock"
        } else {
            "in virtual time"
        }
    );
    if let Some((table, row)) = experiment.table_row() {
        println!(
            "Table {}, row {} (lab5's runs/table{}_{experiment}.csv)",
            table.number,
            row + 1,
            table.number
        );
    }
    let config = LoopConfig {
        realtime,
        stop: Some(StopSignal::on_interrupt()?),
        ..LoopConfig::default()
    };
    let run = run(args, experiment, sim.rig(&clock)?, &clock, config)?;
    report(args, experiment, &run, sim.calibration.volts_full_scale)
}

/// On the real card: the plan, the card's ID, the question, then the run.
#[cfg(all(feature = "ppdev", target_os = "linux"))]
fn real_card(
    args: &cli::Args,
    port: &std::path::Path,
    experiment: &Experiment,
    realtime: Option<RealTime>,
) -> Result<Ended, Box<dyn std::error::Error>> {
    use std::io::Write;

    let (file, config) = card::load(port, args.card.as_deref(), args.no_watchdog_acknowledged)?;
    experiment.validate(&config.calibration)?;
    let cal = &config.calibration;
    println!("About to run ONE experiment on the REAL card.");
    println!("port: {}\ncard file: {}", port.display(), file.display());
    println!("{}", describe(experiment));
    println!(
        "drives: the motor on PWM channel {} for {} s, saturated at ±{} V; halts at the \
         first fault (cart 1 beyond ±{:.0} mm or cart 2 beyond ±{:.0} mm, a bus fault, a \
         stalled motor, a dead cart-2 encoder, the drive held at its limit, timing, Ctrl-C).",
        cal.pwm_channel,
        experiment.duration,
        cal.volts_full_scale,
        cal.travel_limits[0] * 1e3,
        cal.travel_limits[1] * 1e3,
    );
    println!(
        "Nothing has been written to the card. Next: read its ID register {:#04x} (a read only).",
        config.map.id
    );
    let id = card::check_id(port, &config)?;
    println!("The card answers {id:#04x}, as the card file says.");
    if !args.yes {
        print!("Carts at rest, hand on the emergency stop? Drive the motor [y/N] ");
        std::io::stdout().flush()?;
        if !confirmed(std::io::stdin().lock())? {
            println!("Nothing driven.");
            return Ok(Ended::Measured);
        }
    }
    // Only now does Ctrl-C halt the rig rather than end the process: before,
    // nothing was driven.
    let stop = StopSignal::on_interrupt()?;
    let rig = card::rig(port, &config, PERIOD)?;
    let loop_config = LoopConfig {
        realtime,
        stop: Some(stop),
        ..LoopConfig::default()
    };
    let run = run(args, experiment, rig, &Clock::RealTime, loop_config)?;
    report(args, experiment, &run, cal.volts_full_scale)
}

/// Runs `experiment` on `rig`: as the library runs it, or with `--scope`
/// its controller and reference tapped for the live scope (the same
/// controller, reference and metrics: `Experiment::controller`,
/// `reference`, `measure`).
fn run<P: EppPort>(
    args: &cli::Args,
    experiment: &Experiment,
    rig: MassSpringRig<P>,
    clock: &Clock,
    config: LoopConfig,
) -> Result<ExperimentRun, Box<dyn std::error::Error>> {
    if !args.scope {
        return Ok(experiment.run(rig, clock, &config)?);
    }
    let cal = *rig.calibration();
    let stop = config.stop.clone().unwrap_or_default();
    let (producer, consumer) = scope::queue();
    let now = scope::Now::default();
    let tap = scope::Tap::new(experiment.controller()?, producer, Rc::clone(&now));
    let dropped = tap.dropped();
    let frame = scope::Frame {
        experiment: *experiment,
        volts_full_scale: cal.volts_full_scale,
        travel_mm: cal.travel_limits[experiment.cart.number() - 1] * 1e3,
    };
    // The terminal is taken before the run: without one, nothing is driven.
    let scope = scope::Scope::start(consumer, stop.clone(), frame)
        .map_err(|e| format!("--scope needs a terminal: {e}"))?;
    let config = LoopConfig {
        duration: experiment.duration,
        stop: Some(stop),
        ..config
    };
    let reference = scope::timed(experiment.reference(), now);
    let outcome = hw::run(rig, tap, reference, clock, &config);
    let drawn = scope.finish();
    let run = experiment.measure(outcome, cal.volts_full_scale)?;
    if let Err(e) = drawn {
        eprintln!("experiment: the scope failed ({e}); the run and its recording are whole");
    }
    let dropped = dropped.load(Ordering::Relaxed);
    if dropped > 0 {
        println!("scope: {dropped} samples not drawn (the recording has them all)");
    }
    Ok(run)
}

/// The answer to "Drive the motor [y/N]": yes only for `y` or `yes`; an
/// empty line, anything else or the end of input (a script without
/// `--yes`) is no.
#[cfg_attr(not(all(feature = "ppdev", target_os = "linux")), allow(dead_code))]
fn confirmed(mut input: impl std::io::BufRead) -> std::io::Result<bool> {
    let mut answer = String::new();
    input.read_line(&mut answer)?;
    Ok(matches!(answer.trim(), "y" | "Y" | "yes" | "Yes" | "YES"))
}

/// The experiment in the lab's words.
fn describe(e: &Experiment) -> String {
    format!(
        "experiment: cart {}, Kf = {} (V/mm, V/(mm/s)), G = {}, setpoint {} mm, {} s",
        e.cart.number(),
        kf_display(&e.gains.kf),
        kf_display(&e.gains.g),
        e.setpoint_mm,
        e.duration
    )
}

/// Saves the recording, prints the metrics and what halted the run.
fn report(
    args: &cli::Args,
    experiment: &Experiment,
    run: &ExperimentRun,
    full_scale: f64,
) -> Result<Ended, Box<dyn std::error::Error>> {
    paths::prepare_out(&args.out, &[], &[])?;
    let path: PathBuf = args.out.join(format!("{experiment}.csv"));
    run.recording.write_csv(&path)?;
    let dash = || "–".to_string();
    let step = run.outcome.step();
    let metric = |f: &dyn Fn(&ctrlab::StepInfo) -> String| step.map_or_else(dash, f);
    let (peak_u, saturated) = run.drive(full_scale);
    // The batch report's precision (lab5's Tables 5 and 6).
    let rows = [
        ("POT", metric(&|s| format!("{:.2} %", s.overshoot))),
        (
            "settling time (2 %)",
            metric(&|s| format!("{:.3} s", s.settling_time)),
        ),
        (
            "steady-state error",
            metric(&|s| format!("{:.2} mm", s.steady_state_error.unwrap_or(f64::NAN))),
        ),
        (
            "peak",
            metric(&|s| format!("{:.2} mm at {:.3} s", s.peak, s.peak_time)),
        ),
        (
            "final value y∞",
            metric(&|s| format!("{:.2} mm", s.steady_state_value)),
        ),
        ("outcome", outcome(&run.outcome, experiment, full_scale)),
        (
            "drive",
            format!(
                "peak |u| {peak_u:.2} V, at ±{full_scale} V {:.0} % of the samples",
                saturated * 100.0
            ),
        ),
        ("samples", format!("{}", run.recording.len())),
    ];
    println!();
    for (name, value) in rows {
        println!("  {name:<20} {value}");
    }
    println!("\nrecording: {}", path.display());
    Ok(match &run.fault {
        None | Some(RigError::Fault(LoopFault::TravelLimit { .. })) => Ended::Measured,
        Some(fault) => {
            eprintln!("experiment: the rig halted: {fault}");
            Ended::Halted
        }
    })
}

/// The outcome in words, as lab5's tables say it.
fn outcome(o: &RigOutcome, e: &Experiment, full_scale: f64) -> String {
    match o {
        RigOutcome::Settled(_) => "settled".into(),
        RigOutcome::TooSlow { y_end_mm } => format!(
            "too slow for the {} s run ({y_end_mm:.2} mm at the end)",
            e.duration
        ),
        RigOutcome::Oscillating {
            lo_mm,
            hi_mm,
            saturated,
        } => format!(
            "sustained oscillation {lo_mm:.1} … {hi_mm:.1} mm, the drive at ±{full_scale} V {:.0} % of the last quarter",
            saturated * 100.0
        ),
        RigOutcome::Diverged {
            at,
            why:
                Halt::TravelLimit {
                    cart,
                    position,
                    limit,
                },
        } => format!(
            "diverged: halted at t = {at:.3} s, cart {cart} at {:.1} mm beyond the ±{:.0} mm travel limit",
            position * 1e3,
            limit * 1e3
        ),
        // Not the gains' doing: the rig or the loop stopped the run.
        RigOutcome::Diverged {
            at,
            why: Halt::Fault(message),
        } => format!("halted at t = {at:.3} s: {message}"),
        RigOutcome::Diverged {
            at,
            why: Halt::NoMetrics(e),
        } => format!("no metrics (run ended at t = {at:.3} s): {e}"),
    }
}

#[cfg(test)]
mod tests {
    use super::confirmed;

    #[test]
    fn only_a_yes_drives_the_motor() {
        for (input, yes) in [
            ("y\n", true),
            ("yes\n", true),
            ("\n", false),
            ("n\n", false),
            ("yy\n", false),
            ("", false),
        ] {
            assert_eq!(confirmed(input.as_bytes()).unwrap(), yes, "{input:?}");
        }
    }
}
