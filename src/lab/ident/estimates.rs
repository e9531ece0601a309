//! The identified parameters: [`Estimate`], [`MassSpringEstimate`],
//! [`SeparateSpringsEstimate`].

use super::{Scheme, Timing};
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

/// The parameters identified by [`identify`](super::identify) (equal springs `k1 = k2 = k12`).
///
/// # Examples
///
/// ```
/// use ctrlab::{Recording, lab::ident::{identify, Scheme}};
///
/// let rec = Recording::read_csv(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ident_square_wave.csv"))?;
/// let est = identify(&rec, 1.3, 0.7, Scheme::Central)?;
/// assert!((est.k12.value - 950.0).abs() < 0.003 * 950.0);
/// let sys = est.state_space()?; // the identified model, output cart 2
/// assert!((sys.b()[(3, 0)] - est.gain.value / 0.7).abs() < 1e-12);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct MassSpringEstimate {
    /// Spring constant `k1 = k2`, N/m.
    pub k12: Estimate,
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
    /// Stage 1 fit (`θ = [k12, b1]`, then `F1` with Coulomb friction): fit
    /// %, R², condition number, rows, ….
    pub first: LeastSquaresFit,
    /// Stage 2 fit (`θ = [K, b2]`, then `m2` when
    /// [free](super::Options::free_m2), then `F2` with Coulomb friction); with
    /// Newey–West its covariance includes stage 1's error in `k12`.
    pub second: LeastSquaresFit,
}

impl MassSpringEstimate {
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

    /// The identified plant as [`MassSpring`] parameters.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::{Recording, lab::ident::{identify, Scheme}};
    /// # let rec = Recording::read_csv(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ident_square_wave.csv"))?;
    /// let p = identify(&rec, 1.3, 0.7, Scheme::Lab)?.plant();
    /// assert_eq!(p.k1, p.k2);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn plant(&self) -> MassSpring {
        MassSpring {
            m1: self.m1,
            m2: self.m2,
            k1: self.k12.value,
            k2: self.k12.value,
            b1: self.b1.value,
            b2: self.b2.value,
            gain: self.gain.value,
        }
    }

    /// The identified plant with its Coulomb friction, a nonlinear
    /// [`Dynamics`](crate::integrate::Dynamics) to simulate (breakaway at
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
    /// assert_eq!(a[(1, 0)], -2.0 * est.k12.value / 1.3);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn state_space(&self) -> Result<StateSpace<4, 1, 1, Continuous>, Error> {
        self.plant().state_space(Cart::Two)
    }
}

/// The parameters identified by [`identify_separate_springs`](super::identify_separate_springs) (`k1 ≠ k2`).
///
/// # Examples
///
/// ```
/// use ctrlab::{Recording, lab::ident::{identify_separate_springs, Scheme}};
///
/// let rec = Recording::read_csv(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ident_square_wave.csv"))?;
/// let est = identify_separate_springs(&rec, 1.3, 0.7, Scheme::Central)?;
/// // The fixture's springs are equal: both estimates find 950 N/m.
/// assert!((est.k1.value / est.k2.value - 1.0).abs() < 0.01);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct SeparateSpringsEstimate {
    /// Spring between the wall and cart 1, N/m.
    pub k1: Estimate,
    /// Spring between the carts, N/m.
    pub k2: Estimate,
    /// Viscous friction of cart 1, N·s/m.
    pub b1: Estimate,
    /// Motor gain `K`, N per input unit.
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
    /// Stage 1 fit (`θ = [k1, k2, b1]`, then `F1` with Coulomb friction).
    pub first: LeastSquaresFit,
    /// Stage 2 fit (`θ = [K, b2]`, then `m2` when
    /// [free](super::Options::free_m2), then `F2` with Coulomb friction); with
    /// Newey–West its covariance includes stage 1's error in `k2`.
    pub second: LeastSquaresFit,
}

impl SeparateSpringsEstimate {
    /// Warning-level checks of the inputs (empty when all is plausible): a
    /// cart mass outside [`PLAUSIBLE_MASS_KG`] is most likely in grams or
    /// tonnes, and every estimate scales with it.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::{Recording, lab::ident::{identify_separate_springs, Scheme}};
    /// # let rec = Recording::read_csv(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ident_square_wave.csv"))?;
    /// assert!(identify_separate_springs(&rec, 1.3, 0.7, Scheme::Lab)?.warnings().is_empty());
    /// assert_eq!(identify_separate_springs(&rec, 1300.0, 700.0, Scheme::Lab)?.warnings().len(), 2);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn warnings(&self) -> Vec<Warning> {
        mass_warnings(self.m1, self.m2)
    }

    /// The identified plant as [`MassSpring`] parameters.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::{Recording, lab::ident::{identify_separate_springs, Scheme}};
    /// # let rec = Recording::read_csv(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ident_square_wave.csv"))?;
    /// let est = identify_separate_springs(&rec, 1.3, 0.7, Scheme::Central)?;
    /// assert_eq!(est.plant().k2, est.k2.value);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn plant(&self) -> MassSpring {
        MassSpring {
            m1: self.m1,
            m2: self.m2,
            k1: self.k1.value,
            k2: self.k2.value,
            b1: self.b1.value,
            b2: self.b2.value,
            gain: self.gain.value,
        }
    }

    /// The identified plant with its Coulomb friction, a nonlinear
    /// [`Dynamics`](crate::integrate::Dynamics) to simulate (breakaway at
    /// the Coulomb force; a negative force estimate taken as 0, none
    /// without [`Options::coulomb`](super::Options::coulomb)).
    /// [`plant`](Self::plant) is its linear part, for design.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::{Recording, lab::ident::{Options, identify_separate_springs_with}};
    /// # let rec = Recording::read_csv(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ident_square_wave.csv"))?;
    /// let est = identify_separate_springs_with(&rec, 1.3, 0.7, &Options { coulomb: true, ..Options::default() })?;
    /// let model = est.friction_plant();
    /// assert_eq!(model.truth(), est.plant());
    /// assert_eq!(model.friction()[1], est.coulomb.unwrap()[1].value.max(0.0));
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn friction_plant(&self) -> FrictionPlant {
        FrictionPlant::new(self.plant(), coulomb_forces(self.coulomb))
    }

    /// The identified continuous model, output the position of cart 2.
    ///
    /// # Errors
    ///
    /// [`Error::InvalidParameter`] when an estimate is negative.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::{Recording, lab::ident::{identify_separate_springs, Scheme}};
    /// # let rec = Recording::read_csv(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ident_square_wave.csv"))?;
    /// let est = identify_separate_springs(&rec, 1.3, 0.7, Scheme::Central)?;
    /// assert_eq!(est.state_space()?.a()[(3, 0)], est.k2.value / 0.7);
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
