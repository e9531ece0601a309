//! Table 1 of the lab: open-loop static deflection of the two carts.
//!
//! For F = 10 … 50 N on cart 2, simulates the nominal plant from rest to
//! steady state (exact ZOH, 2 ms grid, 10 s) and prints the final positions
//! of both carts in millimetres beside the exact static deflection
//! `x1 = F/k1`, `x2 = F/k1 + F/k2`.
//!
//! ```text
//! cargo run --release --example open_loop
//! ```

use ctrlab::sim::{Solver, simulate, time_grid};
use ctrlab::{Cart, MassSpring};
use nalgebra::{SVector, vector};

fn main() -> Result<(), ctrlab::Error> {
    let plant = MassSpring::nominal();
    let sys = plant.state_space(Cart::Two)?;
    // The slowest pole decays at 3.70 /s: after 10 s what is left is e^-37.
    let t = time_grid(10.0, 0.002)?;

    println!("Table 1: open loop, nominal plant (force input), steady state after 10 s");
    println!();
    println!("| F (N) | x1 sim (mm) | x1 exact (mm) | x2 sim (mm) | x2 exact (mm) |");
    println!("|------:|------------:|--------------:|------------:|--------------:|");
    for force in [10.0, 20.0, 30.0, 40.0, 50.0] {
        let r = simulate(&sys, &t, SVector::zeros(), |_| vector![force], Solver::Zoh)?;
        let x = r.x.last().copied().unwrap_or_default();
        let (x1, x2) = plant.static_deflection(force)?;
        println!(
            "| {force:5.0} | {:11.4} | {:13.4} | {:11.4} | {:13.4} |",
            x[0] * 1e3,
            x1 * 1e3,
            x[2] * 1e3,
            x2 * 1e3
        );
    }
    Ok(())
}
