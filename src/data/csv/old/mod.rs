//! The reader built on the `csv` crate, as it was before the port to
//! `csv-core`, kept for the tests only: `tests::*` reads random logs with
//! both and asks for the same outcome, bit for bit.

mod lines;

use std::io::{BufReader, Chain, Cursor, Read};

use self::lines::{HeaderLine, Uncommented};
use super::header::{Scale, parse_header};
use super::value::{self, BadValue};
use super::{CsvOptions, is_input_name};
use crate::data::{Channel, Recording, Schema};
use crate::error::Error;

/// The old reader's line error.
fn csv_error(line: u64, reason: impl Into<String>) -> Error {
    Error::Csv {
        line,
        reason: reason.into(),
    }
}

/// What the CSV parser reads: the header line again, then the rest of the
/// file without its comment and blank lines.
type Source<R> = Chain<Cursor<Vec<u8>>, BufReader<Uncommented<BufReader<R>>>>;

/// The file's line number of the parser's line `line`.
fn file_line<R: Read>(rdr: &csv::Reader<Source<R>>, line: u64) -> u64 {
    rdr.get_ref().get_ref().1.get_ref().file_line(line)
}

/// A CSV parser's error: [`Error::Io`] for a failing reader, otherwise
/// [`Error::Csv`] on the file's line (`fallback` when the parser names
/// none).
fn from_csv_crate<R: Read>(rdr: &csv::Reader<Source<R>>, err: &csv::Error, fallback: u64) -> Error {
    let line = file_line(rdr, err.position().map_or(fallback, csv::Position::line)).max(1);
    match err.kind() {
        csv::ErrorKind::Io(e) => Error::io(format!("reading CSV (near line {line})"), e),
        _ => csv_error(line, err.to_string()),
    }
}

/// Where one channel is read from, and how its values become SI.
struct Slot<'a> {
    /// The column's index in a row.
    index: usize,
    /// Divide by this, then multiply by that: one of them is 1, so the
    /// conversion is one rounding (`0.001` mm is the double nearest 1e-6 m).
    divisor: f64,
    factor: f64,
    name: &'a str,
}

/// A row's fields as found, joined by the separator.
fn row_text(record: &csv::StringRecord, separator: u8) -> String {
    let sep = (separator as char).to_string();
    record.iter().collect::<Vec<_>>().join(&sep)
}

pub(super) fn from_reader_with(
    reader: impl Read,
    options: &CsvOptions,
) -> Result<Recording, Error> {
    if let Err(crate::data::CsvError::Options { source }) = options.check() {
        return Err(source);
    }
    let mut lines = BufReader::new(Uncommented::new(BufReader::new(reader)));
    let header =
        HeaderLine::read(&mut lines).map_err(|e| Error::io("reading the CSV header", &e))?;
    let Some(header) = header else {
        let dropped = lines.get_ref().dropped_lines();
        return Err(if dropped == 0 {
            csv_error(1, "empty input: expected a header line")
        } else {
            csv_error(
                dropped,
                format!("no header line: the {dropped} lines are all comments (# or %) or blank"),
            )
        });
    };
    let separator = header.separator();
    let decimal_comma = separator != b',';
    let found = {
        let text = String::from_utf8_lossy(header.text()).replace('\t', "\\t");
        match separator {
            b';' => format!("`{text}` (columns separated by `;`)"),
            b'\t' => format!("`{text}` (columns separated by tabs)"),
            _ => format!("`{text}`"),
        }
    };
    let source = Cursor::new(header.bytes).chain(lines);
    let mut rdr = csv::ReaderBuilder::new()
        .has_headers(false)
        .flexible(true)
        .delimiter(separator)
        .from_reader(source);
    let header_line = file_line(&rdr, 1);

    let mut record = csv::StringRecord::new();
    match rdr.read_record(&mut record) {
        Ok(true) => {}
        Ok(false) => {
            return Err(csv_error(
                header_line,
                "empty input: expected a header line",
            ));
        }
        Err(e) => return Err(from_csv_crate(&rdr, &e, 1)),
    }
    let headers: Vec<String> = record.iter().map(|h| h.trim().to_string()).collect();
    if headers.iter().all(String::is_empty) {
        return Err(csv_error(
            header_line,
            format!("the header line has no column names: {found}"),
        ));
    }

    // (column index, scale) of time, and of each channel in order.
    let mut time: Option<(usize, Scale)> = None;
    let mut inputs: Vec<(Channel, usize, Scale)> = Vec::new();
    let mut measurements: Vec<(Channel, usize, Scale)> = Vec::new();
    for (i, header) in headers.iter().enumerate() {
        let (channel, scale) = parse_header(header);
        let is_time = matches!(channel.name.as_str(), "t" | "time");
        if is_time && channel.unit == "s" {
            if time.is_some() {
                return Err(csv_error(
                    header_line,
                    format!("two time columns in header {found}"),
                ));
            }
            time = Some((i, scale));
        } else if is_time {
            return Err(csv_error(
                header_line,
                format!("column `{header}` has no time unit: name it t_s or t_ms (header {found})"),
            ));
        } else if scale == Scale::Counts && options.metres_per_count.is_none() {
            return Err(csv_error(
                header_line,
                format!(
                    "column `{header}` is in encoder counts: set \
                     CsvOptions::metres_per_count (m per count) to read it in metres \
                     (header {found})"
                ),
            ));
        } else if is_input_name(&channel.name) {
            inputs.push((channel, i, scale));
        } else {
            measurements.push((channel, i, scale));
        }
    }
    let Some((time_index, time_scale)) = time else {
        // A column in seconds under another name (`Zeit [s]`) is the
        // likely culprit.
        let in_seconds = inputs
            .iter()
            .chain(&measurements)
            .find(|c| c.0.unit == "s")
            .map(|c| format!("; column `{}` is in s: name it t or time", headers[c.1]))
            .unwrap_or_default();
        return Err(csv_error(
            header_line,
            format!(
                "missing a time column t_s (or t_ms, t [s]); the header is {found}{in_seconds}"
            ),
        ));
    };
    let schema = Schema::new(
        inputs.iter().map(|c| c.0.clone()).collect(),
        measurements.iter().map(|c| c.0.clone()).collect(),
    )
    .map_err(|e| csv_error(header_line, format!("{e} (header {found})")))?;
    let slot_of = |index: usize, scale: Scale, name| match scale {
        Scale::Divide(divisor) => Slot {
            index,
            divisor,
            factor: 1.0,
            name,
        },
        Scale::Counts => Slot {
            index,
            divisor: 1.0,
            factor: options.metres_per_count.unwrap_or(1.0),
            name,
        },
    };
    let slots: Vec<Slot> = std::iter::once(slot_of(time_index, time_scale, "t"))
        .chain(
            inputs
                .iter()
                .chain(&measurements)
                .map(|(c, i, s)| slot_of(*i, *s, c.name.as_str())),
        )
        .collect();

    let mut cols: Vec<Vec<f64>> = (0..slots.len()).map(|_| Vec::new()).collect();
    let mut scratch = String::new();
    // The parser's line of the last row read (the header's at first).
    let mut last = 1;
    // The first interval that overflows: (line, previous time, time).
    let mut overflow: Option<(u64, f64, f64)> = None;
    loop {
        match rdr.read_record(&mut record) {
            Ok(false) => break,
            Ok(true) => {}
            Err(e) => return Err(from_csv_crate(&rdr, &e, last + 1)),
        }
        last = record.position().map_or(last + 1, csv::Position::line);
        if record.len() != headers.len() {
            return Err(csv_error(
                file_line(&rdr, last),
                format!(
                    "{} fields where the header has {}: `{}`",
                    record.len(),
                    headers.len(),
                    row_text(&record, separator)
                ),
            ));
        }
        for (slot, col) in slots.iter().zip(cols.iter_mut()) {
            let text = record.get(slot.index).unwrap_or("").trim();
            let bad = |why: BadValue| {
                csv_error(
                    file_line(&rdr, last),
                    why.describe(slot.name, text, decimal_comma),
                )
            };
            let value = value::parse(text, decimal_comma, &mut scratch).map_err(bad)?;
            let value = value / slot.divisor * slot.factor;
            if !value.is_finite() {
                return Err(csv_error(
                    file_line(&rdr, last),
                    format!("column {}: `{text}` is not a finite number", slot.name),
                ));
            }
            col.push(value);
        }
        // Increasing, but not necessarily uniform: a rig's recording
        // has its actual sampling instants, jitter and gaps included,
        // and must read back; `sample_period` and identification judge
        // the timing.
        let t = &cols[0];
        if let [.., before, now] = t[..] {
            if now <= before {
                return Err(csv_error(
                    file_line(&rdr, last),
                    format!("time {now} s does not increase (previous {before} s)"),
                ));
            }
            if overflow.is_none() && !(now - before).is_finite() {
                overflow = Some((last, before, now));
            }
        }
    }

    let rows = cols[0].len();
    if rows < 2 {
        return Err(csv_error(
            file_line(&rdr, last),
            format!("only {rows} data rows: at least 2 are needed"),
        ));
    }
    // Reported once the whole column is known to increase: ±1e308
    // alternating overflows every interval, but is first of all a time
    // that goes back.
    if let Some((line, before, now)) = overflow {
        return Err(csv_error(
            file_line(&rdr, line),
            format!("the interval from {before} s to {now} s overflows"),
        ));
    }
    let mut cols = cols.into_iter();
    let t = cols.next().unwrap_or_default();
    Ok(Recording {
        schema,
        t,
        columns: cols.collect(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::CsvError;
    use proptest::prelude::*;

    /// Whether the reader built on `csv-core` reads `bytes` as the old one:
    /// the same recording bit for bit, or the same error on the same line
    /// with the same message (for invalid UTF-8 in a row, the old message
    /// was the `csv` crate's, with its own record and line counts).
    fn same(bytes: &[u8], options: &CsvOptions) -> Result<(), TestCaseError> {
        let old = from_reader_with(bytes, options);
        let new = Recording::from_reader_with(bytes, options);
        let bits = |rec: &Recording| -> Vec<u64> {
            rec.t
                .iter()
                .chain(rec.columns.iter().flatten())
                .map(|v| v.to_bits())
                .collect()
        };
        match (&old, &new) {
            (Ok(a), Ok(b)) => {
                prop_assert_eq!(&a.schema, &b.schema);
                prop_assert_eq!(bits(a), bits(b));
            }
            (
                Err(Error::Csv {
                    line: la,
                    reason: ra,
                }),
                Err(CsvError::Line {
                    line: lb,
                    reason: rb,
                }),
            ) => {
                prop_assert_eq!(
                    la,
                    lb,
                    "{} / {} in {:?}",
                    ra,
                    rb,
                    String::from_utf8_lossy(bytes)
                );
                if !ra.contains("invalid utf-8") {
                    prop_assert_eq!(ra, rb, "in {:?}", String::from_utf8_lossy(bytes));
                }
            }
            (Err(a @ Error::InvalidParameter { .. }), Err(CsvError::Options { source: b })) => {
                prop_assert_eq!(a, b);
            }
            _ => prop_assert!(
                false,
                "{:?} / {:?} in {:?}",
                old,
                new,
                String::from_utf8_lossy(bytes)
            ),
        }
        Ok(())
    }

    /// The writer as it was: the `csv` crate, a `format!` a value.
    fn old_to_writer(rec: &Recording) -> Vec<u8> {
        use super::super::header::header_of;
        let mut w = csv::Writer::from_writer(Vec::new());
        let header: Vec<String> = std::iter::once("t_s".to_string())
            .chain(rec.schema.channels().map(header_of))
            .collect();
        w.write_record(&header).unwrap();
        let mut fields: Vec<String> = Vec::with_capacity(header.len());
        for k in 0..rec.len() {
            fields.clear();
            fields.push(format!("{:?}", rec.t[k]));
            fields.extend(rec.columns.iter().map(|c| format!("{:?}", c[k])));
            w.write_record(&fields).unwrap();
        }
        w.into_inner().unwrap()
    }

    fn options(counts: bool) -> CsvOptions {
        CsvOptions {
            metres_per_count: counts.then_some(1.0 / 102_400.0),
        }
    }

    fn cell() -> impl Strategy<Value = String> {
        prop_oneof![
            10 => (-1e4f64..1e4).prop_map(|v| format!("{v}")),
            3 => any::<f64>().prop_map(|v| format!("{v:e}")),
            2 => any::<f64>().prop_map(|v| format!("{v}")),
            3 => prop::sample::select(vec![
                "1.234,5", "1,2,3", "nan", "inf", "-0", "1e308", "-1e309", "", " ", "\"1,5\"",
                "#", "%", "\"", "x", "\"2.5\"", "\" 3 \"", "\"4\"\"\"", "\"0.5\n\"", "\"#\n1\"",
                "\"1\r\n\"", "\"1\r\r\"", "\u{a0}7\u{a0}", "\u{3000}8", "9\u{b}", "\u{feff}1",
                "\"\"", "\"1\"x", "1\"", "\"\n\n\"", "\"\r\n# c\r\n\"",
            ])
            .prop_map(str::to_string),
        ]
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 4096, ..ProptestConfig::default() })]

        #[test]
        fn logs_read_as_the_old_reader_read_them(
            time in prop::sample::select(vec!["t_s", "T [ms]", "time_s", "\"t_s\"", " t_s ", "t"]),
            channels in prop::sample::subsequence(vec!["u", "U_V", "x1_mm", "X2 [m]", "x3_counts", "x4 [cnt]", "y [deg]", "u2", "\"x5\"", "x1_m"], 1..5),
            time_at in 0usize..5,
            rows in 0usize..8,
            dt in prop_oneof![Just(0.002), 1e-9f64..10.0, Just(1e300), Just(5e-324)],
            cells in prop::collection::vec(cell(), 40),
            separator in prop::sample::select(vec![",", ";", "\t", ", "]),
            breaks in prop::sample::select(vec!["\n", "\r\n", "\r"]),
            extra in prop::collection::vec((0usize..10, prop::sample::select(vec!["# c", "% c, \"x", "", "  \t", "#", "\u{feff}", "\"", " # t_s,u"])), 0..4),
            last_break: bool,
            bom: bool,
            counts: bool,
        ) {
            let mut header: Vec<&str> = channels.clone();
            header.insert(time_at.min(header.len()), time);
            let width = header.len();
            let mut lines = vec![header.join(separator)];
            let mut cells = cells.into_iter();
            for k in 0..rows {
                let mut row: Vec<String> = (1..width).map(|_| cells.next().unwrap_or_default()).collect();
                row.insert(time_at.min(width - 1), format!("{}", k as f64 * dt));
                let row = row.join(separator);
                lines.push(if separator.starts_with(',') { row } else { row.replace('.', ",") });
            }
            for (at, line) in extra {
                let at = at.min(lines.len());
                lines.insert(at, line.to_string());
            }
            let mut text = lines.join(breaks);
            if last_break {
                text.push_str(breaks);
            }
            if bom {
                text.insert(0, '\u{feff}');
            }
            same(text.as_bytes(), &options(counts))?;
        }

        #[test]
        fn any_text_reads_as_the_old_reader_read_it(
            text in "[tTs_uUxX12 ,;\t\n\r\"#%.0-9eE+\\-\u{a0}\u{feff}\u{b}]{0,160}",
            counts: bool,
        ) {
            same(text.as_bytes(), &options(counts))?;
        }

        #[test]
        fn mutated_logs_read_as_the_old_reader_read_them(
            rows in 2usize..8,
            values in prop::collection::vec(-1e3f64..1e3, 16),
            semicolons: bool,
            edits in prop::collection::vec((any::<prop::sample::Index>(), prop::sample::select(b"\n\r\",;\t#% \xff\xc3\xa0e-.0x".to_vec()), 0u8..3), 1..5),
        ) {
            let (sep, point) = if semicolons { (";", ",") } else { (",", ".") };
            let mut text = ["t_s", "u_V", "x1_mm"].join(sep) + "\n";
            for k in 0..rows {
                let row = [format!("{}", k as f64 * 0.002), format!("{}", values[2 * k]), format!("{:e}", values[2 * k + 1])];
                text += &row.map(|v| v.replace('.', point)).join(sep);
                text.push('\n');
            }
            let mut bytes = text.into_bytes();
            for (at, b, op) in edits {
                let at = at.index(bytes.len() + 1);
                match op {
                    0 if at < bytes.len() => bytes[at] = b,
                    1 if at < bytes.len() => { bytes.remove(at); }
                    _ => bytes.insert(at, b),
                }
            }
            same(&bytes, &CsvOptions::default())?;
        }

        #[test]
        fn recordings_are_written_as_the_old_writer_wrote_them(
            n in 0usize..300,
            values in prop::collection::vec(prop_oneof![any::<f64>().prop_filter("finite", |v| v.is_finite()), Just(-0.0), Just(1e-300), -1e3f64..1e3], 6),
            schema in prop::sample::select(vec![0usize, 1, 2]),
        ) {
            use crate::data::Channel;
            let schema = match schema {
                0 => crate::lab::schema(),
                1 => Schema::numbered(2, 3),
                _ => Schema::new(vec![Channel::new("u", "V")], vec![Channel::new("x 1", "deg"), Channel::new("w", "rad/s"), Channel::new("#y", "")]).unwrap(),
            };
            let mut rec = Recording::with_capacity(schema.clone(), n);
            let m = schema.inputs().len();
            for k in 0..n {
                let v: Vec<f64> = (0..schema.len()).map(|i| values[(i * 7 + k) % 6] * if k % 2 == 0 { 1.0 } else { -0.5 }).collect();
                rec.push(k as f64 * 0.002, &v[..m], &v[m..]).unwrap();
            }
            let mut new = Vec::new();
            rec.to_writer(&mut new).unwrap();
            prop_assert_eq!(String::from_utf8(new).unwrap(), String::from_utf8(old_to_writer(&rec)).unwrap());
        }

        #[test]
        fn random_bytes_read_as_the_old_reader_read_them(
            bytes in prop::collection::vec(any::<u8>(), 0..200),
            counts: bool,
        ) {
            same(&bytes, &options(counts))?;
        }
    }

    #[test]
    fn the_test_logs_read_as_the_old_reader_read_them() {
        let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/logs");
        let mut paths: Vec<_> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().path())
            .collect();
        paths.push(
            concat!(
                env!("CARGO_MANIFEST_DIR"),
                "/tests/data/ident_square_wave.csv"
            )
            .into(),
        );
        for n in 1..=3 {
            paths.push(format!("{dir}/lab5/group7_run{n}.csv").into());
        }
        for path in paths.iter().filter(|p| p.is_file()) {
            let bytes = std::fs::read(path).unwrap();
            for counts in [false, true] {
                same(&bytes, &options(counts)).unwrap();
            }
        }
    }

    /// The bench's log (`benches/csv.rs`): `rows` rows of `t,u,x1,x2`.
    fn lab_log(rows: usize) -> String {
        use std::fmt::Write as _;
        let mut text = String::with_capacity(rows * 40);
        text.push_str("t_s,u,x1_mm,x2_mm\n");
        for k in 0..rows {
            let t = k as f64 * 0.002;
            let u = if (k / 100) % 2 == 0 { 2.0 } else { -2.0 };
            let x1 = 12.5 * (t * 3.1).sin();
            let x2 = 20.25 * (t * 2.3).cos();
            writeln!(text, "{t:.3},{u},{x1:.6},{x2:.6}").unwrap();
        }
        text
    }

    /// Old and new reader timed in turn on the bench's 1e6-row logs (the
    /// best of seven each, so that other work on the machine weighs on
    /// both alike): `cargo test --release --lib old::tests::timing --
    /// --ignored --nocapture`.
    #[test]
    #[ignore = "a timing, not a test"]
    fn timing() {
        use std::time::Instant;
        let rows: usize =
            std::env::var("CTRLAB_TIMING_ROWS").map_or(1_000_000, |n| n.parse().unwrap());
        let log = lab_log(rows);
        let excel: String = log
            .replace(',', ";")
            .replace('.', ",")
            .lines()
            .enumerate()
            .map(|(k, line)| {
                if k % 1000 == 999 {
                    format!("# {k} rows\r\n{line}\r\n")
                } else {
                    format!("{line}\r\n")
                }
            })
            .collect();
        let path = std::env::temp_dir().join(format!("ctrlab_timing_{}.csv", std::process::id()));
        std::fs::write(&path, &log).unwrap();
        let options = CsvOptions::default();
        // Under `perf stat` or valgrind: one reader only, on one log,
        // `CTRLAB_TIMING_N` times (once).
        if let Ok(only) = std::env::var("CTRLAB_TIMING_ONLY") {
            let text = if only.ends_with("excel") {
                &excel
            } else {
                &log
            };
            let n: usize = std::env::var("CTRLAB_TIMING_N").map_or(1, |n| n.parse().unwrap());
            for _ in 0..n * usize::from(only != "none") {
                let rec = if only.starts_with("old") {
                    from_reader_with(text.as_bytes(), &options).unwrap()
                } else {
                    Recording::from_reader_with(text.as_bytes(), &options).unwrap()
                };
                assert_eq!(rec.len(), rows);
            }
            return;
        }
        // Old and new in turn, the best of each.
        let best = |old: &dyn Fn() -> Recording, new: &dyn Fn() -> Recording| {
            let (mut a, mut b) = (f64::INFINITY, f64::INFINITY);
            for _ in 0..9 {
                for (f, best) in [(old, &mut a), (new, &mut b)] {
                    let start = Instant::now();
                    let rec = f();
                    *best = best.min(start.elapsed().as_secs_f64());
                    assert_eq!(rec.len(), 1_000_000);
                }
            }
            (a * 1e3, b * 1e3)
        };
        for (what, text) in [("comma", &log), ("excel", &excel)] {
            let (old, new) = best(
                &|| from_reader_with(text.as_bytes(), &options).unwrap(),
                &|| Recording::from_reader_with(text.as_bytes(), &options).unwrap(),
            );
            println!(
                "{what} ({} MB): old {old:.1} ms, new {new:.1} ms",
                text.len() / 1_000_000
            );
        }
        let (old, new) = best(
            &|| from_reader_with(std::fs::File::open(&path).unwrap(), &options).unwrap(),
            &|| Recording::read_csv(&path).unwrap(),
        );
        println!("file: old {old:.1} ms, new read_csv {new:.1} ms");
        std::fs::remove_file(&path).unwrap();
    }
}
