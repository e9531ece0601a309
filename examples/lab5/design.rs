//! Design: predict, then run. On the model identified earlier in the run,
//! `lab::lqi::design_search` designs LQI with a Kalman filter on the two
//! measured positions to the spec for each of the lab's cases, predicting
//! each step with what the rig adds to the linear model (the drive's
//! full scale in 0.1 % steps, its delay, the encoders' counts, the
//! identified Coulomb friction); then each design runs on the rig, and
//! the prediction is compared with the run.

use ctrlab::Recording;
use ctrlab::lab::lqi::{
    self, CASES, Comparison, DURATION, Design, IntegratorWalk, KnownDifferences, Metrics, Spec,
};
use ctrlab::lab::protocol::PERIOD;
use ctrlab::lab::{MassSpring, SimulatedRig};
use ctrlab::nalgebra::vector;

use crate::backend::{Backend, RunId};
use crate::identification::Identification;

/// One case's design, its run on the rig, and how they compare.
pub struct Case {
    pub design: Design,
    /// The run's recording, to the halt if it halted.
    pub rig: Recording,
    /// Why the rig ended the run early, if it did.
    pub halted: Option<String>,
    pub measured: Metrics,
    pub comparison: Comparison,
    pub walk: IntegratorWalk,
}

/// The section's results.
pub struct DesignSection {
    /// The rig as the prediction knows it.
    pub rig: SimulatedRig,
    /// The identified model and Coulomb forces (N) designed on.
    pub model: MassSpring,
    pub coulomb: [f64; 2],
    pub cases: Vec<Case>,
    /// What the simulated card has that the prediction has not (simulated
    /// rig only).
    pub known: Option<KnownDifferences>,
}

/// Designs each of the lab's cases, runs it on the rig
/// (`runs/design_cart{n}_rig.csv`, the prediction beside it as
/// `runs/design_cart{n}_predicted.csv`) and compares.
pub fn section(
    backend: &Backend,
    ident: &Identification,
) -> Result<DesignSection, Box<dyn std::error::Error>> {
    let (model, coulomb) = (ident.model(), ident.coulomb());
    // What is known of the rig without identifying anything: its encoders,
    // drive and period (the card's calibration).
    let rig = lqi::predicted_rig(model, coulomb, &backend.calibration(), PERIOD);
    let count = rig.metres_per_count();
    // A cart's breakaway force: the simulated card's, else the identified
    // Coulomb force (stiction is not identified).
    let breakaway = |i: usize| {
        backend.sim().map_or(coulomb[i], |sim| {
            sim.friction.stiction[i].max(sim.friction.coulomb[i])
        })
    };
    let mut cases = Vec::new();
    for (cart, setpoint) in CASES {
        let spec = Spec::new(cart, setpoint, rig.calibration.volts_full_scale);
        let design = lqi::design_search(&rig, spec)?;
        let n = cart.number();
        backend.save(&format!("design_cart{n}_predicted"), &design.predicted)?;
        let outcome = backend.experiment(
            &RunId::new(format!("design_cart{n}_rig")),
            200 + n as u64,
            design.lqi.controller,
            move |_| vector![setpoint],
            DURATION,
        )?;
        let (rec, halted) = match outcome {
            Ok(out) => (out.recording, None),
            Err(e) => {
                let e = *e;
                (e.recording, Some(e.error.to_string()))
            }
        };
        let measured = Metrics::of(&rec, &spec, count)?;
        let comparison = Comparison::of(
            (&design.predicted, &design.metrics),
            (&rec, &measured),
            &spec,
            count,
            PERIOD,
        );
        let walk = IntegratorWalk::of(
            &design,
            (&rec, &measured),
            [breakaway(0), breakaway(1)],
            model.gain,
            count,
        );
        cases.push(Case {
            design,
            rig: rec,
            halted,
            measured,
            comparison,
            walk,
        });
    }
    let known = backend.sim().map(|sim| KnownDifferences::of(&model, sim));
    Ok(DesignSection {
        rig,
        model,
        coulomb,
        cases,
        known,
    })
}
