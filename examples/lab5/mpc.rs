//! Constrained MPC: predict, then run. On the model identified earlier in
//! the run, `lab::mpc::design` builds the MPC for each of its cases (cart 2
//! to 5 mm inside its travel limit, cart 1 to 15 mm); each is predicted
//! on the rig as the prediction knows it (`lab::lqi::predicted_rig`: the
//! identified plant with its Coulomb friction, the drive's steps and
//! delay, the encoders' counts) and then run on the rig through `hw::run`.

use ctrlab::Recording;
use ctrlab::design::mpc::MpcStats;
use ctrlab::lab::lqi::{self, Comparison, DURATION, Metrics, Spec};
use ctrlab::lab::mpc::{self, Figures};
use ctrlab::lab::protocol::PERIOD;
use ctrlab::lab::{Cart, SimulatedRig};
use ctrlab::nalgebra::vector;

use crate::backend::{Backend, RunId};
use crate::identification::Identification;

/// One run of a case: its recording, figures and the controller's counts.
pub struct Run {
    pub recording: Recording,
    pub metrics: Metrics,
    pub figures: Figures,
    pub stats: MpcStats,
    /// Longest stretch with the drive at its full scale, s.
    pub longest_at_limit: f64,
}

/// One case, predicted and on the rig.
pub struct Case {
    pub cart: Cart,
    pub setpoint: f64,
    pub predicted: Run,
    pub rig: Run,
    /// Why the rig ended the run early, if it did.
    pub halted: Option<String>,
    pub comparison: Comparison,
}

/// The section's results.
pub struct MpcSection {
    /// The rig as the prediction knows it.
    pub rig: SimulatedRig,
    pub cases: Vec<Case>,
}

/// Designs, predicts and runs each case (`runs/mpc_cart{n}_{predicted,rig}.csv`).
pub fn section(
    backend: &Backend,
    ident: &Identification,
) -> Result<MpcSection, Box<dyn std::error::Error>> {
    let calibration = backend.calibration();
    let rig = lqi::predicted_rig(ident.model(), ident.coulomb(), &calibration, PERIOD);
    let model = lqi::position_model(&ident.model(), PERIOD)?;
    let count = rig.metres_per_count();
    let mut cases = Vec::new();
    for (cart, setpoint) in mpc::cases(&calibration) {
        let n = cart.number();
        let spec = Spec::new(cart, setpoint, calibration.volts_full_scale);
        let mut controller = mpc::design(&model, cart, &calibration)?;
        let predicted = lqi::predict(&rig, &mut controller, setpoint, DURATION)?;
        backend.save(&format!("mpc_cart{n}_predicted"), &predicted)?;
        let predicted = run_of(predicted, controller.inner().stats(), &spec, &rig)?;
        // On the wall clock each tick's solve also has a time budget (the
        // prediction's counts are taken above, from the controller it ran).
        if backend.real_time() {
            controller = mpc::design_with(&model, cart, &calibration, &mpc::Tuning::REAL_TIME)?;
        }
        let outcome = backend.experiment(
            &RunId::new(format!("mpc_cart{n}_rig")),
            300 + n as u64,
            &mut controller,
            move |_| vector![setpoint],
            DURATION,
        )?;
        let (recording, halted) = match outcome {
            Ok(out) => (out.recording, None),
            Err(e) => {
                let e = *e;
                (e.recording, Some(e.error.to_string()))
            }
        };
        let measured = run_of(recording, controller.inner().stats(), &spec, &rig)?;
        let comparison = Comparison::of(
            (&predicted.recording, &predicted.metrics),
            (&measured.recording, &measured.metrics),
            &spec,
            count,
            PERIOD,
        );
        cases.push(Case {
            cart,
            setpoint,
            predicted,
            rig: measured,
            halted,
            comparison,
        });
    }
    Ok(MpcSection { rig, cases })
}

fn run_of(
    recording: Recording,
    stats: &MpcStats,
    spec: &Spec,
    rig: &SimulatedRig,
) -> Result<Run, ctrlab::Error> {
    let metrics = Metrics::of(&recording, spec, rig.metres_per_count())?;
    let figures = Figures::of(&recording, &rig.calibration)?;
    let volts = rig.calibration.volts_full_scale;
    let (mut run, mut longest) = (0usize, 0usize);
    for u in recording.channel("u")? {
        run = if u.abs() >= volts { run + 1 } else { 0 };
        longest = longest.max(run);
    }
    Ok(Run {
        recording,
        metrics,
        figures,
        stats: *stats,
        longest_at_limit: longest as f64 * rig.period,
    })
}
