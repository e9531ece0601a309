//! The discrete Sylvester (Stein) equation `A X B − X + C = 0`.

use nalgebra::DMatrix;

use super::bartels_stewart::{Condition, quasi_stein, schur, singular_pair};
use super::{Lyapunov, SquareMatrix, SylvesterOperands, back, pair_equation, relative, unscale};
use crate::error::Error;
use crate::kernels::reduce::pow2_floor;

/// Discrete Sylvester (Stein) equation `A X B − X + C = 0`: its solution
/// `X` (`m × n`, `A` `m × m`, `B` `n × n`), MATLAB's `dlyap(A, B, C)`;
/// python-control's `dlyap(A, Q, C)` solves `A X Qᵀ − X + C = 0`, that is
/// `dsylvester(a, qᵀ, c)`. With `B = Aᵀ` it is [`dlyap`](super::dlyap).
///
/// The solution is unique unless an eigenvalue `λ` of `A` and an
/// eigenvalue `μ` of `B` have the product `λ μ = 1`. Bartels–Stewart on
/// the Schur forms of `A` and `Bᵀ` with Barraud's back-substitution,
/// `O(m³ + n³ + m n (m + n))`; `A` and `B` are first balanced by a power
/// of two (`A / 2^k`, `B 2^k`, which leaves `A X B` unchanged), and the
/// singularity test is [`dlyap`](super::dlyap)'s:
/// `|λ μ − 1| ≤ 100 max(m, n) ε (1 + ‖S‖_F)(1 + ‖T‖_F)` on the balanced
/// Schur factors. [`Lyapunov::residual`] is
/// `‖A X B − X + C‖_F / (‖A X B‖_F + ‖X‖_F + ‖C‖_F)`.
///
/// # Errors
///
/// [`Error::DimensionMismatch`] naming `A`, `B` or `C` if a shape is
/// wrong (run-time sizes only); [`Error::NonFinite`] for a NaN or infinite
/// entry; [`Error::SingularEquation`] naming `λ` of `A` and `μ` of `B`
/// with `λ μ = 1`; [`Error::NoConvergence`] if a Schur iteration fails;
/// [`Error::Overflow`] if `X` does not fit in `f64`.
///
/// # Examples
///
/// ```
/// use ctrlab::analysis::dsylvester;
/// use ctrlab::nalgebra::{dmatrix, matrix};
///
/// // Scalars: a x b − x + c = 0 gives x = c / (1 − a b).
/// let sol = dsylvester(&matrix![0.5], &matrix![-0.8], &matrix![2.8])?;
/// assert!((sol.x[(0, 0)] - 2.0).abs() < 1e-15);
///
/// // Run-time sizes: A 3 × 3, B 2 × 2 (a complex pair), C 3 × 2.
/// let a = dmatrix![0.5, 0.1, 0.0; -0.2, 0.3, 0.4; 0.0, 0.1, -0.6];
/// let b = dmatrix![0.2, -0.9; 0.9, 0.2];
/// let c = dmatrix![1.0, 2.0; 3.0, 4.0; 5.0, 6.0];
/// let sol = dsylvester(&a, &b, &c)?;
/// assert!((&a * &sol.x * &b - &sol.x + &c).amax() < 1e-14);
/// assert!(sol.residual < 1e-15);
///
/// // λ = 2 of A and μ = 0.5 of B: λ μ = 1, no unique solution.
/// assert!(matches!(
///     dsylvester(&matrix![2.0], &matrix![0.5], &matrix![1.0]),
///     Err(ctrlab::Error::SingularEquation { .. })
/// ));
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[doc(alias = "dlyap")]
#[doc(alias = "stein")]
#[doc(alias = "discrete_sylvester")]
pub fn dsylvester<A, B>(a: &A, b: &B, c: &A::Rhs) -> Result<Lyapunov<A::Rhs>, Error>
where
    A: SylvesterOperands<B>,
    B: SquareMatrix,
{
    pair_equation(a, b, c, stein)
}

/// [`dsylvester`] on checked, finite data of matching shapes.
fn stein(
    a: &DMatrix<f64>,
    b: &DMatrix<f64>,
    c: &DMatrix<f64>,
) -> Result<(DMatrix<f64>, f64), Error> {
    const EQUATION: &str = "discrete Sylvester (Stein) equation A X B − X + C = 0";
    let (m, n) = (a.nrows(), b.nrows());
    if m == 0 || n == 0 {
        return Ok((DMatrix::zeros(m, n), 0.0));
    }
    // A / α and B α with α = 2^k halfway between their magnitudes
    // (exponents, so that no ratio overflows); exact.
    let exponent = |v: f64| pow2_floor(v).log2() as i32;
    let alpha = if a.amax() > 0.0 && b.amax() > 0.0 {
        2f64.powi((exponent(a.amax()) - exponent(b.amax())) / 2)
    } else {
        1.0
    };
    let gamma = pow2_floor(c.amax());
    let (a, b, c) = (a / alpha, b * alpha, c / gamma);
    let (sa, sb) = (schur(&a)?, schur(&b.transpose())?);
    if let Some((l, mu)) = singular_pair(&sa, &sb, Condition::Product) {
        return Err(Error::SingularEquation {
            equation: EQUATION,
            lambda_re: l.re * alpha,
            lambda_im: l.im * alpha,
            mu_re: mu.re / alpha,
            mu_im: mu.im / alpha,
            condition: "λ μ = 1",
        });
    }
    // A = U S Uᵀ, Bᵀ = V T Vᵀ: S Y Tᵀ − Y + Uᵀ C V = 0 for Y = Uᵀ X V.
    let mut y = sa.u.transpose() * &c * &sb.u;
    quasi_stein(&sa.t, &sa.blocks, &sb.t, &sb.blocks, &mut y);
    let x = back(&sa, &y, &sb, false);
    let axb = &a * &x * &b;
    let r = (&axb - &x + &c).norm();
    let residual = relative(r, &[axb.norm(), x.norm(), c.norm()]);
    Ok((unscale(x, gamma, 1.0, EQUATION)?, residual))
}
