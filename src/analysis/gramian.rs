//! Gramians of stable models and their Hankel singular values (MATLAB's
//! `gram` and `hsvd`), on both model types: the run-time-sized
//! implementation here, which the fixed-size methods call.

use nalgebra::{DMatrix, SMatrix};

use super::lyapunov::{Lyapunov, LyapunovFactor, dlyap, dlyapchol, lyap, lyapchol};
use super::stability::stable_poles;
use crate::error::Error;
use crate::model::{Domain, DynStateSpace, StateSpace, period_of};

/// Which Gramian [`StateSpace::gram`] (and the other `gram` methods)
/// compute: MATLAB's `gram(sys, 'c')` and `gram(sys, 'o')`.
///
/// # Examples
///
/// ```
/// use ctrlab::StateSpace;
/// use ctrlab::analysis::GramianKind;
/// use ctrlab::nalgebra::matrix;
///
/// // ẋ = −2 x + 3 u, y = 5 x: Wc = 3² / 4, Wo = 5² / 4.
/// let sys = StateSpace::continuous(matrix![-2.0], matrix![3.0], matrix![5.0], matrix![0.0])?;
/// assert_eq!(sys.gram(GramianKind::Controllability)?.x[(0, 0)], 2.25);
/// assert_eq!(sys.gram(GramianKind::Observability)?.x[(0, 0)], 6.25);
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GramianKind {
    /// `Wc`: `A Wc + Wc Aᵀ + B Bᵀ = 0` (continuous),
    /// `A Wc Aᵀ − Wc + B Bᵀ = 0` (discrete); `∫₀^∞ e^{At} B Bᵀ e^{Aᵀt} dt`
    /// or `Σₖ Aᵏ B Bᵀ (Aᵀ)ᵏ`, in (state units per input unit)² (times
    /// seconds, continuous).
    Controllability,
    /// `Wo`: `Aᵀ Wo + Wo A + Cᵀ C = 0` (continuous),
    /// `Aᵀ Wo A − Wo + Cᵀ C = 0` (discrete): the energy of the free output
    /// from a unit initial state, in (output units per state unit)² (times
    /// seconds, continuous).
    Observability,
}

/// The model's matrices for `kind`: `(A, B)` or the dual `(Aᵀ, Cᵀ)`.
fn operands<D: Domain>(sys: &DynStateSpace<D>, kind: GramianKind) -> (DMatrix<f64>, DMatrix<f64>) {
    match kind {
        GramianKind::Controllability => (sys.a().clone(), sys.b().clone()),
        GramianKind::Observability => (sys.a().transpose(), sys.c().transpose()),
    }
}

/// The Gramian `kind` of a model checked stable.
fn gramian<D: Domain>(
    sys: &DynStateSpace<D>,
    kind: GramianKind,
) -> Result<Lyapunov<DMatrix<f64>>, Error> {
    stable_poles(sys, "gram")?;
    let (a, b) = operands(sys, kind);
    let q = &b * b.transpose();
    if !q.iter().all(|v| v.is_finite()) {
        return Err(Error::Overflow { operation: "gram" });
    }
    if period_of(&sys.domain()).is_some() {
        dlyap(&a, &q)
    } else {
        lyap(&a, &q)
    }
}

/// The Cholesky factor of the Gramian `kind`, checked stable, with the
/// name of the operation that needed stability.
pub(super) fn gramian_factor<D: Domain>(
    sys: &DynStateSpace<D>,
    kind: GramianKind,
    operation: &'static str,
) -> Result<LyapunovFactor<DMatrix<f64>>, Error> {
    stable_poles(sys, operation)?;
    let (a, b) = operands(sys, kind);
    if period_of(&sys.domain()).is_some() {
        dlyapchol(&a, &b)
    } else {
        lyapchol(&a, &b)
    }
}

/// The SVD `Ro Rcᵀ = U diag(σ) Vᵀ` (`Wc = Rcᵀ Rc`, `Wo = Roᵀ Ro`).
pub(super) struct HankelSvd {
    pub(super) u: DMatrix<f64>,
    /// The Hankel singular values, descending.
    pub(super) sigma: Vec<f64>,
    pub(super) v: DMatrix<f64>,
}

/// The SVD of `Ro Rcᵀ` by faer (as `minimal_realization` uses).
pub(super) fn hankel_svd(
    rc: &DMatrix<f64>,
    ro: &DMatrix<f64>,
    operation: &'static str,
) -> Result<HankelSvd, Error> {
    let n = rc.nrows();
    let m = ro * rc.transpose();
    if !m.iter().all(|v| v.is_finite()) {
        return Err(Error::Overflow { operation });
    }
    if n == 0 {
        return Ok(HankelSvd {
            u: m.clone(),
            sigma: Vec::new(),
            v: m,
        });
    }
    let fm = faer::MatRef::from_column_major_slice(m.as_slice(), n, n);
    let svd = fm.svd().map_err(|_| Error::NoConvergence {
        operation,
        iterations: 0,
    })?;
    let (u, s, v) = (svd.U(), svd.S().column_vector(), svd.V());
    let sigma: Vec<f64> = (0..n).map(|i| s[i]).collect();
    if !sigma.iter().all(|v| v.is_finite()) {
        return Err(Error::Overflow { operation });
    }
    Ok(HankelSvd {
        u: DMatrix::from_fn(n, n, |i, j| u[(i, j)]),
        sigma,
        v: DMatrix::from_fn(n, n, |i, j| v[(i, j)]),
    })
}

impl<D: Domain> DynStateSpace<D> {
    /// The controllability or observability Gramian ([`GramianKind`]) of
    /// a stable model, with the relative residual of its Lyapunov
    /// equation: MATLAB's `gram(sys, 'c')` / `gram(sys, 'o')`, SciPy's
    /// `solve_continuous_lyapunov(A, −B Bᵀ)` or
    /// `solve_discrete_lyapunov(A, B Bᵀ)` (and the duals with `Aᵀ`,
    /// `Cᵀ C`). [`lyap`] or [`dlyap`] by the model's time domain.
    ///
    /// # Errors
    ///
    /// [`Error::Unstable`] (operation `"gram"`) naming the first pole on
    /// or outside the stability boundary by
    /// [`unstable_pole`](Self::unstable_pole)'s test (the Gramian of an
    /// unstable model is infinite); [`Error::Overflow`] (operation
    /// `"gram"`) if `B Bᵀ` (`Cᵀ C`) or the Gramian is beyond `f64`;
    /// otherwise as [`lyap`]: in particular [`Error::SingularEquation`]
    /// for a stable but very stiff model, whose slowest pole is within
    /// `100 n ε` of the Schur form's norm (poles at 1e-3 and 1e12 rad/s;
    /// 1e-3 and 1e6 are solved), which the solvers' normwise test cannot
    /// tell from the imaginary axis.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::DynStateSpace;
    /// use ctrlab::analysis::GramianKind;
    /// use ctrlab::nalgebra::dmatrix;
    ///
    /// // x[k+1] = 0.5 x[k] + u[k]: Wc = 1 / (1 − 0.25).
    /// let sys = DynStateSpace::discrete(dmatrix![0.5], dmatrix![1.0], dmatrix![1.0],
    ///                                   dmatrix![0.0], 0.1)?;
    /// let wc = sys.gram(GramianKind::Controllability)?;
    /// assert!((wc.x[(0, 0)] - 4.0 / 3.0).abs() < 1e-15);
    ///
    /// // An integrator has no Gramian.
    /// let acc = DynStateSpace::discrete(dmatrix![1.0], dmatrix![1.0], dmatrix![1.0],
    ///                                   dmatrix![0.0], 0.1)?;
    /// assert!(matches!(acc.gram(GramianKind::Controllability),
    ///                  Err(ctrlab::Error::Unstable { operation: "gram", .. })));
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn gram(&self, kind: GramianKind) -> Result<Lyapunov<DMatrix<f64>>, Error> {
        gramian(self, kind)
    }

    /// The Cholesky factor `R` of a stable model's Gramian
    /// (`W = Rᵀ R`, `R` upper triangular with a non-negative diagonal),
    /// MATLAB's `gram(sys, 'cf')` / `gram(sys, 'of')` with
    /// [`lyapchol`]'s convention: [`lyapchol`] or [`dlyapchol`] on
    /// `(A, B)` or `(Aᵀ, Cᵀ)`, without forming the Gramian, so that a
    /// nearly singular one keeps its small directions.
    ///
    /// # Errors
    ///
    /// As [`gram`](Self::gram) (operation `"gram"`).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::DynStateSpace;
    /// use ctrlab::analysis::GramianKind;
    /// use ctrlab::nalgebra::dmatrix;
    ///
    /// let sys = DynStateSpace::continuous(dmatrix![0.0, 1.0; -4.0, -1.0], dmatrix![0.0; 1.0],
    ///                                     dmatrix![1.0, 0.0], dmatrix![0.0])?;
    /// let r = sys.gram_factor(GramianKind::Observability)?.factor;
    /// let wo = sys.gram(GramianKind::Observability)?.x;
    /// assert!((r.transpose() * &r - wo).amax() < 1e-14);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[doc(alias = "gram")]
    pub fn gram_factor(&self, kind: GramianKind) -> Result<LyapunovFactor<DMatrix<f64>>, Error> {
        gramian_factor(self, kind, "gram")
    }

    /// The Hankel singular values of a stable model, descending:
    /// `σᵢ = √λᵢ(Wc Wo)`, MATLAB's `hsvd(sys)`; dimensionless system gains
    /// (output units per input unit), `σ₁` the Hankel norm. Computed as
    /// the singular values of `Ro Rcᵀ` from the Gramians' Cholesky factors
    /// ([`gram_factor`](Self::gram_factor)), never from the product
    /// `Wc Wo`, whose eigenvalues lose the small `σ` (relative accuracy
    /// `ε σ₁ / σᵢ` at best there, against `ε σ₁` absolute here).
    ///
    /// A zero `σ` marks a state that is uncontrollable or unobservable.
    ///
    /// # Errors
    ///
    /// [`Error::Unstable`] (operation `"hsvd"`) as [`gram`](Self::gram);
    /// [`Error::Overflow`] if `Ro Rcᵀ` overflows; [`Error::NoConvergence`]
    /// if the SVD fails.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::DynStateSpace;
    /// use ctrlab::nalgebra::dmatrix;
    ///
    /// // Two decoupled channels: σ = |b c| / (2 a) each, 6/2 and 1/4.
    /// let sys = DynStateSpace::continuous(dmatrix![-1.0, 0.0; 0.0, -2.0],
    ///                                     dmatrix![2.0, 0.0; 0.0, 1.0],
    ///                                     dmatrix![3.0, 0.0; 0.0, 1.0], dmatrix![0.0, 0.0; 0.0, 0.0])?;
    /// let hsv = sys.hsvd()?;
    /// assert!((hsv[0] - 3.0).abs() < 1e-15 && (hsv[1] - 0.25).abs() < 1e-15);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn hsvd(&self) -> Result<Vec<f64>, Error> {
        const OPERATION: &str = "hsvd";
        let rc = gramian_factor(self, GramianKind::Controllability, OPERATION)?.factor;
        let ro = gramian_factor(self, GramianKind::Observability, OPERATION)?.factor;
        Ok(hankel_svd(&rc, &ro, OPERATION)?.sigma)
    }
}

impl<const N: usize, const M: usize, const P: usize, D: Domain> StateSpace<N, M, P, D> {
    /// The controllability or observability Gramian of a stable model
    /// (`N × N`), MATLAB's `gram(sys, 'c')` / `gram(sys, 'o')`: see
    /// [`DynStateSpace::gram`] for the definitions and the method.
    ///
    /// # Errors
    ///
    /// As [`DynStateSpace::gram`]: [`Error::Unstable`] for an unstable
    /// model.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{Cart, MassSpring};
    /// use ctrlab::analysis::GramianKind;
    ///
    /// let plant = MassSpring::nominal().state_space(Cart::Two)?;
    /// let wc = plant.gram(GramianKind::Controllability)?;
    /// assert!(wc.residual < 1e-13);
    /// // Positive definite: the rig is controllable.
    /// assert!(wc.x.symmetric_eigenvalues().min() > 0.0);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn gram(&self, kind: GramianKind) -> Result<Lyapunov<SMatrix<f64, N, N>>, Error> {
        let w = gramian(&DynStateSpace::from(self), kind)?;
        Ok(Lyapunov {
            x: SMatrix::from_column_slice(w.x.as_slice()),
            residual: w.residual,
        })
    }

    /// The Cholesky factor `R` (`W = Rᵀ R`) of a stable model's Gramian,
    /// MATLAB's `gram(sys, 'cf')` / `gram(sys, 'of')`: see
    /// [`DynStateSpace::gram_factor`].
    ///
    /// # Errors
    ///
    /// As [`gram`](Self::gram).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::StateSpace;
    /// use ctrlab::analysis::GramianKind;
    /// use ctrlab::nalgebra::matrix;
    ///
    /// let sys = StateSpace::continuous(matrix![-2.0], matrix![3.0], matrix![1.0], matrix![0.0])?;
    /// let r = sys.gram_factor(GramianKind::Controllability)?.factor;
    /// assert!((r[(0, 0)] - 1.5).abs() < 1e-15);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[doc(alias = "gram")]
    pub fn gram_factor(
        &self,
        kind: GramianKind,
    ) -> Result<LyapunovFactor<SMatrix<f64, N, N>>, Error> {
        let r = gramian_factor(&DynStateSpace::from(self), kind, "gram")?;
        Ok(LyapunovFactor {
            factor: SMatrix::from_column_slice(r.factor.as_slice()),
            residual: r.residual,
        })
    }

    /// The `N` Hankel singular values of a stable model, descending,
    /// MATLAB's `hsvd(sys)`: see [`DynStateSpace::hsvd`].
    ///
    /// # Errors
    ///
    /// As [`DynStateSpace::hsvd`].
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::StateSpace;
    /// use ctrlab::nalgebra::matrix;
    ///
    /// // x[k+1] = 0.5 x[k] + u[k], y = x[k]: σ = |b c| / (1 − a²).
    /// let sys = StateSpace::discrete(matrix![0.5], matrix![1.0], matrix![1.0], matrix![0.0], 0.01)?;
    /// assert!((sys.hsvd()?[0] - 4.0 / 3.0).abs() < 1e-15);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn hsvd(&self) -> Result<[f64; N], Error> {
        let all = DynStateSpace::from(self).hsvd()?;
        Ok(core::array::from_fn(|i| all[i]))
    }
}
