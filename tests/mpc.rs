//! The model-predictive controller (`design::mpc::Mpc`, `lab::mpc`):
//! against the LQR it must equal when no limit binds, on the simulated rig
//! through the whole driver stack (limits at every sample, the count it
//! must settle to with Coulomb friction, the fallback an infeasible request
//! forces), and bad designs refused by name.

// Built on the two-cart lab (its plant and simulated rig).
#![cfg(feature = "lab")]

use ctrlab::design::dlqr;
use ctrlab::design::mpc::{Estimation, Mpc, MpcDesign, OutputLimit, QpStatus, Row, TickStatus};
use ctrlab::hw::{Clock, LoopConfig, VirtualClock, run};
use ctrlab::lab::{Calibration, Cart, MassSpring, SimulatedRig, lqi, mpc};
use ctrlab::{Controller, Error, Recording, StateSpace};
use nalgebra::{SMatrix, SVector, matrix, vector};
use proptest::prelude::*;

/// The lab's plant, sampled at 2 ms, every state measured.
fn full_state_plant() -> StateSpace<4, 1, 4, ctrlab::Discrete> {
    let plant = MassSpring::nominal().state_space(Cart::Two).unwrap();
    plant
        .with_output(
            SMatrix::<f64, 4, 4>::identity(),
            SMatrix::<f64, 4, 1>::zeros(),
        )
        .unwrap()
        .discretize(0.002, ctrlab::Discretization::Zoh)
        .unwrap()
}

/// An estimator with measurements far more precise than the process
/// noise, and no disturbance model.
fn trusting<const Q: usize>() -> Estimation<1, Q> {
    Estimation {
        input_noise: matrix![1.0],
        disturbance_noise: matrix![0.0],
        output_disturbance_noise: 0.0,
        measurement_noise: SMatrix::<f64, Q, Q>::identity() * 1e-20,
    }
}

#[test]
fn without_binding_limits_it_is_the_lqr_of_its_weights() {
    // With the Riccati solution as terminal weight, the finite-horizon
    // optimum is the infinite-horizon one: u = u_s − K (x − x_s) whatever
    // the horizon, when no limit binds. dlqr is an independent solver.
    let model = full_state_plant();
    let q = SMatrix::<f64, 4, 4>::from_diagonal(&vector![1e4, 1.0, 1e5, 1.0]);
    let r = matrix![1e-2];
    let lqr = dlqr(&model, &q, &r).unwrap();
    for horizon in [1, 5, 30] {
        let design = MpcDesign::new(horizon, q, r);
        // Track x2 (measurement 3) to 0: the target is the origin.
        let mut mpc = Mpc::new(&model, &matrix![0.0, 0.0, 1.0, 0.0], &design, &trusting()).unwrap();
        let x = vector![0.001, -0.02, 0.002, 0.01];
        let u = mpc.update(&x, &vector![0.0]);
        // On the MPC's own estimate of the state (its filter is not under
        // test here).
        let expected = -(lqr.gain * mpc.state_estimate())[0];
        assert!(
            (u[0] - expected).abs() <= 1e-6 * expected.abs().max(1.0),
            "horizon {horizon}: MPC {} against LQR {expected}",
            u[0]
        );
        assert!(mpc.last_status().is_solved());
    }
}

/// A double integrator at 0.1 s, position measured.
fn double_integrator() -> StateSpace<2, 1, 1, ctrlab::Discrete> {
    StateSpace::discrete(
        matrix![1.0, 0.1; 0.0, 1.0],
        matrix![0.005; 0.1],
        matrix![1.0, 0.0],
        matrix![0.0],
        0.1,
    )
    .unwrap()
}

fn limited_design() -> MpcDesign<2, 1> {
    let mut design = MpcDesign::new(20, matrix![10.0, 0.0; 0.0, 1.0], matrix![0.1]);
    design.input_min = vector![-0.5];
    design.input_max = vector![0.5];
    design.rate_max = vector![0.2];
    design.output_limits.push(OutputLimit {
        output: matrix![1.0, 0.0],
        min: -1.0,
        max: 1.05,
        kind: Row::Soft {
            linear: 1e3,
            quadratic: 1e4,
        },
    });
    design
}

#[test]
fn input_and_rate_limits_hold_at_every_step_and_the_output_limit_is_respected() {
    let model = double_integrator();
    let mut mpc = Mpc::new(&model, &matrix![1.0], &limited_design(), &trusting()).unwrap();
    let (mut x, mut previous) = (vector![0.0, 0.0], 0.0);
    for k in 0..300 {
        let u = mpc.update(&(model.c() * x), &vector![1.0]);
        assert!(u[0].abs() <= 0.5, "step {k}: u = {}", u[0]);
        assert!((u[0] - previous).abs() <= 0.2 + 1e-12, "step {k}: Δu");
        mpc.applied(&u);
        previous = u[0];
        x = model.advance(&x, &u);
        assert!(x[0] <= 1.05 + 1e-6, "step {k}: x = {}", x[0]);
    }
    assert!(
        (x[0] - 1.0).abs() < 1e-6,
        "settles on the reference: {}",
        x[0]
    );
    let stats = mpc.stats();
    assert_eq!((stats.ticks, stats.fallbacks()), (300, 0), "{stats}");
    assert!(stats.iterations_max <= 200 && stats.solve_time_max > 0.0);
}

/// The rig with Coulomb friction only (breakaway at the Coulomb force),
/// the drive's steps and delay, the encoders' counts: the simulated rig
/// the "within one count" is checked on.
fn coulomb_rig() -> SimulatedRig {
    let sim = SimulatedRig::default();
    lqi::predicted_rig(sim.truth, sim.friction.coulomb, &sim.calibration, 0.002)
}

/// What identification gets wrong: the motor gain 3 % low, k2 2 % high.
fn identified(truth: &MassSpring) -> MassSpring {
    MassSpring {
        gain: truth.gain * 0.97,
        k2: truth.k2 * 1.02,
        ..*truth
    }
}

/// Runs `controller` through `hw::run` on `sim` (its card, driver and
/// checks) to `setpoint` for `duration` s.
fn on_the_rig<C: Controller<4, 1, 1>>(
    sim: &SimulatedRig,
    controller: C,
    reference: impl FnMut(f64) -> SVector<f64, 1>,
    duration: f64,
) -> Recording {
    let clock = Clock::Virtual(VirtualClock::new());
    let rig = sim.rig(&clock).unwrap();
    let config = LoopConfig {
        duration,
        ..LoopConfig::default()
    };
    match run(rig, controller, reference, &clock, &config) {
        Ok(outcome) => outcome.recording,
        Err(e) => panic!("the rig halted: {}", e.error),
    }
}

#[test]
fn on_the_simulated_rig_every_sample_keeps_the_limits_and_each_cart_settles_within_a_count() {
    let sim = coulomb_rig();
    let cal = sim.calibration;
    let model = lqi::position_model(&identified(&sim.truth), sim.period).unwrap();
    let count = cal.metres_per_count;
    for (cart, setpoint) in mpc::cases(&cal) {
        let mut controller = mpc::design(&model, cart, &cal).unwrap();
        let rec = on_the_rig(&sim, &mut controller, |_| vector![setpoint], 3.0);
        let u = rec.channel("u").unwrap();
        let drive_step = cal.volts_full_scale / 1000.0;
        for (k, w) in u.windows(2).enumerate() {
            assert!(
                w[1].abs() <= cal.volts_full_scale,
                "{cart:?} sample {k}: {}",
                w[1]
            );
            // Applied drive is the command in 24 mV steps: the rate limit
            // holds to half a step.
            assert!(
                (w[1] - w[0]).abs() <= mpc::RATE_LIMIT + drive_step / 2.0 + 1e-9,
                "{cart:?} sample {k}: Δu = {}",
                w[1] - w[0]
            );
        }
        let figures = mpc::Figures::of(&rec, &cal).unwrap();
        for (i, clearance) in figures.clearance.iter().enumerate() {
            assert!(
                *clearance > 0.0,
                "{cart:?}: cart {} reached its travel limit",
                i + 1
            );
        }
        // The last 0.5 s: every reading within a count of the setpoint.
        let y = rec.channel(ctrlab::lab::position_channel(cart)).unwrap();
        let tail = &y[y.len() - 250..];
        let worst = tail.iter().fold(0.0f64, |m, v| m.max((v - setpoint).abs()));
        assert!(
            worst <= count * (1.0 + 1e-9),
            "{cart:?} to {setpoint} m: {:.2} counts off at rest",
            worst / count
        );
        let stats = controller.inner().stats();
        assert_eq!(
            stats.invalid_inputs + stats.infeasible,
            0,
            "{cart:?}: {stats}"
        );
    }
}

/// Wraps a lab MPC and, from `at` s on, asks for cart 2 to stay below
/// `limit` m (its hard output limit), as an operator might mid-run.
struct Tighten {
    inner: mpc::PositionsMpc,
    t: f64,
    at: f64,
    limit: f64,
    /// The MPC's counts when the request came.
    before: Option<ctrlab::design::mpc::MpcStats>,
}

impl Controller<4, 1, 1> for Tighten {
    fn update(&mut self, y: &SVector<f64, 4>, r: &SVector<f64, 1>) -> SVector<f64, 1> {
        if self.t >= self.at && self.before.is_none() {
            self.before = Some(*self.inner.inner().stats());
            self.inner
                .inner_mut()
                .set_output_limit(1, -0.048, self.limit)
                .unwrap();
        }
        self.t += 0.002;
        self.inner.update(y, r)
    }
    fn applied(&mut self, u: &SVector<f64, 1>) {
        self.inner.applied(u)
    }
    fn reset(&mut self) {
        self.inner.reset();
        self.t = 0.0;
    }
    fn period(&self) -> Option<f64> {
        self.inner.period()
    }
}

#[test]
fn an_infeasible_request_falls_back_within_the_limits_and_is_counted() {
    // Cart 2 held at 30 mm, then asked (hard) to stay below 20 mm at once:
    // no input moves it 10 mm in one period, so the QP's hard rows cannot
    // hold. The controller falls back (plan, then LQR), keeps the drive
    // within its limits, and counts every such tick; the rig runs on.
    let sim = coulomb_rig();
    let cal = sim.calibration;
    let model = lqi::position_model(&sim.truth, sim.period).unwrap();
    let tuning = mpc::Tuning {
        travel_penalty: Row::Hard,
        ..mpc::Tuning::LAB
    };
    let inner = mpc::design_with(&model, Cart::Two, &cal, &tuning).unwrap();
    let mut c = Tighten {
        inner,
        t: 0.0,
        at: 1.5,
        limit: 0.020,
        before: None,
    };
    let rec = on_the_rig(&sim, &mut c, |_| vector![0.030], 2.0);
    let stats = *c.inner.inner().stats();
    assert!(
        stats.infeasible > 0 && stats.fallbacks() >= stats.infeasible,
        "{stats}"
    );
    assert!(
        stats.fallback_shifted > 0 && stats.fallback_lqr > 0,
        "{stats}"
    );
    match c.inner.inner().last_status() {
        TickStatus::Fallback { reason, .. } => assert_eq!(reason, QpStatus::PrimalInfeasible),
        other => panic!("expected a fallback, got {other:?}"),
    }
    let u = rec.channel("u").unwrap();
    assert!(u.iter().all(|v| v.abs() <= cal.volts_full_scale));
    assert_eq!(rec.len(), 1000, "the rig ran the whole 2 s");
    // Before the request, every tick was solved.
    let before = c.before.expect("the request came");
    assert_eq!((before.infeasible, before.fallbacks()), (0, 0), "{before}");
}

#[test]
fn a_solver_out_of_iterations_falls_back_and_counts_it() {
    let model = double_integrator();
    let mut design = limited_design();
    design.solver.max_iterations = 1;
    design.solver.polish = false;
    design.solver.active_set_steps = 0;
    let mut mpc = Mpc::new(&model, &matrix![1.0], &design, &trusting()).unwrap();
    let mut x = vector![0.0, 0.0];
    for _ in 0..50 {
        let u = mpc.update(&(model.c() * x), &vector![1.0]);
        assert!(u[0].abs() <= 0.5);
        mpc.applied(&u);
        x = model.advance(&x, &u);
    }
    let stats = *mpc.stats();
    assert!(stats.iteration_limit > 0, "{stats}");
    assert_eq!(stats.iteration_limit + stats.solved, 50);
    assert_eq!(stats.fallbacks(), stats.iteration_limit + stats.infeasible);
    assert_eq!(stats.iterations_max, 1);
}

#[test]
fn a_non_finite_measurement_holds_the_input_and_reset_forgets_the_run() {
    let model = double_integrator();
    let mut mpc = Mpc::new(&model, &matrix![1.0], &limited_design(), &trusting()).unwrap();
    let u = mpc.update(&vector![0.0], &vector![1.0]);
    mpc.applied(&u);
    let held = mpc.update(&vector![f64::NAN], &vector![1.0]);
    assert_eq!(held, u);
    assert_eq!(mpc.last_status(), TickStatus::InvalidInput);
    assert_eq!(mpc.stats().invalid_inputs, 1);
    let inf_ref = mpc.update(&vector![0.0], &vector![f64::INFINITY]);
    assert!(inf_ref[0].is_finite());
    mpc.reset();
    assert_eq!(mpc.stats().ticks, 0);
    assert_eq!(mpc.last_status(), TickStatus::NotStarted);
    // From rest again, the first move is the first move of before.
    let again = mpc.update(&vector![0.0], &vector![1.0]);
    assert!((again[0] - u[0]).abs() <= 1e-9, "{again} against {u}");
}

#[test]
fn bad_designs_are_refused_by_name() {
    let model = double_integrator();
    let est = trusting::<1>();
    let refuse =
        |design: MpcDesign<2, 1>| Mpc::new(&model, &matrix![1.0], &design, &est).unwrap_err();
    let base = limited_design;
    let named = |e: Error, name: &str| match e {
        Error::InvalidParameter { name: n, .. } => assert_eq!(n, name),
        other => panic!("expected {name}, got {other:?}"),
    };
    named(
        refuse(MpcDesign {
            horizon: 0,
            ..base()
        }),
        "horizon",
    );
    named(
        refuse(MpcDesign {
            horizon: 100_000,
            ..base()
        }),
        "horizon",
    );
    named(
        refuse(MpcDesign {
            input_min: vector![1.0],
            ..base()
        }),
        "input_min",
    );
    named(
        refuse(MpcDesign {
            input_max: vector![f64::NAN],
            ..base()
        }),
        "input_min",
    );
    named(
        refuse(MpcDesign {
            rate_max: vector![0.0],
            ..base()
        }),
        "rate_max",
    );
    named(
        refuse(MpcDesign {
            integral_gain: -1.0,
            ..base()
        }),
        "integral_gain",
    );
    named(
        refuse(MpcDesign {
            integral_zone: 0.0,
            ..base()
        }),
        "integral_zone",
    );
    let mut flipped = base();
    flipped.output_limits[0].min = 2.0;
    named(refuse(flipped), "output_limits");
    assert!(matches!(
        refuse(MpcDesign {
            rate_weight: matrix![-1.0],
            ..base()
        }),
        Error::InvalidMatrix { matrix: "S", .. }
    ));
    assert!(
        refuse(MpcDesign {
            input_weight: matrix![0.0],
            ..base()
        })
        .to_string()
        .contains('R')
    );
    let mut bad_solver = base();
    bad_solver.solver.alpha = 2.0;
    named(refuse(bad_solver), "alpha");
    // A model with feedthrough, and a tracked output that is not finite.
    let feedthrough =
        StateSpace::discrete(*model.a(), *model.b(), *model.c(), matrix![1.0], 0.1).unwrap();
    assert!(matches!(
        Mpc::new(&feedthrough, &matrix![1.0], &base(), &est).unwrap_err(),
        Error::InvalidMatrix { matrix: "D", .. }
    ));
    assert!(matches!(
        Mpc::new(&model, &matrix![f64::NAN], &base(), &est).unwrap_err(),
        Error::NonFinite { matrix: "H", .. }
    ));
}

#[test]
fn the_lab_design_refuses_a_calibration_without_room_inside_its_travel() {
    let model = lqi::position_model(&MassSpring::nominal(), 0.002).unwrap();
    let cal = Calibration {
        travel_limits: [0.001, 0.05],
        ..Calibration::default()
    };
    assert!(matches!(
        mpc::design(&model, Cart::Two, &cal).unwrap_err(),
        Error::InvalidParameter {
            name: "travel_limits",
            ..
        }
    ));
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    /// Whatever the setpoints and where the carts start, the drive stays
    /// within ±24 V and its rate limit at every tick, and every input is
    /// finite (hard limits; the nominal model as plant).
    #[test]
    fn hard_limits_hold_for_any_request(
        setpoints in prop::collection::vec(-0.06f64..0.06, 1..4),
        x0 in prop::array::uniform4(-0.03f64..0.03),
        cart_two in any::<bool>(),
    ) {
        let cal = Calibration::default();
        let model = lqi::position_model(&MassSpring::nominal(), 0.002).unwrap();
        let cart = if cart_two { Cart::Two } else { Cart::One };
        let mut c = mpc::design(&model, cart, &cal).unwrap();
        let mut x = SVector::<f64, 4>::from_column_slice(&x0);
        let mut previous = 0.0;
        let per = 150;
        for k in 0..per * setpoints.len() {
            let y = vector![x[0], x[1], x[2], x[3]];
            let u = c.update(&y, &vector![setpoints[k / per]]);
            prop_assert!(u[0].is_finite() && u[0].abs() <= 24.0);
            prop_assert!((u[0] - previous).abs() <= mpc::RATE_LIMIT + 1e-9);
            c.applied(&u);
            previous = u[0];
            x = model.a() * x + model.b() * u;
        }
    }
}
