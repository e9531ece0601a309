//! Analysis of run-time-sized models ([`DynStateSpace`]): the same
//! algorithms as the fixed-size methods of [`StateSpace`], which hand their
//! matrices to these.

use nalgebra::{Complex, DMatrix};

use super::controllability::{krylov, scaled_krylov_rank};
use super::{Damping, damping_of, eigenvalues_dyn, first_unstable_dyn, gain};
use crate::error::Error;
#[cfg(doc)]
use crate::model::StateSpace;
use crate::model::{Domain, DynStateSpace, period_of};

impl<D: Domain> DynStateSpace<D> {
    /// The poles: eigenvalues of `A`, sorted by real part then imaginary part
    /// (ascending), as [`StateSpace::poles`] sorts them. `s`-plane (rad/s)
    /// for continuous models, `z`-plane (dimensionless) for discrete ones.
    ///
    /// # Errors
    ///
    /// [`Error::NoConvergence`] if the eigenvalue iteration fails;
    /// [`Error::Overflow`] if an eigenvalue is not finite.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::DynStateSpace;
    /// use ctrlab::nalgebra::dmatrix;
    ///
    /// // x'' + 2 x' + 5 x = u: poles −1 ± 2i.
    /// let sys = DynStateSpace::continuous(dmatrix![0.0, 1.0; -5.0, -2.0], dmatrix![0.0; 1.0],
    ///                                     dmatrix![1.0, 0.0], dmatrix![0.0])?;
    /// let p = sys.poles()?;
    /// assert!((p[0].re + 1.0).abs() < 1e-12 && (p[0].im + 2.0).abs() < 1e-12);
    /// assert!((p[1].re + 1.0).abs() < 1e-12 && (p[1].im - 2.0).abs() < 1e-12);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn poles(&self) -> Result<Vec<Complex<f64>>, Error> {
        eigenvalues_dyn(self.a())
    }

    /// True when every pole is strictly inside the stability region by more
    /// than its rounding error (`Re s < −tol`, `|z| < 1 − tol`): the test of
    /// [`StateSpace::is_stable`], whose documentation gives the tolerance.
    ///
    /// # Errors
    ///
    /// As [`poles`](Self::poles).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::DynStateSpace;
    /// use ctrlab::nalgebra::dmatrix;
    ///
    /// let lag = DynStateSpace::continuous(dmatrix![-1.0], dmatrix![1.0], dmatrix![1.0], dmatrix![0.0])?;
    /// let integrator = DynStateSpace::continuous(dmatrix![0.0], dmatrix![1.0], dmatrix![1.0], dmatrix![0.0])?;
    /// assert!(lag.is_stable()? && !integrator.is_stable()?);
    /// // Units do not matter: a slow and a very fast mode are both stable.
    /// let stiff = DynStateSpace::continuous(dmatrix![-1e-3, 0.0; 0.0, -1e12], dmatrix![1.0; 1.0],
    ///                                       dmatrix![1.0, 1.0], dmatrix![0.0])?;
    /// assert!(stiff.is_stable()?);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn is_stable(&self) -> Result<bool, Error> {
        Ok(self.unstable_pole()?.is_none())
    }

    /// The first pole, in the order of [`poles`](Self::poles), on or outside
    /// the stability boundary within its rounding error, or `None` for a
    /// stable model: [`StateSpace::unstable_pole`]'s test.
    ///
    /// # Errors
    ///
    /// As [`poles`](Self::poles).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::DynStateSpace;
    /// use ctrlab::nalgebra::dmatrix;
    ///
    /// let sys = DynStateSpace::discrete(dmatrix![0.5, 0.0; 0.0, 1.5], dmatrix![1.0; 1.0],
    ///                                   dmatrix![1.0, 1.0], dmatrix![0.0], 0.1)?;
    /// assert_eq!(sys.unstable_pole()?.map(|z| z.re), Some(1.5));
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn unstable_pole(&self) -> Result<Option<Complex<f64>>, Error> {
        let poles = self.poles()?;
        Ok(first_unstable_dyn(
            &poles,
            self.a(),
            period_of(&self.domain()),
        ))
    }

    /// The steady-state gain, `p × m` (output units per input unit):
    /// `−C A⁻¹ B + D` in continuous time, `C (I − A)⁻¹ B + D` in discrete
    /// time. MATLAB's and python-control's `dcgain`; the algorithm and the
    /// refusal of a pole at `s = 0` / `z = 1` are those of
    /// [`StateSpace::dc_gain`].
    ///
    /// # Errors
    ///
    /// [`Error::Singular`] for a pole at `s = 0` / `z = 1` to working
    /// precision (Skeel condition number of `A` or `I − A` above
    /// `1 / (10⁴ ε)`); [`Error::Overflow`] for a gain that overflows.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{DynStateSpace, Error};
    /// use ctrlab::nalgebra::dmatrix;
    ///
    /// // Two lags with gains 2 and 0.5, one per channel.
    /// let sys = DynStateSpace::continuous(dmatrix![-2.0, 0.0; 0.0, -4.0], dmatrix![4.0, 0.0; 0.0, 2.0],
    ///                                     dmatrix![1.0, 0.0; 0.0, 1.0], dmatrix![0.0, 0.0; 0.0, 0.0])?;
    /// assert_eq!(sys.dc_gain()?, dmatrix![2.0, 0.0; 0.0, 0.5]);
    /// let integrator = DynStateSpace::continuous(dmatrix![0.0], dmatrix![1.0], dmatrix![1.0], dmatrix![0.0])?;
    /// assert!(matches!(integrator.dc_gain(), Err(Error::Singular { .. })));
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[doc(alias = "dcgain")]
    pub fn dc_gain(&self) -> Result<DMatrix<f64>, Error> {
        gain::dc_gain(
            self.a(),
            self.b(),
            self.c(),
            self.d(),
            period_of(&self.domain()),
        )
    }

    /// The controllability matrix `[B, A B, …, A^(n−1) B]`, `n × (n·m)`.
    ///
    /// # Errors
    ///
    /// [`Error::Overflow`] if a power of `A` overflows.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::DynStateSpace;
    /// use ctrlab::nalgebra::dmatrix;
    ///
    /// let sys = DynStateSpace::continuous(dmatrix![0.0, 1.0; 0.0, 0.0], dmatrix![0.0; 1.0],
    ///                                     dmatrix![1.0, 0.0], dmatrix![0.0])?;
    /// assert_eq!(sys.controllability()?, dmatrix![0.0, 1.0; 1.0, 0.0]);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[doc(alias = "ctrb")]
    pub fn controllability(&self) -> Result<DMatrix<f64>, Error> {
        krylov(self.a(), self.b(), "controllability matrix")
    }

    /// The observability matrix `[C; C A; …; C A^(n−1)]`, `(n·p) × n`.
    ///
    /// # Errors
    ///
    /// [`Error::Overflow`] if a power of `A` overflows.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::DynStateSpace;
    /// use ctrlab::nalgebra::dmatrix;
    ///
    /// let sys = DynStateSpace::continuous(dmatrix![0.0, 1.0; 0.0, 0.0], dmatrix![0.0; 1.0],
    ///                                     dmatrix![1.0, 0.0], dmatrix![0.0])?;
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

    /// True when the controllability matrix has full rank `n` by the
    /// scale-independent test of [`StateSpace::is_controllable`].
    ///
    /// # Errors
    ///
    /// [`Error::Overflow`] if scaled powers of `A` overflow;
    /// [`Error::NoConvergence`] if the SVD fails.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::DynStateSpace;
    /// use ctrlab::nalgebra::{DMatrix, dmatrix};
    ///
    /// // Five integrators in a chain, coupled by 10⁶: controllable from the
    /// // first, though the raw matrix spans 24 decades.
    /// let n = 5;
    /// let a = DMatrix::from_fn(n, n, |i, j| if i == j + 1 { 1e6 } else { 0.0 });
    /// let b = DMatrix::from_fn(n, 1, |i, _| if i == 0 { 1.0 } else { 0.0 });
    /// let sys = DynStateSpace::continuous(a, b, DMatrix::from_element(1, n, 1.0), dmatrix![0.0])?;
    /// assert!(sys.is_controllable()?);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn is_controllable(&self) -> Result<bool, Error> {
        Ok(scaled_krylov_rank(self.a(), self.b())? == self.states())
    }

    /// True when the observability matrix has full rank `n`, scaled as in
    /// [`is_controllable`](Self::is_controllable).
    ///
    /// # Errors
    ///
    /// As [`is_controllable`](Self::is_controllable).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::DynStateSpace;
    /// use ctrlab::nalgebra::dmatrix;
    ///
    /// // The output sees only the first of two decoupled states.
    /// let sys = DynStateSpace::continuous(dmatrix![-1.0, 0.0; 0.0, -2.0], dmatrix![1.0; 1.0],
    ///                                     dmatrix![1.0, 0.0], dmatrix![0.0])?;
    /// assert!(!sys.is_observable()?);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn is_observable(&self) -> Result<bool, Error> {
        Ok(scaled_krylov_rank(&self.a().transpose(), &self.c().transpose())? == self.states())
    }

    /// [`Damping`] (natural frequency in rad/s, damping ratio, time constant
    /// in s) of each pole, in the order of [`poles`](Self::poles); a
    /// discrete pole `z` is first mapped to `s = ln(z) / dt`, as MATLAB's
    /// `damp` does.
    ///
    /// # Errors
    ///
    /// As [`poles`](Self::poles).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::DynStateSpace;
    /// use ctrlab::nalgebra::dmatrix;
    ///
    /// // ωn = 10 rad/s, ζ = 0.3.
    /// let sys = DynStateSpace::continuous(dmatrix![0.0, 1.0; -100.0, -6.0], dmatrix![0.0; 1.0],
    ///                                     dmatrix![1.0, 0.0], dmatrix![0.0])?;
    /// for d in sys.damping()? {
    ///     assert!((d.natural_frequency - 10.0).abs() < 1e-12);
    ///     assert!((d.damping_ratio - 0.3).abs() < 1e-12);
    ///     assert!((d.time_constant - 1.0 / 3.0).abs() < 1e-12);
    /// }
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[doc(alias = "damp")]
    pub fn damping(&self) -> Result<Vec<Damping>, Error> {
        Ok(damping_of(&self.poles()?, period_of(&self.domain())))
    }
}
