//! [`CsvError`]: what can go wrong reading or writing a recording as CSV.

/// The category of a [`CsvError`], for callers that branch on what happened
/// rather than on the details.
///
/// `#[non_exhaustive]`: match with a wildcard arm.
///
/// # Examples
///
/// ```
/// use ctrlab::Recording;
/// use ctrlab::data::CsvErrorKind;
///
/// let err = Recording::from_reader("t_s,u\n0,1\n".as_bytes()).unwrap_err();
/// assert_eq!(err.kind(), CsvErrorKind::Line); // one row: too few
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum CsvErrorKind {
    /// Opening, reading or writing failed.
    Io,
    /// A line of the file is malformed.
    Line,
    /// The recording cannot be written as CSV.
    Recording,
    /// The [`CsvOptions`](super::CsvOptions) are invalid.
    Options,
}

/// What can go wrong reading or writing a [`Recording`](crate::Recording)
/// as CSV: the file (I/O, a malformed line), or what the caller handed in
/// (a recording that cannot be written, invalid options).
///
/// Not `Clone` or `PartialEq`: it keeps the [`std::io::Error`] as its
/// [`source`](std::error::Error::source). `#[non_exhaustive]`: match with a
/// wildcard arm.
///
/// # Examples
///
/// ```
/// use ctrlab::{Recording, data::CsvError};
///
/// let log = "t_s,u,x1_mm\n0,2,0\n0.002,2,0,1\n";
/// match Recording::from_reader(log.as_bytes()) {
///     Err(CsvError::Line { line, reason }) => {
///         assert_eq!(line, 3);
///         assert!(reason.contains("4 fields where the header has 3"), "{reason}");
///     }
///     other => panic!("{other:?}"),
/// }
///
/// let err = Recording::read_csv("no/such/log.csv").unwrap_err();
/// assert!(err.to_string().contains("no/such/log.csv"));
/// let io = std::error::Error::source(&err).unwrap().downcast_ref::<std::io::Error>().unwrap();
/// assert_eq!(io.kind(), std::io::ErrorKind::NotFound);
/// ```
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum CsvError {
    /// Opening, reading or writing failed.
    #[error("{context}: {source}")]
    Io {
        /// What was being done: the path when there is one (`"opening
        /// log.csv"`), and when reading, near which line of the file.
        context: String,
        /// The I/O error.
        #[source]
        source: std::io::Error,
    },
    /// A line of the file is malformed: no header, a missing or unit-less
    /// time column, two columns for one channel, a column in encoder counts
    /// without a calibration, a row of the wrong width, a value that is not
    /// a finite number (or holds a thousands separator, or is not UTF-8), a
    /// time column that does not increase, too few rows.
    #[error("CSV line {line}: {reason}")]
    Line {
        /// One-based line number in the file, comment and blank lines
        /// counted (a header after two comment lines is line 3).
        line: u64,
        /// What is wrong on that line, with what was found there.
        reason: String,
    },
    /// The recording cannot be written as CSV so that it reads back
    /// identical: a value that is not finite
    /// ([`Error::InvalidRecording`](crate::Error::InvalidRecording)), or a
    /// channel whose header would not read back as itself
    /// ([`Error::Channel`](crate::Error::Channel)).
    #[error("cannot write the recording as CSV: {source}")]
    Recording {
        /// What is wrong with the recording.
        #[source]
        source: crate::Error,
    },
    /// The [`CsvOptions`](super::CsvOptions) are invalid
    /// ([`Error::InvalidParameter`](crate::Error::InvalidParameter) naming
    /// the field).
    #[error("invalid CSV options: {source}")]
    Options {
        /// Which option, and why.
        #[source]
        source: crate::Error,
    },
}

impl CsvError {
    /// The category of this error.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{Recording, data::{CsvErrorKind, CsvOptions}};
    /// let options = CsvOptions { metres_per_count: Some(-1.0) };
    /// let err = Recording::from_reader_with("t_s,u\n0,1\n1,1\n".as_bytes(), &options).unwrap_err();
    /// assert_eq!(err.kind(), CsvErrorKind::Options);
    /// ```
    pub fn kind(&self) -> CsvErrorKind {
        match self {
            CsvError::Io { .. } => CsvErrorKind::Io,
            CsvError::Line { .. } => CsvErrorKind::Line,
            CsvError::Recording { .. } => CsvErrorKind::Recording,
            CsvError::Options { .. } => CsvErrorKind::Options,
        }
    }

    /// A [`CsvError::Io`] from what was being done and the I/O error.
    pub(super) fn io(context: impl Into<String>, source: std::io::Error) -> Self {
        CsvError::Io {
            context: context.into(),
            source,
        }
    }
}
