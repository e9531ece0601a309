//! [`Design`]: the design operations' view of the two model types, and
//! [`PoleTargets`], the pole lists [`place`](super::place),
//! [`acker`](super::acker) and [`place_observer`](super::place_observer)
//! accept.

use std::fmt::{Debug, Display};

use nalgebra::{Complex, Const, DMatrix, Dim, Dyn, SMatrix};

use super::integral::{augment_integral, augmented};
use super::kalman::{self, Lqe};
use super::lqr::{self, Lqr};
use super::place::{acker_pair, check_targets};
use super::robust_place::{observer_pair, place_pair};
use crate::error::Error;
use crate::model::{Domain, DynStateSpace, LinearSystem, StateSpace, Token, period_of};

/// A model the design functions take: [`StateSpace`] and [`DynStateSpace`],
/// in either time domain. Its associated types are the shapes of the
/// designs' arguments and results, `SMatrix`es of the model's sizes for a
/// fixed-size model (so a wrong size does not compile) and `DMatrix`es for
/// one sized at run time (checked when called); see
/// [`LinearSystem`] for why the crate is written this way.
///
/// | | `StateSpace<N, M, P, _>` | `DynStateSpace<_>` |
/// |---|---|---|
/// | [`StateWeight`](Self::StateWeight) (`Q`) | `SMatrix<f64, N, N>` | `DMatrix<f64>` |
/// | [`InputWeight`](Self::InputWeight) (`R`) | `SMatrix<f64, M, M>` | `DMatrix<f64>` |
/// | [`OutputWeight`](Self::OutputWeight) (`RN`) | `SMatrix<f64, P, P>` | `DMatrix<f64>` |
/// | [`Gain`](Self::Gain) (`K`) | `SMatrix<f64, M, N>` | `DMatrix<f64>` |
/// | [`ObserverGain`](Self::ObserverGain) (`L`) | `SMatrix<f64, N, P>` | `DMatrix<f64>` |
/// | [`Lqr`](Self::Lqr) | `Lqr<Const<N>, Const<M>>` | [`DynLqr`](super::DynLqr) |
/// | [`Lqe`](Self::Lqe) | `Lqe<Const<N>, Const<P>>` | [`DynLqe`](super::DynLqe) |
///
/// Sealed: implemented by the two model types only.
///
/// # Examples
///
/// A design written once for both sizes. In generic code the result is the
/// model's [`Lqr`](Self::Lqr), which prints (and clones); its fields are
/// read where the size is known:
///
/// ```
/// use ctrlab::{Continuous, DynStateSpace, StateSpace, design::{Design, lqr}};
/// use ctrlab::nalgebra::{dmatrix, matrix};
///
/// fn report<S: Design<Domain = Continuous>>(sys: &S, q: &S::StateWeight, r: &S::InputWeight)
///     -> Result<String, ctrlab::Error>
/// {
///     Ok(lqr(sys, q, r)?.to_string())
/// }
/// let sys = StateSpace::continuous(matrix![1.0], matrix![1.0], matrix![1.0], matrix![0.0])?;
/// let fixed = report(&sys, &matrix![1.0], &matrix![1.0])?;
/// assert_eq!(fixed, report(&DynStateSpace::from(&sys), &dmatrix![1.0], &dmatrix![1.0])?);
/// assert_eq!(fixed, "K =\n  2.4142\npoles = -1.4142\n");
/// assert!(lqr(&sys, &matrix![1.0], &matrix![1.0])?.residual < 1e-12);
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub trait Design: LinearSystem {
    /// An `n × n` matrix: a state weight `Q`.
    type StateWeight;
    /// An `m × m` matrix: an input weight `R`.
    type InputWeight;
    /// A `p × p` matrix: a measurement noise covariance `RN`.
    type OutputWeight;
    /// An `m × n` state-feedback gain `K` (`u = −K x`).
    type Gain;
    /// An `n × p` observer gain `L`.
    type ObserverGain;
    /// The regulator [`lqr`](super::lqr) and [`dlqr`](super::dlqr) return
    /// (printable: its gain and poles).
    type Lqr: Debug + Clone + Display;
    /// The Kalman filter [`lqe`](super::lqe) and [`dlqe`](super::dlqe)
    /// return.
    type Lqe: Debug + Clone;

    /// The regulator for `Q`, `R`, in the model's time domain.
    #[doc(hidden)]
    fn regulator(
        &self,
        _: Token,
        q: &Self::StateWeight,
        r: &Self::InputWeight,
    ) -> Result<Self::Lqr, Error>;

    /// The robust placement gain.
    #[doc(hidden)]
    fn place_gain(&self, _: Token, poles: &[Complex<f64>]) -> Result<Self::Gain, Error>;

    /// Ackermann's gain (one input).
    #[doc(hidden)]
    fn acker_gain(&self, _: Token, poles: &[Complex<f64>]) -> Result<Self::Gain, Error>;

    /// The observer gain, by placement on the dual.
    #[doc(hidden)]
    fn observer_gain(&self, _: Token, poles: &[Complex<f64>]) -> Result<Self::ObserverGain, Error>;
}

/// The noise model of a Kalman filter ([`lqe`](super::lqe),
/// [`dlqe`](super::dlqe)) on a model of either size: `G` is how the process
/// noise `w` enters (`n × w`), and
/// [`NoiseCovariance`](Self::NoiseCovariance) is `QN`'s shape (`w × w`):
/// `SMatrix<f64, N, W>` and `SMatrix<f64, W, W>` for a fixed-size model
/// (any `W`), `DMatrix<f64>` for both on a model sized at run time.
///
/// Sealed: implemented by the two model types only.
///
/// # Examples
///
/// ```
/// use ctrlab::{DynStateSpace, StateSpace, design::lqe};
/// use ctrlab::nalgebra::{dmatrix, matrix};
///
/// // A random walk measured directly: the same filter for either size.
/// let sys = StateSpace::continuous(matrix![0.0], matrix![0.1], matrix![1.0], matrix![0.0])?;
/// let fixed = lqe(&sys, &matrix![0.1], &matrix![10.0], &matrix![2.0])?;
/// let dynamic = lqe(&DynStateSpace::from(&sys), &dmatrix![0.1], &dmatrix![10.0], &dmatrix![2.0])?;
/// assert_eq!(fixed.gain.as_slice(), dynamic.gain.as_slice());
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub trait Kalman<G>: Design {
    /// A `w × w` matrix: the process noise covariance `QN`.
    type NoiseCovariance;

    /// The steady-state filter in the model's time domain.
    #[doc(hidden)]
    fn estimator(
        &self,
        _: Token,
        g: &G,
        qn: &Self::NoiseCovariance,
        rn: &Self::OutputWeight,
    ) -> Result<Self::Lqe, Error>;
}

/// Integral action ([`lqi`](super::lqi), [`dlqi`](super::dlqi)) on a
/// model of either size: `Q` weighs the augmented state `[x; z]`, an
/// `SMatrix<f64, NA, NA>` with `NA = N + P` for a `StateSpace<N, M, P, _>`
/// (a wrong `NA` does not compile) or a `DMatrix<f64>` for a
/// `DynStateSpace`; [`Lqi`](Self::Lqi) is the regulator of the augmented
/// model, `Lqr<Const<NA>, Const<M>>` or [`DynLqr`](super::DynLqr).
///
/// Sealed: implemented by the two model types only.
///
/// # Examples
///
/// ```
/// use ctrlab::{DynStateSpace, StateSpace, design::lqi};
/// use ctrlab::nalgebra::{dmatrix, matrix};
///
/// // A lag with an integrator on its output.
/// let sys = StateSpace::continuous(matrix![-1.0], matrix![1.0], matrix![1.0], matrix![0.0])?;
/// let fixed = lqi(&sys, &matrix![1.0, 0.0; 0.0, 10.0], &matrix![1.0])?;
/// let dynamic = lqi(&DynStateSpace::from(&sys), &dmatrix![1.0, 0.0; 0.0, 10.0], &dmatrix![1.0])?;
/// assert_eq!(fixed.gain.as_slice(), dynamic.gain.as_slice());
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub trait IntegralAction<Q>: Design {
    /// The regulator of the model augmented with its integrators.
    type Lqi: Debug + Clone + Display;

    /// The regulator of the augmented model, in the model's time domain.
    #[doc(hidden)]
    fn integral_regulator(
        &self,
        _: Token,
        q: &Q,
        r: &Self::InputWeight,
    ) -> Result<Self::Lqi, Error>;
}

impl<const N: usize, const M: usize, const P: usize, const NA: usize, D: Domain>
    IntegralAction<SMatrix<f64, NA, NA>> for StateSpace<N, M, P, D>
{
    type Lqi = Lqr<Const<NA>, Const<M>>;

    fn integral_regulator(
        &self,
        _: Token,
        q: &SMatrix<f64, NA, NA>,
        r: &Self::InputWeight,
    ) -> Result<Self::Lqi, Error> {
        let aug = augment_integral::<N, M, P, NA, D>(self)?;
        lqr::regulator(aug.a(), aug.b(), q, r, period_of(&self.domain()))
    }
}

impl<D: Domain> IntegralAction<DMatrix<f64>> for DynStateSpace<D> {
    type Lqi = Lqr<Dyn, Dyn>;

    fn integral_regulator(
        &self,
        _: Token,
        q: &DMatrix<f64>,
        r: &Self::InputWeight,
    ) -> Result<Self::Lqi, Error> {
        let aug = augmented(self)?;
        lqr::regulator(aug.a(), aug.b(), q, r, period_of(&self.domain()))
    }
}

/// The design operations of both model types: the same code, each on its
/// own matrices (the types are all that differ).
macro_rules! design_for {
    ($([$($generics:tt)*] $model:ty {
        $(type $name:ident = $ty:ty;)*
        [$($kalman_generics:tt)*] Kalman<$noise:ty, $covariance:ty>
    })*) => {$(
        impl<$($generics)*> Design for $model {
            $(type $name = $ty;)*

            fn regulator(
                &self,
                _: Token,
                q: &Self::StateWeight,
                r: &Self::InputWeight,
            ) -> Result<Self::Lqr, Error> {
                lqr::regulator(self.a(), self.b(), q, r, period_of(&self.domain()))
            }

            fn place_gain(&self, _: Token, poles: &[Complex<f64>]) -> Result<Self::Gain, Error> {
                check_targets(poles, self.states())?;
                place_pair(self.a(), self.b(), poles)
            }

            fn acker_gain(&self, _: Token, poles: &[Complex<f64>]) -> Result<Self::Gain, Error> {
                single_input(self.states(), self.inputs())?;
                check_targets(poles, self.states())?;
                acker_pair(self.a(), self.b(), poles)
            }

            fn observer_gain(
                &self,
                _: Token,
                poles: &[Complex<f64>],
            ) -> Result<Self::ObserverGain, Error> {
                check_targets(poles, self.states())?;
                observer_pair(self.a(), self.c(), poles)
            }
        }

        impl<$($kalman_generics)*> Kalman<$noise> for $model {
            type NoiseCovariance = $covariance;

            fn estimator(
                &self,
                _: Token,
                g: &$noise,
                qn: &Self::NoiseCovariance,
                rn: &Self::OutputWeight,
            ) -> Result<Self::Lqe, Error> {
                kalman::estimator(self.a(), self.c(), g, qn, rn, period_of(&self.domain()))
            }
        }
    )*};
}

design_for! {
    [const N: usize, const M: usize, const P: usize, D: Domain] StateSpace<N, M, P, D> {
        type StateWeight = SMatrix<f64, N, N>;
        type InputWeight = SMatrix<f64, M, M>;
        type OutputWeight = SMatrix<f64, P, P>;
        type Gain = SMatrix<f64, M, N>;
        type ObserverGain = SMatrix<f64, N, P>;
        type Lqr = Lqr<Const<N>, Const<M>>;
        type Lqe = Lqe<Const<N>, Const<P>>;
        [const N: usize, const M: usize, const P: usize, const W: usize, D: Domain]
        Kalman<SMatrix<f64, N, W>, SMatrix<f64, W, W>>
    }

    [D: Domain] DynStateSpace<D> {
        type StateWeight = DMatrix<f64>;
        type InputWeight = DMatrix<f64>;
        type OutputWeight = DMatrix<f64>;
        type Gain = DMatrix<f64>;
        type ObserverGain = DMatrix<f64>;
        type Lqr = Lqr<Dyn, Dyn>;
        type Lqe = Lqe<Dyn, Dyn>;
        [D: Domain] Kalman<DMatrix<f64>, DMatrix<f64>>
    }
}

/// [`Error::DimensionMismatch`] named `"B"` unless there is one input.
fn single_input(states: usize, inputs: usize) -> Result<(), Error> {
    if inputs == 1 {
        Ok(())
    } else {
        Err(Error::DimensionMismatch {
            matrix: "B",
            expected_rows: states,
            expected_cols: 1,
            found_rows: states,
            found_cols: inputs,
        })
    }
}

mod sealed {
    use nalgebra::Complex;

    /// The conversion behind [`PoleTargets`](super::PoleTargets).
    pub trait Targets<N> {
        fn to_complex(&self) -> Vec<Complex<f64>>;
    }
}

/// Target poles for [`place`](super::place), [`acker`](super::acker) and
/// [`place_observer`](super::place_observer), `s` in rad/s or `z`: any
/// list of numbers that convert into `Complex<f64>`, so real poles are
/// written as plain `f64` (`[-5.0, -6.0]`) and complex ones as
/// `Complex::new(re, im)`.
///
/// `N` is the model's [`States`](LinearSystem::States): for a fixed-size
/// model (`Const<N>`) an array of exactly `N` targets, by value or by
/// reference, so the count is checked at compile time; for a
/// `DynStateSpace` (`Dyn`) any array, slice or `Vec`, counted when called.
///
/// Sealed: implemented for those lists only.
///
/// # Examples
///
/// ```
/// use ctrlab::{DynStateSpace, StateSpace, design::place};
/// use ctrlab::nalgebra::{Complex, matrix};
///
/// // A double integrator.
/// let sys = StateSpace::continuous(matrix![0.0, 1.0; 0.0, 0.0], matrix![0.0; 1.0],
///                                  matrix![1.0, 0.0], matrix![0.0])?;
/// let real = place(&sys, [-1.0, -2.0])?; // (s + 1)(s + 2) = s² + 3 s + 2
/// assert!((real[(0, 0)] - 2.0).abs() < 1e-12 && (real[(0, 1)] - 3.0).abs() < 1e-12);
/// let pair = place(&sys, &[Complex::new(-1.0, 1.0), Complex::new(-1.0, -1.0)])?;
/// assert!((pair[(0, 0)] - 2.0).abs() < 1e-12 && (pair[(0, 1)] - 2.0).abs() < 1e-12);
///
/// // Sized at run time: a slice or a Vec, counted when called.
/// let dynamic = DynStateSpace::from(&sys);
/// assert_eq!(place(&dynamic, vec![-1.0, -2.0])?.as_slice(), real.as_slice());
/// assert!(place(&dynamic, &[-1.0][..]).is_err());
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub trait PoleTargets<N: Dim>: sealed::Targets<N> {}

impl<N: Dim, X: sealed::Targets<N>> PoleTargets<N> for X {}

/// The lists [`PoleTargets`] takes: arrays of the model's size for a
/// fixed-size model, any list for one sized at run time.
macro_rules! pole_lists {
    ($([$($generics:tt)*] $list:ty => $dim:ty),* $(,)?) => {$(
        impl<T: Copy + Into<Complex<f64>>, $($generics)*> sealed::Targets<$dim> for $list {
            fn to_complex(&self) -> Vec<Complex<f64>> {
                self.iter().map(|&p| p.into()).collect()
            }
        }
    )*};
}

pole_lists! {
    [const N: usize] [T; N] => Const<N>,
    [const N: usize] &[T; N] => Const<N>,
    [const K: usize] [T; K] => Dyn,
    [const K: usize] &[T; K] => Dyn,
    [] &[T] => Dyn,
    [] Vec<T> => Dyn,
    [] &Vec<T> => Dyn,
}

/// The targets as complex numbers, for the placement code.
pub(crate) fn targets<N: Dim>(poles: &impl PoleTargets<N>) -> Vec<Complex<f64>> {
    sealed::Targets::to_complex(poles)
}
