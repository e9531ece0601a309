//! Zeros of the state-space model types, and their value at a point.

use nalgebra::{Complex, DMatrix};

use super::kernel::Evaluator;
use super::tf::check_point;
use super::zeros::invariant_zeros;
use crate::error::Error;
use crate::model::{Domain, DynStateSpace, StateSpace};

impl<D: Domain> DynStateSpace<D> {
    /// The invariant zeros: the finite `s` (rad/s; `z` for a discrete
    /// model) at which the Rosenbrock system matrix `[A − sI, B; C, D]`
    /// loses rank, sorted by real then imaginary part. For a minimal SISO
    /// model they are the transmission zeros, the roots of the transfer
    /// function's numerator; for a non-minimal one they include the
    /// uncontrollable and unobservable modes that cancel.
    ///
    /// Square models (inputs = outputs) only: full-rank `D` through
    /// `eig(A − B D⁻¹ C)`, `D = 0` with a full-rank first Markov parameter
    /// through the zero dynamics (exactly `n − r m` zeros for relative
    /// degree `r`), otherwise the finite generalized eigenvalues of the
    /// pencil by faer's QZ, where an eigenvalue counts as infinite beyond
    /// `‖[A B; C D]‖_F / √ε`.
    ///
    /// # Errors
    ///
    /// [`Error::InvalidMatrix`] (`"D"`) for a non-square model (not
    /// implemented: select a square subsystem); the errors of the
    /// eigenvalue computations.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{Cart, DynStateSpace, MassSpring};
    ///
    /// let plant = DynStateSpace::from(MassSpring::nominal().state_space(Cart::Two)?);
    /// let z = plant.zeros()?;
    /// // Cart 1 held by both springs: m1 s² + b1 s + k1 + k2, ≈ 39 rad/s.
    /// assert_eq!(z.len(), 2);
    /// assert!(z.iter().all(|z| z.re < 0.0 && (z.norm() - (2000.0f64 / 1.3).sqrt()).abs() < 1e-9));
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[doc(alias = "tzero")]
    #[doc(alias = "zero")]
    pub fn zeros(&self) -> Result<Vec<Complex<f64>>, Error> {
        invariant_zeros(self.a(), self.b(), self.c(), self.d())
    }
}

/// `G(s) = C (sI − A)⁻¹ B + D` at one point.
fn evaluate_at(
    a: &DMatrix<f64>,
    b: &DMatrix<f64>,
    c: &DMatrix<f64>,
    d: &DMatrix<f64>,
    s: Complex<f64>,
) -> Result<DMatrix<Complex<f64>>, Error> {
    check_point(s)?;
    let (p, m) = (c.nrows(), b.ncols());
    let mut out = vec![Complex::new(0.0, 0.0); p * m];
    Evaluator::new(a, b, c, d).eval(s, &mut out)?;
    Ok(DMatrix::from_row_slice(p, m, &out))
}

impl<D: Domain> DynStateSpace<D> {
    /// The transfer matrix at one complex point, `C (sI − A)⁻¹ B + D`
    /// (`s` in rad/s, or `z` for a discrete model), `outputs × inputs`.
    /// For many frequencies use
    /// [`FrequencyDomain::frequency_response`](super::FrequencyDomain::frequency_response),
    /// which reduces `A` once.
    ///
    /// # Errors
    ///
    /// [`Error::InvalidParameter`] for a non-finite point;
    /// [`Error::Singular`] at a pole; [`Error::Overflow`] if a value is not
    /// finite.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::DynStateSpace;
    /// use ctrlab::nalgebra::{Complex, dmatrix};
    ///
    /// let sys = DynStateSpace::continuous(dmatrix![-2.0], dmatrix![4.0], dmatrix![1.0], dmatrix![0.0])?;
    /// assert_eq!(sys.evaluate(Complex::new(2.0, 0.0))?[(0, 0)], Complex::new(1.0, 0.0));
    /// assert!(sys.evaluate(Complex::new(-2.0, 0.0)).is_err()); // the pole
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[doc(alias = "evalfr")]
    pub fn evaluate(&self, s: Complex<f64>) -> Result<DMatrix<Complex<f64>>, Error> {
        evaluate_at(self.a(), self.b(), self.c(), self.d(), s)
    }
}

impl<const N: usize, const M: usize, const P: usize, D: Domain> StateSpace<N, M, P, D> {
    /// The transfer matrix at one complex point, as
    /// [`DynStateSpace::evaluate`].
    ///
    /// # Errors
    ///
    /// As [`DynStateSpace::evaluate`].
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{Cart, MassSpring};
    /// use ctrlab::nalgebra::Complex;
    ///
    /// let plant = MassSpring::nominal().state_space(Cart::Two)?;
    /// assert!((plant.evaluate(Complex::new(0.0, 0.0))?[(0, 0)].re - 0.002).abs() < 1e-15);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[doc(alias = "evalfr")]
    pub fn evaluate(&self, s: Complex<f64>) -> Result<DMatrix<Complex<f64>>, Error> {
        let sys = DynStateSpace::from(self);
        evaluate_at(sys.a(), sys.b(), sys.c(), sys.d(), s)
    }

    /// The invariant zeros, as [`DynStateSpace::zeros`].
    ///
    /// # Errors
    ///
    /// As [`DynStateSpace::zeros`].
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::StateSpace;
    /// use ctrlab::nalgebra::matrix;
    ///
    /// // (s + 3) / ((s + 1)(s + 2)) with a feedthrough of 1: zeros of
    /// // s² + 4 s + 5 = (s + 2)² + 1.
    /// let sys = StateSpace::continuous(matrix![-3.0, -2.0; 1.0, 0.0], matrix![1.0; 0.0],
    ///                                  matrix![1.0, 3.0], matrix![1.0])?;
    /// let z = sys.zeros()?;
    /// assert!((z[0].re + 2.0).abs() < 1e-12 && (z[0].im.abs() - 1.0).abs() < 1e-12);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[doc(alias = "tzero")]
    #[doc(alias = "zero")]
    pub fn zeros(&self) -> Result<Vec<Complex<f64>>, Error> {
        let heap = |m: &[f64], r: usize, c: usize| DMatrix::from_column_slice(r, c, m);
        invariant_zeros(
            &heap(self.a().as_slice(), N, N),
            &heap(self.b().as_slice(), N, M),
            &heap(self.c().as_slice(), P, N),
            &heap(self.d().as_slice(), P, M),
        )
    }
}
