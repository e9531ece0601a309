//! Simulation: solvers agree with each other and with analytic responses;
//! bad grids and inputs are errors.

// Built on the two-cart lab (its plant, simulated rig or card).
#![cfg(feature = "lab")]

mod common;

use ctrlab::signal::{Signal, SquareWave};
use ctrlab::sim::{
    Solver, simulate, simulate_discrete, simulate_discrete_feedback, step_response, time_grid,
};
use ctrlab::{Cart, Discretization, Error, MassSpring, StateSpace};
use nalgebra::{SVector, matrix, vector};

#[test]
fn rk4_and_zoh_simulations_agree() {
    let sys = MassSpring::nominal().state_space(Cart::Two).unwrap();
    let t = time_grid(2.0, 0.002).unwrap();
    // ±10 N every 0.2 s: `SquareWave` is exactly the hand-written
    // `((t / 0.2) as u64).is_multiple_of(2)` wave this test used.
    let wave = SquareWave::new(10.0, 0.2).unwrap();
    let square = |t: f64| vector![wave.value(t)];
    let zoh = simulate(&sys, &t, SVector::zeros(), square, Solver::Zoh).unwrap();
    assert_eq!(zoh.len(), 1001);
    let worst = |substeps| {
        let rk4 = simulate(&sys, &t, SVector::zeros(), square, Solver::Rk4 { substeps }).unwrap();
        zoh.x
            .iter()
            .zip(&rk4.x)
            .map(|(a, b)| (a - b).amax())
            .fold(0.0, f64::max)
    };
    let amplitude = zoh.x.iter().map(|x| x.amax()).fold(0.0, f64::max);
    // Global RK4 error ≈ t·λ·(hλ)⁴/120 relative: 2 s · 51 rad/s · (0.5 ms · 51)⁴
    // / 120 ≈ 4e-7 as an upper estimate. Halving h must cut it by ~16.
    let (e4, e8) = (worst(4), worst(8));
    assert!(
        e4 < 4e-7 * amplitude,
        "worst difference {e4:e} of {amplitude}"
    );
    assert!((12.0..20.0).contains(&(e4 / e8)), "{e4:e} → {e8:e}");
}

#[test]
fn first_order_step_response_is_analytic() {
    let tau = 0.25;
    let sys = common::lag(tau, 3.0);
    let r = step_response(&sys, 2.0, 0.01).unwrap();
    for (t, y) in r.t.iter().zip(&r.y) {
        let want = 3.0 * (1.0 - (-t / tau).exp());
        assert!((y[0] - want).abs() < 1e-13, "t = {t}");
    }
}

#[test]
fn discrete_simulation_matches_the_continuous_one_at_the_samples() {
    let sys = MassSpring::nominal().state_space(Cart::One).unwrap();
    let d = sys.discretize(0.002, Discretization::Zoh).unwrap();
    let inputs = vec![vector![5.0]; 500];
    let disc = simulate_discrete(&d, SVector::zeros(), &inputs).unwrap();
    let t = time_grid(0.998, 0.002).unwrap();
    let cont = simulate(&sys, &t, SVector::zeros(), |_| vector![5.0], Solver::Zoh).unwrap();
    assert_eq!(disc.len(), cont.len());
    for k in 0..disc.len() {
        assert!((disc.t[k] - cont.t[k]).abs() < 1e-12);
        assert!((disc.y[k] - cont.y[k]).amax() < 1e-15);
    }
}

#[test]
fn closed_loop_feedback_sees_the_current_state() {
    let d =
        StateSpace::discrete(matrix![1.0], matrix![1.0], matrix![1.0], matrix![0.0], 0.5).unwrap();
    let r = simulate_discrete_feedback(&d, vector![1.0], 5, |k, x| vector![k as f64] - x).unwrap();
    // u = k - x drives x[k+1] = k.
    assert_eq!(r.output(0).unwrap(), vec![1.0, 0.0, 1.0, 2.0, 3.0]);
    assert_eq!(r.t, vec![0.0, 0.5, 1.0, 1.5, 2.0]);
}

#[test]
fn bad_grids_and_inputs_are_errors() {
    let sys = MassSpring::nominal().state_space(Cart::Two).unwrap();
    let run = |t: &[f64]| simulate(&sys, t, SVector::zeros(), |_| vector![1.0], Solver::Zoh);
    for t in [
        &[][..],
        &[0.0, 0.1, 0.1][..],
        &[0.0, f64::NAN][..],
        &[0.2, 0.1][..],
    ] {
        assert!(
            matches!(run(t), Err(Error::InvalidParameter { name: "t", .. })),
            "{t:?}"
        );
    }
    let t = [0.0, 0.1];
    assert!(matches!(
        simulate(
            &sys,
            &t,
            SVector::zeros(),
            |_| vector![f64::NAN],
            Solver::Zoh
        ),
        Err(Error::InvalidParameter { name: "input", .. })
    ));
    assert!(matches!(
        simulate(
            &sys,
            &t,
            SVector::zeros(),
            |_| vector![1.0],
            Solver::Rk4 { substeps: 0 }
        ),
        Err(Error::InvalidParameter {
            name: "substeps",
            ..
        })
    ));
    assert!(matches!(
        simulate(
            &sys,
            &t,
            vector![f64::INFINITY, 0.0, 0.0, 0.0],
            |_| vector![1.0],
            Solver::Zoh
        ),
        Err(Error::NonFinite { matrix: "x0", .. })
    ));
    for (t_end, dt, name) in [
        (1.0, 0.0, "dt"),
        (1.0, f64::NAN, "dt"),
        (0.001, 0.002, "t_end"),
        (f64::INFINITY, 0.002, "t_end"),
        (1e9, 1e-3, "t_end"),
    ] {
        match step_response(&sys, t_end, dt) {
            Err(Error::InvalidParameter { name: got, .. }) => assert_eq!(got, name),
            other => panic!("t_end {t_end}, dt {dt}: {other:?}"),
        }
    }
}
