//! Reading a [`Recording`] from CSV.

use std::io::{BufReader, Chain, Cursor, Read};
use std::path::Path;

use super::header::{Scale, parse_header};
use super::lines::{HeaderLine, Uncommented};
use super::value::{self, BadValue};
use super::{CsvOptions, csv_error, is_input_name};
use crate::data::{Channel, Recording, Schema};
use crate::error::Error;

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

impl Recording {
    /// Reads a recording from a CSV file; see [`from_reader`](Self::from_reader)
    /// for the format.
    ///
    /// # Errors
    ///
    /// [`Error::Io`] (with the path) when the file cannot be opened, and the
    /// errors of [`from_reader`](Self::from_reader).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::{Error, Recording};
    /// let path = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ident_square_wave.csv");
    /// let rec = Recording::read_csv(path)?;
    /// assert_eq!(rec.len(), 2500);
    /// assert!(matches!(Recording::read_csv("no/such/file.csv"), Err(Error::Io { .. })));
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn read_csv(path: impl AsRef<Path>) -> Result<Self, Error> {
        Self::read_csv_with(path, &CsvOptions::default())
    }

    /// Reads a recording from a CSV file with `options` (the calibration of
    /// a column in encoder counts); see
    /// [`from_reader_with`](Self::from_reader_with) for the format.
    ///
    /// # Errors
    ///
    /// [`Error::Io`] (with the path) when the file cannot be opened or
    /// read, and the errors of [`from_reader_with`](Self::from_reader_with).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::{Error, Recording, data::CsvOptions};
    /// let path = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/logs/counts.csv");
    /// let options = CsvOptions { metres_per_count: Some(1.0 / 102_400.0) };
    /// let rec = Recording::read_csv_with(path, &options)?;
    /// assert_eq!(rec.schema().measurements()[0].unit, "m"); // counts read as metres
    /// assert!(matches!(Recording::read_csv(path), Err(Error::Csv { .. }))); // no calibration
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn read_csv_with(path: impl AsRef<Path>, options: &CsvOptions) -> Result<Self, Error> {
        let path = path.as_ref();
        let file = std::fs::File::open(path)
            .map_err(|e| Error::io(format!("opening {}", path.display()), &e))?;
        Self::from_reader_with(file, options).map_err(|e| match e {
            Error::Io { kind, message, .. } => Error::Io {
                context: format!("reading {}", path.display()),
                kind,
                message,
            },
            other => other,
        })
    }

    /// Reads a recording from CSV text with the default [`CsvOptions`]: any
    /// log [`from_reader_with`](Self::from_reader_with) reads, except one
    /// with a column in encoder counts.
    ///
    /// # Errors
    ///
    /// As [`from_reader_with`](Self::from_reader_with).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::{Error, Recording};
    /// let text = "t_s,u,x1_mm,x2_mm\n\
    ///             0.000,2,0,0\n0.002,2,0,0.05\n0.004,2,0.01,0.2\n";
    /// let rec = Recording::from_reader(text.as_bytes())?;
    /// assert_eq!(rec.channel("x2")?[2], 0.2 / 1000.0); // millimetres are converted to metres
    /// assert_eq!(rec.schema().inputs()[0].name, "u");
    /// assert_eq!(rec.schema().measurements()[0].unit, "m");
    ///
    /// let bad = text.replace("0.01,0.2", "0.01,oops");
    /// let err = Recording::from_reader(bad.as_bytes()).unwrap_err();
    /// assert!(matches!(err, Error::Csv { line: 4, .. }));
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn from_reader(reader: impl Read) -> Result<Self, Error> {
        Self::from_reader_with(reader, &CsvOptions::default())
    }

    /// Reads a recording from CSV text, a log as students have it.
    ///
    /// **Lines.** Comment lines (first character other than space or tab
    /// `#` or `%`) and blank lines are skipped anywhere, before the header
    /// too; line breaks may be `\n`, `\r\n` or `\r`; a UTF-8 byte-order mark
    /// is skipped. Line numbers in errors are the file's own, one-based,
    /// skipped lines counted.
    ///
    /// **Separator.** The first line that is not skipped is the header; it
    /// shows the separator: a tab if it holds one, else `;` if it holds one,
    /// else `,` (a header holding a comma is always comma-separated: names
    /// and units cannot hold one). Fields may be quoted (`"0.5"`); whitespace
    /// around each is trimmed.
    ///
    /// **Numbers.** A decimal point, or, in files separated by `;` or tabs,
    /// a decimal comma (`0,002`). A value with a comma and a point, or two
    /// commas (`1.234,5`), is refused: it can only hold a thousands
    /// separator. Values must be finite.
    ///
    /// **Columns.** One column is time: a channel named `t` or `time` in
    /// `s` or `ms` (`t_s`, `T_s`, `t [s]`, `Time (s)`, `time_s`, `t_ms`,
    /// `T [ms]`). Every other column is a channel; its header carries its
    /// unit, and values are converted to SI on reading:
    ///
    /// - `name_unit` with a unit from [`KNOWN_UNITS`](crate::data::KNOWN_UNITS)
    ///   written as SI writes it (`x1_mm`, `v1_m_s`, `u_V`);
    /// - `name [unit]` / `name (unit)` with any unit (`X1 [mm]`,
    ///   `v1 [mm/s]`, `U [V]`): one of [`KNOWN_UNITS`](crate::data::KNOWN_UNITS)
    ///   is matched ignoring case, except for the letters `m` and `s`, which
    ///   SI tells from `M` (mega) and `S` (siemens): `[v]` is `V`, `[MM]` is
    ///   not `mm` (it is kept as written, a unit the reader does not know,
    ///   as any other);
    /// - raw encoder counts, `name_counts` or `name [counts]` / `[count]` /
    ///   `[cnt]` in any case: read in metres (unit `m`) with
    ///   [`CsvOptions::metres_per_count`], which must then be set;
    /// - `name` alone: a channel without a unit (the lab's `u`).
    ///
    /// Names are read in lower case (`X1 [mm]` is channel `x1`). Channels
    /// named `u` or `u1`, `u2`, … are the inputs, the others the
    /// measurements, in file order.
    ///
    /// **Rows.** As many fields as the header; the time column must
    /// increase strictly, with at least two rows. It need not be uniform (a
    /// rig's recording holds its actual sampling instants, jitter and gaps
    /// included): [`sample_period`](Recording::sample_period) checks
    /// uniformity for those who need it, and the lab's identification
    /// splits at gaps. What a file must hold beyond that is for its user to
    /// check (the lab's identification asks for its own channels and rows).
    ///
    /// # Errors
    ///
    /// [`Error::InvalidParameter`] for a `metres_per_count` that is not
    /// finite and positive. [`Error::Csv`] with the file's line and what was
    /// found there: for no header line, and on the header line (shown as
    /// found) for a missing or duplicated time column, two columns for one
    /// channel, or a column in counts without
    /// [`CsvOptions::metres_per_count`]; for a row with the wrong number of
    /// fields (found and expected, and the row); for a value that is not a
    /// finite number or holds a thousands separator (the value); for a time
    /// that does not increase (or an interval that overflows); for fewer
    /// than two rows; for bytes the CSV parser rejects (invalid UTF-8).
    /// [`Error::Io`] for a failing reader.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{Error, Recording, data::CsvOptions};
    ///
    /// // Excel in a German locale, with the logger's own comments.
    /// let log = "# lab 5, group 3\n\
    ///            T [ms];U [V];X1 [mm]\n\
    ///            0;2,5;0\n\
    ///            % the motor starts\n\
    ///            2;2,5;0,125\n";
    /// let rec = Recording::from_reader_with(log.as_bytes(), &CsvOptions::default())?;
    /// assert_eq!(rec.time(), &[0.0, 0.002]);
    /// assert_eq!(rec.channel("u")?, &[2.5, 2.5]);
    /// assert_eq!(rec.channel("x1")?[1], 0.125 / 1000.0);
    ///
    /// // A thousands separator, on the file's line 5.
    /// let bad = log.replace("0,125", "1.000,125");
    /// match Recording::from_reader_with(bad.as_bytes(), &CsvOptions::default()) {
    ///     Err(Error::Csv { line, reason }) => {
    ///         assert_eq!(line, 5);
    ///         assert!(reason.contains("`1.000,125`"), "{reason}");
    ///     }
    ///     other => panic!("{other:?}"),
    /// }
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn from_reader_with(reader: impl Read, options: &CsvOptions) -> Result<Self, Error> {
        options.check()?;
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
                    format!(
                        "no header line: the {dropped} lines are all comments (# or %) or blank"
                    ),
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
                    format!(
                        "column `{header}` has no time unit: name it t_s or t_ms (header {found})"
                    ),
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
}
