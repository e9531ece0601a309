//! Writing a [`Recording`] as CSV.

use std::io::Write;
use std::path::Path;

use super::header::{Scale, header_of, parse_header};
use super::is_input_name;
use crate::data::Recording;
use crate::error::Error;

impl Recording {
    /// Checks every channel's header reads back as the same channel in the
    /// same role, so that a written file always reads back identical.
    fn check_round_trip(&self) -> Result<(), Error> {
        let inputs = self.schema.inputs().len();
        for (k, channel) in self.schema.channels().enumerate() {
            let (parsed, scale) = parse_header(&header_of(channel));
            let reason = if matches!(parsed.name.as_str(), "t" | "time") {
                Some("a channel cannot be named like the time column (t, time)")
            } else if parsed.name != channel.name && parsed.name == channel.name.to_lowercase() {
                Some(
                    "the CSV reader reads names in lower case: \
                     name it in lower case so that it reads back",
                )
            } else if parsed != *channel || scale != Scale::Divide(1.0) {
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

impl Recording {
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
    /// name and unit (`x1_m`, `v1_m_s`, `u_V`; see [`KNOWN_UNITS`](crate::data::KNOWN_UNITS)). Values
    /// are written in Rust's shortest round-trip form, so reading the output
    /// back gives the identical recording.
    ///
    /// # Errors
    ///
    /// [`Error::InvalidRecording`] for a non-finite value (the reader would
    /// refuse it); [`Error::Channel`] for a channel whose header would not
    /// read back as itself (a unit outside [`KNOWN_UNITS`](crate::data::KNOWN_UNITS) that is not SI
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
