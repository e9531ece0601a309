//! Issue 11's reproducers, one test each (numbered as in the issue): bad
//! input never panics, hangs, or comes back as a non-finite number inside
//! `Ok`, and answers do not depend on the units a model is written in.

// Built on the two-cart lab (its plant, simulated rig or card).
#![cfg(feature = "lab")]

use ctrlab::data::CsvError;
use ctrlab::design::{acker, lqr};
use ctrlab::discretize::expm;
use ctrlab::hw::{Clock, Pc104, PortErrorKind, SimulatedCard, SimulatedCardConfig, VirtualClock};
use ctrlab::ident::{LeastSquares, Rls};
use ctrlab::lab::SimulatedRig;
use ctrlab::lab::ident::{Scheme, Spread, identify};
use ctrlab::metrics::SettleFailure;
use ctrlab::sim::{Solver, simulate, step_response, time_grid};
use ctrlab::{Error, MassSpring, Recording, StateSpace, StepInfoOptions, step_info, step_info_of};
use nalgebra::{Complex, SMatrix, SVector, matrix, vector};

/// The CSV of reproducer 1: positions near f64::MAX / 2, accepted by the
/// reader.
const HUGE_CSV: &str = "t_s,u,x1_m,x2_m\n\
    0,1,-8e307,6.4e307\n\
    1,1,0,-4e307\n\
    2,1,-4e307,8e307\n\
    3,1,-8e307,0\n\
    4,1,-6.4e307,-4e307\n\
    5,0,4e307,6.4e307\n";

fn all_finite(v: &[f64]) -> bool {
    v.iter().all(|v| v.is_finite())
}

// 1. Least squares with a column whose norm overflows.

#[test]
fn least_squares_with_an_overflowing_column_norm_solves() {
    let mut ls = LeastSquares::new(2);
    ls.push_columns(&[&[1e308; 3], &[1.0, 2.0, 3.0]], &[0.0, 1.0, 2.0])
        .unwrap();
    // λ = θ₀ 1e308 + θ₁ k exactly for θ = [−1e−308, 1].
    let fit = ls.solve().unwrap();
    assert!((fit.theta[1] - 1.0).abs() < 1e-12, "{:?}", fit.theta);
    assert!(
        (fit.theta[0] * 1e308 + 1.0).abs() < 1e-12,
        "{:?}",
        fit.theta
    );
    assert!(all_finite(fit.std_errors.as_slice()));
    assert!(all_finite(fit.covariance.as_slice()));
    assert!(fit.residual_rms.is_finite() && fit.r_squared.is_finite());
}

#[test]
fn identify_on_a_csv_of_huge_positions_is_an_error_or_finite() {
    let rec = Recording::from_reader(HUGE_CSV.as_bytes()).unwrap();
    for scheme in [Scheme::Lab, Scheme::Central] {
        match identify(&rec, 1.3, 0.7, scheme) {
            Ok(est) => {
                for e in [est.k12().unwrap(), est.b1, est.gain, est.b2] {
                    assert!(e.value.is_finite() && e.std_error.is_finite(), "{est:?}");
                }
            }
            // The second differences of positions near f64::MAX overflow
            // while the regressor is formed, and the solver names the entry.
            Err(e) => assert!(
                matches!(
                    e,
                    Error::Overflow { .. }
                        | Error::NonFinite {
                            matrix: "regressor",
                            ..
                        }
                ),
                "{e}"
            ),
        }
    }
}

// 2. Response::output out of range.

#[test]
fn response_output_out_of_range_is_an_error() {
    let sys = MassSpring::nominal()
        .state_space(ctrlab::Cart::Two)
        .unwrap();
    let r = step_response(&sys, 0.1, 0.01).unwrap();
    assert_eq!(r.output(0).unwrap().len(), r.len());
    assert_eq!(
        r.output(1).unwrap_err(),
        Error::OutOfRange {
            what: "output",
            index: 1,
            len: 1
        }
    );
}

// 3. RK4 with an absurd number of sub-steps.

#[test]
fn rk4_substeps_are_bounded() {
    let sys =
        StateSpace::continuous(matrix![-1.0], matrix![1.0], matrix![1.0], matrix![0.0]).unwrap();
    let err = simulate(
        &sys,
        &[0.0, 1.0],
        vector![0.0],
        |_| vector![1.0],
        Solver::Rk4 { substeps: 1 << 40 },
    )
    .unwrap_err();
    assert!(
        matches!(
            err,
            Error::InvalidParameter {
                name: "substeps",
                ..
            }
        ),
        "{err}"
    );
}

// 4. Plots of ranges whose padding overflows.

#[cfg(feature = "plot")]
#[test]
fn plots_of_huge_ranges_finish() {
    use ctrlab::plot::{Series, responses_svg};
    let dir = std::env::temp_dir();
    let drawable: [(&[f64], &[f64]); 6] = [
        (&[0.0, 1.0], &[0.0, f64::MAX]),
        (&[0.0, 1.0], &[-f64::MAX, -f64::MAX / 2.0]),
        (&[0.0, 1.0], &[1.0, 1.0 + 1e-15]),
        (&[0.0, 1.0], &[1e300, 1e300]),
        (&[1e300, 1e300], &[0.0, 1.0]),
        (&[0.0, 1.0], &[0.0, 1e-320]),
    ];
    for (k, (t, y)) in drawable.iter().enumerate() {
        let path = dir.join(format!("ctrlab_robustness_plot_{k}.svg"));
        responses_svg(&path, "huge", "t", "y", &[Series::new("s", t, y)]).unwrap();
        let svg = std::fs::read_to_string(&path).unwrap();
        assert!(svg.contains("<svg") && !svg.contains("NaN"), "case {k}");
        std::fs::remove_file(&path).ok();
    }
    // No axis can span −1e308 … 1e308: an error, not a hang.
    let path = dir.join("ctrlab_robustness_plot_wide.svg");
    for (t, y) in [
        (&[0.0, 1.0][..], &[-1e308, 1e308][..]),
        (&[-1e308, 1e308][..], &[0.0, 1.0][..]),
    ] {
        let err = responses_svg(&path, "wide", "t", "y", &[Series::new("s", t, y)]).unwrap_err();
        assert!(
            matches!(
                err,
                ctrlab::plot::PlotError::Data(Error::InvalidData { .. })
            ),
            "{err}"
        );
    }
}

// 5. The virtual clock and the simulated card after a long jump.

#[test]
fn the_virtual_clock_never_runs_backwards() {
    let clock = VirtualClock::new();
    clock.advance(1.0).unwrap();
    // u64::MAX ns is 1.8e10 s: a jump past it is refused, time unchanged.
    clock.advance(1e10).unwrap();
    let err = clock.advance(1e10).unwrap_err();
    assert_eq!(err.kind(), PortErrorKind::InvalidCommand);
    assert_eq!(clock.now_nanos(), 10_000_000_001_000_000_000);
    clock.advance_nanos(u64::MAX);
    assert_eq!(clock.now_nanos(), u64::MAX);
    clock.advance_nanos(5);
    assert_eq!(clock.now_nanos(), u64::MAX);
}

#[test]
fn the_simulated_card_bounds_its_work_after_a_long_jump() {
    let clock = VirtualClock::new();
    let mut pc104 = Pc104::new(
        SimulatedRig::default()
            .card(&Clock::Virtual(clock.clone()))
            .unwrap(),
    );
    pc104.latch().unwrap();
    // 1e6 s at 0.25 ms would be 4e9 RK4 steps for one register read.
    clock.advance(1e6).unwrap();
    let err = pc104.latch().unwrap_err();
    assert_eq!(err.kind(), PortErrorKind::Simulation);
    assert!(err.to_string().contains("RK4 sub-steps"), "{err}");
    assert_eq!(pc104.port().time(), 0.0);
    // Within the bound, the card catches up.
    let clock = VirtualClock::new();
    let mut pc104 = Pc104::new(
        SimulatedRig::default()
            .card(&Clock::Virtual(clock.clone()))
            .unwrap(),
    );
    clock.advance(100.0).unwrap();
    pc104.latch().unwrap();
    assert_eq!(pc104.port().time(), 100.0);
}

#[test]
fn a_diverging_simulated_plant_is_an_error_not_zero_counts() {
    let blow_up = |_t: f64, x: &SVector<f64, 1>, _u: &SVector<f64, 1>| vector![x[0] * x[0]];
    let config = SimulatedCardConfig::<1> {
        encoders: [Some(0), None, None, None],
        initial_state: vector![1.0],
        ..Default::default()
    };
    let clock = VirtualClock::new();
    let mut pc104 =
        Pc104::new(SimulatedCard::new(blow_up, config, Clock::Virtual(clock.clone())).unwrap());
    // x' = x² from 1 blows up at t = 1 s.
    clock.advance(2.0).unwrap();
    let err = pc104.latch().unwrap_err();
    assert_eq!(err.kind(), PortErrorKind::Simulation);
    assert!(err.to_string().contains("diverged"), "{err}");
    assert_eq!(pc104.port().time(), 0.0);
    assert!(pc104.port().true_state()[0].is_finite());
}

// 6. Non-finite numbers inside Ok.

#[test]
fn static_deflection_that_overflows_is_an_error() {
    let plant = MassSpring {
        k1: 1e-320,
        ..MassSpring::nominal()
    };
    assert!(matches!(
        plant.static_deflection(1.0),
        Err(Error::Overflow { .. })
    ));
}

#[test]
fn simulation_of_a_diverging_plant_is_an_error() {
    let sys =
        StateSpace::continuous(matrix![50.0], matrix![1.0], matrix![1.0], matrix![0.0]).unwrap();
    let t = time_grid(100.0, 0.01).unwrap();
    for solver in [Solver::Zoh, Solver::Rk4 { substeps: 1 }] {
        let err = simulate(&sys, &t, vector![1.0], |_| vector![0.0], solver).unwrap_err();
        assert!(matches!(err, Error::Overflow { .. }), "{err}");
    }
    // Only the output overflows (the states stay within 1); only one of two
    // states diverges, and the output is the other one.
    let output_only = StateSpace::continuous(
        matrix![-1.0],
        matrix![1.0],
        matrix![f64::MAX],
        matrix![f64::MAX],
    )
    .unwrap();
    let err = simulate(
        &output_only,
        &t,
        vector![0.0],
        |_| vector![1.0],
        Solver::Zoh,
    )
    .unwrap_err();
    assert!(matches!(err, Error::Overflow { .. }), "{err}");
    let one_of_two = StateSpace::continuous(
        matrix![50.0, 0.0; 0.0, -1.0],
        matrix![1.0; 1.0],
        matrix![0.0, 1.0],
        matrix![0.0],
    )
    .unwrap();
    let err = simulate(
        &one_of_two,
        &t,
        vector![0.0, 0.0],
        |_| vector![1.0],
        Solver::Zoh,
    )
    .unwrap_err();
    assert!(matches!(err, Error::Overflow { .. }), "{err}");
}

#[test]
fn step_info_overshoot_that_overflows_is_an_error() {
    let err = step_info(
        &[0.0, 1.0, 2.0],
        &[0.0, 1e300, 1e-9],
        &StepInfoOptions::default(),
    )
    .unwrap_err();
    assert!(matches!(err, Error::Overflow { .. }), "{err}");
}

#[test]
fn least_squares_with_tiny_columns_has_finite_statistics() {
    let x = [1.0, 2.0, 3.0, 4.0];
    let y = [1.1, 1.9, 3.2, 3.9];
    let mut reference = LeastSquares::new(2);
    reference.push_columns(&[&[1.0; 4], &x], &y).unwrap();
    let reference = reference.solve().unwrap();
    let rel = |a: f64, b: f64| (a / b - 1.0).abs();
    for scale in [1e-100, 1e100, 1e-150] {
        let column: Vec<f64> = x.iter().map(|v| v * scale).collect();
        let mut ls = LeastSquares::new(2);
        ls.push_columns(&[&[scale; 4], &column], &y).unwrap();
        let fit = ls.solve().unwrap();
        assert!(fit.r_squared < 1.0);
        assert!((fit.r_squared - reference.r_squared).abs() < 1e-12);
        for j in 0..2 {
            assert!(rel(fit.theta[j] * scale, reference.theta[j]) < 1e-12);
            assert!(rel(fit.std_errors[j] * scale, reference.std_errors[j]) < 1e-12);
        }
    }
    // With columns of 1e-200, θ and its standard errors (about 1e200) are
    // representable but their covariance (1e400) is not: an error, not NaN.
    let column: Vec<f64> = x.iter().map(|v| v * 1e-200).collect();
    let mut ls = LeastSquares::new(2);
    ls.push_columns(&[&[1e-200; 4], &column], &y).unwrap();
    assert!(matches!(ls.solve(), Err(Error::Overflow { .. })));
}

#[test]
fn least_squares_with_a_huge_right_hand_side_is_finite_or_an_error() {
    let mut ls = LeastSquares::new(1);
    ls.push_columns(&[&[1.0, 1.0, 1.0]], &[1e150, 1e150, -1e150])
        .unwrap();
    let fit = ls.solve().unwrap();
    assert!((fit.theta[0] / (1e150 / 3.0) - 1.0).abs() < 1e-14);
    assert!(fit.std_errors[0].is_finite() && fit.r_squared.is_finite());
    // At 1e300 the estimate is representable, its variance (1e600) not.
    let mut ls = LeastSquares::new(1);
    ls.push_columns(&[&[1.0, 1.0, 1.0]], &[1e300, 1e300, -1e300])
        .unwrap();
    assert!(matches!(ls.solve(), Err(Error::Overflow { .. })));
    // θ itself cannot be represented: say so.
    let mut ls = LeastSquares::new(1);
    ls.push_columns(&[&[1e-10, 1e-10, 1e-10]], &[1e308, 1e308, 1e308])
        .unwrap();
    assert!(matches!(ls.solve(), Err(Error::Overflow { .. })));
}

#[test]
fn rls_learns_from_huge_regressors() {
    let mut rls = Rls::<1>::new(1.0, 1e6).unwrap();
    for _ in 0..5 {
        rls.update(&vector![1e200], 1e200).unwrap();
    }
    assert!((rls.theta()[0] - 1.0).abs() < 1e-9, "{}", rls.theta()[0]);
    assert!(rls.covariance()[(0, 0)].is_finite());
}

#[test]
fn spread_is_finite_or_an_error() {
    let s = Spread::of(&[1e308, 1e308]).unwrap();
    assert_eq!((s.mean, s.std_dev), (1e308, 0.0));
    let s = Spread::of(&[f64::MAX, -f64::MAX, 0.0]).unwrap();
    assert_eq!(s.mean, 0.0);
    assert!((s.std_dev / f64::MAX - 1.0).abs() < 1e-15);
    assert!(matches!(
        Spread::of(&[f64::NAN, 1.0]),
        Err(Error::InvalidData { index: 0, .. })
    ));
    assert!(matches!(
        Spread::of(&[f64::MAX, -f64::MAX]),
        Err(Error::Overflow { .. })
    ));
}

// 7. Answers that depend on the model's scale.

#[test]
fn stability_does_not_depend_on_scale() {
    let sys = StateSpace::continuous(
        matrix![-1e-3, 0.0; 0.0, -1e12],
        matrix![1.0; 1.0],
        matrix![1.0, 0.0],
        matrix![0.0],
    )
    .unwrap();
    assert!(sys.is_stable().unwrap());
    assert_eq!(sys.unstable_pole().unwrap(), None);
    // Its step metrics are no longer refused as unstable; a 1 s step is
    // 10¹² times the fast time constant, which the ZOH says it cannot
    // compute to 1e-8 (the slow mode would come out 2e-5 off).
    match step_info_of(&sys, 20_000.0, 1.0, &StepInfoOptions::default()) {
        Ok(info) => assert!((info.rise_time - 1000.0 * 9f64.ln()).abs() < 1.0),
        Err(e) => assert!(matches!(e, Error::IllConditioned { .. }), "{e}"),
    }
    // Scaled so that the step is not stiff: the slow lag's figures.
    let mild = StateSpace::continuous(
        matrix![-1e-3, 0.0; 0.0, -1e3],
        matrix![1.0; 1.0],
        matrix![1.0, 0.0],
        matrix![0.0],
    )
    .unwrap();
    assert!(mild.is_stable().unwrap());
    let info = step_info_of(&mild, 20_000.0, 1.0, &StepInfoOptions::default()).unwrap();
    assert!((info.rise_time - 1000.0 * 9f64.ln()).abs() < 1.0);
    // A genuine rigid-body mode computed from physical parameters is still
    // on the boundary.
    let mut free = MassSpring::nominal();
    free.k1 = 0.0;
    assert!(
        !free
            .state_space(ctrlab::Cart::Two)
            .unwrap()
            .is_stable()
            .unwrap()
    );
}

#[test]
fn dc_gain_does_not_depend_on_scale() {
    let sys = StateSpace::continuous(
        matrix![-1.0, 0.0; 0.0, -1e12],
        matrix![1.0; 1.0],
        matrix![1.0, 0.0],
        matrix![0.0],
    )
    .unwrap();
    assert_eq!(sys.dc_gain().unwrap(), matrix![1.0]);
}

#[test]
fn controllability_does_not_depend_on_scale() {
    let c = 1e6;
    let a = matrix![
        0.0, c, 0.0, 0.0;
        0.0, 0.0, c, 0.0;
        0.0, 0.0, 0.0, c;
        0.0, 0.0, 0.0, 0.0
    ];
    let sys = StateSpace::continuous(
        a,
        matrix![0.0; 0.0; 0.0; 1.0],
        matrix![1.0, 0.0, 0.0, 0.0],
        matrix![0.0],
    )
    .unwrap();
    assert!(sys.is_controllable().unwrap());
    assert!(sys.is_observable().unwrap());
    // Still: B in an invariant subspace is not controllable at any scale.
    let sys = StateSpace::continuous(
        matrix![-1e6, 0.0; 0.0, -2e6],
        matrix![1e-6; 0.0],
        matrix![1.0, 1.0],
        matrix![0.0],
    )
    .unwrap();
    assert!(!sys.is_controllable().unwrap());
}

#[test]
fn acker_refuses_gains_that_miss_their_poles() {
    let a = SMatrix::<f64, 8, 8>::from_diagonal(&nalgebra::SVector::from_fn(|i, _| {
        3.0 * (i + 1) as f64
    }));
    let sys = StateSpace::continuous(
        a,
        SMatrix::<f64, 8, 1>::repeat(1.0),
        SMatrix::<f64, 1, 8>::repeat(1.0),
        matrix![0.0],
    )
    .unwrap();
    let targets: [Complex<f64>; 8] =
        std::array::from_fn(|i| Complex::new(-3.0 * (i + 1) as f64, 0.0));
    match acker(&sys, targets) {
        Ok(k) => {
            // Any gain returned places the poles.
            let cl =
                StateSpace::continuous(a - sys.b() * k, *sys.b(), *sys.c(), matrix![0.0]).unwrap();
            let mut p = cl.poles().unwrap();
            p.sort_by(|x, y| y.re.total_cmp(&x.re));
            for (p, t) in p.iter().zip(targets.iter()) {
                assert!((p - t).norm() < 1e-3 * t.norm(), "{p} vs {t}");
            }
        }
        Err(e) => assert!(matches!(e, Error::IllConditioned { .. }), "{e}"),
    }
}

#[test]
fn lqr_accepts_huge_weights() {
    let sys = StateSpace::continuous(
        matrix![0.0, 1.0; 0.0, 0.0],
        matrix![0.0, 0.0; 1.0, 1.0],
        matrix![1.0, 0.0],
        matrix![0.0, 0.0],
    )
    .unwrap();
    let q = matrix![1e308, 0.0; 0.0, 1e308];
    let r = matrix![1e308, 0.0; 0.0, 1e308];
    let scaled = lqr(&sys, &q, &r).unwrap();
    let unit = lqr(
        &sys,
        &matrix![1.0, 0.0; 0.0, 1.0],
        &matrix![1.0, 0.0; 0.0, 1.0],
    )
    .unwrap();
    assert!((scaled.gain - unit.gain).norm() < 1e-9 * unit.gain.norm());
}

#[test]
fn expm_of_a_fast_rotation_is_accurate_or_refused() {
    for theta in [1e3, 1e15, 1e300] {
        let a = matrix![0.0, -theta; theta, 0.0];
        match expm(&a) {
            Ok(e) => {
                // Orthogonal, and the rotation by θ.
                let orth = (e.transpose() * e - SMatrix::<f64, 2, 2>::identity()).norm();
                assert!(orth < 1e-9, "θ = {theta}: ‖EᵀE − I‖ = {orth}");
                assert!((e[(1, 0)] - theta.sin()).abs() < 1e-9, "θ = {theta}");
            }
            Err(e) => {
                assert!(theta > 1e10, "θ = {theta}: {e}");
                assert!(matches!(e, Error::IllConditioned { .. }), "{e}");
            }
        }
    }
}

// 8. Errors that say what is wrong.

#[test]
fn acker_names_the_unpaired_pole() {
    let sys = StateSpace::continuous(
        matrix![0.0, 1.0; 0.0, 0.0],
        matrix![0.0; 1.0],
        matrix![1.0, 0.0],
        matrix![0.0],
    )
    .unwrap();
    let err = acker(&sys, [Complex::new(-2.0, 1.0), Complex::new(-3.0, 0.0)]).unwrap_err();
    assert!(
        matches!(
            err,
            Error::InvalidPole {
                index: 0,
                re: -2.0,
                im: 1.0,
                ..
            }
        ),
        "{err}"
    );
    assert!(err.to_string().contains("-2 + 1i"), "{err}");
}

fn not_settled(t: &[f64], y: &[f64]) -> (SettleFailure, String) {
    match step_info(t, y, &StepInfoOptions::default()) {
        Err(e @ Error::NotSettled { cause, .. }) => (cause, e.to_string()),
        other => panic!("{other:?}"),
    }
}

#[test]
fn not_settled_says_why() {
    let t: Vec<f64> = (0..=4000).map(|k| k as f64 * 0.001).collect();
    // Still converging: τ = 2 s over a 4 s record.
    let slow: Vec<f64> = t.iter().map(|t| 1.0 - (-t / 2.0).exp()).collect();
    let (cause, msg) = not_settled(&t, &slow);
    assert_eq!(cause, SettleFailure::TooShort, "{msg}");
    assert!(msg.contains("longer"), "{msg}");
    // Growing without bound.
    let growing: Vec<f64> = t.iter().map(|t| (3.0 * t).exp() - 1.0).collect();
    assert_eq!(not_settled(&t, &growing).0, SettleFailure::Diverging);
    let ramp = t.clone();
    assert_eq!(not_settled(&t, &ramp).0, SettleFailure::Diverging);
    // An undamped oscillation about 1, and one that grows.
    let ringing: Vec<f64> = t.iter().map(|t| 1.0 - (60.0 * t).cos()).collect();
    let (cause, msg) = not_settled(&t, &ringing);
    assert_eq!(cause, SettleFailure::Oscillating, "{msg}");
    let growing_ringing: Vec<f64> = t
        .iter()
        .map(|t| 1.0 - (t / 0.02).exp() * (60.0 * t).cos())
        .collect();
    assert_eq!(
        not_settled(&t, &growing_ringing).0,
        SettleFailure::Diverging
    );
    // No float noise in the times printed (0.475, not 0.47500000000000003).
    let t: Vec<f64> = (0..=20).map(|k| k as f64 * 0.025).collect();
    let y: Vec<f64> = t.iter().map(|t| 1.0 - (-t / 0.2).exp()).collect();
    let (_, msg) = not_settled(&t, &y);
    assert!(msg.contains("t = 0.475 s"), "{msg}");
}

#[test]
fn csv_errors_show_what_they_found() {
    let err = Recording::from_reader("time_ms_x,u,x1_m\n0,1,2\n1,1,2\n".as_bytes()).unwrap_err();
    assert!(err.to_string().contains("time_ms_x,u,x1_m"), "{err}");
    // A header after blank lines is reported on its own line.
    let err = Recording::from_reader("\n\nx,u\n0,1\n1,1\n".as_bytes()).unwrap_err();
    assert!(matches!(err, CsvError::Line { line: 3, .. }), "{err}");
    let err = Recording::from_reader("\n\nt_s,u\n0,1\n0,1\n".as_bytes()).unwrap_err();
    assert!(matches!(err, CsvError::Line { line: 5, .. }), "{err}");
}

#[test]
fn masses_in_grams_are_flagged() {
    let rec = Recording::read_csv(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/ident_square_wave.csv"
    ))
    .unwrap();
    let in_kg = identify(&rec, 1.3, 0.7, Scheme::Central).unwrap();
    assert!(in_kg.warnings().is_empty());
    let in_grams = identify(&rec, 1300.0, 700.0, Scheme::Central).unwrap();
    let warnings = in_grams.warnings();
    assert_eq!(warnings.len(), 2, "{warnings:?}");
    assert_eq!(warnings[0].parameter, "m1");
    assert!(warnings[0].to_string().contains("grams"), "{}", warnings[0]);
}

// 9. A uniform grid computed as k·dt is one discretisation.

#[test]
fn step_response_on_a_long_grid_matches_the_discrete_model() {
    let sys = MassSpring::nominal()
        .state_space(ctrlab::Cart::Two)
        .unwrap();
    let (t_end, dt) = (20.0, 0.0005);
    let r = step_response(&sys, t_end, dt).unwrap();
    assert_eq!(r.len(), 40_001);
    let d = sys.discretize(dt, ctrlab::Discretization::Zoh).unwrap();
    let disc = ctrlab::sim::simulate_discrete(
        &d,
        nalgebra::SVector::zeros(),
        &vec![vector![1.0]; r.len()],
    )
    .unwrap();
    let worst =
        r.y.iter()
            .zip(&disc.y)
            .map(|(a, b)| (a - b).norm())
            .fold(0.0, f64::max);
    assert!(worst < 1e-15, "{worst}");
}

// 6 (continued). The discrete simulators refuse what they cannot answer.

#[test]
fn discrete_simulation_is_finite_or_an_error() {
    let d =
        StateSpace::discrete(matrix![2.0], matrix![1.0], matrix![1.0], matrix![0.0], 0.1).unwrap();
    // x doubles every sample: 1e300 · 2^k passes f64::MAX within 30 samples.
    let err = ctrlab::sim::simulate_discrete(&d, vector![1e300], &[vector![0.0]; 40]).unwrap_err();
    assert!(matches!(err, Error::Overflow { .. }), "{err}");
    let err =
        ctrlab::sim::simulate_discrete(&d, vector![f64::NAN], &[vector![0.0]; 2]).unwrap_err();
    assert!(
        matches!(err, Error::InvalidParameter { name: "x0", .. }),
        "{err}"
    );
    let err =
        ctrlab::sim::simulate_discrete(&d, vector![0.0], &[vector![f64::INFINITY]]).unwrap_err();
    assert!(
        matches!(err, Error::InvalidParameter { name: "input", .. }),
        "{err}"
    );
    // The input is blamed also where it does not reach a state (B = 0:
    // ∞ · 0 is NaN) and in a model without states (only D).
    let unreached =
        StateSpace::discrete(matrix![0.5], matrix![0.0], matrix![1.0], matrix![1.0], 0.1).unwrap();
    let err = ctrlab::sim::simulate_discrete(&unreached, vector![0.0], &[vector![f64::INFINITY]])
        .unwrap_err();
    assert!(
        matches!(err, Error::InvalidParameter { name: "input", .. }),
        "{err}"
    );
    let gain = StateSpace::<0, 1, 1, _>::discrete(
        nalgebra::SMatrix::zeros(),
        nalgebra::SMatrix::zeros(),
        nalgebra::SMatrix::zeros(),
        matrix![2.0],
        0.1,
    )
    .unwrap();
    let err = ctrlab::sim::simulate_discrete(
        &gain,
        nalgebra::SVector::zeros(),
        &[vector![1.0], vector![f64::NAN]],
    )
    .unwrap_err();
    assert!(
        matches!(err, Error::InvalidParameter { name: "input", .. }),
        "{err}"
    );
    // A period so long that the third sample's time overflows.
    let eons = StateSpace::discrete(
        matrix![0.5],
        matrix![1.0],
        matrix![1.0],
        matrix![0.0],
        1e308,
    )
    .unwrap();
    assert_eq!(
        ctrlab::sim::simulate_discrete(&eons, vector![0.0], &[vector![0.0]; 2])
            .unwrap()
            .t[1],
        1e308
    );
    let err = ctrlab::sim::simulate_discrete(&eons, vector![0.0], &[vector![0.0]; 3]).unwrap_err();
    assert!(
        matches!(err, Error::InvalidParameter { name: "dt", .. }),
        "{err}"
    );
    // Only the output overflows, at the fourth sample (x = 1.5).
    let output_only = StateSpace::discrete(
        matrix![1.0],
        matrix![0.5],
        matrix![f64::MAX],
        matrix![0.0],
        0.1,
    )
    .unwrap();
    let err =
        ctrlab::sim::simulate_discrete(&output_only, vector![0.0], &[vector![1.0]; 4]).unwrap_err();
    assert!(matches!(err, Error::Overflow { .. }), "{err}");
    let err =
        ctrlab::sim::simulate_discrete_feedback(&d, vector![0.0], usize::MAX, |_, _| vector![0.0])
            .unwrap_err();
    assert!(
        matches!(err, Error::InvalidParameter { name: "steps", .. }),
        "{err}"
    );
}

/// Found by `proptest_api::simulation`: `round(t_end / dt)` rounds up, so a
/// `t_end` near f64::MAX put the grid's last time at +∞ inside `Ok`.
#[test]
fn a_time_grid_whose_last_time_overflows_is_refused() {
    let err = time_grid(1.79e308, 0.7e308).unwrap_err();
    assert!(
        matches!(err, Error::InvalidParameter { name: "t_end", .. }),
        "{err}"
    );
    // Just below, the grid is finite.
    let t = time_grid(1.4e308, 0.7e308).unwrap();
    assert!(t.iter().all(|v| v.is_finite()) && t.len() == 3);
}
