//! The Excitation section's runs: each input of `lab::excitation`
//! [`IDENT_RUNS`] times on the rig, identified as the separate-springs
//! model with Coulomb friction.

use ctrlab::Recording;
use ctrlab::lab::excitation::{Estimates, Failure, Input, InputResult, inputs};
use ctrlab::lab::ident::{MassSpringEstimate, SEPARATE_SPRINGS, identify_with};
use ctrlab::lab::protocol::{IDENT_DURATION, IDENT_RUNS, M1, M2, PERIOD};
use ctrlab::nalgebra::vector;
use ctrlab::signal::Signal;

use crate::backend::Backend;

/// Every input's result, and the first PRBS run's recording: a run the
/// Validation section's models have not seen.
pub struct Excitation {
    /// The inputs' peak, V: the identification's amplitude.
    pub volts: f64,
    pub inputs: Vec<InputResult>,
    pub fresh: Option<Recording>,
}

/// The name of the fresh run's recording.
pub const FRESH_RUN: &str = "runs/excite_1_1.csv";

/// Every input [`IDENT_RUNS`] times at `volts` peak (the identification's
/// amplitude; recordings `runs/excite_{i}_{seed}`), up to the first run
/// that fails.
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
            let outcome = backend.experiment(
                &format!("excite_{i}_{seed}"),
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
                        fresh = Some(out.recording);
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
