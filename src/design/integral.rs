//! Integral action: a plant augmented with integrators of its outputs
//! ([`augment_integral`]), the linear-quadratic-integral design ([`lqi`],
//! [`dlqi`]), and the discrete controller with anti-windup
//! ([`IntegralFeedback`]).

use nalgebra::{DMatrix, SMatrix, SVector};

use super::IntegralAction;
#[cfg(doc)]
use super::lqr::{dlqr, lqr};
use super::observer::finite;
use crate::design::Controller;
use crate::error::{Error, check_finite};
use crate::model::{Continuous, Discrete, Domain, DynStateSpace, StateSpace, Token, period_of};

/// `sys` augmented with one integrator per output, the plant that
/// linear-quadratic-integral design works on (MATLAB's `lqi` convention).
///
/// The augmented state is `[x; z]` (`NA = N + P` states; a mismatch is a
/// compile-time error), with `z` the integral of the tracking error
/// `r − y`, `y = C x + D u`:
///
/// ```text
/// continuous: z' = r − y,                  A_a = [A 0; −C 0],   B_a = [B; −D]
/// discrete:   z[k+1] = z[k] + T (r[k] − y[k]),  A_a = [A 0; −T C I], B_a = [B; −T D]
/// ```
///
/// (forward Euler at the model's period `T` in discrete time, as MATLAB's
/// `lqi` documents), and outputs `y = [C 0] [x; z] + D u`. The reference
/// `r` is an exogenous input and does not appear in the augmented model:
/// the control law `u = −K [x; z]` is designed with `r = 0`.
///
/// To integrate only some outputs, or a combination of states, give the
/// model those outputs first ([`StateSpace::with_output`]).
///
/// python-control's `lqr(sys, Q, R, integral_action=C_i)` augments the
/// other way round: its integrator state is `ζ = ∫ C_i x` (continuous) or
/// `ζ[k+1] = ζ[k] + C_i x[k]` (discrete, no `T`), so `z = −ζ` (continuous)
/// or `z = −T ζ` (discrete) when `r = 0`. With `S = diag(I, −I)` or
/// `diag(I, −T I)`, the same design is `Q = S⁻ᵀ Q_pc S⁻¹`, and then
/// `K = K_pc S⁻¹` and `X = S⁻ᵀ X_pc S⁻¹` (the tests check exactly this
/// against python-control).
///
/// # Errors
///
/// [`Error::Overflow`] if `T C` or `T D` overflows.
///
/// # Examples
///
/// ```
/// use ctrlab::{MassSpring, Cart, design::augment_integral};
///
/// let plant = MassSpring::nominal().state_space(Cart::Two)?; // output x2
/// let aug = augment_integral::<4, 1, 1, 5, _>(&plant)?;
/// // z' = r − x2: the last row of A is −C.
/// assert_eq!(aug.a().row(4).iter().copied().collect::<Vec<_>>(), [0.0, 0.0, -1.0, 0.0, 0.0]);
/// // A new pole at s = 0: the integrator.
/// assert!(aug.poles()?.iter().any(|p| p.norm() < 1e-9));
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[doc(alias = "lqi")]
pub fn augment_integral<const N: usize, const M: usize, const P: usize, const NA: usize, D>(
    sys: &StateSpace<N, M, P, D>,
) -> Result<StateSpace<NA, M, P, D>, Error>
where
    D: Domain,
{
    const { assert!(NA == N + P, "the augmented model has NA = N + P states") };
    StateSpace::try_from(&augmented(&DynStateSpace::from(sys))?)
}

/// [`augment_integral`] of a model of any size: the one implementation
/// (a fixed-size model's is copied to the heap and back, design-time work).
pub(super) fn augmented<D: Domain>(sys: &DynStateSpace<D>) -> Result<DynStateSpace<D>, Error> {
    let (n, m, p) = (sys.states(), sys.inputs(), sys.outputs());
    let (scale, keep) = match period_of(&sys.domain()) {
        None => (1.0, 0.0),
        Some(dt) => (dt, 1.0),
    };
    let mut a = DMatrix::zeros(n + p, n + p);
    a.view_mut((0, 0), (n, n)).copy_from(sys.a());
    a.view_mut((n, 0), (p, n)).copy_from(&(sys.c() * -scale));
    a.view_mut((n, n), (p, p))
        .copy_from(&(DMatrix::<f64>::identity(p, p) * keep));
    let mut b = DMatrix::zeros(n + p, m);
    b.view_mut((0, 0), (n, m)).copy_from(sys.b());
    b.view_mut((n, 0), (p, m)).copy_from(&(sys.d() * -scale));
    let mut c = DMatrix::zeros(p, n + p);
    c.view_mut((0, 0), (p, n)).copy_from(sys.c());
    DynStateSpace::from_computed(
        a,
        b,
        c,
        sys.d().clone(),
        sys.domain(),
        "integral augmentation",
    )
}

/// Continuous-time linear-quadratic-integral design (MATLAB's `lqi`): the
/// LQR gain `K = [K_x K_z]` of the plant augmented with integrators of its
/// outputs ([`augment_integral`], which documents the state convention),
/// minimising `∫ ([x; z]ᵀ Q [x; z] + uᵀ R u) dt`. The control law is
/// `u = −K_x x − K_z z` with `z' = r − y`.
///
/// Either model size ([`IntegralAction`]): for a `StateSpace<N, M, P, _>`,
/// `Q` is an `SMatrix<f64, NA, NA>` with `NA = N + P` (checked at compile
/// time) and the result an `Lqr<Const<NA>, Const<M>>`; for a
/// `DynStateSpace`, `Q` is an `(n + p) × (n + p)` `DMatrix` (checked when
/// called) and the result a [`DynLqr`](super::DynLqr).
///
/// # Errors
///
/// [`Error::DimensionMismatch`] named `"Q"` or `"R"` for a weight of the
/// wrong size (a run-time-sized model); as [`augment_integral`] and
/// [`lqr`] ([`Error::Unstable`] when, for
/// instance, the plant has a zero at `s = 0`, which an integrator cannot
/// get past).
///
/// # Examples
///
/// ```
/// use ctrlab::{MassSpring, Cart, design::lqi};
/// use ctrlab::nalgebra::{SMatrix, matrix, vector};
///
/// let plant = MassSpring::nominal().state_space(Cart::Two)?;
/// let q = SMatrix::<f64, 5, 5>::from_diagonal(&vector![0.0, 0.0, 1e6, 0.0, 1e8]);
/// let sol = lqi(&plant, &q, &matrix![1.0])?;
/// // The integrator's gain has the sign that pushes x2 up to r: K_z < 0.
/// assert!(sol.gain[4] < 0.0);
/// assert!(sol.poles.iter().all(|p| p.re < 0.0) && sol.residual < 1e-9);
///
/// // Sized at run time: the same gain.
/// let dynamic = ctrlab::DynStateSpace::from(&plant);
/// let qd = ctrlab::nalgebra::DMatrix::from_column_slice(5, 5, q.as_slice());
/// assert_eq!(lqi(&dynamic, &qd, &ctrlab::nalgebra::dmatrix![1.0])?.gain.as_slice(), sol.gain.as_slice());
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub fn lqi<S, Q>(sys: &S, q: &Q, r: &S::InputWeight) -> Result<S::Lqi, Error>
where
    S: IntegralAction<Q, Domain = Continuous>,
{
    sys.integral_regulator(Token(()), q, r)
}

/// Discrete-time linear-quadratic-integral design (MATLAB's `lqi` on a
/// discrete model): the [`dlqr`] gain of the plant augmented with the
/// forward-Euler integrators `z[k+1] = z[k] + T (r[k] − y[k])`
/// ([`augment_integral`]), minimising `Σ ([x; z]ᵀ Q [x; z] + uᵀ R u)`.
/// Either model size, as [`lqi`].
///
/// # Errors
///
/// As [`lqi`], with [`dlqr`]'s.
///
/// # Examples
///
/// ```
/// use ctrlab::{MassSpring, Cart, Discretization, design::dlqi};
/// use ctrlab::nalgebra::{SMatrix, matrix, vector};
///
/// let plant = MassSpring::nominal().state_space(Cart::Two)?.discretize(0.002, Discretization::Zoh)?;
/// let q = SMatrix::<f64, 5, 5>::from_diagonal(&vector![0.0, 0.0, 1e6, 0.0, 1e8]);
/// let sol = dlqi(&plant, &q, &matrix![1.0])?;
/// assert!(sol.poles.iter().all(|z| z.norm() < 1.0));
/// let dynamic = ctrlab::DynStateSpace::from(&plant);
/// let qd = ctrlab::nalgebra::DMatrix::from_column_slice(5, 5, q.as_slice());
/// assert_eq!(dlqi(&dynamic, &qd, &ctrlab::nalgebra::dmatrix![1.0])?.gain.as_slice(), sol.gain.as_slice());
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub fn dlqi<S, Q>(sys: &S, q: &Q, r: &S::InputWeight) -> Result<S::Lqi, Error>
where
    S: IntegralAction<Q, Domain = Discrete>,
{
    sys.integral_regulator(Token(()), q, r)
}

/// What an integral controller does when the drive applies less than it
/// asked for (saturation; also the drive's quantisation), reported to it
/// by [`Controller::applied`].
///
/// # Examples
///
/// ```
/// use ctrlab::design::AntiWindup;
/// let aw = AntiWindup::BackCalculation { tracking: 0.02, deadband: 0.012 };
/// assert_ne!(aw, AntiWindup::None);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum AntiWindup {
    /// None: the integrators integrate the error whatever the drive does
    /// (they wind up under saturation). For comparison.
    None,
    /// Back-calculation: after each sample the integrators are pulled
    /// towards the values that would have asked for the applied input,
    /// `z ← z + (T / T_t) K_z⁺ e`, with `K_z⁺` the pseudo-inverse of the
    /// integrators' gain and `e` the excess `u_asked − u_applied` beyond
    /// `±deadband` on each input; so `−K_z z` moves by `T / T_t` of the
    /// excess each period.
    ///
    /// The dead band keeps the drive's rounding from being taken for
    /// saturation: set it to at least half the drive's quantisation step
    /// (the lab's drive: 24 mV steps, so 0.012 V or more). Without it the
    /// back-calculation holds the asked input within a step of the applied
    /// one, the integrators stall, and a count or so of error remains.
    BackCalculation {
        /// The tracking time constant `T_t`, s (finite, at least the
        /// sampling period `T`; `T_t = T` removes the whole excess at once).
        tracking: f64,
        /// Mismatch per input that is ignored, input unit (finite, ≥ 0).
        deadband: f64,
    },
}

/// The integrators and the law `u = −K_x x − K_z z` shared by
/// [`IntegralFeedback`] and the observer-based controller.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct IntegralLaw<const N: usize, const M: usize, const I: usize> {
    kx: SMatrix<f64, M, N>,
    kz: SMatrix<f64, M, I>,
    /// `(T / T_t) K_z⁺`, zero without anti-windup.
    back: SMatrix<f64, I, M>,
    /// Mismatch per input that the back-calculation ignores.
    deadband: f64,
    /// `T D_i`: the integrated outputs' feedthrough of the applied input.
    feedthrough: SMatrix<f64, I, M>,
    period: f64,
    z: SVector<f64, I>,
    asked: SVector<f64, M>,
}

impl<const N: usize, const M: usize, const I: usize> IntegralLaw<N, M, I> {
    /// From the augmented gain `[K_x K_z]` (`NA = N + I`), the integrated
    /// outputs' feedthrough `D_i` and the period.
    pub(crate) fn new<const NA: usize>(
        gain: &SMatrix<f64, M, NA>,
        d: &SMatrix<f64, I, M>,
        period: f64,
        anti_windup: AntiWindup,
    ) -> Result<Self, Error> {
        const { assert!(NA == N + I, "the gain has NA = N + I columns") };
        check_finite("K", gain)?;
        let kx = gain.fixed_view::<M, N>(0, 0).into_owned();
        let kz = gain.fixed_view::<M, I>(0, N).into_owned();
        let (back, deadband) = match anti_windup {
            AntiWindup::None => (SMatrix::zeros(), 0.0),
            AntiWindup::BackCalculation { tracking, deadband } => {
                if !(deadband.is_finite() && deadband >= 0.0) {
                    return Err(Error::InvalidParameter {
                        name: "deadband",
                        value: deadband,
                        reason: "the anti-windup dead band must be finite and >= 0",
                    });
                }
                if !(tracking.is_finite() && tracking >= period * (1.0 - 1e-12)) {
                    return Err(Error::InvalidParameter {
                        name: "tracking",
                        value: tracking,
                        reason: "the tracking time constant must be finite and at least the \
                                 sampling period, s",
                    });
                }
                let pinv = DMatrix::from_fn(M, I, |i, j| kz[(i, j)])
                    .pseudo_inverse(f64::EPSILON * kz.amax() * (M.max(I) as f64))
                    .map_err(|_| Error::NoConvergence {
                        operation: "pseudo-inverse of the integral gain",
                        iterations: 0,
                    })?;
                let back = SMatrix::<f64, I, M>::from_fn(|i, j| pinv[(i, j)] * period / tracking);
                let back = finite(
                    back,
                    "anti-windup back-calculation (T / T_t) K_z⁺ (the integral gain K_z is \
                     too small to invert)",
                )?;
                (back, deadband)
            }
        };
        Ok(Self {
            kx,
            kz,
            back,
            deadband,
            feedthrough: finite(
                d * period,
                "integral action: T D (the integrated outputs' feedthrough D, times the period)",
            )?,
            period,
            z: SVector::zeros(),
            asked: SVector::zeros(),
        })
    }

    /// `u = −K_x x − K_z z`, then `z += T (r − y_i)` (`y_i` without its
    /// feedthrough, which [`applied`](Self::applied) adds).
    #[inline]
    pub(crate) fn update(
        &mut self,
        x: &SVector<f64, N>,
        integrated: &SVector<f64, I>,
        r: &SVector<f64, I>,
    ) -> SVector<f64, M> {
        self.update_feedback(&(self.kx * x), integrated, r)
    }

    /// [`update`](Self::update) given the state feedback `K_x x` already
    /// formed (the compensator folds its observer into it).
    #[inline]
    pub(crate) fn update_feedback(
        &mut self,
        kx_x: &SVector<f64, M>,
        integrated: &SVector<f64, I>,
        r: &SVector<f64, I>,
    ) -> SVector<f64, M> {
        let u = -kx_x - self.kz * self.z;
        self.z += (r - integrated) * self.period;
        self.asked = u;
        u
    }

    #[inline]
    pub(crate) fn applied(&mut self, u: &SVector<f64, M>) {
        self.z -= self.feedthrough * u;
        let band = self.deadband;
        let excess = (self.asked - u).map(|e| e - e.clamp(-band, band));
        self.z += self.back * excess;
    }

    pub(crate) fn reset(&mut self) {
        self.z = SVector::zeros();
        self.asked = SVector::zeros();
    }

    pub(crate) fn kx(&self) -> &SMatrix<f64, M, N> {
        &self.kx
    }

    pub(crate) fn integrators(&self) -> &SVector<f64, I> {
        &self.z
    }

    pub(crate) fn period(&self) -> f64 {
        self.period
    }
}

/// Discrete state feedback with integral action on measured outputs, the
/// controller an [`lqi`] or [`dlqi`] design runs as:
///
/// ```text
/// u[k]   = −K_x y[k] − K_z z[k]
/// z[k+1] = z[k] + T (r[k] − C_i y[k] − D_i u[k])    (+ anti-windup)
/// ```
///
/// As a [`Controller`] its measurements are the full state (`P = N`), its
/// references the `I` integrated outputs' setpoints, and `C_i`, `D_i`, `T`
/// are the outputs and period of the discrete model it was built from. The
/// integrators see the input actually applied ([`Controller::applied`]),
/// and [`AntiWindup`] says what they do when it falls short. `update` and
/// `applied` are a few small matrix products: no allocation.
///
/// # Examples
///
/// ```
/// use ctrlab::{Controller, MassSpring, Cart, Discretization};
/// use ctrlab::design::{AntiWindup, IntegralFeedback, dlqi};
/// use ctrlab::nalgebra::{SMatrix, matrix, vector};
///
/// let plant = MassSpring::nominal().state_space(Cart::Two)?.discretize(0.002, Discretization::Zoh)?;
/// let q = SMatrix::<f64, 5, 5>::from_diagonal(&vector![0.0, 0.0, 1e6, 0.0, 1e8]);
/// let sol = dlqi(&plant, &q, &matrix![1.0])?;
/// let mut c = IntegralFeedback::new(&plant, &sol.gain, AntiWindup::BackCalculation { tracking: 0.01, deadband: 0.0 })?;
///
/// // Run the loop on the model: x2 settles exactly at the setpoint.
/// let mut x = vector![0.0, 0.0, 0.0, 0.0];
/// for _ in 0..2000 {
///     let u = c.update(&x, &vector![0.030]);
///     c.applied(&u);
///     x = plant.advance(&x, &u);
/// }
/// assert!((x[2] - 0.030).abs() < 1e-9);
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IntegralFeedback<const N: usize, const M: usize, const I: usize> {
    law: IntegralLaw<N, M, I>,
    ci: SMatrix<f64, I, N>,
}

impl<const N: usize, const M: usize, const I: usize> IntegralFeedback<N, M, I> {
    /// The controller for the augmented gain `gain = [K_x K_z]` (from
    /// [`lqi`] on the continuous model or [`dlqi`] on this one), with the
    /// integrated outputs `C_i`, `D_i` and the period `T` of `plant`, the
    /// discrete model it runs at.
    ///
    /// # Errors
    ///
    /// [`Error::NonFinite`] naming `"K"` for a non-finite gain;
    /// [`Error::InvalidParameter`] named `"tracking"` for a back-calculation
    /// time constant that is not finite or shorter than the period,
    /// `"deadband"` for a negative or non-finite dead band;
    /// [`Error::Overflow`] if `T D_i` overflows, or the back-calculation
    /// gain `(T / T_t) K_z⁺` does (an integral gain too small to invert).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{Controller, StateSpace, design::{AntiWindup, IntegralFeedback}};
    /// use ctrlab::nalgebra::{matrix, vector};
    ///
    /// let plant = StateSpace::discrete(matrix![0.5], matrix![1.0], matrix![1.0], matrix![0.0], 0.1)?;
    /// let mut c = IntegralFeedback::new(&plant, &matrix![0.2, -3.0], AntiWindup::None)?;
    /// assert_eq!(c.period(), Some(0.1));
    /// // u = −0.2 y − (−3) z with z = 0 at first; then z = 0.1 (1 − 0.5).
    /// assert_eq!(c.update(&vector![0.5], &vector![1.0]), vector![-0.1]);
    /// assert!((c.integrators()[0] - 0.05).abs() < 1e-15);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn new<const NA: usize>(
        plant: &StateSpace<N, M, I, Discrete>,
        gain: &SMatrix<f64, M, NA>,
        anti_windup: AntiWindup,
    ) -> Result<Self, Error> {
        Ok(Self {
            law: IntegralLaw::new(gain, plant.d(), plant.dt(), anti_windup)?,
            ci: *plant.c(),
        })
    }

    /// The integrators' state `z` (integrated error, output unit · s).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{StateSpace, design::{AntiWindup, IntegralFeedback}};
    /// use ctrlab::nalgebra::matrix;
    /// let plant = StateSpace::discrete(matrix![0.5], matrix![1.0], matrix![1.0], matrix![0.0], 0.1)?;
    /// let c = IntegralFeedback::new(&plant, &matrix![0.2, -3.0], AntiWindup::None)?;
    /// assert_eq!(c.integrators()[0], 0.0);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn integrators(&self) -> &SVector<f64, I> {
        self.law.integrators()
    }
}

impl<const N: usize, const M: usize, const I: usize> Controller<N, I, M>
    for IntegralFeedback<N, M, I>
{
    #[inline]
    fn update(&mut self, y: &SVector<f64, N>, r: &SVector<f64, I>) -> SVector<f64, M> {
        self.law.update(y, &(self.ci * y), r)
    }

    #[inline]
    fn applied(&mut self, u: &SVector<f64, M>) {
        self.law.applied(u);
    }

    fn reset(&mut self) {
        self.law.reset();
    }

    fn period(&self) -> Option<f64> {
        Some(self.law.period())
    }
}
