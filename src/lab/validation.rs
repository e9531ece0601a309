//! The identified models on a run they have not seen, and refined by
//! output error: the lab's formulas, the separate-springs least squares
//! and its refinement (each from the first identification run) simulated
//! from the fresh run's input and compared with its positions; then every
//! run refined, the refined parameters' spread over the runs beside the
//! first run's bootstrap standard errors.
//!
//! # Examples
//!
//! Two runs of a frictionless rig (the same recording twice, here), the
//! second as the fresh one (`no_run`: 32 refinements take a while in a
//! debug build; `tests/lab_identification.rs` runs it on the simulated
//! card):
//!
//! ```no_run
//! use ctrlab::Recording;
//! use ctrlab::lab::ident::{SimulationModel, summarize};
//! use ctrlab::lab::validation::{ModelKind, validate_models};
//! let rec = Recording::read_csv(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ident_square_wave.csv"))?;
//! let summary = summarize([&rec, &rec], 1.3, 0.7)?;
//! let v = validate_models(&summary, &[&rec, &rec], &rec, None, &SimulationModel::default())?;
//! let fit = |k| v.model(k).unwrap().validation.as_ref().unwrap().fit_percent[1];
//! assert!(fit(ModelKind::Refined) >= fit(ModelKind::LeastSquares) - 1e-9);
//! assert_eq!(v.spread.unwrap().runs, 2);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use super::FrictionPlant;
use super::MassSpring;
use super::ident::{
    Bootstrap, Refined, SEPARATE_SPRINGS, SimulationModel, Spread, Summary, Validation, bootstrap,
    refine_with, validate_with,
};
use crate::data::Recording;
use crate::error::Error;

/// Which model is validated.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::validation::{ModelCheck, ModelKind, Validated};
/// # use ctrlab::lab::MassSpring;
/// # use ctrlab::lab::ident::{Refined, ResidualTest, Validation};
/// # let white = ResidualTest { max_correlation: 0.02, lag: 1, bound: 0.05 };
/// # let fit = |f: f64| Validation { fit_percent: [f; 2], rms_error: [1e-4; 2], whiteness: white, independence: white };
/// # let refined = Refined { plant: MassSpring::nominal(), coulomb: [0.4, 0.6], start: fit(95.0), refined: fit(98.0), evaluations: 20 };
/// # let check = |kind, f| ModelCheck { kind, plant: refined.plant, coulomb: refined.coulomb, validation: Ok(fit(f)) };
/// let models = vec![check(ModelKind::LabFormulas, 90.0), check(ModelKind::Refined, 98.0)];
/// let v = Validated { refined, models, bound: 0.05, spread: None };
/// assert!(v.model(ModelKind::Refined).is_some());
/// assert!(v.model(ModelKind::Truth).is_none()); // only on a simulated card
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ModelKind {
    /// The lab's formulas: equal springs, no Coulomb friction.
    LabFormulas,
    /// Separate springs with Coulomb friction, least squares.
    LeastSquares,
    /// The least squares refined by output error.
    Refined,
    /// A simulated card's truth.
    Truth,
}

/// One model simulated on the fresh run.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::{MassSpring, ident::validate, validation::{ModelCheck, ModelKind}};
/// # let rec = ctrlab::Recording::read_csv(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ident_square_wave.csv"))?;
/// # // The fixture's true plant.
/// # let truth = MassSpring { k1: 950.0, k2: 950.0, b1: 12.3, b2: 6.1, gain: 8.5, ..MassSpring::nominal() };
/// let check = ModelCheck {
///     kind: ModelKind::Truth,
///     plant: truth,
///     coulomb: [0.0; 2], // N: the fixture has no dry friction
///     validation: validate(&rec, &truth, [0.0; 2]),
/// };
/// assert!(check.validation?.fit_percent[1] > 99.0); // %
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct ModelCheck {
    /// Which model.
    pub kind: ModelKind,
    /// Its plant.
    pub plant: MassSpring,
    /// Its Coulomb forces, N (cart 1, cart 2).
    pub coulomb: [f64; 2],
    /// How it reproduces the fresh run, or why it could not be simulated.
    pub validation: Result<Validation, Error>,
}

/// Every run refined: the parameters' spread, and the first run's
/// refinement with its bootstrap standard errors.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::ident::{Bootstrap, Spread};
/// use ctrlab::lab::validation::RefinedSpread;
/// let k1 = [950.0, 960.0, 955.0]; // N/m, three runs refined
/// let mut spread = [Spread { mean: 1.0, std_dev: 0.0 }; 7];
/// spread[0] = Spread::of(&k1)?;
/// let s = RefinedSpread { runs: k1.len(), spread, first: [950.0; 7], std_errors: [4.0; 7], bootstrap: Bootstrap::default() };
/// // The spread over runs beside the first run's bootstrap standard error.
/// assert!((s.spread[0].mean - 955.0).abs() < 1e-9);
/// assert!(s.spread[0].std_dev > s.std_errors[0]);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RefinedSpread {
    /// The runs refined.
    pub runs: usize,
    /// Each parameter's mean and spread over the runs, in
    /// [`Parameter::ALL`](super::ident::Parameter::ALL)'s order and units.
    pub spread: [Spread; 7],
    /// The first run's refined parameters.
    pub first: [f64; 7],
    /// Their bootstrap standard errors.
    pub std_errors: [f64; 7],
    /// The bootstrap's settings.
    pub bootstrap: Bootstrap,
}

/// The models on a fresh run, and the refinement.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::validation::{ModelCheck, ModelKind, Validated};
/// # use ctrlab::lab::MassSpring;
/// # use ctrlab::lab::ident::{Refined, ResidualTest, Validation};
/// # let white = ResidualTest { max_correlation: 0.02, lag: 1, bound: 0.05 };
/// # let fit = |f: f64| Validation { fit_percent: [f; 2], rms_error: [1e-4; 2], whiteness: white, independence: white };
/// # let refined = Refined { plant: MassSpring::nominal(), coulomb: [0.4, 0.6], start: fit(95.0), refined: fit(98.0), evaluations: 20 };
/// # let check = |kind, f| ModelCheck { kind, plant: refined.plant, coulomb: refined.coulomb, validation: Ok(fit(f)) };
/// let fresh_samples = 2500.0;
/// let v = Validated { refined, models: vec![check(ModelKind::Refined, 98.0)], bound: 2.58 / f64::sqrt(fresh_samples), spread: None };
/// // The refinement improved the fit on its own run.
/// assert!(v.refined.refined.fit_percent[1] > v.refined.start.fit_percent[1]);
/// assert!((v.bound - 0.0516).abs() < 1e-4); // 99 % whiteness bound
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct Validated {
    /// The first run's refinement (its start and result on that run, the
    /// simulations it took).
    pub refined: Refined,
    /// The lab's formulas, the least squares, the refined model, and the
    /// truth when given (and simulated).
    pub models: Vec<ModelCheck>,
    /// The 99 % bound of a white residual's normalised correlation on the
    /// fresh run, `2.58 / √N`.
    pub bound: f64,
    /// Every run refined, when there are at least two.
    pub spread: Option<RefinedSpread>,
}

impl Validated {
    /// The model of `kind`, if it was validated.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::validation::{ModelCheck, ModelKind, Validated};
    /// # use ctrlab::lab::MassSpring;
    /// # use ctrlab::lab::ident::{Refined, ResidualTest, Validation};
    /// # let white = ResidualTest { max_correlation: 0.02, lag: 1, bound: 0.05 };
    /// # let fit = |f: f64| Validation { fit_percent: [f; 2], rms_error: [1e-4; 2], whiteness: white, independence: white };
    /// # let refined = Refined { plant: MassSpring::nominal(), coulomb: [0.4, 0.6], start: fit(95.0), refined: fit(98.0), evaluations: 20 };
    /// # let check = |kind, f| ModelCheck { kind, plant: refined.plant, coulomb: refined.coulomb, validation: Ok(fit(f)) };
    /// let v = Validated { refined, models: vec![check(ModelKind::LeastSquares, 95.0)], bound: 0.05, spread: None };
    /// let fit = v.model(ModelKind::LeastSquares).map(|m| m.validation.as_ref().unwrap().fit_percent[1]);
    /// assert_eq!(fit, Some(95.0)); // %
    /// assert!(v.model(ModelKind::Truth).is_none());
    /// ```
    pub fn model(&self, kind: ModelKind) -> Option<&ModelCheck> {
        self.models.iter().find(|m| m.kind == kind)
    }
}

/// Validates `summary`'s models from the first of `runs` (the recordings
/// it was identified from, in order) on `fresh`, simulated with `model`;
/// refines every run and bootstraps the first ([`Bootstrap::default`]).
/// `truth`: a simulated card's plant and Coulomb forces, validated too.
/// The work is one refinement per run, one bootstrap (30 refinements) and
/// four simulations of `fresh`.
///
/// # Errors
///
/// [`Error::TooFewSamples`] when `runs` and `summary` hold no run;
/// [`Error::LengthMismatch`] when they hold different numbers of runs; a
/// refinement's or the bootstrap's error. A model that cannot be simulated
/// on `fresh` is not an error: its [`ModelCheck::validation`] says why.
///
/// # Examples
///
/// ```
/// use ctrlab::Recording;
/// use ctrlab::lab::ident::{SimulationModel, summarize};
/// use ctrlab::lab::validation::validate_models;
/// let rec = Recording::read_csv(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/ident_square_wave.csv"))?;
/// let summary = summarize([&rec, &rec], 1.3, 0.7)?;
/// // One recording per run identified: a missing one is refused.
/// let err = validate_models(&summary, &[&rec], &rec, None, &SimulationModel::default()).unwrap_err();
/// assert!(matches!(err, ctrlab::Error::LengthMismatch { expected: 2, found: 1, .. }));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn validate_models(
    summary: &Summary,
    runs: &[&Recording],
    fresh: &Recording,
    truth: Option<&FrictionPlant>,
    model: &SimulationModel,
) -> Result<Validated, Error> {
    if runs.len() != summary.separate.len() {
        return Err(Error::LengthMismatch {
            what: "runs (one per identification)",
            expected: summary.separate.len(),
            found: runs.len(),
        });
    }
    let (Some(first), Some(separate), Some(lab)) =
        (runs.first(), summary.separate.first(), summary.lab.first())
    else {
        return Err(Error::TooFewSamples {
            what: "identification runs to validate",
            needed: 1,
            got: 0,
        });
    };
    let refined: Vec<Refined> = runs
        .iter()
        .zip(&summary.separate)
        .map(|(rec, e)| refine_with(rec, e, model))
        .collect::<Result<_, _>>()?;
    let first_refined = refined[0];
    let mut models = Vec::new();
    for (kind, plant, coulomb) in [
        (ModelKind::LabFormulas, lab.plant(), [0.0; 2]),
        (
            ModelKind::LeastSquares,
            separate.plant(),
            separate.friction_plant().friction(),
        ),
        (
            ModelKind::Refined,
            first_refined.plant,
            first_refined.coulomb,
        ),
    ] {
        models.push(ModelCheck {
            kind,
            plant,
            coulomb,
            validation: validate_with(fresh, &plant, coulomb, model),
        });
    }
    if let Some(t) = truth
        && let Ok(v) = validate_with(fresh, &t.truth(), t.friction(), model)
    {
        models.push(ModelCheck {
            kind: ModelKind::Truth,
            plant: t.truth(),
            coulomb: t.friction(),
            validation: Ok(v),
        });
    }
    let spread = if refined.len() < 2 {
        None
    } else {
        let values: Vec<[f64; 7]> = refined.iter().map(Refined::parameters).collect();
        let mut spread = [Spread {
            mean: 0.0,
            std_dev: 0.0,
        }; 7];
        for (i, s) in spread.iter_mut().enumerate() {
            let column: Vec<f64> = values.iter().map(|v| v[i]).collect();
            *s = Spread::of(&column)?;
        }
        let options = Bootstrap::default();
        let se = bootstrap(first, &SEPARATE_SPRINGS, &first_refined, model, &options)?;
        Some(RefinedSpread {
            runs: refined.len(),
            spread,
            first: first_refined.parameters(),
            std_errors: se.to_array(),
            bootstrap: options,
        })
    };
    Ok(Validated {
        refined: first_refined,
        models,
        bound: 2.58 / (fresh.len() as f64).sqrt(),
        spread,
    })
}
