//! The averages over repeated runs (Tables 3 and 4).

use super::MassSpringEstimate;
use crate::error::Error;
use crate::kernels::reduce::pow2_floor;

/// Mean and sample standard deviation (divisor `n − 1`) of one parameter
/// over repeated runs.
///
/// # Examples
///
/// ```
/// # use ctrlab::lab::ident::Spread;
/// let s = Spread { mean: 950.0, std_dev: 4.0 };
/// assert_eq!(s.mean, 950.0);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Spread {
    /// Mean over the runs.
    pub mean: f64,
    /// Sample standard deviation over the runs (same unit).
    pub std_dev: f64,
}

/// The averages of Tables 3 and 4: each parameter's mean and spread over
/// repeated identification runs.
///
/// # Examples
///
/// ```
/// # use ctrlab::{Recording, lab::ident::{average, identify, Scheme}};
/// # let rec = Recording::read_csv(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ident_square_wave.csv"))?;
/// let est = identify(&rec, 1.3, 0.7, Scheme::Central)?;
/// let avg = average(&[est.clone(), est.clone()])?;
/// assert_eq!((avg.runs, avg.k12.mean, avg.k12.std_dev), (2, est.k12.value, 0.0));
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MassSpringAverage {
    /// Spring constant, N/m.
    pub k12: Spread,
    /// Friction of cart 1, N·s/m.
    pub b1: Spread,
    /// Motor gain, N per input unit.
    pub gain: Spread,
    /// Friction of cart 2, N·s/m.
    pub b2: Spread,
    /// Number of runs averaged.
    pub runs: usize,
}

impl Spread {
    /// Mean and sample standard deviation of `values` (e.g. one parameter of
    /// [`SeparateSpringsEstimate`](super::SeparateSpringsEstimate) over several runs).
    ///
    /// # Errors
    ///
    /// [`Error::TooFewSamples`] for fewer than two values;
    /// [`Error::InvalidData`] for a NaN or infinite value;
    /// [`Error::Overflow`] when the standard deviation exceeds `f64::MAX`.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::{Error, lab::ident::Spread};
    /// let s = Spread::of(&[948.0, 950.0, 952.0])?;
    /// assert_eq!((s.mean, s.std_dev), (950.0, 2.0));
    /// assert!(Spread::of(&[1.0]).is_err());
    /// // Values near f64::MAX do not overflow on the way.
    /// assert_eq!(Spread::of(&[1e308, 1e308])?.mean, 1e308);
    /// assert!(matches!(Spread::of(&[f64::NAN, 1.0]), Err(Error::InvalidData { index: 0, .. })));
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn of(values: &[f64]) -> Result<Self, Error> {
        if values.len() < 2 {
            return Err(Error::TooFewSamples {
                what: "mean and sample standard deviation",
                needed: 2,
                got: values.len(),
            });
        }
        if let Some(index) = values.iter().position(|v| !v.is_finite()) {
            return Err(Error::InvalidData {
                what: "values",
                index,
                reason: "value is not finite",
            });
        }
        spread(values.iter().copied(), values.len())
    }
}

/// Mean and sample standard deviation of `n ≥ 2` finite values, computed
/// on the values divided by a power of two near their largest magnitude so
/// that neither the sum nor the squares overflow or underflow.
fn spread(values: impl Iterator<Item = f64> + Clone, n: usize) -> Result<Spread, Error> {
    let scale = pow2_floor(values.clone().fold(0.0f64, |m, v| m.max(v.abs())));
    let scaled = values.map(|v| v / scale);
    let mean = scaled.clone().sum::<f64>() / n as f64;
    let var = scaled.map(|v| (v - mean) * (v - mean)).sum::<f64>() / (n - 1) as f64;
    let (mean, std_dev) = (mean * scale, var.sqrt() * scale);
    if !std_dev.is_finite() {
        return Err(Error::Overflow {
            operation: "sample standard deviation",
        });
    }
    Ok(Spread { mean, std_dev })
}

/// Mean and sample standard deviation of each parameter over repeated runs
/// (the "average" rows of Tables 3 and 4).
///
/// # Errors
///
/// [`Error::TooFewSamples`] for fewer than two runs (a sample standard
/// deviation needs two); [`Error::Overflow`] for a spread beyond `f64::MAX`.
///
/// # Examples
///
/// ```
/// # use ctrlab::{Error, lab::ident::average};
/// assert!(matches!(average(&[]), Err(Error::TooFewSamples { needed: 2, got: 0, .. })));
/// ```
pub fn average(runs: &[MassSpringEstimate]) -> Result<MassSpringAverage, Error> {
    let n = runs.len();
    if n < 2 {
        return Err(Error::TooFewSamples {
            what: "averaging identification runs",
            needed: 2,
            got: n,
        });
    }
    Ok(MassSpringAverage {
        k12: spread(runs.iter().map(|r| r.k12.value), n)?,
        b1: spread(runs.iter().map(|r| r.b1.value), n)?,
        gain: spread(runs.iter().map(|r| r.gain.value), n)?,
        b2: spread(runs.iter().map(|r| r.b2.value), n)?,
        runs: n,
    })
}
