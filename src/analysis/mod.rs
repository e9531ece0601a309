//! Properties of a linear model: poles, stability, DC gain, damping, and
//! controllability / observability with a numerical rank test; Lyapunov
//! and Sylvester equations ([`lyap`], [`dlyap`], [`sylvester`],
//! [`lyapchol`], [`dlyapchol`], the discrete Sylvester equation
//! [`dsylvester`]); Gramians, Hankel singular values and balanced
//! truncation (`gram`, `hsvd`, `balred`, on both model types); system
//! norms ([`h2_norm`], [`hinf_norm`]).
//!
//! Everything here is a method on [`StateSpace`] (`state_space.rs`) and on
//! [`DynStateSpace`](crate::DynStateSpace) (a model sized at run time,
//! `dyn_state_space.rs`), except [`rank`], the equations, and the norms
//! (free functions over [`LinearSystem`](crate::LinearSystem), MATLAB's
//! `norm(sys)` style); [`Poles`] prints a list of
//! poles. These are design-time computations, not inner loops:
//! each is written once, on run-time-sized matrices (eigenvalues by a
//! balanced Hessenberg QR on the stack up to 8 states, then, balanced as
//! LAPACK's `dgebal` balances (permutation and scaling), nalgebra's Schur
//! and faer's multishift QR; singular values through nalgebra's SVD),
//! and the fixed-size methods hand their matrices to it, so both model
//! types give the same answers.
//!
//! # Examples
//!
//! ```
//! use ctrlab::{MassSpring, Cart};
//!
//! let plant = MassSpring::nominal().state_space(Cart::Two)?;
//! assert!(plant.is_stable()?);
//! assert!(plant.is_controllable()? && plant.is_observable()?);
//! // 1 N on cart 2 moves it 2 mm at rest.
//! assert!((plant.dc_gain()?[(0, 0)] - 0.002).abs() < 1e-15);
//! # Ok::<(), ctrlab::Error>(())
//! ```

mod balance;
mod balred;
mod controllability;
mod dyn_state_space;
mod gain;
mod gramian;
mod lyapunov;
pub(crate) mod minreal;
mod norms;
mod poles;
mod stability;
mod state_space;

pub use balred::{BalancedTruncation, ReducedOrder};
pub(crate) use controllability::{krylov, scaled_krylov_rank};
pub use gramian::GramianKind;
pub use lyapunov::dsylvester;
pub use lyapunov::{
    FactorOperands, Lyapunov, LyapunovFactor, SquareMatrix, SylvesterOperands, dlyap, dlyapchol,
    lyap, lyapchol, sylvester,
};
pub use norms::{HINF_RTOL, HinfNorm, h2_norm, hinf_norm};
pub use poles::Poles;
pub(crate) use stability::{first_unstable, first_unstable_dyn};

use nalgebra::{Complex, DMatrix, SMatrix};

use crate::error::Error;
use crate::kernels::eigen::{SMALL, small_eigenvalues, small_eigenvalues_near};
#[cfg(doc)]
use crate::model::StateSpace;

/// Iteration cap for the Schur and SVD iterations, per matrix dimension.
const ITERATIONS_PER_DIM: usize = 200;

/// Natural frequency, damping ratio and time constant of one pole, the
/// columns of MATLAB's `damp`.
///
/// For a discrete model the pole `z` is first mapped to `s = ln(z) / dt`,
/// as MATLAB does. Definitions: `natural_frequency = |s|` (rad/s),
/// `damping_ratio = −Re(s) / |s|`, `time_constant = −1 / Re(s)` (s). Edge
/// cases, chosen so nothing is NaN: a pole at `s = 0` has `ωn = 0`, `ζ = −1`
/// (MATLAB's convention) and `τ = +∞`; a discrete pole at `z = 0` has
/// `ωn = +∞`, `ζ = 1`, `τ = 0`. Unstable poles have a negative `ζ` and `τ`.
///
/// # Examples
///
/// ```
/// use ctrlab::StateSpace;
/// use ctrlab::nalgebra::matrix;
///
/// // ωn = 10 rad/s, ζ = 0.3: x'' + 6 x' + 100 x = u.
/// let sys = StateSpace::continuous(matrix![0.0, 1.0; -100.0, -6.0], matrix![0.0; 1.0],
///                                  matrix![1.0, 0.0], matrix![0.0])?;
/// for d in sys.damping()? {
///     assert!((d.natural_frequency - 10.0).abs() < 1e-12);
///     assert!((d.damping_ratio - 0.3).abs() < 1e-12);
///     assert!((d.time_constant - 1.0 / 3.0).abs() < 1e-12);
/// }
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Damping {
    /// The pole itself (`s` for continuous, `z` for discrete models).
    pub pole: Complex<f64>,
    /// Natural frequency `ωn = |s|`, rad/s.
    pub natural_frequency: f64,
    /// Damping ratio `ζ = −Re(s) / |s|` (dimensionless).
    pub damping_ratio: f64,
    /// Time constant `τ = −1 / Re(s)`, s.
    pub time_constant: f64,
}

impl Damping {
    fn of_s(pole: Complex<f64>, s: Complex<f64>) -> Self {
        let wn = s.norm();
        if wn == 0.0 {
            return Self {
                pole,
                natural_frequency: 0.0,
                damping_ratio: -1.0,
                time_constant: f64::INFINITY,
            };
        }
        Self {
            pole,
            natural_frequency: wn,
            damping_ratio: -s.re / wn,
            time_constant: if s.re == 0.0 {
                f64::INFINITY
            } else {
                -1.0 / s.re
            },
        }
    }
}

/// [`Damping`] of each pole, for a model with sampling period `period`
/// (`None`: continuous); a discrete pole `z` is first mapped to
/// `s = ln(z) / dt`.
pub(crate) fn damping_of(poles: &[Complex<f64>], period: Option<f64>) -> Vec<Damping> {
    poles
        .iter()
        .map(|&p| match period {
            None => Damping::of_s(p, p),
            Some(_) if p.norm() == 0.0 => Damping {
                pole: p,
                natural_frequency: f64::INFINITY,
                damping_ratio: 1.0,
                time_constant: 0.0,
            },
            Some(dt) => Damping::of_s(p, p.ln() / dt),
        })
        .collect()
}

/// Numerical rank of a matrix: the number of singular values above
/// `rtol · σ_max`.
///
/// `rtol = None` uses NumPy's `matrix_rank` default, `max(rows, cols) · ε`.
/// The tolerance is relative, so the answer does not depend on the units the
/// matrix is written in.
///
/// # Errors
///
/// [`Error::InvalidParameter`] named `"rtol"` for a negative or non-finite
/// tolerance; [`Error::NonFinite`] for a NaN or infinite entry;
/// [`Error::NoConvergence`] if the SVD iteration fails.
///
/// # Examples
///
/// ```
/// use ctrlab::analysis::rank;
/// use ctrlab::nalgebra::dmatrix;
///
/// let m = dmatrix![1.0, 2.0; 2.0, 4.0 + 1e-12];
/// assert_eq!(rank(&m, None)?, 2);        // 1e-12 is far above ε
/// assert_eq!(rank(&m, Some(1e-9))?, 1);  // but not above 1e-9
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub fn rank(m: &DMatrix<f64>, rtol: Option<f64>) -> Result<usize, Error> {
    let sv = singular_values(m, "matrix")?;
    let rtol = match rtol {
        Some(r) if r.is_finite() && r >= 0.0 => r,
        Some(r) => {
            return Err(Error::InvalidParameter {
                name: "rtol",
                value: r,
                reason: "relative tolerance must be finite and >= 0",
            });
        }
        None => m.nrows().max(m.ncols()) as f64 * f64::EPSILON,
    };
    let max = sv.iter().copied().fold(0.0, f64::max);
    Ok(sv.iter().filter(|&&s| s > rtol * max && s > 0.0).count())
}

fn singular_values(m: &DMatrix<f64>, name: &'static str) -> Result<Vec<f64>, Error> {
    if let Some((i, v)) = m.iter().enumerate().find(|(_, v)| !v.is_finite()) {
        return Err(Error::NonFinite {
            matrix: name,
            row: i % m.nrows(),
            col: i / m.nrows(),
            value: *v,
        });
    }
    if m.is_empty() {
        return Ok(Vec::new());
    }
    let iterations = ITERATIONS_PER_DIM * m.nrows().max(m.ncols());
    // Unordered: the ordered variant panics on a NaN singular value, which
    // entries near f64::MAX can produce inside the iteration.
    let svd = m
        .clone()
        .try_svd_unordered(false, false, f64::EPSILON, iterations)
        .ok_or(Error::NoConvergence {
            operation: "singular value decomposition",
            iterations,
        })?;
    if svd.singular_values.iter().any(|s| !s.is_finite()) {
        return Err(Error::Overflow {
            operation: "singular value decomposition",
        });
    }
    Ok(svd.singular_values.iter().copied().collect())
}

/// Eigenvalues of a square matrix, sorted by real part then imaginary part
/// (ascending), the order python-control's fixtures use.
pub(crate) fn eigenvalues<const N: usize>(
    a: &SMatrix<f64, N, N>,
) -> Result<[Complex<f64>; N], Error> {
    let mut out = [Complex::new(0.0, 0.0); N];
    // The lab's sizes: the stack kernel, no copy to the heap.
    if N <= SMALL && small_eigenvalues(a.as_slice(), N, &mut out) {
        sort_poles(&mut out);
        return Ok(out);
    }
    // The kernel gave up (or N is larger): the iterations, not the same
    // kernel again through `eigenvalues_dyn`.
    let values = eigenvalues_iterative(&DMatrix::from_column_slice(N, N, a.as_slice()))?;
    out.copy_from_slice(&values);
    Ok(out)
}

/// Sorted by real part, then imaginary part.
fn sort_poles(p: &mut [Complex<f64>]) {
    p.sort_unstable_by(|x, y| x.re.total_cmp(&y.re).then(x.im.total_cmp(&y.im)));
}

/// The eigenvalues of a matrix, on the stack up to `SMALL` of them.
pub(crate) struct Spectrum {
    small: [Complex<f64>; SMALL],
    n: usize,
    heap: Vec<Complex<f64>>,
}

impl Spectrum {
    pub(crate) fn as_slice(&self) -> &[Complex<f64>] {
        if self.n <= SMALL {
            &self.small[..self.n]
        } else {
            &self.heap
        }
    }
}

/// The eigenvalues (in no particular order) of the `n × n` column-major
/// `a`, expected near `guesses` (a placement's targets, `n` of them): up to
/// `SMALL` states the stack kernel with the guesses as its first shifts, so
/// a placement that hit its targets is confirmed in about `n / 2` QR
/// sweeps; otherwise, or if the kernel gives up, as [`eigenvalues_dyn`].
pub(crate) fn eigenvalues_near(
    a: &[f64],
    n: usize,
    guesses: &[Complex<f64>],
) -> Result<Spectrum, Error> {
    let mut out = Spectrum {
        small: [Complex::new(0.0, 0.0); SMALL],
        n,
        heap: Vec::new(),
    };
    if n > SMALL || !small_eigenvalues_near(a, n, guesses, &mut out.small) {
        let values = eigenvalues_dyn(&DMatrix::from_column_slice(n, n, a))?;
        if n <= SMALL {
            out.small[..n].copy_from_slice(&values);
        } else {
            out.heap = values;
        }
    }
    Ok(out)
}

/// Up to this size `eigenvalues_dyn` tries nalgebra's Schur before faer's
/// (after the stack kernel, which takes up to `kernels::eigen::SMALL`).
const SMALL_EIGEN: usize = 8;

/// Eigenvalues of a square run-time-sized matrix, sorted as [`eigenvalues`]
/// sorts them. The one implementation behind every model's `poles()`.
pub(crate) fn eigenvalues_dyn(a: &DMatrix<f64>) -> Result<Vec<Complex<f64>>, Error> {
    let n = a.nrows();
    debug_assert_eq!(n, a.ncols());
    if n == 0 {
        return Ok(Vec::new());
    }
    // Up to 8 states: EISPACK's balanced Hessenberg QR on the stack
    // (`kernels::eigen`), a fraction of nalgebra's Schur at these sizes;
    // it gives up rather than guess, and the iterations below take over.
    if n <= SMALL {
        let mut small = [Complex::new(0.0, 0.0); SMALL];
        if small_eigenvalues(a.as_slice(), n, &mut small) {
            let mut out = small[..n].to_vec();
            sort_poles(&mut out);
            return Ok(out);
        }
    }
    eigenvalues_iterative(a)
}

/// [`eigenvalues_dyn`] without the stack kernel: balanced as LAPACK's
/// `dgeev` balances (`balance`: isolated eigenvalues permuted out, the
/// rest scaled by powers of two), then nalgebra's Schur and faer's
/// multishift QR on the coupled block, sorted; `a` is square and not
/// empty. Unbalanced, a badly scaled model's slow poles come out with an
/// error relative to its largest entries: python-control's issue #935
/// (16 states, coefficients from 1e-31 to 1e-5) had poles at +4.2e-10 and
/// +1.2e-5 where NumPy, balancing, finds them all stable.
fn eigenvalues_iterative(a: &DMatrix<f64>) -> Result<Vec<Complex<f64>>, Error> {
    let (balanced, lo, hi) = balance::balance(a.clone());
    let isolated = (0..lo)
        .chain(hi..a.nrows())
        .map(|i| Complex::new(balanced[(i, i)], 0.0));
    let mut out: Vec<Complex<f64>> = if hi > lo {
        coupled_eigenvalues(&balanced.view((lo, lo), (hi - lo, hi - lo)).into_owned())?
    } else {
        Vec::new()
    };
    out.extend(isolated);
    if out.iter().any(|p| !(p.re.is_finite() && p.im.is_finite())) {
        return Err(Error::Overflow {
            operation: "eigenvalues",
        });
    }
    sort_poles(&mut out);
    Ok(out)
}

/// The eigenvalues of a balanced, not empty, square block, by nalgebra's
/// Schur and faer's multishift QR.
fn coupled_eigenvalues(a: &DMatrix<f64>) -> Result<Vec<Complex<f64>>, Error> {
    let n = a.nrows();
    let iterations = ITERATIONS_PER_DIM * n;
    let nalgebra_schur = || {
        a.clone()
            .try_schur(f64::EPSILON, iterations)
            .map(|s| s.complex_eigenvalues().iter().copied().collect::<Vec<_>>())
    };
    // faer's multishift QR (exceptional shifts, aggressive early deflation)
    // converges where nalgebra's Francis iteration stalls (a repeated,
    // non-defective eigenvalue; CAREX 6's 30 states) and is the faster at
    // large n; at small n its set-up costs more than the whole of
    // nalgebra's iteration (a 4-state LQR spent a fifth of its time
    // there), so nalgebra goes first there and faer is the fallback.
    let faer_qr = || {
        faer::MatRef::from_column_major_slice(a.as_slice(), n, n)
            .eigenvalues()
            .ok()
            .map(|v| v.iter().map(|e| Complex::new(e.re, e.im)).collect())
    };
    let values = if n <= SMALL_EIGEN {
        nalgebra_schur().or_else(faer_qr)
    } else {
        faer_qr().or_else(nalgebra_schur)
    };
    values.ok_or(Error::NoConvergence {
        operation: "Schur decomposition (eigenvalues)",
        iterations,
    })
}
