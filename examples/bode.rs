//! Bode and Nyquist figures of the lab's two-cart plant (force on cart 2 to
//! the position of cart 2), and the margins of a proportional loop around
//! it:
//!
//!     cargo run --example bode            # writes docs/bode_lab_plant.svg
//!     cargo run --example bode -- out/    # or into another directory
//!
//! Needs the `plot` feature (on by default).

use std::path::PathBuf;

use ctrlab::freq::{
    FrequencyUnit, TransferFunction, bandwidth, bode, bode_svg, logspace, nyquist, nyquist_svg,
    stability_margins,
};
use ctrlab::{Cart, MassSpring};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let dir = PathBuf::from(std::env::args().nth(1).unwrap_or_else(|| "docs".into()));
    let plant = MassSpring::nominal().state_space(Cart::Two)?;

    // 1 to 1000 rad/s (0.16 to 160 Hz), 1000 points.
    let w = logspace(0.0, 3.0, 1000)?;
    let b = bode(&plant, &w)?;
    let path = dir.join("bode_lab_plant.svg");
    bode_svg(
        &path,
        "Two-cart plant: force on cart 2 (N) to its position (m)",
        FrequencyUnit::Hertz,
        &[("G(jω)", &b)],
    )?;
    println!("wrote {}", path.display());

    // The transfer function, its margins under P control (2000 N/m), and
    // the plant's bandwidth.
    let g = TransferFunction::try_from(&plant)?;
    println!("G(s): num {:?}\n      den {:?}", g.num(), g.den());
    let kp = 2000.0;
    let scaled: Vec<f64> = g.num().iter().map(|c| kp * c).collect();
    let l = TransferFunction::continuous(&scaled, g.den())?;
    let m = stability_margins(&l)?;
    match m.phase {
        Some(p) => println!(
            "P control {kp} N/m: phase margin {:.2}° at {:.2} rad/s ({:.2} Hz)",
            p.margin,
            p.frequency,
            p.frequency / (2.0 * std::f64::consts::PI)
        ),
        None => println!("P control {kp} N/m: no gain crossover"),
    }
    match m.gain {
        Some(g) => println!(
            "gain margin {:.2} dB at {:.2} rad/s",
            g.margin_db(),
            g.frequency
        ),
        None => println!("gain margin: none (the phase never crosses −180°)"),
    }
    if let Some(d) = m.delay {
        println!("delay margin {:.2} ms", 1e3 * d.margin);
    }
    if let Some(wb) = bandwidth(&g, -3.0)? {
        println!("plant bandwidth (−3 dB): {wb:.2} rad/s");
    }

    let n = nyquist(&l, &logspace(0.0, 3.0, 2000)?)?;
    let path = dir.join("nyquist_lab_loop.svg");
    nyquist_svg(
        &path,
        "Lab plant under P control, 2000 N/m",
        &[("L(jω)", &n)],
    )?;
    println!("wrote {}", path.display());
    Ok(())
}
