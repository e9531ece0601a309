//! The card bring-up tool: confirms a card's register map (from a card
//! file) and finds its encoder signs, motor polarity and watchdog, step by
//! step, and writes the card file (`card.toml`) that `lab5 --port …
//! --card card.toml` drives the rig from. Only with `--scan` does it look
//! for a map blind, writing test patterns to addresses no map describes
//! (see `docs/hardware.md` for why that comes last).
//!
//! ```text
//! cargo run --example probe -- --simulated                       # the simulated card, a simulated hand
//! cargo run --example probe --features ppdev -- --port /dev/parport0 --card card.toml --out card.toml
//! cargo run --example probe --features ppdev -- --port /dev/parport0 --scan --out card.toml
//! ```
//!
//! Each step prints what it will do before doing it. The encoder step asks
//! you to switch the motor supply off; the drive step pulses the motor only
//! after you answer `yes`. Ctrl-C (or SIGTERM) stops the probe at its next
//! wait — within one pulse — with the PWM zeroed. Keep a hardware e-stop
//! within reach: software alone must not be trusted for safety.

#[cfg(all(feature = "ppdev", target_os = "linux"))]
use std::io::{BufRead, Write};
use std::path::PathBuf;
#[cfg(all(feature = "ppdev", target_os = "linux"))]
use std::time::Duration;
use std::time::Instant;

#[cfg(all(feature = "ppdev", target_os = "linux"))]
use ctrlab::hw::probe::Hands;
use ctrlab::hw::probe::{Operator, Probe, ProbeError, ProbeOptions, ProbeReport};
use ctrlab::hw::{Clock, EppPort, PpdevOptions, StopSignal, VirtualClock};
use ctrlab::lab::{Calibration, RigConfig, SimulatedOperator, SimulatedRig};

const USAGE: &str = "usage: probe (--simulated | --port /dev/parportN) (--card FILE | --scan) [--out FILE] [--metres-per-count M] [--volts V]
  --simulated           probe the simulated card, moved by a simulated hand
  --port PATH           probe the card on this parallel port (feature `ppdev`)
  --card FILE           the card file whose register map ([map]) to confirm; its card_id,
                        calibration and [port] keys are used too (the simulated card's own
                        map when --simulated is given without it)
  --scan                no map: scan blind, writing test patterns to addresses no map
                        describes, which on an FPGA can hit configuration registers
  --out FILE            where the card file goes (default card.toml)
  --metres-per-count M  cart travel per encoder count, m (default: the card file's, or 80 mm / 8192)
  --volts V             motor voltage at 100 % duty, V (default: the card file's, or 24)";

struct Args {
    simulated: bool,
    port: Option<PathBuf>,
    card: Option<PathBuf>,
    scan: bool,
    out: PathBuf,
    metres_per_count: Option<f64>,
    volts: Option<f64>,
}

fn parse() -> Result<Args, String> {
    let mut args = Args {
        simulated: false,
        port: None,
        card: None,
        scan: false,
        out: PathBuf::from("card.toml"),
        metres_per_count: None,
        volts: None,
    };
    let mut it = std::env::args().skip(1);
    // Checked here, before anything is probed or pulsed: a bad value would
    // otherwise surface only when the card file is written, at the end.
    let number = |v: Option<String>, name: &str, unit: &str| -> Result<f64, String> {
        let text = v.ok_or(format!("{name} needs a value"))?;
        match text.parse::<f64>() {
            Ok(x) if x.is_finite() && x > 0.0 => Ok(x),
            Ok(_) => Err(format!(
                "{name} {text}: must be a finite number > 0, {unit}"
            )),
            Err(e) => Err(format!("{name} {text}: {e}")),
        }
    };
    while let Some(arg) = it.next() {
        match arg.as_str() {
            "--simulated" => args.simulated = true,
            "--port" => args.port = Some(it.next().ok_or("--port needs a device path")?.into()),
            "--card" => args.card = Some(it.next().ok_or("--card needs a file")?.into()),
            "--scan" => args.scan = true,
            "--out" => args.out = it.next().ok_or("--out needs a file")?.into(),
            "--metres-per-count" => {
                args.metres_per_count = Some(number(it.next(), "--metres-per-count", "m")?);
            }
            "--volts" => args.volts = Some(number(it.next(), "--volts", "V")?),
            "-h" | "--help" => return Err(USAGE.to_owned()),
            other => return Err(format!("unknown argument {other}\n{USAGE}")),
        }
    }
    if args.out.is_dir() {
        return Err(format!(
            "--out {}: is a directory; give the card file's path (e.g. {}/card.toml)",
            args.out.display(),
            args.out.display()
        ));
    }
    if args.simulated == args.port.is_some() {
        return Err(format!(
            "give exactly one of --simulated and --port\n{USAGE}"
        ));
    }
    if args.scan && args.card.is_some() {
        return Err(format!(
            "give --card (confirm its map) or --scan (no map), not both\n{USAGE}"
        ));
    }
    if args.port.is_some() && !args.scan && args.card.is_none() {
        return Err(format!(
            "a real card is probed against a map: give --card FILE with the register map \
             taken from the lab's driver or the FPGA's sources (see docs/hardware.md), or \
             --scan to look for one blind (writes to unknown addresses)\n{USAGE}"
        ));
    }
    Ok(args)
}

/// The person at the console. Ctrl-C at a prompt takes effect when the
/// line ends (Enter): the answer is then "no", and the probe stops at its
/// next wait.
#[cfg(all(feature = "ppdev", target_os = "linux"))]
struct Console {
    stop: StopSignal,
}

#[cfg(all(feature = "ppdev", target_os = "linux"))]
impl Console {
    fn line() -> String {
        let mut line = String::new();
        // End of input answers "no" and "not ready" alike.
        let _ = std::io::stdin().lock().read_line(&mut line);
        line
    }
}

#[cfg(all(feature = "ppdev", target_os = "linux"))]
impl<P> Operator<P> for Console {
    fn tell(&mut self, message: &str) {
        println!("{message}");
    }

    fn confirm(&mut self, question: &str) -> bool {
        print!("{question} [yes/NO] ");
        let _ = std::io::stdout().flush();
        let yes = matches!(Self::line().trim(), "y" | "yes" | "Y" | "YES");
        yes && !self.stop.is_requested()
    }

    fn hands(&mut self, hands: Hands) {
        let ask = match hands {
            Hands::Off => "Take your hands off the carts.".to_owned(),
            Hands::Move(axis) => format!(
                "Move cart {axis} back and forth by hand over a few centimetres, and keep \
                 moving it until asked to stop; hold the other cart still."
            ),
            Hands::Away(axis) => {
                format!("Hold cart {axis} a few centimetres AWAY from the wall and keep it there.")
            }
        };
        print!("{ask} Press Enter when ready. ");
        let _ = std::io::stdout().flush();
        Self::line();
    }

    fn wait(&mut self, _port: &mut P, seconds: f64) {
        if seconds.is_finite() && seconds > 0.0 {
            std::thread::sleep(Duration::from_secs_f64(seconds.min(60.0)));
        }
    }
}

/// The time of one register read (an address and a data cycle), µs.
fn cycle_time<P: EppPort>(port: &mut P) -> Result<f64, ctrlab::hw::PortError> {
    let start = Instant::now();
    for _ in 0..1000 {
        port.read_register(0)?;
    }
    Ok(start.elapsed().as_secs_f64() * 1e3)
}

fn probe<P: EppPort, O: Operator<P>>(
    port: P,
    operator: O,
    options: ProbeOptions,
    stop: StopSignal,
) -> Result<(ProbeReport, O), ProbeError> {
    let mut probe = Probe::new(port, operator, options)?.with_stop(stop);
    let report = probe.run()?;
    let (_port, operator) = probe.into_parts();
    Ok((report, operator))
}

#[cfg(all(feature = "ppdev", target_os = "linux"))]
fn real(
    path: &std::path::Path,
    options: ProbeOptions,
    port_options: PpdevOptions,
    stop: StopSignal,
) -> Result<ProbeReport, String> {
    println!(
        "step 0, port: opening {} (exclusive), reading its modes",
        path.display()
    );
    let modes = ctrlab::hw::Ppdev::modes_of(path).map_err(|e| e.to_string())?;
    println!("  modes: {modes}");
    let mut port = ctrlab::hw::Ppdev::open_with(path, port_options).map_err(|e| e.to_string())?;
    println!(
        "  data-direction bit around reads (card file [port] data_dir): {}",
        port_options.data_dir
    );
    match cycle_time(&mut port) {
        Ok(us) => println!("  one register read (address + data cycle): {us:.2} µs"),
        Err(e) => println!("  EPP cycles fail with no answer ({e}): no card, or no EPP"),
    }
    let console = Console { stop: stop.clone() };
    probe(port, console, options, stop)
        .map(|(r, _)| r)
        .map_err(|e| e.to_string())
}

#[cfg(not(all(feature = "ppdev", target_os = "linux")))]
fn real(
    _path: &std::path::Path,
    _options: ProbeOptions,
    _port_options: PpdevOptions,
    _stop: StopSignal,
) -> Result<ProbeReport, String> {
    Err("--port needs the `ppdev` feature on Linux: \
         cargo run --example probe --features ppdev -- --port /dev/parport0"
        .to_owned())
}

fn simulated(mut options: ProbeOptions, stop: StopSignal) -> Result<ProbeReport, String> {
    let clock = VirtualClock::new();
    let rig = SimulatedRig::default();
    if options.card_id.is_none() {
        // No card file: confirm the simulated card's own map.
        options.map = rig.card.map;
        options.card_id = Some(rig.calibration.card_id);
    }
    let mut card = rig
        .card(&Clock::Virtual(clock.clone()))
        .map_err(|e| e.to_string())?;
    println!("step 0, port: the simulated card on a virtual clock");
    let us = cycle_time(&mut card).map_err(|e| e.to_string())?;
    println!("  one register read (address + data cycle): {us:.3} µs of computer time");
    // The simulated operator says yes to both confirmations.
    let hand = SimulatedOperator::new(clock, [true, true]);
    let scan = options.scan;
    let result = probe(card, hand, options, stop);
    let (report, hand) = result.map_err(|e| e.to_string())?;
    for line in &hand.transcript {
        println!("{line}");
    }
    if report.map != rig.card.map {
        return Err(format!(
            "the probe found {:?}, not the simulated card's map {:?}",
            report.map, rig.card.map
        ));
    }
    if scan {
        println!("the blind scan rediscovered the simulated card's register map exactly");
    } else {
        println!("the probe confirmed the simulated card's register map");
    }
    Ok(report)
}

fn main() {
    let args = match parse() {
        Ok(args) => args,
        Err(message) => {
            eprintln!("{message}");
            std::process::exit(2);
        }
    };
    let card = match args.card.as_deref().map(RigConfig::read_toml).transpose() {
        Ok(card) => card,
        Err(e) => {
            eprintln!("cannot read the card file: {e}");
            std::process::exit(1);
        }
    };
    let mut base = card.map_or_else(Calibration::default, |c| c.calibration);
    if let Some(m) = args.metres_per_count {
        base.metres_per_count = m;
    }
    if let Some(v) = args.volts {
        base.volts_full_scale = v;
    }
    // The card file is checked as it is read; the arguments over it are
    // checked together with it, still before anything is probed.
    if let Err(e) = base.validate() {
        eprintln!("the calibration with --metres-per-count and --volts: {e}");
        std::process::exit(2);
    }
    let dir = args.out.parent().filter(|d| !d.as_os_str().is_empty());
    if let Some(Err(e)) = dir.map(std::fs::create_dir_all) {
        eprintln!(
            "--out {}: cannot create its directory: {e}",
            args.out.display()
        );
        std::process::exit(2);
    }
    let port_options = card.map(|c| c.port).unwrap_or_default();
    let mut options = ProbeOptions {
        scan: args.scan,
        ..ProbeOptions::default()
    };
    if let Some(card) = &card {
        options.map = card.map;
        options.card_id = Some(card.calibration.card_id);
    }
    // Ctrl-C and SIGTERM stop the probe at its next wait, PWM zeroed,
    // instead of killing it with a pulse's duty on.
    let stop = match StopSignal::on_interrupt() {
        Ok(stop) => stop,
        Err(e) => {
            eprintln!("cannot catch Ctrl-C, so a pulse could not be stopped safely: {e}");
            std::process::exit(1);
        }
    };
    let report = match &args.port {
        Some(path) => real(path, options, port_options, stop),
        None => simulated(options, stop),
    };
    let report = match report {
        Ok(report) => report,
        Err(message) => {
            eprintln!("probe stopped: {message}");
            std::process::exit(1);
        }
    };
    for note in &report.notes {
        println!("note: {note}");
    }
    let config = RigConfig {
        port: port_options,
        ..RigConfig::new(report.map, Calibration::from_probe(&report, &base))
    };
    println!(
        "not measured, taken as given: {} m per count, {} V full scale, travel limits ±{:?} m",
        config.calibration.metres_per_count,
        config.calibration.volts_full_scale,
        config.calibration.travel_limits
    );
    if let Err(e) = config.write_toml(&args.out) {
        eprintln!("cannot write the card file: {e}");
        std::process::exit(1);
    }
    println!("card file written to {}", args.out.display());
    if args.port.is_some() {
        println!(
            "next: cargo run --release --example lab5 --features ppdev -- --port {} --card {}",
            args.port
                .as_deref()
                .unwrap_or(std::path::Path::new("/dev/parport0"))
                .display(),
            args.out.display()
        );
    }
}
