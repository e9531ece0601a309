//! `Recording` CSV: units, round trip, and one test per malformed-input case.

use ctrlab::{Error, Recording};
use proptest::prelude::*;

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
        Err(Error::Csv { line, reason }) => (line, reason),
        other => panic!("expected Error::Csv, got {other:?}"),
    }
}

#[test]
fn millimetres_are_read_as_metres() {
    let rec = Recording::from_reader(GOOD.as_bytes()).unwrap();
    assert_eq!(rec.len(), 6);
    assert_eq!(rec.x2[1], 0.048828125 / 1000.0);
    assert_eq!(rec.t[5], 0.010);
    assert!(rec.v1.is_none() && rec.v2.is_none());
    // The same run in metres, columns reordered, velocities in mm/s, an extra column.
    let si = "x2_m, u ,t_s,x1_m,v1_mm_s,v2_mm_s,duty\n".to_string()
        + &rec
            .t
            .iter()
            .enumerate()
            .map(|(k, t)| {
                format!(
                    "{:?},2,{t:?},{:?},{},-{},7\n",
                    rec.x2[k],
                    rec.x1[k],
                    k * 10,
                    k * 20
                )
            })
            .collect::<String>();
    let rec2 = Recording::from_reader(si.as_bytes()).unwrap();
    assert_eq!(
        (&rec2.t, &rec2.u, &rec2.x1, &rec2.x2),
        (&rec.t, &rec.u, &rec.x1, &rec.x2)
    );
    assert_eq!(rec2.v1.as_ref().unwrap()[3], 0.030);
    assert_eq!(rec2.v2.as_ref().unwrap()[2], -0.040);
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
    assert!(rec.u.iter().all(|u| u.abs() == 2.0));
}

#[test]
fn each_malformed_input_names_its_line() {
    assert_eq!(csv_err("").0, 1);
    let (line, reason) = csv_err(&GOOD.replace("x2_mm", "x3_mm"));
    assert_eq!(line, 1);
    assert!(reason.contains("missing column x2_m or x2_mm"), "{reason}");
    let (line, reason) = csv_err(&GOOD.replace("x1_mm", "x1"));
    assert_eq!(line, 1);
    assert!(reason.contains("no unit"), "{reason}");
    assert_eq!(
        csv_err(&GOOD.replace("t_s,u,", "t_s,u,x1_m,")).0,
        1,
        "duplicate column"
    );
    assert!(
        csv_err(
            &GOOD
                .replace("x2_mm\n", "x2_mm,v1_mm_s\n")
                .replace(",0.048828125\n", ",0.048828125,1\n")
        )
        .1
        .contains("pairs")
    );

    // Non-number on data line 4 (file line 4).
    let (line, reason) = csv_err(&GOOD.replace("0.004,2,0,0.1953125", "0.004,2,zero,0.1953125"));
    assert_eq!(line, 4);
    assert!(
        reason.contains("x1_mm") && reason.contains("zero"),
        "{reason}"
    );
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
    // Irregular: one sample 0.5 ms late (25 % of the interval), line 6.
    let (line, reason) = csv_err(&GOOD.replace("0.008,", "0.0085,"));
    assert_eq!(line, 6);
    assert!(
        reason.contains("irregular") && reason.contains('%'),
        "{reason}"
    );

    // Too few rows: reported on the last line.
    let short: String = GOOD.lines().take(4).map(|l| format!("{l}\n")).collect();
    let (line, reason) = csv_err(&short);
    assert_eq!(line, 4);
    assert!(reason.contains("at least 6"), "{reason}");
    assert_eq!(csv_err("t_s,u,x1_m,x2_m\n").0, 1);
    // Invalid UTF-8 on line 3.
    let mut bytes = GOOD.as_bytes().to_vec();
    let at = GOOD.find("0.002").unwrap();
    bytes[at] = 0xff;
    assert!(matches!(
        Recording::from_reader(&bytes[..]),
        Err(Error::Csv { line: 3, .. })
    ));
}

#[test]
fn missing_file_is_an_io_error_with_the_path() {
    match Recording::read_csv("/no/such/dir/log.csv") {
        Err(Error::Io { context, kind, .. }) => {
            assert!(context.contains("/no/such/dir/log.csv"));
            assert_eq!(kind, std::io::ErrorKind::NotFound);
        }
        other => panic!("expected Io, got {other:?}"),
    }
}

#[test]
fn file_round_trip_and_writer_refusals() {
    let rec = Recording::from_reader(GOOD.as_bytes()).unwrap();
    let path = std::env::temp_dir().join(format!("ctrlab_round_trip_{}.csv", std::process::id()));
    rec.write_csv(&path).unwrap();
    let back = Recording::read_csv(&path).unwrap();
    std::fs::remove_file(&path).unwrap();
    assert_eq!(back, rec);

    let mut ragged = rec.clone();
    ragged.x1.pop();
    assert!(matches!(
        ragged.to_writer(Vec::new()),
        Err(Error::InvalidRecording { index: 5, .. })
    ));
    let mut nan = rec;
    nan.u[2] = f64::NAN;
    assert!(matches!(
        nan.to_writer(Vec::new()),
        Err(Error::InvalidRecording { index: 2, .. })
    ));
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
        n in 6usize..40,
        dt in 1e-4f64..1.0,
        t0 in -10.0f64..10.0,
        values in prop::collection::vec(finite(), 6 * 40),
        velocities: bool,
    ) {
        let mut rec = Recording::with_capacity(n);
        for k in 0..n {
            let state = nalgebra::vector![values[6 * k + 1], values[6 * k + 2], values[6 * k + 3], values[6 * k + 4]];
            let t = t0 + k as f64 * dt;
            if velocities {
                rec.push_state(t, values[6 * k], &state);
            } else {
                rec.push(t, values[6 * k], state[0], state[2]);
            }
        }
        let mut buf = Vec::new();
        rec.to_writer(&mut buf).unwrap();
        let back = Recording::from_reader(&buf[..]).unwrap();
        // Bit-for-bit, including the sign of zero.
        let bits = |r: &Recording| -> Vec<u64> {
            let mut cols = vec![&r.t, &r.u, &r.x1, &r.x2];
            if let (Some(a), Some(b)) = (&r.v1, &r.v2) { cols.push(a); cols.push(b); }
            cols.iter().flat_map(|c| c.iter().map(|v| v.to_bits())).collect()
        };
        prop_assert_eq!(bits(&back), bits(&rec));
        prop_assert_eq!(back.v1.is_some(), velocities);
    }

    #[test]
    fn arbitrary_bytes_never_panic(bytes in prop::collection::vec(any::<u8>(), 0..512)) {
        // Any outcome is fine except a panic; an error must name a line.
        if let Err(e) = Recording::from_reader(&bytes[..]) {
            let ok = matches!(e, Error::Csv { line, .. } if line >= 1);
            prop_assert!(ok, "unexpected error {:?}", e);
        }
    }

    #[test]
    fn csv_like_text_never_panics(
        header in prop::sample::subsequence(vec!["t_s", "u", "x1_mm", "x2_m", "v1_m_s", "v2_mm_s", "x1", "junk"], 0..8),
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
            let ok = matches!(e, Error::Csv { line, .. } if line >= 1);
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
        Err(Error::Csv { line: 4, .. })
    ));
}
