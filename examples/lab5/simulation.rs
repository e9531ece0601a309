//! Tables 1 and 2: the nominal model in simulation.

use ctrlab::lab::LabGains;
use ctrlab::sim::{Solver, simulate, time_grid};
use ctrlab::{Cart, Error, MassSpring, StepInfo, StepInfoOptions, step_info};
use nalgebra::{SVector, vector};

use crate::lab_tables::{self, fmt_kf, fmt_poles};
use crate::report::Report;

/// Table 1: static deflection under F = 10…50 N, simulated to rest.
pub fn table1(report: &mut Report) -> Result<(), Error> {
    let plant = MassSpring::nominal();
    let sys = plant.state_space(Cart::Two)?;
    // The slowest pole decays at 3.70 /s: after 10 s what is left is e^-37.
    let t = time_grid(10.0, 0.002)?;
    report.heading(2, "Table 1: open loop, nominal model (simulation)");
    report.add("Constant force F on cart 2 from rest, exact ZOH simulation for 10 s; final positions in mm beside the static deflection x1 = F/k1, x2 = F/k1 + F/k2.\n");
    let forces = [10.0, 20.0, 30.0, 40.0, 50.0];
    let mut rows = Vec::new();
    let (mut x1s, mut x2s) = (Vec::new(), Vec::new());
    for force in forces {
        let r = simulate(&sys, &t, SVector::zeros(), |_| vector![force], Solver::Zoh)?;
        let x = r.x.last().copied().unwrap_or_default();
        let (s1, s2) = plant.static_deflection(force)?;
        rows.push(vec![
            format!("{force:.0}"),
            format!("{:.4}", x[0] * 1e3),
            format!("{:.4}", s1 * 1e3),
            format!("{:.4}", x[2] * 1e3),
            format!("{:.4}", s2 * 1e3),
        ]);
        x1s.push(x[0] * 1e3);
        x2s.push(x[2] * 1e3);
    }
    report.table(
        &[
            "F (N)",
            "x1 sim (mm)",
            "x1 exact (mm)",
            "x2 sim (mm)",
            "x2 exact (mm)",
        ],
        &rows,
    );
    report.figure(
        "table1.svg",
        "Table 1: final positions against force",
        "F (N)",
        "position (mm)",
        &[
            ("x1".into(), forces.to_vec(), x1s),
            ("x2".into(), forces.to_vec(), x2s),
        ],
    )
}

/// One stable row's figures.
pub struct Measured {
    pub kf: [f64; 4],
    pub info: StepInfo,
}

/// Table 2: state feedback on the nominal model, continuous closed loop.
pub fn table2(report: &mut Report) -> Result<Vec<Measured>, Error> {
    let plant = MassSpring::nominal().state_space(Cart::Two)?;
    let setpoint_mm = 30.0;
    report.heading(
        2,
        "Table 2: state feedback on cart 2, setpoint 30 mm (simulation)",
    );
    report.add("u = Kf (G r − x_mm) on the nominal model (force input, K = 1), exact ZOH on a 0.5 ms grid; crossings interpolated.\n");
    let mut rows = Vec::new();
    let mut curves = Vec::new();
    let mut measured = Vec::new();
    for kf in lab_tables::table2() {
        let cl = LabGains::new(kf, Cart::Two)
            .state_feedback()?
            .closed_loop(&plant)?;
        let poles = cl.poles()?;
        if !cl.is_stable()? {
            rows.push(vec![
                fmt_kf(&kf),
                fmt_poles(&poles),
                "unstable".into(),
                String::new(),
                String::new(),
            ]);
            continue;
        }
        let t = time_grid(3.0, 0.0005)?;
        let r = simulate(
            &cl,
            &t,
            SVector::zeros(),
            |_| vector![setpoint_mm / 1e3],
            Solver::Zoh,
        )?;
        let y: Vec<f64> = r.y.iter().map(|y| y[0] * 1e3).collect();
        let options = StepInfoOptions {
            final_value: Some(cl.dc_gain()?[(0, 0)] * setpoint_mm),
            reference: Some(setpoint_mm),
            ..Default::default()
        };
        let info = step_info(&r.t, &y, &options)?;
        rows.push(vec![
            fmt_kf(&kf),
            fmt_poles(&poles),
            format!("{:.2}", info.overshoot),
            format!("{:.4}", info.settling_time),
            format!("{:.4}", info.steady_state_error.unwrap_or(f64::NAN)),
        ]);
        curves.push((format!("Kf = {}", fmt_kf(&kf)), r.t, y));
        measured.push(Measured { kf, info });
    }
    report.table(
        &[
            "Kf (per mm)",
            "closed-loop poles (1/s)",
            "POT (%)",
            "settling time (s)",
            "steady-state error (mm)",
        ],
        &rows,
    );
    report.figure(
        "table2.svg",
        "Table 2: cart 2 position, setpoint 30 mm (simulation)",
        "t (s)",
        "x2 (mm)",
        &curves,
    )?;
    Ok(measured)
}
