//! SISO transfer functions: [`TransferFunction`] (numerator and
//! denominator polynomials), with `ss2tf` and `tf2ss`.

use nalgebra::{Complex, DMatrix};

use super::poly;
use super::zeros::siso_numerator;
use crate::analysis::{eigenvalues_dyn, rank};
use crate::error::{Error, check_dt};
use crate::kernels::reduce::pow2_floor;
use crate::model::{Continuous, Discrete, Domain, DynStateSpace, StateSpace, period_of};

/// A finite evaluation point, or [`Error::InvalidParameter`] named `"s"`
/// with the offending part.
pub(crate) fn check_point(s: Complex<f64>) -> Result<(), Error> {
    if s.re.is_finite() && s.im.is_finite() {
        Ok(())
    } else {
        Err(Error::InvalidParameter {
            name: "s",
            value: if s.re.is_finite() { s.im } else { s.re },
            reason: "the point must be finite",
        })
    }
}

/// Where a model of `domain` is evaluated for its DC gain: `s = 0`
/// (continuous) or `z = 1` (discrete).
pub(crate) fn dc_point<D: Domain>(domain: &D) -> Complex<f64> {
    match period_of(domain) {
        None => Complex::new(0.0, 0.0),
        Some(_) => Complex::new(1.0, 0.0),
    }
}

/// A polynomial argument checked: non-empty, finite, leading exact zeros
/// removed.
pub(crate) fn check_poly(what: &'static str, p: &[f64]) -> Result<Vec<f64>, Error> {
    if p.is_empty() {
        return Err(Error::InvalidData {
            what,
            index: 0,
            reason: "empty polynomial: give at least one coefficient",
        });
    }
    if let Some(index) = p.iter().position(|c| !c.is_finite()) {
        return Err(Error::InvalidData {
            what,
            index,
            reason: "polynomial coefficient is not finite",
        });
    }
    Ok(poly::trim(p).to_vec())
}

/// A SISO transfer function `G = num / den` in time domain `D`, the
/// polynomials in descending powers of `s` (continuous) or `z` (discrete,
/// period `dt` s), as python-control's `tf` and MATLAB's `tf` take them:
/// `[1.0, 3.0]` is `s + 3`.
///
/// Leading exact zeros are dropped. The transfer function may be improper
/// (it can still be evaluated); only [`to_state_space`](Self::to_state_space)
/// needs it proper. Nothing is cancelled: `(s + 1) / (s + 1)` keeps both
/// factors.
///
/// # Examples
///
/// ```
/// use ctrlab::freq::TransferFunction;
/// use ctrlab::nalgebra::Complex;
///
/// // 10 / (s² + 2 s + 10): ωn = √10 rad/s, ζ ≈ 0.32, DC gain 1.
/// let g = TransferFunction::continuous(&[10.0], &[1.0, 2.0, 10.0])?;
/// assert_eq!(g.dc_gain()?, 1.0);
/// let at = g.evaluate(Complex::new(0.0, 10f64.sqrt()))?; // s = jωn
/// assert!((at - Complex::new(0.0, -10f64.sqrt() / 2.0)).norm() < 1e-12);
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[doc(alias = "tf")]
#[derive(Debug, Clone, PartialEq)]
pub struct TransferFunction<D: Domain = Continuous> {
    num: Vec<f64>,
    den: Vec<f64>,
    domain: D,
}

impl TransferFunction<Continuous> {
    /// `num(s) / den(s)`, coefficients in descending powers of `s`.
    ///
    /// # Errors
    ///
    /// [`Error::InvalidData`] (`what` = `"num"` or `"den"`) for an empty
    /// polynomial, a non-finite coefficient (with its index), or a zero
    /// denominator.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{Error, freq::TransferFunction};
    ///
    /// let g = TransferFunction::continuous(&[0.0, 2.0], &[1.0, 1.0])?;
    /// assert_eq!(g.num(), &[2.0]); // leading zero dropped
    /// assert!(matches!(TransferFunction::continuous(&[1.0], &[0.0, 0.0]),
    ///                  Err(Error::InvalidData { what: "den", .. })));
    /// assert!(TransferFunction::continuous(&[], &[1.0]).is_err());
    /// assert!(TransferFunction::continuous(&[f64::NAN], &[1.0]).is_err());
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn continuous(num: &[f64], den: &[f64]) -> Result<Self, Error> {
        Self::with_domain(num, den, Continuous)
    }
}

impl TransferFunction<Discrete> {
    /// `num(z) / den(z)` with sampling period `dt` (s), coefficients in
    /// descending powers of `z`.
    ///
    /// # Errors
    ///
    /// As [`TransferFunction::continuous`], and [`Error::InvalidParameter`]
    /// for a `dt` that is not finite and positive.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::freq::TransferFunction;
    ///
    /// // A discrete integrator-like lag, 0.5 / (z − 0.5), period 0.1 s.
    /// let g = TransferFunction::discrete(&[0.5], &[1.0, -0.5], 0.1)?;
    /// assert_eq!(g.dt(), 0.1);
    /// assert_eq!(g.dc_gain()?, 1.0);
    /// assert!(TransferFunction::discrete(&[1.0], &[1.0], -1.0).is_err());
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn discrete(num: &[f64], den: &[f64], dt: f64) -> Result<Self, Error> {
        check_dt(dt)?;
        Self::with_domain(num, den, Discrete::new_unchecked(dt))
    }

    /// The sampling period in seconds.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::freq::TransferFunction;
    /// assert_eq!(TransferFunction::discrete(&[1.0], &[1.0, 0.0], 0.002)?.dt(), 0.002);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn dt(&self) -> f64 {
        self.domain.dt()
    }
}

impl<D: Domain> TransferFunction<D> {
    pub(crate) fn with_domain(num: &[f64], den: &[f64], domain: D) -> Result<Self, Error> {
        let num = check_poly("num", num)?;
        let den = check_poly("den", den)?;
        if den == [0.0] {
            return Err(Error::InvalidData {
                what: "den",
                index: 0,
                reason: "the denominator is the zero polynomial",
            });
        }
        Ok(Self { num, den, domain })
    }

    /// The numerator's coefficients, descending powers.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::freq::TransferFunction;
    /// assert_eq!(TransferFunction::continuous(&[1.0, 3.0], &[1.0, 2.0, 1.0])?.num(), &[1.0, 3.0]);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn num(&self) -> &[f64] {
        &self.num
    }

    /// The denominator's coefficients, descending powers.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::freq::TransferFunction;
    /// assert_eq!(TransferFunction::continuous(&[1.0], &[2.0, 1.0])?.den(), &[2.0, 1.0]);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn den(&self) -> &[f64] {
        &self.den
    }

    /// The time domain: [`Continuous`], or [`Discrete`] with its period.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::{Continuous, freq::TransferFunction};
    /// assert_eq!(TransferFunction::continuous(&[1.0], &[1.0, 1.0])?.domain(), Continuous);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn domain(&self) -> D {
        self.domain
    }

    /// Whether `deg num ≤ deg den` (a state-space realisation exists).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::freq::TransferFunction;
    /// assert!(TransferFunction::continuous(&[1.0, 0.0], &[1.0, 1.0])?.is_proper());
    /// assert!(!TransferFunction::continuous(&[1.0, 0.0, 0.0], &[1.0, 1.0])?.is_proper());
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn is_proper(&self) -> bool {
        self.num.len() <= self.den.len()
    }

    /// `G` at a complex point `s` (rad/s) or `z` (dimensionless).
    ///
    /// # Errors
    ///
    /// [`Error::InvalidParameter`] for a non-finite point;
    /// [`Error::Singular`] if the denominator vanishes there (a pole);
    /// [`Error::Overflow`] if the value is not finite.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{Error, freq::TransferFunction};
    /// use ctrlab::nalgebra::Complex;
    ///
    /// let g = TransferFunction::continuous(&[1.0], &[1.0, 0.0])?; // 1/s
    /// assert_eq!(g.evaluate(Complex::new(0.0, 2.0))?, Complex::new(0.0, -0.5));
    /// assert!(matches!(g.evaluate(Complex::new(0.0, 0.0)), Err(Error::Singular { .. })));
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[doc(alias = "evalfr")]
    pub fn evaluate(&self, s: Complex<f64>) -> Result<Complex<f64>, Error> {
        check_point(s)?;
        let g = poly::eval_ratio(&self.num, &self.den, s).ok_or(Error::Singular {
            operation: "transfer function evaluation (a pole)",
        })?;
        if g.re.is_finite() && g.im.is_finite() {
            Ok(g)
        } else {
            Err(Error::Overflow {
                operation: "transfer function evaluation",
            })
        }
    }

    /// The poles: roots of the denominator, sorted by real then imaginary
    /// part (rad/s for continuous models, `z` for discrete ones).
    ///
    /// # Errors
    ///
    /// [`Error::NoConvergence`] or [`Error::Overflow`] from the eigenvalues
    /// of the companion matrix.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::freq::TransferFunction;
    /// let p = TransferFunction::continuous(&[1.0], &[1.0, 3.0, 2.0])?.poles()?;
    /// assert!((p[0].re + 2.0).abs() < 1e-12 && (p[1].re + 1.0).abs() < 1e-12);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[doc(alias = "pole")]
    pub fn poles(&self) -> Result<Vec<Complex<f64>>, Error> {
        poly::roots(&self.den)
    }

    /// The zeros: roots of the numerator (the transmission zeros of a SISO
    /// model), sorted as [`poles`](Self::poles). None for `G ≡ 0`.
    ///
    /// # Errors
    ///
    /// As [`poles`](Self::poles).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::freq::TransferFunction;
    /// let z = TransferFunction::continuous(&[2.0, 6.0], &[1.0, 3.0, 2.0])?.zeros()?;
    /// assert_eq!(z.len(), 1);
    /// assert!((z[0].re + 3.0).abs() < 1e-12);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[doc(alias = "zero")]
    pub fn zeros(&self) -> Result<Vec<Complex<f64>>, Error> {
        poly::roots(&self.num)
    }

    /// The DC gain: `G(0)` for continuous models, `G(1)` for discrete ones.
    ///
    /// # Errors
    ///
    /// [`Error::Singular`] if there is a pole at `s = 0` (`z = 1`).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::freq::TransferFunction;
    /// assert_eq!(TransferFunction::continuous(&[4.0], &[1.0, 2.0])?.dc_gain()?, 2.0);
    /// assert!(TransferFunction::continuous(&[1.0], &[1.0, 0.0])?.dc_gain().is_err());
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[doc(alias = "dcgain")]
    pub fn dc_gain(&self) -> Result<f64, Error> {
        let point = dc_point(&self.domain);
        self.evaluate(point).map(|g| g.re).map_err(|e| match e {
            Error::Singular { .. } => Error::Singular {
                operation: "DC gain (pole at s = 0 or z = 1)",
            },
            e => e,
        })
    }

    /// A state-space realisation in SciPy's `tf2ss` form (controllable
    /// canonical form): with `den` made monic, `sⁿ + a₁ sⁿ⁻¹ + … + aₙ`,
    /// `A` has first row `[−a₁ … −aₙ]` and ones on its subdiagonal,
    /// `B = e₁`, `D = b₀` (the numerator's `sⁿ` coefficient) and
    /// `C = [b₁ − b₀ a₁, …, bₙ − b₀ aₙ]`.
    ///
    /// A static gain (`n = 0`) is the exception: it has no state here, as
    /// in python-control's `tf2ss` (0.10.2: `tf2ss(tf([2], [1]))` has
    /// `States (0)` and `D = [[2]]`), where SciPy's `tf2ss([2], [1])`
    /// returns one state, `A = B = C = [[0]]`, `D = [[2]]` (a pole at 0
    /// that is neither controllable nor observable). The transfer function
    /// is the same; only the state count differs.
    ///
    /// # Errors
    ///
    /// [`Error::InvalidData`] (`"num"`) for an improper transfer function;
    /// [`Error::Overflow`] if normalising overflows.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::freq::TransferFunction;
    /// use ctrlab::nalgebra::dmatrix;
    ///
    /// let g = TransferFunction::continuous(&[1.0, 3.0], &[1.0, 3.0, 2.0])?;
    /// let sys = g.to_state_space()?;
    /// assert_eq!(sys.a(), &dmatrix![-3.0, -2.0; 1.0, 0.0]);
    /// assert_eq!(sys.c(), &dmatrix![1.0, 3.0]);
    /// assert!(TransferFunction::continuous(&[1.0, 0.0], &[1.0])?.to_state_space().is_err());
    ///
    /// // A static gain: no state (python-control), where SciPy adds one.
    /// let k = TransferFunction::continuous(&[2.0], &[1.0])?.to_state_space()?;
    /// assert_eq!((k.states(), k.d()[(0, 0)]), (0, 2.0));
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[doc(alias = "tf2ss")]
    pub fn to_state_space(&self) -> Result<DynStateSpace<D>, Error> {
        if !self.is_proper() {
            return Err(Error::InvalidData {
                what: "num",
                index: 0,
                reason: "improper transfer function (numerator degree above the \
                         denominator's): it has no state-space realisation",
            });
        }
        let n = self.den.len() - 1;
        let lead = self.den[0];
        let den: Vec<f64> = self.den.iter().map(|c| c / lead).collect();
        let mut num = vec![0.0; n + 1];
        let off = n + 1 - self.num.len();
        for (i, c) in self.num.iter().enumerate() {
            num[off + i] = c / lead;
        }
        let mut a = DMatrix::zeros(n, n);
        let mut b = DMatrix::zeros(n, 1);
        let mut c = DMatrix::zeros(1, n);
        for k in 0..n {
            a[(0, k)] = -den[k + 1];
            if k + 1 < n {
                a[(k + 1, k)] = 1.0;
            }
            c[(0, k)] = num[k + 1] - num[0] * den[k + 1];
        }
        if n > 0 {
            b[(0, 0)] = 1.0;
        }
        let d = DMatrix::from_element(1, 1, num[0]);
        DynStateSpace::from_computed(a, b, c, d, self.domain, "tf2ss")
    }

    /// The transfer function of a SISO state-space model, `ss2tf`: the
    /// denominator is the characteristic polynomial `det(sI − A)` (monic,
    /// degree `n`, nothing cancelled, as SciPy's `ss2tf`; eigenvalues
    /// within `n ε ‖A‖_F` of zero, rounding, are put at zero, at most as
    /// many as `A` is rank-deficient once its rows and columns are
    /// equilibrated, so `diag(−1e8, −1e-9)` keeps its pole at −1e-9,
    /// where SciPy 1.17.1's `ss2tf` gives den `[1, 1e8, 0.1]` too),
    /// the numerator
    /// `gain · ∏(s − zᵢ)` with the model's invariant zeros and its leading
    /// coefficient (`D`, or the first non-zero Markov parameter
    /// `C A^k B`).
    ///
    /// # Errors
    ///
    /// [`Error::DimensionMismatch`] (`"D"`) unless the model has one input
    /// and one output; [`Error::Overflow`] if a coefficient is not a finite
    /// number (`A = −1`, `B = C = 1e200`: `1e400 / (s + 1)`); the errors of
    /// the eigenvalue computations.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{DynStateSpace, freq::TransferFunction};
    /// use ctrlab::nalgebra::dmatrix;
    ///
    /// let sys = DynStateSpace::continuous(dmatrix![-3.0, -2.0; 1.0, 0.0], dmatrix![1.0; 0.0],
    ///                                     dmatrix![1.0, 3.0], dmatrix![0.0])?;
    /// let g = TransferFunction::from_state_space(&sys)?;
    /// assert_eq!(g.den(), &[1.0, 3.0, 2.0]);
    /// assert!((g.num()[0] - 1.0).abs() < 1e-12 && (g.num()[1] - 3.0).abs() < 1e-12);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[doc(alias = "ss2tf")]
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
        entry(sys, &characteristic(sys)?, 0, 0)
    }
}

/// `det(sI − A)` from the eigenvalues of `A`, those within rounding of
/// zero set to exactly zero ([`snapped_poles`]), so that an integrator's
/// constant term is exactly zero and its DC gain an error, not 1e18.
pub(crate) fn characteristic<D: Domain>(sys: &DynStateSpace<D>) -> Result<Vec<f64>, Error> {
    Ok(poly::from_roots(&snapped_poles(sys)?))
}

/// The eigenvalues of `A`, those within rounding of zero set to zero: at
/// most as many as `A` is rank-deficient after its rows and columns are
/// equilibrated by powers of two (exactly), the smallest ones, each only if
/// `|λ| ≤ n ε ‖A‖_F` (below the eigenvalue solver's backward error; the
/// norm formed without overflow).
///
/// The rank test keeps a small eigenvalue of a well-scaled block:
/// `diag(−1e8, −1e-9)` has `n ε ‖A‖_F = 4e-8`, and `−1e-9` was put at
/// zero (a pole at `s = 0`, where the DC gain is 1e9); equilibrated it is
/// the identity, of full rank. And `‖A‖_F` of an entry of 1e160 was
/// infinite, which put every pole at zero.
pub(crate) fn snapped_poles<D: Domain>(sys: &DynStateSpace<D>) -> Result<Vec<Complex<f64>>, Error> {
    let a = sys.a();
    let mut poles = eigenvalues_dyn(a)?;
    let n = a.nrows();
    if n == 0 {
        return Ok(poles);
    }
    let deficiency = n - rank(&equilibrated(a), None)?;
    let tol = n as f64 * f64::EPSILON * safe_norm(a);
    let mut by_size: Vec<usize> = (0..poles.len()).collect();
    by_size.sort_by(|&x, &y| poles[x].norm().total_cmp(&poles[y].norm()));
    for &i in by_size.iter().take(deficiency) {
        if poles[i].norm() <= tol {
            poles[i] = Complex::new(0.0, 0.0);
        }
    }
    Ok(poles)
}

/// `‖M‖_F` without overflow or underflow: `max |mᵢⱼ| · ‖M / max‖_F`.
pub(crate) fn safe_norm(m: &DMatrix<f64>) -> f64 {
    let big = m.amax();
    if big == 0.0 || !big.is_finite() {
        return big;
    }
    big * (m / big).norm()
}

/// `A` with every non-zero row, then every non-zero column, divided by the
/// power of two at or below its largest entry (exact).
fn equilibrated(a: &DMatrix<f64>) -> DMatrix<f64> {
    let mut m = a.clone();
    for i in 0..m.nrows() {
        let f = pow2_floor(m.row(i).amax());
        m.row_mut(i).unscale_mut(f);
    }
    for j in 0..m.ncols() {
        let f = pow2_floor(m.column(j).amax());
        m.column_mut(j).unscale_mut(f);
    }
    m
}

/// The `(output, input)` entry of a model's transfer matrix over `den`.
pub(crate) fn entry<D: Domain>(
    sys: &DynStateSpace<D>,
    den: &[f64],
    output: usize,
    input: usize,
) -> Result<TransferFunction<D>, Error> {
    let (zeros, gain) = siso_numerator(sys.a(), sys.b(), sys.c(), sys.d(), output, input)?;
    let num: Vec<f64> = poly::from_roots(&zeros).iter().map(|c| c * gain).collect();
    if num.iter().chain(den).any(|c| !c.is_finite()) {
        return Err(Error::Overflow { operation: "ss2tf" });
    }
    TransferFunction::with_domain(&num, den, sys.domain())
}

impl<D: Domain> TryFrom<&DynStateSpace<D>> for TransferFunction<D> {
    type Error = Error;

    /// [`TransferFunction::from_state_space`].
    fn try_from(sys: &DynStateSpace<D>) -> Result<Self, Error> {
        Self::from_state_space(sys)
    }
}

impl<const N: usize, D: Domain> TryFrom<&StateSpace<N, 1, 1, D>> for TransferFunction<D> {
    type Error = Error;

    /// [`TransferFunction::from_state_space`] of the fixed-size model.
    fn try_from(sys: &StateSpace<N, 1, 1, D>) -> Result<Self, Error> {
        Self::from_state_space(&DynStateSpace::from(sys))
    }
}
