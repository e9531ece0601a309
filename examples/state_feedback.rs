//! Tables 2, 5 and 6 of the lab in simulation: state feedback
//! `u = Kf (G r − x_mm)` on the nominal two-cart plant.
//!
//! Every row prints the lab's gains Kf (per mm), the closed-loop poles, the
//! percent overshoot (POT), the 2 % settling time and the steady-state error
//! in millimetres. A row whose closed loop is unstable prints "unstable" and
//! the offending poles instead of metrics of a diverging signal.
//!
//! Tables 5 and 6 are measured on the rig in the lab; here they use the
//! nominal plant with motor gain 1 (force input), since the rig's gain is
//! only known after identification.
//!
//! Responses are computed exactly (ZOH) on a 0.5 ms grid, the grid of the
//! python-control reference; rise and settling crossings are interpolated.
//!
//! ```text
//! cargo run --release --example state_feedback
//! cargo run --release --example state_feedback --features plot   # + SVGs
//! ```
//!
//! With the `plot` feature, one SVG per table (every stable row's response)
//! is written to `target/state_feedback/`.

use ctrlab::lab::LabGains;
use ctrlab::lab::tables::{TABLE2, TABLE5, TABLE6, kf_display, poles_display};
use ctrlab::sim::{Solver, simulate, time_grid};
use ctrlab::{Cart, Error, MassSpring, StepInfo, StepInfoOptions, step_info};
use nalgebra::{Complex, SVector, vector};

/// Grid of the responses, s.
const DT: f64 = 0.0005;

struct Table {
    name: &'static str,
    file: &'static str,
    cart: Cart,
    setpoint_mm: f64,
    rows: Vec<[f64; 4]>,
}

/// What one row of a table came to.
enum Row {
    Stable {
        poles: [Complex<f64>; 4],
        info: Box<StepInfo>,
        t: Vec<f64>,
        y_mm: Vec<f64>,
    },
    Unstable {
        poles: [Complex<f64>; 4],
    },
    /// Stable but not settled within the simulated horizon.
    NotSettled {
        poles: [Complex<f64>; 4],
        horizon: f64,
    },
}

fn tables() -> Vec<Table> {
    vec![
        Table {
            name: "Table 2: cart 2, setpoint 30 mm",
            file: "table2.svg",
            cart: Cart::Two,
            setpoint_mm: 30.0,
            rows: TABLE2.rows(),
        },
        Table {
            name: "Table 5: cart 2, setpoint 30 mm (nominal plant, gain 1)",
            file: "table5.svg",
            cart: Cart::Two,
            setpoint_mm: 30.0,
            rows: TABLE5.rows(),
        },
        Table {
            name: "Table 6: cart 1, setpoint 15 mm (nominal plant, gain 1)",
            file: "table6.svg",
            cart: Cart::One,
            setpoint_mm: 15.0,
            rows: TABLE6.rows(),
        },
    ]
}

/// Simulates one row and measures it.
fn run_row(plant: &MassSpring, table: &Table, kf: [f64; 4]) -> Result<Row, Error> {
    let sys = plant.state_space(table.cart)?;
    let cl = LabGains::new(kf, table.cart)
        .state_feedback()?
        .closed_loop(&sys)?;
    let poles = cl.poles()?;
    if !cl.is_stable()? {
        return Ok(Row::Unstable { poles });
    }
    // Long enough for the slowest mode to decay by e^-12 (its 2 % settling
    // takes about 4 time constants), at least 2 s.
    let slowest = poles.iter().map(|p| -p.re).fold(f64::INFINITY, f64::min);
    let horizon = (12.0 / slowest).clamp(2.0, 120.0);
    let t = time_grid(horizon, DT)?;
    let setpoint = table.setpoint_mm / 1000.0;
    let r = simulate(
        &cl,
        &t,
        SVector::zeros(),
        |_| vector![setpoint],
        Solver::Zoh,
    )?;
    let y_mm: Vec<f64> = r.y.iter().map(|y| y[0] * 1000.0).collect();
    let options = StepInfoOptions {
        // The final value is the closed loop's DC gain, as python-control.
        final_value: Some(cl.dc_gain()?[(0, 0)] * table.setpoint_mm),
        reference: Some(table.setpoint_mm),
        ..Default::default()
    };
    match step_info(&r.t, &y_mm, &options) {
        Ok(info) => Ok(Row::Stable {
            poles,
            info: Box::new(info),
            t: r.t,
            y_mm,
        }),
        Err(Error::NotSettled { .. }) => Ok(Row::NotSettled { poles, horizon }),
        Err(e) => Err(e),
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let plant = MassSpring::nominal();
    for table in tables() {
        println!("{}", table.name);
        println!();
        println!(
            "| Kf (per mm) | closed-loop poles (1/s) | POT (%) | settling time (s) | steady-state error (mm) |"
        );
        println!("|---|---|---:|---:|---:|");
        let mut plotted: Vec<(String, Vec<f64>, Vec<f64>)> = Vec::new();
        let mut longest_settling: f64 = 0.0;
        for kf in &table.rows {
            match run_row(&plant, &table, *kf)? {
                Row::Stable {
                    poles,
                    info,
                    t,
                    y_mm,
                } => {
                    println!(
                        "| {} | {} | {:.2} | {:.4} | {:.4} |",
                        kf_display(kf),
                        poles_display(&poles),
                        info.overshoot,
                        info.settling_time,
                        info.steady_state_error.unwrap_or(f64::NAN),
                    );
                    longest_settling = longest_settling.max(info.settling_time);
                    plotted.push((format!("Kf = {}", kf_display(kf)), t, y_mm));
                }
                Row::Unstable { poles } => {
                    let bad: Vec<Complex<f64>> =
                        poles.iter().copied().filter(|p| p.re >= 0.0).collect();
                    println!(
                        "| {} | {} | unstable: pole(s) {} in the right half-plane | | |",
                        kf_display(kf),
                        poles_display(&poles),
                        poles_display(&bad)
                    );
                }
                Row::NotSettled { poles, horizon } => {
                    println!(
                        "| {} | {} | not settled within {horizon:.0} s | | |",
                        kf_display(kf),
                        poles_display(&poles)
                    );
                }
            }
        }
        println!();
        plot(&table, &plotted, longest_settling)?;
    }
    Ok(())
}

/// Writes the table's stable responses to one SVG (feature `plot`).
#[cfg(feature = "plot")]
fn plot(
    table: &Table,
    rows: &[(String, Vec<f64>, Vec<f64>)],
    longest_settling: f64,
) -> Result<(), Box<dyn std::error::Error>> {
    use ctrlab::plot::{Series, responses_svg};
    if rows.is_empty() {
        return Ok(());
    }
    // Show the transients: up to 1.5× the slowest settling time.
    let t_show = (1.5 * longest_settling).max(0.1);
    let mut series: Vec<Series<'_>> = rows
        .iter()
        .map(|(label, t, y)| {
            let n = t.partition_point(|&t| t <= t_show);
            Series::new(label, &t[..n], &y[..n])
        })
        .collect();
    let setpoint_t = [0.0, t_show];
    let setpoint_y = [table.setpoint_mm; 2];
    series.push(Series::new("setpoint", &setpoint_t, &setpoint_y));
    let dir = std::path::Path::new("target").join("state_feedback");
    std::fs::create_dir_all(&dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    let path = dir.join(table.file);
    let unstable = table.rows.len() - rows.len();
    let title = if unstable > 0 {
        format!("{} ({unstable} unstable rows not drawn)", table.name)
    } else {
        table.name.to_string()
    };
    let y_label = match table.cart {
        Cart::One => "x1 (mm)",
        Cart::Two => "x2 (mm)",
    };
    responses_svg(&path, &title, "t (s)", y_label, &series)?;
    println!("wrote {}", path.display());
    println!();
    Ok(())
}

/// Without the `plot` feature: says how to get the figure.
#[cfg(not(feature = "plot"))]
fn plot(
    table: &Table,
    _rows: &[(String, Vec<f64>, Vec<f64>)],
    _longest_settling: f64,
) -> Result<(), Error> {
    println!(
        "(run with --features plot to write target/state_feedback/{})",
        table.file
    );
    println!();
    Ok(())
}
