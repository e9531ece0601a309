//! Writing a [`Recording`] as CSV, through `csv-core`'s writer (which
//! quotes a field only where needed: never, for the headers and numbers a
//! recording has).

use std::fmt::Write as _;
use std::io::Write;
use std::path::Path;

use super::header::{Scale, header_of, parse_header};
use super::{CsvError, is_input_name};
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
    /// [`CsvError::Io`] (with the path) when the file cannot be created or
    /// written; the errors of [`to_writer`](Self::to_writer).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::Recording;
    /// # use ctrlab::data::Schema;
    /// let mut rec = Recording::new(Schema::numbered(1, 2)?);
    /// for k in 0..6 {
    ///     rec.push(k as f64 * 0.002, &[1.0], &[1e-4 * k as f64, 2e-4 * k as f64])?;
    /// }
    /// let path = std::env::temp_dir().join("ctrlab_doc_write_csv.csv");
    /// rec.write_csv(&path)?;
    /// assert_eq!(Recording::read_csv(&path)?, rec);
    /// # std::fs::remove_file(&path).ok();
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn write_csv(&self, path: impl AsRef<Path>) -> Result<(), CsvError> {
        let path = path.as_ref();
        // Checked before the file is created, so a refused recording leaves
        // no file behind (or an old one as it was).
        self.check_csv()?;
        let file = std::fs::File::create(path)
            .map_err(|e| CsvError::io(format!("creating {}", path.display()), e))?;
        // `write` buffers: the file gets large writes.
        self.write(file)
            .map_err(|e| CsvError::io(format!("writing {}", path.display()), e))
    }

    /// Writes the recording as CSV in SI units: header `t_s` and one column
    /// per channel (inputs, then measurements), each header the channel's
    /// name and unit (`x1_m`, `v1_m_s`, `u_V`; see [`KNOWN_UNITS`](crate::data::KNOWN_UNITS)). Values
    /// are written in Rust's shortest round-trip form, so reading the output
    /// back gives the identical recording.
    ///
    /// # Errors
    ///
    /// [`CsvError::Recording`] holding [`Error::InvalidRecording`] for a
    /// non-finite value (the reader would refuse it), or [`Error::Channel`]
    /// for a channel whose header would not read back as itself (a unit
    /// outside [`KNOWN_UNITS`](crate::data::KNOWN_UNITS) that is not SI
    /// such as `mm`, a name ending in a unit, a name `t` or `time`, or an
    /// input not named `u…` / a measurement named `u…`), so that every
    /// file written reads back identical; nothing is written then.
    /// [`CsvError::Io`] when the writer fails.
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
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn to_writer(&self, writer: impl Write) -> Result<(), CsvError> {
        self.check_csv()?;
        self.write(writer)
            .map_err(|e| CsvError::io("writing CSV", e))
    }

    /// Checks the recording can be written as CSV and read back identical.
    fn check_csv(&self) -> Result<(), CsvError> {
        self.check_values()
            .and_then(|()| self.check_round_trip())
            .map_err(|source| CsvError::Recording { source })
    }

    /// Writes the recording, checked, as CSV.
    fn write(&self, writer: impl Write) -> std::io::Result<()> {
        let mut out = Output::new(writer);
        out.field(b"t_s")?;
        for channel in self.schema.channels() {
            out.delimiter()?;
            out.field(header_of(channel).as_bytes())?;
        }
        out.terminator()?;
        // Each value in Rust's shortest round-trip form (`{:?}`: `2.0`,
        // `0.001`, `1e-7`), written into one reused string.
        let mut number = String::new();
        for k in 0..self.len() {
            for (i, v) in std::iter::once(self.t[k])
                .chain(self.columns.iter().map(|c| c[k]))
                .enumerate()
            {
                if i > 0 {
                    out.delimiter()?;
                }
                number.clear();
                write!(number, "{v:?}").unwrap_or_default();
                out.field(number.as_bytes())?;
            }
            out.terminator()?;
        }
        out.flush()
    }
}

/// `csv-core`'s writer on an [`io::Write`](Write), through a buffer.
struct Output<W> {
    core: csv_core::Writer,
    buf: Vec<u8>,
    /// How much of `buf` is written.
    len: usize,
    writer: W,
}

impl<W: Write> Output<W> {
    fn new(writer: W) -> Self {
        Self {
            core: csv_core::WriterBuilder::new().build(),
            buf: vec![0; 64 * 1024],
            len: 0,
            writer,
        }
    }

    /// Writes what the buffer holds.
    fn flush_buf(&mut self) -> std::io::Result<()> {
        self.writer.write_all(&self.buf[..self.len])?;
        self.len = 0;
        Ok(())
    }

    /// Writes a field, quoted if it needs to be.
    fn field(&mut self, mut input: &[u8]) -> std::io::Result<()> {
        loop {
            let (res, nin, nout) = self.core.field(input, &mut self.buf[self.len..]);
            input = &input[nin..];
            self.len += nout;
            match res {
                csv_core::WriteResult::InputEmpty => return Ok(()),
                csv_core::WriteResult::OutputFull => self.flush_buf()?,
            }
        }
    }

    /// Ends a field.
    fn delimiter(&mut self) -> std::io::Result<()> {
        loop {
            let (res, nout) = self.core.delimiter(&mut self.buf[self.len..]);
            self.len += nout;
            match res {
                csv_core::WriteResult::InputEmpty => return Ok(()),
                csv_core::WriteResult::OutputFull => self.flush_buf()?,
            }
        }
    }

    /// Ends a record (`\n`).
    fn terminator(&mut self) -> std::io::Result<()> {
        loop {
            let (res, nout) = self.core.terminator(&mut self.buf[self.len..]);
            self.len += nout;
            match res {
                csv_core::WriteResult::InputEmpty => return Ok(()),
                csv_core::WriteResult::OutputFull => self.flush_buf()?,
            }
        }
    }

    /// Writes what is buffered and flushes the writer.
    fn flush(&mut self) -> std::io::Result<()> {
        self.flush_buf()?;
        self.writer.flush()
    }
}
