//! The root locus behind Table 5 (`lab::tables::GroupLocus`,
//! `gain_loop`, `sampled_gain_loop`): its poles at the table's gains are
//! the closed loops `Prediction` computes from `eig(A − B K)` directly,
//! and its unit-circle crossing is where the sampled prediction turns
//! unstable.
#![cfg(feature = "lab")]

use ctrlab::freq::root_locus_at;
use ctrlab::lab::tables::{GroupLocus, Prediction, TABLE5, gain_loop, sampled_gain_loop};
use ctrlab::{Cart, MassSpring};
use nalgebra::Complex;

fn nearest(set: &[Complex<f64>], p: Complex<f64>) -> f64 {
    set.iter()
        .map(|q| (q - p).norm())
        .fold(f64::INFINITY, f64::min)
}

#[test]
fn each_table5_row_is_a_point_of_its_groups_locus() {
    let model = MassSpring::nominal();
    for group in TABLE5.groups {
        let locus = GroupLocus::of(&model, Cart::Two, group, 0.002).unwrap();
        for row in group.rows() {
            let k = row[group.varied.index()];
            let p = Prediction::of(&model, row, Cart::Two, 0.002).unwrap();
            let at = locus.continuous.poles_at_gain(k).unwrap();
            for want in p.poles {
                // Measured: at most 3.7e-15 relative.
                assert!(nearest(&at, want) <= 1e-12 * want.norm(), "{row:?}: {want}");
            }
            let z = locus.sampled.poles_at_gain(k).unwrap();
            let radius = z.iter().map(|z| z.norm()).fold(0.0, f64::max);
            assert!(
                (radius - p.radius).abs() <= 1e-12,
                "{row:?}: {radius} vs {}",
                p.radius
            );
        }
    }
}

#[test]
fn the_sampled_kf3_loop_turns_unstable_where_the_locus_leaves_the_circle() {
    let model = MassSpring::nominal();
    let locus = GroupLocus::of(&model, Cart::Two, &TABLE5.groups[0], 0.002).unwrap();
    let c = locus.sampled.crossings[0];
    assert!(c.destabilising);
    let stable = |kf3: f64| {
        Prediction::of(&model, [0.0, 0.0, kf3, 0.0], Cart::Two, 0.002)
            .unwrap()
            .is_stable()
    };
    assert!(
        stable(c.gain * (1.0 - 1e-6)) && !stable(c.gain * (1.0 + 1e-6)),
        "{c:?}"
    );
    // Table 5's Kf3 = 5 is stable, 10 is not: the crossing lies between.
    assert!(c.gain > 5.0 && c.gain < 10.0);
    // The continuous model's locus never crosses: the instability is the
    // sampling's.
    assert!(locus.continuous.crossings.is_empty());
    // The Kf4 group (Kf3 = 10) starts unstable and is stabilised.
    let kf4 = GroupLocus::of(&model, Cart::Two, &TABLE5.groups[1], 0.002).unwrap();
    let first = kf4.sampled.crossings[0];
    assert!(!first.destabilising && first.gain < 0.02, "{first:?}");
}

#[test]
fn the_loops_are_the_closed_loops_by_the_determinant_lemma() {
    // eig(A − B (K₀ + 1000 k e₃ᵀ)) for K₀ with Kf4 = 0.1 held.
    let model = MassSpring::nominal();
    let base = [0.0, 0.0, 0.0, 0.1];
    let kf3 = ctrlab::lab::tables::Gain::Kf3;
    let l = gain_loop(&model, Cart::Two, base, kf3).unwrap();
    let ld = sampled_gain_loop(&model, Cart::Two, base, kf3, 0.002).unwrap();
    for k in [0.3, 3.0, 30.0] {
        let row = [0.0, 0.0, k, 0.1];
        let p = Prediction::of(&model, row, Cart::Two, 0.002).unwrap();
        let at = root_locus_at(&l, &[k]).unwrap().poles_at(0);
        for want in p.poles {
            assert!(nearest(&at, want) <= 1e-11 * want.norm(), "{k}: {want}");
        }
        let z = root_locus_at(&ld, &[k]).unwrap().poles_at(0);
        assert!(nearest(&z, p.dominant) <= 1e-12, "{k}");
    }
    assert!(sampled_gain_loop(&model, Cart::Two, base, kf3, f64::NAN).is_err());
}

#[cfg(feature = "plot")]
#[test]
fn the_table5_figures_mark_every_row() {
    let dir = std::env::temp_dir().join("ctrlab_lab_locus");
    std::fs::create_dir_all(&dir).unwrap();
    let locus =
        GroupLocus::of(&MassSpring::nominal(), Cart::Two, &TABLE5.groups[0], 0.002).unwrap();
    let (s, z) = (dir.join("s.svg"), dir.join("z.svg"));
    locus.write_svgs(&s, &z, "Table 5").unwrap();
    for path in [&s, &z] {
        let svg = std::fs::read_to_string(path).unwrap();
        for v in ["0.1", "0.5", "1", "5", "10"] {
            let text = format!("Kf3 = {v}");
            assert!(svg.lines().any(|l| l.trim() == text), "{path:?}: {text}");
        }
    }
    assert!(
        std::fs::read_to_string(&z)
            .unwrap()
            .contains("k = 5.12, ω = 94.1 rad/s")
    );
}
