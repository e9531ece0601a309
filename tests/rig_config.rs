//! The card file (`lab::RigConfig`): round trip, and every way a field can
//! be wrong (wrong type, missing, unknown, refused value) named by its
//! dotted key.

// Built on the two-cart lab (its plant, simulated rig or card).
#![cfg(feature = "lab")]

use ctrlab::hw::RegisterMap;
use ctrlab::lab::{Calibration, FileError, FileErrorKind, RigConfig};

fn lab() -> RigConfig {
    RigConfig {
        map: RegisterMap::default(),
        calibration: Calibration::default(),
    }
}

/// A card that differs from the defaults in every field, so a field the
/// file drops or mixes up cannot come back equal by luck.
fn unusual() -> RigConfig {
    let mut config = lab();
    let map = &mut config.map;
    map.id = 0x3f;
    map.control = 0x02;
    map.latch_bit = 0x10;
    map.clear_bit = 0x20;
    map.watchdog_bit = 0x80;
    map.pwm_low = [0x40, 0x42, 0x44, 0x46];
    map.pwm_high = [0x41, 0x43, 0x45, 0x47];
    map.encoder = [0x80, 0x84, 0x88, 0xfc];
    let cal = &mut config.calibration;
    cal.metres_per_count = 0.1 / 4096.0;
    cal.sign = [-1.0, 1.0];
    cal.volts_full_scale = 12.5;
    cal.pwm_channel = 3;
    cal.encoder_channels = [2, 0];
    cal.travel_limits = [0.031, 0.047];
    cal.card_id = 0x3c;
    cal.watchdog_timeout = Some(0.25);
    cal.max_speed = 1.5;
    cal.stall_volts = 4.5;
    cal.stall_time = 0.75;
    cal.stall_counts = 7;
    config
}

/// The dotted key of every field the file has, from the file itself.
fn keys(text: &str) -> Vec<String> {
    let mut section = String::new();
    let mut keys = Vec::new();
    for line in text.lines() {
        if let Some(header) = line.strip_prefix('[') {
            section = header.trim_end_matches(']').to_owned();
        } else if let Some((key, _)) = line.split_once(" = ") {
            keys.push(format!("{section}.{key}"));
        }
    }
    keys
}

/// `text` with the value of dotted `key` replaced by `value`.
fn with_value(text: &str, key: &str, value: &str) -> String {
    let (section, name) = key.split_once('.').unwrap();
    let mut current = "";
    let mut out = String::new();
    let mut replaced = false;
    for line in text.lines() {
        if let Some(header) = line.strip_prefix('[') {
            current = header.trim_end_matches(']');
        }
        if current == section && line.starts_with(&format!("{name} = ")) {
            out.push_str(&format!("{name} = {value}\n"));
            replaced = true;
        } else {
            out.push_str(line);
            out.push('\n');
        }
    }
    assert!(replaced, "{key} not in the file");
    out
}

/// `text` without the line of dotted `key`.
fn without(text: &str, key: &str) -> String {
    let (section, name) = key.split_once('.').unwrap();
    let mut current = "";
    let mut out = String::new();
    for line in text.lines() {
        if let Some(header) = line.strip_prefix('[') {
            current = header.trim_end_matches(']');
        }
        if !(current == section && line.starts_with(&format!("{name} = "))) {
            out.push_str(line);
            out.push('\n');
        }
    }
    out
}

/// The key a refused file names, with the whole error for the message.
fn refused_key(text: &str) -> (Option<String>, String) {
    match RigConfig::from_toml(text) {
        Err(e) => (e.key().map(str::to_owned), e.to_string()),
        other => panic!("expected a TOML error, got {other:?} for\n{text}"),
    }
}

#[test]
fn round_trip_is_exact() {
    for config in [lab(), unusual()] {
        let text = config.to_toml();
        assert_eq!(RigConfig::from_toml(&text).unwrap(), config, "{text}");
    }
    let none = RigConfig {
        calibration: Calibration {
            watchdog_timeout: None,
            ..Calibration::default()
        },
        ..lab()
    };
    let text = none.to_toml();
    assert!(text.contains("watchdog_timeout = \"none\""), "{text}");
    assert_eq!(RigConfig::from_toml(&text).unwrap(), none);
}

#[test]
fn the_file_is_commented_and_in_hex_where_it_helps() {
    let text = lab().to_toml();
    for expected in [
        "[map]",
        "[calibration]",
        "id = 0x00",
        "pwm_high = [0x11, 0x13, 0x15, 0x17]",
        "card_id = 0xa5",
        "metres_per_count = 0.000009765625",
        "# m per encoder count",
        "# m/s: a faster count change is a bus fault",
    ] {
        assert!(text.contains(expected), "{expected} missing from\n{text}");
    }
    // Every key written has a comment.
    for line in text.lines().filter(|l| l.contains(" = ")) {
        assert!(line.contains(" # "), "no comment: {line}");
    }
}

#[test]
fn the_file_has_every_field_of_both_structs() {
    let keys = keys(&lab().to_toml());
    assert_eq!(keys.len(), 8 + 12, "{keys:?}");
    assert!(keys.iter().filter(|k| k.starts_with("map.")).count() == 8);
}

#[test]
fn a_value_of_the_wrong_type_names_its_key() {
    let text = unusual().to_toml();
    for key in keys(&text) {
        let bad = with_value(&text, &key, "\"oops\"");
        let (named, message) = refused_key(&bad);
        assert_eq!(named.as_deref(), Some(key.as_str()), "{message}");
        assert!(message.contains(&key), "{message}");
        let kind = RigConfig::from_toml(&bad).unwrap_err().kind();
        assert_eq!(kind, FileErrorKind::WrongType, "{message}");
    }
}

#[test]
fn a_missing_key_is_refused_and_named() {
    let text = unusual().to_toml();
    for key in keys(&text) {
        let bad = without(&text, &key);
        let (named, message) = refused_key(&bad);
        assert_eq!(named.as_deref(), Some(key.as_str()), "{message}");
        assert!(message.contains("missing"), "{message}");
        let kind = RigConfig::from_toml(&bad).unwrap_err().kind();
        assert_eq!(kind, FileErrorKind::MissingKey, "{message}");
    }
    for table in ["map", "calibration"] {
        let text = lab().to_toml();
        let header = format!("\n[{table}]");
        let cut: String = if table == "map" {
            text[text.find("\n[calibration]").unwrap()..].to_owned()
        } else {
            text[..text.find(&header).unwrap()].to_owned()
        };
        let (named, message) = refused_key(&cut);
        assert_eq!(named.as_deref(), Some(table), "{message}");
    }
}

#[test]
fn an_unknown_key_is_refused_and_named() {
    let text = lab().to_toml();
    for (section, typo) in [("map", "encoders"), ("calibration", "travel_limit")] {
        let header = format!("\n[{section}]\n");
        let bad = text.replace(&header, &format!("{header}{typo} = 1\n"));
        let (named, message) = refused_key(&bad);
        assert_eq!(named, Some(format!("{section}.{typo}")), "{message}");
        let kind = RigConfig::from_toml(&bad).unwrap_err().kind();
        assert_eq!(kind, FileErrorKind::UnknownKey, "{message}");
        let line = bad.lines().position(|l| l.starts_with(typo)).unwrap() + 1;
        assert!(
            message.starts_with(&format!("TOML line {line},")),
            "{message}"
        );
    }
    let (named, message) = refused_key(&format!("period = 0.002\n{text}"));
    assert_eq!(named.as_deref(), Some("period"), "{message}");
}

#[test]
fn a_bad_value_names_its_key_and_line() {
    let text = lab().to_toml();
    for (key, value, says) in [
        // Out of the type's range: refused by the parser.
        ("map.id", "256", "expected u8"),
        ("map.control", "-1", "expected u8"),
        ("map.latch_bit", "0x100", "expected u8"),
        ("calibration.pwm_channel", "-1", "expected usize"),
        ("calibration.card_id", "300", "expected u8"),
        // RegisterMap::validate: a clash names the later of the two (an
        // array's element, by its index).
        ("map.control", "0x00", "refused"),
        ("map.latch_bit", "0x00", "refused"),
        ("map.clear_bit", "0x01", "refused"),
        ("map.watchdog_bit", "0x03", "refused"),
        ("map.pwm_low[2]", "[0x10, 0x12, 0x01, 0x16]", "refused"),
        ("map.pwm_high[3]", "[0x11, 0x13, 0x15, 0x10]", "refused"),
        ("map.encoder[3]", "[0x20, 0x24, 0x28, 0xfd]", "refused"),
        // Calibration::validate.
        ("calibration.metres_per_count", "0.0", "refused"),
        ("calibration.sign[1]", "[1.0, 0.5]", "refused"),
        ("calibration.volts_full_scale", "-24.0", "refused"),
        ("calibration.pwm_channel", "4", "refused"),
        ("calibration.encoder_channels[1]", "[1, 1]", "refused"),
        ("calibration.travel_limits[1]", "[0.05, -0.05]", "refused"),
        ("calibration.card_id", "0xff", "refused"),
        ("calibration.watchdog_timeout", "0.0", "refused"),
        ("calibration.max_speed", "nan", "refused"),
        ("calibration.stall_volts", "0.0", "refused"),
        ("calibration.stall_time", "-inf", "refused"),
        ("calibration.stall_counts", "0", "refused"),
    ] {
        let written = key.split('[').next().unwrap();
        let bad = with_value(&text, written, value);
        let name = written.split_once('.').unwrap().1;
        let line = bad
            .lines()
            .position(|l| l.starts_with(&format!("{name} = ")))
            .map(|i| i + 1);
        match RigConfig::from_toml(&bad) {
            Err(e) => {
                let message = e.to_string();
                assert_eq!(e.key(), Some(key), "{message}");
                assert_eq!(e.line(), line, "{key}: {message}");
                assert!(message.contains(says), "{key}: {message}");
                let kind = if says == "refused" {
                    FileErrorKind::Invalid
                } else {
                    FileErrorKind::WrongType
                };
                assert_eq!(e.kind(), kind, "{key}: {message}");
            }
            other => panic!("expected {key} refused, got {other:?}"),
        }
    }
    // An array element: the key names the element.
    let (named, message) =
        refused_key(&with_value(&text, "map.encoder", "[0x20, 0x24, 0x28, 999]"));
    assert_eq!(named.as_deref(), Some("map.encoder[3]"), "{message}");
    // The one field with no value check: any byte is an address.
    assert!(RigConfig::from_toml(&with_value(&text, "map.id", "0x7f")).is_ok());
}

#[test]
fn the_watchdog_is_a_number_or_none_and_nothing_else() {
    let text = lab().to_toml();
    let (named, message) = refused_key(&with_value(
        &text,
        "calibration.watchdog_timeout",
        "\"off\"",
    ));
    assert_eq!(named.as_deref(), Some("calibration.watchdog_timeout"));
    assert!(message.contains("\"none\""), "{message}");
    let integer = with_value(&text, "calibration.watchdog_timeout", "1");
    assert_eq!(
        RigConfig::from_toml(&integer)
            .unwrap()
            .calibration
            .watchdog_timeout,
        Some(1.0)
    );
}

#[test]
fn a_syntax_error_quotes_its_line() {
    let text = lab()
        .to_toml()
        .replace("stall_counts = 3", "stall_counts = = 3");
    match RigConfig::from_toml(&text) {
        Err(FileError::Syntax {
            line: Some(line),
            message,
            ..
        }) => {
            assert_eq!(
                text.lines().nth(line - 1).map(str::trim_start),
                Some(
                    text.lines()
                        .find(|l| l.starts_with("stall_counts"))
                        .unwrap()
                )
            );
            assert!(message.contains("reads `stall_counts = = 3"), "{message}");
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn write_refuses_an_invalid_config_and_writes_nothing() {
    let dir = std::env::temp_dir().join(format!("ctrlab-rig-config-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("card.toml");
    let mut bad = lab();
    bad.calibration.card_id = 0x00;
    match bad.write_toml(&path) {
        Err(e) => assert_eq!(e.key(), Some("calibration.card_id")),
        other => panic!("{other:?}"),
    }
    assert!(!path.exists());
    unusual().write_toml(&path).unwrap();
    assert_eq!(RigConfig::read_toml(&path).unwrap(), unusual());
    assert!(!dir.join("card.toml.tmp").exists());
    // Into a directory that does not exist: an I/O error with the path.
    let nowhere = dir.join("no/such/dir/card.toml");
    match lab().write_toml(&nowhere) {
        Err(e @ FileError::Io { .. }) => {
            assert_eq!(e.path(), Some(nowhere.as_path()));
            assert!(e.to_string().starts_with("writing "), "{e}");
            assert!(e.to_string().contains("card.toml"), "{e}");
        }
        other => panic!("{other:?}"),
    }
    // Reading: the path, and a parse error in the file says it too.
    let err = RigConfig::read_toml(&nowhere).unwrap_err();
    assert_eq!(err.kind(), FileErrorKind::Io);
    std::fs::write(&path, "[map]\nid = 0x00 0x01\n").unwrap();
    let err = RigConfig::read_toml(&path).unwrap_err();
    assert_eq!(
        (err.kind(), err.path(), err.line()),
        (FileErrorKind::Syntax, Some(path.as_path()), Some(2))
    );
    assert!(
        err.to_string()
            .starts_with(&format!("{}: TOML line 2", path.display())),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).ok();
}
