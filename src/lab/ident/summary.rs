//! Repeated identification runs summarised: Tables 3 and 4 (every run by
//! the lab's formulas, the central scheme and separate springs with
//! Coulomb friction, and their averages), the identified model, and each
//! parameter's uncertainty.

use super::{
    AverageError, Estimate, MassSpringAverage, MassSpringEstimate, Options, Scheme, Spread,
    SpringModel, average, identify, identify_with,
};
use crate::data::Recording;
use crate::error::Error;
use crate::lab::{Friction, FrictionPlant, MassSpring, SimulatedRig};

/// The separate-springs identification the lab's model comes from: the
/// central scheme, with each cart's Coulomb friction.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::ident::{SEPARATE_SPRINGS, identify_with};
/// # let rec = ctrlab::Recording::read_csv(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ident_square_wave.csv"))?;
/// let e = identify_with(&rec, 1.3, 0.7, &SEPARATE_SPRINGS)?;
/// assert!(e.coulomb.is_some()); // F1, F2 fitted
/// assert!((e.k1().value / 950.0 - 1.0).abs() < 0.01 && (e.k2().value / 950.0 - 1.0).abs() < 0.01);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub const SEPARATE_SPRINGS: Options = Options {
    springs: SpringModel::Separate,
    scheme: Scheme::Central,
    coulomb: true,
    ..Options::DEFAULT
};

/// A parameter of the separate-springs model with Coulomb friction.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::{MassSpring, ident::Parameter};
/// let p = MassSpring::nominal();
/// let values = Parameter::ALL.map(|q| q.of(&p, [1.0, 2.0]));
/// assert_eq!(values, [1000.0, 1000.0, 10.0, 5.0, 1.0, 1.0, 2.0]);
/// assert_eq!((Parameter::Gain.symbol(), Parameter::Gain.unit()), ("K", "N/V"));
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Parameter {
    /// k1, N/m.
    K1,
    /// k2, N/m.
    K2,
    /// b1, N·s/m.
    B1,
    /// b2, N·s/m.
    B2,
    /// K, N/V.
    Gain,
    /// Cart 1's Coulomb force F1, N.
    F1,
    /// Cart 2's Coulomb force F2, N.
    F2,
}

impl Parameter {
    /// All seven, in the order of
    /// [`Refined::parameters`](super::Refined::parameters).
    pub const ALL: [Parameter; 7] = [
        Parameter::K1,
        Parameter::K2,
        Parameter::B1,
        Parameter::B2,
        Parameter::Gain,
        Parameter::F1,
        Parameter::F2,
    ];

    /// Its symbol (`"k1"`, `"K"`, `"F2"`).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::ident::Parameter;
    /// assert_eq!(Parameter::ALL.map(Parameter::symbol), ["k1", "k2", "b1", "b2", "K", "F1", "F2"]);
    /// ```
    pub fn symbol(self) -> &'static str {
        match self {
            Parameter::K1 => "k1",
            Parameter::K2 => "k2",
            Parameter::B1 => "b1",
            Parameter::B2 => "b2",
            Parameter::Gain => "K",
            Parameter::F1 => "F1",
            Parameter::F2 => "F2",
        }
    }

    /// Its SI unit.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::ident::Parameter;
    /// assert_eq!(Parameter::K2.unit(), "N/m");
    /// assert_eq!(Parameter::B1.unit(), "N·s/m");
    /// assert_eq!(Parameter::F1.unit(), "N");
    /// ```
    pub fn unit(self) -> &'static str {
        match self {
            Parameter::K1 | Parameter::K2 => "N/m",
            Parameter::B1 | Parameter::B2 => "N·s/m",
            Parameter::Gain => "N/V",
            Parameter::F1 | Parameter::F2 => "N",
        }
    }

    /// Its value in `plant` with Coulomb forces `coulomb` (N).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::{MassSpring, ident::Parameter};
    /// let plant = MassSpring::nominal();
    /// assert_eq!(Parameter::B2.of(&plant, [0.3, 0.4]), 5.0); // N·s/m
    /// assert_eq!(Parameter::F2.of(&plant, [0.3, 0.4]), 0.4); // N
    /// ```
    pub fn of(self, plant: &MassSpring, coulomb: [f64; 2]) -> f64 {
        match self {
            Parameter::K1 => plant.k1,
            Parameter::K2 => plant.k2,
            Parameter::B1 => plant.b1,
            Parameter::B2 => plant.b2,
            Parameter::Gain => plant.gain,
            Parameter::F1 => coulomb[0],
            Parameter::F2 => coulomb[1],
        }
    }

    /// Its estimate in `e` (`None`: a Coulomb force not fitted).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::ident::{Options, Parameter, SpringModel, identify_with};
    /// # let rec = ctrlab::Recording::read_csv(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ident_square_wave.csv"))?;
    /// let no_friction = Options { springs: SpringModel::Separate, ..Options::default() };
    /// let e = identify_with(&rec, 1.3, 0.7, &no_friction)?;
    /// assert!(Parameter::F1.estimate(&e).is_none());
    /// let k1 = Parameter::K1.estimate(&e).unwrap();
    /// assert!((k1.value / 950.0 - 1.0).abs() < 0.01); // N/m
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn estimate(self, e: &MassSpringEstimate) -> Option<Estimate> {
        match self {
            Parameter::K1 => Some(e.k1()),
            Parameter::K2 => Some(e.k2()),
            Parameter::B1 => Some(e.b1),
            Parameter::B2 => Some(e.b2),
            Parameter::Gain => Some(e.gain),
            Parameter::F1 => Some(e.coulomb?[0]),
            Parameter::F2 => Some(e.coulomb?[1]),
        }
    }

    /// Its spread over the runs of `a` (`None`: a Coulomb force not
    /// fitted).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::ident::{Options, Parameter, SpringModel, average, identify_with};
    /// # let rec = ctrlab::Recording::read_csv(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ident_square_wave.csv"))?;
    /// let options = Options { springs: SpringModel::Separate, ..Options::default() };
    /// let e = identify_with(&rec, 1.3, 0.7, &options)?;
    /// let a = average(&[e.clone(), e])?;
    /// let gain = Parameter::Gain.spread(&a).unwrap();
    /// assert!((gain.mean / 8.5 - 1.0).abs() < 0.01 && gain.std_dev == 0.0); // N/V, one run twice
    /// assert!(Parameter::F2.spread(&a).is_none());
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn spread(self, a: &MassSpringAverage) -> Option<Spread> {
        match self {
            Parameter::K1 => Some(a.k1()),
            Parameter::K2 => Some(a.k2()),
            Parameter::B1 => Some(a.b1),
            Parameter::B2 => Some(a.b2),
            Parameter::Gain => Some(a.gain),
            Parameter::F1 => Some(a.coulomb?[0]),
            Parameter::F2 => Some(a.coulomb?[1]),
        }
    }
}

/// Why repeated runs could not be summarised.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::ident::{SummaryError, summarize};
/// # let rec = ctrlab::Recording::read_csv(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ident_square_wave.csv"))?;
/// assert!(matches!(summarize([&rec], 1.3, 0.7), Err(SummaryError::Average(_)))); // one run
/// let err = summarize([&rec, &rec], -1.0, 0.7).unwrap_err();
/// assert!(err.to_string().starts_with("run 1: ")); // counted from 1 in messages
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum SummaryError {
    /// One run failed to identify (`run` counts from 0).
    #[error("run {}: {source}", run + 1)]
    Run {
        /// Which run, from 0.
        run: usize,
        /// Its identification's error.
        source: Error,
    },
    /// The averages failed (fewer than two runs, runs that differ, no
    /// Coulomb forces, …).
    #[error(transparent)]
    Average(#[from] AverageError),
}

/// Repeated identification runs: every run three ways, their averages and
/// the identified model.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::ident::{Summary, summarize};
/// # let rec = ctrlab::Recording::read_csv(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ident_square_wave.csv"))?;
/// let s: Summary = summarize([&rec, &rec], 1.3, 0.7)?;
/// assert_eq!((s.lab.len(), s.central.len(), s.separate.len()), (2, 2, 2)); // per run
/// assert!((s.average.gain.mean / 8.5 - 1.0).abs() < 0.01); // N/V
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct Summary {
    /// The lab's formulas (equations (6)–(11)), one per run.
    pub lab: Vec<MassSpringEstimate>,
    /// The central scheme, one per run.
    pub central: Vec<MassSpringEstimate>,
    /// Separate springs with Coulomb friction ([`SEPARATE_SPRINGS`]), one
    /// per run.
    pub separate: Vec<MassSpringEstimate>,
    /// The lab's formulas averaged.
    pub lab_average: MassSpringAverage,
    /// The central scheme averaged.
    pub central_average: MassSpringAverage,
    /// The separate-springs estimates averaged: the identified model.
    pub average: MassSpringAverage,
    /// The averaged Coulomb forces, N (cart 1, cart 2).
    pub coulomb: [Spread; 2],
}

impl Summary {
    /// The identified model: the separate-springs averages' linear part.
    ///
    /// # Examples
    ///
    /// ```
    /// # let rec = ctrlab::Recording::read_csv(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ident_square_wave.csv"))?;
    /// # let s = ctrlab::lab::ident::summarize([&rec, &rec], 1.3, 0.7)?;
    /// let model = s.model();
    /// assert_eq!((model.m1, model.m2), (1.3, 0.7)); // kg, as given
    /// assert!((model.k2 / 950.0 - 1.0).abs() < 0.01); // N/m
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn model(&self) -> MassSpring {
        self.average.plant()
    }

    /// The identified Coulomb forces, N (cart 1, cart 2): the averages.
    ///
    /// # Examples
    ///
    /// ```
    /// # let rec = ctrlab::Recording::read_csv(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ident_square_wave.csv"))?;
    /// # let s = ctrlab::lab::ident::summarize([&rec, &rec], 1.3, 0.7)?;
    /// // The fixture's rig has no dry friction: both forces near 0 N.
    /// assert!(s.coulomb().iter().all(|f| f.abs() < 0.05));
    /// assert_eq!(s.coulomb()[0], s.coulomb[0].mean);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn coulomb(&self) -> [f64; 2] {
        self.coulomb.map(|s| s.mean)
    }

    /// Each parameter's mean and spread over the runs beside the runs' own
    /// standard errors, against `truth` when it is known (a simulated
    /// card's plant and Coulomb forces).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::{FrictionPlant, MassSpring, ident::Parameter};
    /// # let rec = ctrlab::Recording::read_csv(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ident_square_wave.csv"))?;
    /// # let s = ctrlab::lab::ident::summarize([&rec, &rec], 1.3, 0.7)?;
    /// let truth = FrictionPlant::new(MassSpring { k1: 950.0, k2: 950.0, ..MassSpring::nominal() }, [0.0; 2]);
    /// let u = s.uncertainty(Some(&truth));
    /// assert_eq!(u.len(), 7); // every parameter: the fit has Coulomb forces
    /// assert_eq!((u[0].parameter, u[0].runs, u[0].truth), (Parameter::K1, 2, Some(950.0)));
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn uncertainty(&self, truth: Option<&FrictionPlant>) -> Vec<Uncertainty> {
        let n = self.separate.len() as f64;
        Parameter::ALL
            .into_iter()
            .filter_map(|p| {
                let spread = p.spread(&self.average)?;
                let sum: f64 = self
                    .separate
                    .iter()
                    .filter_map(|e| p.estimate(e))
                    .map(|e| e.std_error.powi(2))
                    .sum();
                Some(Uncertainty {
                    parameter: p,
                    spread,
                    std_error: (sum / n).sqrt(),
                    runs: self.separate.len(),
                    truth: truth.map(|t| p.of(&t.truth(), t.friction())),
                })
            })
            .collect()
    }

    /// How uncertain the spread over the runs itself is, relative:
    /// `1 / √(2 (n − 1))` for `n` runs.
    ///
    /// # Examples
    ///
    /// ```
    /// # let rec = ctrlab::Recording::read_csv(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ident_square_wave.csv"))?;
    /// # let s = ctrlab::lab::ident::summarize([&rec, &rec], 1.3, 0.7)?;
    /// // With two runs, the spread itself is uncertain by ±71 %.
    /// assert!((s.spread_uncertainty() - 0.5f64.sqrt()).abs() < 1e-15);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn spread_uncertainty(&self) -> f64 {
        1.0 / (2.0 * (self.separate.len() as f64 - 1.0)).sqrt()
    }
}

/// One parameter's uncertainty over repeated runs.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::ident::{Parameter, Spread, Uncertainty};
/// let u = Uncertainty {
///     parameter: Parameter::Gain,
///     spread: Spread { mean: 1.112, std_dev: 0.004 },
///     std_error: 0.005,
///     runs: 4,
///     truth: Some(1.11),
/// };
/// assert!((u.ratio() - 1.25).abs() < 1e-12);
/// assert!((u.std_error_of_mean() - 0.002).abs() < 1e-12);
/// assert!((u.bias().unwrap() - 1.0).abs() < 1e-9);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Uncertainty {
    /// Which parameter.
    pub parameter: Parameter,
    /// Its mean and sample standard deviation over the runs, in its unit.
    pub spread: Spread,
    /// One run's standard error (Newey–West), the root mean square over
    /// the runs, in its unit.
    pub std_error: f64,
    /// The number of runs.
    pub runs: usize,
    /// The truth, when known, in its unit.
    pub truth: Option<f64>,
}

impl Uncertainty {
    /// Standard error over spread: near 1 when the standard errors are
    /// right.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::lab::ident::{Parameter, Spread, Uncertainty};
    /// # let u = Uncertainty { parameter: Parameter::K1, spread: Spread { mean: 955.0, std_dev: 4.0 }, std_error: 2.0, runs: 4, truth: Some(950.0) };
    /// // The runs scatter twice as much as each run's standard error says.
    /// assert_eq!(u.ratio(), 0.5);
    /// ```
    pub fn ratio(&self) -> f64 {
        self.std_error / self.spread.std_dev
    }

    /// The standard error of the mean, `sd / √n`, in the parameter's unit.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::lab::ident::{Parameter, Spread, Uncertainty};
    /// # let u = Uncertainty { parameter: Parameter::K1, spread: Spread { mean: 955.0, std_dev: 4.0 }, std_error: 2.0, runs: 4, truth: Some(950.0) };
    /// assert_eq!(u.std_error_of_mean(), 2.0); // N/m: 4 N/m over √4 runs
    /// ```
    pub fn std_error_of_mean(&self) -> f64 {
        self.spread.std_dev / (self.runs as f64).sqrt()
    }

    /// `(mean − truth) / (sd / √n)`: the mean's distance from the truth in
    /// its own standard errors (bias where it is more than a few).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::lab::ident::{Parameter, Spread, Uncertainty};
    /// # let u = Uncertainty { parameter: Parameter::K1, spread: Spread { mean: 955.0, std_dev: 4.0 }, std_error: 2.0, runs: 4, truth: Some(950.0) };
    /// // 5 N/m above the truth, 2.5 standard errors of the mean.
    /// assert_eq!(u.bias(), Some(2.5));
    /// assert_eq!(Uncertainty { truth: None, ..u }.bias(), None);
    /// ```
    pub fn bias(&self) -> Option<f64> {
        self.truth
            .map(|t| (self.spread.mean - t) / self.std_error_of_mean())
    }
}

/// Tables 3 and 4 from repeated runs: each run identified by the lab's
/// formulas, the central scheme and [`SEPARATE_SPRINGS`], with the masses
/// `m1`, `m2` (kg) known, and averaged.
///
/// # Errors
///
/// [`SummaryError::Run`] naming the first run that does not identify;
/// [`SummaryError::Average`] for fewer than two runs.
///
/// # Examples
///
/// ```
/// use ctrlab::Recording;
/// use ctrlab::lab::ident::{SummaryError, summarize};
/// let rec = Recording::read_csv(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ident_square_wave.csv"))?;
/// let s = summarize([&rec, &rec], 1.3, 0.7)?;
/// assert_eq!((s.lab.len(), s.average.runs), (2, 2));
/// assert!((s.model().k1 / 950.0 - 1.0).abs() < 0.01);
/// assert!(matches!(summarize([&rec], 1.3, 0.7), Err(SummaryError::Average(_))));
/// assert!(matches!(summarize([&rec, &rec], -1.0, 0.7), Err(SummaryError::Run { run: 0, .. })));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn summarize<'a>(
    runs: impl IntoIterator<Item = &'a Recording>,
    m1: f64,
    m2: f64,
) -> Result<Summary, SummaryError> {
    let (mut lab, mut central, mut separate) = (Vec::new(), Vec::new(), Vec::new());
    for (run, rec) in runs.into_iter().enumerate() {
        let context = |source: Error| SummaryError::Run { run, source };
        lab.push(identify(rec, m1, m2, Scheme::Lab).map_err(context)?);
        central.push(identify(rec, m1, m2, Scheme::Central).map_err(context)?);
        separate.push(identify_with(rec, m1, m2, &SEPARATE_SPRINGS).map_err(context)?);
    }
    let (lab_average, central_average) = (average(&lab)?, average(&central)?);
    let average = average(&separate)?;
    let coulomb = average
        .coulomb
        .ok_or(AverageError::Data(Error::InvalidParameter {
            name: "coulomb",
            value: f64::NAN,
            reason: "the separate-springs fit has no Coulomb forces",
        }))?;
    Ok(Summary {
        lab,
        central,
        separate,
        lab_average,
        central_average,
        average,
        coulomb,
    })
}

/// One run on a card whose springs are equal and without Coulomb friction,
/// where the lab's model is exact: the schemes' own bias, free of model
/// error.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::{MassSpring, ident::EqualSprings};
/// # let rec = ctrlab::Recording::read_csv(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ident_square_wave.csv"))?;
/// let truth = MassSpring { k1: 950.0, k2: 950.0, b1: 12.3, b2: 6.1, gain: 8.5, ..MassSpring::nominal() };
/// let e = EqualSprings::identify(&rec, truth, 1.3, 0.7)?;
/// // Where the lab's model is exact, each scheme's error is its own bias.
/// let error = |k: f64| (k / e.truth.k1 - 1.0).abs();
/// assert!(error(e.lab.k1().value) < 0.02 && error(e.central.k1().value) < 0.01);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct EqualSprings {
    /// The card's plant (k2 = k1).
    pub truth: MassSpring,
    /// The lab's formulas on the run.
    pub lab: MassSpringEstimate,
    /// The central scheme on the run.
    pub central: MassSpringEstimate,
}

impl EqualSprings {
    /// `sim` with k2 = k1, no dry friction and none of its
    /// [`Unmodelled`](crate::lab::Unmodelled) effects (the lab's model is
    /// exact on it): the card to run.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::{SimulatedRig, ident::EqualSprings};
    /// let card = EqualSprings::card(&SimulatedRig::default());
    /// assert_eq!((card.truth.k2, card.friction.coulomb), (950.0, [0.0; 2]));
    /// assert_eq!(card.unmodelled, ctrlab::lab::Unmodelled::NONE);
    /// ```
    pub fn card(sim: &SimulatedRig) -> SimulatedRig {
        SimulatedRig {
            truth: MassSpring {
                k2: sim.truth.k1,
                ..sim.truth
            },
            friction: Friction::NONE,
            unmodelled: crate::lab::Unmodelled::NONE,
            ..sim.clone()
        }
    }

    /// Both schemes on `rec`, a run of a card with plant `truth`, masses
    /// `m1`, `m2` (kg) known.
    ///
    /// # Errors
    ///
    /// As [`identify`].
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{MassSpring, Recording};
    /// use ctrlab::lab::ident::EqualSprings;
    /// let rec = Recording::read_csv(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ident_square_wave.csv"))?;
    /// let truth = MassSpring { k1: 950.0, k2: 950.0, ..MassSpring::nominal() };
    /// let e = EqualSprings::identify(&rec, truth, 1.3, 0.7)?;
    /// assert!((e.central.k1().value / 950.0 - 1.0).abs() < 0.01);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn identify(rec: &Recording, truth: MassSpring, m1: f64, m2: f64) -> Result<Self, Error> {
        Ok(Self {
            truth,
            lab: identify(rec, m1, m2, Scheme::Lab)?,
            central: identify(rec, m1, m2, Scheme::Central)?,
        })
    }
}
