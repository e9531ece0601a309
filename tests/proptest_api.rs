//! Every public numeric entry point on adversarial input (issue 11): no
//! panic, a bounded amount of work (the sizes handed over are bounded, and
//! the library must refuse or bound the rest), and `Ok` only with finite
//! numbers inside. Inputs mix ordinary values with the extremes that broke
//! the crate before: ±f64::MAX, 1e±308, subnormals, zeros, NaN and ±inf.

// Built on the two-cart lab (its plant, simulated rig or card).
#![cfg(feature = "lab")]

use ctrlab::design::{
    AntiWindup, EstimatorForm, IntegralFeedback, Observer, StateFeedback, acker, care, dare, dlqr,
    lqr,
};
use ctrlab::discretize::expm;
use ctrlab::ident::{LeastSquares, Rls, etfe, spa};
use ctrlab::lab::ident::{Options, Scheme, Spread, SpringModel, average, identify, identify_with};
use ctrlab::metrics::step_info_channel;
use ctrlab::metrics::{Definition, step_info_mimo};
use ctrlab::sim::{
    SampledConfig, Solver, impulse_response, initial_response, run_sampled, simulate,
    step_response, time_grid,
};
use ctrlab::{
    Controller, Discretization, DynStateSpace, MassSpring, Recording, StateSpace, StepInfoOptions,
    step_info, step_info_of,
};
use nalgebra::{Complex, DMatrix, DVector, SMatrix, SVector};
use proptest::prelude::*;

/// Any f64, weighted towards the values that break numeric code.
fn wild() -> impl Strategy<Value = f64> {
    prop_oneof![
        4 => -10.0..10.0f64,
        2 => proptest::num::f64::NORMAL,
        1 => proptest::num::f64::SUBNORMAL | proptest::num::f64::ZERO,
        1 => prop_oneof![
            Just(f64::MAX),
            Just(-f64::MAX),
            Just(1e308),
            Just(-1e308),
            Just(1e-308),
            Just(1e300),
            Just(1e-300),
            Just(f64::MIN_POSITIVE),
        ],
        1 => prop_oneof![Just(f64::NAN), Just(f64::INFINITY), Just(f64::NEG_INFINITY)],
    ]
}

/// Finite values only, from tiny to huge.
fn finite() -> impl Strategy<Value = f64> {
    prop_oneof![
        4 => -10.0..10.0f64,
        2 => proptest::num::f64::NORMAL,
        1 => proptest::num::f64::SUBNORMAL | proptest::num::f64::ZERO,
        1 => prop_oneof![Just(f64::MAX), Just(-f64::MAX), Just(1e308), Just(1e-300)],
    ]
}

fn matrix<const R: usize, const C: usize>(
    values: impl Strategy<Value = f64>,
) -> impl Strategy<Value = SMatrix<f64, R, C>> {
    proptest::collection::vec(values, R * C).prop_map(|v| SMatrix::from_column_slice(&v))
}

fn finite_all(v: &[f64]) -> bool {
    v.iter().all(|v| v.is_finite())
}

fn finite_c(v: &[Complex<f64>]) -> bool {
    v.iter().all(|p| p.re.is_finite() && p.im.is_finite())
}

fn model(
    a: SMatrix<f64, 3, 3>,
    b: SMatrix<f64, 3, 1>,
    c: SMatrix<f64, 1, 3>,
) -> Option<StateSpace<3, 1, 1>> {
    StateSpace::continuous(a, b, c, SMatrix::zeros()).ok()
}

/// 64 cases each (CI), or `PROPTEST_CASES` for a longer hunt.
fn config() -> ProptestConfig {
    ProptestConfig {
        cases: std::env::var("PROPTEST_CASES")
            .ok()
            .and_then(|v| v.parse().ok())
            .unwrap_or(64),
        failure_persistence: None,
        ..ProptestConfig::default()
    }
}

proptest! {
    #![proptest_config(config())]

    #[test]
    fn model_analysis(a in matrix::<3, 3>(wild()), b in matrix::<3, 1>(wild()), c in matrix::<1, 3>(wild())) {
        let Ok(sys) = StateSpace::continuous(a, b, c, SMatrix::zeros()) else { return Ok(()) };
        if let Ok(p) = sys.poles() { prop_assert!(finite_c(&p)); }
        if let Ok(Some(p)) = sys.unstable_pole() { prop_assert!(finite_c(&[p])); }
        let _ = sys.is_stable();
        if let Ok(g) = sys.dc_gain() { prop_assert!(finite_all(g.as_slice())); }
        if let Ok(d) = sys.damping() {
            // ωn and ζ are finite; τ is +∞ for a pole on the imaginary axis.
            prop_assert!(d.iter().all(|d| d.natural_frequency.is_finite() && d.damping_ratio.is_finite()));
        }
        if let Ok(m) = sys.controllability() { prop_assert!(finite_all(m.as_slice())); }
        if let Ok(m) = sys.observability() { prop_assert!(finite_all(m.as_slice())); }
        let _ = (sys.is_controllable(), sys.is_observable());
    }

    #[test]
    fn discretisation_and_expm(a in matrix::<3, 3>(wild()), b in matrix::<3, 1>(wild()), dt in wild()) {
        if let Ok(e) = expm(&a) { prop_assert!(finite_all(e.as_slice())); }
        let Some(sys) = model(a, b, SMatrix::from_element(1.0)) else { return Ok(()) };
        for method in [Discretization::Zoh, Discretization::Tustin, Discretization::ForwardEuler, Discretization::BackwardEuler] {
            if let Ok(d) = sys.discretize(dt, method) {
                for m in [d.a().as_slice(), d.b().as_slice(), d.c().as_slice(), d.d().as_slice()] {
                    prop_assert!(finite_all(m));
                }
                if let Ok(g) = d.dc_gain() { prop_assert!(finite_all(g.as_slice())); }
                let _ = d.is_stable();
            }
        }
    }

    #[test]
    fn rank_of_any_matrix(v in proptest::collection::vec(wild(), 0..16), rows in 1usize..5, rtol in wild()) {
        let cols = v.len() / rows;
        let m = DMatrix::from_column_slice(rows, cols, &v[..rows * cols]);
        if let Ok(r) = ctrlab::analysis::rank(&m, Some(rtol)) { prop_assert!(r <= rows.min(cols)); }
        let _ = ctrlab::analysis::rank(&m, None);
    }

    #[test]
    fn simulation(
        a in matrix::<3, 3>(finite()), b in matrix::<3, 1>(finite()),
        x0 in matrix::<3, 1>(wild()), u in wild(),
        t_end in wild(), dt in wild(), substeps in 0usize..4,
        grid in proptest::collection::vec(wild(), 0..40),
    ) {
        let Some(sys) = model(a, b, SMatrix::from_element(1.0)) else { return Ok(()) };
        // Bounded work: at most a few thousand samples of a 3-state model.
        let samples = t_end / dt;
        if samples.is_finite() && samples.abs() <= 2000.0 {
            if let Ok(r) = step_response(&sys, t_end, dt) {
                prop_assert!(r.y.iter().all(|y| finite_all(y.as_slice())));
                prop_assert!(r.output(1).is_err());
            }
            if let Ok(t) = time_grid(t_end, dt) {
                prop_assert!(finite_all(&t));
                for solver in [Solver::Zoh, Solver::Rk4 { substeps }] {
                    if let Ok(r) = simulate(&sys, &t, x0, |_| SVector::from_element(u), solver) {
                        prop_assert!(r.x.iter().all(|x| finite_all(x.as_slice())));
                        prop_assert!(r.y.iter().all(|y| finite_all(y.as_slice())));
                    }
                }
            }
        }
        // Discrete, any period: `Ok` holds finite times, states and outputs.
        if let Ok(d) = StateSpace::discrete(a, b, SMatrix::<f64, 1, 3>::from_element(1.0), SMatrix::<f64, 1, 1>::zeros(), dt)
            && let Ok(r) = ctrlab::sim::simulate_discrete(&d, x0, &[SVector::from_element(u); 8])
        {
            prop_assert!(finite_all(&r.t));
            prop_assert!(r.x.iter().all(|x| finite_all(x.as_slice())));
            prop_assert!(r.y.iter().all(|y| finite_all(y.as_slice())));
        }
        // Any grid at all, sorted or not.
        for solver in [Solver::Zoh, Solver::Rk4 { substeps: 1 << 40 }, Solver::Rk4 { substeps: 2 }] {
            if let Ok(r) = simulate(&sys, &grid, x0, |_| SVector::from_element(u), solver) {
                prop_assert!(r.y.iter().all(|y| finite_all(y.as_slice())));
            }
        }
    }

    #[test]
    fn sampled_simulation(
        a in matrix::<2, 2>(finite()), period in wild(), duration in wild(), max_substep in wild(),
        delay in wild(), gain in wild(), reference in wild(),
        saturation in wild(), input_q in wild(), q in wild(), noise in wild(),
    ) {
        let Ok(plant) = StateSpace::continuous(a, SMatrix::<f64, 2, 1>::from_element(1.0), SMatrix::<f64, 1, 2>::from_element(1.0), SMatrix::zeros()) else { return Ok(()) };
        let config = SampledConfig::<1, 2> {
            max_substep, input_delay: delay, saturation: [saturation], input_quantisation: [input_q],
            quantisation: [q, q], noise: [noise, 0.0],
            ..SampledConfig::new(period, duration)
        };
        // Bounded work: at most 2000 periods and 64 sub-steps each.
        let Ok(n) = config.validate() else { return Ok(()) };
        if n > 2000 || period / max_substep > 64.0 { return Ok(()) }
        let Ok(control) = StateFeedback::new(SMatrix::<f64, 1, 2>::from_element(gain), SMatrix::<f64, 1, 1>::from_element(1.0)) else { return Ok(()) };
        if let Ok(rec) = run_sampled(plant, |x: &SVector<f64, 2>| *x, control, |_| SVector::<f64, 1>::from_element(reference), SVector::zeros(), &config) {
            prop_assert!(finite_all(rec.time()));
            for ch in ["u", "y1", "y2"] {
                prop_assert!(finite_all(rec.channel(ch).unwrap()));
            }
            // The docs' promise: |u| within the saturation, to rounding.
            let u_max = rec.channel("u").unwrap().iter().fold(0.0f64, |m, u| m.max(u.abs()));
            prop_assert!(u_max <= saturation * (1.0 + 1e-12), "|u| = {u_max} > {saturation}");
        }
    }

    #[test]
    fn step_metrics(
        t in proptest::collection::vec(wild(), 0..30),
        y in proptest::collection::vec(wild(), 0..30),
        band in wild(), lo in wild(), hi in wild(), window in wild(),
        initial in proptest::option::of(wild()), fin in proptest::option::of(wild()), reference in proptest::option::of(wild()),
        matlab in any::<bool>(),
    ) {
        let options = StepInfoOptions {
            settling_band: band, rise_limits: (lo, hi), initial_value: initial,
            final_value: fin, reference, final_window: window,
            definition: if matlab { Definition::Matlab } else { Definition::Ctrlab },
        };
        let n = t.len().min(y.len());
        for opts in [options, StepInfoOptions::default(), StepInfoOptions::matlab()] {
            for (t, y) in [(&t[..n], &y[..n]), (&t[..], &y[..])] {
                if let Ok(info) = step_info(t, y, &opts) {
                    prop_assert!(finite_all(&[
                        info.rise_time, info.settling_time, info.transient_time,
                        info.settling_min, info.settling_max,
                        info.overshoot, info.undershoot, info.peak, info.peak_time,
                        info.steady_state_value, info.steady_state_error.unwrap_or(0.0),
                    ]));
                }
            }
        }
        // The same data sorted in time: mostly valid records.
        let mut sorted: Vec<f64> = t[..n].iter().copied().filter(|v| v.is_finite()).collect();
        sorted.sort_by(f64::total_cmp);
        sorted.dedup();
        let ys: Vec<f64> = y.iter().copied().cycle().take(sorted.len()).collect();
        if ys.len() == sorted.len()
            && let Ok(info) = step_info(&sorted, &ys, &StepInfoOptions::default())
        {
            prop_assert!(info.overshoot.is_finite() && info.rise_time.is_finite());
        }
    }

    #[test]
    fn step_metrics_of_models(a in matrix::<3, 3>(finite()), b in matrix::<3, 1>(finite()), c in matrix::<1, 3>(finite()), t_end in 0.0..50.0f64, dt in 0.01..1.0f64) {
        let Some(sys) = model(a, b, c) else { return Ok(()) };
        for options in [StepInfoOptions::default(), StepInfoOptions::matlab()] {
            if let Ok(info) = step_info_of(&sys, t_end, dt, &options) {
                prop_assert!(finite_all(&[info.rise_time, info.settling_time, info.transient_time, info.overshoot, info.peak, info.steady_state_value]));
            }
            if let Ok(all) = step_info_mimo(&sys, t_end, dt, &options) {
                prop_assert_eq!(&all[0][0], &step_info_of(&sys, t_end, dt, &options));
            }
            // The same model sampled at dt: its own grid.
            if let Ok(d) = sys.discretize(dt, Discretization::Zoh)
                && let Ok(info) = step_info_of(&d, t_end, dt, &options)
            {
                prop_assert!(finite_all(&[info.rise_time, info.settling_time, info.transient_time, info.overshoot, info.peak]));
            }
        }
    }

    #[test]
    fn impulse_and_initial_responses(
        a in matrix::<3, 3>(finite()), b in matrix::<3, 1>(finite()),
        x0 in matrix::<3, 1>(wild()), t_end in wild(), dt in wild(),
    ) {
        let Some(sys) = model(a, b, SMatrix::from_element(1.0)) else { return Ok(()) };
        // Bounded work, as for the step response.
        let samples = t_end / dt;
        if !(samples.is_finite() && samples.abs() <= 2000.0) {
            return Ok(());
        }
        let finite_response = |y: &[SVector<f64, 1>]| y.iter().all(|y| finite_all(y.as_slice()));
        if let Ok(r) = impulse_response(&sys, t_end, dt) {
            prop_assert!(finite_response(&r.y));
        }
        if let Ok(r) = initial_response(&sys, t_end, dt, x0) {
            prop_assert!(finite_response(&r.y));
        }
        if let Ok(d) = StateSpace::discrete(a, b, SMatrix::from_element(1.0), SMatrix::zeros(), dt) {
            if let Ok(r) = impulse_response(&d, t_end, dt) {
                prop_assert!(finite_response(&r.y));
            }
            if let Ok(r) = initial_response(&d, t_end, dt, x0) {
                prop_assert!(finite_response(&r.y));
            }
        }
    }

    #[test]
    fn state_feedback_design(
        a in matrix::<3, 3>(finite()), b in matrix::<3, 1>(finite()),
        k in matrix::<1, 3>(wild()),
        poles in proptest::collection::vec((wild(), wild()), 3),
        q in matrix::<3, 3>(wild()), r in wild(), dt in 0.001..1.0f64,
    ) {
        let Some(sys) = model(a, b, SMatrix::from_element(1.0)) else { return Ok(()) };
        let targets = [0, 1, 2].map(|i| Complex::new(poles[i].0, poles[i].1));
        if let Ok(k) = acker(&sys, targets) { prop_assert!(finite_all(k.as_slice())); }
        let q = (q + q.transpose()) * 0.5;
        let r = SMatrix::<f64, 1, 1>::new(r);
        if let Ok(sol) = lqr(&sys, &q, &r) {
            prop_assert!(finite_all(sol.gain.as_slice()) && finite_all(sol.riccati.as_slice()) && finite_c(sol.poles.as_slice()));
        }
        if let Ok(d) = sys.discretize(dt, Discretization::Zoh)
            && let Ok(sol) = dlqr(&d, &q, &r)
        {
            prop_assert!(finite_all(sol.gain.as_slice()) && finite_all(sol.riccati.as_slice()));
        }
        if let Ok(fb) = StateFeedback::new(k, SMatrix::<f64, 1, 1>::from_element(1.0))
            && let Ok(cl) = fb.closed_loop(&sys)
        {
            prop_assert!(finite_all(cl.a().as_slice()));
        }
        if let Ok(fb) = StateFeedback::with_prefilter(&sys, k) {
            prop_assert!(finite_all(fb.reference_gain().as_slice()));
        }
    }

    #[test]
    fn least_squares(cols in proptest::collection::vec(proptest::collection::vec(wild(), 8), 1..4), lambda in proptest::collection::vec(wild(), 8), rows in 0usize..9) {
        let p = cols.len();
        let mut ls = LeastSquares::new(p);
        let slices: Vec<&[f64]> = cols.iter().map(|c| &c[..rows]).collect();
        prop_assert!(ls.push_columns(&slices, &lambda[..rows]).is_ok());
        if let Ok(fit) = ls.solve() {
            prop_assert!(finite_all(fit.theta.as_slice()) && finite_all(fit.std_errors.as_slice()));
            prop_assert!(finite_all(fit.covariance.as_slice()) && fit.residual_rms.is_finite());
            prop_assert!(!fit.r_squared.is_nan() && !fit.fit_percent.is_nan() && fit.condition.is_finite());
        }
        let _ = ls.push_row(&[1.0; 5][..p.min(5)], 1.0);
    }

    #[test]
    fn recursive_least_squares(forgetting in wild(), p0 in wild(), rows in proptest::collection::vec((wild(), wild(), wild()), 0..20)) {
        let Ok(mut rls) = Rls::<2>::new(forgetting, p0) else { return Ok(()) };
        for (a, b, y) in rows {
            if let Ok(e) = rls.update(&nalgebra::vector![a, b], y) {
                prop_assert!(e.is_finite());
            }
            prop_assert!(finite_all(rls.theta().as_slice()) && finite_all(rls.covariance().as_slice()));
        }
    }

    #[test]
    fn lab_plant(m1 in wild(), m2 in wild(), k1 in wild(), k2 in wild(), b1 in wild(), gain in wild(), force in wild()) {
        let plant = MassSpring { m1, m2, k1, k2, b1, b2: b1, gain };
        let _ = plant.validate();
        if let Ok(sys) = plant.state_space(ctrlab::Cart::Two) { prop_assert!(finite_all(sys.a().as_slice())); }
        if let Ok((x1, x2)) = plant.static_deflection(force) { prop_assert!(x1.is_finite() && x2.is_finite()); }
    }

    #[test]
    fn lab_identification(
        x1 in proptest::collection::vec(finite(), 0..24), x2 in proptest::collection::vec(finite(), 24),
        u in proptest::collection::vec(finite(), 24), dt in wild(), m1 in wild(), m2 in wild(),
    ) {
        let n = x1.len();
        let t: Vec<f64> = (0..n).map(|k| k as f64 * dt).collect();
        let schema = ctrlab::lab::schema();
        let Ok(rec) = Recording::from_columns(schema, t, vec![u[..n].to_vec(), x1.clone(), vec![0.0; n], x2[..n].to_vec(), vec![0.0; n]]) else { return Ok(()) };
        for scheme in [Scheme::Lab, Scheme::Central] {
            if let Ok(est) = identify(&rec, m1, m2, scheme) {
                for e in [est.k12().unwrap(), est.b1, est.gain, est.b2] { prop_assert!(e.value.is_finite() && e.std_error.is_finite()); }
                if let Ok(avg) = average(&[est.clone(), est]) { prop_assert!(avg.k12().unwrap().std_dev.is_finite()); }
            }
            if let Ok(est) = identify_with(&rec, m1, m2, &Options { springs: SpringModel::Separate, scheme, ..Options::DEFAULT }) {
                for e in [est.k1(), est.k2(), est.b1, est.gain, est.b2] { prop_assert!(e.value.is_finite() && e.std_error.is_finite()); }
            }
        }
    }

    #[test]
    fn spread(values in proptest::collection::vec(wild(), 0..8)) {
        if let Ok(s) = Spread::of(&values) { prop_assert!(s.mean.is_finite() && s.std_dev.is_finite()); }
    }

    #[test]
    fn csv_reader(text in "[tux12_ms,.\n 0-9eE+-]{0,200}", raw in proptest::collection::vec(any::<u8>(), 0..200)) {
        for bytes in [text.as_bytes(), &raw[..]] {
            if let Ok(rec) = Recording::from_reader(bytes) {
                prop_assert!(finite_all(rec.time()));
                for ch in rec.schema().channels() { prop_assert!(finite_all(rec.channel(&ch.name).unwrap())); }
                let _ = rec.sample_period();
                if rec.schema().position("y").is_some() {
                    let _ = step_info_channel(&rec, "y", &StepInfoOptions::default());
                }
            }
        }
    }
}

// Issue 28: observers and integral action, run-time-sized models, the
// Riccati equations and the spectral estimates.
proptest! {
    #![proptest_config(config())]

    #[test]
    fn observers(
        a in matrix::<2, 2>(wild()), b in matrix::<2, 1>(wild()), c in matrix::<1, 2>(wild()),
        d in wild(), l in matrix::<2, 1>(wild()), current in any::<bool>(), y in -1.0..1.0f64,
    ) {
        let Ok(model) = StateSpace::discrete(a, b, c, SMatrix::from_element(d), 0.01) else { return Ok(()) };
        let form = if current { EstimatorForm::Current } else { EstimatorForm::Predictor };
        if let Ok(mut obs) = Observer::new(&model, l, form) {
            // Accepted: the first estimate of a unit-sized measurement is
            // finite (it was NaN for A⁻¹ L = 1e9 / 1e-300).
            let estimate = obs.correct(&SVector::from_element(y));
            prop_assert!(finite_all(estimate.as_slice()), "{:?}", estimate);
        }
    }

    #[test]
    fn integral_action(
        a in wild(), b in wild(), c in wild(), d in wild(), dt in 0.001..10.0f64,
        gain in matrix::<1, 2>(wild()), tracking in wild(), deadband in wild(), back in any::<bool>(),
    ) {
        let one = |v: f64| SMatrix::<f64, 1, 1>::from_element(v);
        let Ok(plant) = StateSpace::discrete(one(a), one(b), one(c), one(d), dt) else { return Ok(()) };
        let anti_windup = if back { AntiWindup::BackCalculation { tracking, deadband } } else { AntiWindup::None };
        if let Ok(mut ctl) = IntegralFeedback::new(&plant, &gain, anti_windup) {
            // Accepted: at rest it stays finite (T D = 10 · 1e308 and
            // K_z⁺ = 1 / 1e-310 made NaN of zeros; a nonzero signal may
            // overflow on gains of 1e300 legitimately).
            for _ in 0..3 {
                let u = ctl.update(&SVector::zeros(), &SVector::zeros());
                prop_assert!(finite_all(u.as_slice()), "{:?}", u);
                ctl.applied(&SVector::zeros());
                prop_assert!(finite_all(ctl.integrators().as_slice()), "{:?}", ctl.integrators());
            }
        }
    }

    #[test]
    fn run_time_models(
        a in matrix::<2, 2>(wild()), b in matrix::<2, 1>(wild()), c in matrix::<1, 2>(wild()),
        d in wild(), x in matrix::<2, 1>(wild()), u in wild(),
    ) {
        let heap = |m: &[f64], r: usize, k: usize| DMatrix::from_column_slice(r, k, m);
        let Ok(sys) = DynStateSpace::discrete(heap(a.as_slice(), 2, 2), heap(b.as_slice(), 2, 1),
            heap(c.as_slice(), 1, 2), heap(&[d], 1, 1), 0.01) else { return Ok(()) };
        let (x, u) = (DVector::from_column_slice(x.as_slice()), DVector::from_element(1, u));
        if let Ok(next) = sys.advance(&x, &u) { prop_assert!(finite_all(next.as_slice()), "{}", next); }
        if let Ok(y) = sys.output(&x, &u) { prop_assert!(finite_all(y.as_slice()), "{}", y); }
    }

    #[test]
    fn riccati_equations(
        a in matrix::<2, 2>(wild()), b in matrix::<2, 1>(wild()), q in matrix::<2, 2>(wild()),
        r in wild(), discrete in any::<bool>(),
    ) {
        let heap = |m: &[f64], r: usize, k: usize| DMatrix::from_column_slice(r, k, m);
        let q = q + q.transpose(); // symmetric (when finite) so that it gets past the checks
        let (a, b, q, r) = (heap(a.as_slice(), 2, 2), heap(b.as_slice(), 2, 1), heap(q.as_slice(), 2, 2), heap(&[r], 1, 1));
        let sol = if discrete { dare(&a, &b, &q, &r) } else { care(&a, &b, &q, &r) };
        if let Ok(sol) = sol {
            prop_assert!(finite_all(sol.gain.as_slice()), "{}", sol.gain);
            prop_assert!(finite_all(sol.riccati.as_slice()), "{}", sol.riccati);
            prop_assert!(finite_c(sol.poles.as_slice()), "{:?}", sol.poles);
        }
    }

    #[test]
    fn spectral_estimates(
        u in proptest::collection::vec(wild(), 0..40), y in proptest::collection::vec(wild(), 0..40),
        dt in wild(), lag in proptest::option::of(0usize..50), omega in proptest::collection::vec(wild(), 0..4),
    ) {
        let n = u.len().min(y.len());
        for g in [etfe(&u[..n], &y[..n], dt), spa(&u[..n], &y[..n], dt, lag, &omega)].into_iter().flatten() {
            prop_assert!(finite_all(&g.omega), "{:?}", g.omega);
            prop_assert!(finite_c(&g.response), "{:?}", g.response);
        }
    }
}

#[cfg(feature = "plot")]
proptest! {
    #![proptest_config(ProptestConfig { cases: 24, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn plots(t in proptest::collection::vec(wild(), 0..8), y in proptest::collection::vec(wild(), 0..8)) {
        use ctrlab::plot::{Series, responses_svg};
        let path = std::env::temp_dir().join(format!("ctrlab_proptest_plot_{}.svg", std::process::id()));
        let n = t.len().min(y.len());
        match responses_svg(&path, "p", "t", "y", &[Series::new("s", &t[..n], &y[..n])]) {
            Ok(()) => prop_assert!(std::fs::read_to_string(&path).unwrap().contains("<svg")),
            Err(e) => {
                let expected = matches!(e, ctrlab::plot::PlotError::Data(ctrlab::Error::InvalidData { .. } | ctrlab::Error::LengthMismatch { .. }) | ctrlab::plot::PlotError::Write { .. });
                prop_assert!(expected, "{}", e);
            }
        }
        std::fs::remove_file(&path).ok();
    }
}
