//! RK4's order of accuracy against the exact (ZOH) solution.

// Built on the two-cart lab (its plant, simulated rig or card).
#![cfg(feature = "lab")]

use ctrlab::{Cart, Discretization, Dynamics, Euler, Integrator, MassSpring, Rk4};
use nalgebra::{SVector, vector};

/// Max-norm error of `steps` steps of `integrator` over [0, t_end] from rest
/// under a constant 10 N, against the exact solution.
fn error<I: Integrator>(integrator: I, f: &impl Dynamics<4, 1>, t_end: f64, steps: usize) -> f64 {
    let sys = MassSpring::nominal().state_space(Cart::Two).unwrap();
    let exact = sys
        .discretize(t_end, Discretization::Zoh)
        .unwrap()
        .advance(&SVector::zeros(), &vector![10.0]);
    let h = t_end / steps as f64;
    let mut x = SVector::<f64, 4>::zeros();
    for k in 0..steps {
        integrator.step_mut(f, k as f64 * h, h, &mut x, &vector![10.0]);
    }
    (x - exact).amax()
}

#[test]
fn rk4_is_fourth_order() {
    let sys = MassSpring::nominal().state_space(Cart::Two).unwrap();
    for steps in [50, 100, 200] {
        let coarse = error(Rk4, &sys, 0.5, steps);
        let fine = error(Rk4, &sys, 0.5, 2 * steps);
        let ratio = coarse / fine;
        assert!(
            (12.0..20.0).contains(&ratio),
            "{steps} steps: error {coarse:e} → {fine:e}, ratio {ratio}"
        );
    }
}

#[test]
fn euler_is_first_order() {
    let sys = MassSpring::nominal().state_space(Cart::Two).unwrap();
    let ratio = error(Euler, &sys, 0.5, 20_000) / error(Euler, &sys, 0.5, 40_000);
    assert!((1.8..2.2).contains(&ratio), "ratio {ratio}");
}

#[test]
fn the_plant_and_its_linear_model_have_the_same_dynamics() {
    // MassSpring implements Dynamics directly (for nonlinear extensions);
    // it must agree with the StateSpace it builds.
    let plant = MassSpring {
        gain: 8.5,
        ..MassSpring::nominal()
    };
    let sys = plant.state_space(Cart::One).unwrap();
    let x = vector![0.01, -0.2, 0.03, 0.4];
    let u = vector![2.0];
    let via_plant = plant.derivative(0.0, &x, &u);
    let via_model = Dynamics::derivative(&sys, 0.0, &x, &u);
    assert!((via_plant - via_model).norm() < 1e-12);
}
