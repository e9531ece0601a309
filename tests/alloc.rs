//! Proves the inner loops allocate nothing, with a counting global allocator.
//!
//! This file is its own test binary, so the allocator sees only these tests;
//! the count is per thread, so tests running in parallel do not disturb it.

// Built on the two-cart lab (its plant, simulated rig or card).
#![cfg(feature = "lab")]

mod common;

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

use ctrlab::{Cart, Discretization, Integrator, MassSpring, Rk4};
use nalgebra::{SVector, vector};

struct Counting;

thread_local! {
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
}

// SAFETY: forwards every call to the system allocator unchanged; the only
// addition is a thread-local counter, which itself never allocates.
#[allow(unsafe_code)]
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.with(|c| c.set(c.get() + 1));
        // SAFETY: same contract as the caller's.
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: same contract as the caller's.
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCATIONS.with(|c| c.set(c.get() + 1));
        // SAFETY: same contract as the caller's.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// Allocations made by `f` on this thread.
fn allocations(f: impl FnOnce()) -> usize {
    let before = ALLOCATIONS.with(Cell::get);
    f();
    ALLOCATIONS.with(Cell::get) - before
}

#[test]
fn the_counter_sees_allocations() {
    // Guards against a counter that cannot fail.
    assert!(allocations(|| drop(std::hint::black_box(vec![1u8; 16]))) >= 1);
}

#[test]
fn discrete_step_allocates_nothing() {
    let d = MassSpring::nominal()
        .state_space(Cart::Two)
        .unwrap()
        .discretize(0.002, Discretization::Zoh)
        .unwrap();
    let mut x = SVector::<f64, 4>::zeros();
    let n = allocations(|| {
        for _ in 0..1000 {
            d.advance_mut(&mut x, &vector![1.0]);
            x = d.advance(&x, &vector![-1.0]);
        }
    });
    assert_eq!(n, 0);
    assert!(x.iter().all(|v| v.is_finite()) && x.norm() > 0.0);
}

#[test]
fn rk4_step_allocates_nothing() {
    let plant = MassSpring::nominal();
    let sys = plant.state_space(Cart::Two).unwrap();
    let mut x = SVector::<f64, 4>::zeros();
    let n = allocations(|| {
        for k in 0..1000 {
            Rk4.step_mut(&sys, k as f64 * 1e-3, 1e-3, &mut x, &vector![1.0]);
            Rk4.step_mut(&plant, k as f64 * 1e-3, 1e-3, &mut x, &vector![1.0]);
        }
    });
    assert_eq!(n, 0);
    assert!(x.norm() > 0.0);
}

/// The fixed-size `dc_gain` runs the shared code on stack matrices (it
/// used to copy the model to the heap first).
#[test]
fn dc_gain_allocates_nothing() {
    let sys = MassSpring::nominal().state_space(Cart::Two).unwrap();
    let d = sys.discretize(0.002, Discretization::Zoh).unwrap();
    let mut gains = (0.0, 0.0);
    let n = allocations(|| {
        gains = (sys.dc_gain().unwrap()[(0, 0)], d.dc_gain().unwrap()[(0, 0)]);
    });
    assert_eq!(n, 0);
    // 2 mm per newton on cart 2, kept by ZOH.
    assert!((gains.0 - 0.002).abs() < 1e-12 && (gains.1 - 0.002).abs() < 1e-12);
}

#[test]
fn zoh_discretisation_allocates_nothing() {
    let sys = MassSpring::nominal().state_space(Cart::Two).unwrap();
    let mut ad00 = 0.0;
    let n = allocations(|| {
        let d = sys.discretize(0.002, Discretization::Zoh).unwrap();
        ad00 = d.a()[(0, 0)];
    });
    assert_eq!(n, 0);
    assert!(ad00 > 0.99 && ad00 < 1.0);
}

#[test]
fn rig_loop_iteration_on_the_simulated_card_allocates_nothing() {
    use ctrlab::hw::{Clock, VirtualClock};
    use ctrlab::lab::SimulatedRig;
    let clock = VirtualClock::new();
    // The realistic rig: friction, stiction, PWM delay, encoder noise.
    let mut rig = SimulatedRig::default()
        .rig(&Clock::Virtual(clock.clone()))
        .unwrap();
    // The lab's gain [0 0 10 0.1] per mm in SI, toward x2 = 10 mm.
    let k = nalgebra::SMatrix::<f64, 1, 4>::new(0.0, 0.0, 10_000.0, 100.0);
    let target = vector![0.0, 0.0, 0.010, 0.0];
    let mut x = SVector::<f64, 4>::zeros();
    let n = allocations(|| {
        for _ in 0..1000 {
            clock.advance_nanos(2_000_000);
            // Latch and kick, read both counters, control update, PWM write.
            x = rig.read_state().unwrap();
            rig.apply_voltage((k * (target - x))[0]).unwrap();
        }
    });
    assert_eq!(n, 0);
    // The loop moved cart 2 toward the x2 = 9.6 mm the proportional law
    // settles at on the default truth (see `steady_x2`).
    let expected = steady_x2(0.010);
    assert!(x[2] > 0.5 * expected, "the loop moved cart 2: {x}");
}

#[test]
fn step_info_allocates_nothing() {
    use ctrlab::{StepInfoOptions, step_info};
    let t: Vec<f64> = (0..5000).map(|k| k as f64 * 1e-3).collect();
    let y: Vec<f64> = t
        .iter()
        .map(|t| 1.0 - (-3.0 * t).exp() * (20.0 * t).cos())
        .collect();
    let estimated = StepInfoOptions::default();
    let given = StepInfoOptions {
        final_value: Some(1.0),
        reference: Some(1.0),
        ..Default::default()
    };
    let mut overshoot = 0.0;
    let n = allocations(|| {
        for options in [&estimated, &given] {
            if let Ok(info) = step_info(&t, &y, options) {
                overshoot = info.overshoot;
            }
        }
        // The error paths allocate nothing either.
        assert!(step_info(&t, &t, &estimated).is_err());
        assert!(step_info(&t, &y[1..], &estimated).is_err());
    });
    assert_eq!(n, 0);
    // Guard: the Ok path ran and measured the 2nd-order overshoot.
    assert!(overshoot > 10.0);
}

#[test]
fn state_feedback_update_allocates_nothing() {
    use ctrlab::Controller;
    use ctrlab::lab::LabGains;
    let mut ctrl = LabGains::new([0.0, 0.0, 10.0, 0.1], Cart::Two)
        .state_feedback()
        .unwrap();
    let d = MassSpring::nominal()
        .state_space(Cart::Two)
        .unwrap()
        .discretize(0.002, Discretization::Zoh)
        .unwrap();
    let mut x = SVector::<f64, 4>::zeros();
    let n = allocations(|| {
        // Through the trait object too, as a hardware loop would hold it.
        let dynamic: &mut dyn Controller<4, 1, 1> = &mut ctrl;
        let r = vector![0.030];
        for _ in 0..1000 {
            let u = dynamic.update(&x, &r);
            // What the drive applied is reported back, as both loops do.
            dynamic.applied(&u);
            d.advance_mut(&mut x, &u);
        }
        dynamic.reset();
    });
    assert_eq!(n, 0);
    // The loop did something: cart 2 moved towards the setpoint.
    assert!(x[2] > 0.02 && x[2] < 0.035);
}

#[test]
fn observer_and_integral_controllers_allocate_nothing() {
    use ctrlab::Controller;
    use ctrlab::design::{AntiWindup, IntegralFeedback, dlqi};
    use nalgebra::{SMatrix, matrix};
    // The observer + LQI controller on positions the closed-loop tests run.
    let mut on_positions = common::positions_lqi(0.080 / 8192.0);
    let model = common::position_model();
    let tracked = model
        .with_output(matrix![0.0, 1.0] * model.c(), matrix![0.0])
        .unwrap();
    let q = SMatrix::<f64, 5, 5>::from_diagonal(&vector![0.0, 0.0, 1e7, 0.0, 1e10]);
    let lqi = dlqi(&tracked, &q, &matrix![1.0]).unwrap();
    let anti_windup = AntiWindup::BackCalculation {
        tracking: 0.01,
        deadband: 0.024,
    };
    let mut full_state = IntegralFeedback::new(&tracked, &lqi.gain, anti_windup).unwrap();
    let mut x = SVector::<f64, 4>::zeros();
    let mut x_full = SVector::<f64, 4>::zeros();
    let n = allocations(|| {
        // Through trait objects, as a hardware loop would hold them.
        let observed: &mut dyn Controller<4, 1, 1> = &mut on_positions;
        let integral: &mut dyn Controller<4, 1, 1> = &mut full_state;
        let r = vector![0.030];
        for _ in 0..1000 {
            let u = observed.update(&x, &r).map(|u| u.clamp(-24.0, 24.0));
            observed.applied(&u);
            x = model.advance(&x, &u);
            let u = integral.update(&x_full, &r).map(|u| u.clamp(-24.0, 24.0));
            integral.applied(&u);
            x_full = model.advance(&x_full, &u);
        }
        observed.reset();
        integral.reset();
    });
    assert_eq!(n, 0);
    // The loops did something: cart 2 moved towards the setpoint.
    assert!(x[2] > 0.02 && x_full[2] > 0.02, "{x} {x_full}");
}

#[test]
fn rls_update_allocates_nothing() {
    let mut rls = ctrlab::Rls::<4>::new(0.99, 1e3).unwrap();
    let mut err = 0.0;
    let n = allocations(|| {
        for k in 0..1000 {
            let x = k as f64 * 1e-2;
            let phi = vector![1.0, x.sin(), x.cos(), (2.0 * x).sin()];
            err = rls.update(&phi, 0.5 + 2.0 * x.sin()).unwrap();
        }
    });
    assert_eq!(n, 0);
    assert!(err.abs() < 1e-6 && (rls.theta()[1] - 2.0).abs() < 1e-6);
}

#[test]
fn recording_push_vectors_allocates_nothing_within_capacity() {
    // The lab's layout (u; x1, v1, x2, v2), one sample per state read.
    let mut rec = ctrlab::Recording::with_capacity(ctrlab::lab::schema(), 1000);
    let n = allocations(|| {
        for k in 0..1000 {
            let t = k as f64 * 0.002;
            rec.push_vectors(t, &vector![1.0], &vector![t, 1.0, 2.0 * t, 2.0])
                .unwrap();
        }
    });
    assert_eq!(n, 0);
    assert_eq!(rec.len(), 1000);
    assert_eq!(rec.channel("v2").map(<[f64]>::len).unwrap(), 1000);
    // Past capacity it does allocate: the counter would see it.
    assert!(
        allocations(|| rec
            .push_vectors(2.0, &vector![1.0], &vector![0.0, 0.0, 0.0, 0.0])
            .unwrap())
            > 0
    );
}

#[test]
fn recording_push_allocates_nothing_within_capacity() {
    use ctrlab::data::{Channel, Schema};
    // Positions only, as the lab's own logs are.
    let schema = Schema::new(
        vec![Channel::new("u", "V")],
        vec![Channel::new("x1", "m"), Channel::new("x2", "m")],
    )
    .unwrap();
    let mut rec = ctrlab::Recording::with_capacity(schema, 1000);
    let n = allocations(|| {
        for k in 0..1000 {
            rec.push(k as f64 * 0.002, &[1.0], &[0.001, 0.002]).unwrap();
        }
    });
    assert_eq!(n, 0);
    assert_eq!(rec.channel("x1").unwrap().len(), 1000);
}

/// Where the lab's cart-2 law (10 V/mm on x2) holds cart 2 for setpoint
/// `r` on the default truth, without friction: with the static compliance
/// c = 1/k1 + 1/k2 at cart 2 and the loop gain g = c K Kp,
/// x2 = r g / (1 + g) (28.73 mm for 30 mm).
fn steady_x2(r: f64) -> f64 {
    let truth = ctrlab::lab::SimulatedRig::default_truth();
    let loop_gain = (1.0 / truth.k1 + 1.0 / truth.k2) * truth.gain * 10_000.0;
    r * loop_gain / (1.0 + loop_gain)
}

/// How far from [`steady_x2`] cart 2 may stop: its breakaway force on the
/// default rig over the closed loop's stiffness, c F_s / (1 + g), plus
/// three counts of encoder noise and rounding (σ = 0.3 count).
fn friction_band() -> f64 {
    let sim = ctrlab::lab::SimulatedRig::default();
    let truth = sim.truth;
    let compliance = 1.0 / truth.k1 + 1.0 / truth.k2;
    let loop_gain = compliance * truth.gain * 10_000.0;
    sim.friction.stiction[1] * compliance / (1.0 + loop_gain) + 3.0 * sim.metres_per_count()
}

#[test]
fn hw_run_on_the_simulated_rig_allocates_nothing_per_tick() {
    use ctrlab::hw::{Clock, LoopConfig, VirtualClock, run};
    use ctrlab::lab::{LabGains, SimulatedRig};
    let clock = VirtualClock::new();
    let virtual_clock = Clock::Virtual(clock.clone());
    // The realistic rig: friction, stiction, PWM delay, encoder noise; the
    // loop's checks (timing faults, gaps, the rig's bus-fault and stall
    // checks) all run.
    let mut rig = SimulatedRig::default().rig(&virtual_clock).unwrap();
    let ctrl = LabGains::new([0.0, 0.0, 10.0, 0.1], Cart::Two)
        .state_feedback()
        .unwrap();
    let mut counted = |ticks: usize| {
        let config = LoopConfig {
            duration: ticks as f64 * 0.002,
            ..LoopConfig::default()
        };
        let mut out = None;
        let n = allocations(|| {
            out = Some(run(
                &mut rig,
                ctrl,
                |_| vector![0.030],
                &virtual_clock,
                &config,
            ));
        });
        let out = out.unwrap().unwrap();
        assert_eq!(out.recording.len(), ticks);
        (n, out)
    };
    let (short, _) = counted(100);
    let (long, out) = counted(1000);
    println!("hw::run: {short} allocations for 100 ticks, {long} for 1000");
    // Only the up-front buffers (the recording's columns, its schema, the
    // lateness statistics, the timing-fault window): the same for 100
    // ticks as for 1000.
    assert_eq!(short, long, "allocations grow with the number of ticks");
    assert!(long > 0, "the counter sees the run's buffers");
    // The loop did something: after 2 s cart 2 is where the law holds it,
    // within the friction dead band.
    let x2 = *out.recording.channel("x2").unwrap().last().unwrap();
    assert!((x2 - steady_x2(0.030)).abs() <= friction_band(), "{x2}");
}

#[test]
fn run_sampled_allocates_nothing_per_sample() {
    use ctrlab::lab::{LabGains, SimulatedRig};
    use ctrlab::sim::run_sampled;
    // The realistic rig: friction, stiction, the input delay, noise.
    let sim = SimulatedRig::default();
    let ctrl = LabGains::new([0.0, 0.0, 10.0, 0.1], Cart::Two)
        .state_feedback()
        .unwrap();
    let counted = |samples: usize| {
        let config = sim.sampled_config(samples as f64 * 0.002);
        let (plant, sensor) = (sim.plant(), sim.sensor());
        let mut out = None;
        let n = allocations(|| {
            out = Some(run_sampled(
                plant,
                sensor,
                ctrl,
                |_| vector![0.030],
                SVector::zeros(),
                &config,
            ));
        });
        let rec = out.unwrap().unwrap();
        assert_eq!(rec.len(), samples);
        (n, rec)
    };
    let (short, _) = counted(100);
    let (long, rec) = counted(1000);
    println!("run_sampled: {short} allocations for 100 samples, {long} for 1000");
    // Only the recording (its columns and a copy of the schema), up front.
    assert_eq!(short, long, "allocations grow with the number of samples");
    assert!(long > 0, "the counter sees the recording");
    let x2 = *rec.channel("x2").unwrap().last().unwrap();
    assert!((x2 - steady_x2(0.030)).abs() <= friction_band(), "{x2}");
}

#[test]
fn least_squares_push_row_allocates_nothing_within_capacity() {
    let mut ls = ctrlab::LeastSquares::with_capacity(2, 1000);
    let n = allocations(|| {
        for k in 0..1000 {
            let x = k as f64;
            ls.push_row(&[1.0, x], 2.0 + 3.0 * x).unwrap();
        }
    });
    assert_eq!(n, 0);
    assert!((ls.solve().unwrap().theta[1] - 3.0).abs() < 1e-12);
}

#[test]
fn generic_simulations_of_a_fixed_size_model_allocate_per_run_not_per_sample() {
    use ctrlab::sim::{Solver, simulate, simulate_discrete_feedback, step_response, time_grid};
    // The free functions take either model size; a fixed-size model keeps
    // its stack vectors in the loops, so a run allocates its output
    // buffers up front and nothing per sample, whatever its length.
    let plant = MassSpring::nominal().state_space(Cart::Two).unwrap();
    let discrete = plant.discretize(0.002, Discretization::Zoh).unwrap();
    let counted = |seconds: f64| {
        let t = time_grid(seconds, 0.002).unwrap();
        [
            allocations(|| drop(step_response(&plant, seconds, 0.002).unwrap())),
            allocations(|| drop(step_response(&discrete, seconds, 0.002).unwrap())),
            allocations(|| {
                drop(simulate(&plant, &t, SVector::zeros(), |_| vector![1.0], Solver::Zoh).unwrap())
            }),
            allocations(|| {
                let rk4 = Solver::Rk4 { substeps: 2 };
                drop(simulate(&plant, &t, SVector::zeros(), |_| vector![1.0], rk4).unwrap())
            }),
            allocations(|| {
                let steps = t.len();
                drop(
                    simulate_discrete_feedback(&discrete, SVector::zeros(), steps, |_, x| {
                        vector![-10.0 * x[2]]
                    })
                    .unwrap(),
                )
            }),
        ]
    };
    let (short, long) = (counted(0.2), counted(2.0));
    println!("simulations: {short:?} allocations for 100 samples, {long:?} for 1000");
    assert_eq!(short, long, "allocations grow with the number of samples");
    assert!(long.iter().all(|&n| n > 0), "the counter sees the buffers");
}

#[test]
fn the_mpc_tick_allocates_nothing() {
    // The lab's MPC, cart 2 stepped to 5 mm inside its travel and back:
    // every tick of both steps (the active-set solves, the polish, the
    // target, the estimator, the shifted and clipped warm start) runs in
    // the buffers made at construction.
    use ctrlab::Controller;
    use ctrlab::lab::{Calibration, lqi, mpc};
    let cal = Calibration::default();
    let model = lqi::position_model(&MassSpring::nominal(), 0.002).unwrap();
    let mut c = mpc::design(&model, Cart::Two, &cal).unwrap();
    let mut x = SVector::<f64, 4>::zeros();
    let tick = |c: &mut mpc::PositionsMpc, x: &mut SVector<f64, 4>, r: f64| {
        let u = c.update(x, &vector![r]);
        c.applied(&u);
        *x = model.a() * *x + model.b() * u;
    };
    // Counted from the very first tick: it builds nothing either.
    let n = allocations(|| {
        for k in 0..1200 {
            let r = if k < 600 { 0.045 } else { -0.02 };
            tick(&mut c, &mut x, r);
        }
    });
    let stats = *c.inner().stats();
    assert_eq!(n, 0, "{stats}");
    assert!(
        stats.active_set_steps_max > 0,
        "the active-set method ran: {stats}"
    );
}
