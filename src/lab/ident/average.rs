//! The averages over repeated runs (Tables 3 and 4).

use super::MassSpringEstimate;
use crate::error::Error;

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
    /// [`Error::TooFewSamples`] for fewer than two values.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::lab::ident::Spread;
    /// let s = Spread::of(&[948.0, 950.0, 952.0])?;
    /// assert_eq!((s.mean, s.std_dev), (950.0, 2.0));
    /// assert!(Spread::of(&[1.0]).is_err());
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
        Ok(spread(values.iter().copied(), values.len()))
    }
}

fn spread(values: impl Iterator<Item = f64> + Clone, n: usize) -> Spread {
    let mean = values.clone().sum::<f64>() / n as f64;
    let var = values.map(|v| (v - mean) * (v - mean)).sum::<f64>() / (n - 1) as f64;
    Spread {
        mean,
        std_dev: var.sqrt(),
    }
}

/// Mean and sample standard deviation of each parameter over repeated runs
/// (the "average" rows of Tables 3 and 4).
///
/// # Errors
///
/// [`Error::TooFewSamples`] for fewer than two runs (a sample standard
/// deviation needs two).
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
        k12: spread(runs.iter().map(|r| r.k12.value), n),
        b1: spread(runs.iter().map(|r| r.b1.value), n),
        gain: spread(runs.iter().map(|r| r.gain.value), n),
        b2: spread(runs.iter().map(|r| r.b2.value), n),
        runs: n,
    })
}
