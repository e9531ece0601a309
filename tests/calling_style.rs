//! One calling style for both model sizes: the same free function on a
//! `StateSpace` and on the same model as a `DynStateSpace` gives the same
//! numbers (designs, responses, step figures, margins); target poles as
//! plain numbers; the frequency tools on every model type; and the text of
//! each `Display`.

use ctrlab::analysis::{Poles, dlyap, lyap, sylvester};
use ctrlab::design::{acker, dlqe, dlqi, dlqr, lqe, lqi, lqr, place, place_observer};
use ctrlab::freq::{TransferFunction, TransferMatrix, Zpk, bandwidth, stability_margins};
use ctrlab::integrate::{Integrator, Rk4};
use ctrlab::sim::{
    Solver, impulse_response, initial_response, simulate, simulate_discrete,
    simulate_discrete_feedback, step_response, time_grid,
};
use ctrlab::{
    Discretization, DynStateSpace, Error, StateSpace, StepInfoOptions, step_info_mimo, step_info_of,
};
use nalgebra::{Complex, DMatrix, DVector, SMatrix, dvector, matrix, vector};

/// Two carts on springs (1.3 kg and 0.7 kg, 1000 N/m each, light viscous
/// damping), a force on the second, its position measured: the lab's
/// plant, written out so that this file needs no feature.
fn two_carts() -> StateSpace<4, 1, 1> {
    let (m1, m2, k1, k2, c1, c2) = (1.3, 0.7, 1000.0, 1000.0, 2.0, 1.0);
    StateSpace::continuous(
        matrix![0.0, 1.0, 0.0, 0.0;
                -(k1 + k2) / m1, -c1 / m1, k2 / m1, 0.0;
                0.0, 0.0, 0.0, 1.0;
                k2 / m2, 0.0, -k2 / m2, -c2 / m2],
        matrix![0.0; 0.0; 0.0; 1.0 / m2],
        matrix![0.0, 0.0, 1.0, 0.0],
        matrix![0.0],
    )
    .unwrap()
}

fn heap<const R: usize, const C: usize>(m: &SMatrix<f64, R, C>) -> DMatrix<f64> {
    DMatrix::from_column_slice(R, C, m.as_slice())
}

#[test]
fn lqr_and_dlqr_agree_across_sizes() {
    let plant = two_carts();
    let dynamic = DynStateSpace::from(&plant);
    let q = SMatrix::<f64, 4, 4>::from_diagonal(&vector![1e4, 0.0, 1e6, 0.0]);
    let r = matrix![1.0];
    let f = lqr(&plant, &q, &r).unwrap();
    let d = lqr(&dynamic, &heap(&q), &heap(&r)).unwrap();
    assert_eq!(f.gain.as_slice(), d.gain.as_slice());
    assert_eq!(f.riccati.as_slice(), d.riccati.as_slice());
    assert_eq!(f.poles.as_slice(), d.poles.as_slice());
    assert_eq!((f.residual, f.iterations), (d.residual, d.iterations));

    let fd = plant.discretize(0.002, Discretization::Zoh).unwrap();
    let dd = dynamic.discretize(0.002, Discretization::Zoh).unwrap();
    let f = dlqr(&fd, &q, &r).unwrap();
    let d = dlqr(&dd, &heap(&q), &heap(&r)).unwrap();
    assert_eq!(f.gain.as_slice(), d.gain.as_slice());
    assert_eq!(f.riccati.as_slice(), d.riccati.as_slice());
    assert_eq!(f.poles.as_slice(), d.poles.as_slice());
    // A weight of the wrong size is an error for the run-time-sized model
    // (for the fixed-size one it does not compile).
    assert!(matches!(
        dlqr(&dd, &heap(&q), &DMatrix::identity(2, 2)),
        Err(Error::DimensionMismatch { matrix: "R", .. })
    ));
}

#[test]
fn lyapunov_equations_agree_across_sizes() {
    // The plant's controllability Gramians, continuous and ZOH at 2 ms.
    let plant = two_carts();
    let (a, b) = (*plant.a(), *plant.b());
    let q = b * b.transpose();
    let f = lyap(&a, &q).unwrap();
    let d = lyap(&heap(&a), &heap(&q)).unwrap();
    assert_eq!(f.x.as_slice(), d.x.as_slice());
    assert_eq!(f.residual, d.residual);
    let fd = plant.discretize(0.002, Discretization::Zoh).unwrap();
    let (ad, bd) = (*fd.a(), *fd.b());
    let qd = bd * bd.transpose();
    let f = dlyap(&ad, &qd).unwrap();
    let d = dlyap(&heap(&ad), &heap(&qd)).unwrap();
    assert_eq!(f.x.as_slice(), d.x.as_slice());
    // Sylvester with different sizes: A 4 × 4, B 1 × 1, C 4 × 1.
    let f = sylvester(&a, &matrix![3.0], &b).unwrap();
    let d = sylvester(&heap(&a), &heap(&matrix![3.0]), &heap(&b)).unwrap();
    assert_eq!(f.x.as_slice(), d.x.as_slice());
    // A Q of the wrong size is an error at run time only.
    assert!(matches!(
        lyap(&heap(&a), &DMatrix::identity(3, 3)),
        Err(Error::DimensionMismatch { matrix: "Q", .. })
    ));
}

#[test]
fn integral_designs_agree_across_sizes() {
    let plant = two_carts();
    let dynamic = DynStateSpace::from(&plant);
    let q = SMatrix::<f64, 5, 5>::from_diagonal(&vector![0.0, 0.0, 1e6, 0.0, 1e8]);
    let r = matrix![1.0];
    let f = lqi(&plant, &q, &r).unwrap();
    let d = lqi(&dynamic, &heap(&q), &heap(&r)).unwrap();
    assert_eq!(f.gain.as_slice(), d.gain.as_slice());
    assert_eq!(f.riccati.as_slice(), d.riccati.as_slice());
    assert_eq!(f.poles.as_slice(), d.poles.as_slice());
    let fd = plant.discretize(0.002, Discretization::Zoh).unwrap();
    let dd = DynStateSpace::from(&fd);
    let f = dlqi(&fd, &q, &r).unwrap();
    let d = dlqi(&dd, &heap(&q), &heap(&r)).unwrap();
    assert_eq!(f.gain.as_slice(), d.gain.as_slice());
    assert_eq!(f.poles.as_slice(), d.poles.as_slice());
    // Q weighs n + p = 5 states.
    assert!(matches!(
        dlqi(&dd, &DMatrix::identity(4, 4), &heap(&r)),
        Err(Error::DimensionMismatch {
            matrix: "Q",
            expected_rows: 5,
            ..
        })
    ));
}

#[test]
fn kalman_filters_agree_across_sizes() {
    let plant = two_carts();
    let dynamic = DynStateSpace::from(&plant);
    let (qn, rn) = (matrix![1.0], matrix![1e-10]);
    let f = lqe(&plant, plant.b(), &qn, &rn).unwrap();
    let d = lqe(&dynamic, dynamic.b(), &heap(&qn), &heap(&rn)).unwrap();
    assert_eq!(f.gain.as_slice(), d.gain.as_slice());
    assert_eq!(f.covariance.as_slice(), d.covariance.as_slice());
    assert_eq!(f.poles.as_slice(), d.poles.as_slice());
    assert!(f.current_gain.is_none() && d.current_gain.is_none());

    let fd = plant.discretize(0.002, Discretization::Zoh).unwrap();
    let dd = DynStateSpace::from(&fd);
    let f = dlqe(&fd, fd.b(), &qn, &rn).unwrap();
    let d = dlqe(&dd, dd.b(), &heap(&qn), &heap(&rn)).unwrap();
    assert_eq!(f.gain.as_slice(), d.gain.as_slice());
    assert_eq!(
        f.current_gain.unwrap().as_slice(),
        d.current_gain.unwrap().as_slice()
    );
    assert!(matches!(
        dlqe(&dd, &DMatrix::zeros(3, 1), &heap(&qn), &heap(&rn)),
        Err(Error::DimensionMismatch { matrix: "G", .. })
    ));
}

#[test]
fn real_target_poles_are_plain_numbers_for_both_sizes() {
    let plant = two_carts();
    let dynamic = DynStateSpace::from(&plant);
    let real = [-5.0, -6.0, -7.0, -8.0];
    let complex = real.map(|re| Complex::new(re, 0.0));
    let k = place(&plant, real).unwrap();
    // The same gain for complex targets, by reference, and for the model
    // sized at run time from an array, a slice and a Vec.
    let by_reference: &[Complex<f64>; 4] = &complex; // as 0.2 took them
    assert_eq!(place(&plant, by_reference).unwrap(), k);
    for gain in [
        place(&dynamic, real).unwrap(),
        place(&dynamic, &real[..]).unwrap(),
        place(&dynamic, real.to_vec()).unwrap(),
        place(&dynamic, by_reference).unwrap(),
    ] {
        assert_eq!(gain.as_slice(), k.as_slice());
    }
    // The closed loop has the targets as poles.
    let closed = StateSpace::continuous(
        plant.a() - plant.b() * k,
        *plant.b(),
        *plant.c(),
        *plant.d(),
    )
    .unwrap()
    .poles()
    .unwrap();
    for (p, want) in closed.iter().zip([-8.0, -7.0, -6.0, -5.0]) {
        assert!((p - Complex::new(want, 0.0)).norm() < 1e-6 * 8.0, "{p}");
    }
    // Ackermann and the observer take the same lists.
    let ka = acker(&plant, real).unwrap();
    assert_eq!(
        acker(&dynamic, real.to_vec()).unwrap().as_slice(),
        ka.as_slice()
    );
    assert!((ka - k).amax() <= 1e-9 * k.amax());
    let l = place_observer(&plant, [-50.0, -60.0, -70.0, -80.0]).unwrap();
    let ld = place_observer(&dynamic, vec![-50.0, -60.0, -70.0, -80.0]).unwrap();
    assert_eq!(ld.as_slice(), l.as_slice());
    // A mixed list: a conjugate pair and two real poles.
    let mixed = [
        Complex::new(-3.0, 4.0),
        Complex::new(-3.0, -4.0),
        Complex::from(-6.0),
        Complex::from(-7.0),
    ];
    assert_eq!(
        place(&dynamic, mixed).unwrap().as_slice(),
        place(&plant, mixed).unwrap().as_slice()
    );
    // The count is the model's: checked when called for a run-time size.
    assert!(matches!(
        place(&dynamic, [-5.0, -6.0]),
        Err(Error::LengthMismatch {
            what: "poles",
            expected: 4,
            found: 2
        })
    ));
}

#[test]
fn responses_agree_across_sizes() {
    let plant = two_carts();
    let dynamic = DynStateSpace::from(&plant);
    let same = |f: &ctrlab::Response<nalgebra::U4, nalgebra::U1>, d: &ctrlab::DynResponse| {
        assert_eq!(f.t, d.t);
        assert_eq!(f.output(0).unwrap(), d.output(0).unwrap());
        for (x, y) in f.x.iter().zip(&d.x) {
            assert_eq!(x.as_slice(), y.as_slice());
        }
    };
    same(
        &step_response(&plant, 1.0, 0.001).unwrap(),
        &step_response(&dynamic, 1.0, 0.001).unwrap(),
    );
    same(
        &impulse_response(&plant, 1.0, 0.001).unwrap(),
        &impulse_response(&dynamic, 1.0, 0.001).unwrap(),
    );
    let x0 = vector![0.001, 0.0, -0.002, 0.1];
    same(
        &initial_response(&plant, 1.0, 0.001, x0).unwrap(),
        &initial_response(
            &dynamic,
            1.0,
            0.001,
            DVector::from_column_slice(x0.as_slice()),
        )
        .unwrap(),
    );
    let t = time_grid(0.5, 0.001).unwrap();
    for solver in [Solver::Zoh, Solver::Rk4 { substeps: 3 }] {
        same(
            &simulate(&plant, &t, x0, |t| vector![(5.0 * t).sin()], solver).unwrap(),
            &simulate(
                &dynamic,
                &t,
                DVector::from_column_slice(x0.as_slice()),
                |t| dvector![(5.0 * t).sin()],
                solver,
            )
            .unwrap(),
        );
    }
    let fd = plant.discretize(0.002, Discretization::Zoh).unwrap();
    let dd = DynStateSpace::from(&fd);
    same(
        &step_response(&fd, 1.0, 0.002).unwrap(),
        &step_response(&dd, 1.0, 0.002).unwrap(),
    );
    let inputs: Vec<_> = (0..200).map(|k| vector![(k as f64 * 0.05).cos()]).collect();
    let dyn_inputs: Vec<_> = inputs.iter().map(|u| dvector![u[0]]).collect();
    same(
        &simulate_discrete(&fd, x0, &inputs).unwrap(),
        &simulate_discrete(&dd, DVector::from_column_slice(x0.as_slice()), &dyn_inputs).unwrap(),
    );
    same(
        &simulate_discrete_feedback(&fd, x0, 300, |_, x| vector![-10.0 * x[2]]).unwrap(),
        &simulate_discrete_feedback(
            &dd,
            DVector::from_column_slice(x0.as_slice()),
            300,
            |_, x| dvector![-10.0 * x[2]],
        )
        .unwrap(),
    );
    // A run-time-sized model with two inputs has no step response: pick one.
    let two_inputs = DynStateSpace::continuous(
        dynamic.a().clone(),
        DMatrix::from_fn(4, 2, |i, _| dynamic.b()[(i, 0)]),
        dynamic.c().clone(),
        DMatrix::zeros(1, 2),
    )
    .unwrap();
    assert!(matches!(
        step_response(&two_inputs, 1.0, 0.01),
        Err(Error::DimensionMismatch { matrix: "B", .. })
    ));
    same(
        &step_response(&plant, 1.0, 0.001).unwrap(),
        &step_response(&two_inputs.select_input(1).unwrap(), 1.0, 0.001).unwrap(),
    );
}

/// The RK4 simulation runs one generic step for both sizes; for a
/// fixed-size model it is, bit for bit, the crate's `Rk4` stepper on the
/// model (what `simulate` ran before).
#[test]
fn rk4_simulation_is_the_rk4_stepper_bit_for_bit() {
    let plant = two_carts();
    let t = time_grid(0.3, 0.001).unwrap();
    let u = |t: f64| vector![(7.0 * t).sin() + 0.5];
    let r = simulate(
        &plant,
        &t,
        SVector4::zeros(),
        u,
        Solver::Rk4 { substeps: 4 },
    )
    .unwrap();
    let mut x = SVector4::zeros();
    for (k, &tk) in t.iter().enumerate() {
        assert_eq!(r.x[k], x, "sample {k}");
        assert_eq!(r.y[k], plant.output(&x, &u(tk)));
        let h = 0.001 / 4.0;
        for s in 0..4 {
            Rk4.step_mut(&plant, tk + s as f64 * h, h, &mut x, &u(tk));
        }
    }
}

type SVector4 = nalgebra::SVector<f64, 4>;

#[test]
fn step_figures_agree_across_sizes() {
    // The carts under position feedback (the lab's gains K = [0, 0, 10/mm, 0.1 s/mm]).
    let plant = two_carts();
    let k = matrix![0.0, 0.0, 10_000.0, 100.0];
    let closed = StateSpace::continuous(
        plant.a() - plant.b() * k,
        plant.b() * 10_000.0,
        *plant.c(),
        *plant.d(),
    )
    .unwrap();
    let options = StepInfoOptions::default();
    let f = step_info_of(&closed, 2.0, 0.0005, &options).unwrap();
    let d = step_info_of(&DynStateSpace::from(&closed), 2.0, 0.0005, &options).unwrap();
    assert_eq!(f, d);
    let fd = closed.discretize(0.002, Discretization::Zoh).unwrap();
    let f = step_info_of(&fd, 2.0, 0.002, &options).unwrap();
    let d = step_info_of(&DynStateSpace::from(&fd), 2.0, 0.002, &options).unwrap();
    assert_eq!(f, d);
    // Every channel of a MIMO model: the same list of lists for both.
    let mimo = StateSpace::continuous(
        matrix![-10.0, 0.0; 0.0, -1.0],
        matrix![10.0, 0.0; 0.0, 1.0],
        matrix![1.0, 0.0; 0.0, 1.0],
        matrix![0.0, 0.0; 0.0, 0.0],
    )
    .unwrap();
    let f = step_info_mimo(&mimo, 10.0, 0.001, &options).unwrap();
    let d = step_info_mimo(&DynStateSpace::from(&mimo), 10.0, 0.001, &options).unwrap();
    assert_eq!(f, d);
    assert_eq!((f.len(), f[0].len()), (2, 2));
    // step_info_of of a run-time-sized MIMO model is an error, not a panic.
    assert!(matches!(
        step_info_of(&DynStateSpace::from(&mimo), 10.0, 0.001, &options),
        Err(Error::DimensionMismatch { matrix: "B", .. })
    ));
}

#[test]
fn margins_and_bandwidth_of_every_model_type_are_those_of_its_transfer_function() {
    let plant = two_carts();
    // A proportional loop, 2000 N/m on cart 2's position, as each type.
    let loop_ss =
        StateSpace::continuous(*plant.a(), *plant.b(), plant.c() * 2000.0, *plant.d()).unwrap();
    let tf = TransferFunction::try_from(&loop_ss).unwrap();
    let want = stability_margins(&tf).unwrap();
    assert!(want.phase.is_some() || want.gain.is_some());
    let dynamic = DynStateSpace::from(&loop_ss);
    assert_eq!(stability_margins(&loop_ss).unwrap(), want);
    assert_eq!(stability_margins(&dynamic).unwrap(), want);
    assert_eq!(
        stability_margins(&TransferFunction::try_from(&dynamic).unwrap()).unwrap(),
        want
    );
    let zpk = Zpk::try_from(&loop_ss).unwrap();
    assert_eq!(
        stability_margins(&zpk).unwrap(),
        stability_margins(&zpk.to_transfer_function().unwrap()).unwrap()
    );
    let matrix_1x1 = TransferMatrix::new(vec![vec![tf.clone()]]).unwrap();
    assert_eq!(stability_margins(&matrix_1x1).unwrap(), want);

    // Discrete: the ZOH loop.
    let d = loop_ss.discretize(0.002, Discretization::Zoh).unwrap();
    let want = stability_margins(&TransferFunction::try_from(&d).unwrap()).unwrap();
    assert_eq!(stability_margins(&d).unwrap(), want);
    assert_eq!(stability_margins(&DynStateSpace::from(&d)).unwrap(), want);

    // Bandwidth of the plant itself.
    let g = TransferFunction::try_from(&plant).unwrap();
    let want = bandwidth(&g, -3.0).unwrap();
    assert_eq!(bandwidth(&plant, -3.0).unwrap(), want);
    assert_eq!(bandwidth(&DynStateSpace::from(&plant), -3.0).unwrap(), want);
    assert_eq!(bandwidth(&Zpk::try_from(&plant).unwrap(), -3.0).unwrap(), {
        bandwidth(
            &Zpk::try_from(&plant)
                .unwrap()
                .to_transfer_function()
                .unwrap(),
            -3.0,
        )
        .unwrap()
    });

    // Two outputs: a clear error, for every way of asking.
    let two_outputs = plant
        .with_output(
            matrix![1.0, 0.0, 0.0, 0.0; 0.0, 0.0, 1.0, 0.0],
            matrix![0.0; 0.0],
        )
        .unwrap();
    let not_siso = |e: Error| {
        matches!(
            e,
            Error::DimensionMismatch {
                matrix: "D",
                expected_rows: 1,
                expected_cols: 1,
                found_rows: 2,
                found_cols: 1
            }
        )
    };
    assert!(not_siso(stability_margins(&two_outputs).unwrap_err()));
    assert!(not_siso(
        stability_margins(&DynStateSpace::from(&two_outputs)).unwrap_err()
    ));
    assert!(not_siso(bandwidth(&two_outputs, -3.0).unwrap_err()));
    let tm = TransferMatrix::try_from(&two_outputs).unwrap();
    assert!(not_siso(stability_margins(&tm).unwrap_err()));
}

#[test]
fn poles_print_as_pairs_and_real_numbers() {
    let plant = two_carts();
    let poles = plant.poles().unwrap();
    let text = Poles(&poles).to_string();
    // Two lightly damped pairs, each printed once.
    assert_eq!(text.matches('±').count(), 2, "{text}");
    assert_eq!(text.matches(", ").count(), 1, "{text}");
    assert_eq!(
        Poles(&[Complex::new(-9.997499218261337, 0.0)]).to_string(),
        "-9.9975"
    );
    assert_eq!(
        format!(
            "{:.2}",
            Poles(&[Complex::new(-3.7123, 22.2), Complex::new(-3.7123, -22.2)])
        ),
        "-3.71 ± 22.20j"
    );
    assert_eq!(format!("{:#}", Poles(&[Complex::new(-0.1, 0.0)])), "-0.1");
    assert_eq!(Poles(&[]).to_string(), "");
}

#[test]
fn regulators_print_their_gain_and_poles() {
    let sys =
        StateSpace::continuous(matrix![1.0], matrix![1.0], matrix![1.0], matrix![0.0]).unwrap();
    let sol = lqr(&sys, &matrix![1.0], &matrix![1.0]).unwrap();
    // K = 1 + √2, the closed-loop pole −√2.
    assert_eq!(sol.to_string(), "K =\n  2.4142\npoles = -1.4142\n");
    assert_eq!(format!("{sol:.1}"), "K =\n  2.4\npoles = -1.4\n");
    let dynamic = lqr(
        &DynStateSpace::from(&sys),
        &DMatrix::identity(1, 1),
        &DMatrix::identity(1, 1),
    )
    .unwrap();
    assert_eq!(dynamic.to_string(), sol.to_string());
}

#[test]
fn models_print_five_significant_digits_unless_told_otherwise() {
    let lag =
        StateSpace::continuous(matrix![-1.0], matrix![1.0], matrix![1.0], matrix![0.0]).unwrap();
    let d = lag.discretize(0.002, Discretization::Zoh).unwrap();
    let header = "x[k+1] = A x[k] + B u[k], y[k] = C x[k] + D u[k], dt = 0.002 s\n";
    assert_eq!(
        d.to_string(),
        format!("{header}A =\n  0.998\nB =\n  0.001998\nC =\n  1\nD =\n  0\n")
    );
    assert_eq!(
        format!("{d:.4}"),
        format!("{header}A =\n  0.9980\nB =\n  0.0020\nC =\n  1.0000\nD =\n  0.0000\n")
    );
    // `{:#}`: every digit, read back to the same bits.
    let exact = format!("{d:#}");
    let a: f64 = exact.lines().nth(2).unwrap().trim().parse().unwrap();
    assert_eq!(a.to_bits(), d.a()[(0, 0)].to_bits());
    // Tiny and huge entries in scientific notation, zeros as 0.
    let wide = StateSpace::continuous(
        matrix![-1.0e-7, 0.0; 0.0, -123456.7],
        matrix![1.0; 0.0],
        matrix![1.0, 1.0],
        matrix![0.0],
    )
    .unwrap();
    assert_eq!(
        wide.to_string(),
        "x' = A x + B u, y = C x + D u\nA =\n      -1e-7          0\n          0  -1.2346e5\nB =\n  1\n  0\nC =\n  1  1\nD =\n  0\n"
    );
    // The run-time-sized model prints the same text.
    let dynamic = DynStateSpace::from(&d);
    assert_eq!(dynamic.to_string(), d.to_string());
    assert_eq!(format!("{dynamic:.4}"), format!("{d:.4}"));
    assert_eq!(format!("{dynamic:#}"), exact);
}

#[test]
fn step_figures_print_with_units() {
    let lag =
        StateSpace::continuous(matrix![-10.0], matrix![10.0], matrix![1.0], matrix![0.0]).unwrap();
    let info = step_info_of(&lag, 2.0, 0.001, &StepInfoOptions::default()).unwrap();
    let text = info.to_string();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 9, "{text}");
    assert!(
        lines[0].starts_with("rise time           0.2197") && lines[0].ends_with(" s"),
        "{text}"
    );
    assert!(
        lines[3].starts_with("overshoot") && lines[3].ends_with(" %"),
        "{text}"
    );
    assert_eq!(lines[8], "steady-state value  1");
    let with_reference = step_info_of(
        &lag,
        2.0,
        0.001,
        &StepInfoOptions {
            reference: Some(1.5),
            ..Default::default()
        },
    )
    .unwrap();
    assert!(
        with_reference
            .to_string()
            .ends_with("steady-state error  0.5\n")
    );
}
