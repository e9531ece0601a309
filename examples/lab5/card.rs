//! The real card (`--port`, feature `ppdev`): nothing is driven until a
//! card file is given (`--card`, a `ctrlab::lab::RigConfig`) and the card
//! answers with the ID it names, and what will be done is printed before
//! any register is written.

use std::path::Path;

use ctrlab::hw::{Pc104, Ppdev, RigError};
use ctrlab::lab::ident_input::{IdentInput, PROBE_DURATION, PROBE_FRACTIONS, TRAVEL_FRACTION};
use ctrlab::lab::{MassSpringRig, RigConfig};

/// The card file named by `--card` and its configuration, checked (a card
/// without a watchdog must be acknowledged, in the file or by
/// `--no-watchdog-acknowledged`); without one, how to make it.
pub fn load<'a>(
    port: &Path,
    card: Option<&'a Path>,
    no_watchdog_acknowledged: bool,
) -> Result<(&'a Path, RigConfig), String> {
    let Some(card) = card else {
        return Err(format!(
            "--port {port} needs the card's register map and calibration: --card card.toml. \
             The built-in map is the simulated card's, and nothing is driven on a real card \
             from it. Write the map from the lab's driver or the FPGA's sources in card.toml; the probe confirms it step by step and writes the card file (--scan searches blind, see docs/hardware.md):\n  \
             cargo run --example probe --features ppdev -- --port {port} --card card.toml --out card.toml\n\
             then: cargo run --release --example lab5 --features ppdev -- --port {port} --card card.toml",
            port = port.display()
        ));
    };
    let mut config =
        RigConfig::read_toml(card).map_err(|e| format!("card file {}: {e}", card.display()))?;
    config.calibration.no_watchdog_acknowledged |= no_watchdog_acknowledged;
    // Before anything is opened: the same check building the rig makes.
    config.calibration.check_watchdog().map_err(|e| {
        format!(
            "card file {}: {}",
            card.display(),
            e.in_table("calibration")
        )
    })?;
    Ok((card, config))
}

/// What the run will do, for the person at the rig to check before the
/// first register access.
pub fn plan(port: &Path, card: &Path, config: &RigConfig, ident: &IdentInput) -> String {
    let cal = &config.calibration;
    let what = config
        .to_string()
        .lines()
        .map(|line| format!("  {line}\n"))
        .collect::<String>();
    format!(
        "About to run the rig sections on the REAL card.\n\
         port: {port}\n\
         card file: {card}\n\
         {what}\
         runs: {probes}5 open-loop runs of 5 s with a {signal} of {ident_volts}, 20 more of 5 s \
         comparing inputs of the same peak (square wave, PRBS, multisine, chirp), then 26 closed-loop \
         runs of 3 s (24 for Tables 5 and 6, 2 for the Design section's LQI) saturated at ±{full} V, 3 s pauses between runs; each run \
         halts the motor at the first fault (travel limit, bus fault, stall, a dead cart-2 encoder, \
         the drive held at its limit, timing, Ctrl-C and the other stop signals).\n\
         Nothing has been written to the card. Next: open the port and read the ID register \
         {id:#04x} (a read only).",
        port = port.display(),
        card = card.display(),
        full = cal.volts_full_scale,
        id = config.map.id,
        signal = ident.signal,
        probes = if ident.scale_to_travel {
            format!(
                "2 probe runs of {PROBE_DURATION} s at {} and {} V, ",
                PROBE_FRACTIONS[0] * ident.volts,
                PROBE_FRACTIONS[1] * ident.volts
            )
        } else {
            String::new()
        },
        ident_volts = if ident.scale_to_travel {
            format!(
                "at most ±{} V (lowered to keep both carts within {:.0} % of their travel)",
                ident.volts,
                TRAVEL_FRACTION * 100.0
            )
        } else {
            format!("±{} V (fixed)", ident.volts)
        },
    )
}

/// Opens the port with the file's map and reads the card's ID: the first
/// access, and a read. Dropping the card releases the port.
pub fn check_id(port: &Path, config: &RigConfig) -> Result<u8, RigError> {
    let mut card = Pc104::with_map(Ppdev::open_with(port, config.port)?, config.map)?;
    Ok(card.probe_id(config.calibration.card_id)?)
}

/// The rig on the card with the file's map and calibration
/// ([`RigConfig::rig`]: a card without a watchdog only if acknowledged):
/// the ID is probed (building the rig) before the counters are cleared, the
/// first write.
pub fn rig(port: &Path, config: &RigConfig, period: f64) -> Result<MassSpringRig<Ppdev>, RigError> {
    let mut rig = config.rig(Ppdev::open_with(port, config.port)?, period)?;
    rig.card_mut().clear_counters()?;
    Ok(rig)
}
