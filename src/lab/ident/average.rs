//! The averages over repeated runs (Tables 3 and 4): one
//! [`MassSpringAverage`] of whatever the runs identified.

use std::fmt;

use super::estimates::plus_minus;
use super::{MassSpringEstimate, SpringModel, Springs};
use crate::error::{Error, ErrorKind};
use crate::kernels::reduce::pow2_floor;
use crate::lab::{FrictionPlant, MassSpring};

/// Mean and sample standard deviation (divisor `n − 1`) of one parameter
/// over repeated runs.
///
/// Displays as `mean ± std_dev`, the formatter's precision applying to
/// both.
///
/// # Examples
///
/// ```
/// # use ctrlab::lab::ident::Spread;
/// let s = Spread { mean: 950.0, std_dev: 4.0 };
/// assert_eq!(s.mean, 950.0);
/// assert_eq!(format!("{s:.1}"), "950.0 ± 4.0");
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Spread {
    /// Mean over the runs.
    pub mean: f64,
    /// Sample standard deviation over the runs (same unit).
    pub std_dev: f64,
}

impl fmt::Display for Spread {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        plus_minus(f, self.mean, self.std_dev)
    }
}

impl Spread {
    /// Mean and sample standard deviation of `values` (e.g. one parameter of
    /// [`MassSpringEstimate`] over several runs).
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

/// The averages of Tables 3 and 4: each parameter's mean and spread over
/// repeated identification runs ([`average`]), and the model of the
/// means. The springs are those the runs identified: `k12` for the lab's
/// equal springs, `k1` and `k2` for separate ones.
///
/// # Examples
///
/// ```
/// # use ctrlab::{Recording, lab::ident::{average, identify, Scheme}};
/// # let rec = Recording::read_csv(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ident_square_wave.csv"))?;
/// let est = identify(&rec, 1.3, 0.7, Scheme::Central)?;
/// let avg = average(&[est.clone(), est.clone()])?;
/// let k12 = avg.k12().unwrap();
/// assert_eq!((avg.runs, k12.mean, k12.std_dev), (2, est.k12().unwrap().value, 0.0));
/// assert_eq!(avg.plant(), est.plant());
/// assert_eq!(avg.coulomb, None);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MassSpringAverage {
    /// The springs, N/m, as the runs identified them.
    pub springs: Springs<Spread>,
    /// Viscous friction of cart 1, N·s/m.
    pub b1: Spread,
    /// Motor gain `K`, N per input unit.
    pub gain: Spread,
    /// Viscous friction of cart 2, N·s/m.
    pub b2: Spread,
    /// Coulomb friction force of cart 1 and cart 2, N, when the runs
    /// fitted it.
    pub coulomb: Option<[Spread; 2]>,
    /// Mass of cart 1, kg (the same in every run).
    pub m1: f64,
    /// Mass of cart 2, kg: the one given (the same in every run), or the
    /// fitted ones ([`Options::free_m2`](super::Options::free_m2)). Given,
    /// it is averaged like the others, so its mean and spread are the mass
    /// and 0 to within rounding (three runs of 0.7 kg: 0.6999999999999998).
    pub m2: Spread,
    /// Number of runs averaged.
    pub runs: usize,
}

impl MassSpringAverage {
    /// The spring between the wall and cart 1, N/m: `k12` for equal
    /// springs ([`Springs::k1`]).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::{Recording, lab::ident::{Options, SpringModel, average, identify_with}};
    /// # let rec = Recording::read_csv(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ident_square_wave.csv"))?;
    /// let est = identify_with(&rec, 1.3, 0.7, &Options { springs: SpringModel::Separate, ..Options::DEFAULT })?;
    /// assert_eq!(average(&[est.clone(), est.clone()])?.k1().mean, est.k1().value);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn k1(&self) -> Spread {
        self.springs.k1()
    }

    /// The spring between the carts, N/m: `k12` for equal springs
    /// ([`Springs::k2`]).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::{Recording, lab::ident::{Options, SpringModel, average, identify_with}};
    /// # let rec = Recording::read_csv(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ident_square_wave.csv"))?;
    /// let est = identify_with(&rec, 1.3, 0.7, &Options { springs: SpringModel::Separate, ..Options::DEFAULT })?;
    /// assert_eq!(average(&[est.clone(), est.clone()])?.k2().mean, est.k2().value);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn k2(&self) -> Spread {
        self.springs.k2()
    }

    /// `k12`, N/m, when the runs identified equal springs; `None` for
    /// separate ones ([`Springs::k12`]).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::{Recording, lab::ident::{Scheme, average, identify}};
    /// # let rec = Recording::read_csv(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ident_square_wave.csv"))?;
    /// let est = identify(&rec, 1.3, 0.7, Scheme::Lab)?;
    /// assert_eq!(average(&[est.clone(), est.clone()])?.k12().map(|k| k.std_dev), Some(0.0));
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn k12(&self) -> Option<Spread> {
        self.springs.k12()
    }

    /// The model of the means, as [`MassSpring`] parameters (the linear
    /// part, for design; equal springs: `k1 = k2 = k12`).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::{Recording, lab::ident::{Scheme, average, identify}};
    /// # let rec = Recording::read_csv(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ident_square_wave.csv"))?;
    /// let est = identify(&rec, 1.3, 0.7, Scheme::Central)?;
    /// let plant = average(&[est.clone(), est])?.plant();
    /// assert_eq!(plant.k1, plant.k2);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn plant(&self) -> MassSpring {
        MassSpring {
            m1: self.m1,
            m2: self.m2.mean,
            k1: self.k1().mean,
            k2: self.k2().mean,
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
    /// # use ctrlab::{Recording, lab::ident::{Options, SpringModel, average, identify_with}};
    /// # let rec = Recording::read_csv(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ident_square_wave.csv"))?;
    /// let options = Options { springs: SpringModel::Separate, coulomb: true, ..Options::DEFAULT };
    /// let est = identify_with(&rec, 1.3, 0.7, &options)?;
    /// let avg = average(&[est.clone(), est.clone()])?;
    /// assert_eq!(avg.friction_plant(), est.friction_plant());
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn friction_plant(&self) -> FrictionPlant {
        let forces = self
            .coulomb
            .map_or([0.0; 2], |c| c.map(|f| f.mean.max(0.0)));
        FrictionPlant::new(self.plant(), forces)
    }
}

/// Why [`average`] did not average the runs: too few of them or a spread
/// beyond `f64::MAX` (the numeric [`Error`]), or runs whose parameters
/// mean different things ([`Mismatch`]).
///
/// # Examples
///
/// ```
/// use ctrlab::{Error, ErrorKind, Recording};
/// use ctrlab::lab::ident::{AverageError, Mismatch, Options, SpringModel, average, identify_with};
///
/// let rec = Recording::read_csv(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ident_square_wave.csv"))?;
/// let equal = identify_with(&rec, 1.3, 0.7, &Options::DEFAULT)?;
/// let separate = identify_with(&rec, 1.3, 0.7, &Options { springs: SpringModel::Separate, ..Options::DEFAULT })?;
/// let err = average(&[equal.clone(), separate]).unwrap_err();
/// assert_eq!(err, AverageError::Mismatch {
///     run: 1,
///     what: Mismatch::Springs { first: SpringModel::Equal, other: SpringModel::Separate },
/// });
/// assert_eq!(err.kind(), ErrorKind::InvalidInput);
/// assert!(err.to_string().contains("spring models"));
/// assert!(matches!(average(&[equal]), Err(AverageError::Data(Error::TooFewSamples { needed: 2, got: 1, .. }))));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum AverageError {
    /// Fewer than two runs ([`Error::TooFewSamples`]), or a spread beyond
    /// `f64::MAX` ([`Error::Overflow`]).
    #[error(transparent)]
    Data(#[from] Error),
    /// Run `run` (from 0) was identified otherwise than run 0 in `what`.
    #[error("run {run} cannot be averaged with run 0: {what}")]
    Mismatch {
        /// The first run that differs from run 0, counted from 0.
        run: usize,
        /// What differs.
        what: Mismatch,
    },
}

impl AverageError {
    /// The category of the error: the numeric error's own, or
    /// [`ErrorKind::InvalidInput`] for runs that do not match.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{Error, ErrorKind, lab::ident::AverageError};
    /// let e = AverageError::from(Error::Overflow { operation: "sample standard deviation" });
    /// assert_eq!(e.kind(), ErrorKind::Numerical);
    /// ```
    pub fn kind(&self) -> ErrorKind {
        match self {
            AverageError::Data(e) => e.kind(),
            AverageError::Mismatch { .. } => ErrorKind::InvalidInput,
        }
    }
}

/// What differs between two runs [`average`] will not mix
/// ([`AverageError::Mismatch`]): `first` is run 0's, `other` the
/// differing run's.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::ident::Mismatch;
/// let m = Mismatch::M1 { first: 1.3, other: 1.2 };
/// assert_eq!(m.to_string(), "the masses of cart 1 differ (1.3 kg, 1.2 kg)");
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum Mismatch {
    /// Equal springs in one run, separate in the other: `k12` is not
    /// `k1`.
    Springs {
        /// Run 0's spring model.
        first: SpringModel,
        /// The other run's.
        other: SpringModel,
    },
    /// The masses of cart 1 given, kg: every estimate scales with it.
    M1 {
        /// Run 0's.
        first: f64,
        /// The other run's.
        other: f64,
    },
    /// The masses of cart 2 given, kg (both given, not fitted).
    M2 {
        /// Run 0's.
        first: f64,
        /// The other run's.
        other: f64,
    },
    /// Cart 2's mass fitted ([`Options::free_m2`](super::Options::free_m2))
    /// in one run and given in the other.
    FreeM2 {
        /// Whether run 0 fitted it.
        first: bool,
        /// Whether the other run did.
        other: bool,
    },
    /// Coulomb friction fitted ([`Options::coulomb`](super::Options::coulomb))
    /// in one run and not in the other: the viscous frictions then mean
    /// different things.
    Coulomb {
        /// Whether run 0 fitted it.
        first: bool,
        /// Whether the other run did.
        other: bool,
    },
}

impl fmt::Display for Mismatch {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let fitted = |yes: bool| if yes { "fitted" } else { "not fitted" };
        match *self {
            Mismatch::Springs { first, other } => {
                write!(f, "the spring models differ ({first:?}, {other:?})")
            }
            Mismatch::M1 { first, other } => {
                write!(f, "the masses of cart 1 differ ({first} kg, {other} kg)")
            }
            Mismatch::M2 { first, other } => {
                write!(f, "the masses of cart 2 differ ({first} kg, {other} kg)")
            }
            Mismatch::FreeM2 { first, other } => write!(
                f,
                "cart 2's mass is {} in one and {} in the other",
                fitted(first),
                fitted(other)
            ),
            Mismatch::Coulomb { first, other } => write!(
                f,
                "Coulomb friction is {} in one and {} in the other",
                fitted(first),
                fitted(other)
            ),
        }
    }
}

/// The first thing `other` was identified with otherwise than `first`.
fn mismatch(first: &MassSpringEstimate, other: &MassSpringEstimate) -> Option<Mismatch> {
    let (a, b) = (first.springs.model(), other.springs.model());
    if a != b {
        return Some(Mismatch::Springs { first: a, other: b });
    }
    if first.m1 != other.m1 {
        return Some(Mismatch::M1 {
            first: first.m1,
            other: other.m1,
        });
    }
    let (a, b) = (first.m2_estimate.is_some(), other.m2_estimate.is_some());
    if a != b {
        return Some(Mismatch::FreeM2 { first: a, other: b });
    }
    if !a && first.m2 != other.m2 {
        return Some(Mismatch::M2 {
            first: first.m2,
            other: other.m2,
        });
    }
    let (a, b) = (first.coulomb.is_some(), other.coulomb.is_some());
    (a != b).then_some(Mismatch::Coulomb { first: a, other: b })
}

/// Mean and sample standard deviation of each parameter over repeated runs
/// (the "average" rows of Tables 3 and 4), of whatever the runs
/// identified: the springs of their model, the Coulomb forces when fitted,
/// cart 2's mass.
///
/// # Errors
///
/// [`AverageError::Mismatch`] when a run was identified with another
/// spring model, another mass of cart 1, another given mass of cart 2, or
/// with cart 2's mass or the Coulomb forces fitted where the first run did
/// not (or the reverse): their parameters mean different things.
/// [`AverageError::Data`] with [`Error::TooFewSamples`] for fewer than two
/// runs (a sample standard deviation needs two), [`Error::InvalidParameter`]
/// naming `m1` or `m2` for a run's mass that is not finite and positive,
/// [`Error::Overflow`] for a spread beyond `f64::MAX`.
///
/// # Examples
///
/// ```
/// # use ctrlab::{Error, Recording, lab::ident::{AverageError, Mismatch, Options, average, identify_with}};
/// # let rec = Recording::read_csv(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ident_square_wave.csv"))?;
/// assert!(matches!(average(&[]), Err(AverageError::Data(Error::TooFewSamples { needed: 2, got: 0, .. }))));
/// let a = identify_with(&rec, 1.3, 0.7, &Options::DEFAULT)?;
/// let b = identify_with(&rec, 1.2, 0.7, &Options::DEFAULT)?;
/// assert!(matches!(
///     average(&[a.clone(), a.clone(), b]),
///     Err(AverageError::Mismatch { run: 2, what: Mismatch::M1 { first: 1.3, other: 1.2 } })
/// ));
/// let c = identify_with(&rec, 1.3, 0.7, &Options { coulomb: true, ..Options::DEFAULT })?;
/// assert!(matches!(
///     average(&[a, c]),
///     Err(AverageError::Mismatch { run: 1, what: Mismatch::Coulomb { first: false, other: true } })
/// ));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn average(runs: &[MassSpringEstimate]) -> Result<MassSpringAverage, AverageError> {
    let n = runs.len();
    let Some(first) = runs.first().filter(|_| n >= 2) else {
        return Err(Error::TooFewSamples {
            what: "averaging identification runs",
            needed: 2,
            got: n,
        }
        .into());
    };
    // A mass that is not a mass would otherwise be copied into the
    // average (m1), or read as runs identified with different masses (NaN
    // differs from itself).
    for r in runs {
        for (name, value) in [("m1", r.m1), ("m2", r.m2)] {
            if !(value.is_finite() && value > 0.0) {
                return Err(Error::InvalidParameter {
                    name,
                    value,
                    reason: "a run's cart mass must be finite and > 0, kg",
                }
                .into());
            }
        }
    }
    if let Some((run, what)) = runs
        .iter()
        .enumerate()
        .find_map(|(i, r)| Some((i, mismatch(first, r)?)))
    {
        return Err(AverageError::Mismatch { run, what });
    }
    let of = |f: fn(&MassSpringEstimate) -> f64| spread(runs.iter().map(f), n);
    let springs = match first.springs.model() {
        SpringModel::Equal => Springs::Equal {
            k12: of(|r| r.k1().value)?,
        },
        SpringModel::Separate => Springs::Separate {
            k1: of(|r| r.k1().value)?,
            k2: of(|r| r.k2().value)?,
        },
    };
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
    Ok(MassSpringAverage {
        springs,
        b1: of(|r| r.b1.value)?,
        gain: of(|r| r.gain.value)?,
        b2: of(|r| r.b2.value)?,
        coulomb,
        m1: first.m1,
        m2: of(|r| r.m2)?,
        runs: n,
    })
}
