//! The fast path reads every log as the general path does: the same
//! values bit for bit, the same errors on the same lines.

use proptest::prelude::*;

use super::*;

/// A reader that hands out at most `n` bytes a read, so that rows are cut
/// at every place across reads.
struct Trickle<'a>(&'a [u8], usize);

impl Read for Trickle<'_> {
    fn read(&mut self, out: &mut [u8]) -> std::io::Result<usize> {
        let n = self.0.len().min(out.len()).min(self.1);
        out[..n].copy_from_slice(&self.0[..n]);
        self.0 = &self.0[n..];
        Ok(n)
    }
}

/// What a read gives, comparable bit for bit: the schema's channels and
/// every value's bits, or the error's text.
fn outcome(result: Result<Recording, CsvError>) -> Result<(String, Vec<Vec<u64>>), String> {
    let rec = result.map_err(|e| e.to_string())?;
    let mut cols = vec![rec.t.iter().map(|v| v.to_bits()).collect::<Vec<_>>()];
    cols.extend(
        rec.columns
            .iter()
            .map(|c| c.iter().map(|v| v.to_bits()).collect()),
    );
    Ok((format!("{:?}", rec.schema), cols))
}

/// `text` read by both paths, in reads of `fill` bytes, with its length
/// known or not, and on three threads in parts of 64 bytes: the fast
/// path's outcome, checked to be the general's.
fn both(text: &[u8], fill: usize, sized: bool) -> Result<(String, Vec<Vec<u64>>), String> {
    let options = CsvOptions {
        metres_per_count: Some(1.0 / 102_400.0),
    };
    let size = sized.then_some(text.len() as u64);
    let general = outcome(read(
        Trickle(text, fill),
        &options,
        size,
        None,
        Pace::GENERAL,
    ));
    let fast = outcome(read(Trickle(text, fill), &options, size, None, Pace::FAST));
    assert_eq!(fast, general, "{}", String::from_utf8_lossy(text));
    let threads = Pace {
        workers: 3,
        part: 64,
        ..Pace::FAST
    };
    let parallel = outcome(read(Trickle(text, fill), &options, size, None, threads));
    assert_eq!(parallel, general, "{}", String::from_utf8_lossy(text));
    fast
}

/// One value as a logger or a student might write it.
fn value() -> impl Strategy<Value = String> {
    let number = prop_oneof![
        -1e4..1e4f64,
        -1.0..1.0f64,
        (-1_000_000i64..1_000_000).prop_map(|n| n as f64),
        any::<f64>(),
    ];
    (number, 0..12usize, 0..100u8).prop_map(|(v, digits, style)| match style {
        0 => format!("{v}"),
        1 => format!("{v:e}"),
        2 => format!(" {v:.digits$}\t"),
        3 => format!("\"{v:.digits$}\""),
        4 => format!("{v:.20}"),
        5 => format!("+{:.digits$}", v.abs()),
        6 => "x".to_string(),
        7 => String::new(),
        8 => format!("{v:.digits$}.5"),
        9 => format!("{:.0}.", v.trunc()),
        _ => format!("{v:.digits$}"),
    })
}

/// A generated log: separator, line break, rows of values with times
/// increasing (mostly), comments and blank lines here and there.
fn log() -> impl Strategy<Value = Vec<u8>> {
    let row = (
        0.0005..0.01f64,
        prop::collection::vec(value(), 3),
        0..40u8,
        0..3usize,
    );
    (
        prop::sample::select(vec![b',', b';', b'\t']),
        prop::sample::select(vec!["\n", "\r\n", "\r"]),
        0..20u8,
        prop::collection::vec(row, 0..40),
        any::<bool>(),
    )
        .prop_map(|(sep, newline, oddity, rows, end)| {
            let sep = sep as char;
            let newline = if oddity < 16 { "\n" } else { newline };
            let mut text = format!("t_ms{sep}u{sep}x1 [mm]{sep}x2_counts{newline}");
            let mut t = 0.0;
            for (dt, values, kind, digits) in rows {
                t += dt;
                let mut fields = vec![format!("{:.digits$}", t * 1000.0, digits = digits + 1)];
                fields.extend(values);
                // A few rows a field short or long.
                if kind == 0 {
                    fields.pop();
                } else if kind == 1 {
                    fields.push("1".into());
                }
                let mut line = fields.join(&sep.to_string());
                if sep != ',' && kind % 3 == 0 {
                    line = line.replace('.', ",");
                }
                match kind {
                    2 => text += &format!("# comment{newline}"),
                    3 => text += newline,
                    4 => text += &format!("  % indented{newline}"),
                    5 => text += "\r\n",
                    _ => {}
                }
                text += &line;
                text += newline;
            }
            if !end && text.ends_with('\n') {
                text.pop();
            }
            text.into_bytes()
        })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 512, ..ProptestConfig::default() })]

    #[test]
    fn the_fast_path_reads_as_the_general_path(
        text in log(),
        fill in prop::sample::select(vec![1usize, 3, 7, 64, 1 << 20]),
        sized in any::<bool>(),
    ) {
        // `both` compares the paths; either outcome may be right.
        let _ = both(&text, fill, sized);
    }
}

/// A clean log, which the fast path reads from start to end.
fn clean(sep: char, decimal: char, newline: &str, rows: usize) -> String {
    let mut text = format!("t_s{sep}u{sep}x1_mm{sep}x2_mm{newline}");
    for k in 0..rows {
        let t = k as f64 * 0.002;
        let x1 = 12.5 * (t * 3.1).sin();
        let x2 = 20.25 * (t * 2.3).cos();
        let row = format!("{t:.3}{sep}{}{sep}{x1:.6}{sep}{x2:.6}", k % 5);
        text += &row.replace('.', &decimal.to_string());
        text += newline;
    }
    text
}

#[test]
fn clean_logs_read_alike_in_every_form() {
    for (sep, decimal) in [(',', '.'), (';', ','), (';', '.'), ('\t', ',')] {
        for newline in ["\n", "\r\n", "\r"] {
            let text = clean(sep, decimal, newline, 3000);
            for fill in [5, 4096, 1 << 20] {
                let got = both(text.as_bytes(), fill, true);
                assert_eq!(got.map(|r| r.1[0].len()), Ok(3000));
            }
        }
    }
}

#[test]
fn errors_in_fast_rows_name_the_same_line_and_column() {
    let text = clean(';', ',', "\r\n", 600);
    // Line 401 is row 400 (the header is line 1).
    let lines: Vec<&str> = text.split("\r\n").collect();
    let bad = [
        ("0,8;1;x;2", "column x1: `x` is not a number"),
        ("0,8;1;1.234,5;2", "thousands"),
        ("0,8;1;;2", "column x1 is empty"),
        ("0,8;1;2", "3 fields where the header has 4"),
        ("0,8;1;1e999;2", "column x1: `1e999` is not a finite number"),
        ("0,5;1;1;2", "time 0.5 s does not increase"),
    ];
    for (row, why) in bad {
        let mut edited = lines.clone();
        edited[400] = row;
        let edited = edited.join("\r\n");
        for fill in [7, 1 << 20] {
            let err = both(edited.as_bytes(), fill, true).unwrap_err();
            assert!(err.starts_with("CSV line 401: "), "{err}");
            assert!(err.contains(why), "{err}");
        }
    }
}

#[test]
fn the_fast_path_reads_clean_rows_itself() {
    // So that the comparisons above are not of the general path with itself.
    let slot = |index, divisor| Slot {
        index,
        divisor,
        factor: 1.0,
        name: "c",
    };
    let slots = [slot(0, 1.0), slot(1, 1.0), slot(2, 1000.0), slot(3, 1000.0)];
    for (sep, decimal, newline) in [(',', '.', "\n"), (';', ',', "\r\n"), ('\t', ',', "\n")] {
        let text = clean(sep, decimal, newline, 3000);
        let rows = &text.as_bytes()[text.find(newline).unwrap() + newline.len()..];
        let mut fast = fast::Fast::new(&slots, 4, sep as u8, decimal == ',');
        let mut cols = Columns::new(4);
        let got = fast.rows(rows, &mut cols, usize::MAX);
        assert_eq!(got, (rows.len(), 3000, fast::Stop::Partial));
        // A comment stops it where it is.
        let commented = [rows, b"# end\n"].concat();
        let got = fast.rows(&commented, &mut Columns::new(4), usize::MAX);
        assert_eq!(got, (rows.len(), 3000, fast::Stop::Unusual));

        // On three threads, the same rows, bit for bit.
        let pace = Pace {
            workers: 3,
            part: 1000,
            ..Pace::FAST
        };
        let mut threads = Parallel::new(&fast, pace);
        let mut parallel = Columns::new(4);
        let got = threads.rows(rows, &mut parallel);
        assert_eq!(got, Some((rows.len(), 3000, fast::Stop::Partial)));
        assert_eq!(bits(parallel), bits(cols));
        // A comment in the middle ends the block there, and the threads
        // are not asked again.
        let middle = rows.len() / 2
            + rows[rows.len() / 2..]
                .iter()
                .position(|&b| b == b'\n')
                .unwrap()
            + 1;
        let commented = [&rows[..middle], b"# note\n", &rows[middle..]].concat();
        let mut cols = Columns::new(4);
        let got = Parallel::new(&fast, pace).rows(&commented, &mut cols);
        let lines = rows[..middle].iter().filter(|&&b| b == b'\n').count() as u64;
        assert_eq!(got, Some((middle, lines, fast::Stop::Unusual)));
        assert_eq!(cols.len() as u64, lines);
        let mut threads = Parallel::new(&fast, pace);
        let _ = threads.rows(&commented, &mut Columns::new(4));
        assert_eq!(threads.rows(rows, &mut Columns::new(4)), None);
    }
}

/// Every value's bits, per column.
fn bits(cols: Columns) -> Vec<Vec<u64>> {
    cols.into_vecs()
        .iter()
        .map(|c| c.iter().map(|v| v.to_bits()).collect())
        .collect()
}

#[test]
fn a_time_that_does_not_increase_is_found_on_every_row_by_every_path() {
    // Wherever the parts are cut, a time that does not increase is the
    // general path's error, on its line.
    let text = clean(',', '.', "\n", 400);
    let lines: Vec<&str> = text.lines().collect();
    for row in 2..lines.len() {
        let time = lines[row - 1].split(',').next().unwrap();
        let rest = lines[row].split_once(',').unwrap().1;
        let repeated = format!("{time},{rest}");
        let mut edited = lines.clone();
        edited[row] = &repeated;
        let edited = edited.join("\n") + "\n";
        let err = both(edited.as_bytes(), 1 << 20, true).unwrap_err();
        assert!(
            err.starts_with(&format!("CSV line {}: time", row + 1)),
            "{err}"
        );
    }
}

#[test]
fn a_wrong_length_only_costs_room() {
    // The length sizes the columns; a file that grew or shrank since
    // (or a pipe that says something else) reads the same.
    let text = clean(';', ',', "\n", 5000);
    let options = CsvOptions::default();
    let pace = Pace {
        workers: 2,
        part: 256,
        ..Pace::FAST
    };
    let want = outcome(read(text.as_bytes(), &options, None, None, Pace::GENERAL));
    for size in [1, 100, text.len() as u64 / 3, 10 * text.len() as u64] {
        for pace in [Pace::FAST, pace] {
            let got = outcome(read(text.as_bytes(), &options, Some(size), None, pace));
            assert_eq!(got, want, "size {size}, {pace:?}");
        }
    }
}
