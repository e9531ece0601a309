//! The condensed form of a linear MPC problem: the predictions as linear
//! maps of the initial deviation and the input sequence, and the QP's
//! fixed matrices built from them once, at design time.

use nalgebra::{DMatrix, DVector};

use super::qp::Row;

/// Output limits as rows: `lower ≤ c x ≤ upper` on the predicted state
/// at every step `1..=H`, each row hard or soft.
#[derive(Debug, Clone)]
pub(super) struct OutputRows {
    /// `L × N`.
    pub(super) c: DMatrix<f64>,
    pub(super) lower: DVector<f64>,
    pub(super) upper: DVector<f64>,
    pub(super) kind: Vec<Row>,
}

/// What the controller needs every tick, all fixed at design time. The
/// decision variable is `δU = [δu₀; …; δu_{H−1}]`, the inputs' deviation
/// from their steady-state target; the predicted deviations are
/// `δX = Φ δx₀ + Γ δU`.
#[derive(Debug, Clone)]
pub(super) struct Condensed {
    pub(super) horizon: usize,
    /// The QP's Hessian `2 (Γᵀ Q̄ Γ + R̄ + Dᵀ S̄ D)` (`MH × MH`).
    pub(super) hessian: DMatrix<f64>,
    /// `q = Fx δx₀ + Fu (u_s − u_prev)`: `2 Γᵀ Q̄ Φ` and `2 Dᵀ S̄ E₀`.
    pub(super) fx: DMatrix<f64>,
    pub(super) fu: DMatrix<f64>,
    /// The constraint rows: `MH` input rows, `rate_rows` rate rows, then
    /// `L H` output rows (step by step, each step's `L` rows together).
    pub(super) g: DMatrix<f64>,
    pub(super) kinds: Vec<Row>,
    /// Whether the rate rows are present (any finite rate limit).
    pub(super) rate_rows: usize,
    /// `C_c Φ` (`L H × N`): the output rows' free response to `δx₀`.
    pub(super) output_free: DMatrix<f64>,
    /// Each row's scale (applied to `g` and to be applied to its bounds):
    /// one over the span of its limits, so a residual means the same
    /// fraction of every limit's range whatever its units (V, m).
    pub(super) row_scale: DVector<f64>,
}

/// One over a limit's span: `max − min` where finite, else the finite
/// one's magnitude, else 1.
pub(super) fn span_scale(min: f64, max: f64) -> f64 {
    let span = if min.is_finite() && max.is_finite() {
        max - min
    } else if min.is_finite() {
        min.abs()
    } else if max.is_finite() {
        max.abs()
    } else {
        1.0
    };
    if span > 0.0 && span.is_finite() {
        1.0 / span
    } else {
        1.0
    }
}

impl Condensed {
    /// Builds the condensed problem of `x⁺ = A x + B u` over `horizon`
    /// steps with stage weights `q`, `r`, rate weight `s`, terminal weight
    /// `p`, the input limits' and rate limits' row scales (`M` each; no
    /// rate rows if `rate_scale` is `None`), and the output rows.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn new(
        a: &DMatrix<f64>,
        b: &DMatrix<f64>,
        q: &DMatrix<f64>,
        r: &DMatrix<f64>,
        s: &DMatrix<f64>,
        p: &DMatrix<f64>,
        horizon: usize,
        input_scale: &[f64],
        rate_scale: Option<&[f64]>,
        outputs: &OutputRows,
    ) -> Self {
        let (n, m, h) = (a.nrows(), b.ncols(), horizon);
        let l = outputs.c.nrows();
        // Φ: A^k stacked, k = 1..H; Γ block lower triangular with
        // Γ[k][j] = A^{k−1−j} B (row block k is δx_{k+1}).
        let mut phi = DMatrix::zeros(n * h, n);
        let mut gamma = DMatrix::zeros(n * h, m * h);
        let mut power = a.clone();
        let mut ab = b.clone(); // A^{k} B as k grows
        for k in 0..h {
            phi.view_mut((n * k, 0), (n, n)).copy_from(&power);
            for j in 0..h - k {
                // Block (k + j, j) = A^k B.
                gamma.view_mut((n * (k + j), m * j), (n, m)).copy_from(&ab);
            }
            power = a * &power;
            ab = a * &ab;
        }
        // Q̄ = diag(Q, …, Q, P); R̄, S̄ block diagonal; D the first
        // difference (I on the diagonal, −I below).
        let mut qbar = DMatrix::zeros(n * h, n * h);
        for k in 0..h {
            let w = if k + 1 == h { p } else { q };
            qbar.view_mut((n * k, n * k), (n, n)).copy_from(w);
        }
        let mut rbar = DMatrix::zeros(m * h, m * h);
        let mut sbar = DMatrix::zeros(m * h, m * h);
        let mut diff = DMatrix::zeros(m * h, m * h);
        for k in 0..h {
            rbar.view_mut((m * k, m * k), (m, m)).copy_from(r);
            sbar.view_mut((m * k, m * k), (m, m)).copy_from(s);
            diff.view_mut((m * k, m * k), (m, m)).fill_with_identity();
            if k > 0 {
                let mut below = diff.view_mut((m * k, m * (k - 1)), (m, m));
                below.fill_with_identity();
                below.neg_mut();
            }
        }
        let qg = &qbar * &gamma;
        let sd = &sbar * &diff;
        let mut hessian = (gamma.transpose() * &qg + &rbar + diff.transpose() * &sd) * 2.0;
        // Exactly symmetric (the products round differently above and
        // below the diagonal).
        hessian = (&hessian + hessian.transpose()) * 0.5;
        let fx = qg.transpose() * &phi * 2.0;
        // E₀ = [I; 0; …]: Dᵀ S̄ E₀ is the first block column of Dᵀ S̄.
        let fu = (diff.transpose() * &sbar).columns(0, m) * 2.0;

        let rate_rows = if rate_scale.is_some() { m * h } else { 0 };
        let mut g = DMatrix::zeros(m * h + rate_rows + l * h, m * h);
        g.view_mut((0, 0), (m * h, m * h)).fill_with_identity();
        if rate_scale.is_some() {
            g.view_mut((m * h, 0), (m * h, m * h)).copy_from(&diff);
        }
        let mut output_free = DMatrix::zeros(l * h, n);
        for k in 0..h {
            let rows = m * h + rate_rows + l * k;
            let step = outputs.c.clone() * gamma.view((n * k, 0), (n, m * h));
            g.view_mut((rows, 0), (l, m * h)).copy_from(&step);
            output_free
                .view_mut((l * k, 0), (l, n))
                .copy_from(&(&outputs.c * phi.view((n * k, 0), (n, n))));
        }
        let output_scale: Vec<f64> = (0..l)
            .map(|j| span_scale(outputs.lower[j], outputs.upper[j]))
            .collect();
        let mut row_scale = Vec::with_capacity(g.nrows());
        for _ in 0..h {
            row_scale.extend_from_slice(input_scale);
        }
        if let Some(rate) = rate_scale {
            for _ in 0..h {
                row_scale.extend_from_slice(rate);
            }
        }
        let mut kinds = vec![Row::Hard; m * h + rate_rows];
        for _ in 0..h {
            row_scale.extend_from_slice(&output_scale);
            // A scaled row's violation is `scale` times the original's.
            kinds.extend(
                outputs
                    .kind
                    .iter()
                    .zip(&output_scale)
                    .map(|(k, &sc)| match *k {
                        Row::Hard => Row::Hard,
                        Row::Soft { linear, quadratic } => Row::Soft {
                            linear: linear / sc,
                            quadratic: quadratic / (sc * sc),
                        },
                    }),
            );
        }
        let row_scale = DVector::from_vec(row_scale);
        for (i, &sc) in row_scale.iter().enumerate() {
            g.row_mut(i).scale_mut(sc);
        }
        Self {
            horizon,
            hessian,
            fx,
            fu,
            g,
            kinds,
            rate_rows,
            output_free,
            row_scale,
        }
    }
}
