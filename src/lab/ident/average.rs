//! The averages over repeated runs (Tables 3 and 4).

use super::{MassSpringEstimate, SeparateSpringsEstimate};
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
/// # Ok::<(), Box<dyn std::error::Error>>(())
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

/// The averaged model of repeated separate-springs identifications
/// ([`average_separate_springs`]): each parameter's mean and spread over
/// the runs, and the model of the means.
///
/// # Examples
///
/// ```
/// # use ctrlab::{Recording, lab::ident::{average_separate_springs, identify_separate_springs, Scheme}};
/// # let rec = Recording::read_csv(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ident_square_wave.csv"))?;
/// let est = identify_separate_springs(&rec, 1.3, 0.7, Scheme::Central)?;
/// let avg = average_separate_springs(&[est.clone(), est.clone()])?;
/// assert_eq!(avg.plant(), est.plant());
/// assert_eq!((avg.runs, avg.k2.std_dev, avg.coulomb), (2, 0.0, None));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SeparateSpringsAverage {
    /// Spring between the wall and cart 1, N/m.
    pub k1: Spread,
    /// Spring between the carts, N/m.
    pub k2: Spread,
    /// Viscous friction of cart 1, N·s/m.
    pub b1: Spread,
    /// Motor gain `K`, N per input unit.
    pub gain: Spread,
    /// Viscous friction of cart 2, N·s/m.
    pub b2: Spread,
    /// Coulomb friction force of cart 1 and cart 2, N, when every run
    /// fitted it.
    pub coulomb: Option<[Spread; 2]>,
    /// Mass of cart 1, kg (the same in every run).
    pub m1: f64,
    /// Mass of cart 2, kg: the one given (spread 0), or the fitted ones
    /// ([`Options::free_m2`](super::Options::free_m2)).
    pub m2: Spread,
    /// Number of runs averaged.
    pub runs: usize,
}

impl SeparateSpringsAverage {
    /// The model of the means, as [`MassSpring`](crate::lab::MassSpring)
    /// parameters (the linear part, for design).
    pub fn plant(&self) -> crate::lab::MassSpring {
        crate::lab::MassSpring {
            m1: self.m1,
            m2: self.m2.mean,
            k1: self.k1.mean,
            k2: self.k2.mean,
            b1: self.b1.mean,
            b2: self.b2.mean,
            gain: self.gain.mean,
        }
    }

    /// The model of the means with its mean Coulomb forces (each at least
    /// 0; none when not fitted), to simulate.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::{Recording, lab::ident::{Options, average_separate_springs, identify_separate_springs_with}};
    /// # let rec = Recording::read_csv(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ident_square_wave.csv"))?;
    /// let est = identify_separate_springs_with(&rec, 1.3, 0.7, &Options { coulomb: true, ..Options::DEFAULT })?;
    /// let avg = average_separate_springs(&[est.clone(), est.clone()])?;
    /// assert_eq!(avg.friction_plant(), est.friction_plant());
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn friction_plant(&self) -> crate::lab::FrictionPlant {
        let forces = self
            .coulomb
            .map_or([0.0; 2], |c| c.map(|f| f.mean.max(0.0)));
        crate::lab::FrictionPlant::new(self.plant(), forces)
    }
}

/// Averages repeated separate-springs identifications (one per run) into
/// one model: each parameter's mean and sample standard deviation.
///
/// # Errors
///
/// [`Error::TooFewSamples`] for fewer than two runs;
/// [`Error::InvalidParameter`] when the runs were identified with different
/// `m1`, or some with Coulomb friction and some without (their parameters
/// mean different things); [`Error::Overflow`] for a spread beyond
/// `f64::MAX`.
///
/// # Examples
///
/// ```
/// # use ctrlab::{Error, Recording, lab::ident::{Options, average_separate_springs, identify_separate_springs, identify_separate_springs_with, Scheme}};
/// # let rec = Recording::read_csv(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ident_square_wave.csv"))?;
/// let a = identify_separate_springs(&rec, 1.3, 0.7, Scheme::Central)?;
/// let b = identify_separate_springs(&rec, 1.2, 0.7, Scheme::Central)?;
/// assert!(matches!(average_separate_springs(&[a.clone(), b]), Err(Error::InvalidParameter { name: "m1", .. })));
/// let friction = Options { coulomb: true, ..Options::DEFAULT };
/// let c = identify_separate_springs_with(&rec, 1.3, 0.7, &friction)?;
/// assert!(matches!(average_separate_springs(&[a, c]), Err(Error::InvalidParameter { name: "coulomb", .. })));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn average_separate_springs(
    runs: &[SeparateSpringsEstimate],
) -> Result<SeparateSpringsAverage, Error> {
    let n = runs.len();
    let Some(first) = runs.first().filter(|_| n >= 2) else {
        return Err(Error::TooFewSamples {
            what: "averaging identification runs",
            needed: 2,
            got: n,
        });
    };
    if let Some(other) = runs.iter().find(|r| r.m1 != first.m1) {
        return Err(Error::InvalidParameter {
            name: "m1",
            value: other.m1,
            reason: "the runs were identified with different masses of cart 1",
        });
    }
    if runs
        .iter()
        .any(|r| r.coulomb.is_some() != first.coulomb.is_some())
    {
        return Err(Error::InvalidParameter {
            name: "coulomb",
            value: runs.iter().filter(|r| r.coulomb.is_some()).count() as f64,
            reason: "runs with and without Coulomb friction cannot be averaged",
        });
    }
    let of = |f: fn(&SeparateSpringsEstimate) -> f64| spread(runs.iter().map(f), n);
    let coulomb = match first.coulomb {
        Some(_) => {
            let force = |cart: usize| {
                spread(
                    runs.iter()
                        .filter_map(move |r| Some(r.coulomb?[cart].value)),
                    n,
                )
            };
            Some([force(0)?, force(1)?])
        }
        None => None,
    };
    Ok(SeparateSpringsAverage {
        k1: of(|r| r.k1.value)?,
        k2: of(|r| r.k2.value)?,
        b1: of(|r| r.b1.value)?,
        gain: of(|r| r.gain.value)?,
        b2: of(|r| r.b2.value)?,
        coulomb,
        m1: first.m1,
        m2: of(|r| r.m2)?,
        runs: n,
    })
}
