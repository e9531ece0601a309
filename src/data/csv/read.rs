//! Reading a [`Recording`] from CSV: one pass over the bytes. Rows as a
//! logger writes them (one line each, plain numbers) are read straight from
//! the buffer ([`fast`]); anything else, and every error, goes through the
//! general path: the lines of the log ([`Lines`]) told apart as they come,
//! comment and blank lines skipped; content lines go to `csv-core`'s
//! tokenizer, which splits them into fields (quotes included), except a row
//! without a quote, split at the separator in place as the tokenizer would
//! ([`records`]); each field is trimmed and parsed from its bytes (one
//! UTF-8 check a row), and only the header is read as text. A large file
//! is read a block at a time, its rows on a thread per CPU ([`parallel`]),
//! into columns sized once from the file's length ([`columns`]).

use std::io::Read;
use std::path::Path;

use self::columns::{Columns, ESTIMATE_AFTER, size_columns};
use self::fast::{Fast, Stop};
use self::parallel::{Pace, Parallel};
use self::records::{Records, field_text, trim};
use super::header::{Scale, parse_header};
use super::lines::{CHUNK, Kind, Lines, separator, without_break};
use super::value::{self, BadValue};
use super::{CsvError, CsvOptions, csv_error, is_input_name};
use crate::data::{Channel, Recording, Schema};

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

/// Reads the values of the current row (of the right width, on line
/// `line`) into `values`, one per slot, in SI.
fn read_row<R: Read>(
    records: &Records<R>,
    slots: &[Slot],
    values: &mut [f64],
    decimal_comma: bool,
    scratch: &mut String,
    line: u64,
) -> Result<(), CsvError> {
    // One check that the row is text; a field cut out of it at characters
    // is then text too (a number always is).
    let row = records.text();
    for (slot, out) in slots.iter().zip(values.iter_mut()) {
        let cut = match row {
            Some(row) => row.get(records.bounds(slot.index)),
            None => None,
        };
        let text = match cut {
            Some(text) => trim(text),
            None => match field_text(records.field(slot.index)) {
                Some(text) => text,
                None => return Err(not_text(line, slot, records.field(slot.index))),
            },
        };
        let value = match value::parse(text, decimal_comma, scratch) {
            Ok(value) => value,
            Err(why) => return Err(not_a_number(line, slot, text, why, decimal_comma)),
        };
        // As `value / divisor * factor`: dividing or multiplying by 1
        // changes no bit.
        let value = if slot.divisor == 1.0 {
            value
        } else {
            value / slot.divisor
        };
        let value = if slot.factor == 1.0 {
            value
        } else {
            value * slot.factor
        };
        if !value.is_finite() {
            return Err(not_finite(line, slot, text));
        }
        *out = value;
    }
    Ok(())
}

/// A field whose bytes are not UTF-8.
#[cold]
fn not_text(line: u64, slot: &Slot, raw: &[u8]) -> CsvError {
    csv_error(
        line,
        format!(
            "column {}: `{}` is not a number (not even UTF-8 text)",
            slot.name,
            String::from_utf8_lossy(raw).trim()
        ),
    )
}

/// A field that is not a number.
#[cold]
fn not_a_number(
    line: u64,
    slot: &Slot,
    text: &str,
    why: BadValue,
    decimal_comma: bool,
) -> CsvError {
    csv_error(line, why.describe(slot.name, text, decimal_comma))
}

/// A number that is not finite (as written, or once in SI).
#[cold]
fn not_finite(line: u64, slot: &Slot, text: &str) -> CsvError {
    csv_error(
        line,
        format!("column {}: `{text}` is not a finite number", slot.name),
    )
}

impl Recording {
    /// Reads a recording from a CSV file; see [`from_reader`](Self::from_reader)
    /// for the format.
    ///
    /// **Threads.** A file of 4 MiB or more (about 130 000 rows of the
    /// lab's log) is read in blocks of 2 MiB a thread, on a thread per CPU
    /// the process may use ([`std::thread::available_parallelism`], which
    /// honours CPU affinity and quotas; at most 8), started for each block
    /// and ended with it. Values and errors are those of a read on one
    /// thread, bit for bit. A file with comment lines or rows the fast
    /// path leaves to the general one (quotes, exponents, errors) is read
    /// on the calling thread from the first of them. To read on the
    /// calling thread only (from a real-time thread, say, whose scheduling
    /// policy the threads it starts inherit), pass the opened file to
    /// [`from_reader_with`](Self::from_reader_with).
    ///
    /// # Errors
    ///
    /// [`CsvError::Io`] (with the path) when the file cannot be opened or
    /// read, and the errors of [`from_reader`](Self::from_reader).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::{Recording, data::CsvError};
    /// let path = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ident_square_wave.csv");
    /// let rec = Recording::read_csv(path)?;
    /// assert_eq!(rec.len(), 2500);
    /// assert!(matches!(Recording::read_csv("no/such/file.csv"), Err(CsvError::Io { .. })));
    /// # Ok::<(), CsvError>(())
    /// ```
    pub fn read_csv(path: impl AsRef<Path>) -> Result<Self, CsvError> {
        Self::read_csv_with(path, &CsvOptions::default())
    }

    /// Reads a recording from a CSV file with `options` (the calibration of
    /// a column in encoder counts); see
    /// [`from_reader_with`](Self::from_reader_with) for the format.
    ///
    /// # Errors
    ///
    /// [`CsvError::Io`] (with the path, and near which line when reading)
    /// when the file cannot be opened or read, and the errors of
    /// [`from_reader_with`](Self::from_reader_with).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::{Recording, data::{CsvError, CsvOptions}};
    /// let path = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/logs/counts.csv");
    /// let options = CsvOptions { metres_per_count: Some(1.0 / 102_400.0) };
    /// let rec = Recording::read_csv_with(path, &options)?;
    /// assert_eq!(rec.schema().measurements()[0].unit, "m"); // counts read as metres
    /// assert!(matches!(Recording::read_csv(path), Err(CsvError::Line { line: 1, .. }))); // no calibration
    /// # Ok::<(), CsvError>(())
    /// ```
    pub fn read_csv_with(path: impl AsRef<Path>, options: &CsvOptions) -> Result<Self, CsvError> {
        let path = path.as_ref();
        let file = std::fs::File::open(path)
            .map_err(|e| CsvError::io(format!("opening {}", path.display()), e))?;
        // The file's length sizes the columns once (0 for a pipe: unknown).
        let size = file.metadata().ok().map(|m| m.len()).filter(|&n| n > 0);
        read(file, options, size, Some(path), Pace::for_size(size))
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
    /// # use ctrlab::{Recording, data::CsvError};
    /// let text = "t_s,u,x1_mm,x2_mm\n\
    ///             0.000,2,0,0\n0.002,2,0,0.05\n0.004,2,0.01,0.2\n";
    /// let rec = Recording::from_reader(text.as_bytes())?;
    /// assert_eq!(rec.channel("x2")?[2], 0.2 / 1000.0); // millimetres are converted to metres
    /// assert_eq!(rec.schema().inputs()[0].name, "u");
    /// assert_eq!(rec.schema().measurements()[0].unit, "m");
    ///
    /// let bad = text.replace("0.01,0.2", "0.01,oops");
    /// let err = Recording::from_reader(bad.as_bytes()).unwrap_err();
    /// assert!(matches!(err, CsvError::Line { line: 4, .. }));
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn from_reader(reader: impl Read) -> Result<Self, CsvError> {
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
    /// [`CsvError::Options`] for a `metres_per_count` that is not finite and
    /// positive. [`CsvError::Line`] with the file's line and what was found
    /// there: for no header line, and on the header line (shown as found)
    /// for a missing or duplicated time column, two columns for one
    /// channel, a column in counts without
    /// [`CsvOptions::metres_per_count`], or a header that is not UTF-8; for
    /// a row with the wrong number of fields (found and expected, and the
    /// row); for a value that is not a finite number, holds a thousands
    /// separator or is not UTF-8 (the value); for a time that does not
    /// increase (or an interval that overflows); for fewer than two rows.
    /// [`CsvError::Io`] for a failing reader (near which line), the
    /// reader's error as its source.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{Recording, data::{CsvError, CsvOptions}};
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
    ///     Err(CsvError::Line { line, reason }) => {
    ///         assert_eq!(line, 5);
    ///         assert!(reason.contains("`1.000,125`"), "{reason}");
    ///     }
    ///     other => panic!("{other:?}"),
    /// }
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn from_reader_with(reader: impl Read, options: &CsvOptions) -> Result<Self, CsvError> {
        read(reader, options, None, None, Pace::FAST)
    }
}

/// What an I/O error while reading was doing: reading the header or near
/// which line, of the file at `path` when there is one.
fn reading(path: Option<&Path>, header: bool, line: u64) -> String {
    match (path, header) {
        (None, true) => "reading the CSV header".to_string(),
        (None, false) => format!("reading CSV (near line {line})"),
        (Some(path), _) => format!("reading {} (near line {line})", path.display()),
    }
}

/// Reads a recording from `reader` (of `size` bytes when known, to size
/// the columns once; the file at `path` when there is one, for errors), at
/// `pace`.
fn read<R: Read>(
    reader: R,
    options: &CsvOptions,
    size: Option<u64>,
    path: Option<&Path>,
    pace: Pace,
) -> Result<Recording, CsvError> {
    options.check()?;
    let mut lines = Lines::with_capacity(reader, pace.buffer(CHUNK));
    let header = loop {
        match lines.next() {
            Ok(Some(line)) if line.kind == Kind::Content => break line,
            Ok(Some(_)) => {}
            Ok(None) => {
                let dropped = lines.line();
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
            }
            Err(e) => return Err(CsvError::io(reading(path, true, lines.line() + 1), e)),
        }
    };
    let header_line = header.number;
    let text = without_break(lines.bytes(header.range.clone()));
    let separator = separator(text);
    let decimal_comma = separator != b',';
    let found = {
        let text = String::from_utf8_lossy(text).replace('\t', "\\t");
        match separator {
            b';' => format!("`{text}` (columns separated by `;`)"),
            b'\t' => format!("`{text}` (columns separated by tabs)"),
            _ => format!("`{text}`"),
        }
    };
    let mut records = Records::new(lines, separator);
    let io = |records: &Records<R>, e: std::io::Error| {
        CsvError::io(reading(path, false, records.lines.line() + 1), e)
    };
    match records.next(Some(header)) {
        Ok(Some(_)) => {}
        Ok(None) => {
            return Err(csv_error(
                header_line,
                "empty input: expected a header line",
            ));
        }
        Err(e) => return Err(io(&records, e)),
    }
    let mut headers: Vec<String> = Vec::with_capacity(records.len());
    for i in 0..records.len() {
        match std::str::from_utf8(records.field(i)) {
            Ok(h) => headers.push(h.trim().to_string()),
            Err(_) => {
                return Err(csv_error(
                    header_line,
                    format!("the header line is not valid UTF-8: {found}"),
                ));
            }
        }
    }
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

    let width = headers.len();
    let mut cols = Columns::new(slots.len());
    let mut values = vec![0.0; slots.len()];
    let mut scratch = String::new();
    // The line of the last row read (the header's at first).
    let mut last = header_line;
    // Where the rows start, to size the columns from the first rows.
    let rows_start = records.lines.consumed();
    // The first interval that overflows: (line, previous time, time).
    let mut overflow: Option<(u64, f64, f64)> = None;
    let mut fast = Fast::new(&slots, width, separator, decimal_comma);
    let mut parallel = Parallel::new(&fast, pace);
    // Whether the columns are sized (or cannot be: the length is unknown).
    let mut sized = size.is_none();
    loop {
        // After the rows read so far, by either path.
        size_columns(
            &mut sized,
            &mut cols,
            size,
            records.lines.consumed() - rows_start,
            rows_start,
            width,
        );
        if pace.fast
            && let Some(pending) = records.lines.pending()
        {
            // Up to the row after which the columns are sized, then all:
            // on several threads when a block of rows is buffered.
            let limit = match ESTIMATE_AFTER.checked_sub(cols.len()) {
                Some(left) if !sized && left > 0 => left,
                _ => usize::MAX,
            };
            let parallel = match limit {
                usize::MAX => parallel.rows(pending, &mut cols),
                _ => None,
            };
            let (bytes, lines, stop) =
                parallel.unwrap_or_else(|| fast.rows(pending, &mut cols, limit));
            if lines > 0 {
                records.lines.skip(bytes, lines);
                last = records.lines.line();
            }
            match stop {
                Stop::Limit => continue,
                Stop::Partial => match records.lines.more() {
                    Ok(true) => continue,
                    Ok(false) => {}
                    Err(e) => return Err(io(&records, e)),
                },
                Stop::Unusual => {}
            }
        }
        match records.next(None) {
            Ok(Some(line)) => last = line,
            Ok(None) => break,
            Err(e) => return Err(io(&records, e)),
        }
        if records.len() != width {
            return Err(csv_error(
                last,
                format!(
                    "{} fields where the header has {}: `{}`",
                    records.len(),
                    width,
                    records.joined(separator)
                ),
            ));
        }
        read_row(
            &records,
            &slots,
            &mut values,
            decimal_comma,
            &mut scratch,
            last,
        )?;
        cols.push(&values);
        // Increasing, but not necessarily uniform: a rig's recording has its
        // actual sampling instants, jitter and gaps included, and must read
        // back; `sample_period` and identification judge the timing.
        if let Some((before, now)) = cols.last_two() {
            if now <= before {
                return Err(csv_error(
                    last,
                    format!("time {now} s does not increase (previous {before} s)"),
                ));
            }
            if overflow.is_none() && !(now - before).is_finite() {
                overflow = Some((last, before, now));
            }
        }
    }

    let rows = cols.len();
    if rows < 2 {
        return Err(csv_error(
            last,
            format!("only {rows} data rows: at least 2 are needed"),
        ));
    }
    // Reported once the whole column is known to increase: ±1e308
    // alternating overflows every interval, but is first of all a time that
    // goes back.
    if let Some((line, before, now)) = overflow {
        return Err(csv_error(
            line,
            format!("the interval from {before} s to {now} s overflows"),
        ));
    }
    let mut cols = cols.into_vecs().into_iter();
    let t = cols.next().unwrap_or_default();
    Ok(Recording {
        schema,
        t,
        columns: cols.collect(),
    })
}

mod columns;
mod fast;
mod parallel;
mod records;
#[cfg(test)]
mod tests;
#[cfg(test)]
mod tests_fast;
