//! System norms of a stable model: [`h2_norm`] (through a Gramian) and
//! [`hinf_norm`] with its peak frequency (Hamiltonian iteration).

mod h2;
mod hinf;

use super::stability::stable_poles;
use crate::error::Error;
use crate::model::{LinearSystem, Token, period_of};

/// The relative accuracy of [`hinf_norm`]: the norm lies in
/// `[value, value · (1 + 2 · HINF_RTOL)]`.
///
/// # Examples
///
/// ```
/// assert_eq!(ctrlab::analysis::HINF_RTOL, 1e-10);
/// ```
pub const HINF_RTOL: f64 = 1e-10;

/// The H∞ norm of a stable model and the frequency where it is reached,
/// from [`hinf_norm`].
///
/// # Examples
///
/// ```
/// use ctrlab::StateSpace;
/// use ctrlab::analysis::hinf_norm;
/// use ctrlab::nalgebra::matrix;
///
/// // 3 / (s + 2): largest at DC, 3/2.
/// let lag = StateSpace::continuous(matrix![-2.0], matrix![3.0], matrix![1.0], matrix![0.0])?;
/// let h = hinf_norm(&lag)?;
/// assert!((h.value - 1.5).abs() < 1e-9 && h.peak_frequency == Some(0.0));
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HinfNorm {
    /// The norm, `sup_ω σ̄(G(jω))` (or over `G(e^(jω dt))`), in output
    /// units per input unit: the largest singular value of the frequency
    /// response found, within a relative [`HINF_RTOL`] (twice) below the
    /// supremum.
    pub value: f64,
    /// Where `value` is reached, rad/s: in `[0, ∞)` for a continuous model,
    /// in `[0, π/dt]` for a discrete one. `None` for a continuous model
    /// whose gain is largest as `ω → ∞` (`value = σ̄(D)`, approached but
    /// not reached; MATLAB's `fpeak = Inf`).
    pub peak_frequency: Option<f64>,
}

/// The H2 norm of a stable model: the RMS of its output under unit white
/// noise on each input, `‖G‖₂ = √(trace(C W_c Cᵀ))` in continuous time
/// (`W_c` the controllability Gramian, `A W_c + W_c Aᵀ + B Bᵀ = 0`), and
/// `√(trace(C W_c Cᵀ + D Dᵀ))` in discrete time
/// (`A W_c Aᵀ − W_c + B Bᵀ = 0`; no `dt` factor, as MATLAB's and
/// python-control's `norm(sys, 2)`). Units: output units per input unit
/// per √s in continuous time.
///
/// Continuous: the Gramian's Cholesky factor `R` from [`lyapchol`]
/// (Hammarling), `‖G‖₂ = ‖R Cᵀ‖_F`, never the square root of a rounded
/// negative. Discrete: [`dlyap`]'s Gramian. `B` and `C` are first scaled by
/// powers of two (exact), so that `B Bᵀ` cannot overflow.
///
/// # Where python-control and MATLAB return `inf`
///
/// python-control 0.10.2's `norm(sys, 2)` returns `inf` (with a warning)
/// for an unstable model, for a pole within `1e-8` of the imaginary axis
/// (of the unit circle) and for a continuous model with `D ≠ 0`; MATLAB's
/// `norm(sys, 2)` returns `Inf` in the same cases. Here each is a named
/// refusal, and every `Ok` is finite.
///
/// # Errors
///
/// [`Error::Unstable`] naming the first pole on or outside the stability
/// boundary (the test of [`StateSpace::unstable_pole`]: within its rounding
/// error counts as on it); [`Error::InvalidMatrix`] named `"D"` for a
/// continuous model with a non-zero `D` (its H2 norm is infinite);
/// [`Error::SingularEquation`], [`Error::NoConvergence`] from the Lyapunov
/// solvers; [`Error::Overflow`] for a norm that does not fit in `f64`.
///
/// # Examples
///
/// ```
/// use ctrlab::{DynStateSpace, Error, StateSpace};
/// use ctrlab::analysis::h2_norm;
/// use ctrlab::nalgebra::{dmatrix, matrix};
///
/// // k / (s + a): k / √(2 a), here 3 / √4.
/// let lag = StateSpace::continuous(matrix![-2.0], matrix![3.0], matrix![1.0], matrix![0.0])?;
/// assert!((h2_norm(&lag)? - 1.5).abs() < 1e-15);
///
/// // x[k+1] = 0.5 x[k] + u[k], y = x + u: √(1 + 1/(1 − 0.25)).
/// let d = DynStateSpace::discrete(dmatrix![0.5], dmatrix![1.0], dmatrix![1.0], dmatrix![1.0], 0.1)?;
/// assert!((h2_norm(&d)? - (1.0 + 4.0 / 3.0f64).sqrt()).abs() < 1e-15);
///
/// // Feedthrough in continuous time, and an unstable model, are refused.
/// let biproper = StateSpace::continuous(matrix![-1.0], matrix![1.0], matrix![1.0], matrix![1.0])?;
/// assert!(matches!(h2_norm(&biproper), Err(Error::InvalidMatrix { matrix: "D", .. })));
/// let unstable = StateSpace::continuous(matrix![1.0], matrix![1.0], matrix![1.0], matrix![0.0])?;
/// assert!(matches!(h2_norm(&unstable), Err(Error::Unstable { .. })));
/// # Ok::<(), ctrlab::Error>(())
/// ```
///
/// [`lyapchol`]: super::lyapchol
/// [`dlyap`]: super::dlyap
/// [`StateSpace::unstable_pole`]: crate::StateSpace::unstable_pole
#[doc(alias = "norm")]
#[doc(alias = "system_norm")]
#[doc(alias = "h2norm")]
pub fn h2_norm<S: LinearSystem>(sys: &S) -> Result<f64, Error> {
    let sys = sys.to_dyn(Token(()));
    let period = period_of(&sys.domain());
    stable_poles(&sys, "H2 norm")?;
    h2::h2(sys.a(), sys.b(), sys.c(), sys.d(), period)
}

/// The H∞ norm of a stable model, `sup_ω σ̄(G(jω))` (the peak gain over
/// frequency; for a SISO model the peak of its Bode magnitude), and the
/// frequency where it is reached: MATLAB's `hinfnorm` and `norm(sys, Inf)`,
/// python-control's `norm(sys, 'inf')`. MIMO: `σ̄` is the largest singular
/// value.
///
/// # Algorithm
///
/// Bruinsma and Steinbuch (1990): a lower bound `γ` from `ω = 0`, each
/// pole's `|λ|` and `ω → ∞` (`σ̄(D)`); then, at `γ (1 + 2 HINF_RTOL)`, the
/// imaginary eigenvalues `jωᵢ` of the `2n × 2n` Hamiltonian matrix
/// (Boyd, Balakrishnan and Kabamba, 1989) are the frequencies where that
/// level is a singular value of `G(jω)`; the gain at the midpoints of
/// consecutive `ωᵢ` raises `γ`, until there are none above the level.
/// Quadratic convergence, capped at 50 eigenvalue problems. The model is
/// scaled by powers of two first (time and gain, exactly). Eigenvalues
/// by the crate's path for `poles` (the stack kernel up to 8, so up to 4
/// states); gains by the frequency-response kernel.
///
/// A discrete model goes through the bilinear map
/// `s = (2/dt)(z − 1)/(z + 1)`, which keeps the values on the unit circle
/// (`ω_c = (2/dt) tan(ω dt/2)`); the peak is mapped back by
/// `ω = (2/dt) atan(ω_c dt/2)`, so it is in `[0, π/dt]`. Unlike
/// python-control's SciPy path, a pole at `z = 0` is fine.
///
/// # Unstable models
///
/// Refused by name. python-control 0.10.2 (without slycot) computes the
/// L∞ norm `sup σ̄(G(jω))` of an unstable model with no pole on the axis,
/// by bisection to a relative `1e-6`; MATLAB's `hinfnorm` returns `Inf`.
/// (That SciPy path also fails on a model with more inputs than outputs
/// or fewer: it sizes `γ² I − Dᵀ D`'s identity by the outputs.)
///
/// # Errors
///
/// [`Error::Unstable`] naming the first pole on or outside the stability
/// boundary (as [`h2_norm`]); [`Error::NoConvergence`] if the iteration
/// (or an eigenvalue or singular value iteration) reaches its cap;
/// [`Error::Singular`] for a discrete pole so near `z = −1` that the
/// bilinear map fails; [`Error::Overflow`] for values that do not fit in
/// `f64`.
///
/// # Examples
///
/// ```
/// use ctrlab::{Cart, DynStateSpace, Discretization, MassSpring, StateSpace};
/// use ctrlab::analysis::hinf_norm;
/// use ctrlab::nalgebra::{dmatrix, matrix};
///
/// // ωn² / (s² + 2 ζ ωn s + ωn²), ζ = 0.1: peak 1 / (2ζ√(1 − ζ²)) at ωn √(1 − 2ζ²).
/// let (wn, z) = (10.0, 0.1);
/// let sys = StateSpace::continuous(matrix![0.0, 1.0; -wn * wn, -2.0 * z * wn], matrix![0.0; wn * wn],
///                                  matrix![1.0, 0.0], matrix![0.0])?;
/// let h = hinf_norm(&sys)?;
/// assert!((h.value - 1.0 / (2.0 * z * (1.0 - z * z).sqrt())).abs() < 1e-8);
/// assert!((h.peak_frequency.unwrap() - wn * (1.0 - 2.0 * z * z).sqrt()).abs() < 1e-3);
///
/// // The lab plant, sampled at 2 ms: the same peak, near 20 rad/s.
/// let plant = MassSpring::nominal().state_space(Cart::Two)?;
/// let (hc, hd) = (hinf_norm(&plant)?, hinf_norm(&plant.discretize(0.002, Discretization::Tustin)?)?);
/// assert!((hc.value - hd.value).abs() < 1e-6 * hc.value);
///
/// // MIMO, sized at run time: two decoupled lags, gains 2 and 0.5.
/// let mimo = DynStateSpace::continuous(dmatrix![-1.0, 0.0; 0.0, -4.0], dmatrix![2.0, 0.0; 0.0, 2.0],
///                                      dmatrix![1.0, 0.0; 0.0, 1.0], dmatrix![0.0, 0.0; 0.0, 0.0])?;
/// assert!((hinf_norm(&mimo)?.value - 2.0).abs() < 1e-9);
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[doc(alias = "hinfnorm")]
#[doc(alias = "norm")]
#[doc(alias = "system_norm")]
#[doc(alias = "linfnorm")]
#[doc(alias = "getPeakGain")]
pub fn hinf_norm<S: LinearSystem>(sys: &S) -> Result<HinfNorm, Error> {
    let sys = sys.to_dyn(Token(()));
    let period = period_of(&sys.domain());
    let poles = stable_poles(&sys, "H∞ norm")?;
    let (a, b, c, d) = (sys.a(), sys.b(), sys.c(), sys.d());
    let peak = match period {
        None => hinf::continuous(a, b, c, d, &poles)?,
        Some(dt) => hinf::discrete(a, b, c, d, dt, &poles)?,
    };
    Ok(HinfNorm {
        value: peak.value,
        peak_frequency: peak.omega,
    })
}
