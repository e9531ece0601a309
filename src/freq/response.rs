//! Frequency responses: [`FrequencyResponse`] (complex, MIMO) and its SISO
//! views [`Bode`] and [`Nyquist`], for every model type through
//! [`FrequencyDomain`].

use std::borrow::Cow;
use std::f64::consts::PI;

use nalgebra::Complex;

use super::bode::{Bode, Nyquist};
use super::kernel::Evaluator;
use super::matrix::TransferMatrix;
use super::tf::TransferFunction;
use super::zpk::Zpk;
use crate::error::Error;
use crate::model::{Domain, DynStateSpace, StateSpace, period_of};

type C64 = Complex<f64>;

/// Checks angular frequencies: every one finite.
/// Checks an `(output, input)` pair against a `outputs × inputs` response.
pub(crate) fn check_channel(
    output: usize,
    input: usize,
    outputs: usize,
    inputs: usize,
) -> Result<(), Error> {
    if output >= outputs {
        return Err(Error::OutOfRange {
            what: "output",
            index: output,
            len: outputs,
        });
    }
    if input >= inputs {
        return Err(Error::OutOfRange {
            what: "input",
            index: input,
            len: inputs,
        });
    }
    Ok(())
}

pub(crate) fn check_omega(omega: &[f64]) -> Result<(), Error> {
    match omega.iter().position(|w| !w.is_finite()) {
        None => Ok(()),
        Some(index) => Err(Error::InvalidData {
            what: "omega",
            index,
            reason: "angular frequency (rad/s) is not finite",
        }),
    }
}

/// The point where a model of period `period` is evaluated at `ω` rad/s:
/// `s = jω`, or `z = e^(jω dt)`.
pub(crate) fn point(period: Option<f64>, w: f64) -> C64 {
    match period {
        None => C64::new(0.0, w),
        Some(dt) => C64::from_polar(1.0, w * dt),
    }
}

mod sealed {
    use std::borrow::Cow;

    use super::TransferFunction;
    use crate::error::Error;
    use crate::model::Domain;

    /// Seals [`FrequencyDomain`](super::FrequencyDomain) and gives the
    /// margin and bandwidth code each model's transfer function.
    pub trait Sealed {
        /// The model's time domain.
        type Domain: Domain;

        /// The model as one SISO transfer function;
        /// [`Error::DimensionMismatch`] named `"D"` (expected 1 × 1) for a
        /// model with several inputs or outputs.
        fn siso_transfer_function(&self) -> Result<Cow<'_, TransferFunction<Self::Domain>>, Error>;
    }
}

/// [`Error::DimensionMismatch`] named `"D"` for a `outputs × inputs` model
/// where a SISO one is needed.
fn not_siso(outputs: usize, inputs: usize) -> Error {
    Error::DimensionMismatch {
        matrix: "D",
        expected_rows: 1,
        expected_cols: 1,
        found_rows: outputs,
        found_cols: inputs,
    }
}

/// A linear model whose frequency response can be evaluated:
/// [`StateSpace`], [`DynStateSpace`], [`TransferFunction`],
/// [`TransferMatrix`] and [`Zpk`], continuous or discrete. [`bode`],
/// [`nyquist`], [`frequency_response`],
/// [`stability_margins`](super::stability_margins) and
/// [`bandwidth`](super::bandwidth) take any of them (the last two a SISO
/// one, checked when called).
///
/// Continuous models are evaluated at `s = jω`, discrete ones at
/// `z = e^(jω dt)`, for `ω` in rad/s. Discrete responses are periodic in
/// `ω` with period `2π/dt`; frequencies above the Nyquist frequency `π/dt`
/// are evaluated as given (python-control's `bode` drops them).
///
/// # Examples
///
/// ```
/// use ctrlab::freq::{FrequencyDomain, TransferFunction};
///
/// let g = TransferFunction::continuous(&[1.0], &[1.0, 1.0])?; // 1/(s + 1)
/// let r = g.frequency_response(&[0.0, 1.0])?;
/// assert_eq!(r.response(0, 0)?[0].re, 1.0);
/// assert!((r.response(0, 0)?[1].norm() - 0.5f64.sqrt()).abs() < 1e-15);
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[doc(alias = "freqresp")]
pub trait FrequencyDomain: sealed::Sealed {
    /// The complex response `G(jω)` (or `G(e^(jω dt))`) at each `ω`
    /// (rad/s), every output and input.
    ///
    /// # Errors
    ///
    /// [`Error::InvalidData`] (`"omega"`) for a non-finite frequency;
    /// [`Error::Singular`] if a frequency falls exactly on a pole (an
    /// integrator at `ω = 0`); [`Error::Overflow`] if a value is not finite.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{Cart, MassSpring, freq::FrequencyDomain};
    ///
    /// let plant = MassSpring::nominal().state_space(Cart::Two)?;
    /// let r = plant.frequency_response(&[0.0, 1e3])?;
    /// assert!((r.response(0, 0)?[0].re - 0.002).abs() < 1e-15); // 2 mm/N at DC
    /// assert!(r.response(0, 0)?[1].norm() < 2e-6); // rolled off at 1000 rad/s
    /// assert!(plant.frequency_response(&[f64::NAN]).is_err());
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[doc(alias = "freqresp")]
    fn frequency_response(&self, omega: &[f64]) -> Result<FrequencyResponse, Error>;
}

/// A model's complex frequency response at angular frequencies `ω` (rad/s):
/// for each output `i` and input `j`, the values `G_ij` at every `ω`
/// (python-control's `frequency_response`, MATLAB's `freqresp`).
///
/// # Examples
///
/// ```
/// use ctrlab::freq::{FrequencyDomain, TransferFunction, logspace};
///
/// let w = logspace(-1.0, 2.0, 301)?; // 0.1 to 100 rad/s
/// let r = TransferFunction::continuous(&[10.0], &[1.0, 10.0])?.frequency_response(&w)?;
/// let bode = r.bode(0, 0)?;
/// // −3 dB and −45° at the corner, 10 rad/s (index 200).
/// assert!((bode.magnitude_db()[200] + 3.0103).abs() < 1e-4);
/// assert!((bode.phase_deg()[200] + 45.0).abs() < 1e-9);
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct FrequencyResponse {
    omega: Vec<f64>,
    outputs: usize,
    inputs: usize,
    /// Channel `(i, j)` at `[(i · inputs + j) · len ..][..len]`.
    values: Vec<C64>,
}

impl FrequencyResponse {
    /// The angular frequencies, rad/s.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::freq::{FrequencyDomain, TransferFunction};
    /// let r = TransferFunction::continuous(&[1.0], &[1.0, 1.0])?.frequency_response(&[1.0, 2.0])?;
    /// assert_eq!(r.omega(), &[1.0, 2.0]);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn omega(&self) -> &[f64] {
        &self.omega
    }

    /// The frequencies in hertz, `ω / 2π`.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::freq::{FrequencyDomain, TransferFunction};
    /// # use std::f64::consts::PI;
    /// let r = TransferFunction::continuous(&[1.0], &[1.0, 1.0])?.frequency_response(&[2.0 * PI])?;
    /// assert_eq!(r.frequency_hz(), vec![1.0]);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn frequency_hz(&self) -> Vec<f64> {
        self.omega.iter().map(|w| w / (2.0 * PI)).collect()
    }

    /// The number of outputs.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::freq::{FrequencyDomain, TransferFunction};
    /// let r = TransferFunction::continuous(&[1.0], &[1.0, 1.0])?.frequency_response(&[1.0])?;
    /// assert_eq!((r.outputs(), r.inputs()), (1, 1));
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn outputs(&self) -> usize {
        self.outputs
    }

    /// The number of inputs.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::freq::{FrequencyDomain, TransferFunction};
    /// let r = TransferFunction::continuous(&[1.0], &[1.0, 1.0])?.frequency_response(&[1.0])?;
    /// assert_eq!(r.inputs(), 1);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn inputs(&self) -> usize {
        self.inputs
    }

    /// The complex values `G_ij(jω)` from input `input` to output
    /// `output`, one per frequency.
    ///
    /// # Errors
    ///
    /// [`Error::OutOfRange`] for an index past the end.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::freq::{FrequencyDomain, TransferFunction};
    /// # use ctrlab::nalgebra::Complex;
    /// let r = TransferFunction::continuous(&[1.0], &[1.0, 0.0])?.frequency_response(&[2.0])?;
    /// assert_eq!(r.response(0, 0)?, &[Complex::new(0.0, -0.5)]);
    /// assert!(r.response(1, 0).is_err());
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn response(&self, output: usize, input: usize) -> Result<&[C64], Error> {
        check_channel(output, input, self.outputs, self.inputs)?;
        let len = self.omega.len();
        let at = (output * self.inputs + input) * len;
        Ok(&self.values[at..at + len])
    }

    /// The Bode data of one channel: magnitude and unwrapped phase.
    ///
    /// # Errors
    ///
    /// As [`response`](Self::response).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::freq::{FrequencyDomain, TransferFunction};
    /// // 1/(s + 1)³: the phase runs on past −180° instead of jumping to +107°.
    /// let g = TransferFunction::continuous(&[1.0], &[1.0, 3.0, 3.0, 1.0])?;
    /// let b = g.frequency_response(&[0.1, 1.0, 10.0])?.bode(0, 0)?;
    /// assert!((b.phase_deg()[2] + 3.0 * 10f64.atan().to_degrees()).abs() < 1e-9);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn bode(&self, output: usize, input: usize) -> Result<Bode, Error> {
        Ok(Bode::from_checked(
            &self.omega,
            self.response(output, input)?,
        ))
    }

    /// The Nyquist data of one channel: real and imaginary parts.
    ///
    /// # Errors
    ///
    /// As [`response`](Self::response).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::freq::{FrequencyDomain, TransferFunction};
    /// let r = TransferFunction::continuous(&[1.0], &[1.0, 1.0])?.frequency_response(&[1.0])?;
    /// let n = r.nyquist(0, 0)?;
    /// assert_eq!((n.re[0], n.im[0]), (0.5, -0.5));
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn nyquist(&self, output: usize, input: usize) -> Result<Nyquist, Error> {
        let g = self.response(output, input)?;
        Ok(Nyquist {
            omega: self.omega.clone(),
            re: g.iter().map(|g| g.re).collect(),
            im: g.iter().map(|g| g.im).collect(),
        })
    }
}

/// The frequency response of any model ([`FrequencyDomain`]) at `ω`
/// (rad/s), python-control's `frequency_response`.
///
/// # Errors
///
/// As [`FrequencyDomain::frequency_response`].
///
/// # Examples
///
/// ```
/// use ctrlab::freq::{TransferFunction, frequency_response};
///
/// let r = frequency_response(&TransferFunction::continuous(&[2.0], &[1.0])?, &[1.0])?;
/// assert_eq!(r.response(0, 0)?[0].re, 2.0);
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[doc(alias = "freqresp")]
pub fn frequency_response(
    sys: &impl FrequencyDomain,
    omega: &[f64],
) -> Result<FrequencyResponse, Error> {
    sys.frequency_response(omega)
}

/// Bode data (magnitude, unwrapped phase) of a SISO model at `ω` (rad/s).
///
/// # Errors
///
/// [`Error::DimensionMismatch`] unless the model has one input and one
/// output; as [`FrequencyDomain::frequency_response`].
///
/// # Examples
///
/// ```
/// use ctrlab::{Cart, MassSpring, freq::{bode, logspace}};
///
/// let plant = MassSpring::nominal().state_space(Cart::Two)?;
/// let b = bode(&plant, &logspace(0.0, 3.0, 1000)?)?;
/// // −54 dB (2 mm/N) at low frequency, a resonance peak 8 dB above it
/// // near 20 rad/s (3.3 Hz).
/// assert!((b.magnitude_db()[0] + 53.96).abs() < 0.01);
/// assert!(b.magnitude_db().iter().any(|&m| m > -46.0));
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub fn bode(sys: &impl FrequencyDomain, omega: &[f64]) -> Result<Bode, Error> {
    siso(sys.frequency_response(omega)?)?.bode(0, 0)
}

/// Nyquist data of a SISO model at `ω` (rad/s).
///
/// # Errors
///
/// As [`bode`].
///
/// # Examples
///
/// ```
/// use ctrlab::freq::{TransferFunction, nyquist};
///
/// let n = nyquist(&TransferFunction::continuous(&[1.0], &[1.0, 1.0])?, &[1.0])?;
/// assert_eq!((n.re[0], n.im[0]), (0.5, -0.5));
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub fn nyquist(sys: &impl FrequencyDomain, omega: &[f64]) -> Result<Nyquist, Error> {
    siso(sys.frequency_response(omega)?)?.nyquist(0, 0)
}

pub(crate) fn siso(r: FrequencyResponse) -> Result<FrequencyResponse, Error> {
    if r.outputs == 1 && r.inputs == 1 {
        Ok(r)
    } else {
        Err(not_siso(r.outputs, r.inputs))
    }
}

/// The model as one SISO transfer function, for the margins and the
/// bandwidth.
pub(crate) fn siso_transfer_function<S: FrequencyDomain>(
    sys: &S,
) -> Result<Cow<'_, TransferFunction<<S as sealed::Sealed>::Domain>>, Error> {
    sys.siso_transfer_function()
}

/// The state-space response through the Hessenberg kernel.
fn state_space_response<D: Domain>(
    sys: &DynStateSpace<D>,
    omega: &[f64],
) -> Result<FrequencyResponse, Error> {
    check_omega(omega)?;
    let (p, m, len) = (sys.outputs(), sys.inputs(), omega.len());
    let period = period_of(&sys.domain());
    let mut ev = Evaluator::new(sys.a(), sys.b(), sys.c(), sys.d());
    let mut values = vec![C64::new(0.0, 0.0); p * m * len];
    let points: Vec<C64> = omega.iter().map(|&w| point(period, w)).collect();
    ev.eval_many(&points, &mut values)?;
    Ok(FrequencyResponse {
        omega: omega.to_vec(),
        outputs: p,
        inputs: m,
        values,
    })
}

impl<D: Domain> sealed::Sealed for DynStateSpace<D> {
    type Domain = D;

    fn siso_transfer_function(&self) -> Result<Cow<'_, TransferFunction<D>>, Error> {
        TransferFunction::from_state_space(self).map(Cow::Owned)
    }
}
impl<D: Domain> FrequencyDomain for DynStateSpace<D> {
    fn frequency_response(&self, omega: &[f64]) -> Result<FrequencyResponse, Error> {
        state_space_response(self, omega)
    }
}

impl<const N: usize, const M: usize, const P: usize, D: Domain> sealed::Sealed
    for StateSpace<N, M, P, D>
{
    type Domain = D;

    fn siso_transfer_function(&self) -> Result<Cow<'_, TransferFunction<D>>, Error> {
        if (M, P) != (1, 1) {
            return Err(not_siso(P, M));
        }
        TransferFunction::from_state_space(&DynStateSpace::from(self)).map(Cow::Owned)
    }
}
impl<const N: usize, const M: usize, const P: usize, D: Domain> FrequencyDomain
    for StateSpace<N, M, P, D>
{
    fn frequency_response(&self, omega: &[f64]) -> Result<FrequencyResponse, Error> {
        state_space_response(&DynStateSpace::from(self), omega)
    }
}

/// A response of SISO entries evaluated one point at a time.
fn pointwise<D: Domain>(
    outputs: usize,
    inputs: usize,
    domain: D,
    omega: &[f64],
    eval: impl Fn(usize, C64) -> Result<C64, Error>,
) -> Result<FrequencyResponse, Error> {
    check_omega(omega)?;
    let period = period_of(&domain);
    let len = omega.len();
    let mut values = Vec::with_capacity(outputs * inputs * len);
    for ch in 0..outputs * inputs {
        for &w in omega {
            values.push(eval(ch, point(period, w)).map_err(|e| match e {
                Error::Singular { .. } => Error::Singular {
                    operation: "frequency response (ω is at a pole)",
                },
                e => e,
            })?);
        }
    }
    Ok(FrequencyResponse {
        omega: omega.to_vec(),
        outputs,
        inputs,
        values,
    })
}

impl<D: Domain> sealed::Sealed for TransferFunction<D> {
    type Domain = D;

    fn siso_transfer_function(&self) -> Result<Cow<'_, TransferFunction<D>>, Error> {
        Ok(Cow::Borrowed(self))
    }
}
impl<D: Domain> FrequencyDomain for TransferFunction<D> {
    fn frequency_response(&self, omega: &[f64]) -> Result<FrequencyResponse, Error> {
        pointwise(1, 1, self.domain(), omega, |_, s| self.evaluate(s))
    }
}

impl<D: Domain> sealed::Sealed for TransferMatrix<D> {
    type Domain = D;

    fn siso_transfer_function(&self) -> Result<Cow<'_, TransferFunction<D>>, Error> {
        match self.entries() {
            [g] => Ok(Cow::Borrowed(g)),
            _ => Err(not_siso(self.outputs(), self.inputs())),
        }
    }
}
impl<D: Domain> FrequencyDomain for TransferMatrix<D> {
    fn frequency_response(&self, omega: &[f64]) -> Result<FrequencyResponse, Error> {
        let domain = self.entries()[0].domain();
        pointwise(self.outputs(), self.inputs(), domain, omega, |ch, s| {
            self.entries()[ch].evaluate(s)
        })
    }
}

impl<D: Domain> sealed::Sealed for Zpk<D> {
    type Domain = D;

    fn siso_transfer_function(&self) -> Result<Cow<'_, TransferFunction<D>>, Error> {
        self.to_transfer_function().map(Cow::Owned)
    }
}
impl<D: Domain> FrequencyDomain for Zpk<D> {
    fn frequency_response(&self, omega: &[f64]) -> Result<FrequencyResponse, Error> {
        pointwise(1, 1, self.domain(), omega, |_, s| self.evaluate(s))
    }
}
