//! The identified parameters: [`Estimate`], [`Springs`],
//! [`MassSpringEstimate`].

use std::fmt;

use super::{Scheme, SpringModel, Timing};
use crate::error::Error;
use crate::ident::LeastSquaresFit;
use crate::lab::{Cart, FrictionPlant, MassSpring};
use crate::model::{Continuous, StateSpace};

/// One identified parameter and its standard error (same unit).
///
/// # Examples
///
/// ```
/// # use ctrlab::lab::ident::Estimate;
/// let k = Estimate { value: 950.0, std_error: 1.9 };
/// assert!((k.relative_error() - 0.002).abs() < 1e-15);
/// // `value ± std_error`, the precision applying to both.
/// assert_eq!(format!("{k:.1}"), "950.0 ± 1.9");
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Estimate {
    /// The estimate.
    pub value: f64,
    /// Its standard error (same unit), from the covariance
    /// [`Options::covariance`](super::Options::covariance) chose
    /// (Newey–West by default).
    pub std_error: f64,
}

impl Estimate {
    /// `std_error / |value|`.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::lab::ident::Estimate;
    /// assert_eq!(Estimate { value: -2.0, std_error: 0.5 }.relative_error(), 0.25);
    /// ```
    pub fn relative_error(&self) -> f64 {
        self.std_error / self.value.abs()
    }
}

impl fmt::Display for Estimate {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        plus_minus(f, self.value, self.std_error)
    }
}

/// `value ± error`, with the formatter's precision (if any) on both.
pub(super) fn plus_minus(f: &mut fmt::Formatter<'_>, value: f64, error: f64) -> fmt::Result {
    match f.precision() {
        Some(p) => write!(f, "{value:.p$} ± {error:.p$}"),
        None => write!(f, "{value} ± {error}"),
    }
}

/// The identified springs, N/m: the lab's equal springs `k1 = k2 = k12`
/// (equations (4)–(11)), or `k1` and `k2` apart
/// ([`SpringModel::Separate`]). `T` is what is known of each:
/// an [`Estimate`] in a [`MassSpringEstimate`], a
/// [`Spread`](super::Spread) over runs in a
/// [`MassSpringAverage`](super::MassSpringAverage).
///
/// Displays in N/m, the formatter's precision applying to every number.
///
/// # Examples
///
/// ```
/// use ctrlab::{Recording, lab::ident::{Estimate, Options, SpringModel, Springs, identify_with}};
///
/// let equal = Springs::Equal { k12: Estimate { value: 950.0, std_error: 1.9 } };
/// assert_eq!(equal.k2(), equal.k1());
/// assert_eq!(equal.k12(), Some(equal.k1()));
/// assert_eq!(format!("{equal:.1}"), "k12 = 950.0 ± 1.9 N/m");
///
/// let rec = Recording::read_csv(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ident_square_wave.csv"))?;
/// let options = Options { springs: SpringModel::Separate, ..Options::default() };
/// let est = identify_with(&rec, 1.3, 0.7, &options)?;
/// assert_eq!(est.springs.model(), SpringModel::Separate);
/// assert_eq!(est.springs.k12(), None);
/// assert_eq!(format!("{:.1}", est.springs), "k1 = 950.0 ± 0.1 N/m, k2 = 950.0 ± 0.1 N/m");
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Springs<T = Estimate> {
    /// `k1 = k2 = k12`, the lab's model ([`SpringModel::Equal`]).
    Equal {
        /// Both springs, N/m.
        k12: T,
    },
    /// The springs apart ([`SpringModel::Separate`]).
    Separate {
        /// The spring between the wall and cart 1, N/m.
        k1: T,
        /// The spring between the carts, N/m.
        k2: T,
    },
}

impl<T: Copy> Springs<T> {
    /// The spring between the wall and cart 1: `k12` for equal springs.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::lab::ident::Springs;
    /// assert_eq!(Springs::Equal { k12: 950.0 }.k1(), 950.0);
    /// assert_eq!(Springs::Separate { k1: 940.0, k2: 1050.0 }.k1(), 940.0);
    /// ```
    pub fn k1(&self) -> T {
        match *self {
            Springs::Equal { k12 } => k12,
            Springs::Separate { k1, .. } => k1,
        }
    }

    /// The spring between the carts: `k12` for equal springs.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::lab::ident::Springs;
    /// assert_eq!(Springs::Equal { k12: 950.0 }.k2(), 950.0);
    /// assert_eq!(Springs::Separate { k1: 940.0, k2: 1050.0 }.k2(), 1050.0);
    /// ```
    pub fn k2(&self) -> T {
        match *self {
            Springs::Equal { k12 } => k12,
            Springs::Separate { k2, .. } => k2,
        }
    }

    /// `k12` of equal springs; `None` for separate ones.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::lab::ident::Springs;
    /// assert_eq!(Springs::Equal { k12: 950.0 }.k12(), Some(950.0));
    /// assert_eq!(Springs::Separate { k1: 940.0, k2: 1050.0 }.k12(), None);
    /// ```
    pub fn k12(&self) -> Option<T> {
        match *self {
            Springs::Equal { k12 } => Some(k12),
            Springs::Separate { .. } => None,
        }
    }

    /// Which model these springs are.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::lab::ident::{SpringModel, Springs};
    /// assert_eq!(Springs::Equal { k12: 950.0 }.model(), SpringModel::Equal);
    /// ```
    pub fn model(&self) -> SpringModel {
        match self {
            Springs::Equal { .. } => SpringModel::Equal,
            Springs::Separate { .. } => SpringModel::Separate,
        }
    }
}

impl<T: fmt::Display> fmt::Display for Springs<T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let one = |f: &mut fmt::Formatter<'_>, name: &str, k: &T| match f.precision() {
            Some(p) => write!(f, "{name} = {k:.p$} N/m"),
            None => write!(f, "{name} = {k} N/m"),
        };
        match self {
            Springs::Equal { k12 } => one(f, "k12", k12),
            Springs::Separate { k1, k2 } => {
                one(f, "k1", k1)?;
                f.write_str(", ")?;
                one(f, "k2", k2)
            }
        }
    }
}

/// The parameters identified by [`identify_with`](super::identify_with)
/// (and [`identify`](super::identify)): the springs as
/// [`Options::springs`](super::Options::springs) chose — the lab's equal
/// springs, or separate ones as a case of the same estimate — then cart
/// 1's friction, the motor's gain and cart 2's friction.
///
/// # Examples
///
/// ```
/// use ctrlab::{Recording, lab::ident::{identify, Scheme}};
///
/// let rec = Recording::read_csv(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ident_square_wave.csv"))?;
/// let est = identify(&rec, 1.3, 0.7, Scheme::Central)?;
/// let k12 = est.k12().unwrap(); // the lab's equal springs
/// assert!((k12.value - 950.0).abs() < 0.003 * 950.0);
/// assert_eq!((est.k1(), est.k2()), (k12, k12));
/// let sys = est.state_space()?; // the identified model, output cart 2
/// assert!((sys.b()[(3, 0)] - est.gain.value / 0.7).abs() < 1e-12);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct MassSpringEstimate {
    /// The springs, N/m: `k12` ([`SpringModel::Equal`], the lab's), or
    /// `k1` and `k2` ([`SpringModel::Separate`]).
    pub springs: Springs,
    /// Viscous friction of cart 1, N·s/m.
    pub b1: Estimate,
    /// Motor gain `K`, N per input unit (N/V on the rig).
    pub gain: Estimate,
    /// Viscous friction of cart 2, N·s/m.
    pub b2: Estimate,
    /// Coulomb friction force of cart 1 and cart 2, N, when identified
    /// ([`Options::coulomb`](super::Options::coulomb)); `None` otherwise.
    pub coulomb: Option<[Estimate; 2]>,
    /// Cart 2's effective mass, kg, when fitted
    /// ([`Options::free_m2`](super::Options::free_m2)); `None` when given.
    pub m2_estimate: Option<Estimate>,
    /// Mass of cart 1 used, kg.
    pub m1: f64,
    /// Mass of cart 2, kg: the one given, or the fitted one
    /// ([`m2_estimate`](Self::m2_estimate)).
    pub m2: f64,
    /// Mean sampling period over the segments used, s: the recording's
    /// period when it has no gap.
    pub dt: f64,
    /// The scheme used.
    pub scheme: Scheme,
    /// The recording's segments, gaps and jitter.
    pub timing: Timing,
    /// Stage 1 fit (`θ = [k12, b1]` with equal springs, `[k1, k2, b1]`
    /// with separate ones, then `F1` with Coulomb friction): fit %, R²,
    /// condition number, rows, ….
    pub first: LeastSquaresFit,
    /// Stage 2 fit (`θ = [K, b2]`, then `m2` when
    /// [free](super::Options::free_m2), then `F2` with Coulomb friction); with
    /// Newey–West its covariance includes stage 1's error in `k2` (`k12`).
    pub second: LeastSquaresFit,
}

impl MassSpringEstimate {
    /// The spring between the wall and cart 1, N/m: `k12` for equal
    /// springs ([`Springs::k1`]).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::{Recording, lab::ident::{Options, SpringModel, identify_with}};
    /// # let rec = Recording::read_csv(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ident_square_wave.csv"))?;
    /// let options = Options { springs: SpringModel::Separate, ..Options::default() };
    /// let est = identify_with(&rec, 1.3, 0.7, &options)?;
    /// assert_eq!(est.k1().value, est.first.theta[0]);
    /// assert!((est.k1().value / 950.0 - 1.0).abs() < 0.01);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn k1(&self) -> Estimate {
        self.springs.k1()
    }

    /// The spring between the carts, N/m: `k12` for equal springs
    /// ([`Springs::k2`]).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::{Recording, lab::ident::{Options, SpringModel, identify_with}};
    /// # let rec = Recording::read_csv(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ident_square_wave.csv"))?;
    /// let options = Options { springs: SpringModel::Separate, ..Options::default() };
    /// let est = identify_with(&rec, 1.3, 0.7, &options)?;
    /// assert_eq!(est.k2().value, est.first.theta[1]);
    /// assert!((est.k2().value / 950.0 - 1.0).abs() < 0.01);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn k2(&self) -> Estimate {
        self.springs.k2()
    }

    /// `k12`, N/m, when the springs were identified equal (the lab's
    /// model, the default); `None` for separate springs
    /// ([`Springs::k12`]).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::{Recording, lab::ident::{Options, Scheme, SpringModel, identify, identify_with}};
    /// # let rec = Recording::read_csv(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ident_square_wave.csv"))?;
    /// let equal = identify(&rec, 1.3, 0.7, Scheme::Central)?;
    /// assert_eq!(equal.k12().map(|k| k.value), Some(equal.first.theta[0]));
    /// let options = Options { springs: SpringModel::Separate, ..Options::default() };
    /// assert_eq!(identify_with(&rec, 1.3, 0.7, &options)?.k12(), None);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn k12(&self) -> Option<Estimate> {
        self.springs.k12()
    }

    /// Warning-level checks of the inputs (empty when all is plausible): a
    /// cart mass outside [`PLAUSIBLE_MASS_KG`] is most likely in grams or
    /// tonnes, and every estimate scales with it.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::{Recording, lab::ident::{identify, Scheme}};
    /// # let rec = Recording::read_csv(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ident_square_wave.csv"))?;
    /// assert!(identify(&rec, 1.3, 0.7, Scheme::Lab)?.warnings().is_empty());
    /// assert_eq!(identify(&rec, 1300.0, 700.0, Scheme::Lab)?.warnings().len(), 2);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn warnings(&self) -> Vec<Warning> {
        mass_warnings(self.m1, self.m2)
    }

    /// The identified plant as [`MassSpring`] parameters (equal springs:
    /// `k1 = k2 = k12`).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::{Recording, lab::ident::{Options, Scheme, SpringModel, identify, identify_with}};
    /// # let rec = Recording::read_csv(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ident_square_wave.csv"))?;
    /// let p = identify(&rec, 1.3, 0.7, Scheme::Lab)?.plant();
    /// assert_eq!(p.k1, p.k2);
    /// let options = Options { springs: SpringModel::Separate, ..Options::default() };
    /// let est = identify_with(&rec, 1.3, 0.7, &options)?;
    /// assert_eq!((est.plant().k1, est.plant().k2), (est.k1().value, est.k2().value));
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn plant(&self) -> MassSpring {
        MassSpring {
            m1: self.m1,
            m2: self.m2,
            k1: self.k1().value,
            k2: self.k2().value,
            b1: self.b1.value,
            b2: self.b2.value,
            gain: self.gain.value,
        }
    }

    /// The identified plant with its Coulomb friction, a nonlinear
    /// [`Dynamics`](crate::Dynamics) to simulate (breakaway at
    /// the Coulomb force; a negative force estimate taken as 0, none
    /// without [`Options::coulomb`](super::Options::coulomb)).
    /// [`plant`](Self::plant) is its linear part, for design.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::{Recording, lab::ident::{Options, identify_with}};
    /// # let rec = Recording::read_csv(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ident_square_wave.csv"))?;
    /// let est = identify_with(&rec, 1.3, 0.7, &Options { coulomb: true, ..Options::default() })?;
    /// let model = est.friction_plant();
    /// assert_eq!(model.truth(), est.plant());
    /// assert_eq!(model.friction()[1], est.coulomb.unwrap()[1].value.max(0.0));
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn friction_plant(&self) -> FrictionPlant {
        FrictionPlant::new(self.plant(), coulomb_forces(self.coulomb))
    }

    /// The identified continuous model (equation (3)), output the position
    /// of cart 2, input in the recording's input unit.
    ///
    /// # Errors
    ///
    /// [`Error::InvalidParameter`] when an estimate is negative (e.g. a
    /// friction estimate from a run with too little motion).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::{Recording, lab::ident::{identify, Scheme}};
    /// # let rec = Recording::read_csv(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ident_square_wave.csv"))?;
    /// let est = identify(&rec, 1.3, 0.7, Scheme::Central)?;
    /// let a = *est.state_space()?.a();
    /// assert_eq!(a[(1, 0)], -2.0 * est.k12().unwrap().value / 1.3);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn state_space(&self) -> Result<StateSpace<4, 1, 1, Continuous>, Error> {
        self.plant().state_space(Cart::Two)
    }
}

/// The fitted Coulomb forces, N, each at least 0; zero when not fitted.
fn coulomb_forces(coulomb: Option<[Estimate; 2]>) -> [f64; 2] {
    coulomb.map_or([0.0; 2], |c| c.map(|f| f.value.max(0.0)))
}

/// The range of cart masses (kg) the lab's identification takes as
/// plausible; a mass outside it is most likely in the wrong unit (grams,
/// tonnes) and is reported by [`MassSpringEstimate::warnings`].
///
/// # Examples
///
/// ```
/// use ctrlab::lab::ident::PLAUSIBLE_MASS_KG;
/// let (lo, hi) = PLAUSIBLE_MASS_KG;
/// assert!(lo < 0.7 && 1.3 < hi && hi < 700.0);
/// ```
pub const PLAUSIBLE_MASS_KG: (f64, f64) = (0.01, 100.0);

/// A warning-level finding about an identification's inputs: the numbers
/// were computed, but a value is implausible for the lab and probably in
/// the wrong unit.
///
/// # Examples
///
/// ```
/// use ctrlab::{Recording, lab::ident::{identify, Scheme}};
///
/// let rec = Recording::read_csv(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ident_square_wave.csv"))?;
/// // Cart 1's mass given in grams.
/// let est = identify(&rec, 1300.0, 0.7, Scheme::Central)?;
/// let w = &est.warnings()[0];
/// assert_eq!((w.parameter, w.value), ("m1", 1300.0));
/// assert!(w.to_string().contains("grams"));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct Warning {
    /// The parameter (`"m1"`, `"m2"`).
    pub parameter: &'static str,
    /// Its value, in the unit the API documents (kg for masses).
    pub value: f64,
    /// What is implausible and the likely mix-up.
    pub reason: &'static str,
}

impl std::fmt::Display for Warning {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "`{}` = {}: {}", self.parameter, self.value, self.reason)
    }
}

/// Warnings for cart masses outside [`PLAUSIBLE_MASS_KG`].
fn mass_warnings(m1: f64, m2: f64) -> Vec<Warning> {
    let (lo, hi) = PLAUSIBLE_MASS_KG;
    [("m1", m1), ("m2", m2)]
        .into_iter()
        .filter_map(|(parameter, value)| {
            let reason = if value > hi {
                "implausibly heavy for a lab cart: masses are in kg (was it given in grams?)"
            } else if value < lo {
                "implausibly light for a lab cart: masses are in kg (was it given in tonnes?)"
            } else {
                return None;
            };
            Some(Warning {
                parameter,
                value,
                reason,
            })
        })
        .collect()
}
