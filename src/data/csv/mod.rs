//! CSV reading and writing of [`Recording`](super::Recording)s: the lines
//! of a log ([`lines`]: comments, blank lines, the separator), a header
//! and its units ([`header`]), one field's number ([`value`]), the options
//! ([`options`]), the reader ([`read`]) and the writer ([`write`]), and what
//! goes wrong ([`error`]).

mod error;
mod header;
mod lines;
mod options;
mod read;
mod value;
mod write;

pub use self::error::{CsvError, CsvErrorKind};
pub use self::options::CsvOptions;

/// The units the CSV reader recognises as a header suffix, with the SI unit
/// they stand for and how many of them make one SI unit:
/// `(suffix, SI unit, divisor)`. A header `x1_mm` is channel `x1` in `m`,
/// read values ÷ 1000 (a division, so `0.001` mm is exactly the double
/// nearest 1e-6 m); `v1_m_s` is `v1` in `m/s`. As a suffix a unit is
/// matched as written here; in brackets (`name [unit]`, with `/` for `_`)
/// ignoring case except for the letters `m` and `s`, which SI tells from
/// `M` (mega) and `S` (siemens): `U [v]` is in `V`, `x [MM]` is not in
/// `mm` (see [`Recording::from_reader_with`](crate::Recording::from_reader_with)).
/// The writer uses the SI suffixes.
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

/// Input channels in a file are those named `u` or `u` followed by digits
/// (python-control's and MATLAB's convention for inputs).
pub(super) fn is_input_name(name: &str) -> bool {
    name.strip_prefix('u')
        .is_some_and(|rest| rest.chars().all(|c| c.is_ascii_digit()))
}

/// A [`CsvError::Line`]: what is wrong on the file's line `line`.
pub(super) fn csv_error(line: u64, reason: impl Into<String>) -> CsvError {
    CsvError::Line {
        line,
        reason: reason.into(),
    }
}
