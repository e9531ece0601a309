//! The H∞ norm of a stable model: Bruinsma and Steinbuch's (1990) iteration
//! on the imaginary-axis eigenvalues of a Hamiltonian matrix, after Boyd,
//! Balakrishnan and Kabamba (1989), in continuous time; a discrete model
//! goes through the bilinear (Tustin) map, which keeps the norm.

use nalgebra::{Complex, DMatrix, linalg::Cholesky};

use super::super::{ITERATIONS_PER_DIM, eigenvalues_dyn, singular_values};
use super::HINF_RTOL;
use crate::error::Error;
use crate::freq::Evaluator;
use crate::kernels::linalg::Lu;
use crate::kernels::reduce::pow2_floor;

type C64 = Complex<f64>;

/// Hamiltonian eigenvalue problems allowed (Bruinsma–Steinbuch converges
/// quadratically: 2 to 6 on the fixtures).
pub(super) const MAX_ITERATIONS: usize = 50;

/// An eigenvalue `λ` of the Hamiltonian counts as imaginary when
/// `|Re λ| ≤ AXIS_RTOL |λ| + AXIS_ATOL ‖H‖_F`. Generous on purpose: a
/// pair that truly sits on the axis, close to a double eigenvalue near the
/// peak, is computed up to `√ε ‖H‖` off it, and missing it would stop the
/// iteration below the norm; an eigenvalue wrongly taken costs only a
/// frequency evaluation, whose value decides (see [`continuous`]).
const AXIS_RTOL: f64 = 1e-6;
const AXIS_ATOL: f64 = 1e-7;

/// The first lower bound's grid: points per decade over the poles' range
/// (a decade beyond each end), and at most this many.
const GRID_PER_DECADE: f64 = 8.0;
const GRID_MAX: f64 = 200.0;

/// The operation named in errors.
pub(super) const OPERATION: &str = "H∞ norm (Bruinsma–Steinbuch iteration)";

/// The largest singular value found and where: `omega = None` is `ω → ∞`
/// (the value is then `σ̄(D)`).
#[derive(Debug, Clone, Copy)]
pub(super) struct Peak {
    pub(super) value: f64,
    pub(super) omega: Option<f64>,
}

impl Peak {
    /// Takes `(value, omega)` if `value` is strictly larger.
    fn raise(&mut self, value: f64, omega: Option<f64>) {
        if value > self.value {
            *self = Peak { value, omega };
        }
    }
}

/// The peak gain of the stable continuous `(a, b, c, d)` (checked: finite,
/// consistent shapes) whose poles are `poles`.
pub(super) fn continuous(
    a: &DMatrix<f64>,
    b: &DMatrix<f64>,
    c: &DMatrix<f64>,
    d: &DMatrix<f64>,
    poles: &[C64],
) -> Result<Peak, Error> {
    let (m, p) = (b.ncols(), c.nrows());
    let sigma_d = singular_values(d, "D")?.into_iter().fold(0.0, f64::max);
    if m == 0 || p == 0 {
        return Ok(Peak {
            value: 0.0,
            omega: Some(0.0),
        });
    }
    if a.is_empty() || b.amax() == 0.0 || c.amax() == 0.0 {
        // G = D at every frequency.
        return Ok(Peak {
            value: sigma_d,
            omega: Some(0.0),
        });
    }
    // Exact scalings by powers of two: time by α (G'(s) = G(α s), so
    // frequencies scale by 1/α), B and C to entries in [1, 2).
    let alpha = pow2_floor(a.amax());
    let a = a / alpha;
    let b = b / alpha;
    let (beta, kappa) = (pow2_floor(b.amax()), pow2_floor(c.amax()));
    let (b, c) = (b / beta, c / kappa);
    let d = d / beta / kappa;
    if d.iter().any(|v| !v.is_finite()) || b.iter().any(|v| !v.is_finite()) {
        return Err(Error::Overflow {
            operation: OPERATION,
        });
    }
    let gain = beta * kappa;
    let peak = scaled(&a, &b, &c, &d, sigma_d / gain, poles, alpha)?;
    let value = peak.value * gain;
    if !value.is_finite() {
        return Err(Error::Overflow {
            operation: OPERATION,
        });
    }
    Ok(Peak {
        value,
        omega: peak.omega.map(|w| w * alpha),
    })
}

/// [`continuous`] on the scaled model (`poles` still unscaled, divided by
/// `alpha` here).
fn scaled(
    a: &DMatrix<f64>,
    b: &DMatrix<f64>,
    c: &DMatrix<f64>,
    d: &DMatrix<f64>,
    sigma_d: f64,
    poles: &[C64],
    alpha: f64,
) -> Result<Peak, Error> {
    let (m, p) = (b.ncols(), c.nrows());
    let mut evaluator = Evaluator::new(a, b, c, d);
    let mut g = vec![C64::new(0.0, 0.0); p * m];
    let mut sigma = |w: f64| -> Result<f64, Error> {
        evaluator.eval(C64::new(0.0, w), &mut g)?;
        largest_singular_value(&g, p, m)
    };
    // Lower bound: ω = 0, each pole's |λ| (a lightly damped pair peaks
    // near it), a coarse logarithmic grid over the poles' range, then
    // ω → ∞ (σ̄(D)), kept only if strictly larger. A good first bound
    // keeps `γ² I − DᵀD` away from singular and the crossings found.
    let mut best = Peak {
        value: sigma(0.0)?,
        omega: Some(0.0),
    };
    let mut candidates: Vec<f64> = poles.iter().map(|l| l.norm() / alpha).collect();
    let (lo, hi) = candidates
        .iter()
        .filter(|w| **w > 0.0)
        .fold((f64::INFINITY, 0.0f64), |(lo, hi), &w| {
            (lo.min(w), hi.max(w))
        });
    if lo <= hi {
        let (lo, hi) = ((lo / 10.0).log10(), (hi * 10.0).log10());
        let count = ((hi - lo) * GRID_PER_DECADE).ceil().clamp(2.0, GRID_MAX) as usize;
        candidates
            .extend((0..count).map(|i| 10f64.powf(lo + (hi - lo) * i as f64 / (count - 1) as f64)));
    }
    for w in candidates {
        best.raise(sigma(w)?, Some(w));
    }
    best.raise(sigma_d, None);
    for _ in 0..MAX_ITERATIONS {
        // γ = 0 would be no test: G ≡ 0 to rounding is tested at ε (the
        // data are scaled to entries near 1).
        let gamma = if best.value > 0.0 {
            best.value * (1.0 + 2.0 * HINF_RTOL)
        } else {
            f64::EPSILON
        };
        let h = hamiltonian(a, b, c, d, gamma)?;
        let tol = AXIS_ATOL * h.norm();
        let mut omegas: Vec<f64> = eigenvalues_dyn(&h)?
            .into_iter()
            .filter(|l| l.im >= 0.0 && l.re.abs() <= AXIS_RTOL * l.norm() + tol)
            .map(|l| l.im)
            .collect();
        omegas.sort_by(f64::total_cmp);
        // Between two consecutive crossings a singular value stays above
        // or below γ; where σ̄ > γ, any point between shows it. No such
        // point above γ: no crossing (or only spurious ones), the norm is
        // below γ. The crossings themselves are evaluated too (near the
        // peak they are next to it).
        let mut crossed = false;
        let midpoints = omegas.windows(2).map(|pair| match pair[0] > 0.0 {
            // Geometric: a crossing interval can span decades.
            true => (pair[0] * pair[1]).sqrt(),
            false => 0.5 * (pair[0] + pair[1]),
        });
        for w in midpoints.chain(omegas.iter().copied()) {
            let s = sigma(w)?;
            best.raise(s, Some(w));
            crossed |= s > gamma;
        }
        if !crossed {
            return Ok(best);
        }
    }
    Err(Error::NoConvergence {
        operation: OPERATION,
        iterations: MAX_ITERATIONS,
    })
}

/// `σ̄` of the `p × m` row-major matrix `g`.
fn largest_singular_value(g: &[C64], p: usize, m: usize) -> Result<f64, Error> {
    let s = if p == 1 || m == 1 {
        g.iter().map(|v| v.norm_sqr()).sum::<f64>().sqrt()
    } else {
        let iterations = ITERATIONS_PER_DIM * p.max(m);
        let svd = DMatrix::from_row_slice(p, m, g)
            .try_svd_unordered(false, false, f64::EPSILON, iterations)
            .ok_or(Error::NoConvergence {
                operation: "singular value decomposition (H∞ norm)",
                iterations,
            })?;
        svd.singular_values.iter().copied().fold(0.0, f64::max)
    };
    if s.is_finite() {
        Ok(s)
    } else {
        Err(Error::Overflow {
            operation: OPERATION,
        })
    }
}

/// The Hamiltonian whose imaginary eigenvalues `jω` are the frequencies
/// where `γ` is a singular value of `G(jω)` (for `γ > σ̄(D)`):
/// `[F, γ B R⁻¹ Bᵀ; −γ Cᵀ S⁻¹ C, −Fᵀ]`, `F = A + B R⁻¹ Dᵀ C`,
/// `R = γ² I − Dᵀ D`, `S = γ² I − D Dᵀ` (python-control's matrix, similar
/// to it by `diag(I, γ I)`, which evens the off-diagonal blocks).
fn hamiltonian(
    a: &DMatrix<f64>,
    b: &DMatrix<f64>,
    c: &DMatrix<f64>,
    d: &DMatrix<f64>,
    gamma: f64,
) -> Result<DMatrix<f64>, Error> {
    let n = a.nrows();
    let g2 = gamma * gamma;
    let shifted = |dd: DMatrix<f64>| {
        let k = dd.nrows();
        DMatrix::identity(k, k) * g2 - dd
    };
    let singular = Error::Singular {
        operation: "H∞ norm (γ² I − Dᵀ D at γ near σ̄(D))",
    };
    let r = Cholesky::new(shifted(d.transpose() * d)).ok_or(singular.clone())?;
    let s = Cholesky::new(shifted(d * d.transpose())).ok_or(singular)?;
    let rb = r.solve(&b.transpose()); // R⁻¹ Bᵀ, m × n
    let f = a + &rb.transpose() * d.transpose() * c; // R⁻¹ symmetric
    let top = b * &rb * gamma;
    let bottom = c.transpose() * s.solve(c) * (-gamma);
    let mut h = DMatrix::zeros(2 * n, 2 * n);
    h.view_mut((0, 0), (n, n)).copy_from(&f);
    h.view_mut((0, n), (n, n)).copy_from(&top);
    h.view_mut((n, 0), (n, n)).copy_from(&bottom);
    h.view_mut((n, n), (n, n)).copy_from(&(-f.transpose()));
    if h.iter().all(|v| v.is_finite()) {
        Ok(h)
    } else {
        Err(Error::Overflow {
            operation: OPERATION,
        })
    }
}

/// The peak gain of the stable discrete `(a, b, c, d)` with period `dt`
/// and poles `poles` (`z`-plane): the bilinear map
/// `s = (2/dt) (z − 1)/(z + 1)` takes it to a continuous model with the
/// same values on the axis, `G_c(jω_c) = G_d(e^(jω dt))` with
/// `ω_c = (2/dt) tan(ω dt / 2)`; its peak is mapped back
/// (`ω → ∞` to the Nyquist frequency `π/dt`).
pub(super) fn discrete(
    a: &DMatrix<f64>,
    b: &DMatrix<f64>,
    c: &DMatrix<f64>,
    d: &DMatrix<f64>,
    dt: f64,
    poles: &[C64],
) -> Result<Peak, Error> {
    let n = a.nrows();
    let k = 2.0 / dt;
    // M = (I + A)⁻¹: A_c = k (A − I) M, B_c = √(2k) M B, C_c = √(2k) C M,
    // D_c = D − C M B.
    let minv = Lu::new(
        &(DMatrix::identity(n, n) + a),
        "H∞ norm (bilinear map: pole at z = −1)",
    )?
    .solve(&DMatrix::identity(n, n));
    let mb = &minv * b;
    let root = (2.0 * k).sqrt();
    let ac = (a - DMatrix::identity(n, n)) * &minv * k;
    let bc = &mb * root;
    let cc = c * &minv * root;
    let dc = d - c * &mb;
    let continuous_poles: Vec<C64> = poles.iter().map(|z| (z - 1.0) / (z + 1.0) * k).collect();
    if [&ac, &bc, &cc, &dc]
        .iter()
        .any(|m| m.iter().any(|v| !v.is_finite()))
    {
        return Err(Error::Overflow {
            operation: "H∞ norm (bilinear map)",
        });
    }
    let peak = continuous(&ac, &bc, &cc, &dc, &continuous_poles)?;
    Ok(Peak {
        value: peak.value,
        omega: Some(match peak.omega {
            Some(w) => k * (w / k).atan(),
            None => std::f64::consts::PI / dt,
        }),
    })
}
