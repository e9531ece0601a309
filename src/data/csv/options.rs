//! [`CsvOptions`]: what the reader needs to know that a log does not say.

use super::CsvError;
use crate::error::Error;

/// What the CSV reader needs to know that a log does not say about itself:
/// the calibration of raw encoder counts. The default reads every log that
/// has no column in counts.
///
/// Used by [`Recording::from_reader_with`](crate::Recording::from_reader_with)
/// and [`Recording::read_csv_with`](crate::Recording::read_csv_with).
///
/// # Examples
///
/// ```
/// use ctrlab::{Recording, data::CsvOptions};
///
/// // The lab's encoders: 102 400 counts per metre.
/// let options = CsvOptions { metres_per_count: Some(1.0 / 102_400.0), ..Default::default() };
/// let log = "t_s,u_V,x1_counts\n0,2,0\n0.002,2,512\n";
/// let rec = Recording::from_reader_with(log.as_bytes(), &options)?;
/// assert_eq!(rec.channel("x1")?[1], 512.0 * (1.0 / 102_400.0)); // 5 mm, in m
/// assert_eq!(rec.schema().measurements()[0].unit, "m");
///
/// // Without the calibration a column in counts is refused.
/// assert!(Recording::from_reader_with(log.as_bytes(), &CsvOptions::default()).is_err());
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct CsvOptions {
    /// Metres per encoder count, m (finite and positive): a column whose
    /// unit is `counts` (`x1_counts`, `x1 [counts]`, `x1 [cnt]`) is read as
    /// the channel in `m`, each value times this. `None` (the default): a
    /// column in counts is a [`CsvError::Line`] on the header line.
    pub metres_per_count: Option<f64>,
}

impl CsvOptions {
    /// Checks every field: [`CsvError::Options`] holding the
    /// [`Error::InvalidParameter`] that names the first bad one.
    pub(super) fn check(&self) -> Result<(), CsvError> {
        match self.metres_per_count {
            Some(m) if !(m.is_finite() && m > 0.0) => Err(CsvError::Options {
                source: Error::InvalidParameter {
                    name: "metres_per_count",
                    value: m,
                    reason: "must be finite and positive (m per encoder count)",
                },
            }),
            _ => Ok(()),
        }
    }
}
