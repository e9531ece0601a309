//! Properties of a linear model: poles, stability, DC gain, damping, and
//! controllability / observability with a numerical rank test.
//!
//! Everything here is a method on [`StateSpace`] except [`rank`]. These are
//! design-time computations, not inner loops: eigenvalues and singular values
//! go through a heap `DMatrix` (nalgebra's Schur and SVD), which keeps the
//! signatures free of typenum bounds.
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

mod dynamic;

use nalgebra::{Complex, DMatrix, SMatrix};

use crate::error::Error;
use crate::kernels::linalg::{Lu, boundary_tolerance_dyn};
use crate::kernels::reduce::pow2_floor;
use crate::model::{Domain, StateSpace, period_of};

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
/// use nalgebra::matrix;
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
/// use nalgebra::dmatrix;
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
    let values = eigenvalues_dyn(&DMatrix::from_column_slice(N, N, a.as_slice()))?;
    let mut out = [Complex::new(0.0, 0.0); N];
    out.copy_from_slice(&values);
    Ok(out)
}

/// Eigenvalues of a square run-time-sized matrix, sorted as [`eigenvalues`]
/// sorts them. The one implementation behind every model's `poles()`.
pub(crate) fn eigenvalues_dyn(a: &DMatrix<f64>) -> Result<Vec<Complex<f64>>, Error> {
    let n = a.nrows();
    debug_assert_eq!(n, a.ncols());
    if n == 0 {
        return Ok(Vec::new());
    }
    let iterations = ITERATIONS_PER_DIM * n;
    // faer's multishift QR (exceptional shifts, aggressive early deflation)
    // first: it converges where nalgebra's Francis iteration stalls (a
    // repeated, non-defective eigenvalue; CAREX 6's 30 states) and is the
    // faster at large n. nalgebra's Schur is the fallback.
    let view = faer::MatRef::from_column_major_slice(a.as_slice(), n, n);
    let mut out: Vec<Complex<f64>> = match view.eigenvalues() {
        Ok(values) => values.iter().map(|e| Complex::new(e.re, e.im)).collect(),
        Err(_) => a
            .clone()
            .try_schur(f64::EPSILON, iterations)
            .ok_or(Error::NoConvergence {
                operation: "Schur decomposition (eigenvalues)",
                iterations,
            })?
            .complex_eigenvalues()
            .iter()
            .copied()
            .collect(),
    };
    if out.iter().any(|p| !(p.re.is_finite() && p.im.is_finite())) {
        return Err(Error::Overflow {
            operation: "eigenvalues",
        });
    }
    out.sort_by(|x, y| x.re.total_cmp(&y.re).then(x.im.total_cmp(&y.im)));
    Ok(out)
}

/// The block `[M, A M, A² M, …]` of `powers` terms (controllability when
/// `M = B`), as a heap matrix N × (powers·K).
fn krylov<const N: usize, const K: usize>(
    a: &SMatrix<f64, N, N>,
    m: &SMatrix<f64, N, K>,
    name: &'static str,
) -> Result<DMatrix<f64>, Error> {
    let mut out = DMatrix::zeros(N, N * K);
    let mut block = *m;
    for p in 0..N {
        for c in 0..K {
            for r in 0..N {
                let v = block[(r, c)];
                if !v.is_finite() {
                    return Err(Error::Overflow { operation: name });
                }
                out[(r, p * K + c)] = v;
            }
        }
        block = a * block;
    }
    Ok(out)
}

/// The numerical rank of the Krylov matrix `[M, A M, …, A^(N−1) M]`,
/// independent of the units of the states, inputs and time: the rank of
/// `R C S` with `C` the Krylov matrix and `R`, `S` diagonal (powers of two),
/// which does not change the exact rank. Each column `A^k m` is scaled by
/// the size of the terms it sums, the matching column of
/// `[|M|, |A| |M|, …]` (so rounding noise in a column that cancels to
/// nearly zero stays noise, while a column that is small because of the
/// units is brought to size), and each row by that magnitude's largest
/// entry in it (a state in µm next to one in km). Powers are scaled as they
/// are formed, so nothing overflows.
pub(crate) fn scaled_krylov_rank<const N: usize, const K: usize>(
    a: &SMatrix<f64, N, N>,
    m: &SMatrix<f64, N, K>,
) -> Result<usize, Error> {
    let abs_a = a.abs();
    let mut out = DMatrix::zeros(N, N * K);
    let mut size = DMatrix::zeros(N, N * K);
    for c in 0..K {
        let (mut v, mut w) = (m.column(c).into_owned(), m.column(c).abs());
        for p in 0..N {
            let f = 1.0 / pow2_floor(w.amax());
            v *= f;
            w *= f;
            if v.iter().chain(w.iter()).any(|x| !x.is_finite()) {
                return Err(Error::Overflow {
                    operation: "Krylov matrix (rank test)",
                });
            }
            out.column_mut(p * K + c).copy_from(&v);
            size.column_mut(p * K + c).copy_from(&w);
            v = a * v;
            w = abs_a * w;
        }
    }
    for i in 0..N {
        let f = 1.0 / pow2_floor(size.row(i).amax());
        out.row_mut(i).scale_mut(f);
    }
    rank(&out, None)
}

impl<const N: usize, const M: usize, const P: usize, D: Domain> StateSpace<N, M, P, D> {
    /// The poles (eigenvalues of `A`), sorted by real part and then by
    /// imaginary part, ascending; for a continuous model the most damped come
    /// first. Units: rad/s for continuous models, dimensionless `z` for
    /// discrete ones.
    ///
    /// # Errors
    ///
    /// [`Error::NoConvergence`] if the Schur iteration fails (not seen on
    /// finite matrices in practice).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{MassSpring, Cart};
    ///
    /// let p = MassSpring::nominal().state_space(Cart::Two)?.poles()?;
    /// // Two lightly damped pairs, about 20 rad/s and 50 rad/s.
    /// assert!(p.iter().all(|p| p.re < 0.0 && p.im.abs() > 20.0));
    /// assert_eq!(p[0].conj(), p[1]);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn poles(&self) -> Result<[Complex<f64>; N], Error> {
        eigenvalues(self.a())
    }

    /// The controllability matrix `[B, A B, …, A^(N−1) B]`, N × (N·M).
    ///
    /// # Errors
    ///
    /// [`Error::Overflow`] if a power of `A` overflows.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::StateSpace;
    /// use nalgebra::{dmatrix, matrix};
    ///
    /// let sys = StateSpace::continuous(matrix![0.0, 1.0; 0.0, 0.0], matrix![0.0; 1.0],
    ///                                  matrix![1.0, 0.0], matrix![0.0])?;
    /// assert_eq!(sys.controllability()?, dmatrix![0.0, 1.0; 1.0, 0.0]);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[doc(alias = "ctrb")]
    pub fn controllability(&self) -> Result<DMatrix<f64>, Error> {
        krylov(self.a(), self.b(), "controllability matrix")
    }

    /// The observability matrix `[C; C A; …; C A^(N−1)]`, (N·P) × N.
    ///
    /// # Errors
    ///
    /// [`Error::Overflow`] if a power of `A` overflows.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::StateSpace;
    /// use nalgebra::{dmatrix, matrix};
    ///
    /// let sys = StateSpace::continuous(matrix![0.0, 1.0; 0.0, 0.0], matrix![0.0; 1.0],
    ///                                  matrix![1.0, 0.0], matrix![0.0])?;
    /// assert_eq!(sys.observability()?, dmatrix![1.0, 0.0; 0.0, 1.0]);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[doc(alias = "obsv")]
    pub fn observability(&self) -> Result<DMatrix<f64>, Error> {
        // Observability of (A, C) is controllability of (Aᵀ, Cᵀ), transposed.
        Ok(krylov(
            &self.a().transpose(),
            &self.c().transpose(),
            "observability matrix",
        )?
        .transpose())
    }

    /// True when the controllability matrix has full rank `N` by
    /// [`rank`] with the default relative tolerance, after scaling its rows
    /// and columns so that the answer does not depend on the units of the
    /// states, input or time (a chain of integrators coupled by 10⁶ is
    /// controllable; its raw controllability matrix has singular values
    /// from 1 to 10¹⁸).
    ///
    /// # Errors
    ///
    /// [`Error::Overflow`] if scaled powers of `A` overflow (not seen for
    /// finite `A`); [`Error::NoConvergence`] if the SVD fails.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::StateSpace;
    /// use nalgebra::matrix;
    ///
    /// // The input drives only the first of two decoupled states.
    /// let sys = StateSpace::continuous(matrix![-1.0, 0.0; 0.0, -2.0], matrix![1.0; 0.0],
    ///                                  matrix![1.0, 1.0], matrix![0.0])?;
    /// assert!(!sys.is_controllable()?);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn is_controllable(&self) -> Result<bool, Error> {
        Ok(scaled_krylov_rank(self.a(), self.b())? == N)
    }

    /// True when the observability matrix has full rank `N` by [`rank`] with
    /// the default relative tolerance, scaled as in
    /// [`is_controllable`](Self::is_controllable).
    ///
    /// # Errors
    ///
    /// As [`is_controllable`](Self::is_controllable).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{MassSpring, Cart};
    ///
    /// // Either cart's position alone reveals the whole state.
    /// assert!(MassSpring::nominal().state_space(Cart::One)?.is_observable()?);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn is_observable(&self) -> Result<bool, Error> {
        Ok(scaled_krylov_rank(&self.a().transpose(), &self.c().transpose())? == N)
    }
}

impl<const N: usize, const M: usize, const P: usize, D: Domain> StateSpace<N, M, P, D> {
    /// True when every pole is strictly inside the stability region by more
    /// than its rounding error: `Re s < −tol` in continuous time,
    /// `|z| < 1 − tol` in discrete time, with `tol` the pole's own error
    /// bound (see [`unstable_pole`](Self::unstable_pole)), so that the
    /// answer does not depend on the units of the states:
    /// `diag(−1e−3, −1e12)` is stable.
    ///
    /// A pole on the boundary (an integrator, an undamped oscillator, a
    /// rigid-body mode computed from physical parameters) is not stable.
    ///
    /// # Errors
    ///
    /// As [`poles`](Self::poles).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::StateSpace;
    /// use nalgebra::matrix;
    ///
    /// let lag = StateSpace::continuous(matrix![-1.0], matrix![1.0], matrix![1.0], matrix![0.0])?;
    /// let integrator = StateSpace::continuous(matrix![0.0], matrix![1.0], matrix![1.0], matrix![0.0])?;
    /// assert!(lag.is_stable()? && !integrator.is_stable()?);
    ///
    /// let sys = StateSpace::discrete(matrix![0.5], matrix![1.0], matrix![1.0], matrix![0.0], 0.1)?;
    /// let acc = StateSpace::discrete(matrix![1.0], matrix![1.0], matrix![1.0], matrix![0.0], 0.1)?;
    /// assert!(sys.is_stable()? && !acc.is_stable()?);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn is_stable(&self) -> Result<bool, Error> {
        Ok(self.unstable_pole()?.is_none())
    }

    /// The first pole, in the order of [`poles`](Self::poles), on or outside
    /// the stability boundary, or `None` for a stable model. This is the
    /// crate's one stability test: [`is_stable`](Self::is_stable), step
    /// metrics and the LQR checks all use it.
    ///
    /// "On" the boundary means within the pole's rounding error `tol` of
    /// it: `Re s ≥ −tol` in continuous time, `|z| ≥ 1 − tol` in discrete
    /// time. `tol` is the smaller of the normwise bound
    /// `100 N ε max(1, ‖A‖₁)` (eigenvalues are computed to about `ε ‖A‖`)
    /// and the componentwise bound `100 N ε |y|ᵀ|A||x| / |yᴴx|` (`x`, `y`
    /// the pole's right and left eigenvectors), the error of a pole of a
    /// matrix whose entries are each known to a relative ε. The second does
    /// not change with the units of the states (it is the bound of the
    /// balanced matrix), so a slow pole next to a fast one stays stable,
    /// while a rigid-body mode computed from physical parameters stays on
    /// the boundary.
    ///
    /// # Errors
    ///
    /// As [`poles`](Self::poles).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::StateSpace;
    /// use nalgebra::matrix;
    ///
    /// let sys = StateSpace::continuous(matrix![-1.0, 0.0; 0.0, 2.0], matrix![1.0; 1.0], matrix![1.0, 1.0], matrix![0.0])?;
    /// assert_eq!(sys.unstable_pole()?.map(|p| p.re), Some(2.0));
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn unstable_pole(&self) -> Result<Option<Complex<f64>>, Error> {
        let poles = self.poles()?;
        Ok(first_unstable(&poles, self.a(), period_of(&self.domain())))
    }

    /// The steady-state gain (output units per input unit; m/N for the lab
    /// plant): `−C A⁻¹ B + D` in continuous time, `C (I − A)⁻¹ B + D` in
    /// discrete time. MATLAB's and python-control's `dcgain`.
    ///
    /// # Errors
    ///
    /// [`Error::Singular`] for a pole at `s = 0` / `z = 1` to working
    /// precision (the gain is infinite or undefined, and is reported instead
    /// of returned as inf/NaN): refused when the Skeel condition number
    /// `‖ |A⁻¹| |A| ‖∞` of `A` (or `I − A`) exceeds `1 / (10⁴ ε)`, i.e. fewer
    /// than about four digits of the gain would be right (a measure that
    /// does not depend on the units of the states: `diag(−1, −1e12)` is
    /// fine); [`Error::Overflow`] for a gain that overflows.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{Cart, Error, MassSpring, Method, StateSpace};
    /// use nalgebra::matrix;
    ///
    /// let lag = StateSpace::continuous(matrix![-2.0], matrix![4.0], matrix![1.0], matrix![0.0])?;
    /// assert_eq!(lag.dc_gain()?, matrix![2.0]);
    /// let integrator = StateSpace::continuous(matrix![0.0], matrix![1.0], matrix![1.0], matrix![0.0])?;
    /// assert!(matches!(integrator.dc_gain(), Err(Error::Singular { .. })));
    ///
    /// // ZOH keeps the DC gain: 2 mm per newton on cart 2.
    /// let d = MassSpring::nominal().state_space(Cart::Two)?.discretize(0.002, Method::Zoh)?;
    /// assert!((d.dc_gain()?[(0, 0)] - 0.002).abs() < 1e-12);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[doc(alias = "dcgain")]
    pub fn dc_gain(&self) -> Result<SMatrix<f64, P, M>, Error> {
        match period_of(&self.domain()) {
            None => {
                let x = gain_solve(self.a(), self.b(), "DC gain (pole at s = 0)")?;
                finite_gain(self.d() - self.c() * x)
            }
            Some(_) => {
                let i_minus_a = SMatrix::<f64, N, N>::identity() - self.a();
                let x = gain_solve(&i_minus_a, self.b(), "DC gain (pole at z = 1)")?;
                finite_gain(self.c() * x + self.d())
            }
        }
    }

    /// [`Damping`] (natural frequency, damping ratio, time constant) of each
    /// pole, in the order of [`poles`](Self::poles). A discrete pole `z` is
    /// first mapped to `s = ln(z) / dt`, as MATLAB's `damp` does.
    ///
    /// # Errors
    ///
    /// As [`poles`](Self::poles).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{Cart, MassSpring, StateSpace};
    /// use nalgebra::matrix;
    ///
    /// let d = MassSpring::nominal().state_space(Cart::Two)?.damping()?;
    /// // Both modes of the rig are lightly damped.
    /// assert!(d.iter().all(|d| d.damping_ratio > 0.0 && d.damping_ratio < 0.2));
    ///
    /// // z = e^(−2 · 0.1): the discrete image of s = −2.
    /// let sys = StateSpace::discrete(matrix![(-0.2f64).exp()], matrix![1.0], matrix![1.0], matrix![0.0], 0.1)?;
    /// let d = sys.damping()?[0];
    /// assert!((d.natural_frequency - 2.0).abs() < 1e-12 && (d.time_constant - 0.5).abs() < 1e-12);
    /// assert!((d.damping_ratio - 1.0).abs() < 1e-12);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[doc(alias = "damp")]
    pub fn damping(&self) -> Result<[Damping; N], Error> {
        let poles = self.poles()?;
        Ok(match period_of(&self.domain()) {
            None => poles.map(|p| Damping::of_s(p, p)),
            Some(dt) => poles.map(|z| {
                if z.norm() == 0.0 {
                    Damping {
                        pole: z,
                        natural_frequency: f64::INFINITY,
                        damping_ratio: 1.0,
                        time_constant: 0.0,
                    }
                } else {
                    Damping::of_s(z, z.ln() / dt)
                }
            }),
        })
    }
}

/// The crate's one stability test: the first of `poles` (eigenvalues of `a`)
/// on or outside the stability boundary of the domain with sampling period
/// `period` (`None`: continuous), within rounding of `a`.
///
/// A pole is on the boundary when it is within its own rounding error of
/// it: the smaller of the normwise bound `100 N ε max(1, ‖A‖₁)` and the
/// componentwise one `100 N ε |y|ᵀ|A||x| / |yᴴx|` (`x`, `y` its right and
/// left eigenvectors), which is what the pole's error is when `A`'s entries
/// are known to a relative ε. The componentwise bound does not change under
/// a diagonal change of state units (it is the bound of the balanced
/// matrix), so `diag(−1e−3, −1e12)` is stable, while a rigid-body mode
/// computed from physical parameters stays on the boundary. It is computed
/// only for poles the normwise bound leaves in doubt.
pub(crate) fn first_unstable<const N: usize>(
    poles: &[Complex<f64>; N],
    a: &SMatrix<f64, N, N>,
    period: Option<f64>,
) -> Option<Complex<f64>> {
    first_unstable_dyn(
        poles,
        &DMatrix::from_column_slice(N, N, a.as_slice()),
        period,
    )
}

/// [`first_unstable`] for a run-time-sized `a` (`poles` its eigenvalues).
pub(crate) fn first_unstable_dyn(
    poles: &[Complex<f64>],
    a: &DMatrix<f64>,
    period: Option<f64>,
) -> Option<Complex<f64>> {
    let normwise = boundary_tolerance_dyn(a);
    let outside = |p: &Complex<f64>, tol: f64| match period {
        None => p.re >= -tol,
        Some(_) => p.norm() >= 1.0 - tol,
    };
    let strictly_inside = |p: &Complex<f64>| match period {
        None => p.re < 0.0,
        Some(_) => p.norm() < 1.0,
    };
    poles.iter().copied().find(|p| {
        outside(p, normwise)
            && !(strictly_inside(p)
                && componentwise_tolerance(a, *p).is_some_and(|tol| !outside(p, tol)))
    })
}

/// `100 N ε |y|ᵀ|A||x| / |yᴴx|`, the rounding error of the eigenvalue `p`
/// of `a` under relative perturbations of its entries, with `x`, `y` the
/// right and left singular vectors of `A − p I` for its smallest singular
/// value (its eigenvectors). `None` when the SVD fails.
fn componentwise_tolerance(a: &DMatrix<f64>, p: Complex<f64>) -> Option<f64> {
    let n = a.nrows();
    let shifted = DMatrix::from_fn(n, n, |i, j| {
        Complex::new(a[(i, j)], 0.0) - if i == j { p } else { Complex::new(0.0, 0.0) }
    });
    let iterations = ITERATIONS_PER_DIM * n;
    let svd = shifted.try_svd_unordered(true, true, f64::EPSILON, iterations)?;
    if svd.singular_values.iter().any(|s| !s.is_finite()) {
        return None;
    }
    let (u, v_t) = (svd.u?, svd.v_t?);
    let k = svd.singular_values.imin();
    let x = v_t.row(k).adjoint();
    let y = u.column(k);
    let mut weighted = 0.0;
    for i in 0..n {
        for j in 0..n {
            weighted += y[i].norm() * a[(i, j)].abs() * x[j].norm();
        }
    }
    let overlap = y.dotc(&x).norm();
    let tol = 100.0 * n as f64 * f64::EPSILON * weighted / overlap;
    tol.is_finite().then_some(tol)
}

/// Solves `m x = b` for a DC gain, refusing an `m` so ill-conditioned that
/// the gain would have fewer than about four correct digits: a pole at
/// s = 0 / z = 1 that rounding moved slightly off it must be reported, not
/// turned into a huge, meaningless number. The equations are first scaled
/// by powers of two (each row's largest entry in [1, 2)), and the test is
/// the Skeel condition number `‖ |m⁻¹| |m| ‖∞`, which no such scaling
/// changes: `diag(−1, −1e12)` is perfectly conditioned.
fn gain_solve<const N: usize, const M: usize>(
    m: &SMatrix<f64, N, N>,
    b: &SMatrix<f64, N, M>,
    operation: &'static str,
) -> Result<SMatrix<f64, N, M>, Error> {
    let (mut m, mut b) = (*m, *b);
    for i in 0..N {
        let f = 1.0 / pow2_floor(m.row(i).amax());
        m.row_mut(i).scale_mut(f);
        b.row_mut(i).scale_mut(f);
    }
    let lu = Lu::new(&m, operation)?;
    let skeel = (lu.solve(&SMatrix::<f64, N, N>::identity()).abs() * m.abs())
        .row_iter()
        .map(|r| r.sum())
        .fold(0.0, f64::max);
    if !skeel.is_finite() || skeel * f64::EPSILON > 1e-4 {
        return Err(Error::Singular { operation });
    }
    Ok(lu.solve(&b))
}

fn finite_gain<const P: usize, const M: usize>(
    g: SMatrix<f64, P, M>,
) -> Result<SMatrix<f64, P, M>, Error> {
    if g.iter().all(|v| v.is_finite()) {
        Ok(g)
    } else {
        Err(Error::Overflow {
            operation: "DC gain",
        })
    }
}
