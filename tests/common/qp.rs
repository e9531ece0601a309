//! Quadratic programs for `DenseQp`'s tests: the fixtures of
//! `tests/data/qp_fixtures.json` and the
//! optimality certificate (KKT conditions) computed here, independently of
//! the solver.

use ctrlab::design::mpc::{DenseQp, QpReport, QpSettings, Row};
use nalgebra::{DMatrix, DVector};
use serde_json::Value;

/// `min ½ xᵀ P x + qᵀ x + Σ_soft penalty` subject to `l ≤ G x ≤ u`
/// (hard rows).
#[derive(Debug, Clone)]
pub struct Qp {
    pub p: DMatrix<f64>,
    pub q: Vec<f64>,
    pub g: DMatrix<f64>,
    pub lower: Vec<f64>,
    pub upper: Vec<f64>,
    pub rows: Vec<Row>,
}

impl Qp {
    pub fn n(&self) -> usize {
        self.p.nrows()
    }

    pub fn m(&self) -> usize {
        self.g.nrows()
    }

    /// A solver of this problem.
    pub fn solver(&self, settings: QpSettings) -> DenseQp {
        DenseQp::new(&self.p, &self.g, &self.rows, settings).expect("a valid problem")
    }

    /// The objective with the soft penalties at `x`, computed here.
    pub fn objective(&self, x: &[f64]) -> f64 {
        let xv = DVector::from_column_slice(x);
        let gx = &self.g * &xv;
        let mut f = 0.5 * xv.dot(&(&self.p * &xv)) + xv.dot(&DVector::from_column_slice(&self.q));
        for (i, row) in self.rows.iter().enumerate() {
            if let Row::Soft { linear, quadratic } = *row {
                let d = (self.lower[i] - gx[i]).max(gx[i] - self.upper[i]).max(0.0);
                f += linear * d + 0.5 * quadratic * d * d;
            }
        }
        f
    }
}

fn bound(v: &Value, infinity: f64) -> f64 {
    v.as_f64().unwrap_or(infinity)
}

/// A case of `qp_fixtures.json`: the problem, OSQP's `x`, its objective,
/// and whether `x` is unique.
pub struct QpFixture {
    pub name: String,
    pub qp: Qp,
    pub x: Vec<f64>,
    pub objective: f64,
    pub x_unique: bool,
}

pub fn qp_fixtures() -> Vec<QpFixture> {
    let data = super::fixture("qp_fixtures.json");
    let floats = |v: &Value| -> Vec<f64> { super::floats(v) };
    data["cases"]
        .as_array()
        .expect("cases")
        .iter()
        .map(|c| {
            let rows = c["rows"]
                .as_array()
                .expect("rows")
                .iter()
                .map(|r| {
                    if r.get("hard").is_some() {
                        Row::Hard
                    } else {
                        Row::Soft {
                            linear: r["linear"].as_f64().expect("linear"),
                            quadratic: r["quadratic"].as_f64().expect("quadratic"),
                        }
                    }
                })
                .collect();
            let infinite = |key: &str, inf: f64| -> Vec<f64> {
                c[key]
                    .as_array()
                    .expect("bounds")
                    .iter()
                    .map(|v| bound(v, inf))
                    .collect()
            };
            QpFixture {
                name: c["name"].as_str().expect("name").to_owned(),
                qp: Qp {
                    p: super::dmatrix(&c["p"]),
                    q: floats(&c["q"]),
                    g: super::dmatrix(&c["g"]),
                    lower: infinite("lower", f64::NEG_INFINITY),
                    upper: infinite("upper", f64::INFINITY),
                    rows,
                },
                x: floats(&c["x"]),
                objective: c["objective"].as_f64().expect("objective"),
                x_unique: c["x_unique"].as_bool().expect("x_unique"),
            }
        })
        .collect()
}

/// How far `(x, y)` is from satisfying the problem's optimality
/// conditions, each measure relative to its tolerance (≤ 1: holds). The
/// tolerances are OSQP's termination criterion, the solver's own notion of
/// "solved": residuals in the ∞-norm relative to the largest of their terms.
#[derive(Debug, Clone, Copy)]
pub struct Kkt {
    /// `‖P x + q + Gᵀ y‖∞ / (eps_abs + eps_rel · max(‖P x‖, ‖q‖, ‖Gᵀ y‖))`.
    pub stationarity: f64,
    /// The hard rows' worst violation of `[l, u]` over
    /// `δ = eps_abs + eps_rel · ‖G x‖∞`.
    pub feasibility: f64,
    /// Each multiplier's distance from the subdifferential of its row's
    /// penalty (the hard rows': the normal cone of `[l, u]`; the soft
    /// rows': `[0, linear]` at the upper bound, `linear + quadratic · d`
    /// beyond it, 0 inside, mirrored below) taken over `gᵢ x ± δ`, over
    /// `eps_abs + eps_rel · ‖y‖∞`: complementary slackness and the
    /// multipliers' signs in one number.
    pub multipliers: f64,
}

impl Kkt {
    pub fn worst(&self) -> f64 {
        self.stationarity
            .max(self.feasibility)
            .max(self.multipliers)
    }
}

/// The interval of multipliers a row admits at values in `[v − δ, v + δ]`
/// (the subdifferential is monotone, so it runs from its lower end at
/// `v − δ` to its upper end at `v + δ`).
fn admissible(row: Row, l: f64, u: f64, v: f64, delta: f64) -> (f64, f64) {
    let (lo_v, hi_v) = (v - delta, v + delta);
    match row {
        Row::Hard => (
            if lo_v > l { 0.0 } else { f64::NEG_INFINITY },
            if hi_v < u { 0.0 } else { f64::INFINITY },
        ),
        Row::Soft { linear, quadratic } => {
            let lo = if lo_v > u {
                linear + quadratic * (lo_v - u)
            } else if lo_v > l {
                0.0
            } else {
                -(linear + quadratic * (l - lo_v))
            };
            let hi = if hi_v < l {
                -(linear + quadratic * (l - hi_v))
            } else if hi_v < u {
                0.0
            } else {
                linear + quadratic * (hi_v - u)
            };
            (lo, hi)
        }
    }
}

/// The KKT conditions of `qp` at `(x, y)` with tolerances `eps_abs`,
/// `eps_rel`.
pub fn kkt(qp: &Qp, x: &[f64], y: &[f64], eps_abs: f64, eps_rel: f64) -> Kkt {
    let xv = DVector::from_column_slice(x);
    let yv = DVector::from_column_slice(y);
    let px = &qp.p * &xv;
    let gty = qp.g.transpose() * &yv;
    let q = DVector::from_column_slice(&qp.q);
    let r = &px + &q + &gty;
    let scale = px.amax().max(q.amax()).max(gty.amax());
    let stationarity = r.amax() / (eps_abs + eps_rel * scale);
    let gx = &qp.g * &xv;
    let delta = eps_abs + eps_rel * gx.amax();
    let ytol = eps_abs + eps_rel * yv.amax();
    let (mut feasibility, mut multipliers) = (0.0f64, 0.0f64);
    for i in 0..qp.m() {
        let (l, u, v) = (qp.lower[i], qp.upper[i], gx[i]);
        if qp.rows[i] == Row::Hard {
            feasibility = feasibility.max((l - v).max(v - u).max(0.0) / delta);
        }
        let (lo, hi) = admissible(qp.rows[i], l, u, v, delta);
        multipliers = multipliers.max((lo - y[i]).max(y[i] - hi).max(0.0) / ytol);
    }
    Kkt {
        stationarity,
        feasibility,
        multipliers,
    }
}

// Assertions shared by `tests/qp.rs`.

/// `max |a − b| / max(1, ‖b‖∞)`.
pub fn rel_diff(a: &[f64], b: &[f64]) -> f64 {
    let scale = b.iter().fold(1.0f64, |m, v| m.max(v.abs()));
    a.iter()
        .zip(b)
        .fold(0.0f64, |m, (p, q)| m.max((p - q).abs()))
        / scale
}

/// Every number of a solve's answer is finite and its iterations within
/// the bound.
pub fn assert_finite(qp: &DenseQp, report: &QpReport, max_iterations: usize) {
    assert!(report.iterations <= max_iterations, "{report:?}");
    for v in [
        report.primal_residual,
        report.dual_residual,
        report.objective,
        report.rho,
    ] {
        assert!(v.is_finite(), "{report:?}");
    }
    assert!(qp.solution().iter().all(|v| v.is_finite()), "{report:?}");
    assert!(qp.multipliers().iter().all(|v| v.is_finite()), "{report:?}");
}

/// The certificate at the solver's own tolerances (OSQP's criterion: the
/// ∞-norm residuals relative to the largest of their terms), a factor 2
/// for the rounding of the test's own products.
pub fn kkt_holds(qp: &Qp, solver: &DenseQp, s: &QpSettings) -> Result<(), String> {
    let k = kkt(
        qp,
        solver.solution(),
        solver.multipliers(),
        s.eps_abs,
        s.eps_rel,
    );
    if k.worst() <= 2.0 {
        Ok(())
    } else {
        Err(format!("{k:?}"))
    }
}

pub fn assert_kkt(qp: &Qp, solver: &DenseQp, s: &QpSettings, what: &str) {
    if let Err(e) = kkt_holds(qp, solver, s) {
        panic!("{what}: {e}");
    }
}

/// An `Err` whose message names `what`.
pub fn assert_names<T: std::fmt::Debug>(r: Result<T, ctrlab::Error>, what: &str) {
    match r {
        Err(e) => assert!(e.to_string().contains(what), "{e} does not name {what}"),
        Ok(v) => panic!("accepted, expected an error naming {what}: {v:?}"),
    }
}
