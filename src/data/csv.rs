//! CSV reading and writing of [`Recording`]s.

use std::io::{Read, Write};
use std::path::Path;

use super::{Channel, Recording, Schema};
use crate::error::Error;

/// The units the CSV reader recognises as a header suffix, with the SI unit
/// they stand for and how many of them make one SI unit:
/// `(suffix, SI unit, divisor)`. A header `x1_mm` is channel `x1` in `m`,
/// read values ÷ 1000 (a division, so `0.001` mm is exactly the double
/// nearest 1e-6 m); `v1_m_s` is `v1` in `m/s`. The writer uses the SI
/// suffixes.
///
/// # Examples
///
/// ```
/// use ctrlab::data::KNOWN_UNITS;
/// assert!(KNOWN_UNITS.contains(&("mm_s", "m/s", 1000.0)));
/// ```
pub const KNOWN_UNITS: [(&str, &str, f64); 10] = [
    ("mm_s", "m/s", 1000.0),
    ("m_s", "m/s", 1.0),
    ("rad_s", "rad/s", 1.0),
    ("mm", "m", 1000.0),
    ("ms", "s", 1000.0),
    ("m", "m", 1.0),
    ("s", "s", 1.0),
    ("V", "V", 1.0),
    ("N", "N", 1.0),
    ("rad", "rad", 1.0),
];

/// Splits a header into a channel (SI unit) and the divisor to SI: the
/// bracket form `name [unit]` / `name (unit)` or a known suffix `name_unit`;
/// otherwise the whole header is the name, without a unit.
fn parse_header(header: &str) -> (Channel, f64) {
    let bracketed = header
        .strip_suffix(']')
        .and_then(|h| h.rsplit_once('['))
        .or_else(|| header.strip_suffix(')').and_then(|h| h.rsplit_once('(')));
    if let Some((name, unit)) = bracketed {
        let (name, unit) = (name.trim(), unit.trim());
        let suffix = unit.replace('/', "_");
        return match KNOWN_UNITS.iter().find(|k| k.0 == suffix) {
            Some(&(_, si, divisor)) => (Channel::new(name, si), divisor),
            None => (Channel::new(name, unit), 1.0),
        };
    }
    for &(suffix, si, divisor) in &KNOWN_UNITS {
        if let Some(name) = header
            .strip_suffix(suffix)
            .and_then(|h| h.strip_suffix('_'))
            .filter(|n| !n.is_empty())
        {
            return (Channel::new(name, si), divisor);
        }
    }
    (Channel::new(header, ""), 1.0)
}

/// The header the writer uses for `channel`: `name_unit` for a unit in
/// [`KNOWN_UNITS`] (`/` written as `_`), `name [unit]` for any other unit,
/// `name` alone without one.
fn header_of(channel: &Channel) -> String {
    if channel.unit.is_empty() {
        return channel.name.clone();
    }
    let suffix = channel.unit.replace('/', "_");
    if KNOWN_UNITS.iter().any(|k| k.0 == suffix && k.2 == 1.0) {
        format!("{}_{suffix}", channel.name)
    } else {
        format!("{} [{}]", channel.name, channel.unit)
    }
}

impl Recording {
    /// Checks every channel's header reads back as the same channel in the
    /// same role, so that a written file always reads back identical.
    fn check_round_trip(&self) -> Result<(), Error> {
        let inputs = self.schema.inputs().len();
        for (k, channel) in self.schema.channels().enumerate() {
            let (parsed, divisor) = parse_header(&header_of(channel));
            let reason = if matches!(parsed.name.as_str(), "t" | "time") {
                Some("a channel cannot be named like the time column (t, time)")
            } else if parsed != *channel || divisor != 1.0 {
                Some(
                    "its CSV header would read back as another channel: \
                     give it an SI unit, or a name that does not end in a unit",
                )
            } else if is_input_name(&channel.name) != (k < inputs) {
                Some(
                    "in a CSV file, inputs are the channels named u, u1, u2, …: \
                     rename it so that its role reads back",
                )
            } else {
                None
            };
            if let Some(reason) = reason {
                return Err(Error::Channel {
                    name: channel.name.clone(),
                    reason: reason.to_string(),
                });
            }
        }
        Ok(())
    }
}

/// Input channels in a file are those named `u` or `u` followed by digits
/// (python-control's and MATLAB's convention for inputs).
fn is_input_name(name: &str) -> bool {
    name.strip_prefix('u')
        .is_some_and(|rest| rest.chars().all(|c| c.is_ascii_digit()))
}

fn csv_error(line: u64, reason: impl Into<String>) -> Error {
    Error::Csv {
        line,
        reason: reason.into(),
    }
}

fn from_csv_crate(err: &csv::Error, fallback_line: u64) -> Error {
    let line = err
        .position()
        .map(|p| p.line())
        .unwrap_or(fallback_line)
        .max(1);
    csv_error(line, err.to_string())
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
        let path = path.as_ref();
        let file = std::fs::File::open(path)
            .map_err(|e| Error::io(format!("opening {}", path.display()), &e))?;
        Self::from_reader(std::io::BufReader::new(file))
    }

    /// Reads a recording from CSV text.
    ///
    /// The first line is a header. One column is time: `t_s` (or `t_ms`,
    /// `t [s]`, `time_s`, …: a channel named `t` or `time` in a time unit).
    /// Every other column is a channel; its header carries its unit, and
    /// values are converted to SI on reading:
    ///
    /// - `name_unit` with a unit from [`KNOWN_UNITS`] (`x1_mm`, `v1_m_s`,
    ///   `u_V`), or `name [unit]` / `name (unit)` with any unit;
    /// - `name` alone: a channel without a unit (the lab's `u`).
    ///
    /// Channels named `u` or `u1`, `u2`, … are the inputs, the others the
    /// measurements, in file order. Surrounding whitespace is trimmed. The
    /// time column must increase strictly, with at least two rows; it need
    /// not be uniform (a rig's recording holds its actual sampling instants,
    /// jitter and gaps included): [`sample_period`](Recording::sample_period)
    /// checks uniformity for those who need it, and the lab's
    /// identification splits at gaps. What a file must hold beyond that is
    /// for its user to check (the lab's identification asks for its own
    /// channels and rows).
    ///
    /// # Errors
    ///
    /// [`Error::Csv`] with the one-based line (header = line 1) for: empty
    /// input, a missing or duplicated time column (the message shows the
    /// header found), two columns for one channel, a row with the wrong
    /// number of fields, a value that is not a finite number, a time that
    /// does not increase (or an interval that overflows), fewer than two
    /// rows, or bytes the CSV parser rejects (invalid
    /// UTF-8). [`Error::Io`] for a failing reader.
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
        let mut rdr = csv::ReaderBuilder::new()
            .has_headers(true)
            .trim(csv::Trim::All)
            .from_reader(reader);
        let headers = rdr.headers().map_err(|e| from_csv_crate(&e, 1))?.clone();
        if headers.is_empty() || headers.iter().all(str::is_empty) {
            return Err(csv_error(1, "empty input: expected a header line"));
        }
        // The header's own line: the parser skips blank lines before it
        // (and reports the header's position as line 1), so take the line
        // the reader is on after it, less the header's line break.
        let header_line = rdr.position().line().saturating_sub(1).max(1);
        let found = || headers.iter().collect::<Vec<_>>().join(",");

        // (column index, divisor) of time, and of each channel in order.
        let mut time: Option<(usize, f64)> = None;
        let mut inputs: Vec<(Channel, usize, f64)> = Vec::new();
        let mut measurements: Vec<(Channel, usize, f64)> = Vec::new();
        for (i, header) in headers.iter().enumerate() {
            let (channel, divisor) = parse_header(header);
            if matches!(channel.name.as_str(), "t" | "time") && channel.unit == "s" {
                if time.is_some() {
                    return Err(csv_error(
                        header_line,
                        format!("two time columns in header `{}`", found()),
                    ));
                }
                time = Some((i, divisor));
            } else if matches!(channel.name.as_str(), "t" | "time") {
                return Err(csv_error(
                    header_line,
                    format!(
                        "column `{header}` has no time unit: name it t_s or t_ms (header `{}`)",
                        found()
                    ),
                ));
            } else if is_input_name(&channel.name) {
                inputs.push((channel, i, divisor));
            } else {
                measurements.push((channel, i, divisor));
            }
        }
        let Some((time_index, time_divisor)) = time else {
            return Err(csv_error(
                header_line,
                format!(
                    "missing a time column t_s (or t_ms, t [s]); the header is `{}`",
                    found()
                ),
            ));
        };
        let schema = Schema::new(
            inputs.iter().map(|c| c.0.clone()).collect(),
            measurements.iter().map(|c| c.0.clone()).collect(),
        )
        .map_err(|e| csv_error(header_line, format!("{e} (header `{}`)", found())))?;
        let slots: Vec<(usize, f64, &str)> = std::iter::once((time_index, time_divisor, "t"))
            .chain(
                inputs
                    .iter()
                    .chain(&measurements)
                    .map(|(c, i, f)| (*i, *f, c.name.as_str())),
            )
            .collect();

        let mut cols: Vec<Vec<f64>> = vec![Vec::new(); slots.len()];
        let mut lines: Vec<u64> = Vec::new();
        let mut record = csv::StringRecord::new();
        let mut last_line = header_line;
        loop {
            match rdr.read_record(&mut record) {
                Ok(false) => break,
                Ok(true) => {}
                Err(e) => return Err(from_csv_crate(&e, last_line + 1)),
            }
            let line = record.position().map_or(last_line + 1, |p| p.line());
            last_line = line;
            for (&(i, divisor, name), col) in slots.iter().zip(cols.iter_mut()) {
                let text = record.get(i).unwrap_or("");
                let value: f64 = text.parse().map_err(|_| {
                    csv_error(line, format!("column {name}: `{text}` is not a number"))
                })?;
                let value = value / divisor;
                if !value.is_finite() {
                    return Err(csv_error(
                        line,
                        format!("column {name}: `{text}` is not a finite number"),
                    ));
                }
                col.push(value);
            }
            lines.push(line);
        }

        if lines.len() < 2 {
            return Err(csv_error(
                last_line,
                format!("only {} data rows: at least 2 are needed", lines.len()),
            ));
        }
        let mut cols = cols.into_iter();
        let t = cols.next().unwrap_or_default();
        // Increasing, but not necessarily uniform: a rig's recording has its
        // actual sampling instants, jitter and gaps included, and must read
        // back; `sample_period` and identification judge the timing.
        if let Some(k) = (1..t.len()).find(|&k| t[k] <= t[k - 1]) {
            return Err(csv_error(
                lines[k],
                format!(
                    "time {} s does not increase (previous {} s)",
                    t[k],
                    t[k - 1]
                ),
            ));
        }
        if let Some(k) = (1..t.len()).find(|&k| !(t[k] - t[k - 1]).is_finite()) {
            return Err(csv_error(
                lines[k],
                format!("the interval from {} s to {} s overflows", t[k - 1], t[k]),
            ));
        }
        Ok(Recording {
            schema,
            t,
            columns: cols.collect(),
        })
    }

    /// Writes the recording as CSV to a file; see
    /// [`to_writer`](Self::to_writer) for the format.
    ///
    /// # Errors
    ///
    /// [`Error::Io`] (with the path) when the file cannot be created or
    /// written; the errors of [`to_writer`](Self::to_writer).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::Recording;
    /// # use ctrlab::data::Schema;
    /// let mut rec = Recording::new(Schema::numbered(1, 2));
    /// for k in 0..6 {
    ///     rec.push(k as f64 * 0.002, &[1.0], &[1e-4 * k as f64, 2e-4 * k as f64])?;
    /// }
    /// let path = std::env::temp_dir().join("ctrlab_doc_write_csv.csv");
    /// rec.write_csv(&path)?;
    /// assert_eq!(Recording::read_csv(&path)?, rec);
    /// # std::fs::remove_file(&path).ok();
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn write_csv(&self, path: impl AsRef<Path>) -> Result<(), Error> {
        let path = path.as_ref();
        let file = std::fs::File::create(path)
            .map_err(|e| Error::io(format!("creating {}", path.display()), &e))?;
        let mut w = std::io::BufWriter::new(file);
        self.to_writer(&mut w).map_err(|e| match e {
            Error::Io { kind, message, .. } => Error::Io {
                context: format!("writing {}", path.display()),
                kind,
                message,
            },
            other => other,
        })?;
        w.flush()
            .map_err(|e| Error::io(format!("writing {}", path.display()), &e))
    }

    /// Writes the recording as CSV in SI units: header `t_s` and one column
    /// per channel (inputs, then measurements), each header the channel's
    /// name and unit (`x1_m`, `v1_m_s`, `u_V`; see [`KNOWN_UNITS`]). Values
    /// are written in Rust's shortest round-trip form, so reading the output
    /// back gives the identical recording.
    ///
    /// # Errors
    ///
    /// [`Error::InvalidRecording`] for a non-finite value (the reader would
    /// refuse it); [`Error::Channel`] for a channel whose header would not
    /// read back as itself (a unit outside [`KNOWN_UNITS`] that is not SI
    /// such as `mm`, a name ending in a unit, a name `t` or `time`, or an
    /// input not named `u…` / a measurement named `u…`), so that every
    /// file written reads back identical; [`Error::Io`] when the writer
    /// fails.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::data::{Channel, Recording, Schema};
    /// let schema = Schema::new(vec![Channel::new("u", "V")], vec![Channel::new("x1", "m"), Channel::new("v1", "m/s")])?;
    /// let mut rec = Recording::new(schema);
    /// rec.push(0.0, &[2.0], &[0.001, 0.0025])?;
    /// let mut out = Vec::new();
    /// rec.to_writer(&mut out)?;
    /// assert_eq!(String::from_utf8(out).unwrap(), "t_s,u_V,x1_m,v1_m_s\n0.0,2.0,0.001,0.0025\n");
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn to_writer(&self, writer: impl Write) -> Result<(), Error> {
        self.check_values()?;
        self.check_round_trip()?;
        let io = |e: csv::Error| match e.into_kind() {
            csv::ErrorKind::Io(e) => Error::io("writing CSV", &e),
            other => Error::io("writing CSV", &std::io::Error::other(format!("{other:?}"))),
        };
        let mut w = csv::Writer::from_writer(writer);
        let header: Vec<String> = std::iter::once("t_s".to_string())
            .chain(self.schema.channels().map(header_of))
            .collect();
        w.write_record(&header).map_err(io)?;
        let mut fields: Vec<String> = Vec::with_capacity(header.len());
        for k in 0..self.len() {
            fields.clear();
            fields.push(format!("{:?}", self.t[k]));
            fields.extend(self.columns.iter().map(|c| format!("{:?}", c[k])));
            w.write_record(&fields).map_err(io)?;
        }
        w.flush().map_err(|e| Error::io("writing CSV", &e))
    }
}
