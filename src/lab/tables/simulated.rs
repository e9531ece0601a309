//! Tables 1 and 2: the nominal model in simulation.

use crate::nalgebra::{Complex, SVector, vector};

use super::TABLE2;
use crate::error::Error;
use crate::lab::{Cart, LabGains, MassSpring};
use crate::metrics::{StepInfo, StepInfoOptions, step_info};
use crate::sim::{Solver, simulate, time_grid};

/// Table 1's forces, N.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::{MassSpring, tables::FORCES};
/// // 10 N to 50 N in steps of 10 N.
/// assert!(FORCES.windows(2).all(|w| w[1] - w[0] == 10.0) && FORCES[0] == 10.0);
/// // The largest pushes cart 2 100 mm at rest on the nominal springs.
/// let (_, x2) = MassSpring::nominal().static_deflection(FORCES[4])?;
/// assert!((x2 - 0.100).abs() < 1e-12); // m
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub const FORCES: [f64; 5] = [10.0, 20.0, 30.0, 40.0, 50.0];
/// How long Table 1 simulates each force, s: the nominal model's slowest
/// pole decays at 3.70 /s, so what is left after 10 s is e^−37.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::tables::{TABLE1_DURATION, TABLE1_STEP};
/// assert!((-3.70 * TABLE1_DURATION).exp() < 1e-16); // the transient is gone
/// assert!((TABLE1_DURATION / TABLE1_STEP - 5000.0).abs() < 1e-9); // whole steps
/// ```
pub const TABLE1_DURATION: f64 = 10.0;
/// Table 1's time step, s.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::{protocol::PERIOD, tables::TABLE1_STEP};
/// assert_eq!(TABLE1_STEP, PERIOD); // the loop's 2 ms
/// ```
pub const TABLE1_STEP: f64 = 0.002;
/// Table 2's simulated time, s.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::{protocol::STEP_DURATION, tables::TABLE2_DURATION};
/// assert_eq!(TABLE2_DURATION, STEP_DURATION); // as long as a rig run (Tables 5, 6)
/// ```
pub const TABLE2_DURATION: f64 = 3.0;
/// Table 2's time step, s: the python-control reference's grid.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::{protocol::PERIOD, tables::{TABLE2_DURATION, TABLE2_STEP}};
/// assert!((PERIOD / TABLE2_STEP - 4.0).abs() < 1e-12); // four per loop period
/// assert!((TABLE2_DURATION / TABLE2_STEP - 6000.0).abs() < 1e-9);
/// ```
pub const TABLE2_STEP: f64 = 0.0005;

/// One row of Table 1: a constant force on cart 2 from rest, the simulated
/// final positions beside the static deflection.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::{MassSpring, tables::Table1Row};
/// let force = 20.0; // N
/// let (s1, s2) = MassSpring::nominal().static_deflection(force)?;
/// let row = Table1Row { force, x1_mm: 20.0, x1_static_mm: s1 * 1e3, x2_mm: 40.0, x2_static_mm: s2 * 1e3 };
/// // Cart 2 moves twice as far: both springs stretch, k1 = k2.
/// assert!((row.x2_static_mm - 2.0 * row.x1_static_mm).abs() < 1e-9);
/// assert!((row.x2_mm - row.x2_static_mm).abs() < 1e-9); // mm
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Table1Row {
    /// The force on cart 2, N.
    pub force: f64,
    /// Cart 1's simulated final position, mm.
    pub x1_mm: f64,
    /// Cart 1's static deflection `F / k1`, mm.
    pub x1_static_mm: f64,
    /// Cart 2's simulated final position, mm.
    pub x2_mm: f64,
    /// Cart 2's static deflection `F / k1 + F / k2`, mm.
    pub x2_static_mm: f64,
}

/// Table 1: open loop on the nominal model, one row per force of
/// [`FORCES`].
///
/// # Examples
///
/// ```
/// use ctrlab::lab::tables::{FORCES, table1};
/// let t = table1()?;
/// assert_eq!(t.rows.len(), FORCES.len());
/// // Linear: five times the force, five times the deflection.
/// assert!((t.rows[4].x2_mm - 5.0 * t.rows[0].x2_mm).abs() < 1e-6); // mm
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct Table1 {
    /// The rows, by force.
    pub rows: Vec<Table1Row>,
}

/// Table 1 on [`MassSpring::nominal`]: each force of [`FORCES`] on cart 2
/// from rest, exact ZOH simulation for [`TABLE1_DURATION`] at
/// [`TABLE1_STEP`]; five simulations of 5000 steps.
///
/// # Errors
///
/// Only as the simulation can fail (it does not on the nominal model).
///
/// # Examples
///
/// ```
/// let t = ctrlab::lab::tables::table1()?;
/// // F = 10 N: cart 1 at 10 mm, cart 2 at 20 mm.
/// assert!((t.rows[0].x1_mm - 10.0).abs() < 1e-3 && (t.rows[0].x2_mm - 20.0).abs() < 1e-3);
/// assert!(t.rows.iter().all(|r| (r.x2_mm - r.x2_static_mm).abs() < 1e-6));
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub fn table1() -> Result<Table1, Error> {
    let plant = MassSpring::nominal();
    let sys = plant.state_space(Cart::Two)?;
    let t = time_grid(TABLE1_DURATION, TABLE1_STEP)?;
    let mut rows = Vec::with_capacity(FORCES.len());
    for force in FORCES {
        let r = simulate(&sys, &t, SVector::zeros(), |_| vector![force], Solver::Zoh)?;
        let x = r.x.last().copied().unwrap_or_default();
        let (s1, s2) = plant.static_deflection(force)?;
        rows.push(Table1Row {
            force,
            x1_mm: x[0] * 1e3,
            x1_static_mm: s1 * 1e3,
            x2_mm: x[2] * 1e3,
            x2_static_mm: s2 * 1e3,
        });
    }
    Ok(Table1 { rows })
}

/// A simulated step of Table 2: its metrics and the response.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::{Cart, MassSpring, tables::{TABLE2_STEP, linear_step}};
/// let s = linear_step(&MassSpring::nominal(), [0.0, 0.0, 10.0, 0.0], Cart::Two, 30.0)?;
/// assert_eq!(s.t.len(), s.y_mm.len());
/// assert!((s.t[1] - s.t[0] - TABLE2_STEP).abs() < 1e-15); // s
/// // Kf3 = 10 alone: the final value falls short of 30 mm by the steady-state error.
/// assert!(s.info.steady_state_error.unwrap() > 0.0);
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct SimulatedStep {
    /// Step metrics of cart 2's position in mm against the setpoint (the
    /// final value the closed loop's DC gain; crossings interpolated).
    pub info: StepInfo,
    /// Time, s.
    pub t: Vec<f64>,
    /// Cart 2's position, mm.
    pub y_mm: Vec<f64>,
}

/// One row of Table 2.
///
/// # Examples
///
/// ```
/// let t = ctrlab::lab::tables::table2()?;
/// let row = &t.rows[3]; // Kf = [0 0 10 0.1]
/// assert_eq!(row.kf, [0.0, 0.0, 10.0, 0.1]);
/// // A stable closed loop: every pole in the left half plane, and a step.
/// assert!(row.poles.iter().all(|p| p.re < 0.0) && row.step.is_some());
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct Table2Row {
    /// The lab's gains, per mm.
    pub kf: [f64; 4],
    /// The continuous closed loop's poles, 1/s.
    pub poles: [Complex<f64>; 4],
    /// The step, or `None` when the closed loop is unstable (no metrics of
    /// a diverging signal).
    pub step: Option<SimulatedStep>,
}

/// Table 2: state feedback `u = Kf (G r − x_mm)` on the nominal model.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::tables::{TABLE2, table2};
/// let t = table2()?;
/// assert_eq!(t.setpoint_mm, TABLE2.setpoint_mm); // 30 mm
/// assert_eq!(t.rows.iter().map(|r| r.kf).collect::<Vec<_>>(), TABLE2.rows());
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct Table2 {
    /// The setpoint, mm.
    pub setpoint_mm: f64,
    /// The rows of [`TABLE2`], in order.
    pub rows: Vec<Table2Row>,
}

impl Table2 {
    /// The row with gains `kf`, if the table has it.
    ///
    /// # Examples
    ///
    /// ```
    /// let t = ctrlab::lab::tables::table2()?;
    /// let row = t.row([0.0, 0.0, 10.0, 0.1]).expect("a row of Table 2");
    /// // python-control: 5.03 % overshoot.
    /// assert!((row.step.as_ref().unwrap().info.overshoot - 5.03).abs() < 0.05);
    /// assert!(t.row([1.0, 0.0, 0.0, 0.0]).is_none());
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn row(&self, kf: [f64; 4]) -> Option<&Table2Row> {
        self.rows.iter().find(|r| r.kf == kf)
    }
}

/// Table 2 on [`MassSpring::nominal`] (force input, K = 1): each row of
/// [`TABLE2`] as a continuous closed loop, simulated exactly (ZOH) for
/// [`TABLE2_DURATION`] on a [`TABLE2_STEP`] grid toward the setpoint; six
/// simulations of 6000 steps at most.
///
/// # Errors
///
/// As the closed loop's analysis and the step metrics can fail (a stable
/// row that does not settle in the simulated time: [`Error::NotSettled`];
/// none does).
///
/// # Examples
///
/// ```
/// let t = ctrlab::lab::tables::table2()?;
/// assert_eq!(t.rows.len(), 6);
/// // Kf3 = 0.1 → 10 shrinks the steady-state error.
/// let sse = |i: usize| t.rows[i].step.as_ref().unwrap().info.steady_state_error.unwrap();
/// assert!(sse(2).abs() < sse(0).abs());
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub fn table2() -> Result<Table2, Error> {
    let plant = MassSpring::nominal();
    let setpoint_mm = TABLE2.setpoint_mm;
    let mut rows = Vec::new();
    for kf in TABLE2.rows() {
        let cl = LabGains::new(kf, TABLE2.cart)
            .state_feedback()?
            .closed_loop(&plant.state_space(TABLE2.cart)?)?;
        let poles = cl.poles()?;
        let step = if cl.is_stable()? {
            Some(linear_step(&plant, kf, TABLE2.cart, setpoint_mm)?)
        } else {
            None
        };
        rows.push(Table2Row { kf, poles, step });
    }
    Ok(Table2 { setpoint_mm, rows })
}

/// The linear closed loop of `model` under the lab's gains `kf` (per mm)
/// on `cart`, from rest toward `setpoint_mm` (mm): [`TABLE2_DURATION`]
/// simulated exactly (ZOH) on a [`TABLE2_STEP`] grid, with its step
/// metrics (mm; y∞ the closed loop's DC gain times the setpoint). Table 2
/// on the nominal model; on an identified one, what the rig would do
/// without a drive limit and without friction. Meaningful only for a
/// stable loop.
///
/// # Errors
///
/// A non-finite gain or setpoint, an invalid model, or step metrics that
/// fail (a loop that does not settle within the 3 s).
///
/// # Examples
///
/// ```
/// use ctrlab::lab::{Cart, MassSpring, tables::linear_step};
/// let s = linear_step(&MassSpring::nominal(), [0.0, 0.0, 10.0, 0.1], Cart::Two, 30.0)?;
/// assert!(s.info.overshoot < 10.0 && s.info.steady_state_error.unwrap() < 2.0);
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub fn linear_step(
    model: &MassSpring,
    kf: [f64; 4],
    cart: Cart,
    setpoint_mm: f64,
) -> Result<SimulatedStep, Error> {
    let cl = LabGains::new(kf, cart)
        .state_feedback()?
        .closed_loop(&model.state_space(cart)?)?;
    let t = time_grid(TABLE2_DURATION, TABLE2_STEP)?;
    let r = simulate(
        &cl,
        &t,
        SVector::zeros(),
        |_| vector![setpoint_mm / 1e3],
        Solver::Zoh,
    )?;
    let y_mm: Vec<f64> = r.y.iter().map(|y| y[0] * 1e3).collect();
    let options = StepInfoOptions {
        final_value: Some(cl.dc_gain()?[(0, 0)] * setpoint_mm),
        reference: Some(setpoint_mm),
        ..Default::default()
    };
    let info = step_info(&r.t, &y_mm, &options)?;
    Ok(SimulatedStep { info, t: r.t, y_mm })
}
