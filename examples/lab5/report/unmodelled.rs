//! On a simulated rig with unmodelled effects: the identification against
//! the card's truth, and what it does not recover.

use ctrlab::lab::SimulatedRig;
use ctrlab::lab::ident::{MassSpringEstimate, Options, SEPARATE_SPRINGS, Spread, identify_with};
use ctrlab::lab::protocol::{M1, M2};

use super::{Report, pct};
use crate::backend::Backend;
use crate::identification::Identification;

impl Report {
    /// "What the identification does not recover", on a simulated rig
    /// with unmodelled effects (nothing otherwise): a further section,
    /// computed from the identification runs without runs of its own.
    pub fn unmodelled(
        &mut self,
        backend: &Backend,
        ident: &Identification,
    ) -> Result<(), Box<dyn std::error::Error>> {
        match backend.sim() {
            Some(sim) if sim.unmodelled != ctrlab::lab::Unmodelled::NONE => {
                self.not_recovered(sim, ident)
            }
            _ => Ok(()),
        }
    }

    /// On a simulated rig with unmodelled effects: each parameter against
    /// the card's truth, what the model does not fit, and cart 2's mass
    /// fitted instead of given.
    fn not_recovered(
        &mut self,
        sim: &SimulatedRig,
        ident: &Identification,
    ) -> Result<(), Box<dyn std::error::Error>> {
        let u = &sim.unmodelled;
        let (t, m2) = (sim.truth, sim.effective_truth().m2);
        let s = &ident.summary;
        let a = &s.average;
        let [sf1, sf2] = s.coulomb;
        self.heading(2, "What the identification does not recover");
        self.add(&format!(
            "The simulated card has what real rigs have and the model does not (its `[unmodelled]` table): cart 2's effective mass is m2 + J/r² = {} + {:.3} = {m2:.3} kg (the motor's rotor through the pinion), while the identification is told the weighed {M2} kg; the drive gives no force below {:.2} V and {:.2} V less above it (deadband); the Coulomb and breakaway forces vary by ±{:.0} % along the rail over {:.0} mm; and each run's friction is drawn from its seed with σ = {:.0} %. Against the card's truth (the Coulomb forces' nominal values, the mean of the draws):\n",
            t.m2,
            u.rotor_mass,
            u.deadband,
            u.deadband,
            100.0 * u.friction_ripple,
            1e3 * u.ripple_period,
            100.0 * u.friction_variation,
        ));
        let rel_sd = |sp: &Spread| format!("{:.2} %", 100.0 * sp.std_dev / sp.mean.abs());
        let rows: Vec<Vec<String>> = [
            ("K (N/V)", t.gain, a.gain, 4),
            ("k1 (N/m)", t.k1, a.k1(), 1),
            ("k2 (N/m)", t.k2, a.k2(), 1),
            ("b1 (N·s/m)", t.b1, a.b1, 3),
            ("b2 (N·s/m)", t.b2, a.b2, 3),
            ("Coulomb 1 (N)", sim.friction.coulomb[0], sf1, 3),
            ("Coulomb 2 (N)", sim.friction.coulomb[1], sf2, 3),
        ]
        .into_iter()
        .map(|(name, want, got, digits)| {
            vec![
                name.to_owned(),
                format!("{want:.digits$}"),
                format!("{:.digits$}", got.mean),
                pct(got.mean, want),
                rel_sd(&got),
            ]
        })
        .collect();
        self.table(
            &[
                "parameter",
                "truth",
                "identified (mean)",
                "error",
                "sd over runs",
            ],
            &rows,
        );
        let volts = ident.volts();
        let free: Vec<MassSpringEstimate> = ident
            .recordings()
            .into_iter()
            .map(|r| {
                identify_with(
                    r,
                    M1,
                    M2,
                    &Options {
                        free_m2: true,
                        ..SEPARATE_SPRINGS
                    },
                )
            })
            .collect::<Result<_, _>>()?;
        let mean =
            |f: fn(&MassSpringEstimate) -> f64| free.iter().map(f).sum::<f64>() / free.len() as f64;
        self.add(&format!(
            "Not recovered: **the rotor's mass**, with m2 fixed at the weighed value: the missing {:.3} kg of inertia goes into K and b2. **The deadband**: a ±{volts:.2} V square wave holds |u| constant, so the deadband's K·{:.2} V·sign(u) looks like a smaller K (about {:+.1} % at this amplitude), and nothing in the model separates them. **Friction along the rail** is averaged into one Coulomb force per cart. **The per-run friction** shows as the Coulomb forces' spread over the runs, and their mean is off the nominal by the draws' own mean. Fitting cart 2's effective mass as well (`Options::free_m2`) finds m2 = {:.3} kg ({} against {m2:.3} kg) and b2 {}, but K is {} off: mostly the deadband's bias, which no mass explains.\n",
            u.rotor_mass,
            u.deadband,
            -100.0 * u.deadband / volts,
            mean(|e| e.m2),
            pct(mean(|e| e.m2), m2),
            pct(mean(|e| e.b2.value), t.b2),
            pct(mean(|e| e.gain.value), t.gain),
        ));
        Ok(())
    }
}
