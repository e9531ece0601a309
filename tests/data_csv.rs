//! `Recording` CSV: units, round trip, and one test per malformed-input case;
//! `Schema` and `Recording::from_columns` refusals.

// Built on the two-cart lab (its plant, simulated rig or card).
#![cfg(feature = "lab")]

use ctrlab::data::{Channel, CsvError, CsvErrorKind, Schema};
use ctrlab::lab::ident::{MIN_SAMPLES, Scheme, identify};
use ctrlab::{Error, Recording};
use proptest::prelude::*;

/// A lab log in the lab's own header (positions in mm, `u` without a unit).
const GOOD: &str = "t_s,u,x1_mm,x2_mm
0.000,2,0,0
0.002,2,0,0.048828125
0.004,2,0,0.1953125
0.006,2,0.009765625,0.4296875
0.008,2,0.029296875,0.751953125
0.010,2,0.068359375,1.1572265625
";

fn csv_err(text: &str) -> (u64, String) {
    match Recording::from_reader(text.as_bytes()) {
        Err(CsvError::Line { line, reason }) => (line, reason),
        other => panic!("expected CsvError::Line, got {other:?}"),
    }
}

fn read(text: &str) -> Recording {
    Recording::from_reader(text.as_bytes()).unwrap()
}

/// `(name, unit)` of every channel, inputs first.
fn channels(rec: &Recording) -> Vec<(String, String)> {
    rec.schema()
        .channels()
        .map(|c| (c.name.clone(), c.unit.clone()))
        .collect()
}

fn pairs(list: &[(&str, &str)]) -> Vec<(String, String)> {
    list.iter()
        .map(|(n, u)| (n.to_string(), u.to_string()))
        .collect()
}

/// Every value (time, then each channel) as bits: equality including the
/// sign of zero.
fn bits(rec: &Recording) -> Vec<u64> {
    let mut out: Vec<u64> = rec.time().iter().map(|v| v.to_bits()).collect();
    for c in rec.schema().channels() {
        out.extend(rec.channel(&c.name).unwrap().iter().map(|v| v.to_bits()));
    }
    out
}

#[test]
fn millimetres_are_read_as_metres() {
    let rec = read(GOOD);
    assert_eq!(rec.len(), 6);
    let x2 = rec.channel("x2").unwrap();
    assert_eq!(x2[1], 0.048828125 / 1000.0);
    assert_eq!(rec.time()[5], 0.010);
    // No velocity columns, so no velocity channels.
    assert!(matches!(rec.channel("v1"), Err(Error::Channel { .. })));
    assert!(matches!(rec.channel("v2"), Err(Error::Channel { .. })));
    // The same run in metres, columns reordered, velocities in mm/s, an
    // extra column (a channel without a unit now, read as it is).
    let (t, x1) = (rec.time(), rec.channel("x1").unwrap());
    let si = "x2_m, u ,t_s,x1_m,v1_mm_s,v2_mm_s,duty\n".to_string()
        + &t.iter()
            .enumerate()
            .map(|(k, t)| format!("{:?},2,{t:?},{:?},{},-{},7\n", x2[k], x1[k], k * 10, k * 20))
            .collect::<String>();
    let rec2 = read(&si);
    for name in ["u", "x1", "x2"] {
        assert_eq!(rec2.channel(name).unwrap(), rec.channel(name).unwrap());
    }
    assert_eq!(rec2.time(), rec.time());
    assert_eq!(rec2.channel("v1").unwrap()[3], 0.030);
    assert_eq!(rec2.channel("v2").unwrap()[2], -0.040);
    assert_eq!(rec2.channel("duty").unwrap(), &[7.0; 6]);
    // Channels keep file order, inputs first; units are SI.
    assert_eq!(
        channels(&rec2),
        pairs(&[
            ("u", ""),
            ("x2", "m"),
            ("x1", "m"),
            ("v1", "m/s"),
            ("v2", "m/s"),
            ("duty", "")
        ])
    );
}

#[test]
fn the_old_lab_header_reads_as_u_x1_x2_in_metres() {
    let rec = read(GOOD);
    let want = Schema::new(
        vec![Channel::new("u", "")],
        vec![Channel::new("x1", "m"), Channel::new("x2", "m")],
    )
    .unwrap();
    assert_eq!(rec.schema(), &want);
    assert_eq!(rec.input(0), Some(&[2.0; 6][..]));
    // Every value in this file is exactly the millimetres / 1000.
    for (line, row) in GOOD.lines().skip(1).enumerate() {
        let f: Vec<f64> = row.split(',').map(|v| v.parse().unwrap()).collect();
        assert_eq!(rec.time()[line], f[0]);
        assert_eq!(rec.channel("u").unwrap()[line], f[1]);
        assert_eq!(rec.channel("x1").unwrap()[line], f[2] / 1000.0);
        assert_eq!(rec.channel("x2").unwrap()[line], f[3] / 1000.0);
    }
}

#[test]
fn fixture_reads_with_its_documented_shape() {
    let rec = Recording::read_csv(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/ident_square_wave.csv"
    ))
    .unwrap();
    assert_eq!(rec.len(), 2500);
    assert!((rec.sample_period().unwrap() - 0.002).abs() < 1e-12);
    assert!(rec.channel("u").unwrap().iter().all(|u| u.abs() == 2.0));
    assert_eq!(
        channels(&rec),
        pairs(&[("u", ""), ("x1", "m"), ("x2", "m")])
    );
}

#[test]
fn bracketed_units_and_time_units_are_read() {
    // `name [unit]` and `name (unit)`: known units converted to SI, other
    // units kept as they are; time in milliseconds.
    let text = "t [ms], u [V] ,x1 [mm],v1 [mm/s],angle [deg],w (rad/s)\n\
                0,1.5,1,10,90,0.5\n\
                2,1.5,2,20,45,0.25\n\
                4,-1.5,4,-30,0,0\n";
    let rec = read(text);
    assert_eq!(
        channels(&rec),
        pairs(&[
            ("u", "V"),
            ("x1", "m"),
            ("v1", "m/s"),
            ("angle", "deg"),
            ("w", "rad/s")
        ])
    );
    assert_eq!(rec.time(), &[0.0, 0.002, 0.004]);
    assert_eq!(rec.channel("u").unwrap(), &[1.5, 1.5, -1.5]);
    assert_eq!(rec.channel("x1").unwrap(), &[1e-3, 2e-3, 4e-3]);
    assert_eq!(rec.channel("v1").unwrap(), &[0.010, 0.020, -0.030]);
    assert_eq!(rec.channel("angle").unwrap(), &[90.0, 45.0, 0.0]);
    assert_eq!(rec.channel("w").unwrap(), &[0.5, 0.25, 0.0]);
    assert!((rec.sample_period().unwrap() - 0.002).abs() < 1e-15);

    // The writer uses `name_unit` for the known SI units and `name [unit]`
    // for the others, and the result reads back identical.
    let mut out = Vec::new();
    rec.to_writer(&mut out).unwrap();
    let out = String::from_utf8(out).unwrap();
    assert_eq!(
        out.lines().next(),
        Some("t_s,u_V,x1_m,v1_m_s,angle [deg],w_rad_s")
    );
    let back = read(&out);
    assert_eq!(back, rec);
    assert_eq!(bits(&back), bits(&rec));

    // `t [s]` and `time_s` are time columns too.
    for header in ["t [s]", "time_s", "t (s)"] {
        let rec = read(&format!("{header},y\n0,1\n0.5,2\n"));
        assert_eq!(rec.time(), &[0.0, 0.5], "{header}");
        assert_eq!(channels(&rec), pairs(&[("y", "")]), "{header}");
    }
}

#[test]
fn lab_schema_round_trip_is_exact() {
    let schema = ctrlab::lab::schema();
    let mut rec = Recording::with_capacity(schema.clone(), 50);
    for k in 0..50 {
        let t = k as f64 * 0.002;
        let s = (k as f64 * 0.37).sin();
        rec.push(
            t,
            &[if k % 20 < 10 { 2.0 } else { -2.0 }],
            &[
                s * 1e-3 / 3.0,
                -0.1 * s,
                0.0123456789 * s,
                1.0 / (k as f64 + 3.0),
            ],
        )
        .unwrap();
    }
    let mut out = Vec::new();
    rec.to_writer(&mut out).unwrap();
    let text = String::from_utf8(out).unwrap();
    assert_eq!(text.lines().next(), Some("t_s,u_V,x1_m,v1_m_s,x2_m,v2_m_s"));
    assert_eq!(text.lines().count(), 51);
    let back = read(&text);
    assert_eq!(back.schema(), &schema);
    assert_eq!(back, rec);
    assert_eq!(bits(&back), bits(&rec));
}

#[test]
fn each_malformed_input_names_its_line() {
    assert_eq!(csv_err("").0, 1);
    // Two columns for one channel (x1 in m and in mm).
    let (line, reason) = csv_err(&GOOD.replace("t_s,u,", "t_s,u,x1_m,"));
    assert_eq!(line, 1, "duplicate column");
    assert!(
        reason.contains("x1") && reason.contains("twice"),
        "{reason}"
    );

    // Non-number on data line 4 (file line 4).
    let (line, reason) = csv_err(&GOOD.replace("0.004,2,0,0.1953125", "0.004,2,zero,0.1953125"));
    assert_eq!(line, 4);
    assert!(reason.contains("x1") && reason.contains("zero"), "{reason}");
    assert_eq!(csv_err(&GOOD.replace("0.006,2,", "0.006,NaN,")).0, 5);
    assert_eq!(csv_err(&GOOD.replace("0.006,2,", "0.006,inf,")).0, 5);
    // Wrong number of fields on line 3.
    assert_eq!(
        csv_err(&GOOD.replace("0.002,2,0,0.048828125", "0.002,2,0")).0,
        3
    );

    // Time goes backwards on line 5.
    let (line, reason) = csv_err(&GOOD.replace("0.006,", "0.003,"));
    assert_eq!(line, 5);
    assert!(reason.contains("does not increase"), "{reason}");
    // Repeated time stamp.
    assert_eq!(csv_err(&GOOD.replace("0.006,", "0.004,")).0, 5);
    // Irregular: one sample 0.5 ms late (25 % of the interval), line 6. The
    // reader keeps it (a rig records its actual instants); the recording
    // has no uniform sampling period, and says where.
    let late = Recording::from_reader(GOOD.replace("0.008,", "0.0085,").as_bytes()).unwrap();
    match late.sample_period() {
        Err(Error::InvalidRecording { index, reason }) => {
            assert_eq!(index, 4); // the fifth sample, line 6
            assert!(
                reason.contains("irregular") && reason.contains('%'),
                "{reason}"
            );
        }
        other => panic!("expected InvalidRecording, got {other:?}"),
    }

    // Too few rows (the reader needs 2): reported on the last line.
    let one_row: String = GOOD.lines().take(2).map(|l| format!("{l}\n")).collect();
    let (line, reason) = csv_err(&one_row);
    assert_eq!(line, 2);
    assert!(reason.contains("at least 2"), "{reason}");
    assert_eq!(csv_err("t_s,u,x1_m,x2_m\n").0, 1);
    // Invalid UTF-8 on line 3.
    let mut bytes = GOOD.as_bytes().to_vec();
    let at = GOOD.find("0.002").unwrap();
    bytes[at] = 0xff;
    assert!(matches!(
        Recording::from_reader(&bytes[..]),
        Err(CsvError::Line { line: 3, .. })
    ));
}

#[test]
fn time_column_errors_show_the_header() {
    // Missing: the message shows the header that was found.
    let (line, reason) = csv_err(&GOOD.replace("t_s,", "time_stamp,"));
    assert_eq!(line, 1);
    assert!(reason.contains("missing a time column"), "{reason}");
    assert!(
        reason.contains("`time_stamp,u,x1_mm,x2_mm`"),
        "header not shown: {reason}"
    );
    // Duplicated (in two units).
    let (line, reason) = csv_err("t_s,u,t_ms\n0,1,0\n0.002,1,2\n");
    assert_eq!(line, 1);
    assert!(
        reason.contains("two time columns") && reason.contains("t_s,u,t_ms"),
        "{reason}"
    );
    // A time column without a time unit.
    let (line, reason) = csv_err(&GOOD.replace("t_s,", "t,"));
    assert_eq!(line, 1);
    assert!(
        reason.contains("no time unit") && reason.contains("t,u,x1_mm,x2_mm"),
        "{reason}"
    );
}

#[test]
fn the_generic_reader_accepts_what_the_lab_identification_refuses() {
    // Before the refactor the reader itself refused these lab logs: a
    // missing x1/x2 column, a position without a unit, an unpaired velocity
    // and fewer than six rows. The reader now takes any uniform file with
    // named channels; the lab's identification asks for its own channels
    // (`u`, `x1`, `x2`) and rows (`MIN_SAMPLES`).

    // No x2 column: x3 is just another channel, in metres.
    let rec = read(&GOOD.replace("x2_mm", "x3_mm"));
    assert_eq!(
        channels(&rec),
        pairs(&[("u", ""), ("x1", "m"), ("x3", "m")])
    );
    match identify(&rec, 1.3, 0.7, Scheme::Central) {
        Err(Error::Channel { name, reason }) => {
            assert_eq!(name, "x2");
            assert!(reason.contains("t, u, x1, x3"), "{reason}");
        }
        other => panic!("expected Error::Channel, got {other:?}"),
    }
    // No x1 column.
    let rec = read(&GOOD.replace("x1_mm", "y1_mm"));
    match identify(&rec, 1.3, 0.7, Scheme::Lab) {
        Err(Error::Channel { name, reason }) => {
            assert_eq!(name, "x1");
            assert!(reason.contains("t, u, y1, x2"), "{reason}");
        }
        other => panic!("expected Error::Channel, got {other:?}"),
    }

    // A column without a unit is a channel without a unit, values as read.
    let rec = read(&GOOD.replace("x1_mm", "x1"));
    assert_eq!(channels(&rec), pairs(&[("u", ""), ("x1", ""), ("x2", "m")]));
    assert_eq!(rec.channel("x1").unwrap()[5], 0.068359375);

    // One velocity without the other.
    let rec = read(
        &GOOD
            .replace("x2_mm\n", "x2_mm,v1_mm_s\n")
            .lines()
            .enumerate()
            .map(|(k, l)| {
                if k == 0 {
                    format!("{l}\n")
                } else {
                    format!("{l},{k}\n")
                }
            })
            .collect::<String>(),
    );
    assert_eq!(rec.channel("v1").unwrap()[2], 0.003);
    assert!(rec.channel("v2").is_err());

    // Three rows read; identification needs MIN_SAMPLES.
    let short: String = GOOD.lines().take(4).map(|l| format!("{l}\n")).collect();
    let rec = read(&short);
    assert_eq!(rec.len(), 3);
    assert_eq!(MIN_SAMPLES, 6);
    assert!(matches!(
        identify(&rec, 1.3, 0.7, Scheme::Lab),
        Err(Error::TooFewSamples {
            needed: MIN_SAMPLES,
            got: 3,
            ..
        })
    ));
}

#[test]
fn missing_file_is_an_io_error_with_the_path() {
    match Recording::read_csv("/no/such/dir/log.csv") {
        Err(e @ CsvError::Io { .. }) => {
            assert_eq!(e.kind(), CsvErrorKind::Io);
            assert!(e.to_string().contains("/no/such/dir/log.csv"), "{e}");
            // The io::Error itself, as the source.
            let source = std::error::Error::source(&e).unwrap();
            let io = source.downcast_ref::<std::io::Error>().unwrap();
            assert_eq!(io.kind(), std::io::ErrorKind::NotFound);
            let CsvError::Io { context, source } = e else {
                unreachable!()
            };
            assert!(context.contains("/no/such/dir/log.csv"));
            assert_eq!(source.kind(), std::io::ErrorKind::NotFound);
        }
        other => panic!("expected Io, got {other:?}"),
    }
    // Writing into a directory that is not there.
    let rec = read(GOOD);
    match rec.write_csv("/no/such/dir/log.csv") {
        Err(CsvError::Io { context, source }) => {
            assert!(
                context.contains("creating /no/such/dir/log.csv"),
                "{context}"
            );
            assert_eq!(source.kind(), std::io::ErrorKind::NotFound);
        }
        other => panic!("expected Io, got {other:?}"),
    }
}

#[test]
fn file_round_trip_and_writer_refusals() {
    let rec = read(GOOD);
    let path = std::env::temp_dir().join(format!("ctrlab_round_trip_{}.csv", std::process::id()));
    rec.write_csv(&path).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    let back = Recording::read_csv(&path).unwrap();
    std::fs::remove_file(&path).unwrap();
    assert_eq!(text.lines().next(), Some("t_s,u,x1_m,x2_m"));
    assert_eq!(back, rec);

    // A ragged recording cannot be built any more (see
    // `from_columns_refuses_inconsistent_columns`); a non-finite value can,
    // and the writer refuses it.
    let mut nan = rec;
    nan.channel_mut("u").unwrap()[2] = f64::NAN;
    assert!(matches!(
        nan.to_writer(Vec::new()),
        Err(CsvError::Recording {
            source: Error::InvalidRecording { index: 2, .. }
        })
    ));
    let path = std::env::temp_dir().join(format!("ctrlab_nan_{}.csv", std::process::id()));
    let err = nan.write_csv(&path).unwrap_err();
    assert!(
        matches!(
            err,
            CsvError::Recording {
                source: Error::InvalidRecording { index: 2, .. }
            }
        ),
        "{err:?}"
    );
    assert_eq!(err.kind(), CsvErrorKind::Recording);
    // The message keeps the numeric error's.
    assert!(err.to_string().contains("u = NaN"), "{err}");
    // Refused before the file is created.
    assert!(!path.exists());
    let mut late = read(GOOD);
    late.time_mut()[4] = f64::INFINITY;
    assert!(matches!(
        late.to_writer(Vec::new()),
        Err(CsvError::Recording {
            source: Error::InvalidRecording { index: 4, .. }
        })
    ));
}

#[test]
fn from_columns_refuses_inconsistent_columns() {
    let schema = Schema::numbered(1, 2).unwrap();
    let t = vec![0.0, 0.1, 0.2];
    let ok = Recording::from_columns(
        schema.clone(),
        t.clone(),
        vec![vec![1.0; 3], vec![0.0, 0.5, 1.0], vec![2.0; 3]],
    )
    .unwrap();
    assert_eq!(ok.channel("y1").unwrap(), &[0.0, 0.5, 1.0]);
    assert_eq!(ok.measurement(1), Some(&[2.0; 3][..]));

    // One column per channel.
    assert!(matches!(
        Recording::from_columns(schema.clone(), t.clone(), vec![vec![1.0; 3], vec![0.0; 3]]),
        Err(Error::LengthMismatch {
            expected: 3,
            found: 2,
            ..
        })
    ));
    // Every column as long as the time column.
    assert!(matches!(
        Recording::from_columns(
            schema.clone(),
            t.clone(),
            vec![vec![1.0; 3], vec![0.0; 2], vec![2.0; 3]]
        ),
        Err(Error::LengthMismatch {
            expected: 3,
            found: 2,
            ..
        })
    ));
    // Finite values, time included.
    assert!(matches!(
        Recording::from_columns(
            schema.clone(),
            t.clone(),
            vec![vec![1.0; 3], vec![0.0, 0.0, f64::NAN], vec![2.0; 3]]
        ),
        Err(Error::InvalidRecording { index: 2, .. })
    ));
    assert!(matches!(
        Recording::from_columns(
            schema.clone(),
            vec![0.0, f64::NEG_INFINITY, 0.2],
            vec![vec![1.0; 3], vec![0.0; 3], vec![2.0; 3]]
        ),
        Err(Error::InvalidRecording { index: 1, .. })
    ));
    // Strictly increasing time.
    for bad in [vec![0.0, 0.1, 0.1], vec![0.0, 0.2, 0.1]] {
        match Recording::from_columns(
            schema.clone(),
            bad,
            vec![vec![1.0; 3], vec![0.0; 3], vec![2.0; 3]],
        ) {
            Err(Error::InvalidRecording { index, reason }) => {
                assert_eq!(index, 2);
                assert!(reason.contains("does not increase"), "{reason}");
            }
            other => panic!("expected InvalidRecording, got {other:?}"),
        }
    }
    // Increasing but irregular is a valid recording; it has no sampling
    // period.
    let irregular = Recording::from_columns(
        schema,
        vec![0.0, 0.1, 0.3],
        vec![vec![1.0; 3], vec![0.0; 3], vec![2.0; 3]],
    )
    .unwrap();
    assert!(matches!(
        irregular.sample_period(),
        Err(Error::InvalidRecording { index: 1, .. })
    ));
}

#[test]
fn schema_refuses_names_a_csv_header_cannot_hold() {
    let refused = |inputs: Vec<Channel>, measurements: Vec<Channel>, name: &str| match Schema::new(
        inputs,
        measurements,
    ) {
        Err(Error::Channel { name: got, .. }) => assert_eq!(got, name),
        other => panic!("expected Error::Channel for `{name}`, got {other:?}"),
    };
    let u = || Channel::new("u", "V");
    // Duplicates, within and across inputs and measurements.
    refused(vec![u(), Channel::new("u", "N")], vec![], "u");
    refused(vec![u()], vec![Channel::new("u", "m")], "u");
    refused(
        vec![],
        vec![Channel::new("x", "m"), Channel::new("x", "m")],
        "x",
    );
    // `t` is time.
    refused(vec![], vec![Channel::new("t", "s")], "t");
    // Characters a header cannot hold, in the name or the unit.
    refused(vec![Channel::new("u,1", "V")], vec![], "u,1");
    refused(vec![], vec![Channel::new("x", "m,s")], "x");
    refused(vec![], vec![Channel::new("x;1", "m")], "x;1");
    refused(vec![], vec![Channel::new("x\"", "m")], "x\"");
    refused(vec![], vec![Channel::new("x[1]", "m")], "x[1]");
    refused(vec![], vec![Channel::new("x\n", "m")], "x\n");
    refused(vec![], vec![Channel::new("", "m")], "");
    // Fine: unusual but header-safe names and units.
    let s = Schema::new(
        vec![u()],
        vec![Channel::new("x 1", "m/s"), Channel::new("time_to_go", "")],
    )
    .unwrap();
    assert_eq!(s.len(), 3);
    assert_eq!(s.position("time_to_go"), Some(2));
}

fn finite() -> impl Strategy<Value = f64> {
    prop_oneof![
        -1e3f64..1e3,
        any::<f64>().prop_filter("finite", |v| v.is_finite()),
        Just(0.0),
        Just(-0.0),
        Just(f64::MIN_POSITIVE),
    ]
}

proptest! {
    #[test]
    fn write_then_read_is_lossless(
        n in 2usize..40,
        dt in 1e-4f64..1.0,
        t0 in -10.0f64..10.0,
        values in prop::collection::vec(finite(), 6 * 40),
        velocities: bool,
    ) {
        // With velocities: the lab's schema; without: its positions only.
        let schema = if velocities {
            ctrlab::lab::schema()
        } else {
            Schema::new(
                vec![Channel::new("u", "V")],
                vec![Channel::new("x1", "m"), Channel::new("x2", "m")],
            )
            .unwrap()
        };
        let mut rec = Recording::with_capacity(schema, n);
        for k in 0..n {
            let v = &values[6 * k..6 * k + 5];
            let t = t0 + k as f64 * dt;
            if velocities {
                rec.push(t, &v[..1], &v[1..5]).unwrap();
            } else {
                rec.push(t, &v[..1], &[v[1], v[3]]).unwrap();
            }
        }
        let mut buf = Vec::new();
        rec.to_writer(&mut buf).unwrap();
        let back = Recording::from_reader(&buf[..]).unwrap();
        // Bit-for-bit, including the sign of zero.
        prop_assert_eq!(bits(&back), bits(&rec));
        prop_assert_eq!(back.schema(), rec.schema());
        prop_assert_eq!(back.channel("v1").is_ok(), velocities);
    }

    #[test]
    fn arbitrary_bytes_never_panic(bytes in prop::collection::vec(any::<u8>(), 0..512)) {
        // Any outcome is fine except a panic; an error must name a line.
        if let Err(e) = Recording::from_reader(&bytes[..]) {
            let ok = matches!(e, CsvError::Line { line, .. } if line >= 1);
            prop_assert!(ok, "unexpected error {:?}", e);
        }
    }

    #[test]
    fn csv_like_text_never_panics(
        header in prop::sample::subsequence(vec!["t_s", "u", "x1_mm", "x2_m", "v1_m_s", "v2_mm_s", "x1", "junk", "t [ms]", "y [deg]", "u2"], 0..11),
        cells in prop::collection::vec(prop_oneof![Just("0.002".to_string()), Just("".to_string()), Just("nan".to_string()), "[-0-9.e]{0,6}"], 0..80),
        width in 1usize..8,
    ) {
        let mut text = header.join(",");
        text.push('\n');
        for row in cells.chunks(width) {
            text.push_str(&row.join(","));
            text.push('\n');
        }
        if let Err(e) = Recording::from_reader(text.as_bytes()) {
            let ok = matches!(e, CsvError::Line { line, .. } if line >= 1);
            prop_assert!(ok, "unexpected error {:?}", e);
        }
    }
}

#[test]
fn a_time_column_whose_span_overflows_is_refused() {
    // Alternating ±1e308 overflows the mean period to inf; it must still be
    // reported as a non-increasing column, not accepted.
    let mut text = String::from("t_s,u,x1_m,x2_m\n");
    for k in 0..8 {
        let t = if k % 2 == 0 { -1e308 } else { 1e308 };
        text += &format!("{t:e},0,0,0\n");
    }
    assert!(matches!(
        Recording::from_reader(text.as_bytes()),
        Err(CsvError::Line { line: 4, .. })
    ));
}
