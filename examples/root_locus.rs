//! Root loci and pole-zero maps as SVG figures: textbook loops, and the
//! lab's loop under the position gain Kf3 (the picture behind Table 5).
//!
//! ```text
//! cargo run --example root_locus [-- OUT_DIR]
//! ```
//!
//! Writes `OUT_DIR` (default `target/root_locus`): `third_order.svg`,
//! `lag_lead.svg`, `double.svg`, `discrete.svg`, `plant_pzmap.svg`,
//! `plant_pzmap_z.svg`, and Table 5's groups: `table5_kf3_s.svg` (the
//! continuous model) and `table5_kf3_z.svg` (sampled every 2 ms, near
//! z = 1), the same for Kf4 with Kf3 = 10.

use std::path::PathBuf;

use ctrlab::freq::{TransferFunction, pole_zero_map, pole_zero_svg, root_locus, root_locus_svg};
use ctrlab::lab::tables::{GroupLocus, TABLE5};
use ctrlab::{Cart, Discretization, MassSpring};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out = std::env::args()
        .nth(1)
        .map_or_else(|| PathBuf::from("target/root_locus"), PathBuf::from);
    std::fs::create_dir_all(&out)?;

    let l = TransferFunction::continuous(&[1.0], &[1.0, 6.0, 11.0, 6.0])?;
    let locus = root_locus(&l)?;
    root_locus_svg(
        out.join("third_order.svg"),
        "Root locus of k / ((s+1)(s+2)(s+3))",
        &locus,
        &[],
    )?;
    println!(
        "third order: {} gains, crossing at k = {:.4}",
        locus.gains.len(),
        locus.crossings[0].gain
    );

    let l = TransferFunction::continuous(&[1.0, 3.0], &[1.0, 5.0, 12.0, 8.0, 0.0])?;
    let locus = root_locus(&l)?;
    root_locus_svg(
        out.join("lag_lead.svg"),
        "Root locus of k (s+3) / (s (s+1)(s²+4s+8))",
        &locus,
        &[],
    )?;
    println!("(s+3)/(s(s+1)(s²+4s+8)): {} gains", locus.gains.len());

    let l = TransferFunction::continuous(&[1.0], &[1.0, 2.0, 0.0])?;
    let locus = root_locus(&l)?;
    root_locus_svg(
        out.join("double.svg"),
        "Root locus of k / (s (s+2))",
        &locus,
        &[("k = 5", 5.0)],
    )?;

    let l = TransferFunction::discrete(&[0.25], &[1.0, -1.5, 0.5], 0.1)?;
    let locus = root_locus(&l)?;
    root_locus_svg(
        out.join("discrete.svg"),
        "Root locus of 0.25 k / ((z−1)(z−0.5)), T = 0.1 s",
        &locus,
        &[],
    )?;
    println!("discrete: {} gains", locus.gains.len());

    let plant = MassSpring::nominal().state_space(Cart::Two)?;
    let sampled = plant.discretize(0.002, Discretization::Zoh)?;
    pole_zero_svg(
        out.join("plant_pzmap.svg"),
        "Two-cart plant, force to x2",
        &[("continuous", &pole_zero_map(&plant)?)],
    )?;
    pole_zero_svg(
        out.join("plant_pzmap_z.svg"),
        "Two-cart plant sampled at 2 ms (ZOH)",
        &[("ZOH 2 ms", &pole_zero_map(&sampled)?)],
    )?;

    // The lab: Table 5's groups on the nominal model, the rig's 2 ms.
    for (group, name) in TABLE5.groups.iter().zip(["table5_kf3", "table5_kf4"]) {
        let locus = GroupLocus::of(&MassSpring::nominal(), TABLE5.cart, group, 0.002)?;
        locus.write_svgs(
            out.join(format!("{name}_s.svg")),
            out.join(format!("{name}_z.svg")),
            "Table 5",
        )?;
        for c in &locus.sampled.crossings {
            println!(
                "{name}: the sampled loop leaves the unit circle at {} = {:.3} ({:.2} Hz)",
                group.varied,
                c.gain,
                c.frequency / std::f64::consts::TAU
            );
        }
    }
    Ok(())
}
