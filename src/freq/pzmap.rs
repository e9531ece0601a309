//! Pole-zero maps ([`pole_zero_map`]): a model's poles and zeros as data.

use nalgebra::Complex;

use super::matrix::TransferMatrix;
use super::tf::TransferFunction;
use super::zpk::Zpk;
use crate::error::Error;
use crate::model::{Domain, DynStateSpace, StateSpace, period_of};

/// A model's poles and zeros (python-control's `PoleZeroData`, MATLAB's
/// `[p, z] = pzmap(sys)`): in rad/s for a continuous model, in the
/// `z`-plane for a discrete one ([`period`](Self::period) set). Each list
/// is sorted by real, then imaginary part.
///
/// # Examples
///
/// ```
/// use ctrlab::freq::{TransferFunction, pole_zero_map};
///
/// let g = TransferFunction::continuous(&[1.0, 3.0], &[1.0, 3.0, 2.0])?;
/// let pz = pole_zero_map(&g)?;
/// assert_eq!((pz.poles.len(), pz.zeros.len()), (2, 1));
/// assert_eq!(pz.period, None);
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct PoleZeroMap {
    /// The poles: eigenvalues of `A`, or roots of the denominator.
    pub poles: Vec<Complex<f64>>,
    /// The zeros: invariant zeros of a state-space model (square models),
    /// roots of a transfer function's numerator.
    pub zeros: Vec<Complex<f64>>,
    /// The sampling period (s) of a discrete model; `None` if continuous.
    pub period: Option<f64>,
}

mod sealed {
    pub trait Sealed {}
}

/// A model with a pole-zero map: [`StateSpace`], [`DynStateSpace`],
/// [`TransferFunction`], [`Zpk`] and [`TransferMatrix`] (through its
/// minimal realisation), continuous or discrete. Sealed.
///
/// # Examples
///
/// ```
/// use ctrlab::{Cart, MassSpring, freq::PoleZero};
///
/// let plant = MassSpring::nominal().state_space(Cart::Two)?;
/// let pz = plant.pole_zero_map()?;
/// assert_eq!((pz.poles.len(), pz.zeros.len()), (4, 2));
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub trait PoleZero: sealed::Sealed {
    /// The model's [`PoleZeroMap`].
    ///
    /// # Errors
    ///
    /// [`Error::InvalidMatrix`] (`"D"`) for a state-space model with more
    /// inputs than outputs or the reverse (invariant zeros are computed for
    /// square models); the errors of the eigenvalue and root computations.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::freq::{PoleZero, Zpk};
    /// use ctrlab::nalgebra::Complex;
    ///
    /// let g = Zpk::continuous(&[Complex::new(-3.0, 0.0)], &[Complex::new(-1.0, 0.0)], 2.0)?;
    /// assert_eq!(g.pole_zero_map()?.zeros, [Complex::new(-3.0, 0.0)]);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[doc(alias = "pzmap")]
    fn pole_zero_map(&self) -> Result<PoleZeroMap, Error>;
}

fn sorted(mut v: Vec<Complex<f64>>) -> Vec<Complex<f64>> {
    v.sort_by(|x, y| x.re.total_cmp(&y.re).then(x.im.total_cmp(&y.im)));
    v
}

fn map<D: Domain>(poles: Vec<Complex<f64>>, zeros: Vec<Complex<f64>>, domain: D) -> PoleZeroMap {
    PoleZeroMap {
        poles: sorted(poles),
        zeros: sorted(zeros),
        period: period_of(&domain),
    }
}

impl<D: Domain> sealed::Sealed for DynStateSpace<D> {}
impl<D: Domain> PoleZero for DynStateSpace<D> {
    fn pole_zero_map(&self) -> Result<PoleZeroMap, Error> {
        Ok(map(self.poles()?, self.zeros()?, self.domain()))
    }
}

impl<const N: usize, const M: usize, const P: usize, D: Domain> sealed::Sealed
    for StateSpace<N, M, P, D>
{
}
impl<const N: usize, const M: usize, const P: usize, D: Domain> PoleZero
    for StateSpace<N, M, P, D>
{
    fn pole_zero_map(&self) -> Result<PoleZeroMap, Error> {
        Ok(map(self.poles()?.to_vec(), self.zeros()?, self.domain()))
    }
}

impl<D: Domain> sealed::Sealed for TransferFunction<D> {}
impl<D: Domain> PoleZero for TransferFunction<D> {
    fn pole_zero_map(&self) -> Result<PoleZeroMap, Error> {
        Ok(map(self.poles()?, self.zeros()?, self.domain()))
    }
}

impl<D: Domain> sealed::Sealed for Zpk<D> {}
impl<D: Domain> PoleZero for Zpk<D> {
    fn pole_zero_map(&self) -> Result<PoleZeroMap, Error> {
        Ok(map(
            self.poles().to_vec(),
            self.zeros().to_vec(),
            self.domain(),
        ))
    }
}

impl<D: Domain> sealed::Sealed for TransferMatrix<D> {}
impl<D: Domain> PoleZero for TransferMatrix<D> {
    fn pole_zero_map(&self) -> Result<PoleZeroMap, Error> {
        self.to_state_space()?.pole_zero_map()
    }
}

/// The poles and zeros of a model (MATLAB's and python-control's
/// `pzmap`, python-control's `pole_zero_map`): the same as
/// [`PoleZero::pole_zero_map`], as a free function. A state-space model's
/// zeros are its invariant zeros (nothing cancelled), a transfer
/// function's the roots of its numerator.
///
/// # Errors
///
/// As [`PoleZero::pole_zero_map`].
///
/// # Examples
///
/// ```
/// use ctrlab::{Cart, Discretization, MassSpring, freq::pole_zero_map};
///
/// let plant = MassSpring::nominal().state_space(Cart::Two)?;
/// let sampled = plant.discretize(0.002, Discretization::Zoh)?;
/// let pz = pole_zero_map(&sampled)?;
/// assert_eq!(pz.period, Some(0.002));
/// // Sampled by ZOH: every pole inside the unit circle, one zero more.
/// assert!(pz.poles.iter().all(|p| p.norm() < 1.0));
/// assert_eq!(pz.zeros.len(), 3);
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[doc(alias = "pzmap")]
pub fn pole_zero_map(sys: &impl PoleZero) -> Result<PoleZeroMap, Error> {
    sys.pole_zero_map()
}
