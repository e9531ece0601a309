//! Continuous → discrete conversion: [`Discretization::Zoh`] (exact for a
//! zero-order-held input), [`Discretization::Tustin`], [`Discretization::ForwardEuler`] and
//! [`Discretization::BackwardEuler`], plus the matrix exponential [`expm`];
//! and back: [`StateSpace::d2c`] / [`DynStateSpace::d2c`] invert each
//! method (ZOH through the principal matrix logarithm [`logm`]).
//!
//! The definitions match SciPy's `cont2discrete` (methods `zoh`, `bilinear`,
//! `euler`, `backward_diff`); the reference fixtures in `tests/data/` check it.
//!
//! Each algorithm is written once, generic over nalgebra's [`Dim`]: a
//! fixed-size [`StateSpace`] runs it on stack matrices without allocating,
//! a run-time-sized [`DynStateSpace`] on heap matrices, with the same
//! arithmetic in the same order (the results agree bit for bit).

use nalgebra::{Const, DMatrix, DefaultAllocator, Dim, OMatrix, SMatrix, U0, allocator::Allocator};

use crate::error::{Error, check_dt};
use crate::kernels::linalg::Lu;
use crate::model::{Continuous, Discrete, DynStateSpace, StateSpace};

mod d2c;
mod logm;

pub use logm::{LOGM_MAX_ERROR, logm, logm_dyn};

/// How to turn a continuous model into a discrete one with period `h`.
///
/// With `α` the generalised-bilinear weight (Tustin ½, forward Euler 0,
/// backward Euler 1) and `W = (I − α h A)⁻¹`, the non-ZOH methods are
///
/// ```text
/// Ad = W (I + (1 − α) h A)    Bd = W h B    Cd = C W    Dd = D + α C Bd
/// ```
///
/// exactly as SciPy's `cont2discrete`. Note that Tustin and backward Euler
/// change `C` and `D` as well; ZOH and forward Euler keep them.
///
/// # Examples
///
/// `ẋ = −x + u` at 0.1 s: every method keeps the pole inside the unit
/// circle, at `e^{−0.1}` (ZOH) or an approximation of it.
///
/// ```
/// use ctrlab::{Discretization, StateSpace};
/// use ctrlab::nalgebra::matrix;
///
/// let sys = StateSpace::continuous(matrix![-1.0], matrix![1.0], matrix![1.0], matrix![0.0])?;
/// let pole = |m| -> Result<f64, ctrlab::Error> { Ok(sys.discretize(0.1, m)?.a()[(0, 0)]) };
/// assert!((pole(Discretization::Zoh)? - (-0.1f64).exp()).abs() < 1e-15);
/// assert!((pole(Discretization::ForwardEuler)? - 0.9).abs() < 1e-15); // 1 + h a
/// assert!((pole(Discretization::BackwardEuler)? - 1.0 / 1.1).abs() < 1e-15); // 1 / (1 − h a)
/// assert!((pole(Discretization::Tustin)? - 0.95 / 1.05).abs() < 1e-15);
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum Discretization {
    /// Zero-order hold, exact when the input is constant over each period:
    /// `[[Ad, Bd], [0, I]] = exp([[A, B], [0, 0]] h)`.
    Zoh,
    /// Bilinear (trapezoidal) transform, `s ← (2/h)(z − 1)/(z + 1)`; maps the
    /// stable half-plane onto the unit disc.
    Tustin,
    /// Forward Euler, `Ad = I + h A`, `Bd = h B`.
    ForwardEuler,
    /// Backward Euler, `Ad = (I − h A)⁻¹`.
    BackwardEuler,
}

impl<const N: usize, const M: usize, const P: usize> StateSpace<N, M, P, Continuous> {
    /// The discrete model with sampling period `dt` seconds by `method`.
    ///
    /// # Errors
    ///
    /// - [`Error::InvalidParameter`] named `"dt"` unless `dt` is finite and > 0;
    /// - [`Error::Singular`] when Tustin or backward Euler meets a singular
    ///   `I − α h A` (a pole exactly at `1/(α h)`);
    /// - [`Error::Overflow`] when `dt` is so large for the dynamics that the
    ///   result is not representable;
    /// - [`Error::IllConditioned`] (ZOH) when the rounding error of the
    ///   matrix exponential may exceed [`EXPM_MAX_ERROR`] (a lightly damped
    ///   mode over millions of its periods).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{Discretization, StateSpace};
    /// use ctrlab::nalgebra::matrix;
    ///
    /// // x' = -x + u held for 0.1 s: Ad = e^-0.1, Bd = 1 - e^-0.1.
    /// let sys = StateSpace::continuous(matrix![-1.0], matrix![1.0], matrix![1.0], matrix![0.0])?;
    /// let d = sys.discretize(0.1, Discretization::Zoh)?;
    /// assert!((d.a()[(0, 0)] - (-0.1f64).exp()).abs() < 1e-15);
    /// assert!((d.b()[(0, 0)] - (1.0 - (-0.1f64).exp())).abs() < 1e-15);
    /// assert_eq!(d.dt(), 0.1);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[doc(alias = "c2d")]
    pub fn discretize(
        &self,
        dt: f64,
        method: Discretization,
    ) -> Result<StateSpace<N, M, P, Discrete>, Error> {
        check_dt(dt)?;
        let ((ad, bd, cd, dd), operation) =
            discretize_parts(self.a(), self.b(), self.c(), self.d(), dt, method)?;
        StateSpace::from_computed(ad, bd, cd, dd, dt, operation)
    }
}

impl DynStateSpace<Continuous> {
    /// The discrete model with sampling period `dt` seconds by `method`:
    /// the algorithm of [`StateSpace::discretize`] (ZOH by scaling and
    /// squaring with its error estimate, the generalised bilinear transform
    /// for the others), run on the heap; the result agrees with the
    /// fixed-size one bit for bit.
    ///
    /// # Errors
    ///
    /// As [`StateSpace::discretize`]: [`Error::InvalidParameter`] named
    /// `"dt"`, [`Error::Singular`], [`Error::Overflow`],
    /// [`Error::IllConditioned`].
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{DynStateSpace, Discretization};
    /// use ctrlab::nalgebra::dmatrix;
    ///
    /// // x' = -x + u held for 0.1 s: Ad = e^-0.1, Bd = 1 - e^-0.1.
    /// let sys = DynStateSpace::continuous(dmatrix![-1.0], dmatrix![1.0], dmatrix![1.0], dmatrix![0.0])?;
    /// let d = sys.discretize(0.1, Discretization::Zoh)?;
    /// assert!((d.a()[(0, 0)] - (-0.1f64).exp()).abs() < 1e-15);
    /// assert!((d.b()[(0, 0)] - (1.0 - (-0.1f64).exp())).abs() < 1e-15);
    /// assert_eq!(d.dt(), 0.1);
    /// // Tustin changes C and D too: Dd = α C Bd with α = ½.
    /// let t = sys.discretize(0.1, Discretization::Tustin)?;
    /// assert!((t.d()[(0, 0)] - 0.5 * t.b()[(0, 0)]).abs() < 1e-15);
    /// assert!(sys.discretize(0.0, Discretization::Zoh).is_err());
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[doc(alias = "c2d")]
    pub fn discretize(
        &self,
        dt: f64,
        method: Discretization,
    ) -> Result<DynStateSpace<Discrete>, Error> {
        check_dt(dt)?;
        let ((ad, bd, cd, dd), operation) =
            discretize_parts(self.a(), self.b(), self.c(), self.d(), dt, method)?;
        DynStateSpace::from_computed(ad, bd, cd, dd, Discrete::new_unchecked(dt), operation)
    }
}

/// The allocations the conversions of a model with `N` states, `M`
/// inputs and `P` outputs need (`Allocator<N, P>` for `Cᵀ`): one bound,
/// met by every triple of nalgebra's dimensions.
pub(crate) trait ModelAlloc<N: Dim, M: Dim, P: Dim>:
    Allocator<N, N>
    + Allocator<N, M>
    + Allocator<P, N>
    + Allocator<N, P>
    + Allocator<P, M>
    + Allocator<N>
{
}

impl<N: Dim, M: Dim, P: Dim, T> ModelAlloc<N, M, P> for T where
    T: Allocator<N, N>
        + Allocator<N, M>
        + Allocator<P, N>
        + Allocator<N, P>
        + Allocator<P, M>
        + Allocator<N>
{
}

/// The four matrices of a model with `N` states, `M` inputs, `P` outputs.
type Parts<N, M, P> = (
    OMatrix<f64, N, N>,
    OMatrix<f64, N, M>,
    OMatrix<f64, P, N>,
    OMatrix<f64, P, M>,
);

/// `(Ad, Bd, Cd, Dd)` of `(A, B, C, D)` by `method` at period `dt` (already
/// checked), with the name of the operation for an overflow of the result.
fn discretize_parts<N: Dim, M: Dim, P: Dim>(
    a: &OMatrix<f64, N, N>,
    b: &OMatrix<f64, N, M>,
    c: &OMatrix<f64, P, N>,
    d: &OMatrix<f64, P, M>,
    dt: f64,
    method: Discretization,
) -> Result<(Parts<N, M, P>, &'static str), Error>
where
    DefaultAllocator: ModelAlloc<N, M, P>,
{
    match method {
        Discretization::Zoh => {
            const OP: &str = "ZOH discretisation";
            let (ad, bd) = zoh(a, b, dt)?;
            Ok(((ad, bd, c.clone(), d.clone()), OP))
        }
        Discretization::Tustin => gbt(a, b, c, d, dt, 0.5, "Tustin discretisation"),
        Discretization::ForwardEuler => gbt(a, b, c, d, dt, 0.0, "forward Euler discretisation"),
        Discretization::BackwardEuler => gbt(a, b, c, d, dt, 1.0, "backward Euler discretisation"),
    }
}

/// Generalised bilinear transform with weight `alpha` (SciPy's `gbt`).
fn gbt<N: Dim, M: Dim, P: Dim>(
    a: &OMatrix<f64, N, N>,
    b: &OMatrix<f64, N, M>,
    c: &OMatrix<f64, P, N>,
    d: &OMatrix<f64, P, M>,
    dt: f64,
    alpha: f64,
    operation: &'static str,
) -> Result<(Parts<N, M, P>, &'static str), Error>
where
    DefaultAllocator: ModelAlloc<N, M, P>,
{
    let (n, _) = a.shape_generic();
    let id = OMatrix::<f64, N, N>::identity_generic(n, n);
    let parts = if alpha == 0.0 {
        (id + a * dt, b * dt, c.clone(), d.clone())
    } else {
        let ima = &id - a * (alpha * dt);
        let lu = Lu::new(&ima, operation)?;
        let ad = lu.solve(&(id + a * ((1.0 - alpha) * dt)));
        let bd = lu.solve(&(b * dt));
        let cd = Lu::solve_right(&ima, c, operation)?;
        let dd = d + c * &bd * alpha;
        (ad, bd, cd, dd)
    };
    Ok((parts, operation))
}

/// Degree of the diagonal Padé approximant; with the scaling below
/// (‖W‖∞ ≤ ½) its relative error bound is 3.4e-16 (Golub & Van Loan,
/// *Matrix Computations*, §11.3).
const PADE_Q: usize = 6;

/// Largest estimated relative error of a ZOH discretisation or [`expm`]
/// that is returned; above it the result is refused with
/// [`Error::IllConditioned`]. Scaling and squaring loses accuracy only
/// when the squarings amplify rounding (about `ε ‖A h‖` for a lightly
/// damped or rotating mode: a rotation by 10¹⁵ rad cannot be computed).
///
/// # Examples
///
/// ```
/// use ctrlab::{Error, discretize::{EXPM_MAX_ERROR, expm}};
/// use ctrlab::nalgebra::matrix;
///
/// let r = expm(&matrix![0.0, -1e3; 1e3, 0.0])?; // error about 1e-13
/// assert!((r[(1, 0)] - 1e3f64.sin()).abs() < 1e-10);
/// match expm(&matrix![0.0, -1e15; 1e15, 0.0]) {
///     Err(Error::IllConditioned { error, limit, .. }) => assert!(error > limit && limit == EXPM_MAX_ERROR),
///     other => panic!("{other:?}"),
/// }
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub const EXPM_MAX_ERROR: f64 = 1e-8;

/// `(Ad, Bd)` of a model under a held input.
pub(crate) type Held<N, M> = (OMatrix<f64, N, N>, OMatrix<f64, N, M>);

/// Exact ZOH: `Ad = exp(A h)`, `Bd = ∫₀ʰ exp(A s) ds · B`.
///
/// Both come out of `exp(W)` with `W = [[A, B], [0, 0]] h`, computed by
/// scaling and squaring a diagonal Padé approximant. `W` is block upper
/// triangular with a zero lower-right block, so every polynomial in it is
/// `[[p(X), r(X) Y], [0, p(0) I]]` with `X = A h`, `Y = B h`; the algorithm runs
/// on the N×N and N×M blocks alone (no (N+M)-sized matrix, which const
/// generics cannot spell).
///
/// The squarings `[[E, G], [0, I]]² = [[E², E G + G], [0, I]]` amplify
/// rounding: by about `2^s ε` for a mode that neither decays nor grows
/// much (a rotation by 10¹⁵ rad cannot be computed), and for the slow modes
/// of a stiff model under a step far longer than its fastest time constant
/// (`exp` of a slow mode after many halvings is `1` plus less than `ε`).
/// When the squarings are many enough for that to matter
/// (`2^s (N + 2) ε > `[`EXPM_MAX_ERROR`]) a componentwise bound on the
/// rounding error is carried along, and a result whose bound exceeds the
/// limit is refused rather than returned wrong.
pub(crate) fn zoh<N: Dim, M: Dim>(
    a: &OMatrix<f64, N, N>,
    b: &OMatrix<f64, N, M>,
    h: f64,
) -> Result<Held<N, M>, Error>
where
    DefaultAllocator: Allocator<N, N> + Allocator<N, M> + Allocator<N>,
{
    const OP: &str = "ZOH discretisation";
    let (n, m) = b.shape_generic();
    let mut x = a * h;
    let mut y = b * h;
    if x.iter().chain(y.iter()).any(|v| !v.is_finite()) {
        return Err(Error::Overflow { operation: OP });
    }
    // ∞-norm of W: the largest row sum over [X Y].
    let row_sum = |i: usize| -> f64 {
        x.row(i).iter().map(|v| v.abs()).sum::<f64>()
            + y.row(i).iter().map(|v| v.abs()).sum::<f64>()
    };
    let norm = (0..n.value()).map(row_sum).fold(0.0f64, f64::max);
    if !norm.is_finite() {
        // Row sums beyond f64::MAX: 2^1024 and more halvings would be
        // needed, and the squarings could not be accurate anyway.
        return Err(Error::Overflow { operation: OP });
    }
    let squarings = if norm > 0.5 {
        // 2 + floor(log2 ‖W‖) halvings bring the norm below ½.
        (norm.log2().floor() as i32 + 2).max(0)
    } else {
        0
    };
    let scale = 0.5f64.powi(squarings);
    x *= scale;
    y *= scale;

    let id = OMatrix::<f64, N, N>::identity_generic(n, n);
    let mut nx = id.clone();
    let mut dx = id.clone();
    let mut ny = OMatrix::<f64, N, M>::zeros_generic(n, m);
    let mut dy = OMatrix::<f64, N, M>::zeros_generic(n, m);
    let mut xk = id.clone(); // X^k
    let mut pk = y; // X^(k-1) Y
    let mut c = 1.0;
    let mut sign = 1.0;
    for k in 1..=PADE_Q {
        c *= (PADE_Q - k + 1) as f64 / (k * (2 * PADE_Q - k + 1)) as f64;
        sign = -sign;
        xk = &x * &xk;
        nx += &xk * c;
        dx += &xk * (sign * c);
        ny += &pk * c;
        dy += &pk * (sign * c);
        pk = &x * &pk;
    }
    let lu = Lu::new(&dx, OP)?;
    let mut e = lu.solve(&nx);
    let mut g = lu.solve(&(&ny - &dy));
    let unit = (n.value() + 2) as f64 * f64::EPSILON;
    if 2f64.powi(squarings) * unit <= EXPM_MAX_ERROR {
        for _ in 0..squarings {
            g = &e * &g + &g;
            e = &e * &e;
        }
    } else {
        // Componentwise error bounds: the solve's to start (ε-relative to
        // the magnitudes that made E and G: |D⁻¹| (|N| + |D| |E|)), then
        // δ(E²) = δE E + E δE and δ(E G + G) = (E + I) δG + δE G, plus each
        // step's rounding. E is judged at every step against max(|E|, 1) (a
        // decaying mode's tiny entries need no relative accuracy; a
        // rotation whose rounding has made it decay must not pass), G at
        // the end.
        let inv = lu.solve(&id).abs();
        let mut de = &inv * (nx.abs() + dx.abs() * e.abs()) * unit;
        let mut dg = &inv * ((&ny - &dy).abs() + dx.abs() * g.abs()) * unit;
        // A bound that overflowed (NaN from inf · 0 included) is no bound.
        let largest = |m: &[f64]| {
            m.iter().fold(
                0.0f64,
                |w, &v| {
                    if v.is_nan() { f64::INFINITY } else { w.max(v) }
                },
            )
        };
        let mut error = 0.0f64;
        for _ in 0..squarings {
            let ea = e.abs();
            error = error.max(largest(de.as_slice()) / ea.amax().max(1.0));
            if error.is_nan() || error > EXPM_MAX_ERROR {
                break;
            }
            let ga = g.abs();
            dg = (&ea + &id) * &dg + &de * &ga + (&ea * &ga + &ga) * unit;
            de = &de * &ea + &ea * &de + &ea * &ea * unit;
            g = &e * &g + &g;
            e = &e * &e;
        }
        error = error.max(largest(de.as_slice()) / e.abs().amax().max(1.0));
        if g.amax() > 0.0 {
            error = error.max(largest(dg.as_slice()) / g.amax());
        }
        if error.is_nan() || error > EXPM_MAX_ERROR {
            return Err(Error::IllConditioned {
                operation: "matrix exponential (scaling and squaring amplifies rounding \
                            past the result: a fast rotation, or a step far longer than \
                            the fastest time constant)",
                error,
                limit: EXPM_MAX_ERROR,
            });
        }
    }
    if e.iter().chain(g.iter()).any(|v| !v.is_finite()) {
        return Err(Error::Overflow { operation: OP });
    }
    Ok((e, g))
}

/// The matrix exponential `exp(A)` by scaling and squaring a degree-6 Padé
/// approximant (the algorithm behind [`Discretization::Zoh`]).
///
/// # Errors
///
/// [`Error::NonFinite`] for a NaN or infinite entry; [`Error::Overflow`]
/// when the result is not representable; [`Error::IllConditioned`] when
/// its estimated rounding error exceeds [`EXPM_MAX_ERROR`] (see there).
///
/// # Examples
///
/// ```
/// use ctrlab::discretize::expm;
/// use ctrlab::nalgebra::matrix;
///
/// // A rotation generator: exp([[0, -θ], [θ, 0]]) is the rotation by θ.
/// let theta = 0.3f64;
/// let r = expm(&matrix![0.0, -theta; theta, 0.0])?;
/// assert!((r[(0, 0)] - theta.cos()).abs() < 1e-15);
/// assert!((r[(1, 0)] - theta.sin()).abs() < 1e-15);
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub fn expm<const N: usize>(a: &SMatrix<f64, N, N>) -> Result<SMatrix<f64, N, N>, Error> {
    crate::error::check_finite("A", a)?;
    zoh(a, &SMatrix::<f64, N, 0>::zeros(), 1.0).map(|(e, _)| e)
}

/// [`expm`] of a square run-time-sized matrix: the same scaling and
/// squaring, error estimate and refusals; the result agrees with the
/// fixed-size one bit for bit.
///
/// # Errors
///
/// [`Error::DimensionMismatch`] named `"A"` unless `a` is square; as
/// [`expm`] otherwise.
///
/// # Examples
///
/// ```
/// use ctrlab::discretize::expm_dyn;
/// use ctrlab::nalgebra::{DMatrix, dmatrix};
///
/// let theta = 0.3f64;
/// let r = expm_dyn(&dmatrix![0.0, -theta; theta, 0.0])?;
/// assert!((r[(0, 0)] - theta.cos()).abs() < 1e-15);
/// assert!((r[(1, 0)] - theta.sin()).abs() < 1e-15);
/// // A nilpotent shift of any size: exp is the truncated series.
/// let n = 6;
/// let shift = DMatrix::from_fn(n, n, |i, j| if j == i + 1 { 1.0 } else { 0.0 });
/// assert!((expm_dyn(&shift)?[(0, n - 1)] - 1.0 / 120.0).abs() < 1e-15);
/// assert!(expm_dyn(&DMatrix::zeros(2, 3)).is_err());
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub fn expm_dyn(a: &DMatrix<f64>) -> Result<DMatrix<f64>, Error> {
    crate::error::check_shape("A", a, a.nrows(), a.nrows())?;
    crate::error::check_finite_dyn("A", a)?;
    let none = OMatrix::<f64, _, U0>::zeros_generic(a.shape_generic().0, Const::<0>);
    zoh(a, &none, 1.0).map(|(e, _)| e)
}
