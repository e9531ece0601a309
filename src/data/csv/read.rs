//! Reading a [`Recording`] from CSV.

use std::io::Read;
use std::path::Path;

use super::header::parse_header;
use super::{csv_error, from_csv_crate, is_input_name};
use crate::data::{Channel, Recording, Schema};
use crate::error::Error;

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
    /// - `name_unit` with a unit from [`KNOWN_UNITS`](crate::data::KNOWN_UNITS) (`x1_mm`, `v1_m_s`,
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
}
