//! The analysis methods of fixed-size models ([`StateSpace`]), each
//! handing the model's matrices to the one run-time-sized implementation.

use nalgebra::{Complex, DMatrix, SMatrix};

#[cfg(doc)]
use super::rank;
use super::{Damping, damping_of, eigenvalues, gain};
use crate::error::Error;
use crate::model::{Domain, DynStateSpace, StateSpace, period_of};

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
    /// use ctrlab::nalgebra::{dmatrix, matrix};
    ///
    /// let sys = StateSpace::continuous(matrix![0.0, 1.0; 0.0, 0.0], matrix![0.0; 1.0],
    ///                                  matrix![1.0, 0.0], matrix![0.0])?;
    /// assert_eq!(sys.controllability()?, dmatrix![0.0, 1.0; 1.0, 0.0]);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[doc(alias = "ctrb")]
    pub fn controllability(&self) -> Result<DMatrix<f64>, Error> {
        DynStateSpace::from(self).controllability()
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
    /// use ctrlab::nalgebra::{dmatrix, matrix};
    ///
    /// let sys = StateSpace::continuous(matrix![0.0, 1.0; 0.0, 0.0], matrix![0.0; 1.0],
    ///                                  matrix![1.0, 0.0], matrix![0.0])?;
    /// assert_eq!(sys.observability()?, dmatrix![1.0, 0.0; 0.0, 1.0]);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[doc(alias = "obsv")]
    pub fn observability(&self) -> Result<DMatrix<f64>, Error> {
        DynStateSpace::from(self).observability()
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
    /// use ctrlab::nalgebra::matrix;
    ///
    /// // The input drives only the first of two decoupled states.
    /// let sys = StateSpace::continuous(matrix![-1.0, 0.0; 0.0, -2.0], matrix![1.0; 0.0],
    ///                                  matrix![1.0, 1.0], matrix![0.0])?;
    /// assert!(!sys.is_controllable()?);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn is_controllable(&self) -> Result<bool, Error> {
        DynStateSpace::from(self).is_controllable()
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
        DynStateSpace::from(self).is_observable()
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
    /// use ctrlab::nalgebra::matrix;
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
    /// use ctrlab::nalgebra::matrix;
    ///
    /// let sys = StateSpace::continuous(matrix![-1.0, 0.0; 0.0, 2.0], matrix![1.0; 1.0], matrix![1.0, 1.0], matrix![0.0])?;
    /// assert_eq!(sys.unstable_pole()?.map(|p| p.re), Some(2.0));
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn unstable_pole(&self) -> Result<Option<Complex<f64>>, Error> {
        DynStateSpace::from(self).unstable_pole()
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
    /// use ctrlab::{Cart, Error, MassSpring, Discretization, StateSpace};
    /// use ctrlab::nalgebra::matrix;
    ///
    /// let lag = StateSpace::continuous(matrix![-2.0], matrix![4.0], matrix![1.0], matrix![0.0])?;
    /// assert_eq!(lag.dc_gain()?, matrix![2.0]);
    /// let integrator = StateSpace::continuous(matrix![0.0], matrix![1.0], matrix![1.0], matrix![0.0])?;
    /// assert!(matches!(integrator.dc_gain(), Err(Error::Singular { .. })));
    ///
    /// // ZOH keeps the DC gain: 2 mm per newton on cart 2.
    /// let d = MassSpring::nominal().state_space(Cart::Two)?.discretize(0.002, Discretization::Zoh)?;
    /// assert!((d.dc_gain()?[(0, 0)] - 0.002).abs() < 1e-12);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[doc(alias = "dcgain")]
    pub fn dc_gain(&self) -> Result<SMatrix<f64, P, M>, Error> {
        gain::dc_gain(
            self.a(),
            self.b(),
            self.c(),
            self.d(),
            period_of(&self.domain()),
        )
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
    /// use ctrlab::nalgebra::matrix;
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
        let all = damping_of(&poles, period_of(&self.domain()));
        Ok(core::array::from_fn(|i| all[i]))
    }
}
