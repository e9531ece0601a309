//! Algebraic Riccati equations and linear-quadratic regulators sized at run
//! time: [`care`], [`dare`] and `DynStateSpace::lqr`, the one
//! implementation behind the fixed-size [`lqr`](super::lqr) and
//! [`dlqr`](super::dlqr) too. The method is documented on [`DynLqr`].

mod kernels;

use nalgebra::{Complex, DMatrix, DefaultAllocator, Dim, Dyn, OMatrix, allocator::Allocator};

use crate::analysis::{eigenvalues_dyn, first_unstable_dyn};
use crate::error::{Error, check_finite_dyn, check_shape};
use crate::kernels::linalg::Lu;
use crate::kernels::reduce::pow2_floor;
use crate::model::{Continuous, Discrete, DynStateSpace};
use kernels::{MAX_ITERATIONS, Square, finite, fro, inverse, lyapunov, sda, stein, symmetrize};

/// A continuous solution with a relative residual above this after Newton
/// refinement is retried with another Cayley shift, unless Newton stalled
/// (the residual is then the problem's rounding floor); the best is kept.
const GOOD_RESIDUAL: f64 = 1e-13;
/// Newton refinement steps after the doubling, at most.
const REFINE_STEPS: usize = 3;
/// Newton steps after doubling on a regularised `R` (a discrete equation
/// with a singular `R`): the start is then about 1e-8 away, so Newton is the
/// solver here, not a polish, and runs until the residual stops falling.
const REGULARISED_REFINE_STEPS: usize = 12;
/// Cayley shifts tried, as multiples of the Hamiltonian's scale.
const SHIFTS: [f64; 7] = [1.0, 0.5, 2.0, 0.25, 4.0, 0.1, 10.0];

/// A solved algebraic Riccati equation, or linear-quadratic regulator, sized
/// at run time: the gain, the stabilising solution, the closed-loop poles,
/// and how well the equation is satisfied. The run-time counterpart of
/// [`Lqr`](super::Lqr), returned by [`care`], [`dare`] and
/// [`DynStateSpace::lqr`].
///
/// # Method
///
/// The discrete equation
/// `X = Aᵀ X A − Aᵀ X B (R + Bᵀ X B)⁻¹ Bᵀ X A + Q` is the fixed point of the
/// structure-preserving doubling algorithm (SDA) of Chu, Fan and Lin (2005):
/// with `E₀ = A`, `G₀ = B R⁻¹ Bᵀ`, `H₀ = Q`,
///
/// ```text
/// W = I + G H,  E ← E W⁻¹ E,  G ← G + E W⁻¹ G Eᵀ,  H ← H + Eᵀ H W⁻¹ E
/// ```
///
/// and `H → X` quadratically. The continuous equation
/// `Aᵀ X + X A − X B R⁻¹ Bᵀ X + Q = 0` is first mapped to that form by the
/// Cayley transform of its Hamiltonian with a shift `γ > 0`
/// (`A_γ = A − γ I`, `W_γ = A_γᵀ + Q A_γ⁻¹ G`, `E₀ = I + 2γ W_γ⁻ᵀ`,
/// `G₀ = 2γ A_γ⁻¹ G W_γ⁻¹`, `H₀ = 2γ W_γ⁻¹ Q A_γ⁻¹`; Chu, Fan, Lin and Weng,
/// 2004). Neither needs a stable or invertible `A`, so both converge for
/// unstable plants: the only requirements are the usual LQR ones, `(A, B)`
/// stabilisable and `(A, Q)` detectable, with no closed-loop pole on the
/// stability boundary. The shift starts at
/// `γ = max(‖A‖_F, √(‖G‖_F ‖Q‖_F))`, the scale of the Hamiltonian's
/// eigenvalues; if the residual stays above 1e-13 and the Newton steps
/// below could still lower it, a few other shifts (γ/2, 2γ, γ/4, 4γ,
/// γ/10, 10γ) are tried and the best solution kept.
///
/// On an ill-conditioned problem (a large `X` from nearly cancelling terms)
/// the doubling alone can stop at a relative residual of about 1e-9. Up to
/// three Newton steps follow it (while the residual is above 4ε), each
/// kept only if it lowers the residual:
/// a Lyapunov equation of the closed loop for the continuous case (solved
/// by the matrix-sign-function iteration), a Stein equation for the
/// discrete one (squared Smith). Every step of every part costs `O(N³)`:
/// LU solves, products and inverses, no `N² × N²` system. The code is
/// generic over nalgebra's dimensions, so the fixed-size [`lqr`](super::lqr)
/// runs it on stack matrices and `DynStateSpace::lqr` on heap ones, with
/// cache-blocked products (matrixmultiply) at large `N`.
///
/// A discrete equation with a singular (positive semidefinite) `R`, which
/// only [`dare`] accepts, is first solved with `R + δ I`
/// (`δ = 10⁻⁸ (‖R‖ + ‖B‖² ‖Q‖)`), and Newton's method on the true equation
/// (it needs only `R + Bᵀ X B` invertible) takes it from there.
///
/// Every solution's closed loop is checked: one that is not stable is
/// refused with [`Error::Unstable`]. The relative residual of the Riccati
/// equation is returned in [`DynLqr::residual`] and is not a refusal
/// criterion: callers that need a bound check it.
///
/// # Examples
///
/// ```
/// use ctrlab::design::care;
/// use nalgebra::dmatrix;
///
/// // x' = x + u (unstable), q = r = 1: X = 1 + √2, K = X.
/// let sol = care(&dmatrix![1.0], &dmatrix![1.0], &dmatrix![1.0], &dmatrix![1.0])?;
/// assert!((sol.riccati[(0, 0)] - (1.0 + 2f64.sqrt())).abs() < 1e-12);
/// assert!((sol.gain[(0, 0)] - (1.0 + 2f64.sqrt())).abs() < 1e-12);
/// assert!((sol.poles[0].re + 2f64.sqrt()).abs() < 1e-12);
/// assert!(sol.residual < 1e-12);
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct DynLqr {
    /// The optimal state gain `K` (`m × n`) of `u = −K x` (SI: input unit
    /// per state unit): `R⁻¹ Bᵀ X` in continuous time,
    /// `(R + Bᵀ X B)⁻¹ Bᵀ X A` in discrete time.
    pub gain: DMatrix<f64>,
    /// The stabilising solution `X` (`n × n`, symmetric) of the Riccati
    /// equation; for a regulator the optimal cost from `x₀` is `x₀ᵀ X x₀`
    /// (units of the cost per squared state unit).
    pub riccati: DMatrix<f64>,
    /// Poles of the closed loop `A − B K` (s-plane in rad/s, or z-plane),
    /// sorted as [`DynStateSpace::poles`].
    pub poles: Vec<Complex<f64>>,
    /// Relative residual of the Riccati equation at `X`: the Frobenius norm
    /// of the equation's left side minus its right, over the sum of the
    /// norms of its terms (dimensionless).
    pub residual: f64,
    /// Doubling steps the solver took.
    pub iterations: usize,
}

/// Which weights a caller accepts.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Weights {
    /// A regulator or estimator: `Q` symmetric positive semidefinite, `R`
    /// symmetric positive definite; errors name them as given
    /// (`["Q", "R"]`, or `["QN", "RN"]` for a Kalman filter).
    Regulator([&'static str; 2]),
    /// A Riccati equation as SciPy's solvers take it: `Q` symmetric (of any
    /// inertia), `R` symmetric positive definite (continuous) or positive
    /// semidefinite (discrete, where only `R + Bᵀ X B` is inverted).
    Equation,
}

/// Continuous-time algebraic Riccati equation
/// `Aᵀ X + X A − X B R⁻¹ Bᵀ X + Q = 0`: its stabilising solution `X` (the
/// one that makes `A − B R⁻¹ Bᵀ X` stable), with the gain
/// `K = R⁻¹ Bᵀ X`; SciPy's `solve_continuous_are(a, b, q, r)`, MATLAB's
/// `icare(A, B, Q, R)`. Sizes are taken from the matrices: `A` and `Q` are
/// `n × n`, `B` is `n × m`, `R` is `m × m`. The method is described on
/// [`DynLqr`]; `O(n³)` per step.
///
/// Unlike [`DynStateSpace::lqr`], `Q` may be indefinite (only symmetric), as
/// SciPy allows; the solution is then not necessarily positive
/// semidefinite.
///
/// # Errors
///
/// [`Error::DimensionMismatch`] naming the first matrix of the wrong shape;
/// [`Error::NonFinite`] for a non-finite entry; [`Error::InvalidMatrix`]
/// unless `Q` is symmetric and `R` symmetric positive definite;
/// [`Error::Singular`], [`Error::Overflow`] or [`Error::NoConvergence`] if
/// the doubling breaks down for every shift; [`Error::Unstable`] if the
/// solution does not stabilise `A − B K` (no stabilising solution exists).
///
/// # Examples
///
/// SciPy's CAREX 1 (a double integrator):
///
/// ```
/// use ctrlab::design::care;
/// use nalgebra::dmatrix;
///
/// let a = dmatrix![0.0, 1.0; 0.0, 0.0];
/// let b = dmatrix![0.0; 1.0];
/// let sol = care(&a, &b, &dmatrix![1.0, 0.0; 0.0, 2.0], &dmatrix![1.0])?;
/// // X = [2 1; 1 2], K = [1 2].
/// assert!((&sol.riccati - dmatrix![2.0, 1.0; 1.0, 2.0]).amax() < 1e-14);
/// assert!((&sol.gain - dmatrix![1.0, 2.0]).amax() < 1e-14);
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[doc(alias = "solve_continuous_are")]
#[doc(alias = "icare")]
pub fn care(
    a: &DMatrix<f64>,
    b: &DMatrix<f64>,
    q: &DMatrix<f64>,
    r: &DMatrix<f64>,
) -> Result<DynLqr, Error> {
    check_problem(a, b, q, r)?;
    continuous(a, b, q, r, Weights::Equation).map(DynLqr::from)
}

/// Discrete-time algebraic Riccati equation
/// `X = Aᵀ X A − Aᵀ X B (R + Bᵀ X B)⁻¹ Bᵀ X A + Q`: its stabilising solution
/// `X` (the one that puts the poles of `A − B K` inside the unit circle),
/// with the gain `K = (R + Bᵀ X B)⁻¹ Bᵀ X A`; SciPy's
/// `solve_discrete_are(a, b, q, r)`, MATLAB's `idare(A, B, Q, R)`. Sizes as
/// [`care`]; the method is described on [`DynLqr`].
///
/// `Q` may be indefinite and `R` singular (positive semidefinite), as SciPy
/// allows, as long as `R + Bᵀ X B` is invertible at the solution.
///
/// # Errors
///
/// As [`care`], except that `R` need only be symmetric positive
/// semidefinite; [`Error::Unstable`] means a closed-loop pole on or outside
/// the unit circle; [`Error::Singular`] if `R + Bᵀ X B` is singular.
///
/// # Examples
///
/// SciPy's DAREX 5 (a two-step delay):
///
/// ```
/// use ctrlab::design::dare;
/// use nalgebra::dmatrix;
///
/// let a = dmatrix![0.0, 1.0; 0.0, 0.0];
/// let b = dmatrix![0.0; 1.0];
/// let q = dmatrix![1.0, 2.0; 2.0, 4.0];
/// let sol = dare(&a, &b, &q, &dmatrix![1.0])?;
/// // The equation holds at X…
/// let x = &sol.riccati;
/// let res = a.transpose() * x * &a - x + &q
///     - a.transpose() * x * &b * &sol.gain;
/// assert!(res.amax() < 1e-13);
/// // …and X is the stabilising solution.
/// assert!(sol.poles.iter().all(|z| z.norm() < 1.0));
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[doc(alias = "solve_discrete_are")]
#[doc(alias = "idare")]
pub fn dare(
    a: &DMatrix<f64>,
    b: &DMatrix<f64>,
    q: &DMatrix<f64>,
    r: &DMatrix<f64>,
) -> Result<DynLqr, Error> {
    check_problem(a, b, q, r)?;
    discrete(a, b, q, r, Weights::Equation, None).map(DynLqr::from)
}

impl DynStateSpace<Continuous> {
    /// Continuous-time LQR: the gain `K = R⁻¹ Bᵀ X` (`m × n`) minimising
    /// `∫ (xᵀ Q x + uᵀ R u) dt` for `u = −K x`, with `X` the stabilising
    /// solution of the continuous algebraic Riccati equation (see
    /// [`DynLqr`]). MATLAB's and python-control's `lqr(sys, Q, R)`; the
    /// run-time counterpart of [`lqr`](crate::design::lqr).
    ///
    /// # Errors
    ///
    /// [`Error::DimensionMismatch`] unless `Q` is `n × n` and `R` `m × m`;
    /// [`Error::NonFinite`] for a non-finite weight;
    /// [`Error::InvalidMatrix`] unless `Q` is symmetric positive
    /// semidefinite and `R` symmetric positive definite;
    /// [`Error::NoConvergence`] if the doubling does not converge;
    /// [`Error::Unstable`] if the solution does not stabilise the loop (the
    /// plant is not stabilisable, or `(A, Q)` not detectable).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{Cart, DynStateSpace, MassSpring};
    /// use nalgebra::{DMatrix, dmatrix, dvector};
    ///
    /// let plant = DynStateSpace::from(MassSpring::nominal().state_space(Cart::Two)?);
    /// let q = DMatrix::from_diagonal(&dvector![0.0, 0.0, 1e6, 0.0]);
    /// let sol = plant.lqr(&q, &dmatrix![1.0])?;
    /// assert_eq!(sol.gain.shape(), (1, 4));
    /// assert!(sol.poles.iter().all(|p| p.re < 0.0));
    /// assert!(sol.residual < 1e-12);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn lqr(&self, q: &DMatrix<f64>, r: &DMatrix<f64>) -> Result<DynLqr, Error> {
        check_weight_shapes(self.states(), self.inputs(), q, r)?;
        continuous(self.a(), self.b(), q, r, Weights::Regulator(["Q", "R"])).map(DynLqr::from)
    }
}

impl DynStateSpace<Discrete> {
    /// Discrete-time LQR: the gain `K = (R + Bᵀ X B)⁻¹ Bᵀ X A` (`m × n`)
    /// minimising `Σ (xᵀ Q x + uᵀ R u)` for `u[k] = −K x[k]`, with `X` the
    /// stabilising solution of the discrete algebraic Riccati equation (see
    /// [`DynLqr`]). MATLAB's `lqr(sys, Q, R)` on a discrete model,
    /// python-control's `dlqr`; the run-time counterpart of
    /// [`dlqr`](crate::design::dlqr).
    ///
    /// # Errors
    ///
    /// As [`DynStateSpace::<Continuous>::lqr`]; [`Error::Unstable`] means a
    /// closed-loop pole on or outside the unit circle.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{Cart, DynStateSpace, MassSpring, Method};
    /// use nalgebra::{DMatrix, dmatrix, dvector};
    ///
    /// let d = MassSpring::nominal().state_space(Cart::Two)?.discretize(0.002, Method::Zoh)?;
    /// let plant = DynStateSpace::from(d);
    /// let q = DMatrix::from_diagonal(&dvector![1e4, 0.0, 1e6, 0.0]);
    /// let sol = plant.lqr(&q, &dmatrix![1.0])?;
    /// assert!(sol.poles.iter().all(|z| z.norm() < 1.0));
    /// assert!(sol.residual < 1e-12);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[doc(alias = "dlqr")]
    pub fn lqr(&self, q: &DMatrix<f64>, r: &DMatrix<f64>) -> Result<DynLqr, Error> {
        check_weight_shapes(self.states(), self.inputs(), q, r)?;
        discrete(
            self.a(),
            self.b(),
            q,
            r,
            Weights::Regulator(["Q", "R"]),
            Some(self.dt()),
        )
        .map(DynLqr::from)
    }
}

fn check_weight_shapes(
    n: usize,
    m: usize,
    q: &DMatrix<f64>,
    r: &DMatrix<f64>,
) -> Result<(), Error> {
    check_shape("Q", q, n, n)?;
    check_shape("R", r, m, m)
}

fn check_problem(
    a: &DMatrix<f64>,
    b: &DMatrix<f64>,
    q: &DMatrix<f64>,
    r: &DMatrix<f64>,
) -> Result<(), Error> {
    let (n, m) = (a.nrows(), b.ncols());
    check_shape("A", a, n, n)?;
    check_shape("B", b, n, m)?;
    check_weight_shapes(n, m, q, r)?;
    check_finite_dyn("A", a)?;
    check_finite_dyn("B", b)
}

/// The allocations one Riccati problem with `N` states and `M` inputs
/// needs; implemented for every pair of dimensions nalgebra can allocate,
/// `Const` (stack) or `Dyn` (heap).
pub(crate) trait RiccatiAlloc<N: Dim, M: Dim>:
    Allocator<N, N> + Allocator<N, M> + Allocator<M, N> + Allocator<M, M> + Allocator<N> + Allocator<M>
{
}
impl<N: Dim, M: Dim, T> RiccatiAlloc<N, M> for T where
    T: Allocator<N, N>
        + Allocator<N, M>
        + Allocator<M, N>
        + Allocator<M, M>
        + Allocator<N>
        + Allocator<M>
{
}

/// A solution in the caller's matrix sizes; [`DynLqr`] and the fixed-size
/// [`Lqr`](super::Lqr) are built from it.
pub(crate) struct Solution<N: Dim, M: Dim>
where
    DefaultAllocator: RiccatiAlloc<N, M>,
{
    pub(crate) gain: OMatrix<f64, M, N>,
    pub(crate) riccati: Square<N>,
    pub(crate) poles: Vec<Complex<f64>>,
    pub(crate) residual: f64,
    pub(crate) iterations: usize,
}

impl From<Solution<Dyn, Dyn>> for DynLqr {
    fn from(s: Solution<Dyn, Dyn>) -> Self {
        Self {
            gain: s.gain,
            riccati: s.riccati,
            poles: s.poles,
            residual: s.residual,
            iterations: s.iterations,
        }
    }
}

/// A copy on the heap, for the checks and diagnostics written for
/// run-time-sized matrices (outside the iterations).
fn heap<R: Dim, C: Dim>(m: &OMatrix<f64, R, C>) -> DMatrix<f64>
where
    DefaultAllocator: Allocator<R, C>,
{
    DMatrix::from_iterator(m.nrows(), m.ncols(), m.iter().copied())
}

/// The continuous solver behind [`care`], `DynStateSpace::lqr` and the
/// fixed-size [`lqr`](super::lqr); shapes already checked.
pub(crate) fn continuous<N: Dim, M: Dim>(
    a: &Square<N>,
    b: &OMatrix<f64, N, M>,
    q: &Square<N>,
    r: &OMatrix<f64, M, M>,
    weights: Weights,
) -> Result<Solution<N, M>, Error>
where
    DefaultAllocator: RiccatiAlloc<N, M>,
{
    check_weights(&heap(q), &heap(r), weights, true)?;
    let (q, r, weight) = balance_weights(q, r);
    let (dim, _) = a.shape_generic();
    let r_inv_bt = Lu::new(&r, "LQR (R)")?.solve(&b.transpose());
    let mut g = b * &r_inv_bt;
    symmetrize(&mut g);
    let eval = |x: &Square<N>| care_eval(a, b, &r_inv_bt, &q, x);
    // Newton step: (A − G X)ᵀ Δ + Δ (A − G X) + Res(X) = 0.
    let newton = |x: &Square<N>, res: &Square<N>| {
        let a_c = a - b * (&r_inv_bt * x);
        lyapunov(&a_c, res)
    };

    let scale = fro(a).max((fro(&g) * fro(&q)).sqrt());
    let gamma0 = if scale > 0.0 && scale.is_finite() {
        scale
    } else {
        1.0
    };
    let id = Square::<N>::identity_generic(dim, dim);
    let mut best: Option<(Square<N>, usize, f64)> = None;
    let mut last_err = None;
    for factor in SHIFTS {
        let gamma = gamma0 * factor;
        let attempt = (|| {
            let a_g = a - &id * gamma;
            let a_g_inv_g = Lu::new(&a_g, "LQR Cayley transform (A − γI)")?.solve(&g);
            let w = a_g.transpose() + &q * &a_g_inv_g;
            let w_inv = inverse(&w, "LQR Cayley transform (W)")?;
            let e0 = &id + w_inv.transpose() * (2.0 * gamma);
            let mut g0 = &a_g_inv_g * &w_inv * (2.0 * gamma);
            // H₀ = 2γ W⁻¹ Q A_γ⁻¹; Q A_γ⁻¹ = (A_γ⁻ᵀ Q)ᵀ as Q is symmetric.
            let q_a_inv = Lu::new(&a_g.transpose(), "LQR Cayley transform (A − γI)")?
                .solve(&q)
                .transpose();
            let mut h0 = &w_inv * &q_a_inv * (2.0 * gamma);
            symmetrize(&mut g0);
            symmetrize(&mut h0);
            sda(e0, g0, h0)
        })();
        match attempt {
            Ok((x, iterations)) => {
                let (x, res, stalled) =
                    refine(x, REFINE_STEPS, 4.0 * f64::EPSILON, false, &eval, &newton);
                if best.as_ref().is_none_or(|(_, _, r)| res < *r) {
                    best = Some((x, iterations, res));
                }
                // Another shift helps only where Newton could not finish
                // the job; at a stall the residual is the problem's floor,
                // and every shift lands on it (7 times the cost for nothing).
                if res <= GOOD_RESIDUAL || stalled {
                    break;
                }
            }
            Err(e) => last_err = Some(e),
        }
    }
    let Some((x, iterations, residual)) = best else {
        let err = last_err.unwrap_or(Error::NoConvergence {
            operation: "LQR Riccati doubling",
            iterations: MAX_ITERATIONS,
        });
        return Err(explain(a, b, None).unwrap_or(err));
    };
    let gain = &r_inv_bt * &x;
    finish(a, b, gain, x, weight, residual, iterations, None)
}

/// The discrete solver behind [`dare`], `DynStateSpace::lqr` and the
/// fixed-size [`dlqr`](super::dlqr); shapes already checked. `period` is
/// the model's (`None` for a bare equation).
pub(crate) fn discrete<N: Dim, M: Dim>(
    a: &Square<N>,
    b: &OMatrix<f64, N, M>,
    q: &Square<N>,
    r: &OMatrix<f64, M, M>,
    weights: Weights,
    period: Option<f64>,
) -> Result<Solution<N, M>, Error>
where
    DefaultAllocator: RiccatiAlloc<N, M>,
{
    check_weights(&heap(q), &heap(r), weights, false)?;
    let (q, r, weight) = balance_weights(q, r);
    let (m, _) = r.shape_generic();
    // A singular R (accepted for an equation only) is regularised for the
    // doubling, which needs R⁻¹; Newton on the true equation then removes δ.
    let (r_inv_bt, regularised) = match Lu::new(&r, "LQR (R)") {
        Ok(r_lu) => (r_lu.solve(&b.transpose()), false),
        Err(e) if matches!(weights, Weights::Regulator(_)) => return Err(e),
        Err(_) => {
            let delta = 1e-8 * (fro(&r) + fro(b).powi(2) * fro(&q));
            let delta = if delta > 0.0 && delta.is_finite() {
                delta
            } else {
                1.0
            };
            let r_reg = &r + OMatrix::<f64, M, M>::identity_generic(m, m) * delta;
            let r_lu = Lu::new(&r_reg, "DLQR (R + δI)")?;
            (r_lu.solve(&b.transpose()), true)
        }
    };
    let mut g = b * &r_inv_bt;
    symmetrize(&mut g);
    let (x, iterations) =
        sda(a.clone(), g, q.clone()).map_err(|err| explain(a, b, Some(1.0)).unwrap_or(err))?;
    let eval = |x: &Square<N>| match dare_gain(a, b, &r, x) {
        Ok(gain) => dare_eval(a, b, &q, x, &gain),
        Err(_) => (x * 0.0, f64::INFINITY),
    };
    // Newton (Hewer) step: Δ − A_clᵀ Δ A_cl = Res(X), A_cl = A − B K(X).
    let newton = |x: &Square<N>, res: &Square<N>| {
        let gain = dare_gain(a, b, &r, x).ok()?;
        let a_cl = a - b * &gain;
        stein(&a_cl, res)
    };
    let steps = if regularised {
        REGULARISED_REFINE_STEPS
    } else {
        REFINE_STEPS
    };
    let (x, residual, _) = refine(x, steps, 4.0 * f64::EPSILON, regularised, &eval, &newton);
    let gain = dare_gain(a, b, &r, &x)?;
    finish(
        a,
        b,
        gain,
        x,
        weight,
        residual,
        iterations,
        Some(period.unwrap_or(1.0)),
    )
}

/// Why no solution was found, when the plant says so: the first unstable
/// eigenvalue of `A` that the input cannot reach (`[A − λI, B]` loses rank
/// by the PBH test, to 1e-8 of `‖A‖ + ‖B‖`), as [`Error::Unstable`].
/// Without a stabilisable `(A, B)` the stabilising solution does not exist
/// and the doubling diverges; this names the mode. Only run on failure:
/// one SVD per unstable eigenvalue.
fn explain<N: Dim, M: Dim>(
    a: &Square<N>,
    b: &OMatrix<f64, N, M>,
    period: Option<f64>,
) -> Option<Error>
where
    DefaultAllocator: RiccatiAlloc<N, M>,
{
    let (a, b) = (heap(a), heap(b));
    let (n, m) = (a.nrows(), b.ncols());
    let poles = eigenvalues_dyn(&a).ok()?;
    let scale = fro(&a) + fro(&b);
    let zero = Complex::new(0.0, 0.0);
    let p = poles.into_iter().find(|&p| {
        let unstable = match period {
            None => p.re >= 0.0,
            Some(_) => p.norm() >= 1.0,
        };
        let pbh = DMatrix::from_fn(n, n + m, |i, j| {
            if j < n {
                Complex::new(a[(i, j)], 0.0) - if i == j { p } else { zero }
            } else {
                Complex::new(b[(i, j - n)], 0.0)
            }
        });
        unstable
            && pbh
                .try_svd(false, false, f64::EPSILON, 100 * (n + m))
                .is_some_and(|svd| svd.singular_values.min() <= 1e-8 * scale)
    })?;
    Some(Error::Unstable {
        operation: "LQR: no stabilising Riccati solution, (A, B) is not stabilisable \
                    (an unstable mode the input cannot reach)",
        re: p.re,
        im: p.im,
    })
}

/// Newton refinement of a Riccati solution: up to `steps` steps, each kept
/// only if it lowers the relative residual, and none once that is below
/// `good` unless `to_stagnation`; returns `X`, its residual, and whether
/// the refinement stalled (a Newton step was solved but did not lower the
/// residual: `X` is then as accurate as rounding lets this problem be).
/// `step(X, Res)` solves the correction's linear equation.
fn refine<N: Dim>(
    mut x: Square<N>,
    steps: usize,
    good: f64,
    to_stagnation: bool,
    eval: &impl Fn(&Square<N>) -> (Square<N>, f64),
    step: &impl Fn(&Square<N>, &Square<N>) -> Option<Square<N>>,
) -> (Square<N>, f64, bool)
where
    DefaultAllocator: Allocator<N, N>,
{
    let (mut res, mut residual) = eval(&x);
    for _ in 0..steps {
        if residual == 0.0 || residual <= good && !to_stagnation {
            break;
        }
        let Some(delta) = step(&x, &res) else {
            break;
        };
        if !finite(&delta) {
            break;
        }
        let mut next = &x + &delta;
        symmetrize(&mut next);
        let (next_res, next_residual) = eval(&next);
        if next_residual < residual {
            (x, res, residual) = (next, next_res, next_residual);
        } else {
            return (x, residual, true);
        }
    }
    (x, residual, false)
}

/// The solution: `riccati` is of the weights scaled by `weight` (see
/// [`balance_weights`]) and is scaled back here; the closed loop must be
/// stable in the domain of `period` (`None`: continuous).
#[allow(clippy::too_many_arguments)]
fn finish<N: Dim, M: Dim>(
    a: &Square<N>,
    b: &OMatrix<f64, N, M>,
    gain: OMatrix<f64, M, N>,
    riccati: Square<N>,
    weight: f64,
    residual: f64,
    iterations: usize,
    period: Option<f64>,
) -> Result<Solution<N, M>, Error>
where
    DefaultAllocator: RiccatiAlloc<N, M>,
{
    if !finite(&gain) {
        return Err(Error::Overflow {
            operation: "LQR gain",
        });
    }
    let riccati = riccati * (1.0 / weight);
    if !finite(&riccati) {
        return Err(Error::Overflow {
            operation: "LQR Riccati solution (X exceeds f64::MAX for these weights)",
        });
    }
    let a_cl = heap(&(a - b * &gain));
    let poles = eigenvalues_dyn(&a_cl)?;
    if let Some(p) = first_unstable_dyn(&poles, &a_cl, period) {
        return Err(Error::Unstable {
            operation: "LQR: the Riccati solution does not stabilise the loop \
                        (is (A, B) stabilisable and (A, Q) detectable?)",
            re: p.re,
            im: p.im,
        });
    }
    Ok(Solution {
        gain,
        riccati,
        poles,
        residual,
        iterations,
    })
}

/// `Q` and `R` times one power of two `c` that brings the geometric mean of
/// their largest entries near 1 (the LQR problem does not change when both
/// weights are scaled alike: `X` scales with them, `K` not at all), and
/// `c`. Weights of 1e308 then neither overflow nor make `R⁻¹` underflow.
fn balance_weights<N: Dim, M: Dim>(
    q: &Square<N>,
    r: &OMatrix<f64, M, M>,
) -> (Square<N>, OMatrix<f64, M, M>, f64)
where
    DefaultAllocator: RiccatiAlloc<N, M>,
{
    let (q_max, r_max) = (q.amax(), r.amax());
    let (sq, sr) = (pow2_floor(q_max), pow2_floor(r_max));
    // 1 / √(sq sr), rounded to a power of two, without forming sq sr.
    let c = if q_max > 0.0 && r_max > 0.0 {
        1.0 / pow2_floor(sq.sqrt() * sr.sqrt())
    } else if q_max > 0.0 {
        1.0 / sq
    } else {
        1.0 / sr
    };
    (q * c, r * c, c)
}

/// The CARE left side `Aᵀ X + X A − X G X + Q` and its relative norm.
///
/// `X G X` is formed as `(X B)(R⁻¹ Bᵀ X)`: with a large `X`, the product
/// `(X G) X` loses about `ε ‖X G‖ ‖X‖`, which can be a 1e-9 part of the
/// result, while the factored form stays near `ε ‖X G X‖`.
fn care_eval<N: Dim, M: Dim>(
    a: &Square<N>,
    b: &OMatrix<f64, N, M>,
    r_inv_bt: &OMatrix<f64, M, N>,
    q: &Square<N>,
    x: &Square<N>,
) -> (Square<N>, f64)
where
    DefaultAllocator: RiccatiAlloc<N, M>,
{
    let at_x = a.transpose() * x;
    let xgx = (x * b) * (r_inv_bt * x);
    let lhs = &at_x + at_x.transpose() - &xgx + q;
    let rel = relative(fro(&lhs), &[2.0 * fro(&at_x), fro(&xgx), fro(q)]);
    (lhs, rel)
}

/// `K = (R + Bᵀ X B)⁻¹ Bᵀ X A`.
fn dare_gain<N: Dim, M: Dim>(
    a: &Square<N>,
    b: &OMatrix<f64, N, M>,
    r: &OMatrix<f64, M, M>,
    x: &Square<N>,
) -> Result<OMatrix<f64, M, N>, Error>
where
    DefaultAllocator: RiccatiAlloc<N, M>,
{
    let bt_x = b.transpose() * x;
    let s = r + &bt_x * b;
    Ok(Lu::new(&s, "DLQR (R + Bᵀ X B)")?.solve(&(&bt_x * a)))
}

/// The DARE residual `Aᵀ X A − Aᵀ X B K + Q − X` (with `K` the optimal gain
/// for `X`) and its relative norm.
fn dare_eval<N: Dim, M: Dim>(
    a: &Square<N>,
    b: &OMatrix<f64, N, M>,
    q: &Square<N>,
    x: &Square<N>,
    gain: &OMatrix<f64, M, N>,
) -> (Square<N>, f64)
where
    DefaultAllocator: RiccatiAlloc<N, M>,
{
    let at = a.transpose();
    let atxa = &at * (x * a);
    let cross = (&at * (x * b)) * gain;
    let lhs = &atxa - &cross + q - x;
    let rel = relative(fro(&lhs), &[fro(&atxa), fro(x), fro(&cross), fro(q)]);
    (lhs, rel)
}

fn relative(err: f64, terms: &[f64]) -> f64 {
    let scale: f64 = terms.iter().sum();
    if scale > 0.0 { err / scale } else { err }
}

/// Checks the weights for `weights`; `continuous` says whether `R` must be
/// definite even for a bare equation (its inverse is in the equation).
pub(crate) fn check_weights(
    q: &DMatrix<f64>,
    r: &DMatrix<f64>,
    weights: Weights,
    continuous: bool,
) -> Result<(), Error> {
    let [q_name, r_name] = match weights {
        Weights::Regulator(names) => names,
        Weights::Equation => ["Q", "R"],
    };
    check_finite_dyn(q_name, q)?;
    check_finite_dyn(r_name, r)?;
    // Scaled to unit largest entry first: the norm of weights near
    // f64::MAX must not overflow.
    let q = q / pow2_floor(q.amax());
    let r = r / pow2_floor(r.amax());
    let symmetric_enough = |m: &DMatrix<f64>| (m - m.transpose()).norm() <= 1e-12 * m.norm();
    if !symmetric_enough(&q) {
        return Err(Error::InvalidMatrix {
            matrix: q_name,
            reason: "must be symmetric",
        });
    }
    if !symmetric_enough(&r) {
        return Err(Error::InvalidMatrix {
            matrix: r_name,
            reason: "must be symmetric",
        });
    }
    if matches!(weights, Weights::Regulator(_)) && min_symmetric_eigenvalue(&q)? < -1e-12 * q.norm()
    {
        return Err(Error::InvalidMatrix {
            matrix: q_name,
            reason: "must be positive semidefinite",
        });
    }
    let m = r.nrows();
    let min_r = min_symmetric_eigenvalue(&r)?;
    if matches!(weights, Weights::Regulator(_)) || continuous {
        if min_r <= f64::EPSILON * m as f64 * r.norm() || m == 0 {
            return Err(Error::InvalidMatrix {
                matrix: r_name,
                reason: "must be positive definite",
            });
        }
    } else if min_r < -1e-12 * r.norm() || m == 0 {
        return Err(Error::InvalidMatrix {
            matrix: r_name,
            reason: "must be positive semidefinite",
        });
    }
    Ok(())
}

fn min_symmetric_eigenvalue(m: &DMatrix<f64>) -> Result<f64, Error> {
    if m.is_empty() {
        return Ok(0.0);
    }
    let iterations = 200 * m.nrows();
    let eig = m
        .clone()
        .try_symmetric_eigen(f64::EPSILON, iterations)
        .ok_or(Error::NoConvergence {
            operation: "symmetric eigenvalues",
            iterations,
        })?;
    Ok(eig
        .eigenvalues
        .iter()
        .copied()
        .fold(f64::INFINITY, f64::min))
}
