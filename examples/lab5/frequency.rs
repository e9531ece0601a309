//! The Frequency response section's run: the multisine of
//! `lab::frequency` on the rig, estimated against the identified model.

use ctrlab::OpenLoop;
use ctrlab::lab::frequency::{self, DURATION, FrequencyResponse};
use ctrlab::lab::lqi::predicted_rig;
use ctrlab::lab::protocol::{IDENT_VOLTS, PERIOD};
use ctrlab::nalgebra::vector;
use ctrlab::signal::{Multisine, Signal};

use crate::backend::{Backend, RunId};
use crate::identification::Identification;

/// The multisine run and its estimates, or why the run halted.
pub struct Frequency {
    pub multisine: Multisine,
    pub response: Result<FrequencyResponse, String>,
}

/// Runs the multisine (`runs/frequency_multisine.csv`) and estimates the
/// response from u (V) to x2 (m) against the identified model with its
/// friction, simulated through the same drive.
pub fn section(
    backend: &Backend,
    ident: &Identification,
) -> Result<Frequency, Box<dyn std::error::Error>> {
    let multisine = frequency::multisine(IDENT_VOLTS)?;
    let rec = match backend.experiment(
        &RunId::new("frequency_multisine"),
        1,
        OpenLoop,
        |t| vector![multisine.value(t)],
        DURATION,
    )? {
        Ok(out) => out.recording,
        Err(e) => {
            return Ok(Frequency {
                multisine,
                response: Err(e.error.to_string()),
            });
        }
    };
    let rig = predicted_rig(
        ident.model(),
        ident.coulomb(),
        &backend.calibration(),
        PERIOD,
    );
    let truth = backend.truth();
    let response = frequency::frequency_response(&rec, &rig, truth.as_ref(), &multisine)?;
    Ok(Frequency {
        multisine,
        response: Ok(response),
    })
}
