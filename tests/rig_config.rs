//! The lab's TOML files. The card file (`lab::RigConfig`): round trip, and
//! every way a field can be wrong (wrong type, missing, unknown, refused
//! value) named by its dotted key. The simulated rig's truth file
//! (`lab::SimulatedRig`): defaults, unknown keys, round trip, and a bad
//! value giving the same error from the file as from code, including what
//! used to fail later under a name the file does not have.

// Built on the two-cart lab (its plant, simulated rig or card).
#![cfg(feature = "lab")]

use ctrlab::MassSpring;
use ctrlab::hw::{Clock, RegisterMap};
use ctrlab::lab::ident_input::{IdentInput, IdentSignal};
use ctrlab::lab::{
    Calibration, CardSettings, FileError, FileErrorKind, Friction, RigConfig, SimulatedRig,
    Unmodelled,
};

fn lab() -> RigConfig {
    RigConfig::new(RegisterMap::default(), Calibration::default())
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
    cal.no_watchdog_acknowledged = true;
    cal.follow_time = 0.02;
    cal.max_saturation_time = 1.5;
    config.port.data_dir = true;
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
    // 8 of the map, 15 of the calibration (12, and the safety keys
    // no_watchdog_acknowledged, follow_time, max_saturation_time), 1 of the
    // port.
    assert_eq!(keys.len(), 8 + 15 + 1, "{keys:?}");
    assert!(keys.iter().filter(|k| k.starts_with("map.")).count() == 8);
    assert_eq!(keys.last().map(String::as_str), Some("port.data_dir"));
}

#[test]
fn the_port_table_and_its_key_default_to_no_data_direction_bit() {
    let text = unusual().to_toml();
    assert!(text.contains("[port]\ndata_dir = true"), "{text}");
    // The key left out, then the whole table: the default, `false`.
    let no_key = without(&text, "port.data_dir");
    let no_table = &text[..text.find("\n[port]").unwrap()];
    for cut in [no_key.as_str(), no_table] {
        let config = RigConfig::from_toml(cut).unwrap();
        assert!(!config.port.data_dir, "{cut}");
        assert_eq!(
            (config.map, config.calibration),
            (unusual().map, unusual().calibration)
        );
    }
    // A card file from before the key existed reads the same way.
    assert_eq!(
        RigConfig::from_toml(no_table).unwrap().port,
        Default::default()
    );
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
    // [port]'s keys default (the test above); every other key is required.
    for key in keys(&text).into_iter().filter(|k| !k.starts_with("port.")) {
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
    for (section, typo) in [
        ("map", "encoders"),
        ("calibration", "travel_limit"),
        ("port", "datadir"),
    ] {
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
        ("calibration.follow_time", "0.0", "refused"),
        ("calibration.max_saturation_time", "-2.0", "refused"),
        ("calibration.no_watchdog_acknowledged", "1", "invalid type"),
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

// ---- truth files: the same bad value, the same error from file and code --------

/// A bad value of a simulated rig's truth file and the same value set in
/// code: `from_toml` refuses the file with `FileError::Invalid` holding the
/// very error `validate` gives the rig, named by the file's key, at the
/// line the key is written on.
fn same_error(file: &str, code: &SimulatedRig, key: &str) {
    let from_code = code.validate().unwrap_err();
    assert_eq!(from_code.key(), key, "{from_code}");
    match SimulatedRig::from_toml(file) {
        Err(FileError::Invalid { error, line, .. }) => {
            // Debug, so that a NaN value compares equal to itself.
            assert_eq!(format!("{error:?}"), format!("{from_code:?}"), "{file}");
            let written = key.split('[').next().unwrap().rsplit('.').next().unwrap();
            let at = file
                .lines()
                .position(|l| l.trim_start().starts_with(&format!("{written} =")))
                .map(|i| i + 1);
            assert_eq!(line, at, "{file}");
        }
        other => panic!("expected {key} refused, got {other:?} for\n{file}"),
    }
    // The card and the rig refuse it with the same error.
    assert_eq!(
        format!("{:?}", code.card(&Clock::RealTime).unwrap_err()),
        format!("{from_code:?}")
    );
}

#[test]
fn a_bad_truth_value_gives_the_same_error_from_a_file_and_from_code() {
    let d = SimulatedRig::default();
    let cases: Vec<(&str, SimulatedRig, &str)> = vec![
        (
            "[truth]\nm2 = 0.0",
            SimulatedRig {
                truth: MassSpring { m2: 0.0, ..d.truth },
                ..d.clone()
            },
            "truth.m2",
        ),
        (
            "[friction]\ncoulomb = [1.0, -2.0]",
            SimulatedRig {
                friction: Friction {
                    coulomb: [1.0, -2.0],
                    ..d.friction
                },
                ..d.clone()
            },
            "friction.coulomb[1]",
        ),
        (
            "[friction]\nstiction = [nan, 2.4]",
            SimulatedRig {
                friction: Friction {
                    stiction: [f64::NAN, 2.4],
                    ..d.friction
                },
                ..d.clone()
            },
            "friction.stiction[0]",
        ),
        (
            "[card]\nencoder_noise = -0.5",
            SimulatedRig {
                card: CardSettings {
                    encoder_noise: -0.5,
                    ..d.card
                },
                ..d.clone()
            },
            "card.encoder_noise",
        ),
        (
            "[card]\nmax_substep = 0.0",
            SimulatedRig {
                card: CardSettings {
                    max_substep: 0.0,
                    ..d.card
                },
                ..d.clone()
            },
            "card.max_substep",
        ),
        (
            "[card.map]\nencoder = [0x20, 0x24, 0x28, 0xfd]",
            SimulatedRig {
                card: CardSettings {
                    map: RegisterMap {
                        encoder: [0x20, 0x24, 0x28, 0xfd],
                        ..d.card.map
                    },
                    ..d.card
                },
                ..d.clone()
            },
            "card.map.encoder[3]",
        ),
        (
            "[calibration]\ntravel_limits = [0.05, -0.05]",
            SimulatedRig {
                calibration: Calibration {
                    travel_limits: [0.05, -0.05],
                    ..d.calibration
                },
                ..d.clone()
            },
            "calibration.travel_limits[1]",
        ),
        (
            "[calibration]\nwatchdog_timeout = nan",
            SimulatedRig {
                calibration: Calibration {
                    watchdog_timeout: Some(f64::NAN),
                    ..d.calibration
                },
                ..d.clone()
            },
            "calibration.watchdog_timeout",
        ),
        (
            "[calibration]\nencoder_channels = [1, 1]",
            SimulatedRig {
                calibration: Calibration {
                    encoder_channels: [1, 1],
                    ..d.calibration
                },
                ..d.clone()
            },
            "calibration.encoder_channels[1]",
        ),
        (
            "period = 0.0",
            SimulatedRig {
                period: 0.0,
                ..d.clone()
            },
            "period",
        ),
        (
            "initial_state = [0.0, 0.0, inf, 0.0]",
            SimulatedRig {
                initial_state: [0.0, 0.0, f64::INFINITY, 0.0],
                ..d.clone()
            },
            "initial_state[2]",
        ),
    ];
    for (file, code, key) in &cases {
        same_error(file, code, key);
    }
}

#[test]
fn what_would_fail_later_under_another_name_is_refused_under_the_files_key() {
    let d = SimulatedRig::default();
    // A Coulomb force so small that the stiction over it overflows: it
    // validated, and failed later as the simulation model's
    // `stiction_ratio = inf`.
    let tiny = SimulatedRig {
        friction: Friction {
            coulomb: [5e-324, 2.0],
            ..d.friction
        },
        ..d.clone()
    };
    let later = tiny.simulation_model().validate().unwrap_err();
    assert!(later.to_string().contains("stiction_ratio"), "{later}");
    same_error(
        "[friction]\ncoulomb = [5e-324, 2.0]",
        &tiny,
        "friction.coulomb[0]",
    );
    // A resolution whose travel per revolution overflows on the card
    // (the old `travel_per_revolution = 1e300` over
    // `counts_per_revolution = 1e-300`, which failed later as
    // `metres_per_count = inf`): named by the file's one resolution key.
    let coarse = SimulatedRig {
        calibration: Calibration {
            metres_per_count: 1e306,
            ..d.calibration
        },
        ..d.clone()
    };
    same_error(
        "[calibration]\nmetres_per_count = 1e306",
        &coarse,
        "calibration.metres_per_count",
    );
    // A resolution too fine for the card's 32-bit counters.
    let fine = SimulatedRig {
        calibration: Calibration {
            metres_per_count: 1e-300,
            ..d.calibration
        },
        ..d.clone()
    };
    same_error(
        "[calibration]\nmetres_per_count = 1e-300",
        &fine,
        "calibration.metres_per_count",
    );
    // A watchdog shorter than two periods: the loop refused it later as
    // `max_gap`.
    let quick = SimulatedRig {
        calibration: Calibration {
            watchdog_timeout: Some(0.003),
            ..d.calibration
        },
        ..d.clone()
    };
    same_error(
        "[calibration]\nwatchdog_timeout = 0.003",
        &quick,
        "calibration.watchdog_timeout",
    );
    // A PWM delay of a period or more: the sampled-data simulation refused
    // it later as `input_delay`.
    let slow = SimulatedRig {
        card: CardSettings {
            pwm_delay: 0.002,
            ..d.card
        },
        ..d.clone()
    };
    assert!(slow.sampled_config(1.0).validate().is_err());
    same_error("[card]\npwm_delay = 0.002", &slow, "card.pwm_delay");
    // A period below the loop's 1 µs: refused later by `hw::run`.
    let fast = SimulatedRig {
        period: 1e-7,
        ..d.clone()
    };
    same_error("period = 1e-7", &fast, "period");
    // A mass so small that an acceleration overflows: the card diverged
    // at its first step.
    let light = SimulatedRig {
        truth: MassSpring {
            m1: 1e-320,
            ..d.truth
        },
        ..d.clone()
    };
    same_error("[truth]\nm1 = 1e-320", &light, "truth.m1");
    // A cart starting beyond its travel limit: the first sample halted the
    // rig.
    let outside = SimulatedRig {
        initial_state: [0.0, 0.0, 0.06, 0.0],
        ..d.clone()
    };
    same_error(
        "initial_state = [0.0, 0.0, 0.06, 0.0]",
        &outside,
        "initial_state[2]",
    );
    // Encoders counting down: the simulated card counts up.
    let reversed = SimulatedRig {
        calibration: Calibration {
            sign: [1.0, -1.0],
            ..d.calibration
        },
        ..d.clone()
    };
    same_error(
        "[calibration]\nsign = [1.0, -1.0]",
        &reversed,
        "calibration.sign[1]",
    );
}

#[test]
fn a_truth_file_keeps_defaults_refuses_unknown_keys_and_round_trips() {
    // Left out: the default; a table given in part keeps the rest.
    let rig = SimulatedRig::from_toml("[truth]\ngain = 1.5\n[card]\nseed = 9").unwrap();
    assert_eq!(rig.truth.gain, 1.5);
    assert_eq!(rig.truth.m1, SimulatedRig::default_truth().m1);
    assert_eq!(rig.card.seed, 9);
    assert_eq!(
        rig.card.encoder_noise,
        CardSettings::default().encoder_noise
    );
    assert_eq!(rig.calibration, Calibration::default());
    // Unknown keys, by their dotted key and line, the old flat layout's
    // among them.
    for (text, key, line) in [
        ("[truth]\ngian = 1.2", "truth.gian", 2),
        ("coulomb_friction = [1.0, 2.0]", "coulomb_friction", 1),
        (
            "[card]\ntravel_per_revolution = 1e300",
            "card.travel_per_revolution",
            2,
        ),
        ("[card.map]\nencoders = 1", "card.map.encoders", 2),
    ] {
        let err = SimulatedRig::from_toml(text).unwrap_err();
        assert_eq!(err.kind(), FileErrorKind::UnknownKey, "{err}");
        assert_eq!((err.key(), err.line()), (Some(key), Some(line)), "{err}");
    }
    // Every key written reads back equal, for a rig unlike the default in
    // every part.
    let unusual = SimulatedRig {
        period: 0.001,
        initial_state: [0.001, 0.0, -0.002, 0.01],
        truth: MassSpring::nominal(),
        friction: Friction::coulomb([0.3, 0.6]),
        unmodelled: Unmodelled {
            rotor_mass: 0.04,
            deadband: 0.1,
            friction_ripple: 0.2,
            ripple_period: 0.03,
            friction_variation: 0.02,
        },
        card: CardSettings {
            encoder_noise: 0.1,
            seed: 3,
            pwm_delay: 0.0001,
            max_substep: 0.0001,
            map: RegisterMap {
                encoder: [0x40, 0x44, 0x48, 0x4c],
                ..RegisterMap::default()
            },
        },
        calibration: Calibration {
            travel_limits: [0.04, 0.045],
            watchdog_timeout: None,
            card_id: 0x3c,
            ..Calibration::default()
        },
        ident: IdentInput {
            signal: IdentSignal::Multisine,
            volts: 5.0,
            half_period: 0.25,
            scale_to_travel: false,
        },
    };
    let text = unusual.to_toml();
    assert_eq!(SimulatedRig::from_toml(&text).unwrap(), unusual, "{text}");
    for table in [
        "[truth]",
        "[friction]",
        "[unmodelled]",
        "[card]",
        "[card.map]",
        "[calibration]",
        "[ident]",
    ] {
        assert!(text.contains(table), "{table} missing from\n{text}");
    }
    // The identification input is written only when it is not lab5's
    // default, as in a card file.
    let default = SimulatedRig::default().to_toml();
    assert!(!default.contains("[ident]"), "{default}");
    assert_eq!(
        SimulatedRig::from_toml(&default).unwrap(),
        SimulatedRig::default()
    );
}

// ---- the safety keys: defaults, checks, the same error from file and code ------

#[test]
fn the_safety_keys_have_defaults_checks_and_the_same_errors_from_file_and_code() {
    let d = Calibration::default();
    assert_eq!(
        (
            d.no_watchdog_acknowledged,
            d.follow_time,
            d.max_saturation_time
        ),
        (false, 0.01, 2.0)
    );
    // A truth file leaving them out keeps the defaults.
    let rig = SimulatedRig::from_toml("[calibration]\nstall_time = 0.4").unwrap();
    assert_eq!(rig.calibration.follow_time, d.follow_time);
    assert_eq!(rig.calibration.max_saturation_time, d.max_saturation_time);
    assert!(!rig.calibration.no_watchdog_acknowledged);
    // A card file must say them (its every key is required): named.
    let text = lab().to_toml();
    for key in [
        "calibration.no_watchdog_acknowledged",
        "calibration.follow_time",
        "calibration.max_saturation_time",
    ] {
        let err = RigConfig::from_toml(&without(&text, key)).unwrap_err();
        assert_eq!(
            (err.kind(), err.key()),
            (FileErrorKind::MissingKey, Some(key))
        );
    }
    // A bad value: the same ConfigError from a truth file, from code, and
    // (under its table) from a card file.
    let base = SimulatedRig::default();
    for (name, value, calibration) in [
        (
            "follow_time",
            "0.0",
            Calibration {
                follow_time: 0.0,
                ..d
            },
        ),
        (
            "follow_time",
            "nan",
            Calibration {
                follow_time: f64::NAN,
                ..d
            },
        ),
        (
            "max_saturation_time",
            "-1.0",
            Calibration {
                max_saturation_time: -1.0,
                ..d
            },
        ),
        (
            "max_saturation_time",
            "inf",
            Calibration {
                max_saturation_time: f64::INFINITY,
                ..d
            },
        ),
    ] {
        let key = format!("calibration.{name}");
        let code = SimulatedRig {
            calibration,
            ..base.clone()
        };
        same_error(&format!("[calibration]\n{name} = {value}"), &code, &key);
        let from_code = calibration.validate().unwrap_err();
        assert_eq!(from_code.key(), name);
        match RigConfig::from_toml(&with_value(&text, &key, value)) {
            Err(FileError::Invalid { error, .. }) => {
                assert_eq!(
                    format!("{error:?}"),
                    format!("{:?}", from_code.in_table("calibration"))
                );
            }
            other => panic!("expected {key} refused, got {other:?}"),
        }
    }
}
