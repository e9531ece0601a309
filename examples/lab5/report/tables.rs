//! Tables 1, 2, 5 and 6.

use ctrlab::lab::protocol::STEP_DURATION;
use ctrlab::lab::tables::{
    Halt, Prediction, RigOutcome, SATURATED_OSCILLATION, TABLE1_DURATION, TABLE2, Table1, Table2,
    kf_display, poles_display,
};

use super::{Report, curve, timing_text};
use crate::backend::Backend;
use crate::rig_tables::RigTable;

/// A rig table's title: `Table 5: cart 2, setpoint 30 mm (rig)`.
fn rig_title(t: &RigTable) -> String {
    format!(
        "Table {}: cart {}, setpoint {} mm (rig)",
        t.table.number,
        t.table.cart.number(),
        t.table.setpoint_mm
    )
}

impl Report {
    /// Table 1 and its figure.
    pub fn table1(&mut self, t: &Table1) -> Result<(), Box<dyn std::error::Error>> {
        self.heading(2, "Table 1: open loop, nominal model (simulation)");
        self.add(&format!("Constant force F on cart 2 from rest, exact ZOH simulation for {TABLE1_DURATION} s; final positions in mm beside the static deflection x1 = F/k1, x2 = F/k1 + F/k2.\n"));
        let rows: Vec<Vec<String>> = t
            .rows
            .iter()
            .map(|r| {
                vec![
                    format!("{:.0}", r.force),
                    format!("{:.4}", r.x1_mm),
                    format!("{:.4}", r.x1_static_mm),
                    format!("{:.4}", r.x2_mm),
                    format!("{:.4}", r.x2_static_mm),
                ]
            })
            .collect();
        self.table(
            &[
                "F (N)",
                "x1 sim (mm)",
                "x1 exact (mm)",
                "x2 sim (mm)",
                "x2 exact (mm)",
            ],
            &rows,
        );
        let forces: Vec<f64> = t.rows.iter().map(|r| r.force).collect();
        self.lines(
            "table1.svg",
            "Table 1: final positions against force",
            ("F (N)", "position (mm)"),
            &[
                (
                    "x1".into(),
                    forces.clone(),
                    t.rows.iter().map(|r| r.x1_mm).collect(),
                ),
                (
                    "x2".into(),
                    forces,
                    t.rows.iter().map(|r| r.x2_mm).collect(),
                ),
            ],
            &[],
        )
    }

    /// Table 2 and its figure.
    pub fn table2(&mut self, t: &Table2) -> Result<(), Box<dyn std::error::Error>> {
        self.heading(
            2,
            &format!(
                "Table 2: state feedback on cart {}, setpoint {} mm (simulation)",
                TABLE2.cart.number(),
                t.setpoint_mm
            ),
        );
        self.add("u = Kf (G r − x_mm) on the nominal model (force input, K = 1), exact ZOH on a 0.5 ms grid; crossings interpolated.\n");
        let mut rows = Vec::new();
        let mut curves = Vec::new();
        for r in &t.rows {
            let (kf, poles) = (
                kf_display(&r.kf).to_string(),
                poles_display(&r.poles).to_string(),
            );
            match &r.step {
                None => rows.push(vec![
                    kf,
                    poles,
                    "unstable".into(),
                    String::new(),
                    String::new(),
                ]),
                Some(step) => {
                    let info = &step.info;
                    rows.push(vec![
                        kf.clone(),
                        poles,
                        format!("{:.2}", info.overshoot),
                        format!("{:.4}", info.settling_time),
                        format!("{:.4}", info.steady_state_error.unwrap_or(f64::NAN)),
                    ]);
                    curves.push((format!("Kf = {kf}"), step.t.clone(), step.y_mm.clone()));
                }
            }
        }
        self.table(
            &[
                "Kf (per mm)",
                "closed-loop poles (1/s)",
                "POT (%)",
                "settling time (s)",
                "steady-state error (mm)",
            ],
            &rows,
        );
        self.lines(
            "table2.svg",
            &format!(
                "Table 2: cart {} position, setpoint {} mm (simulation)",
                TABLE2.cart.number(),
                t.setpoint_mm
            ),
            ("t (s)", "x2 (mm)"),
            &curves,
            &[(format!("setpoint {} mm", t.setpoint_mm), t.setpoint_mm)],
        )
    }

    /// A rig table (5 or 6), its timing and its figure.
    pub fn rig_table(
        &mut self,
        backend: &Backend,
        t: &RigTable,
    ) -> Result<(), Box<dyn std::error::Error>> {
        let title = rig_title(t);
        let full = t.volts_full_scale;
        self.heading(2, &title);
        self.add(&format!(
            "u = Kf (G r − x_mm) in volts per mm, saturated at ±{full} V, {STEP_DURATION} s per run on {}; metrics of the measured position (2 % band over the last 5 % of the run; y∞ = mean of that window, POT relative to y∞). The prediction is the identified linear model's closed loop sampled at 2 ms (ZOH, no saturation, no friction): stable when its spectral radius ρ = max |z| < 1; the continuous poles are shown for reference. Each run's recording is in `runs/`.\n",
            super::describe(backend)
        ));
        let channel = ctrlab::lab::position_channel(t.table.cart);
        let mut rows = Vec::new();
        let mut curves = Vec::new();
        for (run, rec) in &t.runs {
            let p = &run.prediction;
            let predicted = verdict(p);
            let mut row = vec![
                kf_display(&run.kf).to_string(),
                predicted,
                poles_display(&p.poles).to_string(),
                outcome(&run.outcome, full),
            ];
            match &run.outcome {
                RigOutcome::Settled(info) => row.extend([
                    format!("{:.2}", info.steady_state_value),
                    format!("{:.2}", info.peak),
                    format!("{:.2}", info.overshoot),
                    format!("{:.3}", info.settling_time),
                    format!("{:.2}", info.steady_state_error.unwrap_or(f64::NAN)),
                ]),
                _ => row.extend(std::iter::repeat_n("–".to_string(), 5)),
            }
            rows.push(row);
            let label = match &run.outcome {
                RigOutcome::Settled(_) => "settled",
                RigOutcome::TooSlow { .. } => "too slow",
                RigOutcome::Oscillating { .. } => "oscillating",
                RigOutcome::Diverged { .. } => "diverged",
            };
            curves.push(curve(
                format!("{}: {label}", kf_display(&run.kf)),
                rec,
                channel,
            )?);
        }
        self.table(
            &[
                "Kf (per mm)",
                "sampled loop, identified model",
                "continuous poles (1/s)",
                "outcome",
                "y∞ (mm)",
                "peak (mm)",
                "POT (%)",
                "settling time (s)",
                "steady-state error (mm)",
            ],
            &rows,
        );
        if let Some(timing) = &t.timing {
            self.add(&timing_text(timing));
        }
        self.runs(
            &format!("table{}.svg", t.table.number),
            &format!("{title}: position (setpoint dashed) and applied voltage"),
            (t.table.setpoint_mm, full),
            &curves,
        )
    }
}

/// The sampled loop's verdict with ρ printed to as many digits as it takes
/// to show which side of 1 it is on (up to 9): never `stable (ρ = 1.000)`.
pub(super) fn verdict(p: &Prediction) -> String {
    let word = if p.is_stable() { "stable" } else { "unstable" };
    let mut digits = 3;
    while digits < 9 {
        let shown: f64 = format!("{:.digits$}", p.radius).parse().unwrap_or(p.radius);
        if (shown < 1.0) == p.is_stable() && shown != 1.0 {
            break;
        }
        digits += 1;
    }
    format!("{word} (ρ = {:.digits$})", p.radius)
}

/// The outcome cell of a rig table.
pub(super) fn outcome(o: &RigOutcome, full_scale: f64) -> String {
    match o {
        RigOutcome::Settled(_) => "settled".into(),
        RigOutcome::TooSlow { y_end_mm } => {
            format!("too slow for the {STEP_DURATION} s run (at {y_end_mm:.2} mm at the end)")
        }
        RigOutcome::Oscillating {
            lo_mm,
            hi_mm,
            saturated,
        } if *saturated > SATURATED_OSCILLATION => format!(
            "bounded oscillation under saturation: {lo_mm:.1} … {hi_mm:.1} mm, the drive at ±{full_scale} V {:.0} % of the time",
            saturated * 100.0
        ),
        RigOutcome::Oscillating { lo_mm, hi_mm, .. } => {
            format!("sustained oscillation: {lo_mm:.1} … {hi_mm:.1} mm")
        }
        RigOutcome::Diverged { at, why } => {
            let why = match why {
                Halt::TravelLimit {
                    cart,
                    position,
                    limit,
                } => format!(
                    "cart {cart} at {:.1} mm beyond the ±{:.0} mm travel limit",
                    position * 1e3,
                    limit * 1e3
                ),
                Halt::Fault(message) => message.clone(),
                Halt::NoMetrics(e) => format!("no metrics: {e}"),
            };
            format!("diverged: halted at t = {at:.3} s, {why}")
        }
    }
}
