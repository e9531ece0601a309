//! The crate's TOML files from any text: a card file (`RigConfig`) and a
//! simulated rig's truth file (`SimulatedRig`) load or are refused; what
//! loads is valid and writes back to the same value.
#![no_main]

use ctrlab::lab::{RigConfig, SimulatedRig};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok(card) = RigConfig::from_toml(text) {
        assert!(card.validate().is_ok());
        let again = RigConfig::from_toml(&card.to_toml()).expect("its own file loads");
        assert_eq!(again, card);
    }
    if let Ok(rig) = SimulatedRig::from_toml(text) {
        assert!(rig.validate().is_ok());
        let again = SimulatedRig::from_toml(&rig.to_toml()).expect("its own file loads");
        assert_eq!(again, rig);
    }
});
