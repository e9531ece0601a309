//! Zero-pole-gain form.

use nalgebra::Complex;

use super::poly;
use super::tf::{TransferFunction, check_point, dc_point, snapped_poles};
use super::zeros::siso_numerator;
use crate::error::{Error, check_dt};
use crate::model::{Continuous, Discrete, Domain, DynStateSpace, StateSpace};

/// A SISO transfer function in zero-pole-gain form,
/// `G = gain · ∏(s − zᵢ) / ∏(s − pⱼ)` (python-control's and MATLAB's
/// `zpk`): zeros and poles in rad/s (continuous) or in the `z`-plane
/// (discrete, period `dt` s). Complex zeros and poles come in conjugate
/// pairs, so that the polynomials are real.
///
/// # Examples
///
/// ```
/// use ctrlab::freq::Zpk;
/// use ctrlab::nalgebra::Complex;
///
/// // 2 (s + 3) / ((s + 1)(s + 2))
/// let g = Zpk::continuous(&[Complex::new(-3.0, 0.0)],
///                         &[Complex::new(-1.0, 0.0), Complex::new(-2.0, 0.0)], 2.0)?;
/// assert_eq!(g.dc_gain()?, 3.0);
/// let tf = g.to_transfer_function()?;
/// assert_eq!((tf.num(), tf.den()), (&[2.0, 6.0][..], &[1.0, 3.0, 2.0][..]));
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[doc(alias = "zpk")]
#[derive(Debug, Clone, PartialEq)]
pub struct Zpk<D: Domain = Continuous> {
    zeros: Vec<Complex<f64>>,
    poles: Vec<Complex<f64>>,
    gain: f64,
    domain: D,
}

/// Checks roots: finite, and each non-real one matched by its conjugate
/// (to `1e-9` of its modulus, as computed eigenvalues pair).
fn check_roots(what: &'static str, r: &[Complex<f64>]) -> Result<(), Error> {
    if let Some(index) = r
        .iter()
        .position(|z| !(z.re.is_finite() && z.im.is_finite()))
    {
        return Err(Error::InvalidData {
            what,
            index,
            reason: "root is not finite",
        });
    }
    for (index, z) in r.iter().enumerate() {
        if z.im == 0.0 {
            continue;
        }
        let tol = 1e-9 * z.norm();
        let same = r.iter().filter(|w| (*w - z).norm() <= tol).count();
        let conj = r.iter().filter(|w| (*w - z.conj()).norm() <= tol).count();
        if same != conj {
            return Err(Error::InvalidData {
                what,
                index,
                reason: "complex root without its conjugate: the polynomial would not be real",
            });
        }
    }
    Ok(())
}

impl Zpk<Continuous> {
    /// `gain · ∏(s − zᵢ) / ∏(s − pⱼ)`.
    ///
    /// # Errors
    ///
    /// [`Error::InvalidData`] (`"zeros"` or `"poles"`) for a non-finite
    /// root or a complex one without its conjugate;
    /// [`Error::InvalidParameter`] for a non-finite gain.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::freq::Zpk;
    /// use ctrlab::nalgebra::Complex;
    ///
    /// assert!(Zpk::continuous(&[], &[Complex::new(-1.0, 1.0)], 1.0).is_err()); // no conjugate
    /// assert!(Zpk::continuous(&[], &[Complex::new(-1.0, 1.0), Complex::new(-1.0, -1.0)], 1.0).is_ok());
    /// ```
    pub fn continuous(
        zeros: &[Complex<f64>],
        poles: &[Complex<f64>],
        gain: f64,
    ) -> Result<Self, Error> {
        Self::with_domain(zeros, poles, gain, Continuous)
    }
}

impl Zpk<Discrete> {
    /// `gain · ∏(z − zᵢ) / ∏(z − pⱼ)` with sampling period `dt` (s).
    ///
    /// # Errors
    ///
    /// As [`Zpk::continuous`], and [`Error::InvalidParameter`] for a `dt`
    /// that is not finite and positive.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::freq::Zpk;
    /// use ctrlab::nalgebra::Complex;
    ///
    /// let g = Zpk::discrete(&[], &[Complex::new(0.5, 0.0)], 0.5, 0.1)?;
    /// assert_eq!(g.dc_gain()?, 1.0);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn discrete(
        zeros: &[Complex<f64>],
        poles: &[Complex<f64>],
        gain: f64,
        dt: f64,
    ) -> Result<Self, Error> {
        check_dt(dt)?;
        Self::with_domain(zeros, poles, gain, Discrete::new_unchecked(dt))
    }
}

impl<D: Domain> Zpk<D> {
    fn with_domain(
        zeros: &[Complex<f64>],
        poles: &[Complex<f64>],
        gain: f64,
        domain: D,
    ) -> Result<Self, Error> {
        check_roots("zeros", zeros)?;
        check_roots("poles", poles)?;
        if !gain.is_finite() {
            return Err(Error::InvalidParameter {
                name: "gain",
                value: gain,
                reason: "the gain must be finite",
            });
        }
        Ok(Self {
            zeros: zeros.to_vec(),
            poles: poles.to_vec(),
            gain,
            domain,
        })
    }

    /// The zeros.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::freq::Zpk;
    /// # use ctrlab::nalgebra::Complex;
    /// let z = [Complex::new(-3.0, 0.0)];
    /// assert_eq!(Zpk::continuous(&z, &[], 1.0)?.zeros(), &z);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn zeros(&self) -> &[Complex<f64>] {
        &self.zeros
    }

    /// The poles.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::freq::Zpk;
    /// # use ctrlab::nalgebra::Complex;
    /// let p = [Complex::new(-1.0, 0.0)];
    /// assert_eq!(Zpk::continuous(&[], &p, 1.0)?.poles(), &p);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn poles(&self) -> &[Complex<f64>] {
        &self.poles
    }

    /// The gain `k` (the ratio of the leading coefficients).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::freq::Zpk;
    /// assert_eq!(Zpk::continuous(&[], &[], 2.5)?.gain(), 2.5);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn gain(&self) -> f64 {
        self.gain
    }

    /// The time domain.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::{Continuous, freq::Zpk};
    /// assert_eq!(Zpk::continuous(&[], &[], 1.0)?.domain(), Continuous);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn domain(&self) -> D {
        self.domain
    }

    /// `G` at a complex point `s` (rad/s) or `z`.
    ///
    /// # Errors
    ///
    /// [`Error::InvalidParameter`] for a non-finite point,
    /// [`Error::Singular`] at a pole, [`Error::Overflow`] if the value is
    /// not finite.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::freq::Zpk;
    /// # use ctrlab::nalgebra::Complex;
    /// let g = Zpk::continuous(&[], &[Complex::new(-1.0, 0.0)], 1.0)?;
    /// assert_eq!(g.evaluate(Complex::new(1.0, 0.0))?, Complex::new(0.5, 0.0));
    /// assert!(g.evaluate(Complex::new(-1.0, 0.0)).is_err());
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn evaluate(&self, s: Complex<f64>) -> Result<Complex<f64>, Error> {
        check_point(s)?;
        let mut g = Complex::new(self.gain, 0.0);
        for z in &self.zeros {
            g *= s - z;
        }
        for p in &self.poles {
            let f = s - p;
            if f == Complex::new(0.0, 0.0) {
                return Err(Error::Singular {
                    operation: "zero-pole-gain evaluation (a pole)",
                });
            }
            g /= f;
        }
        if g.re.is_finite() && g.im.is_finite() {
            Ok(g)
        } else {
            Err(Error::Overflow {
                operation: "zero-pole-gain evaluation",
            })
        }
    }

    /// The DC gain: `G(0)` (continuous) or `G(1)` (discrete).
    ///
    /// # Errors
    ///
    /// [`Error::Singular`] for a pole at `s = 0` (`z = 1`).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::freq::Zpk;
    /// # use ctrlab::nalgebra::Complex;
    /// assert!(Zpk::continuous(&[], &[Complex::new(0.0, 0.0)], 1.0)?.dc_gain().is_err());
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[doc(alias = "dcgain")]
    pub fn dc_gain(&self) -> Result<f64, Error> {
        let point = dc_point(&self.domain);
        self.evaluate(point).map(|g| g.re)
    }

    /// The polynomial form: `num = k · ∏(s − zᵢ)`, `den = ∏(s − pⱼ)`
    /// (monic).
    ///
    /// # Errors
    ///
    /// [`Error::Overflow`] if a coefficient overflows.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::freq::Zpk;
    /// # use ctrlab::nalgebra::Complex;
    /// let g = Zpk::continuous(&[], &[Complex::new(-1.0, 2.0), Complex::new(-1.0, -2.0)], 5.0)?;
    /// assert_eq!(g.to_transfer_function()?.den(), &[1.0, 2.0, 5.0]);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[doc(alias = "zpk2tf")]
    pub fn to_transfer_function(&self) -> Result<TransferFunction<D>, Error> {
        let num: Vec<f64> = poly::from_roots(&self.zeros)
            .iter()
            .map(|c| c * self.gain)
            .collect();
        let den = poly::from_roots(&self.poles);
        if num.iter().chain(&den).any(|c| !c.is_finite()) {
            return Err(Error::Overflow {
                operation: "zpk2tf",
            });
        }
        TransferFunction::with_domain(&num, &den, self.domain)
    }

    /// The zero-pole-gain form of a transfer function: roots of its
    /// numerator and denominator, gain the ratio of their leading
    /// coefficients (`tf2zpk`).
    ///
    /// # Errors
    ///
    /// The errors of [`TransferFunction::poles`]; [`Error::Overflow`] if
    /// the gain is not a finite number (`1e300 / 1e-300`).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{Error, freq::{TransferFunction, Zpk}};
    ///
    /// let g = Zpk::from_transfer_function(&TransferFunction::continuous(&[2.0, 6.0], &[1.0, 3.0, 2.0])?)?;
    /// assert_eq!(g.gain(), 2.0);
    /// assert!((g.zeros()[0].re + 3.0).abs() < 1e-12);
    /// // A gain of 1e600 is refused.
    /// let big = TransferFunction::continuous(&[1e300], &[1e-300, 1.0])?;
    /// assert!(matches!(Zpk::from_transfer_function(&big), Err(Error::Overflow { .. })));
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[doc(alias = "tf2zpk")]
    pub fn from_transfer_function(tf: &TransferFunction<D>) -> Result<Self, Error> {
        let gain = tf.num()[0] / tf.den()[0];
        if !gain.is_finite() {
            return Err(Error::Overflow {
                operation: "tf2zpk (gain num₀ / den₀)",
            });
        }
        Ok(Self {
            zeros: tf.zeros()?,
            poles: tf.poles()?,
            gain,
            domain: tf.domain(),
        })
    }

    /// The zero-pole-gain form of a SISO state-space model (`ss2zpk`): the
    /// poles are the eigenvalues of `A` (those within rounding of zero put
    /// at zero, as in [`TransferFunction::from_state_space`]), the zeros its invariant zeros
    /// (nothing cancelled), the gain `D` or the first non-zero Markov
    /// parameter `C A^k B`.
    ///
    /// # Errors
    ///
    /// [`Error::DimensionMismatch`] unless the model has one input and one
    /// output; the errors of the eigenvalue computations.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{Cart, DynStateSpace, MassSpring, freq::Zpk};
    ///
    /// let plant = DynStateSpace::from(MassSpring::nominal().state_space(Cart::Two)?);
    /// let g = Zpk::from_state_space(&plant)?;
    /// // Force on cart 2 to its position: 4 poles, the 2 zeros of cart 1's
    /// // resonance (anti-resonance), relative degree 2.
    /// assert_eq!((g.poles().len(), g.zeros().len()), (4, 2));
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[doc(alias = "ss2zpk")]
    pub fn from_state_space(sys: &DynStateSpace<D>) -> Result<Self, Error> {
        if sys.inputs() != 1 || sys.outputs() != 1 {
            return Err(Error::DimensionMismatch {
                matrix: "D",
                expected_rows: 1,
                expected_cols: 1,
                found_rows: sys.outputs(),
                found_cols: sys.inputs(),
            });
        }
        let poles = snapped_poles(sys)?;
        let (zeros, gain) = siso_numerator(sys.a(), sys.b(), sys.c(), sys.d(), 0, 0)?;
        Ok(Self {
            zeros,
            poles,
            gain,
            domain: sys.domain(),
        })
    }
}

impl<const N: usize, D: Domain> TryFrom<&StateSpace<N, 1, 1, D>> for Zpk<D> {
    type Error = Error;

    /// [`Zpk::from_state_space`] of the fixed-size model.
    fn try_from(sys: &StateSpace<N, 1, 1, D>) -> Result<Self, Error> {
        Self::from_state_space(&DynStateSpace::from(sys))
    }
}
