//! The TOML files under hostile values (issue 28): any number put in place
//! of any number of a valid card file or truth file loads as a valid
//! configuration that writes back to itself, or is refused naming the line
//! and the key, the number printed readably.

// The lab's files.
#![cfg(feature = "lab")]

use ctrlab::hw::RegisterMap;
use ctrlab::lab::{Calibration, RigConfig, SimulatedRig};
use proptest::prelude::*;

/// Values that break things: NaN, infinities, extremes, subnormals, signs.
fn wild() -> impl Strategy<Value = f64> {
    prop_oneof![
        3 => -10.0..10.0f64,
        2 => proptest::num::f64::NORMAL,
        1 => proptest::num::f64::SUBNORMAL | proptest::num::f64::ZERO,
        1 => prop::sample::select(vec![f64::NAN, f64::INFINITY, f64::NEG_INFINITY, f64::MAX, -f64::MAX, 1e300, 1e-300, -0.0, 1e-9, 1e9]),
    ]
}

/// `x` as TOML writes a float (`nan`, `inf`, an exponent for extremes).
fn toml_float(x: f64) -> String {
    if x.is_nan() {
        "nan".into()
    } else if x.is_infinite() {
        if x > 0.0 { "inf".into() } else { "-inf".into() }
    } else {
        format!("{x:e}")
    }
}

/// The lines of `text` that set a key to one number (`key = 1.5`), and
/// the text with the `pick`-th of them set to `value`.
fn with_number(text: &str, pick: usize, value: f64) -> Option<(usize, String)> {
    let numeric: Vec<usize> = text
        .lines()
        .enumerate()
        .filter(|(_, l)| {
            let Some((_, v)) = l.split_once(" = ") else {
                return false;
            };
            let v = v.split('#').next().unwrap_or("").trim();
            !l.trim_start().starts_with('#') && v.parse::<f64>().is_ok()
        })
        .map(|(i, _)| i)
        .collect();
    let line = *numeric.get(pick % numeric.len().max(1))?;
    let out: Vec<String> = text
        .lines()
        .enumerate()
        .map(|(i, l)| {
            if i == line {
                let (key, _) = l.split_once(" = ").unwrap();
                format!("{key} = {}", toml_float(value))
            } else {
                l.to_string()
            }
        })
        .collect();
    Some((line + 1, out.join("\n")))
}

fn refused_by_line_and_key(message: &str) -> Result<(), TestCaseError> {
    prop_assert!(message.contains("TOML line "), "no line: {message}");
    prop_assert!(message.contains("key `"), "no key: {message}");
    prop_assert!(
        message.len() <= 400,
        "{} characters: {message}",
        message.len()
    );
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    #[test]
    fn any_number_in_a_truth_file_loads_valid_or_is_refused_by_line_and_key(pick in any::<usize>(), value in wild()) {
        let text = SimulatedRig::default().to_toml();
        let Some((_line, text)) = with_number(&text, pick, value) else { return Ok(()) };
        match SimulatedRig::from_toml(&text) {
            Ok(rig) => {
                prop_assert!(rig.validate().is_ok());
                prop_assert_eq!(SimulatedRig::from_toml(&rig.to_toml()).unwrap(), rig);
            }
            Err(e) => refused_by_line_and_key(&e.to_string())?,
        }
    }

    #[test]
    fn any_number_in_a_card_file_loads_valid_or_is_refused_by_line_and_key(pick in any::<usize>(), value in wild()) {
        let text = RigConfig::new(RegisterMap::default(), Calibration::default()).to_toml();
        let Some((_line, text)) = with_number(&text, pick, value) else { return Ok(()) };
        match RigConfig::from_toml(&text) {
            Ok(card) => {
                prop_assert!(card.validate().is_ok());
                prop_assert_eq!(RigConfig::from_toml(&card.to_toml()).unwrap(), card);
            }
            Err(e) => refused_by_line_and_key(&e.to_string())?,
        }
    }
}
