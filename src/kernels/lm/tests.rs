//! The Levenberg–Marquardt kernel on the test problems of Moré, Garbow and
//! Hillstrom ("Testing unconstrained optimization software", 1981), with
//! analytic Jacobians, against MINPACK's `lmder` from the same starting
//! points with `ftol = xtol = 1.49012e-8`, `gtol = 0`, `factor = 100` and
//! `maxfev = 100 (n + 1)` (the expectations of the `levenberg-marquardt`
//! crate's tests, generated from MINPACK through SciPy's `leastsq`), or
//! against the minima in the paper; and its refusals.

use super::*;

/// A problem from closures: residuals and Jacobian of `x`.
struct Closures<F, G> {
    m: usize,
    f: F,
    g: G,
}

impl<F, G> LeastSquaresProblem for Closures<F, G>
where
    F: FnMut(&[f64], &mut [f64]),
    G: FnMut(&[f64], &mut DMatrix<f64>),
{
    fn residual_count(&self) -> usize {
        self.m
    }
    fn residuals(&mut self, x: &DVector<f64>, out: &mut DVector<f64>) -> bool {
        (self.f)(x.as_slice(), out.as_mut_slice());
        true
    }
    fn jacobian(&mut self, x: &DVector<f64>, out: &mut DMatrix<f64>) -> bool {
        (self.g)(x.as_slice(), out);
        true
    }
}

/// MINPACK's `lmder1` settings of the reference runs.
fn minpack() -> Settings {
    Settings {
        ftol: 1.49012e-8,
        xtol: 1.49012e-8,
        ..Settings::default()
    }
}

fn run<F, G>(m: usize, x0: &[f64], f: F, g: G) -> Report
where
    F: FnMut(&[f64], &mut [f64]),
    G: FnMut(&[f64], &mut DMatrix<f64>),
{
    let mut p = Closures { m, f, g };
    minimize(&mut p, &DVector::from_column_slice(x0), &minpack())
}

/// `got` within `rel` of `want` relatively (absolutely below 1).
fn close(got: f64, want: f64, rel: f64) -> bool {
    (got - want).abs() <= rel * want.abs().max(1.0)
}

/// The report against MINPACK's evaluations, ½‖f‖² and minimiser.
fn check(r: &Report, evaluations: usize, objective: f64, x: Option<&[f64]>) {
    assert_eq!(r.evaluations, evaluations, "{r:?}");
    let rel = if objective == 0.0 {
        1e-20
    } else {
        1e-9 * objective
    };
    assert!(
        (r.objective - objective).abs() <= rel,
        "{r:?}, want {objective:e}"
    );
    if let Some(x) = x {
        for (got, want) in r.x.iter().zip(x) {
            assert!(close(*got, *want, 1e-7), "{r:?}, want {x:?}");
        }
    }
}

fn scaled(x0: &[f64], k: f64) -> Vec<f64> {
    x0.iter().map(|v| v * k).collect()
}

/// MGH 1: linear function, full rank, n = 5. Minimum `m − n` at `x = −1`.
fn linear_full_rank(m: usize) -> Report {
    let n = 5;
    run(
        m,
        &[1.0; 5],
        move |x, f| {
            let t = 2.0 * x.iter().sum::<f64>() / m as f64 + 1.0;
            for (i, fi) in f.iter_mut().enumerate() {
                *fi = if i < n { x[i] } else { 0.0 } - t;
            }
        },
        move |_, j| {
            j.fill(-2.0 / m as f64);
            for i in 0..n {
                j[(i, i)] += 1.0;
            }
        },
    )
}

/// MGH 2: linear function, rank 1: `f_i = i Σ j x_j − 1`.
fn linear_rank1(m: usize) -> Report {
    run(
        m,
        &[1.0; 5],
        |x, f| {
            let s: f64 = x.iter().enumerate().map(|(j, v)| (j + 1) as f64 * v).sum();
            for (i, fi) in f.iter_mut().enumerate() {
                *fi = (i + 1) as f64 * s - 1.0;
            }
        },
        |_, j| {
            for ((r, c), v) in j.iter_mut().enumerate().map(|(k, v)| ((k % m, k / m), v)) {
                *v = ((r + 1) * (c + 1)) as f64;
            }
        },
    )
}

/// MGH 3: linear function, rank 1, with zero first and last columns and
/// rows.
fn linear_rank1_zero(m: usize) -> Report {
    run(
        m,
        &[1.0; 5],
        move |x, f| {
            let s: f64 = (1..4).map(|j| (j + 1) as f64 * x[j]).sum();
            for (i, fi) in f.iter_mut().enumerate() {
                *fi = if i == 0 || i == m - 1 {
                    -1.0
                } else {
                    i as f64 * s - 1.0
                };
            }
        },
        move |_, j| {
            for i in 1..m - 1 {
                for c in 1..4 {
                    j[(i, c)] = (i * (c + 1)) as f64;
                }
            }
        },
    )
}

#[test]
fn linear_problems_full_rank_and_rank_deficient() {
    for (m, half_min) in [(10, 2.5), (50, 22.5)] {
        let r = linear_full_rank(m);
        check(&r, 3, half_min, Some(&[-1.0; 5]));
        assert_eq!(
            r.termination,
            Termination::Converged {
                ftol: true,
                xtol: true
            }
        );
    }
    // The Jacobians have rank 1: the minimum m (m − 1) / (2 (2m + 1)),
    // and (m² + 3m − 6) / (2 (2m − 3)) with zero rows and columns.
    for m in [10, 50] {
        let mf = m as f64;
        let r = linear_rank1(m);
        check(
            &r,
            3,
            0.5 * mf * (mf - 1.0) / (2.0 * (2.0 * mf + 1.0)),
            None,
        );
        assert!(!r.termination.was_usage_issue(), "{r:?}");
        let r = linear_rank1_zero(m);
        let half_min = 0.5 * (mf * mf + 3.0 * mf - 6.0) / (2.0 * (2.0 * mf - 3.0));
        check(&r, 3, half_min, None);
        // The parameters of the zero columns are never moved.
        assert!(r.x[0] == 1.0 && r.x[4] == 1.0, "{r:?}");
    }
}

#[test]
fn rosenbrock_helical_valley_and_powell_singular() {
    let x0 = [-1.2, 1.0];
    for (k, evaluations) in [(1.0, 21), (10.0, 8), (100.0, 6)] {
        let r = run(
            2,
            &scaled(&x0, k),
            |x, f| {
                f[0] = 10.0 * (x[1] - x[0] * x[0]);
                f[1] = 1.0 - x[0];
            },
            |x, j| {
                j[(0, 0)] = -20.0 * x[0];
                j[(0, 1)] = 10.0;
                j[(1, 0)] = -1.0;
            },
        );
        check(&r, evaluations, 0.0, Some(&[1.0, 1.0]));
        assert_eq!(r.termination, Termination::ResidualsZero);
    }

    let x0 = [-1.0, 0.0, 0.0];
    for (k, evaluations, half_min) in [
        (1.0, 11, 4.936724569245567e-33_f64),
        (10.0, 20, 5.456769505027268e-39),
        (100.0, 19, 4.9259630763847064e-58),
    ] {
        let r = run(
            3,
            &scaled(&x0, k),
            |x, f| {
                let tpi = 8.0 * 1f64.atan();
                let theta = if x[0] > 0.0 {
                    (x[1] / x[0]).atan() / tpi
                } else if x[0] < 0.0 {
                    (x[1] / x[0]).atan() / tpi + 0.5
                } else {
                    0.25f64.copysign(x[1])
                };
                f[0] = 10.0 * (x[2] - 10.0 * theta);
                f[1] = 10.0 * (x[0].hypot(x[1]) - 1.0);
                f[2] = x[2];
            },
            |x, j| {
                let tpi = 8.0 * 1f64.atan();
                let s2 = x[0] * x[0] + x[1] * x[1];
                let (t1, t2) = (tpi * s2, s2.sqrt());
                j[(0, 0)] = 100.0 * x[1] / t1;
                j[(0, 1)] = -100.0 * x[0] / t1;
                j[(0, 2)] = 10.0;
                j[(1, 0)] = 10.0 * x[0] / t2;
                j[(1, 1)] = 10.0 * x[1] / t2;
                j[(2, 2)] = 1.0;
            },
        );
        assert_eq!(r.evaluations, evaluations, "{r:?}");
        assert!(r.objective <= half_min.max(1e-30), "{r:?}");
        assert!(close(r.x[0], 1.0, 1e-12) && r.x[1].abs() < 1e-15 && r.x[2].abs() < 1e-15);
        assert_eq!(
            r.termination,
            Termination::Converged {
                ftol: false,
                xtol: true
            }
        );
    }

    // Singular at the solution: MINPACK stops on gtol at machine precision.
    let x0 = [3.0, -1.0, 0.0, 1.0];
    for (k, evaluations) in [(1.0, 59), (10.0, 72), (100.0, 68)] {
        let r = run(
            4,
            &scaled(&x0, k),
            |x, f| {
                f[0] = x[0] + 10.0 * x[1];
                f[1] = 5f64.sqrt() * (x[2] - x[3]);
                f[2] = (x[1] - 2.0 * x[2]).powi(2);
                f[3] = 10f64.sqrt() * (x[0] - x[3]).powi(2);
            },
            |x, j| {
                j.fill(0.0);
                j[(0, 0)] = 1.0;
                j[(0, 1)] = 10.0;
                j[(1, 2)] = 5f64.sqrt();
                j[(1, 3)] = -(5f64.sqrt());
                j[(2, 1)] = 2.0 * (x[1] - 2.0 * x[2]);
                j[(2, 2)] = -2.0 * j[(2, 1)];
                j[(3, 0)] = 2.0 * 10f64.sqrt() * (x[0] - x[3]);
                j[(3, 3)] = -j[(3, 0)];
            },
        );
        assert_eq!(r.evaluations, evaluations, "{r:?}");
        assert!(r.objective < 1e-60 && r.x.amax() < 1e-16, "{r:?}");
        let gtol = Termination::NoImprovementPossible("gtol");
        assert_eq!(r.termination, gtol);
    }
}

#[test]
fn freudenstein_roth_bard_kowalik_osborne_meyer() {
    // Freudenstein–Roth: the local minimum ½ · 48.9842.
    for (k, evaluations, half_min, x) in [
        (
            1.0,
            14,
            24.492126863534953,
            [11.412484465499368, -0.8968279137315035],
        ),
        (
            10.0,
            19,
            24.492126854042752,
            [11.413004661474561, -0.8967960386859591],
        ),
        (
            100.0,
            24,
            24.49212683962172,
            [11.412781785788198, -0.8968051074920677],
        ),
    ] {
        let r = run(
            2,
            &[0.5 * k, -2.0 * k],
            |x, f| {
                f[0] = -13.0 + x[0] + ((5.0 - x[1]) * x[1] - 2.0) * x[1];
                f[1] = -29.0 + x[0] + ((1.0 + x[1]) * x[1] - 14.0) * x[1];
            },
            |x, j| {
                j[(0, 0)] = 1.0;
                j[(0, 1)] = x[1] * (10.0 - 3.0 * x[1]) - 2.0;
                j[(1, 0)] = 1.0;
                j[(1, 1)] = x[1] * (2.0 + 3.0 * x[1]) - 14.0;
            },
        );
        check(&r, evaluations, half_min, Some(&x));
        assert!(close(2.0 * r.objective / 48.9842, 1.0, 1e-5));
    }

    // Bard: ½ · 8.21487e-3 from the standard start.
    let y = [
        0.14, 0.18, 0.22, 0.25, 0.29, 0.32, 0.35, 0.39, 0.37, 0.58, 0.73, 0.96, 1.34, 2.10, 4.39,
    ];
    let uvw = |i: usize| {
        let (u, v) = ((i + 1) as f64, (15 - i) as f64);
        (u, v, u.min(v))
    };
    for (k, evaluations, half_min) in [
        (1.0, 6, 0.00410743865329062),
        (10.0, 37, 8.71434685503351),
        (100.0, 14, 8.714346854926243),
    ] {
        let r = run(
            15,
            &[k; 3],
            |x, f| {
                for (i, fi) in f.iter_mut().enumerate() {
                    let (u, v, w) = uvw(i);
                    *fi = y[i] - (x[0] + u / (v * x[1] + w * x[2]));
                }
            },
            |x, j| {
                for i in 0..15 {
                    let (u, v, w) = uvw(i);
                    let d = (v * x[1] + w * x[2]).powi(2);
                    j[(i, 0)] = -1.0;
                    j[(i, 1)] = u * v / d;
                    j[(i, 2)] = u * w / d;
                }
            },
        );
        let x = [0.0824105765758334, 1.1330366534715044, 2.343694638941154];
        check(&r, evaluations, half_min, (k == 1.0).then_some(&x[..]));
        if k == 1.0 {
            assert!(close(2.0 * r.objective / 8.21487e-3, 1.0, 1e-5));
        }
    }

    // Kowalik–Osborne: ½ · 3.07505e-4; from 100 x₀ MINPACK runs out of
    // patience (500 evaluations).
    let y = [
        0.1957, 0.1947, 0.1735, 0.1600, 0.0844, 0.0627, 0.0456, 0.0342, 0.0323, 0.0235, 0.0246,
    ];
    let u = [
        4.0, 2.0, 1.0, 0.5, 0.25, 0.167, 0.125, 0.1, 0.0833, 0.0714, 0.0625,
    ];
    let x0 = [0.25, 0.39, 0.415, 0.39];
    for (k, evaluations, half_min) in [
        (1.0, 18, 0.00015375280229088455),
        (10.0, 78, 0.000513671535424324),
        (100.0, 500, 0.00015375283657222266),
    ] {
        let r = run(
            11,
            &scaled(&x0, k),
            |x, f| {
                for (i, fi) in f.iter_mut().enumerate() {
                    let n = u[i] * (u[i] + x[1]);
                    let d = u[i] * (u[i] + x[2]) + x[3];
                    *fi = y[i] - x[0] * n / d;
                }
            },
            |x, j| {
                for i in 0..11 {
                    let n = u[i] * (u[i] + x[1]);
                    let d = u[i] * (u[i] + x[2]) + x[3];
                    j[(i, 0)] = -n / d;
                    j[(i, 1)] = -u[i] * x[0] / d;
                    j[(i, 2)] = j[(i, 0)] * j[(i, 1)];
                    j[(i, 3)] = j[(i, 2)] / u[i];
                }
            },
        );
        let x = [
            0.19280781047624931,
            0.1912626533540709,
            0.12305280104693087,
            0.13605322115051674,
        ];
        check(&r, evaluations, half_min, (k == 1.0).then_some(&x[..]));
        if k == 100.0 {
            assert_eq!(r.termination, Termination::LostPatience);
        } else {
            assert_eq!(
                r.termination,
                Termination::Converged {
                    ftol: true,
                    xtol: false
                }
            );
        }
    }

    // Meyer: ½ · 87.9458 (its exponentials make it badly scaled).
    let y = [
        34780.0, 28610.0, 23650.0, 19630.0, 16370.0, 13720.0, 11540.0, 9744.0, 8261.0, 7030.0,
        6005.0, 5147.0, 4427.0, 3820.0, 3307.0, 2872.0,
    ];
    let t = |i: usize| 45.0 + 5.0 * (i + 1) as f64;
    let r = run(
        16,
        &[0.02, 4000.0, 250.0],
        |x, f| {
            for (i, fi) in f.iter_mut().enumerate() {
                *fi = x[0] * (x[1] / (t(i) + x[2])).exp() - y[i];
            }
        },
        |x, j| {
            for i in 0..16 {
                let d = t(i) + x[2];
                let e = (x[1] / d).exp();
                j[(i, 0)] = e;
                j[(i, 1)] = x[0] * e / d;
                j[(i, 2)] = -x[0] * x[1] * e / (d * d);
            }
        },
    );
    let x = [5.60963647102716e-3, 6181.346346286506, 345.22363462414097];
    check(&r, 126, 43.972927585355414, Some(&x));
    assert!(close(2.0 * r.objective / 87.9458, 1.0, 1e-5));
}

/// MGH 20: Watson, m = 31, from x = 0.
fn watson(n: usize) -> Report {
    let ti = |i: usize| (i + 1) as f64 / 29.0;
    run(
        31,
        &vec![0.0; n],
        move |x, f| {
            for (i, fi) in f.iter_mut().take(29).enumerate() {
                let t = ti(i);
                let (mut s1, mut s2, mut tj) = (0.0, x[0], 1.0);
                for (j, xj) in x.iter().enumerate().skip(1) {
                    s1 += j as f64 * xj * tj;
                    tj *= t;
                    s2 += xj * tj;
                }
                *fi = s1 - s2 * s2 - 1.0;
            }
            f[29] = x[0];
            f[30] = x[1] - x[0] * x[0] - 1.0;
        },
        move |x, jac| {
            for i in 0..29 {
                let t = ti(i);
                let (mut s2, mut tj) = (x[0], 1.0);
                for xj in &x[1..] {
                    tj *= t;
                    s2 += xj * tj;
                }
                let mut tj = 1.0 / t;
                for j in 0..n {
                    jac[(i, j)] = j as f64 * tj - 2.0 * s2 * tj * t;
                    tj *= t;
                }
            }
            jac[(29, 0)] = 1.0;
            jac[(30, 0)] = -2.0 * x[0];
            jac[(30, 1)] = 1.0;
        },
    )
}

#[test]
fn watson_box_jennrich_sampson_brown_dennis() {
    // Watson: ½ · 2.28767e-3, 1.39976e-6 and 4.72238e-10 (n = 6, 9, 12).
    for (n, evaluations, half_min, paper) in [
        (6, 8, 0.001143835026786261, 2.28767e-3),
        (9, 8, 6.998800690506343e-07, 1.39976e-6),
        (12, 10, 2.3611905506971735e-10, 4.72238e-10),
    ] {
        let r = watson(n);
        check(&r, evaluations, half_min, None);
        assert!(close(2.0 * r.objective / paper, 1.0, 1e-5), "{r:?}");
    }
    let r = watson(6);
    let x = [
        -0.01572496150837828,
        1.0124348823296545,
        -0.23299172238767143,
        1.260431011028177,
        -1.5137303139441967,
        0.9929972729184159,
    ];
    check(&r, 8, 0.001143835026786261, Some(&x));

    // Box three-dimensional, m = 10: zero at (1, 10, 1).
    let t = |i: usize| 0.1 * (i + 1) as f64;
    let r = run(
        10,
        &[0.0, 10.0, 20.0],
        |x, f| {
            for (i, fi) in f.iter_mut().enumerate() {
                let t = t(i);
                *fi =
                    (-t * x[0]).exp() - (-t * x[1]).exp() - x[2] * ((-t).exp() - (-10.0 * t).exp());
            }
        },
        |x, j| {
            for i in 0..10 {
                let t = t(i);
                j[(i, 0)] = -t * (-t * x[0]).exp();
                j[(i, 1)] = t * (-t * x[1]).exp();
                j[(i, 2)] = -((-t).exp() - (-10.0 * t).exp());
            }
        },
    );
    assert!(r.objective < 1e-28, "{r:?}");
    for (got, want) in r.x.iter().zip([1.0, 10.0, 1.0]) {
        assert!(close(*got, want, 1e-9), "{r:?}");
    }

    // Jennrich–Sampson, m = 10: ½ · 124.362 at x₁ = x₂ = 0.2578.
    let r = run(
        10,
        &[0.3, 0.4],
        |x, f| {
            for (i, fi) in f.iter_mut().enumerate() {
                let k = (i + 1) as f64;
                *fi = 2.0 + 2.0 * k - ((k * x[0]).exp() + (k * x[1]).exp());
            }
        },
        |x, j| {
            for i in 0..10 {
                let k = (i + 1) as f64;
                j[(i, 0)] = -k * (k * x[0]).exp();
                j[(i, 1)] = -k * (k * x[1]).exp();
            }
        },
    );
    assert!(close(2.0 * r.objective / 124.362, 1.0, 1e-5), "{r:?}");
    assert!(r.x.iter().all(|v| (v - 0.2578).abs() < 1e-4), "{r:?}");

    // Brown and Dennis, m = 20: ½ · 85822.2.
    let t = |i: usize| (i + 1) as f64 / 5.0;
    let r = run(
        20,
        &[25.0, 5.0, -5.0, -1.0],
        |x, f| {
            for (i, fi) in f.iter_mut().enumerate() {
                let t = t(i);
                let a = x[0] + t * x[1] - t.exp();
                let b = x[2] + x[3] * t.sin() - t.cos();
                *fi = a * a + b * b;
            }
        },
        |x, j| {
            for i in 0..20 {
                let t = t(i);
                let a = x[0] + t * x[1] - t.exp();
                let b = x[2] + x[3] * t.sin() - t.cos();
                j[(i, 0)] = 2.0 * a;
                j[(i, 1)] = 2.0 * a * t;
                j[(i, 2)] = 2.0 * b;
                j[(i, 3)] = 2.0 * b * t.sin();
            }
        },
    );
    assert!(close(2.0 * r.objective / 85822.2, 1.0, 1e-6), "{r:?}");
    let x = [-11.5944, 13.2036, -0.403439, 0.236779];
    for (got, want) in r.x.iter().zip(x) {
        assert!((got - want).abs() < 1e-3 * want.abs(), "{r:?}");
    }
}

/// `f(x) = x − 3` in one parameter, and a problem checking that the
/// Jacobian is asked for where the residuals were last evaluated (what
/// `lab::ident::refine`'s cached base point relies on).
struct Recorder {
    last: Option<DVector<f64>>,
    bad_residuals: Option<f64>,
    bad_jacobian: Option<f64>,
    abort_after: usize,
    calls: usize,
    jacobians: usize,
}

impl Recorder {
    fn new() -> Recorder {
        Recorder {
            last: None,
            bad_residuals: None,
            bad_jacobian: None,
            abort_after: usize::MAX,
            calls: 0,
            jacobians: 0,
        }
    }
}

impl LeastSquaresProblem for Recorder {
    fn residual_count(&self) -> usize {
        2
    }
    fn residuals(&mut self, x: &DVector<f64>, out: &mut DVector<f64>) -> bool {
        self.calls += 1;
        self.last = Some(x.clone());
        out[0] = self.bad_residuals.unwrap_or(x[0] - 3.0);
        out[1] = 0.5 * (x[0] - 3.0);
        self.calls <= self.abort_after
    }
    fn jacobian(&mut self, x: &DVector<f64>, out: &mut DMatrix<f64>) -> bool {
        assert_eq!(
            self.last.as_ref(),
            Some(x),
            "the Jacobian is asked for at the last point"
        );
        self.jacobians += 1;
        out[(0, 0)] = self.bad_jacobian.unwrap_or(1.0);
        out[(1, 0)] = 0.5;
        true
    }
}

#[test]
fn the_jacobian_is_asked_for_at_the_last_residuals() {
    let mut p = Recorder::new();
    let r = minimize(
        &mut p,
        &DVector::from_element(1, 10.0),
        &Settings::default(),
    );
    assert!(
        matches!(
            r.termination,
            Termination::Converged { .. } | Termination::ResidualsZero
        ),
        "{r:?}"
    );
    assert!((r.x[0] - 3.0).abs() < 1e-12 && r.objective < 1e-24, "{r:?}");
    assert_eq!(r.evaluations, p.calls);
}

#[test]
fn zero_residuals_at_the_start_end_at_once() {
    let mut p = Recorder::new();
    let r = minimize(&mut p, &DVector::from_element(1, 3.0), &Settings::default());
    assert_eq!(r.termination, Termination::ResidualsZero);
    assert_eq!(
        (r.evaluations, p.jacobians, r.x[0], r.objective),
        (1, 0, 3.0, 0.0)
    );
    assert!(!r.termination.was_usage_issue());
}

#[test]
fn non_finite_numbers_are_a_usage_issue_or_a_failed_step() {
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        let mut p = Recorder::new();
        p.bad_residuals = Some(bad);
        let r = minimize(
            &mut p,
            &DVector::from_element(1, 10.0),
            &Settings::default(),
        );
        assert!(matches!(r.termination, Termination::NonFinite(_)), "{r:?}");
        assert!(r.termination.was_usage_issue());
        assert_eq!((r.evaluations, p.jacobians, r.x[0]), (1, 0, 10.0));

        let mut p = Recorder::new();
        p.bad_jacobian = Some(bad);
        let r = minimize(
            &mut p,
            &DVector::from_element(1, 10.0),
            &Settings::default(),
        );
        assert_eq!(r.termination, Termination::NonFinite("jacobian"), "{r:?}");
        assert!(r.termination.was_usage_issue() && r.objective.is_finite());
    }
    // ln x − 1 from x = 10: the Gauss–Newton step lands at x < 0, where
    // the residual is NaN; the step fails, the trust region shrinks, and
    // the minimum x = e is found.
    let mut nan_seen = false;
    let r = run(
        1,
        &[10.0],
        |x, f| {
            f[0] = x[0].ln() - 1.0;
            nan_seen |= f[0].is_nan();
        },
        |x, j| j[(0, 0)] = 1.0 / x[0],
    );
    assert!(!r.termination.was_usage_issue(), "{r:?}");
    assert!(
        (r.x[0] - 1f64.exp()).abs() < 1e-9 && r.objective.is_finite(),
        "{r:?}"
    );
    assert!(nan_seen);
}

#[test]
fn bad_input_and_aborts_are_refused_without_panics() {
    let x0 = DVector::from_element(1, 10.0);
    let mut p = Recorder::new();
    let nothing = minimize(&mut p, &DVector::zeros(0), &Settings::default());
    let nan = minimize(
        &mut p,
        &DVector::from_element(1, f64::NAN),
        &Settings::default(),
    );
    let wide = minimize(&mut p, &DVector::zeros(3), &Settings::default());
    let mut bad_settings = vec![];
    for s in [
        Settings {
            ftol: -1.0,
            ..Settings::default()
        },
        Settings {
            xtol: f64::NAN,
            ..Settings::default()
        },
        Settings {
            gtol: -0.1,
            ..Settings::default()
        },
        Settings {
            factor: 0.0,
            ..Settings::default()
        },
        Settings {
            factor: f64::INFINITY,
            ..Settings::default()
        },
        Settings {
            patience: 0,
            ..Settings::default()
        },
    ] {
        bad_settings.push(minimize(&mut p, &x0, &s));
    }
    for r in [nothing, nan, wide].iter().chain(&bad_settings) {
        assert!(
            matches!(r.termination, Termination::InvalidInput(_)),
            "{r:?}"
        );
        assert!(r.termination.was_usage_issue() && r.evaluations == 0);
    }
    assert_eq!(p.calls, 0);
    // The problem stops it at the first, then at a later evaluation.
    for after in [0, 2] {
        let mut p = Recorder::new();
        p.abort_after = after;
        let r = minimize(&mut p, &x0, &Settings::default());
        assert_eq!(r.termination, Termination::Aborted("residuals"), "{r:?}");
        assert_eq!(r.evaluations, after + 1);
        assert!(r.x[0].is_finite());
    }
}

#[test]
fn patience_bounds_the_evaluations() {
    // Meyer's problem from 10 x₀ needs far more than 12 (n + 1).
    let y = [
        34780.0, 28610.0, 23650.0, 19630.0, 16370.0, 13720.0, 11540.0, 9744.0, 8261.0, 7030.0,
        6005.0, 5147.0, 4427.0, 3820.0, 3307.0, 2872.0,
    ];
    let t = |i: usize| 45.0 + 5.0 * (i + 1) as f64;
    for patience in [1, 12, 100] {
        let mut p = Closures {
            m: 16,
            f: |x: &[f64], f: &mut [f64]| {
                for (i, fi) in f.iter_mut().enumerate() {
                    *fi = x[0] * (x[1] / (t(i) + x[2])).exp() - y[i];
                }
            },
            g: |x: &[f64], j: &mut DMatrix<f64>| {
                for i in 0..16 {
                    let d = t(i) + x[2];
                    let e = (x[1] / d).exp();
                    j[(i, 0)] = e;
                    j[(i, 1)] = x[0] * e / d;
                    j[(i, 2)] = -x[0] * x[1] * e / (d * d);
                }
            },
        };
        let settings = Settings {
            patience,
            ..minpack()
        };
        let r = minimize(
            &mut p,
            &DVector::from_column_slice(&[0.2, 40000.0, 2500.0]),
            &settings,
        );
        assert_eq!(r.termination, Termination::LostPatience, "{r:?}");
        assert_eq!(r.evaluations, patience * 4);
        assert!(r.objective.is_finite() && r.x.iter().all(|v| v.is_finite()));
    }
}

#[test]
fn enorm_neither_overflows_nor_underflows() {
    let plain = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
    for v in [
        vec![3.0, 4.0],
        vec![1e-3, -2.0, 7.5, 0.0],
        vec![0.0; 4],
        vec![],
    ] {
        assert!((enorm(&v) - plain(&v)).abs() <= 1e-15 * plain(&v), "{v:?}");
    }
    assert!((enorm(&[3e200, 4e200]) / 5e200 - 1.0).abs() < 1e-15);
    assert!((enorm(&[3e-200, -4e-200]) / 5e-200 - 1.0).abs() < 1e-15);
    assert!((enorm(&[3e-200, 1.0, 4e200]) / 4e200 - 1.0).abs() < 1e-15);
    assert!(enorm(&[1.0, f64::NAN, 1e300]).is_nan());
    assert_eq!(enorm(&[1.0, f64::INFINITY]), f64::INFINITY);
}

/// Residuals or a Jacobian of the wrong size are refused, not a panic.
struct Resizer {
    residuals_at: usize,
    jacobian: bool,
    calls: usize,
}

impl LeastSquaresProblem for Resizer {
    fn residual_count(&self) -> usize {
        3
    }
    fn residuals(&mut self, x: &DVector<f64>, out: &mut DVector<f64>) -> bool {
        self.calls += 1;
        let len = if self.calls == self.residuals_at {
            2
        } else {
            3
        };
        *out = DVector::from_fn(len, |i, _| x[0] - i as f64);
        true
    }
    fn jacobian(&mut self, _: &DVector<f64>, out: &mut DMatrix<f64>) -> bool {
        *out = DMatrix::from_element(3, if self.jacobian { 2 } else { 1 }, 1.0);
        true
    }
}

#[test]
fn residuals_or_a_jacobian_of_the_wrong_size_are_refused() {
    for (residuals_at, jacobian) in [(1, false), (2, false), (0, true)] {
        let mut p = Resizer {
            residuals_at,
            jacobian,
            calls: 0,
        };
        let r = minimize(
            &mut p,
            &DVector::from_element(1, 10.0),
            &Settings::default(),
        );
        assert!(
            matches!(r.termination, Termination::InvalidInput(_)),
            "{r:?}"
        );
        assert!(r.termination.was_usage_issue() && r.x[0].is_finite());
    }
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(500))]
    /// Random quadratic problems (entries over twelve decades, with zeros;
    /// starts up to 1e6) and settings: no panic, the evaluations within
    /// `patience · (n + 1)`, and unless a usage issue, a finite point whose
    /// cost is at most the start's.
    #[test]
    fn any_problem_ends_within_its_patience_at_a_finite_point(
        n in 1usize..=4,
        extra in 0usize..=4,
        entries in proptest::collection::vec((-1.0f64..1.0, -6i32..6, 0u8..6), 3 * 8 * 4),
        start in proptest::collection::vec((-1.0f64..1.0, 0i32..7), 4),
        tolerances in proptest::collection::vec(proptest::sample::select(vec![0.0, 1e-16, 1e-8, 1e-2]), 3),
        factor in proptest::sample::select(vec![1e-3, 1.0, 100.0]),
        patience in 1usize..30,
    ) {
        let m = n + extra;
        let v = |k: usize| {
            let (x, e, z) = entries[k];
            if z == 0 { 0.0 } else { x * 10f64.powi(e) }
        };
        let (a, q) = (|i: usize, j: usize| v(i * 4 + j), |i: usize| v(64 + i));
        let c = |i: usize| v(80 + i);
        let mut p = Closures {
            m,
            f: |x: &[f64], f: &mut [f64]| {
                for (i, fi) in f.iter_mut().enumerate() {
                    let linear: f64 = (0..n).map(|j| a(i, j) * x[j]).sum();
                    *fi = linear + c(i) + q(i) * x[i % n] * x[i % n];
                }
            },
            g: |x: &[f64], jac: &mut DMatrix<f64>| {
                for i in 0..m {
                    for j in 0..n {
                        jac[(i, j)] = a(i, j);
                    }
                    jac[(i, i % n)] += 2.0 * q(i) * x[i % n];
                }
            },
        };
        let x0 = DVector::from_iterator(n, start.iter().take(n).map(|(x, e)| x * 10f64.powi(*e)));
        let settings = Settings {
            ftol: tolerances[0],
            xtol: tolerances[1],
            gtol: tolerances[2],
            factor,
            patience,
        };
        let mut f0 = DVector::zeros(m);
        p.residuals(&x0, &mut f0);
        let start_cost = 0.5 * enorm(f0.as_slice()).powi(2);
        let r = minimize(&mut p, &x0, &settings);
        proptest::prop_assert!(r.evaluations <= patience * (n + 1), "{r:?}");
        if !r.termination.was_usage_issue() {
            proptest::prop_assert!(r.x.iter().all(|v| v.is_finite()), "{r:?}");
            proptest::prop_assert!(r.objective.is_finite(), "{r:?}");
            proptest::prop_assert!(r.objective <= start_cost, "{r:?} from {start_cost}");
        }
    }
}
