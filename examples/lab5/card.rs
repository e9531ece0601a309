//! The real card (`--port`, feature `ppdev`): nothing is driven until a
//! card file is given (`--card`, a `ctrlab::lab::RigConfig`) and the card
//! answers with the ID it names, and what will be done is printed before
//! any register is written. Shared by lab5 and the single experiment
//! (`examples/experiment`), each printing its own plan.

use std::path::Path;

use ctrlab::hw::{Pc104, Ppdev, RigError};
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
