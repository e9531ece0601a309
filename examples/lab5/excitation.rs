//! The Excitation section's runs: each input of `lab::excitation`
//! [`IDENT_RUNS`] times on the rig, identified as the separate-springs
//! model with Coulomb friction.

use ctrlab::Recording;
use ctrlab::lab::excitation::{Estimates, Failure, Input, InputResult, inputs};
use ctrlab::lab::ident::{MassSpringEstimate, SEPARATE_SPRINGS, identify_with};
use ctrlab::lab::protocol::{IDENT_DURATION, IDENT_RUNS, M1, M2, PERIOD};
use ctrlab::nalgebra::vector;
use ctrlab::signal::Signal;

use crate::backend::{Backend, RunId};

/// Every input's result, and the first PRBS run's name and recording: a
/// run the Validation section's models have not seen.
pub struct Excitation {
    /// The inputs' peak, V: the identification's amplitude.
    pub volts: f64,
    pub inputs: Vec<InputResult>,
    pub fresh: Option<(String, Recording)>,
}

/// An input's kind in a recording's name.
fn kind(input: &Input) -> &'static str {
    match input {
        Input::Square(_) => "square",
        Input::Prbs(_) => "prbs",
        Input::Multisine(_) => "multisine",
        Input::Chirp(_) => "chirp",
    }
}

/// Every input [`IDENT_RUNS`] times at `volts` peak (the identification's
/// amplitude; recordings named for the input, its peak and the run's seed:
/// `runs/excite_prbs_4.78V_seed1.csv`), up to the first run that fails.
/// The first PRBS run is the fresh run the Validation section uses.
pub fn section(backend: &Backend, volts: f64) -> Result<Excitation, Box<dyn std::error::Error>> {
    let truth = backend.friction_truth();
    let mut results = Vec::new();
    let mut fresh = None;
    for (i, input) in inputs(volts, IDENT_DURATION, backend.ident.half_period)?
        .into_iter()
        .enumerate()
    {
        let mut estimates: Vec<MassSpringEstimate> = Vec::new();
        let mut failure = None;
        for seed in 1..=IDENT_RUNS {
            let id = RunId::keyed(
                format!("excite_{}_{volts:.2}V_seed{seed}", kind(&input)),
                format!("excite_{i}_{seed}"),
            );
            let outcome = backend.experiment(
                &id,
                seed,
                ctrlab::OpenLoop,
                |t| vector![input.value(t)],
                IDENT_DURATION,
            )?;
            match outcome {
                Ok(out) => {
                    match identify_with(&out.recording, M1, M2, &SEPARATE_SPRINGS) {
                        Ok(e) => estimates.push(e),
                        Err(e) => failure = Some(Failure::NotIdentified(e)),
                    }
                    if matches!(input, Input::Prbs(_)) && seed == 1 {
                        fresh = Some((id.file, out.recording));
                    }
                }
                Err(e) => failure = Some(Failure::Halted(e.error.to_string())),
            }
            if failure.is_some() {
                break;
            }
        }
        let rms = input.rms(PERIOD, IDENT_DURATION);
        let outcome = match failure {
            Some(f) => Err(f),
            None => Ok(Estimates::of(&estimates, truth.as_ref())?),
        };
        results.push(InputResult {
            input,
            rms,
            outcome,
        });
    }
    Ok(Excitation {
        volts,
        inputs: results,
        fresh,
    })
}
