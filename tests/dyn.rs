//! Run-time-sized models (`DynStateSpace`) against fixed-size ones on the
//! lab plant (the same algorithms, so the same numbers to rounding), a
//! model whose size comes from data against python-control
//! (`tests/data/dyn_fixtures.json`, from `gen_dyn_fixtures.py`), and
//! adversarial sizes and values (no panic; `Ok` only with finite numbers).

// Built on the two-cart lab (its plant, simulated rig or card).
#![cfg(feature = "lab")]

use ctrlab::design::{acker, place, place_observer};
use ctrlab::discretize::{expm, expm_dyn};
use ctrlab::lab::LabGains;
use ctrlab::sim::{Solver, impulse_response, initial_response, simulate, step_response, time_grid};
use ctrlab::{
    Cart, Continuous, Discrete, Discretization, DynStateSpace, Error, MassSpring, StateSpace,
    StepInfoOptions, step_info, step_info_mimo, step_info_of,
};
use nalgebra::{Complex, DMatrix, DVector, SMatrix, SVector, dvector, vector};
use proptest::prelude::*;
use serde_json::Value;

/// Largest difference between two sequences, relative to the largest
/// magnitude in `want` (absolute when that is 0).
fn rel(got: &[f64], want: &[f64]) -> f64 {
    assert_eq!(got.len(), want.len());
    let scale = want.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let worst = got
        .iter()
        .zip(want)
        .fold(0.0f64, |m, (g, w)| m.max((g - w).abs()));
    if scale > 0.0 { worst / scale } else { worst }
}

fn flat_complex(p: &[Complex<f64>]) -> Vec<f64> {
    p.iter().flat_map(|p| [p.re, p.im]).collect()
}

fn plant() -> StateSpace<4, 1, 1> {
    MassSpring::nominal().state_space(Cart::Two).unwrap()
}

/// Rounding of the lab plant's numbers: its `A` has entries up to 10⁴,
/// and results go through a few products; 1e-13 relative is a few hundred
/// ulps, far below anything an algorithmic difference would give.
const ROUNDING: f64 = 1e-13;

#[test]
fn analysis_agrees_with_the_fixed_size_model() {
    let closed = LabGains::new([0.0, 0.0, 10.0, 0.1], Cart::Two)
        .state_feedback()
        .unwrap()
        .closed_loop(&plant())
        .unwrap();
    for (name, dynamic) in [
        ("continuous", DynStateSpace::from(plant())),
        ("closed loop", DynStateSpace::from(closed)),
    ] {
        let fixed = StateSpace::<4, 1, 1>::try_from(&dynamic).unwrap();
        let worst = [
            rel(
                &flat_complex(&dynamic.poles().unwrap()),
                &flat_complex(&fixed.poles().unwrap()),
            ),
            rel(
                dynamic.dc_gain().unwrap().as_slice(),
                fixed.dc_gain().unwrap().as_slice(),
            ),
            rel(
                dynamic.controllability().unwrap().as_slice(),
                fixed.controllability().unwrap().as_slice(),
            ),
            rel(
                dynamic.observability().unwrap().as_slice(),
                fixed.observability().unwrap().as_slice(),
            ),
        ]
        .into_iter()
        .fold(0.0, f64::max);
        println!("{name}: analysis, largest relative difference {worst:e}");
        assert!(worst <= ROUNDING, "{name}: {worst:e}");
        assert_eq!(dynamic.is_stable().unwrap(), fixed.is_stable().unwrap());
        assert_eq!(
            dynamic.unstable_pole().unwrap(),
            fixed.unstable_pole().unwrap()
        );
        assert!(dynamic.is_controllable().unwrap() && fixed.is_controllable().unwrap());
        assert!(dynamic.is_observable().unwrap() && fixed.is_observable().unwrap());
        for (d, f) in dynamic
            .damping()
            .unwrap()
            .iter()
            .zip(fixed.damping().unwrap())
        {
            assert!(
                (d.natural_frequency - f.natural_frequency).abs() <= ROUNDING * f.natural_frequency
            );
            assert!((d.damping_ratio - f.damping_ratio).abs() <= ROUNDING);
        }
    }
}

#[test]
fn discretisation_agrees_bit_for_bit() {
    let fixed = plant();
    let dynamic = DynStateSpace::from(&fixed);
    for method in [
        Discretization::Zoh,
        Discretization::Tustin,
        Discretization::ForwardEuler,
        Discretization::BackwardEuler,
    ] {
        for dt in [0.0005, 0.002, 0.1, 3.0] {
            let f = fixed.discretize(dt, method).unwrap();
            let d = dynamic.discretize(dt, method).unwrap();
            assert_eq!(d.dt(), f.dt());
            let back: StateSpace<4, 1, 1, Discrete> = d.clone().try_into().unwrap();
            assert_eq!(back, f, "{method:?} at {dt}");
            // And the discrete model's analysis.
            let (fp, dp) = (f.poles().unwrap(), d.poles().unwrap());
            assert!(rel(&flat_complex(&dp), &flat_complex(&fp)) <= ROUNDING);
            assert_eq!(d.is_stable().unwrap(), f.is_stable().unwrap());
            if let (Ok(fg), Ok(dg)) = (f.dc_gain(), d.dc_gain()) {
                assert!(
                    rel(dg.as_slice(), fg.as_slice()) <= 1e-12,
                    "{method:?} {dt}"
                );
            }
            for (x, y) in d.damping().unwrap().iter().zip(f.damping().unwrap()) {
                assert!(
                    (x.natural_frequency - y.natural_frequency).abs()
                        <= ROUNDING * y.natural_frequency
                );
            }
        }
    }
    // The matrix exponential, and its refusals, are one implementation.
    let a = *fixed.a() * 0.01;
    let e = expm(&a).unwrap();
    let ed = expm_dyn(&DMatrix::from_column_slice(4, 4, a.as_slice())).unwrap();
    assert_eq!(e.as_slice(), ed.as_slice());
    let spin = nalgebra::matrix![0.0, -1e15; 1e15, 0.0];
    assert!(matches!(expm(&spin), Err(Error::IllConditioned { .. })));
    assert!(matches!(
        expm_dyn(&DMatrix::from_column_slice(2, 2, spin.as_slice())),
        Err(Error::IllConditioned { .. })
    ));
}

#[test]
fn responses_agree_with_the_fixed_size_functions() {
    let fixed = plant();
    let dynamic = DynStateSpace::from(&fixed);
    let outputs = |y: &[DVector<f64>]| y.iter().map(|y| y[0]).collect::<Vec<_>>();
    let fixed_out = |y: &[SVector<f64, 1>]| y.iter().map(|y| y[0]).collect::<Vec<_>>();

    let (f, d) = (
        step_response(&fixed, 2.0, 0.001).unwrap(),
        step_response(&dynamic, 2.0, 0.001).unwrap(),
    );
    assert_eq!(f.t, d.t);
    let step = rel(&outputs(&d.y), &fixed_out(&f.y));
    let (f, d) = (
        impulse_response(&fixed, 2.0, 0.001).unwrap(),
        impulse_response(&dynamic, 2.0, 0.001).unwrap(),
    );
    let impulse = rel(&outputs(&d.y), &fixed_out(&f.y));
    let x0 = vector![0.001, 0.0, -0.002, 0.1];
    let (f, d) = (
        initial_response(&fixed, 2.0, 0.001, x0).unwrap(),
        initial_response(
            &dynamic,
            2.0,
            0.001,
            DVector::from_column_slice(x0.as_slice()),
        )
        .unwrap(),
    );
    let initial = rel(&outputs(&d.y), &fixed_out(&f.y));
    // A non-uniform grid: one discretisation per interval length.
    let t: Vec<f64> = (0..400)
        .map(|k| 0.001 * k as f64 + 1e-6 * (k * k) as f64)
        .collect();
    let f = simulate(
        &fixed,
        &t,
        SVector::zeros(),
        |t| vector![(5.0 * t).sin()],
        Solver::Zoh,
    )
    .unwrap();
    let d = simulate(
        &dynamic,
        &t,
        DVector::zeros(4),
        |t| dvector![(5.0 * t).sin()],
        Solver::Zoh,
    )
    .unwrap();
    let lsim = rel(&outputs(&d.y), &fixed_out(&f.y));
    let states =
        d.x.iter()
            .zip(&f.x)
            .map(|(d, f)| rel(d.as_slice(), f.as_slice()))
            .fold(0.0, f64::max);

    // The discrete model: steps, pulses, the free response, feedback.
    let fd = fixed.discretize(0.002, Discretization::Zoh).unwrap();
    let dd = dynamic.discretize(0.002, Discretization::Zoh).unwrap();
    let discrete = [
        rel(
            &outputs(&step_response(&dd, 1.0, 0.002).unwrap().y),
            &fixed_out(&step_response(&fd, 1.0, 0.002).unwrap().y),
        ),
        rel(
            &outputs(&impulse_response(&dd, 1.0, 0.002).unwrap().y),
            &fixed_out(&impulse_response(&fd, 1.0, 0.002).unwrap().y),
        ),
    ]
    .into_iter()
    .fold(0.0, f64::max);
    let k = [0.0, 0.0, 10.0, 0.1];
    let fr = ctrlab::sim::simulate_discrete_feedback(&fd, SVector::zeros(), 500, |_k, x| {
        vector![10.0 * (0.03 - x[2]) - 0.1 * x[3]]
    })
    .unwrap();
    let dr = ctrlab::sim::simulate_discrete_feedback(&dd, DVector::zeros(4), 500, |_k, x| {
        dvector![k[2] * (0.03 - x[2]) - k[3] * x[3]]
    })
    .unwrap();
    let feedback = rel(&outputs(&dr.y), &fixed_out(&fr.y));
    println!(
        "responses, largest relative difference: step {step:e}, impulse {impulse:e}, \
         initial {initial:e}, lsim {lsim:e} (states {states:e}), discrete {discrete:e}, \
         feedback {feedback:e}"
    );
    for v in [step, impulse, initial, lsim, states, discrete, feedback] {
        assert!(v <= ROUNDING, "{v:e}");
    }
}

#[test]
fn step_metrics_and_placement_agree_with_the_fixed_size_functions() {
    let fixed = plant();
    let cl = LabGains::new([0.0, 0.0, 10.0, 0.1], Cart::Two)
        .state_feedback()
        .unwrap()
        .closed_loop(&fixed)
        .unwrap();
    let dcl = DynStateSpace::from(&cl);
    let options = StepInfoOptions::default();
    let f = step_info_of(&cl, 2.0, 0.0005, &options).unwrap();
    let d = step_info_of(&dcl, 2.0, 0.0005, &options).unwrap();
    let r = step_response(&dcl, 2.0, 0.0005).unwrap();
    let from_response = step_info(&r.t, &r.output(0).unwrap(), &options).unwrap();
    let figures = |i: &ctrlab::StepInfo| {
        vec![
            i.rise_time,
            i.settling_time,
            i.overshoot,
            i.peak,
            i.peak_time,
            i.steady_state_value,
        ]
    };
    let metrics = rel(&figures(&d), &figures(&f));
    println!("step_info, largest relative difference {metrics:e}");
    assert!(metrics <= ROUNDING);
    // The response's own figures estimate the final value from the data.
    assert!((from_response.overshoot - f.overshoot).abs() < 0.1);
    let fd = cl.discretize(0.002, Discretization::Zoh).unwrap();
    let dd = dcl.discretize(0.002, Discretization::Zoh).unwrap();
    let (a, b) = (
        step_info_of(&fd, 2.0, 0.002, &options).unwrap(),
        step_info_of(&dd, 2.0, 0.002, &options).unwrap(),
    );
    assert!(rel(&figures(&b), &figures(&a)) <= ROUNDING);

    let targets = [
        Complex::new(-30.0, 30.0),
        Complex::new(-30.0, -30.0),
        Complex::new(-40.0, 0.0),
        Complex::new(-50.0, 0.0),
    ];
    let dynamic = DynStateSpace::from(&fixed);
    let ka = rel(
        acker(&dynamic, targets).unwrap().as_slice(),
        acker(&fixed, targets).unwrap().as_slice(),
    );
    let kp = rel(
        place(&dynamic, targets).unwrap().as_slice(),
        place(&fixed, targets).unwrap().as_slice(),
    );
    let observed = fixed
        .with_output(
            ctrlab::lab::position_output_matrix(),
            nalgebra::matrix![0.0; 0.0],
        )
        .unwrap();
    let observer_targets = [-100.0, -100.0, -150.0, -150.0].map(|re| Complex::new(re, 0.0));
    let kl = rel(
        place_observer(&DynStateSpace::from(&observed), observer_targets)
            .unwrap()
            .as_slice(),
        place_observer(&observed, observer_targets)
            .unwrap()
            .as_slice(),
    );
    // And on the ZOH model, in the z-plane.
    let z_targets = targets.map(|s| (s * 0.002).exp());
    let fz = fixed.discretize(0.002, Discretization::Zoh).unwrap();
    let dz = DynStateSpace::from(&fz);
    let kz = rel(
        place(&dz, z_targets).unwrap().as_slice(),
        place(&fz, z_targets).unwrap().as_slice(),
    )
    .max(rel(
        acker(&dz, z_targets).unwrap().as_slice(),
        acker(&fz, z_targets).unwrap().as_slice(),
    ));
    println!(
        "gains, largest relative difference: acker {ka:e}, place {kp:e}, observer {kl:e}, discrete {kz:e}"
    );
    for v in [ka, kp, kl, kz] {
        assert!(v <= 1e-12, "{v:e}");
    }
}

// ---- a model sized at run time, against python-control ----

fn fixtures() -> Value {
    serde_json::from_str(include_str!("data/dyn_fixtures.json")).unwrap()
}

fn matrix(v: &Value) -> DMatrix<f64> {
    let rows: Vec<Vec<f64>> = serde_json::from_value(v.clone()).unwrap();
    let (r, c) = (rows.len(), rows.first().map_or(0, Vec::len));
    DMatrix::from_fn(r, c, |i, j| rows[i][j])
}

fn complexes(v: &Value) -> Vec<Complex<f64>> {
    let pairs: Vec<[f64; 2]> = serde_json::from_value(v.clone()).unwrap();
    pairs
        .into_iter()
        .map(|[re, im]| Complex::new(re, im))
        .collect()
}

/// The chain of `n` coupled first-order sections of `gen_dyn_fixtures.py`,
/// built by the same loop: its size is data, not a type.
fn chain(n: usize) -> DynStateSpace {
    let mut a = DMatrix::zeros(n, n);
    for i in 0..n {
        a[(i, i)] = -(1.0 + 0.5 * i as f64);
        if i + 1 < n {
            a[(i + 1, i)] = 2.0 + i as f64;
            a[(i, i + 1)] = -0.3 * (i + 1) as f64;
        }
    }
    let mut b = DMatrix::zeros(n, 2);
    b[(0, 0)] = 1.0;
    b[(3, 1)] = 1.0;
    let mut c = DMatrix::zeros(2, n);
    c[(0, n - 1)] = 1.0;
    c[(1, 0)] = 1.0;
    DynStateSpace::continuous(a, b, c, DMatrix::zeros(2, 2)).unwrap()
}

#[test]
fn a_chain_sized_at_run_time_matches_python_control() {
    let fx = fixtures();
    let n = fx["n"].as_u64().unwrap() as usize;
    let sys = chain(n);
    assert_eq!(sys.a(), &matrix(&fx["A"]));
    assert_eq!(sys.b(), &matrix(&fx["B"]));

    let poles = rel(
        &flat_complex(&sys.poles().unwrap()),
        &flat_complex(&complexes(&fx["poles"])),
    );
    let damping = sys.damping().unwrap();
    let wn: Vec<f64> = damping.iter().map(|d| d.natural_frequency).collect();
    let zeta: Vec<f64> = damping.iter().map(|d| d.damping_ratio).collect();
    let want_wn: Vec<f64> = serde_json::from_value(fx["damp_wn"].clone()).unwrap();
    let want_zeta: Vec<f64> = serde_json::from_value(fx["damp_zeta"].clone()).unwrap();
    let damp = rel(&wn, &want_wn).max(rel(&zeta, &want_zeta));
    let gain = rel(
        sys.dc_gain().unwrap().as_slice(),
        matrix(&fx["dcgain"]).as_slice(),
    );
    let ctrb = rel(
        sys.controllability().unwrap().as_slice(),
        matrix(&fx["ctrb"]).as_slice(),
    );
    let obsv = rel(
        sys.observability().unwrap().as_slice(),
        matrix(&fx["obsv"]).as_slice(),
    );
    assert_eq!(fx["ctrb_rank"].as_u64(), Some(n as u64));
    assert_eq!(fx["obsv_rank"].as_u64(), Some(n as u64));
    assert!(sys.is_controllable().unwrap() && sys.is_observable().unwrap());
    assert!(sys.is_stable().unwrap());

    let dt = fx["dt"].as_f64().unwrap();
    let zoh = sys.discretize(dt, Discretization::Zoh).unwrap();
    let tustin = sys.discretize(dt, Discretization::Tustin).unwrap();
    let mut c2d = 0.0f64;
    for (got, want) in [(&zoh, &fx["zoh"]), (&tustin, &fx["tustin"])] {
        for (m, key) in [
            (got.a(), "A"),
            (got.b(), "B"),
            (got.c(), "C"),
            (got.d(), "D"),
        ] {
            c2d = c2d.max(rel(m.as_slice(), matrix(&want[key]).as_slice()));
        }
    }
    let zoh_poles = rel(
        &flat_complex(&zoh.poles().unwrap()),
        &flat_complex(&complexes(&fx["zoh_poles"])),
    );
    let zoh_gain = rel(
        zoh.dc_gain().unwrap().as_slice(),
        matrix(&fx["zoh_dcgain"]).as_slice(),
    );
    println!(
        "7-state chain vs python-control, largest relative difference: poles {poles:e}, \
         damp {damp:e}, dcgain {gain:e}, ctrb {ctrb:e}, obsv {obsv:e}, c2d {c2d:e}, \
         ZOH poles {zoh_poles:e}, ZOH dcgain {zoh_gain:e}"
    );
    // Eigenvalues and gains to 1e-12 of the largest (LAPACK and faer
    // agree to rounding on this well-conditioned chain); the Krylov
    // matrices are exact products of small integers and tenths; SciPy's
    // expm (Al-Mohy–Higham) and ctrlab's (Padé 6 after scaling) are two
    // algorithms, each accurate to about 1e-15.
    for (what, v, tol) in [
        ("poles", poles, 1e-12),
        ("damp", damp, 1e-12),
        ("dcgain", gain, 1e-12),
        ("ctrb", ctrb, 1e-14),
        ("obsv", obsv, 1e-14),
        ("c2d", c2d, 1e-13),
        ("zoh poles", zoh_poles, 1e-12),
        ("zoh dcgain", zoh_gain, 1e-11),
    ] {
        assert!(v <= tol, "{what}: {v:e}");
    }

    // step_info of channel (output 0, input 0), against python-control on
    // the same grid: python-control snaps crossing times to the grid and
    // ctrlab interpolates, so times agree to one grid step.
    let si = &fx["step_info"];
    let (t_end, grid_dt) = (
        si["t_end"].as_f64().unwrap(),
        si["grid_dt"].as_f64().unwrap(),
    );
    let siso = DynStateSpace::continuous(
        sys.a().clone(),
        sys.b().columns(0, 1).into_owned(),
        sys.c().rows(0, 1).into_owned(),
        DMatrix::zeros(1, 1),
    )
    .unwrap();
    let info = step_info_of(&siso, t_end, grid_dt, &StepInfoOptions::default()).unwrap();
    let get = |k: &str| si[k].as_f64().unwrap();
    println!(
        "step_info: rise {} vs {}, settling {} vs {}, steady state {} vs {}",
        info.rise_time,
        get("RiseTime"),
        info.settling_time,
        get("SettlingTime"),
        info.steady_state_value,
        get("SteadyStateValue")
    );
    assert!((info.rise_time - get("RiseTime")).abs() <= grid_dt);
    assert!((info.settling_time - get("SettlingTime")).abs() <= grid_dt);
    assert!((info.steady_state_value - get("SteadyStateValue")).abs() <= 1e-12);
    assert!((info.overshoot - get("Overshoot")).abs() <= 1e-9);
    // The same channel through step_info_mimo.
    let mimo = step_info_mimo(&sys, t_end, grid_dt, &StepInfoOptions::default()).unwrap();
    assert_eq!(mimo[0][0].as_ref().unwrap(), &info);
    assert_eq!((mimo.len(), mimo[0].len()), (2, 2));

    // Placement: gains are not unique with two inputs, so the achieved
    // poles are checked (python-control's six decimals), and Ackermann's
    // unique single-input gain against python-control's.
    let targets = complexes(&fx["place"]["targets"]);
    let k = place(&sys, &targets).unwrap();
    let closed = DynStateSpace::continuous(
        sys.a() - sys.b() * &k,
        sys.b().clone(),
        sys.c().clone(),
        sys.d().clone(),
    )
    .unwrap();
    let achieved = rel(
        &flat_complex(&closed.poles().unwrap()),
        &flat_complex(&complexes(&fx["place"]["achieved"])),
    );
    let k_acker = acker(&sys.select_input(0).unwrap(), &targets).unwrap();
    let acker_gain = rel(k_acker.as_slice(), matrix(&fx["acker"]["K"]).as_slice());
    println!("place: achieved poles {achieved:e}; acker gain {acker_gain:e}");
    assert!(achieved <= 1e-6);
    assert!(acker_gain <= 1e-9);
}

#[test]
fn wrong_sizes_are_errors_not_panics() {
    let sys = chain(7);
    let one = |re| Complex::new(re, 0.0);
    assert!(matches!(
        place(&sys, [one(-1.0); 3]),
        Err(Error::LengthMismatch {
            what: "poles",
            expected: 7,
            found: 3
        })
    ));
    assert!(matches!(
        acker(&sys, [one(-1.0); 7]),
        Err(Error::DimensionMismatch { matrix: "B", .. })
    ));
    assert!(matches!(
        step_response(&sys, 1.0, 0.01),
        Err(Error::DimensionMismatch { matrix: "B", .. })
    ));
    assert!(matches!(
        step_info_of(&sys, 1.0, 0.01, &StepInfoOptions::default()),
        Err(Error::DimensionMismatch { .. })
    ));
    assert!(matches!(
        initial_response(&sys, 1.0, 0.01, DVector::zeros(6)),
        Err(Error::LengthMismatch { what: "x0", .. })
    ));
    let t = time_grid(1.0, 0.01).unwrap();
    assert!(matches!(
        simulate(&sys, &t, DVector::zeros(7), |_| dvector![1.0], Solver::Zoh),
        Err(Error::LengthMismatch {
            what: "input",
            expected: 2,
            found: 1
        })
    ));
    assert!(matches!(
        simulate(
            &sys,
            &t,
            DVector::from_element(7, f64::NAN),
            |_| dvector![1.0, 0.0],
            Solver::Zoh
        ),
        Err(Error::NonFinite { matrix: "x0", .. })
    ));
    let d = sys.discretize(0.01, Discretization::Zoh).unwrap();
    assert!(matches!(
        ctrlab::sim::simulate_discrete_feedback(&d, DVector::zeros(7), 5, |_, _| DVector::zeros(3)),
        Err(Error::LengthMismatch { what: "input", .. })
    ));
    assert!(step_response(&d, 1.0, 0.02).is_err()); // not its period
    assert!(matches!(
        expm_dyn(&DMatrix::zeros(2, 3)),
        Err(Error::DimensionMismatch { .. })
    ));
    // A model with no states: a static gain.
    let gain = DynStateSpace::continuous(
        DMatrix::zeros(0, 0),
        DMatrix::zeros(0, 1),
        DMatrix::zeros(1, 0),
        DMatrix::from_element(1, 1, 3.0),
    )
    .unwrap();
    assert_eq!(gain.dc_gain().unwrap()[(0, 0)], 3.0);
    assert!(gain.is_stable().unwrap() && gain.is_controllable().unwrap());
    assert_eq!(
        step_response(&gain, 0.1, 0.05).unwrap().output(0).unwrap(),
        vec![3.0; 3]
    );
    let _: DynStateSpace<Continuous> = gain;
}

// ---- adversarial sizes and values ----

/// Any f64, weighted towards the values that break numeric code.
fn wild() -> impl Strategy<Value = f64> {
    prop_oneof![
        6 => -10.0..10.0f64,
        2 => proptest::num::f64::NORMAL,
        1 => proptest::num::f64::SUBNORMAL | proptest::num::f64::ZERO,
        1 => prop_oneof![Just(f64::MAX), Just(-f64::MAX), Just(1e300), Just(1e-300)],
        1 => prop_oneof![Just(f64::NAN), Just(f64::INFINITY)],
    ]
}

/// Sizes up to 5 states, 3 inputs and outputs (0 included) and matrices of
/// those sizes.
fn model() -> impl Strategy<Value = (usize, usize, usize, Vec<f64>)> {
    (0usize..=5, 0usize..=3, 0usize..=3).prop_flat_map(|(n, m, p)| {
        let len = n * n + n * m + p * n + p * m;
        (
            Just(n),
            Just(m),
            Just(p),
            prop::collection::vec(wild(), len),
        )
    })
}

fn build(n: usize, m: usize, p: usize, v: &[f64]) -> [DMatrix<f64>; 4] {
    let mut it = v.iter().copied();
    let mut take = |r, c| DMatrix::from_iterator(r, c, it.by_ref().take(r * c));
    [take(n, n), take(n, m), take(p, n), take(p, m)]
}

fn finite(m: &DMatrix<f64>) -> bool {
    m.iter().all(|v| v.is_finite())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 200, ..ProptestConfig::default() })]

    #[test]
    fn ok_means_finite_and_nothing_panics((n, m, p, v) in model(), dt in wild(), re in wild(), extra in 0usize..3) {
        let [a, b, c, d] = build(n, m, p, &v);
        let Ok(sys) = DynStateSpace::continuous(a.clone(), b.clone(), c.clone(), d.clone()) else {
            prop_assert!(v.iter().any(|v| !v.is_finite()));
            return Ok(());
        };
        if let Ok(poles) = sys.poles() {
            prop_assert!(poles.iter().all(|p| p.re.is_finite() && p.im.is_finite()));
        }
        let _ = sys.is_stable();
        if let Ok(Some(p)) = sys.unstable_pole() { prop_assert!(p.re.is_finite()); }
        if let Ok(g) = sys.dc_gain() { prop_assert!(finite(&g) && g.shape() == (p, m)); }
        if let Ok(k) = sys.controllability() { prop_assert!(finite(&k)); }
        if let Ok(k) = sys.observability() { prop_assert!(finite(&k)); }
        let _ = (sys.is_controllable(), sys.is_observable());
        if let Ok(ds) = sys.damping() {
            prop_assert!(ds.iter().all(|d| !d.natural_frequency.is_nan() && !d.damping_ratio.is_nan()));
        }
        for method in [Discretization::Zoh, Discretization::Tustin, Discretization::ForwardEuler, Discretization::BackwardEuler] {
            if let Ok(z) = sys.discretize(dt, method) {
                prop_assert!(finite(z.a()) && finite(z.b()) && finite(z.c()) && finite(z.d()));
                if let Ok(g) = z.dc_gain() { prop_assert!(finite(&g)); }
                let _ = z.is_stable();
                if let Ok(r) = ctrlab::sim::simulate_discrete_feedback(&z, DVector::zeros(n), 20, |_, _| DVector::from_element(m, 1.0)) {
                    prop_assert!(r.y.iter().all(|y| y.iter().all(|v| v.is_finite())));
                }
            }
        }
        // Wrong and right numbers of targets.
        let targets = vec![Complex::new(re, 0.0); n + extra];
        if let Ok(k) = place(&sys, &targets) { prop_assert!(finite(&k) && extra == 0); }
        if let Ok(k) = place_observer(&sys, &targets) { prop_assert!(finite(&k) && extra == 0); }
        if let Ok(k) = acker(&sys, &targets) { prop_assert!(finite(&k) && extra == 0 && m == 1); }
        if m == 1 {
            if let Ok(r) = step_response(&sys, 0.05, 0.01) {
                prop_assert!(r.y.iter().all(|y| y.iter().all(|v| v.is_finite())));
            }
            if let Ok(r) = impulse_response(&sys, 0.05, 0.01) {
                prop_assert!(r.x.iter().all(|x| x.iter().all(|v| v.is_finite())));
            }
        }
        if let Ok(info) = step_info_of(&sys, 1.0, 0.01, &StepInfoOptions::default()) {
            prop_assert!(info.rise_time.is_finite() && info.settling_time.is_finite());
        }
        let t = [0.0, 0.01, 0.03];
        if let Ok(r) = simulate(&sys, &t, DVector::zeros(n), |_| DVector::from_element(m + extra, re), Solver::Zoh) {
            prop_assert!(extra == 0 && r.y.iter().all(|y| y.iter().all(|v| v.is_finite())));
        }
        if let Ok(e) = expm_dyn(&a) { prop_assert!(finite(&e)); }
    }

    /// Fixed-size and run-time-sized results agree on random 3-state
    /// models (same algorithm, same rounding), Ok and Err alike.
    #[test]
    fn fixed_and_run_time_sized_agree(v in prop::collection::vec(-10.0..10.0f64, 16), dt in 0.001..1.0f64) {
        let a = SMatrix::<f64, 3, 3>::from_column_slice(&v[..9]);
        let b = SMatrix::<f64, 3, 2>::from_column_slice(&v[9..15]);
        let c = SMatrix::<f64, 1, 3>::from_column_slice(&v[12..15]);
        let fixed = StateSpace::continuous(a, b, c, SMatrix::from_element(v[15])).unwrap();
        let dynamic = DynStateSpace::from(&fixed);
        prop_assert_eq!(fixed.is_controllable().ok(), dynamic.is_controllable().ok());
        prop_assert_eq!(fixed.is_stable().ok(), dynamic.is_stable().ok());
        match (fixed.dc_gain(), dynamic.dc_gain()) {
            (Ok(f), Ok(d)) => prop_assert!(rel(d.as_slice(), f.as_slice()) <= 1e-9),
            (f, d) => prop_assert_eq!(f.is_ok(), d.is_ok()),
        }
        match (fixed.discretize(dt, Discretization::Zoh), dynamic.discretize(dt, Discretization::Zoh)) {
            (Ok(f), Ok(d)) => prop_assert_eq!(f.a().as_slice(), d.a().as_slice()),
            (f, d) => prop_assert_eq!(f.is_ok(), d.is_ok()),
        }
    }
}
