//! The Gramians (`gram`, `gram_factor`), Hankel
//! singular values (`hsvd`) and balanced truncation (`balred`) against
//! SciPy 1.17.1 / NumPy 2.4.6, closed forms, refusals and proptest
//! invariants.
//!
//! Fixtures: `tests/data/gram_fixtures.json`, from
//! `tests/data/gen_gram_fixtures.py` (see `tests/data/README.md`):
//! SciPy's `solve_continuous_lyapunov` / `solve_discrete_lyapunov` for the
//! Gramians and `dlyapchol`'s `X`, NumPy's SVD of SciPy's Cholesky factors
//! for the Hankel singular values, and a NumPy square-root balanced
//! truncation whose reduced models are compared by frequency response
//! (realisations differ by the signs of states). Run with `--nocapture`
//! for each case's measured difference.

mod common;

use ctrlab::analysis::{GramianKind, ReducedOrder};
use ctrlab::nalgebra::{Complex, DMatrix, SMatrix, dmatrix, matrix};
use ctrlab::signal::Rng;
use ctrlab::{Continuous, Discrete, Domain, DynStateSpace, Error, StateSpace};
use proptest::prelude::*;
use serde_json::Value;

type C64 = Complex<f64>;

use common::{dmatrix as dm, rel_max as rel_diff};

/// `C (zI − A)⁻¹ B + D`, by complex LU (independent of the crate's
/// frequency-response code).
fn response(
    a: &DMatrix<f64>,
    b: &DMatrix<f64>,
    c: &DMatrix<f64>,
    d: &DMatrix<f64>,
    z: C64,
) -> DMatrix<C64> {
    let n = a.nrows();
    let cx = |m: &DMatrix<f64>| m.map(|v| C64::new(v, 0.0));
    let d = cx(d);
    if n == 0 {
        return d;
    }
    let m = DMatrix::<C64>::identity(n, n) * z - cx(a);
    let x = m.lu().solve(&cx(b)).expect("z is not a pole");
    cx(c) * x + d
}

/// The largest singular value of a complex matrix (the power iteration
/// would do; nalgebra's complex SVD is exact enough).
fn norm2(m: &DMatrix<C64>) -> f64 {
    m.clone().singular_values().max()
}

/// The frequency points of a fixture model: `jω` or `e^{jωdt}`.
fn points(model: &Value) -> Vec<C64> {
    let omega: Vec<f64> = serde_json::from_value(model["omega"].clone()).unwrap();
    match model["dt"].as_f64() {
        Some(dt) => omega.iter().map(|w| C64::new(0.0, w * dt).exp()).collect(),
        None => omega.iter().map(|&w| C64::new(0.0, w)).collect(),
    }
}

#[test]
fn the_fixtures_come_from_the_stated_versions() {
    let data = common::fixture("gram_fixtures.json");
    assert_eq!(data["versions"]["scipy"], "1.17.1");
}

/// The fixture's model as a run-time-sized model of its domain.
fn model<D: Domain>(
    m: &Value,
    make: impl Fn(DMatrix<f64>, DMatrix<f64>, DMatrix<f64>, DMatrix<f64>) -> DynStateSpace<D>,
) -> DynStateSpace<D> {
    make(dm(&m["a"]), dm(&m["b"]), dm(&m["c"]), dm(&m["d"]))
}

/// The Gramians relative to SciPy's (measured at most 3.4e-14), the
/// Hankel singular values relative to `σ₁` (NumPy's SVD of SciPy's
/// Cholesky factors; measured at most 2.3e-14) and the reduced models'
/// frequency responses relative to the full model's peak (measured at
/// most 1.5e-14); each bounded at 1e-10. The fixed-size path is checked
/// on the 4-state models.
fn check_model<D: Domain>(m: &Value, sys: &DynStateSpace<D>, worst: &mut [f64; 3]) {
    let wc = sys.gram(GramianKind::Controllability).unwrap();
    let wo = sys.gram(GramianKind::Observability).unwrap();
    let (dc, do_) = (
        rel_diff(&wc.x, &dm(&m["wc"])),
        rel_diff(&wo.x, &dm(&m["wo"])),
    );
    assert!(dc < 1e-10 && do_ < 1e-10, "{dc:e} {do_:e}");
    assert!(wc.residual < 1e-13 && wo.residual < 1e-13);
    let hsv = sys.hsvd().unwrap();
    let want: Vec<f64> = serde_json::from_value(m["hsv"].clone()).unwrap();
    let dh = hsv
        .iter()
        .zip(&want)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
        / want[0];
    assert!(dh < 1e-10, "{hsv:?} {want:?}");
    let z = points(m);
    let full: Vec<_> = z
        .iter()
        .map(|&z| response(sys.a(), sys.b(), sys.c(), sys.d(), z))
        .collect();
    let peak = full.iter().map(norm2).fold(0.0, f64::max);
    let mut dr: f64 = 0.0;
    for red in m["reduced"].as_array().unwrap() {
        let r = red["order"].as_u64().unwrap() as usize;
        let ours = sys.balred(ReducedOrder::States(r)).unwrap();
        assert_eq!(ours.model.states(), r);
        let bound = red["bound"].as_f64().unwrap();
        assert!((ours.error_bound - bound).abs() < 1e-10 * bound);
        let theirs: Vec<Vec<Vec<[f64; 2]>>> =
            serde_json::from_value(red["response"].clone()).unwrap();
        let mut err: f64 = 0.0;
        for ((zk, g), (t, gf)) in z.iter().zip(&theirs).zip(full.iter().enumerate()) {
            let _ = t;
            let mine = response(
                ours.model.a(),
                ours.model.b(),
                ours.model.c(),
                ours.model.d(),
                *zk,
            );
            let numpy = DMatrix::from_fn(mine.nrows(), mine.ncols(), |i, j| {
                C64::new(g[i][j][0], g[i][j][1])
            });
            dr = dr.max(norm2(&(&mine - &numpy)) / peak);
            err = err.max(norm2(&(gf - &mine)));
        }
        // The bound holds on the grid (NumPy's own check, repeated).
        assert!(
            err <= ours.error_bound * (1.0 + 1e-9),
            "{err} {}",
            ours.error_bound
        );
        // The reduced model is stable; in continuous time it is also
        // balanced with both Gramians diag(σ₁..σᵣ) (in discrete time the
        // truncated block's Gramians are not Σᵣ: measured 3.961 against
        // σ₁ = 4.034 on the 4-state discrete fixture).
        assert!(ours.model.is_stable().unwrap());
        if m["dt"].is_null() {
            let rc = ours.model.gram(GramianKind::Controllability).unwrap().x;
            let ro = ours.model.gram(GramianKind::Observability).unwrap().x;
            let sigma = DMatrix::from_diagonal(&nalgebra::DVector::from_column_slice(&hsv[..r]));
            assert!(
                (&rc - &sigma).amax() < 1e-9 * hsv[0] && (&ro - &sigma).amax() < 1e-9 * hsv[0],
                "{rc} {ro}"
            );
        }
    }
    assert!(dr < 1e-10, "{dr:e}");
    for (w, d) in worst.iter_mut().zip([dc.max(do_), dh, dr]) {
        *w = w.max(d);
    }
}

#[test]
fn gramians_hankel_values_and_balred_agree_with_scipy() {
    let data = common::fixture("gram_fixtures.json");
    let mut worst = [0.0; 3];
    for (k, m) in data["models"].as_array().unwrap().iter().enumerate() {
        if m["discrete"].as_bool().unwrap() {
            let dt = m["dt"].as_f64().unwrap();
            let sys = model(m, |a, b, c, d| {
                DynStateSpace::discrete(a, b, c, d, dt).unwrap()
            });
            check_model(m, &sys, &mut worst);
            if sys.states() == 4 && sys.inputs() == 1 && sys.outputs() == 1 {
                fixed_matches::<Discrete>(&sys);
            }
        } else {
            let sys = model(m, |a, b, c, d| {
                DynStateSpace::continuous(a, b, c, d).unwrap()
            });
            check_model(m, &sys, &mut worst);
            if sys.states() == 4 && sys.inputs() == 1 && sys.outputs() == 1 {
                fixed_matches::<Continuous>(&sys);
            }
        }
        println!("model {k}: done");
    }
    println!(
        "largest differences: Gramians {:.1e}, hsv {:.1e}, reduced responses {:.1e}",
        worst[0], worst[1], worst[2]
    );
}

/// The fixed-size methods give the run-time-sized answers bit for bit.
fn fixed_matches<D: Domain>(sys: &DynStateSpace<D>) {
    let fixed = StateSpace::<4, 1, 1, D>::try_from(sys).unwrap();
    let w: SMatrix<f64, 4, 4> = fixed.gram(GramianKind::Observability).unwrap().x;
    assert_eq!(
        w.as_slice(),
        sys.gram(GramianKind::Observability).unwrap().x.as_slice()
    );
    let r = fixed
        .gram_factor(GramianKind::Controllability)
        .unwrap()
        .factor;
    assert_eq!(
        r.as_slice(),
        sys.gram_factor(GramianKind::Controllability)
            .unwrap()
            .factor
            .as_slice()
    );
    assert_eq!(fixed.hsvd().unwrap().to_vec(), sys.hsvd().unwrap());
    let red = fixed.balred::<2>().unwrap();
    let dynred = sys.balred(ReducedOrder::States(2)).unwrap();
    assert_eq!(red.model.a().as_slice(), dynred.model.a().as_slice());
    assert_eq!(red.error_bound, dynred.error_bound);
    assert_eq!(red.model.domain(), sys.domain());
}

/// A decoupled model with known spectrum: `A = diag(−aᵢ)`, `B = diag(bᵢ)`,
/// `C = diag(cᵢ)`: `Wc = diag(bᵢ² / 2aᵢ)`, `Wo = diag(cᵢ² / 2aᵢ)`,
/// `σᵢ = |bᵢ cᵢ| / 2aᵢ`; truncation drops whole channels, so the error's
/// peak is the largest dropped channel's DC gain `|bᵢ cᵢ| / aᵢ = 2 σᵢ`.
/// Discrete: `σᵢ = |bᵢ cᵢ| / (1 − aᵢ²)`, peak `|bᵢ cᵢ| / (1 − |aᵢ|)`.
#[test]
fn closed_forms_of_a_decoupled_model() {
    let (a, b, c) = (
        [1.0, 2.0, 5.0, 0.5],
        [2.0, -1.0, 3.0, 0.1],
        [3.0, 1.0, 2.0, 1.0],
    );
    let diag = |v: [f64; 4]| DMatrix::from_diagonal(&nalgebra::DVector::from_column_slice(&v));
    let sys = DynStateSpace::continuous(-diag(a), diag(b), diag(c), DMatrix::zeros(4, 4)).unwrap();
    let wc = sys.gram(GramianKind::Controllability).unwrap().x;
    for i in 0..4 {
        assert!((wc[(i, i)] - b[i] * b[i] / (2.0 * a[i])).abs() < 1e-15 * wc[(i, i)].max(1.0));
    }
    let mut want: Vec<f64> = (0..4).map(|i| (b[i] * c[i]).abs() / (2.0 * a[i])).collect();
    want.sort_by(|x, y| y.total_cmp(x));
    let hsv = sys.hsvd().unwrap();
    for (x, y) in hsv.iter().zip(&want) {
        assert!((x - y).abs() < 1e-15 * want[0] * 4.0, "{hsv:?} {want:?}");
    }
    // σ = [3, 0.6, 0.25, 0.1]: keep 2, the error peak 2 · 0.25 at ω = 0.
    let red = sys.balred(ReducedOrder::States(2)).unwrap();
    assert!((red.error_bound - 2.0 * 0.35).abs() < 1e-14);
    let e = response(sys.a(), sys.b(), sys.c(), sys.d(), C64::new(0.0, 0.0))
        - response(
            red.model.a(),
            red.model.b(),
            red.model.c(),
            red.model.d(),
            C64::new(0.0, 0.0),
        );
    assert!((norm2(&e) - 0.5).abs() < 1e-14, "{}", norm2(&e));
    let mut poles: Vec<f64> = red.model.poles().unwrap().iter().map(|p| p.re).collect();
    poles.sort_by(f64::total_cmp);
    assert!(
        (poles[0] + 5.0).abs() < 1e-13 && (poles[1] + 1.0).abs() < 1e-13,
        "{poles:?}"
    );

    let ad = [0.5, -0.8, 0.2, 0.9];
    let sys =
        DynStateSpace::discrete(diag(ad), diag(b), diag(c), DMatrix::zeros(4, 4), 0.01).unwrap();
    let mut want: Vec<f64> = (0..4)
        .map(|i| (b[i] * c[i]).abs() / (1.0 - ad[i] * ad[i]))
        .collect();
    want.sort_by(|x, y| y.total_cmp(x));
    let hsv = sys.hsvd().unwrap();
    for (x, y) in hsv.iter().zip(&want) {
        assert!((x - y).abs() < 1e-14 * want[0], "{hsv:?} {want:?}");
    }
    // The first-order Gramian c² / (1 − a²).
    let wo = sys.gram(GramianKind::Observability).unwrap().x;
    assert!((wo[(1, 1)] - 1.0 / (1.0 - 0.64)).abs() < 1e-14);
    let red = sys.balred(ReducedOrder::States(1)).unwrap();
    assert_eq!(red.model.domain().dt(), 0.01);
    // σ = [8, 6.25, 2.78, 0.53] (z = 0.5, 0.2, −0.8, 0.9): keep the
    // channel at z = 0.5; the error's peak is the z = 0.2 channel's at
    // z = 1 together with the others', bounded by 2 Σ.
    assert!(
        (red.model.a()[(0, 0)] - 0.5).abs() < 1e-14,
        "{}",
        red.model.a()
    );
    assert!((red.error_bound - 2.0 * (6.25 + 1.0 / 0.36 + 0.1 / 0.19)).abs() < 1e-13);
}

#[test]
fn first_order_closed_forms_fixed_size() {
    // ẋ = −a x + b u, y = c x: Wc = b² / 2a, Wo = c² / 2a, σ = |bc| / 2a.
    let sys =
        StateSpace::continuous(matrix![-4.0], matrix![2.0], matrix![-6.0], matrix![1.0]).unwrap();
    assert_eq!(
        sys.gram(GramianKind::Controllability).unwrap().x[(0, 0)],
        0.5
    );
    assert_eq!(sys.gram(GramianKind::Observability).unwrap().x[(0, 0)], 4.5);
    assert!((sys.hsvd().unwrap()[0] - 1.5).abs() < 1e-15);
    let r = sys.gram_factor(GramianKind::Observability).unwrap().factor[(0, 0)];
    assert!((r - 4.5f64.sqrt()).abs() < 1e-15);
    // To zero states: the static gain D, bound 2σ = 3 (= the DC gain's size).
    let red = sys.balred::<0>().unwrap();
    assert_eq!(red.model.d()[(0, 0)], 1.0);
    assert!((red.error_bound - 3.0).abs() < 1e-15);
}

#[test]
fn ties_and_zero_hankel_values() {
    // σ = [3, 1, 1, 0.25]: two equal channels.
    let diag = |v: [f64; 4]| DMatrix::from_diagonal(&nalgebra::DVector::from_column_slice(&v));
    let sys = DynStateSpace::continuous(
        -diag([1.0, 1.0, 2.0, 2.0]),
        diag([2.0, 1.0, 2.0, 1.0]),
        diag([3.0, 2.0, 2.0, 1.0]),
        DMatrix::zeros(4, 4),
    )
    .unwrap();
    let hsv = sys.hsvd().unwrap();
    assert!((hsv[1] - hsv[2]).abs() < 1e-15, "{hsv:?}");
    assert!(matches!(sys.balred(ReducedOrder::States(2)),
                     Err(Error::InvalidParameter { name: "order", value, .. }) if value == 2.0));
    for r in [0, 1, 3, 4] {
        assert_eq!(
            sys.balred(ReducedOrder::States(r)).unwrap().model.states(),
            r
        );
    }
    // A tolerance inside the group keeps it whole.
    let red = sys.balred(ReducedOrder::Tolerance(1.0 - 1e-16)).unwrap();
    assert_eq!(red.model.states(), 3);
    assert_eq!(
        sys.balred(ReducedOrder::Tolerance(1.0))
            .unwrap()
            .model
            .states(),
        1
    );
    assert_eq!(
        sys.balred(ReducedOrder::Tolerance(0.0))
            .unwrap()
            .model
            .states(),
        4
    );
    // The fixed-size order is refused the same way.
    let fixed = StateSpace::<4, 4, 4>::try_from(&sys).unwrap();
    assert!(matches!(
        fixed.balred::<2>(),
        Err(Error::InvalidParameter { name: "order", .. })
    ));
    assert!(
        matches!(fixed.balred::<5>(), Err(Error::InvalidParameter { name: "order", value, .. }) if value == 5.0)
    );

    // An uncontrollable state: σ₂ = 0; keeping it is refused, the
    // tolerance drops it.
    let sys = DynStateSpace::continuous(
        dmatrix![-1.0, 0.0; 0.0, -2.0],
        dmatrix![1.0; 0.0],
        dmatrix![1.0, 1.0],
        dmatrix![0.0],
    )
    .unwrap();
    assert_eq!(sys.hsvd().unwrap()[1], 0.0);
    assert!(matches!(
        sys.balred(ReducedOrder::States(2)),
        Err(Error::InvalidParameter { name: "order", .. })
    ));
    let red = sys.balred(ReducedOrder::Tolerance(0.0)).unwrap();
    assert_eq!(red.model.states(), 1);
    assert!((red.model.a()[(0, 0)] + 1.0).abs() < 1e-15 && red.error_bound == 0.0);
}

#[test]
fn unstable_and_extreme_models_are_refused_by_name() {
    let integrator =
        StateSpace::continuous(matrix![0.0], matrix![1.0], matrix![1.0], matrix![0.0]).unwrap();
    assert!(matches!(
        integrator.gram(GramianKind::Controllability),
        Err(Error::Unstable {
            operation: "gram",
            ..
        })
    ));
    assert!(matches!(
        integrator.gram_factor(GramianKind::Observability),
        Err(Error::Unstable {
            operation: "gram",
            ..
        })
    ));
    assert!(matches!(
        integrator.hsvd(),
        Err(Error::Unstable {
            operation: "hsvd",
            ..
        })
    ));
    assert!(matches!(
        integrator.balred::<1>(),
        Err(Error::Unstable {
            operation: "balred",
            ..
        })
    ));
    let unstable = DynStateSpace::discrete(
        dmatrix![0.5, 0.0; 0.0, -1.2],
        dmatrix![1.0; 1.0],
        dmatrix![1.0, 1.0],
        dmatrix![0.0],
        0.1,
    )
    .unwrap();
    assert!(matches!(unstable.balred(ReducedOrder::States(1)),
                     Err(Error::Unstable { operation: "balred", re, .. }) if re == -1.2));
    assert!(matches!(
        unstable.gram(GramianKind::Controllability),
        Err(Error::Unstable { .. })
    ));
    // Bad tolerances.
    let lag =
        DynStateSpace::continuous(dmatrix![-1.0], dmatrix![1.0], dmatrix![1.0], dmatrix![0.0])
            .unwrap();
    for t in [f64::NAN, f64::INFINITY, -1.0] {
        assert!(matches!(
            lag.balred(ReducedOrder::Tolerance(t)),
            Err(Error::InvalidParameter {
                name: "tolerance",
                ..
            })
        ));
    }
    // 1e300: the Gramian overflows (b² / 2a = 5e599), refused; its factor
    // (1e300 / √2) does not, but σ = 1e600 / 2 does.
    let huge = StateSpace::continuous(matrix![-1.0], matrix![1e300], matrix![1e300], matrix![0.0])
        .unwrap();
    assert!(matches!(
        huge.gram(GramianKind::Controllability),
        Err(Error::Overflow { .. })
    ));
    let r = huge
        .gram_factor(GramianKind::Controllability)
        .unwrap()
        .factor[(0, 0)];
    assert!((r / (1e300 / 2f64.sqrt()) - 1.0).abs() < 1e-15);
    assert!(matches!(
        huge.hsvd(),
        Err(Error::Overflow { operation: "hsvd" })
    ));
    // Tiny: 1e-300 inputs, a Gramian that underflows to 0, and σ = 0.
    let tiny = StateSpace::continuous(
        matrix![-1.0],
        matrix![1e-300],
        matrix![1e-300],
        matrix![0.0],
    )
    .unwrap();
    assert_eq!(tiny.hsvd().unwrap()[0], 0.0);
    // Stiff: poles at 1e-3 and 1e6 rad/s, unit channels: σ₁ ≈ 1/(2a) = 500.
    let stiff = |fast: f64| {
        DynStateSpace::continuous(
            dmatrix![-1e-3, 0.0; 0.0, -fast],
            dmatrix![1.0; 1.0],
            dmatrix![1.0, 1.0],
            dmatrix![0.0],
        )
        .unwrap()
    };
    let hsv = stiff(1e6).hsvd().unwrap();
    assert!((hsv[0] - 500.0).abs() < 1e-9 * 500.0, "{hsv:?}");
    let red = stiff(1e6).balred(ReducedOrder::States(1)).unwrap();
    // NumPy's square-root truncation of the same model: −0.001000000004
    // (the fast mode's coupling shifts the kept pole by 4e-9 relative).
    assert!(
        (red.model.a()[(0, 0)] + 0.001000000004).abs() < 1e-12 * 1e-3,
        "{}",
        red.model.a()
    );
    // At 1e-3 and 1e12 rad/s (stable by the crate's componentwise test)
    // the Lyapunov solvers' normwise singularity test (|λ + μ| within
    // 100 n ε ‖S‖ of zero, here 9e-2 against 2e-3) refuses the slow
    // pole's equation: a named refusal, not a wrong Gramian.
    assert!(stiff(1e12).is_stable().unwrap());
    assert!(matches!(
        stiff(1e12).hsvd(),
        Err(Error::SingularEquation { .. })
    ));
    assert!(matches!(
        stiff(1e12).gram(GramianKind::Controllability),
        Err(Error::SingularEquation { .. })
    ));
    // Huge A and B with a representable Gramian: Wc = (1e300)² / 2e300.
    let fast = StateSpace::continuous(matrix![-1e300], matrix![1e300], matrix![1.0], matrix![0.0])
        .unwrap();
    assert!(matches!(
        fast.gram(GramianKind::Controllability),
        Err(Error::Overflow { operation: "gram" })
    ));
    let r = fast
        .gram_factor(GramianKind::Controllability)
        .unwrap()
        .factor[(0, 0)];
    assert!((r / 0.5e150f64.sqrt() / 1e75 - 1.0).abs() < 1e-14, "{r:e}");
    // No states: empty answers.
    let empty = DynStateSpace::continuous(
        DMatrix::zeros(0, 0),
        DMatrix::zeros(0, 1),
        DMatrix::zeros(1, 0),
        dmatrix![2.0],
    )
    .unwrap();
    assert!(empty.hsvd().unwrap().is_empty());
    assert_eq!(
        empty.gram(GramianKind::Controllability).unwrap().x.nrows(),
        0
    );
    let red = empty.balred(ReducedOrder::States(0)).unwrap();
    assert_eq!((red.model.states(), red.error_bound), (0, 0.0));
}

/// A random stable SISO model of `n` states: continuous with
/// `max Re λ ≤ −margin` (shifted), or discrete with spectral radius
/// below `radius`.
fn random_model(seed: u64, n: usize, margin: f64) -> (DMatrix<f64>, DMatrix<f64>, DMatrix<f64>) {
    let mut rng = Rng::new(seed);
    let g = DMatrix::from_fn(n, n, |_, _| rng.gaussian());
    let shift = DynStateSpace::continuous(
        g.clone(),
        DMatrix::zeros(n, 1),
        DMatrix::zeros(1, n),
        DMatrix::zeros(1, 1),
    )
    .unwrap()
    .poles()
    .unwrap()
    .iter()
    .map(|p| p.re)
    .fold(f64::MIN, f64::max);
    let a = g - DMatrix::identity(n, n) * (shift + margin);
    let b = DMatrix::from_fn(n, 1, |_, _| rng.gaussian());
    let c = DMatrix::from_fn(1, n, |_, _| rng.gaussian());
    (a, b, c)
}

/// Positive semidefinite: the smallest eigenvalue of the symmetrised `W`
/// no lower than rounding relative to its largest.
fn psd(w: &DMatrix<f64>) -> bool {
    let s = (w + w.transpose()) * 0.5;
    let e = s.symmetric_eigenvalues();
    e.min() >= -1e-12 * e.max().abs().max(f64::MIN_POSITIVE)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    /// Gramians PSD, and `max |G − Gr|` over a grid within the bound
    /// `2 Σ σᵢ` (times 1 + 1e-9 for rounding: the reduced response is
    /// computed to about ε ‖G‖, far below the gap measured, which is
    /// positive in every case), continuous and discrete.
    #[test]
    fn gramians_are_psd_and_the_bound_holds(
        seed in any::<u64>(),
        n in 1usize..=7,
        r_frac in 0.0..1.0f64,
        margin in 0.05..2.0f64,
        radius in 0.1..0.98f64,
    ) {
        let (a, b, c) = random_model(seed, n, margin);
        let d = DMatrix::zeros(1, 1);
        let csys = DynStateSpace::continuous(a.clone(), b.clone(), c.clone(), d.clone()).unwrap();
        // The discrete model: A scaled to the spectral radius.
        let rho = csys.poles().unwrap().iter().map(|p| p.norm()).fold(0.0, f64::max);
        let dsys = DynStateSpace::discrete(&a * (radius / rho), b, c, d, 0.1).unwrap();
        let r = ((n as f64) * r_frac) as usize;
        check_bound(&csys, r, &(0..60).map(|k| C64::new(0.0, 10f64.powf(-3.0 + 0.1 * k as f64))).collect::<Vec<_>>())?;
        check_bound(&dsys, r, &(0..=60).map(|k| C64::new(0.0, std::f64::consts::PI * k as f64 / 60.0).exp()).collect::<Vec<_>>())?;
    }
}

fn check_bound<D: Domain>(
    sys: &DynStateSpace<D>,
    r: usize,
    z: &[C64],
) -> Result<(), TestCaseError> {
    for kind in [GramianKind::Controllability, GramianKind::Observability] {
        let w = sys.gram(kind).unwrap().x;
        prop_assert!(psd(&w), "{w}");
    }
    let red = match sys.balred(ReducedOrder::States(r)) {
        Ok(red) => red,
        // A random model can have a tie or a zero σ only by accident;
        // then the refusal must be the documented one.
        Err(Error::InvalidParameter { name: "order", .. }) => return Ok(()),
        Err(e) => return Err(TestCaseError::fail(format!("{e}"))),
    };
    let mut err: f64 = 0.0;
    for &zk in z {
        let g = response(sys.a(), sys.b(), sys.c(), sys.d(), zk);
        let m = &red.model;
        let gr = response(m.a(), m.b(), m.c(), m.d(), zk);
        err = err.max(norm2(&(g - gr)));
    }
    let scale = red.hankel.first().copied().unwrap_or(0.0);
    prop_assert!(
        err <= red.error_bound * (1.0 + 1e-9) + 1e-12 * scale,
        "{err} > {}",
        red.error_bound
    );
    prop_assert!(red.model.is_stable().unwrap());
    Ok(())
}
