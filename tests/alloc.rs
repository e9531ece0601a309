//! Proves the inner loops allocate nothing, with a counting global allocator.
//!
//! This file is its own test binary, so the allocator sees only these tests;
//! the count is per thread, so tests running in parallel do not disturb it.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

use ctrlab::{Integrator, MassSpring, Method, Cart, Rk4};
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
        .discretize(0.002, Method::Zoh)
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

#[test]
fn zoh_discretisation_allocates_nothing() {
    let sys = MassSpring::nominal().state_space(Cart::Two).unwrap();
    let mut ad00 = 0.0;
    let n = allocations(|| {
        let d = sys.discretize(0.002, Method::Zoh).unwrap();
        ad00 = d.a()[(0, 0)];
    });
    assert_eq!(n, 0);
    assert!(ad00 > 0.99 && ad00 < 1.0);
}

#[test]
fn rig_loop_iteration_on_the_simulated_card_allocates_nothing() {
    use ctrlab::hw::{
        Calibration, MassSpringRig, Pc104, Rig, SimulatedCard, SimulatedCardConfig, VirtualClock,
    };
    let clock = VirtualClock::new();
    let config = SimulatedCardConfig {
        coulomb_friction: [0.5, 0.5],
        encoder_noise: 0.5,
        ..Default::default()
    };
    let card = SimulatedCard::virtual_time(config, &clock).unwrap();
    let mut rig = MassSpringRig::new(Pc104::new(card), Calibration::default(), 0.002).unwrap();
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
    assert!(x[2] > 0.005, "the loop moved cart 2: {x}");
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
    use ctrlab::{Controller, StateFeedback};
    let mut ctrl = StateFeedback::from_lab_gains([0.0, 0.0, 10.0, 0.1], Cart::Two).unwrap();
    let d = MassSpring::nominal()
        .state_space(Cart::Two)
        .unwrap()
        .discretize(0.002, Method::Zoh)
        .unwrap();
    let mut x = SVector::<f64, 4>::zeros();
    let n = allocations(|| {
        // Through the trait object too, as a hardware loop would hold it.
        let dynamic: &mut dyn Controller<4, 1> = &mut ctrl;
        for _ in 0..1000 {
            let u = dynamic.update(0.030, &x);
            d.advance_mut(&mut x, &u);
        }
        dynamic.reset();
    });
    assert_eq!(n, 0);
    // The loop did something: cart 2 moved towards the setpoint.
    assert!(x[2] > 0.02 && x[2] < 0.035);
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
fn recording_push_state_allocates_nothing_within_capacity() {
    let mut rec = ctrlab::Recording::with_capacity(1000);
    let n = allocations(|| {
        for k in 0..1000 {
            let t = k as f64 * 0.002;
            rec.push_state(t, 1.0, &vector![t, 1.0, 2.0 * t, 2.0]);
        }
    });
    assert_eq!(n, 0);
    assert_eq!(rec.len(), 1000);
    assert_eq!(rec.v2.as_ref().map(Vec::len), Some(1000));
    // Past capacity it does allocate: the counter would see it.
    assert!(allocations(|| rec.push_state(2.0, 1.0, &vector![0.0, 0.0, 0.0, 0.0])) > 0);
}

#[test]
fn recording_push_allocates_nothing_within_capacity() {
    let mut rec = ctrlab::Recording::with_capacity(1000);
    let n = allocations(|| {
        for k in 0..1000 {
            rec.push(k as f64 * 0.002, 1.0, 0.001, 0.002);
        }
    });
    assert_eq!(n, 0);
    assert_eq!(rec.x1.len(), 1000);
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
