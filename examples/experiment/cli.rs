//! The single experiment's command line: every argument parsed and checked
//! for its form before anything runs (clap names the argument and exits
//! with 2); the setpoint against the rig's travel once the rig is known
//! (`Experiment::validate`).

use std::path::{Path, PathBuf};

use clap::Parser;
use ctrlab::lab::protocol::STEP_DURATION;
use ctrlab::lab::tables::{Experiment, TABLE5, TABLE6};
use ctrlab::lab::{Cart, LabGains};

use crate::paths::{existing_file, out_dir};

/// One closed-loop experiment of Lab 5, as a student runs it: the lab's
/// law u = Kf (G r − x_mm) on one cart, from rest to a setpoint. Prints
/// the metrics (POT, settling time, steady-state error, peak, outcome) and
/// saves the recording as DIR/<what ran>.csv, e.g.
/// target/experiment/cart2_kf_0_0_10_0.1_to_30mm.csv.
///
/// Runs on the built-in simulated rig (or --truth FILE), or on the real
/// card with --port and --card (feature `ppdev`), after showing what will
/// be driven and asking.
#[derive(Debug, Parser)]
#[command(
    name = "experiment",
    after_help = "Examples:
  cargo run --release --example experiment -- --cart 2 --kf 0,0,10,0.1 --setpoint 30mm
  cargo run --release --example experiment -- --cart 1 --kf 1,0.005,0,0 --setpoint 15mm --duration 5
  cargo run --release --example experiment -- --cart 2 --gains-file design.toml --setpoint 0.03m
  cargo run --release --example experiment -- --cart 2 --kf 0,0,10,0.1 --truth truth.toml
  cargo run --release --example experiment -- --cart 2 --kf 0,0,10,0.1 --scope --duration 10
  cargo run --release --example experiment --features ppdev -- --cart 2 --kf 0,0,10,0.1 \\
      --port /dev/parport0 --card card.toml"
)]
pub struct Args {
    /// The cart whose position is controlled: 2 (the driven cart, Table 5)
    /// or 1 (through the spring, Table 6)
    #[arg(long, value_name = "1|2", value_parser = cart)]
    pub cart: Cart,
    /// The lab's gains on [x1, x1', x2, x2'], comma-separated: V/mm on the
    /// positions, V/(mm/s) on the speeds (the Simulink model's Kf)
    #[arg(
        long,
        value_name = "KF1,KF2,KF3,KF4",
        value_parser = kf,
        allow_hyphen_values = true,
        required_unless_present = "gains_file",
        conflicts_with = "gains_file"
    )]
    pub kf: Option<[f64; 4]>,
    /// A saved design instead of --kf: a TOML file with `kf = [Kf1, Kf2,
    /// Kf3, Kf4]` (V/mm, V/(mm/s)) and optionally `g = [G1, G2, G3, G4]`,
    /// the setpoint's column G (default: the lab's, 1 on the cart's
    /// position)
    #[arg(long, value_name = "FILE", value_parser = existing_file)]
    pub gains_file: Option<PathBuf>,
    /// The setpoint with its unit, mm as the lab writes it: 30mm (or
    /// 0.03m); at most 60 % of the cart's travel [default: the cart's
    /// table's: 30mm for cart 2, 15mm for cart 1]
    #[arg(long, value_name = "LENGTH", value_parser = setpoint_mm, allow_hyphen_values = true)]
    pub setpoint: Option<f64>,
    /// The run's length, s (3 or 3s; the lab's runs are 3 s), at most 60 s
    #[arg(long, value_name = "S", default_value = "3", value_parser = seconds, allow_hyphen_values = true)]
    pub duration: f64,
    /// Where the recording goes (created if missing)
    #[arg(long, value_name = "DIR", default_value = "target/experiment", value_parser = out_dir)]
    pub out: PathBuf,
    /// The simulated rig from a TOML file (see ctrlab::lab::SimulatedRig)
    #[arg(long, value_name = "FILE", value_parser = existing_file, conflicts_with = "port")]
    pub truth: Option<PathBuf>,
    /// The simulated card's noise seed [default: lab5's for the matching
    /// table row (100 + row), else 100]
    #[arg(
        long,
        value_name = "N",
        allow_hyphen_values = true,
        conflicts_with = "port"
    )]
    pub seed: Option<u64>,
    /// Run the simulated rig on the wall clock instead of virtual time
    #[arg(long, conflicts_with = "port")]
    pub real_time: bool,
    /// Run the loop with SCHED_FIFO priority N, memory locked (Linux)
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(i32).range(1..=99), allow_hyphen_values = true)]
    pub rt_priority: Option<i32>,
    /// Run on the real PC104 card on this parallel port (feature `ppdev`);
    /// needs --card
    #[arg(long, value_name = "PATH")]
    pub port: Option<PathBuf>,
    /// The real card's register map and calibration (ctrlab::lab::RigConfig),
    /// written by the probe
    #[arg(long, value_name = "FILE", value_parser = existing_file, requires = "port")]
    pub card: Option<PathBuf>,
    /// Drive a card whose card file says `watchdog_timeout = "none"` (as
    /// `no_watchdog_acknowledged = true` in the card file)
    #[arg(long, requires = "card")]
    pub no_watchdog_acknowledged: bool,
    /// Draw the run live in the terminal (position against setpoint, and
    /// the drive); q, Esc or Ctrl-C stops it. On the simulated rig the run
    /// is then on the wall clock
    #[arg(long)]
    pub scope: bool,
    /// On the real card: do not ask before driving (for scripts)
    #[arg(long, requires = "port")]
    pub yes: bool,
}

/// A saved design (`--gains-file`): the lab's `Kf` and, optionally, `G`.
#[derive(Debug, serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct GainsFile {
    kf: [f64; 4],
    g: Option<[f64; 4]>,
}

impl Args {
    /// The experiment the arguments ask for (checked against the rig later).
    pub fn experiment(&self) -> Result<Experiment, String> {
        let gains = match (&self.kf, &self.gains_file) {
            (Some(kf), _) => LabGains::new(*kf, self.cart),
            (None, Some(path)) => gains_file(path, self.cart)?,
            (None, None) => return Err("--kf or --gains-file is needed".into()),
        };
        let table = match self.cart {
            Cart::Two => TABLE5,
            Cart::One => TABLE6,
        };
        Ok(Experiment {
            cart: self.cart,
            gains,
            setpoint_mm: self.setpoint.unwrap_or(table.setpoint_mm),
            duration: self.duration,
        })
    }
}

/// Reads a saved design; its `g` defaults to the lab's for `cart`.
fn gains_file(path: &Path, cart: Cart) -> Result<LabGains, String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let file: GainsFile = toml::from_str(&text).map_err(|e| {
        format!(
            "{}: {e}\nexpected kf = [Kf1, Kf2, Kf3, Kf4] (V/mm, V/(mm/s)) and optionally g = [G1, G2, G3, G4]",
            path.display()
        )
    })?;
    let lab = LabGains::new(file.kf, cart);
    Ok(LabGains {
        g: file.g.unwrap_or(lab.g),
        ..lab
    })
}

/// `--cart`: 1 or 2.
fn cart(s: &str) -> Result<Cart, String> {
    match s.trim() {
        "1" => Ok(Cart::One),
        "2" => Ok(Cart::Two),
        _ => Err(format!("`{s}` is not a cart: 1 or 2")),
    }
}

/// `--kf`: four finite numbers.
fn kf(s: &str) -> Result<[f64; 4], String> {
    let values: Vec<f64> = s
        .split(',')
        .map(str::trim)
        .map(|v| v.parse().map_err(|_| format!("`{v}` is not a number")))
        .collect::<Result<_, _>>()?;
    let kf: [f64; 4] = values.as_slice().try_into().map_err(|_| {
        format!(
            "{} gains given; Kf is four, Kf1,Kf2,Kf3,Kf4 (e.g. 0,0,10,0.1)",
            values.len()
        )
    })?;
    if let Some(i) = kf.iter().position(|v| !v.is_finite()) {
        return Err(format!("Kf{} = {} is not a finite number", i + 1, kf[i]));
    }
    Ok(kf)
}

/// `--setpoint`: a finite length with its unit, in mm.
fn setpoint_mm(s: &str) -> Result<f64, String> {
    let t = s.trim();
    let (number, scale) = if let Some(n) = t.strip_suffix("mm") {
        (n, 1.0)
    } else if let Some(n) = t.strip_suffix('m') {
        (n, 1e3)
    } else {
        return Err(format!(
            "`{s}` needs its unit: mm as the lab writes setpoints (30mm), or m (0.03m)"
        ));
    };
    let value: f64 = number
        .trim()
        .parse()
        .map_err(|_| format!("`{s}` is not a length (30mm or 0.03m)"))?;
    if !value.is_finite() {
        return Err(format!("`{s}` is not a finite length"));
    }
    Ok(value * scale)
}

/// `--duration`: seconds, with or without `s`; > 0 (the upper bound is the
/// experiment's check).
fn seconds(s: &str) -> Result<f64, String> {
    let t = s.trim();
    let number = t.strip_suffix('s').unwrap_or(t);
    let value: f64 = number
        .trim()
        .parse()
        .map_err(|_| format!("`{s}` is not a duration in s (3 or 3s)"))?;
    if !(value.is_finite() && value > 0.0) {
        return Err(format!(
            "`{s}`: a run lasts a finite time > 0 s (the lab's: {STEP_DURATION} s)"
        ));
    }
    Ok(value)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn setpoints_need_their_unit() {
        assert_eq!(setpoint_mm("30mm"), Ok(30.0));
        assert_eq!(setpoint_mm("-15 mm"), Ok(-15.0));
        assert_eq!(setpoint_mm("0.03m"), Ok(30.0));
        assert!(setpoint_mm("30").unwrap_err().contains("unit"));
        assert!(setpoint_mm("NaNmm").is_err());
    }

    #[test]
    fn gains_are_four_finite_numbers() {
        assert_eq!(kf("0, 0, 10, 0.1"), Ok([0.0, 0.0, 10.0, 0.1]));
        assert!(kf("0,0,10").unwrap_err().contains("3 gains given"));
        assert!(kf("0,0,NaN,0").unwrap_err().contains("Kf3 = NaN"));
        assert!(seconds("-1").is_err() && seconds("3s") == Ok(3.0));
    }
}
