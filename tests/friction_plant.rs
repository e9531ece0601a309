//! `FrictionPlant` computes its coefficients once; it must integrate exactly
//! as the plant did when it rebuilt them from `MassSpring` on every call:
//! here against that implementation, kept as the reference, through the
//! same RK4 steps and mode updates, in runs where the carts stick, break
//! away and reverse.

// Built on the two-cart lab (its plant, simulated rig or card).
#![cfg(feature = "lab")]

use ctrlab::Dynamics;
use ctrlab::integrate::{Integrator, Rk4};
use ctrlab::lab::{FrictionPlant, MassSpring, SimulatedRig};
use ctrlab::signal::{Prbs, Signal, SquareWave};
use nalgebra::{SVector, vector};

/// The stick–slip plant as it was: the linear part through
/// `MassSpring::derivative` (A rebuilt on each call), friction over mass
/// per call, the same mode rules.
struct Reference {
    truth: MassSpring,
    friction: [f64; 2],
    stiction: [f64; 2],
    direction: [f64; 2],
}

impl Reference {
    fn mass(&self, cart: usize) -> f64 {
        [self.truth.m1, self.truth.m2][cart]
    }

    fn other_force(&self, x: &SVector<f64, 4>, u: &SVector<f64, 1>, cart: usize) -> f64 {
        self.truth.derivative(0.0, x, u)[2 * cart + 1] * self.mass(cart)
    }
}

impl Dynamics<4, 1> for Reference {
    fn derivative(&self, t: f64, x: &SVector<f64, 4>, u: &SVector<f64, 1>) -> SVector<f64, 4> {
        let mut dx = self.truth.derivative(t, x, u);
        for cart in 0..2 {
            if self.friction[cart] > 0.0 {
                if self.direction[cart] == 0.0 {
                    dx[2 * cart] = 0.0;
                    dx[2 * cart + 1] = 0.0;
                } else {
                    dx[2 * cart + 1] -=
                        self.friction[cart] * self.direction[cart] / self.mass(cart);
                }
            }
        }
        dx
    }

    fn update_mode(&mut self, _t: f64, x: &mut SVector<f64, 4>, u: &SVector<f64, 1>) {
        for cart in 0..2 {
            if self.friction[cart] == 0.0 {
                continue;
            }
            let breakaway = self.stiction[cart].max(self.friction[cart]);
            let v = x[2 * cart + 1];
            if self.direction[cart] != 0.0 && v * self.direction[cart] <= 0.0 {
                let force = self.other_force(x, u, cart);
                if force.abs() <= breakaway {
                    x[2 * cart + 1] = 0.0;
                    self.direction[cart] = 0.0;
                } else {
                    self.direction[cart] = force.signum();
                }
            }
            let v = x[2 * cart + 1];
            if self.direction[cart] == 0.0 && v != 0.0 {
                self.direction[cart] = v.signum();
            } else if self.direction[cart] == 0.0 {
                if self.other_force(x, u, cart).abs() > breakaway {
                    self.direction[cart] = self.other_force(x, u, cart).signum();
                }
            } else if v != 0.0 {
                self.direction[cart] = v.signum();
            }
        }
    }
}

/// What a run did: the largest relative difference of the two plants'
/// states (against the run's largest state component), and the steps on
/// which each cart of the new plant stuck (speed exactly 0).
struct Outcome {
    worst: f64,
    stuck: [usize; 2],
    moved: bool,
}

/// Both plants from `x0` under `input` (V), 2 ms RK4 steps with the mode
/// updated before each, for `steps` steps.
fn run(
    truth: MassSpring,
    friction: [f64; 2],
    stiction: [f64; 2],
    x0: SVector<f64, 4>,
    input: &dyn Signal,
    steps: usize,
) -> Outcome {
    let mut plant = FrictionPlant::new(truth, friction).with_stiction(stiction);
    let mut reference = Reference {
        truth,
        friction,
        stiction,
        direction: [0.0; 2],
    };
    let (mut x, mut y) = (x0, x0);
    let (mut diff, mut scale) = (0.0f64, 0.0f64);
    let mut stuck = [0; 2];
    let h = 0.002;
    for k in 0..steps {
        let t = k as f64 * h;
        let u = vector![input.value(t)];
        plant.update_mode(t, &mut x, &u);
        reference.update_mode(t, &mut y, &u);
        Rk4.step_mut(&plant, t, h, &mut x, &u);
        Rk4.step_mut(&reference, t, h, &mut y, &u);
        diff = diff.max((x - y).amax());
        scale = scale.max(y.amax());
        for (cart, count) in stuck.iter_mut().enumerate() {
            *count += usize::from(x[2 * cart + 1] == 0.0);
        }
    }
    Outcome {
        worst: if scale > 0.0 { diff / scale } else { diff },
        stuck,
        moved: scale > 1e-4,
    }
}

#[test]
fn the_precomputed_plant_integrates_as_the_plant_that_rebuilt_its_coefficients() {
    let rig = SimulatedRig::default();
    let truth = MassSpring {
        gain: 1.4,
        ..rig.truth
    };
    let at_rest = vector![0.0, 0.0, 0.0, 0.0];
    let square = SquareWave::new(6.0, 0.2).unwrap();
    let weak = SquareWave::new(2.0, 0.3).unwrap();
    let prbs = Prbs::new(9.0, 0.04, 7, 0x35).unwrap();
    // (friction, stiction, start, input, what sticks)
    let cases: [(_, _, _, &dyn Signal, _); 6] = [
        // The default rig's friction: the carts stick at each reversal.
        (
            rig.friction.coulomb,
            rig.friction.stiction,
            at_rest,
            &square,
            "reversals",
        ),
        // 2 V (2.8 N) against 2.4 N of breakaway: cart 2 creeps, cart 1
        // barely moves.
        ([1.0, 2.0], [1.2, 2.4], at_rest, &weak, "weak drive"),
        // Breakaway equal to the Coulomb force, a random input.
        ([1.5, 1.0], [1.5, 1.0], at_rest, &prbs, "prbs"),
        // Friction on one cart only.
        ([0.0, 2.0], [0.0, 2.4], at_rest, &square, "cart 2 only"),
        // Released from a deflection with a speed: both slide, then stick.
        (
            [2.0, 2.0],
            [2.4, 2.4],
            vector![0.01, 0.2, -0.02, 0.0],
            &weak,
            "released",
        ),
        // No friction at all: the linear plant.
        (
            [0.0, 0.0],
            [0.0, 0.0],
            vector![0.01, 0.0, 0.0, 0.0],
            &square,
            "linear",
        ),
    ];
    for (friction, stiction, x0, input, name) in cases {
        let o = run(truth, friction, stiction, x0, input, 2500);
        println!(
            "{name}: worst relative difference {:.1e}, stuck steps {:?}",
            o.worst, o.stuck
        );
        assert!(o.moved, "{name}: nothing moved");
        assert!(o.worst <= 1e-12, "{name}: {:e}", o.worst);
        if friction[1] > 0.0 {
            assert!(o.stuck[1] > 0, "{name}: cart 2 never stuck");
        }
    }
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(32))]
    /// Any plausible rig and square wave: the same trajectory to rounding.
    #[test]
    fn the_precomputed_plant_agrees_on_any_plausible_rig(
        k1 in 500.0f64..2000.0, k2 in 500.0f64..2000.0, b1 in 0.0f64..30.0, b2 in 0.0f64..30.0,
        gain in 0.5f64..3.0, f1 in 0.0f64..4.0, f2 in 0.0f64..4.0, extra in 1.0f64..1.5,
        volts in 0.5f64..12.0, half_period in 0.05f64..0.5,
    ) {
        let truth = MassSpring { k1, k2, b1, b2, gain, ..SimulatedRig::default_truth() };
        let wave = SquareWave::new(volts, half_period).unwrap();
        let o = run(truth, [f1, f2], [f1 * extra, f2 * extra], SVector::zeros(), &wave, 1000);
        proptest::prop_assert!(o.worst <= 1e-12, "{:e}", o.worst);
    }
}
