//! CSV reading and writing of [`Recording`]s.

use std::io::{Read, Write};
use std::path::Path;

use super::{MIN_ROWS, Recording, check_time};
use crate::error::Error;

/// A recognised column: which field, and the factor from the file's unit to SI.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Field {
    T,
    U,
    X1,
    X2,
    V1,
    V2,
}

/// `(header name, field, divisor to SI)`.
const COLUMNS: [(&str, Field, f64); 10] = [
    ("t_s", Field::T, 1.0),
    ("u", Field::U, 1.0),
    ("x1_m", Field::X1, 1.0),
    ("x1_mm", Field::X1, 1000.0),
    ("x2_m", Field::X2, 1.0),
    ("x2_mm", Field::X2, 1000.0),
    ("v1_m_s", Field::V1, 1.0),
    ("v1_mm_s", Field::V1, 1000.0),
    ("v2_m_s", Field::V2, 1.0),
    ("v2_mm_s", Field::V2, 1000.0),
];

/// Names that are a known quantity written without a unit.
const UNITLESS: [(&str, &str); 5] = [
    ("t", "t_s"),
    ("x1", "x1_m or x1_mm"),
    ("x2", "x2_m or x2_mm"),
    ("v1", "v1_m_s or v1_mm_s"),
    ("v2", "v2_m_s or v2_mm_s"),
];

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
    /// The first line is a header; the name of each column carries its unit,
    /// and values are converted to SI on reading:
    ///
    /// | quantity | accepted headers |
    /// |---|---|
    /// | time (required) | `t_s` |
    /// | input (required) | `u` (V on the rig, N in simulation; stored as is) |
    /// | cart positions (required) | `x1_m` or `x1_mm`, `x2_m` or `x2_mm` |
    /// | cart velocities (optional, both or neither) | `v1_m_s` or `v1_mm_s`, `v2_m_s` or `v2_mm_s` |
    ///
    /// Columns may come in any order; other columns are ignored. Surrounding
    /// whitespace is trimmed. The time column must increase strictly and be
    /// uniformly sampled (each interval within [`MAX_JITTER`](super::MAX_JITTER)
    /// of the mean), and there must be at least [`MIN_ROWS`] data rows.
    ///
    /// # Errors
    ///
    /// [`Error::Csv`] with the one-based line (header = line 1) for: empty
    /// input, a missing, duplicated or unit-less column, a row with the wrong
    /// number of fields, a value that is not a finite number, a time that
    /// does not increase, irregular sampling (the jitter is in the message),
    /// fewer than [`MIN_ROWS`] rows (reported on the last line), or bytes the
    /// CSV parser rejects (invalid UTF-8). [`Error::Io`] for a failing reader.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::{Error, Recording};
    /// let text = "t_s,u,x1_mm,x2_mm\n\
    ///             0.000,2,0,0\n0.002,2,0,0.05\n0.004,2,0.01,0.2\n\
    ///             0.006,2,0.05,0.43\n0.008,2,0.12,0.75\n0.010,2,0.24,1.15\n";
    /// let rec = Recording::from_reader(text.as_bytes())?;
    /// assert_eq!(rec.x2[2], 0.2 / 1000.0); // millimetres are converted to metres
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

        // Map each recognised header to (column index, divisor).
        let mut slots: [Option<(usize, f64, &str)>; 6] = [None; 6];
        for (i, name) in headers.iter().enumerate() {
            if let Some(&(canonical, field, div)) = COLUMNS.iter().find(|c| c.0 == name) {
                let slot = &mut slots[field as usize];
                if let Some((_, _, first)) = slot {
                    return Err(csv_error(
                        1,
                        format!("column `{name}` duplicates column `{first}`"),
                    ));
                }
                *slot = Some((i, div, canonical));
            } else if let Some((_, want)) = UNITLESS.iter().find(|c| c.0 == name) {
                return Err(csv_error(
                    1,
                    format!("column `{name}` has no unit: name it {want}"),
                ));
            }
        }
        for (field, want) in [
            (Field::T, "t_s"),
            (Field::U, "u"),
            (Field::X1, "x1_m or x1_mm"),
            (Field::X2, "x2_m or x2_mm"),
        ] {
            if slots[field as usize].is_none() {
                return Err(csv_error(1, format!("missing column {want}")));
            }
        }
        let has_v1 = slots[Field::V1 as usize].is_some();
        if has_v1 != slots[Field::V2 as usize].is_some() {
            let missing = if has_v1 { "v2" } else { "v1" };
            return Err(csv_error(
                1,
                format!("velocity columns come in pairs: missing {missing}_m_s or {missing}_mm_s"),
            ));
        }

        let mut cols: [Vec<f64>; 6] = Default::default();
        let mut lines: Vec<u64> = Vec::new();
        let mut record = csv::StringRecord::new();
        let mut last_line = 1u64;
        loop {
            match rdr.read_record(&mut record) {
                Ok(false) => break,
                Ok(true) => {}
                Err(e) => return Err(from_csv_crate(&e, last_line + 1)),
            }
            let line = record.position().map_or(last_line + 1, |p| p.line());
            last_line = line;
            for (slot, col) in slots.iter().zip(cols.iter_mut()) {
                let Some((i, div, name)) = *slot else {
                    continue;
                };
                let text = record.get(i).unwrap_or("");
                let value: f64 = text.parse().map_err(|_| {
                    csv_error(line, format!("column {name}: `{text}` is not a number"))
                })?;
                if !value.is_finite() {
                    return Err(csv_error(
                        line,
                        format!("column {name}: `{text}` is not a finite number"),
                    ));
                }
                col.push(value / div);
            }
            lines.push(line);
        }

        if lines.len() < MIN_ROWS {
            return Err(csv_error(
                last_line,
                format!(
                    "only {} data rows: at least {MIN_ROWS} are needed",
                    lines.len()
                ),
            ));
        }
        let [t, u, x1, x2, v1, v2] = cols;
        check_time(&t).map_err(|(k, reason)| csv_error(lines[k], reason))?;
        Ok(Recording {
            t,
            u,
            x1,
            x2,
            v1: has_v1.then_some(v1),
            v2: has_v1.then_some(v2),
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
    /// let mut rec = Recording::new();
    /// for k in 0..6 {
    ///     rec.push(k as f64 * 0.002, 1.0, 1e-4 * k as f64, 2e-4 * k as f64);
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

    /// Writes the recording as CSV in SI units: header
    /// `t_s,u,x1_m,x2_m` plus `v1_m_s,v2_m_s` when the recording has
    /// velocities. Values are written in Rust's shortest round-trip form, so
    /// reading the output back gives the identical recording (metres are
    /// chosen over millimetres because the conversion would round).
    ///
    /// # Errors
    ///
    /// [`Error::InvalidRecording`] for columns of different lengths or a
    /// non-finite value (the reader would refuse them); [`Error::Io`] when
    /// the writer fails.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::Recording;
    /// let mut rec = Recording::new();
    /// rec.push(0.0, 2.0, 0.001, 0.0025);
    /// let mut out = Vec::new();
    /// rec.to_writer(&mut out)?;
    /// assert_eq!(String::from_utf8(out).unwrap(), "t_s,u,x1_m,x2_m\n0.0,2.0,0.001,0.0025\n");
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn to_writer(&self, writer: impl Write) -> Result<(), Error> {
        let n = self.len();
        let mut columns: Vec<&[f64]> = vec![&self.t, &self.u, &self.x1, &self.x2];
        let mut header = vec!["t_s", "u", "x1_m", "x2_m"];
        if let (Some(v1), Some(v2)) = (&self.v1, &self.v2) {
            columns.push(v1);
            columns.push(v2);
            header.extend(["v1_m_s", "v2_m_s"]);
        }
        for (name, col) in header.iter().zip(&columns) {
            if col.len() != n {
                return Err(Error::InvalidRecording {
                    index: col.len().min(n),
                    reason: format!("column {name} has {} samples, t has {n}", col.len()),
                });
            }
            if let Some(k) = col.iter().position(|v| !v.is_finite()) {
                return Err(Error::InvalidRecording {
                    index: k,
                    reason: format!("{name} = {} is not finite", col[k]),
                });
            }
        }
        let io = |e: csv::Error| match e.into_kind() {
            csv::ErrorKind::Io(e) => Error::io("writing CSV", &e),
            other => Error::io("writing CSV", &std::io::Error::other(format!("{other:?}"))),
        };
        let mut w = csv::Writer::from_writer(writer);
        w.write_record(&header).map_err(io)?;
        let mut fields: Vec<String> = Vec::with_capacity(columns.len());
        for k in 0..n {
            fields.clear();
            fields.extend(columns.iter().map(|c| format!("{:?}", c[k])));
            w.write_record(&fields).map_err(io)?;
        }
        w.flush().map_err(|e| Error::io("writing CSV", &e))
    }
}
