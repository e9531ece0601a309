//! Lyapunov and Sylvester equations, continuous and discrete, for
//! fixed-size (`SMatrix`) and run-time-sized (`DMatrix`) matrices alike:
//! [`lyap`], [`dlyap`] and [`sylvester`], each with the relative residual
//! of its solution, and [`lyapchol`], Hammarling's Cholesky factor of a
//! stable continuous equation's solution; the discrete Sylvester (Stein)
//! equation [`dsylvester`] in `stein.rs`.

mod bartels_stewart;
mod francis;
mod hammarling;
mod stein;

pub use hammarling::dlyapchol;

use nalgebra::{Complex, DMatrix, SMatrix};

use crate::error::{Error, check_finite_dyn, check_shape};
use crate::kernels::reduce::pow2_floor;
use bartels_stewart::{Condition, Schur, quasi_stein, quasi_sylvester, schur, singular_pair};
pub use stein::dsylvester;

/// The solution `X` of a Lyapunov, Stein (discrete Lyapunov) or Sylvester
/// equation, and how well it satisfies the equation.
///
/// `X` has the type of the data: an `SMatrix` for fixed-size matrices, a
/// `DMatrix` for run-time-sized ones.
///
/// # Algorithm
///
/// Bartels and Stewart (1972): a real Schur decomposition `A = U S Uᵀ`
/// (nalgebra's Francis QR, and where it stalls, as it can on repeated
/// eigenvalues, EISPACK's `hqr2` with its exceptional shifts; each capped
/// at `30 max(n, 10)` iterations, LAPACK's `dlahqr` cap), the
/// equation rewritten for `Y = Uᵀ X U` with the quasi-triangular `S`, and
/// `Y` found block by block by back-substitution (LAPACK's `dtrsyl`; for
/// the discrete equation its analogue, Barraud 1977), each 1×1 or 2×2
/// diagonal block a Kronecker system of at most four unknowns solved by
/// Gaussian elimination with complete pivoting. `O(N³)` in all, no
/// unbounded iteration. The data are first scaled by powers of two (exact),
/// so that no norm overflows. A fixed-size problem is copied to the heap
/// and back: these are design-time computations.
///
/// Before the back-substitution the eigenvalues are checked against the
/// equation's singularity condition: the equation is refused with
/// [`Error::SingularEquation`], naming the two eigenvalues, when
/// `|λᵢ + μⱼ| ≤ 100 n ε (‖S‖_F + ‖T‖_F)` (continuous Lyapunov and
/// Sylvester; `S`, `T` the scaled Schur factors) or
/// `|λᵢ λⱼ − 1| ≤ 100 n ε (1 + ‖S‖_F)²` (discrete Lyapunov): that close,
/// rounding errors alone could put the eigenvalues on the condition.
/// Farther, the equation is solved, and a nearly singular one shows in
/// the size of `X` (its residual stays small).
///
/// # Examples
///
/// ```
/// use ctrlab::analysis::{Lyapunov, lyap};
/// use ctrlab::nalgebra::{Matrix1, matrix};
///
/// // ẋ = −x + u: the Gramian is 1 / 2 (in units of Q times seconds).
/// let sol: Lyapunov<Matrix1<f64>> = lyap(&matrix![-1.0], &matrix![1.0])?;
/// assert!((sol.x[(0, 0)] - 0.5).abs() < 1e-15);
/// assert!(sol.residual < 1e-15);
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lyapunov<X> {
    /// The solution (in the units of `Q` (or `C`) times seconds for a
    /// continuous equation with `A` in 1/s; in the units of `Q` for a
    /// discrete one).
    pub x: X,
    /// Relative residual: the Frobenius norm of the equation's left side
    /// minus its right at `X`, over the sum of the norms of its terms
    /// (`‖A X + X Aᵀ + Q‖ / (‖A X‖ + ‖X Aᵀ‖ + ‖Q‖)` for [`lyap`]);
    /// dimensionless, 0 when every term is zero. A small multiple of
    /// `n ε` (measured at most 3e-14 up to 50 states).
    pub residual: f64,
}

mod sealed {
    use nalgebra::DMatrix;

    /// The conversions behind [`SquareMatrix`](super::SquareMatrix) and
    /// [`SylvesterOperands`](super::SylvesterOperands).
    pub trait Matrix: Sized {
        fn to_heap(&self) -> DMatrix<f64>;
        /// `m` has this type's shape (the solvers keep it).
        fn from_heap(m: DMatrix<f64>) -> Self;
    }
}

impl<const R: usize, const C: usize> sealed::Matrix for SMatrix<f64, R, C> {
    fn to_heap(&self) -> DMatrix<f64> {
        DMatrix::from_column_slice(R, C, self.as_slice())
    }
    fn from_heap(m: DMatrix<f64>) -> Self {
        Self::from_column_slice(m.as_slice())
    }
}

impl sealed::Matrix for DMatrix<f64> {
    fn to_heap(&self) -> DMatrix<f64> {
        self.clone()
    }
    fn from_heap(m: DMatrix<f64>) -> Self {
        m
    }
}

/// The square matrices [`lyap`] and [`dlyap`] take: `SMatrix<f64, N, N>`
/// (sizes checked at compile time) and `DMatrix<f64>` (checked when
/// called). Sealed: implemented for those two only.
///
/// # Examples
///
/// [`lyap`] with a fixed-size and a run-time-sized matrix: the same
/// solution, in the type of the data.
///
/// ```
/// use ctrlab::analysis::lyap;
/// use ctrlab::nalgebra::{DMatrix, Matrix2, dmatrix, matrix};
///
/// let fixed: Matrix2<f64> = lyap(&matrix![-1.0, 0.0; 0.0, -2.0], &Matrix2::identity())?.x;
/// let dynamic: DMatrix<f64> =
///     lyap(&dmatrix![-1.0, 0.0; 0.0, -2.0], &DMatrix::identity(2, 2))?.x;
/// // Diagonal A: xᵢᵢ = 1 / (2 |aᵢᵢ|).
/// assert_eq!(fixed.as_slice(), dynamic.as_slice());
/// assert!((fixed - matrix![0.5, 0.0; 0.0, 0.25]).amax() < 1e-15);
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub trait SquareMatrix: sealed::Matrix {}

impl<const N: usize> SquareMatrix for SMatrix<f64, N, N> {}
impl SquareMatrix for DMatrix<f64> {}

/// The coefficient pairs [`sylvester`] takes: `A` an
/// `SMatrix<f64, M, M>` and `B` an `SMatrix<f64, N, N>` (then `C` and `X`
/// are `SMatrix<f64, M, N>`), or both `DMatrix<f64>`. Sealed.
///
/// # Examples
///
/// [`sylvester`] with fixed sizes (`A` 2 × 2, `B` 1 × 1, so `C` and `X`
/// are 2 × 1) and with run-time sizes.
///
/// ```
/// use ctrlab::analysis::sylvester;
/// use ctrlab::nalgebra::{Vector2, dmatrix, matrix};
///
/// let x: Vector2<f64> = sylvester(&matrix![1.0, 0.0; 0.0, 3.0], &matrix![1.0], &matrix![2.0; 4.0])?.x;
/// assert!((x - matrix![1.0; 1.0]).amax() < 1e-15);
///
/// let (a, b, c) = (dmatrix![1.0, 0.0; 0.0, 3.0], dmatrix![1.0], dmatrix![2.0; 4.0]);
/// let xd = sylvester(&a, &b, &c)?.x;
/// assert_eq!(xd.shape(), (2, 1));
/// assert!((&a * &xd + &xd * &b - &c).amax() < 1e-15);
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub trait SylvesterOperands<B: SquareMatrix>: SquareMatrix {
    /// The type of `C` and of the solution `X`.
    type Rhs: sealed::Matrix;
}

impl<const M: usize, const N: usize> SylvesterOperands<SMatrix<f64, N, N>> for SMatrix<f64, M, M> {
    type Rhs = SMatrix<f64, M, N>;
}

impl SylvesterOperands<DMatrix<f64>> for DMatrix<f64> {
    type Rhs = DMatrix<f64>;
}

/// Continuous Lyapunov equation `A X + X Aᵀ + Q = 0`: its solution `X`
/// (`n × n`), MATLAB's and python-control's `lyap(A, Q)`. SciPy's
/// `solve_continuous_lyapunov(a, q)` solves `A X + X Aᵀ = Q`, the other
/// sign of `Q`: it is `lyap(a, −q)`.
///
/// The solution is unique unless two eigenvalues of `A` add up to zero
/// (an eigenvalue at 0 or on the imaginary axis, or a pair `±λ`); for a
/// stable `A` and `Q = B Bᵀ` it is the controllability Gramian
/// `∫₀^∞ e^{At} B Bᵀ e^{Aᵀt} dt`. A symmetric `Q` (exactly) gives an
/// exactly symmetric `X`. Bartels–Stewart, `O(n³)`: see the
/// [`Lyapunov`](Lyapunov#algorithm).
///
/// # Errors
///
/// [`Error::DimensionMismatch`] for a non-square `A` or a `Q` of another
/// size (run-time sizes only); [`Error::NonFinite`] for a NaN or infinite
/// entry; [`Error::SingularEquation`] with the eigenvalues `λ`, `μ` of `A`
/// for which `λ + μ = 0`; [`Error::NoConvergence`] if the Schur iteration
/// fails; [`Error::Overflow`] if `X` does not fit in `f64`.
///
/// # Examples
///
/// The controllability Gramian of `ẋ = −2 x + 3 u`: `b² / (2 a) = 9 / 4`.
///
/// ```
/// use ctrlab::analysis::lyap;
/// use ctrlab::nalgebra::{dmatrix, matrix};
///
/// let (a, b) = (matrix![-2.0], matrix![3.0]);
/// let gramian = lyap(&a, &(b * b.transpose()))?;
/// assert!((gramian.x[(0, 0)] - 2.25).abs() < 1e-15);
/// assert!(gramian.residual < 1e-15);
///
/// // Sized at run time, the same call; an eigenvalue on the imaginary
/// // axis (an undamped oscillator) is refused.
/// let oscillator = dmatrix![0.0, 1.0; -4.0, 0.0];
/// assert!(matches!(
///     lyap(&oscillator, &dmatrix![1.0, 0.0; 0.0, 1.0]),
///     Err(ctrlab::Error::SingularEquation { .. })
/// ));
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[doc(alias = "solve_continuous_lyapunov")]
#[doc(alias = "lyapunov")]
pub fn lyap<M: SquareMatrix>(a: &M, q: &M) -> Result<Lyapunov<M>, Error> {
    square_equation(a, q, continuous)
}

/// Discrete Lyapunov (Stein) equation `A X Aᵀ − X + Q = 0`: its solution
/// `X` (`n × n`), MATLAB's and python-control's `dlyap(A, Q)`, SciPy's
/// `solve_discrete_lyapunov(a, q)` (the same convention).
///
/// The solution is unique unless two eigenvalues of `A` have the product
/// 1 (an eigenvalue at `z = ±1` or elsewhere on the unit circle, or a
/// pair `λ`, `1/λ`); for `A` inside the unit circle and `Q = B Bᵀ` it is
/// the discrete controllability Gramian `Σₖ Aᵏ B Bᵀ (Aᵀ)ᵏ`. A symmetric
/// `Q` (exactly) gives an exactly symmetric `X`. Bartels–Stewart on the
/// Schur form of `A`, `O(n³)` (SciPy's default for `n > 10` is instead
/// the bilinear map to a continuous equation).
///
/// # Errors
///
/// As [`lyap`], with [`Error::SingularEquation`] for eigenvalues `λ`, `μ`
/// of `A` with `λ μ = 1`.
///
/// # Examples
///
/// The Gramian of `x[k+1] = 0.5 x[k] + u[k]`: `1 / (1 − 0.25) = 4/3`.
///
/// ```
/// use ctrlab::analysis::dlyap;
/// use ctrlab::nalgebra::{dmatrix, matrix};
///
/// let gramian = dlyap(&matrix![0.5], &matrix![1.0])?;
/// assert!((gramian.x[(0, 0)] - 4.0 / 3.0).abs() < 1e-15);
///
/// // A rotation (eigenvalues on the unit circle) is refused.
/// let rotation = dmatrix![0.6, -0.8; 0.8, 0.6];
/// assert!(dlyap(&rotation, &dmatrix![1.0, 0.0; 0.0, 1.0]).is_err());
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[doc(alias = "solve_discrete_lyapunov")]
#[doc(alias = "stein")]
pub fn dlyap<M: SquareMatrix>(a: &M, q: &M) -> Result<Lyapunov<M>, Error> {
    square_equation(a, q, discrete)
}

/// A solver on the heap: `(A, Q)` to `(X, relative residual)`.
type Solver = fn(&DMatrix<f64>, &DMatrix<f64>) -> Result<(DMatrix<f64>, f64), Error>;

/// [`lyap`] and [`dlyap`]: `A` and `Q` checked (square, the same size,
/// finite), then `solve` on the heap, the solution back in `M`.
fn square_equation<M: SquareMatrix>(a: &M, q: &M, solve: Solver) -> Result<Lyapunov<M>, Error> {
    let (a, q) = (a.to_heap(), q.to_heap());
    let n = a.nrows();
    check_shape("A", &a, n, n)?;
    check_shape("Q", &q, n, n)?;
    check_finite_dyn("A", &a)?;
    check_finite_dyn("Q", &q)?;
    let (x, residual) = solve(&a, &q)?;
    Ok(Lyapunov {
        x: M::from_heap(x),
        residual,
    })
}

/// Sylvester equation `A X + X B = C`: its solution `X` (`m × n`, `A`
/// `m × m`, `B` `n × n`), SciPy's `solve_sylvester(a, b, c)` and MATLAB's
/// `sylvester(A, B, C)` (the same convention). MATLAB's `lyap(A, B, C)`
/// and python-control's `lyap(A, Q, C)` solve `A X + X B + C = 0`: that is
/// `sylvester(a, b, −c)`.
///
/// The solution is unique unless an eigenvalue `λ` of `A` and an
/// eigenvalue `μ` of `B` add up to zero. Bartels–Stewart on the Schur
/// forms of `A` and `B`, `O(m³ + n³ + m n (m + n))`.
///
/// # Errors
///
/// [`Error::DimensionMismatch`] naming `A`, `B` or `C` if a shape is wrong
/// (run-time sizes only); otherwise as [`lyap`], with
/// [`Error::SingularEquation`] for `λ` of `A` and `μ` of `B` with
/// `λ + μ = 0`.
///
/// # Examples
///
/// ```
/// use ctrlab::analysis::sylvester;
/// use ctrlab::nalgebra::{dmatrix, matrix};
///
/// // SciPy's test case: A 2 × 2, B 1 × 1.
/// let sol = sylvester(&matrix![1.0, 0.0; 0.0, 1.0], &matrix![1.0], &matrix![2.0; 2.0])?;
/// assert!((sol.x - matrix![1.0; 1.0]).amax() < 1e-15);
///
/// // Run-time sizes: 3 × 3 and 2 × 2 (a complex pair), C 3 × 2.
/// let (a, b) = (dmatrix![8.0, 1.0, 6.0; 3.0, 5.0, 7.0; 4.0, 9.0, 2.0],
///               dmatrix![2.0, -3.0; 4.0, 5.0]);
/// let c = dmatrix![1.0, 2.0; 3.0, 4.0; 5.0, 6.0];
/// let sol = sylvester(&a, &b, &c)?;
/// assert!((&a * &sol.x + &sol.x * &b - &c).amax() < 1e-13);
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[doc(alias = "solve_sylvester")]
#[doc(alias = "sylv")]
pub fn sylvester<A, B>(a: &A, b: &B, c: &A::Rhs) -> Result<Lyapunov<A::Rhs>, Error>
where
    A: SylvesterOperands<B>,
    B: SquareMatrix,
{
    pair_equation(a, b, c, sylvester_dyn)
}

/// A solver of a two-coefficient equation on the heap: `(A, B, C)` to
/// `(X, relative residual)`.
type PairSolver =
    fn(&DMatrix<f64>, &DMatrix<f64>, &DMatrix<f64>) -> Result<(DMatrix<f64>, f64), Error>;

/// [`sylvester`] and [`dsylvester`]: `A`, `B`, `C` checked (shapes,
/// finite), then `solve` on the heap, the solution back in `A::Rhs`.
fn pair_equation<A, B>(
    a: &A,
    b: &B,
    c: &A::Rhs,
    solve: PairSolver,
) -> Result<Lyapunov<A::Rhs>, Error>
where
    A: SylvesterOperands<B>,
    B: SquareMatrix,
{
    use sealed::Matrix;
    let (a, b, c) = (a.to_heap(), b.to_heap(), c.to_heap());
    let (m, n) = (a.nrows(), b.nrows());
    check_shape("A", &a, m, m)?;
    check_shape("B", &b, n, n)?;
    check_shape("C", &c, m, n)?;
    check_finite_dyn("A", &a)?;
    check_finite_dyn("B", &b)?;
    check_finite_dyn("C", &c)?;
    let (x, residual) = solve(&a, &b, &c)?;
    Ok(Lyapunov {
        x: A::Rhs::from_heap(x),
        residual,
    })
}

/// The Cholesky factor of a stable continuous Lyapunov equation's
/// solution, from [`lyapchol`], and how well `X = Rᵀ R` satisfies the
/// equation.
///
/// # Examples
///
/// ```
/// use ctrlab::analysis::{LyapunovFactor, lyapchol};
/// use ctrlab::nalgebra::{Matrix1, matrix};
///
/// // ẋ = −2 x + 3 u: X = 9 / 4, so R = 3 / 2.
/// let r: LyapunovFactor<Matrix1<f64>> = lyapchol(&matrix![-2.0], &matrix![3.0])?;
/// assert!((r.factor[(0, 0)] - 1.5).abs() < 1e-15);
/// assert!(r.residual < 1e-15);
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LyapunovFactor<R> {
    /// `R`, upper triangular with a non-negative diagonal, `X = Rᵀ R`
    /// (MATLAB's `lyapchol` convention).
    pub factor: R,
    /// Relative residual of `A X + X Aᵀ + B Bᵀ = 0` at `X = Rᵀ R`, as
    /// [`Lyapunov::residual`].
    pub residual: f64,
}

/// The pairs [`lyapchol`] takes: `A` an `SMatrix<f64, N, N>` and `B` an
/// `SMatrix<f64, N, M>`, or both `DMatrix<f64>`. Sealed.
///
/// # Examples
///
/// [`lyapchol`] with `A` 2 × 2 and `B` 2 × 1, fixed-size and
/// run-time-sized: the same factor.
///
/// ```
/// use ctrlab::analysis::lyapchol;
/// use ctrlab::nalgebra::{dmatrix, matrix};
///
/// let fixed = lyapchol(&matrix![-1.0, 0.0; 0.0, -2.0], &matrix![1.0; 1.0])?.factor;
/// let dynamic = lyapchol(&dmatrix![-1.0, 0.0; 0.0, -2.0], &dmatrix![1.0; 1.0])?.factor;
/// assert!((fixed.transpose() * fixed - matrix![0.5, 1.0 / 3.0; 1.0 / 3.0, 0.25]).amax() < 1e-15);
/// assert!((dynamic - fixed).amax() < 1e-15);
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub trait FactorOperands<B: sealed::Matrix>: SquareMatrix {}

impl<const N: usize, const M: usize> FactorOperands<SMatrix<f64, N, M>> for SMatrix<f64, N, N> {}
impl FactorOperands<DMatrix<f64>> for DMatrix<f64> {}

/// The Cholesky factor `R` of the solution of `A X + X Aᵀ + B Bᵀ = 0`
/// for a stable `A` (`X = Rᵀ R`, `R` upper triangular): MATLAB's
/// `lyapchol(A, B)`; `X` is then the controllability Gramian of `(A, B)`.
///
/// Hammarling's method (1982) on the complex Schur form of `A` (the real
/// one of [`lyap`], each 2×2 block split by a rotation), `O(n³ + n² m)`
/// for `B` `n × m`: the factor is found directly, without forming `B Bᵀ`
/// or `X`, so it keeps its accuracy where `X` is nearly singular (a
/// Gramian of a nearly uncontrollable model), which factoring
/// [`lyap`]'s `X` would not.
///
/// # Errors
///
/// [`Error::DimensionMismatch`] for a non-square `A` or a `B` with
/// another number of rows (run-time sizes only); [`Error::NonFinite`];
/// [`Error::Unstable`] naming an eigenvalue of `A` with a non-negative
/// real part, [`Error::SingularEquation`] for a stable one within
/// rounding of the imaginary axis (as [`lyap`]); [`Error::NoConvergence`] if the Schur iteration fails;
/// [`Error::Overflow`] if `R` does not fit in `f64`.
///
/// # Examples
///
/// ```
/// use ctrlab::analysis::{lyap, lyapchol};
/// use ctrlab::nalgebra::matrix;
///
/// // A lightly damped mode (ωn = 10 rad/s, ζ = 0.3), force input.
/// let a = matrix![0.0, 1.0; -100.0, -6.0];
/// let b = matrix![0.0; 1.0];
/// let r = lyapchol(&a, &b)?;
/// let x = lyap(&a, &(b * b.transpose()))?.x;
/// assert!((r.factor.transpose() * r.factor - x).amax() < 1e-15);
/// assert_eq!(r.factor[(1, 0)], 0.0);
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[doc(alias = "hammarling")]
pub fn lyapchol<A, B>(a: &A, b: &B) -> Result<LyapunovFactor<A>, Error>
where
    A: FactorOperands<B>,
    B: sealed::Matrix,
{
    const OPERATION: &str = "Lyapunov factor (lyapchol)";
    let Some((a, b)) = hammarling::operands(a, b)? else {
        return Ok(hammarling::trivial(a));
    };
    // Scaled by 4^k and 2^j (exact): R scales by 2^j / 2^k.
    let mut alpha = pow2_floor(a.amax());
    if (alpha.log2() as i64) % 2 != 0 {
        alpha *= 2.0;
    }
    let beta = pow2_floor(b.amax());
    let (a, b) = (a / alpha, b / beta);
    let s = schur(&a)?;
    // (The Schur form's entries are finite.)
    if let Some(p) = s.eigenvalues.iter().find(|p| p.re >= 0.0) {
        return Err(Error::Unstable {
            operation: OPERATION,
            re: p.re * alpha,
            im: p.im * alpha,
        });
    }
    if let Some(pair) = singular_pair(&s, &s, Condition::Sum) {
        return Err(refuse(
            "continuous Lyapunov equation A X + X Aᵀ + B Bᵀ = 0",
            "λ + μ = 0",
            pair,
            alpha,
        ));
    }
    let r = hammarling::factor(&s, &b, hammarling::Time::Continuous);
    let x = r.transpose() * &r;
    let bb = &b * b.transpose();
    let (ax, xat) = (&a * &x, &x * a.transpose());
    let res = (&ax + &xat + &bb).norm();
    let residual = relative(res, &[ax.norm(), xat.norm(), bb.norm()]);
    Ok(LyapunovFactor {
        factor: A::from_heap(unscale(r, beta, alpha.sqrt(), OPERATION)?),
        residual,
    })
}

/// `‖r‖ / Σ ‖termᵢ‖`, 0 when the terms are all zero.
fn relative(r: f64, terms: &[f64]) -> f64 {
    let d: f64 = terms.iter().sum();
    if d == 0.0 { r } else { r / d }
}

/// The refusal for a singular pair, eigenvalues scaled back by `scale`.
fn refuse(
    equation: &'static str,
    condition: &'static str,
    (l, m): (Complex<f64>, Complex<f64>),
    scale: f64,
) -> Error {
    Error::SingularEquation {
        equation,
        lambda_re: l.re * scale,
        lambda_im: l.im * scale,
        mu_re: m.re * scale,
        mu_im: m.im * scale,
        condition,
    }
}

/// `X` times `num / den` (powers of two), refused if it overflows.
fn unscale(
    mut x: DMatrix<f64>,
    num: f64,
    den: f64,
    operation: &'static str,
) -> Result<DMatrix<f64>, Error> {
    x *= num;
    x /= den;
    if x.iter().all(|v| v.is_finite()) {
        Ok(x)
    } else {
        Err(Error::Overflow { operation })
    }
}

/// `U Y Uᵀ` (or `U Y Vᵀ`), symmetrised if `symmetric`.
fn back(u: &Schur, y: &DMatrix<f64>, v: &Schur, symmetric: bool) -> DMatrix<f64> {
    let mut x = &u.u * y * v.u.transpose();
    if symmetric {
        let xt = x.transpose();
        x += xt;
        x *= 0.5;
    }
    x
}

fn is_symmetric(q: &DMatrix<f64>) -> bool {
    q == &q.transpose()
}

/// [`lyap`] on checked, finite, square data.
fn continuous(a: &DMatrix<f64>, q: &DMatrix<f64>) -> Result<(DMatrix<f64>, f64), Error> {
    const EQUATION: &str = "continuous Lyapunov equation A X + X Aᵀ + Q = 0";
    let n = a.nrows();
    if n == 0 {
        return Ok((DMatrix::zeros(0, 0), 0.0));
    }
    let (alpha, beta) = (pow2_floor(a.amax()), pow2_floor(q.amax()));
    let (a, q) = (a / alpha, q / beta);
    let s = schur(&a)?;
    if let Some(pair) = singular_pair(&s, &s, Condition::Sum) {
        return Err(refuse(EQUATION, "λ + μ = 0", pair, alpha));
    }
    let mut y = -(s.u.transpose() * &q * &s.u);
    quasi_sylvester(&s.t, &s.blocks, &s.t, &s.blocks, true, &mut y);
    let x = back(&s, &y, &s, is_symmetric(&q));
    let (ax, xat) = (&a * &x, &x * a.transpose());
    let r = (&ax + &xat + &q).norm();
    let residual = relative(r, &[ax.norm(), xat.norm(), q.norm()]);
    Ok((unscale(x, beta, alpha, EQUATION)?, residual))
}

/// [`dlyap`] on checked, finite, square data.
fn discrete(a: &DMatrix<f64>, q: &DMatrix<f64>) -> Result<(DMatrix<f64>, f64), Error> {
    const EQUATION: &str = "discrete Lyapunov equation A X Aᵀ − X + Q = 0";
    let n = a.nrows();
    if n == 0 {
        return Ok((DMatrix::zeros(0, 0), 0.0));
    }
    let beta = pow2_floor(q.amax());
    let q = q / beta;
    let s = schur(a)?;
    if let Some(pair) = singular_pair(&s, &s, Condition::Product) {
        return Err(refuse(EQUATION, "λ μ = 1", pair, 1.0));
    }
    let mut y = s.u.transpose() * &q * &s.u;
    quasi_stein(&s.t, &s.blocks, &s.t, &s.blocks, &mut y);
    let x = back(&s, &y, &s, is_symmetric(&q));
    let axa = a * &x * a.transpose();
    let r = (&axa - &x + &q).norm();
    let residual = relative(r, &[axa.norm(), x.norm(), q.norm()]);
    Ok((unscale(x, beta, 1.0, EQUATION)?, residual))
}

/// [`sylvester`] on checked, finite data of matching shapes.
fn sylvester_dyn(
    a: &DMatrix<f64>,
    b: &DMatrix<f64>,
    c: &DMatrix<f64>,
) -> Result<(DMatrix<f64>, f64), Error> {
    const EQUATION: &str = "Sylvester equation A X + X B = C";
    let (m, n) = (a.nrows(), b.nrows());
    if m == 0 || n == 0 {
        return Ok((DMatrix::zeros(m, n), 0.0));
    }
    let alpha = pow2_floor(a.amax().max(b.amax()));
    let gamma = pow2_floor(c.amax());
    let (a, b, c) = (a / alpha, b / alpha, c / gamma);
    let (sa, sb) = (schur(&a)?, schur(&b)?);
    if let Some(pair) = singular_pair(&sa, &sb, Condition::Sum) {
        return Err(refuse(EQUATION, "λ + μ = 0", pair, alpha));
    }
    let mut y = sa.u.transpose() * &c * &sb.u;
    quasi_sylvester(&sa.t, &sa.blocks, &sb.t, &sb.blocks, false, &mut y);
    let x = back(&sa, &y, &sb, false);
    let (ax, xb) = (&a * &x, &x * &b);
    let r = (&ax + &xb - &c).norm();
    let residual = relative(r, &[ax.norm(), xb.norm(), c.norm()]);
    Ok((unscale(x, gamma, alpha, EQUATION)?, residual))
}
