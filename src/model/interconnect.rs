//! Block-diagram algebra on run-time-sized models: [`series`](DynStateSpace::series),
//! [`parallel`](DynStateSpace::parallel), [`feedback`](DynStateSpace::feedback),
//! [`append`](DynStateSpace::append), and selecting inputs and outputs.
//!
//! The results have as many states as the parts together, which the
//! fixed-size [`StateSpace`](crate::StateSpace) cannot express in stable Rust
//! (`N1 + N2` in a const generic); convert fixed-size models with
//! `DynStateSpace::from` first. State order and formulas follow
//! python-control: the first system's states come first.

use nalgebra::DMatrix;

use crate::error::{Error, check_len};
use crate::kernels::reduce::pow2_floor;
use crate::model::{Domain, DynStateSpace, period_of};

/// The sign of the feedback path in [`DynStateSpace::feedback`]:
/// `u₁ = u − y₂` (negative, the usual case) or `u₁ = u + y₂`.
///
/// # Examples
///
/// A lag `1/(s+1)` under unit feedback: negative feedback moves its pole
/// from −1 to −2 rad/s, positive feedback to 0 (an integrator).
///
/// ```
/// use ctrlab::{DynStateSpace, model::Sign};
/// use ctrlab::nalgebra::{DMatrix, dmatrix};
///
/// let lag = DynStateSpace::continuous(dmatrix![-1.0], dmatrix![1.0], dmatrix![1.0], dmatrix![0.0])?;
/// let unity = DynStateSpace::continuous(DMatrix::zeros(0, 0), DMatrix::zeros(0, 1),
///                                       DMatrix::zeros(1, 0), dmatrix![1.0])?;
/// assert_eq!(lag.feedback(&unity, Sign::Negative)?.a(), &dmatrix![-2.0]);
/// assert_eq!(lag.feedback(&unity, Sign::Positive)?.a(), &dmatrix![0.0]);
/// assert_eq!(Sign::default(), Sign::Negative);
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Sign {
    /// `u₁ = u − y₂`.
    #[default]
    Negative,
    /// `u₁ = u + y₂`.
    Positive,
}

impl Sign {
    fn value(self) -> f64 {
        match self {
            Sign::Negative => -1.0,
            Sign::Positive => 1.0,
        }
    }
}

/// `[[a, 0], [0, b]]`.
fn block_diag(a: &DMatrix<f64>, b: &DMatrix<f64>) -> DMatrix<f64> {
    let mut out = DMatrix::zeros(a.nrows() + b.nrows(), a.ncols() + b.ncols());
    out.view_mut((0, 0), a.shape()).copy_from(a);
    out.view_mut(a.shape(), b.shape()).copy_from(b);
    out
}

/// `[[a, b], [c, d]]` for conforming blocks.
fn blocks(a: DMatrix<f64>, b: DMatrix<f64>, c: DMatrix<f64>, d: DMatrix<f64>) -> DMatrix<f64> {
    let (r0, c0) = a.shape();
    let mut out = DMatrix::zeros(r0 + c.nrows(), c0 + b.ncols());
    out.view_mut((0, 0), a.shape()).copy_from(&a);
    out.view_mut((0, c0), b.shape()).copy_from(&b);
    out.view_mut((r0, 0), c.shape()).copy_from(&c);
    out.view_mut((r0, c0), d.shape()).copy_from(&d);
    out
}

impl<D: Domain> DynStateSpace<D> {
    /// Checks that two models live in the same time domain (the same period).
    fn same_domain(&self, other: &Self) -> Result<(), Error> {
        match (period_of(&self.domain()), period_of(&other.domain())) {
            (Some(a), Some(b)) if a != b => Err(Error::InvalidParameter {
                name: "dt",
                value: b,
                reason: "discrete models connected together must share their sampling period",
            }),
            _ => Ok(()),
        }
    }

    /// A size check between the two sides of a connection.
    fn conforming(what: &'static str, expected: usize, found: usize) -> Result<(), Error> {
        check_len(what, expected, found)
    }

    /// `self` followed by `next`: `next`'s input is `self`'s output, the
    /// result maps `self`'s input to `next`'s output (`next · self`, MATLAB's
    /// and python-control's `series(self, next)`). States `[x_self; x_next]`:
    ///
    /// ```text
    /// A = [A₁ 0; B₂C₁ A₂],  B = [B₁; B₂D₁],  C = [D₂C₁ C₂],  D = D₂D₁
    /// ```
    ///
    /// # Errors
    ///
    /// [`Error::LengthMismatch`] (`"inputs of the second system"`) if `next`
    /// does not have one input per output of `self`;
    /// [`Error::InvalidParameter`] (`"dt"`) for discrete models with different
    /// periods; [`Error::Overflow`] if a product overflows.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::DynStateSpace;
    /// use ctrlab::nalgebra::dmatrix;
    ///
    /// // 1/(s+1) then 2/(s+3): DC gain 1 · 2/3, poles −1 and −3.
    /// let g1 = DynStateSpace::continuous(dmatrix![-1.0], dmatrix![1.0], dmatrix![1.0], dmatrix![0.0])?;
    /// let g2 = DynStateSpace::continuous(dmatrix![-3.0], dmatrix![1.0], dmatrix![2.0], dmatrix![0.0])?;
    /// let g = g1.series(&g2)?;
    /// assert_eq!(g.states(), 2);
    /// let p = g.poles()?;
    /// assert!((p[0].re + 3.0).abs() < 1e-12 && (p[1].re + 1.0).abs() < 1e-12);
    /// // y = C (−A)⁻¹ B at s = 0.
    /// let dc = (g.c() * g.a().clone().try_inverse().unwrap() * g.b())[(0, 0)];
    /// assert!((dc + 2.0 / 3.0).abs() < 1e-12);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn series(&self, next: &Self) -> Result<Self, Error> {
        self.same_domain(next)?;
        Self::conforming("inputs of the second system", self.outputs(), next.inputs())?;
        let (n1, n2) = (self.states(), next.states());
        let a = blocks(
            self.a().clone(),
            DMatrix::zeros(n1, n2),
            next.b() * self.c(),
            next.a().clone(),
        );
        let b = blocks(
            self.b().clone(),
            DMatrix::zeros(n1, 0),
            next.b() * self.d(),
            DMatrix::zeros(n2, 0),
        );
        let c = blocks(
            next.d() * self.c(),
            next.c().clone(),
            DMatrix::zeros(0, n1),
            DMatrix::zeros(0, n2),
        );
        let d = next.d() * self.d();
        Self::from_computed(a, b, c, d, self.domain(), "series connection")
    }

    /// `self` and `other` side by side on one input, outputs added
    /// (python-control's `parallel`). States `[x_self; x_other]`:
    ///
    /// ```text
    /// A = [A₁ 0; 0 A₂],  B = [B₁; B₂],  C = [C₁ C₂],  D = D₁ + D₂
    /// ```
    ///
    /// # Errors
    ///
    /// [`Error::LengthMismatch`] if the two do not have the same numbers of
    /// inputs and of outputs; [`Error::InvalidParameter`] (`"dt"`) for
    /// discrete models with different periods; [`Error::Overflow`] if a sum
    /// overflows.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::DynStateSpace;
    /// use ctrlab::nalgebra::dmatrix;
    ///
    /// // 1/(s+1) + 2 (a pure gain, no states).
    /// let g1 = DynStateSpace::continuous(dmatrix![-1.0], dmatrix![1.0], dmatrix![1.0], dmatrix![0.0])?;
    /// let k = DynStateSpace::continuous(
    ///     ctrlab::nalgebra::DMatrix::zeros(0, 0), ctrlab::nalgebra::DMatrix::zeros(0, 1),
    ///     ctrlab::nalgebra::DMatrix::zeros(1, 0), dmatrix![2.0])?;
    /// let g = g1.parallel(&k)?;
    /// assert_eq!((g.states(), g.d()[(0, 0)]), (1, 2.0));
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn parallel(&self, other: &Self) -> Result<Self, Error> {
        self.same_domain(other)?;
        Self::conforming("inputs of the second system", self.inputs(), other.inputs())?;
        Self::conforming(
            "outputs of the second system",
            self.outputs(),
            other.outputs(),
        )?;
        let a = block_diag(self.a(), other.a());
        let mut b = DMatrix::zeros(a.nrows(), self.inputs());
        b.rows_mut(0, self.states()).copy_from(self.b());
        b.rows_mut(self.states(), other.states())
            .copy_from(other.b());
        let mut c = DMatrix::zeros(self.outputs(), a.ncols());
        c.columns_mut(0, self.states()).copy_from(self.c());
        c.columns_mut(self.states(), other.states())
            .copy_from(other.c());
        let d = self.d() + other.d();
        Self::from_computed(a, b, c, d, self.domain(), "parallel connection")
    }

    /// The closed loop of `self` (forward path) with `other` in the feedback
    /// path: `u₁ = u ± y₂`, `u₂ = y₁`, output `y₁` (python-control's
    /// `feedback(self, other, sign)`; [`Sign::Negative`] is the usual
    /// `u₁ = u − y₂`). States `[x_self; x_other]`. With feedthrough on both
    /// sides the loop is algebraic and is solved through
    /// `E = (I − s D₂ D₁)⁻¹`:
    ///
    /// ```text
    /// A = [A₁ + s B₁ E D₂ C₁,   s B₁ E C₂;
    ///      B₂ (C₁ + s D₁ E D₂ C₁),  A₂ + s B₂ D₁ E C₂]
    /// B = [B₁ E; B₂ D₁ E],  C = [C₁ + s D₁ E D₂ C₁,  s D₁ E C₂],  D = D₁ E
    /// ```
    ///
    /// # Errors
    ///
    /// [`Error::LengthMismatch`] unless `other` has one input per output of
    /// `self` and one output per input of `self`; [`Error::Singular`] if the
    /// algebraic loop `I − s D₂ D₁` is singular or nearly so (the
    /// interconnection is ill-posed); [`Error::InvalidParameter`] (`"dt"`)
    /// for discrete models with different periods; [`Error::Overflow`].
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{DynStateSpace, model::Sign};
    /// use ctrlab::nalgebra::dmatrix;
    ///
    /// // 1/s under unity negative feedback: 1/(s+1).
    /// let plant = DynStateSpace::continuous(dmatrix![0.0], dmatrix![1.0], dmatrix![1.0], dmatrix![0.0])?;
    /// let unity = DynStateSpace::continuous(
    ///     ctrlab::nalgebra::DMatrix::zeros(0, 0), ctrlab::nalgebra::DMatrix::zeros(0, 1),
    ///     ctrlab::nalgebra::DMatrix::zeros(1, 0), dmatrix![1.0])?;
    /// let cl = plant.feedback(&unity, Sign::Negative)?;
    /// assert_eq!(cl.a(), &dmatrix![-1.0]);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn feedback(&self, other: &Self, sign: Sign) -> Result<Self, Error> {
        self.same_domain(other)?;
        Self::conforming(
            "inputs of the feedback system",
            self.outputs(),
            other.inputs(),
        )?;
        Self::conforming(
            "outputs of the feedback system",
            self.inputs(),
            other.outputs(),
        )?;
        let s = sign.value();
        let m1 = self.inputs();
        let f = DMatrix::identity(m1, m1) - s * (other.d() * self.d());
        let e = loop_inverse(&f)?;
        let (a1, b1, c1, d1) = (self.a(), self.b(), self.c(), self.d());
        let (a2, b2, c2, d2) = (other.a(), other.b(), other.c(), other.d());
        let b1e = b1 * &e;
        let d1e = d1 * &e;
        // y₁ = C₁ x₁ + D₁ u₁ with u₁ solved from the loop.
        let y1_x1 = c1 + s * (&d1e * d2 * c1);
        let y1_x2 = s * (&d1e * c2);
        let a = blocks(
            a1 + s * (&b1e * d2 * c1),
            s * (&b1e * c2),
            b2 * &y1_x1,
            a2 + b2 * &y1_x2,
        );
        let mut b = DMatrix::zeros(a.nrows(), m1);
        b.rows_mut(0, self.states()).copy_from(&b1e);
        b.rows_mut(self.states(), other.states())
            .copy_from(&(b2 * &d1e));
        let mut c = DMatrix::zeros(self.outputs(), a.ncols());
        c.columns_mut(0, self.states()).copy_from(&y1_x1);
        c.columns_mut(self.states(), other.states())
            .copy_from(&y1_x2);
        Self::from_computed(a, b, c, d1e, self.domain(), "feedback connection")
    }

    /// `self` and `other` side by side with separate inputs and outputs:
    /// block-diagonal `A`, `B`, `C`, `D` (MATLAB's `append`). Inputs
    /// `[u_self; u_other]`, outputs `[y_self; y_other]`.
    ///
    /// # Errors
    ///
    /// [`Error::InvalidParameter`] (`"dt"`) for discrete models with different
    /// periods.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::DynStateSpace;
    /// use ctrlab::nalgebra::dmatrix;
    ///
    /// let g1 = DynStateSpace::continuous(dmatrix![-1.0], dmatrix![1.0], dmatrix![1.0], dmatrix![0.0])?;
    /// let g = g1.append(&g1)?;
    /// assert_eq!((g.states(), g.inputs(), g.outputs()), (2, 2, 2));
    /// assert_eq!(g.b(), &dmatrix![1.0, 0.0; 0.0, 1.0]);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn append(&self, other: &Self) -> Result<Self, Error> {
        self.same_domain(other)?;
        Ok(Self::from_parts_unchecked(
            block_diag(self.a(), other.a()),
            block_diag(self.b(), other.b()),
            block_diag(self.c(), other.c()),
            block_diag(self.d(), other.d()),
            self.domain(),
        ))
    }

    /// The model with input `j` alone (`B`'s and `D`'s column `j`), e.g. to
    /// take the step response of one input of a multi-input model:
    /// [`StateSpace::select_input`](crate::StateSpace::select_input) for a
    /// model sized at run time.
    ///
    /// # Errors
    ///
    /// [`Error::OutOfRange`] (`"input"`) unless `j` is below the number of
    /// inputs.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::DynStateSpace;
    /// use ctrlab::nalgebra::dmatrix;
    ///
    /// let sys = DynStateSpace::continuous(dmatrix![-1.0], dmatrix![1.0, 2.0], dmatrix![1.0], dmatrix![0.0, 0.5])?;
    /// let second = sys.select_input(1)?;
    /// assert_eq!((second.b(), second.d()), (&dmatrix![2.0], &dmatrix![0.5]));
    /// assert!(sys.select_input(2).is_err());
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn select_input(&self, j: usize) -> Result<Self, Error> {
        self.select_inputs(&[j])
    }

    /// The model seen from the listed inputs only, in the order given
    /// (repeats allowed): the columns of `B` and `D`.
    ///
    /// # Errors
    ///
    /// [`Error::OutOfRange`] (`"input"`) for an index ≥ the number of inputs.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::DynStateSpace;
    /// use ctrlab::nalgebra::dmatrix;
    ///
    /// let sys = DynStateSpace::continuous(dmatrix![-1.0], dmatrix![1.0, 2.0, 3.0],
    ///                                     dmatrix![1.0], dmatrix![0.0, 0.0, 0.5])?;
    /// let two = sys.select_inputs(&[2, 0])?;
    /// assert_eq!(two.b(), &dmatrix![3.0, 1.0]);
    /// assert_eq!(two.d(), &dmatrix![0.5, 0.0]);
    /// assert!(sys.select_inputs(&[3]).is_err());
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn select_inputs(&self, inputs: &[usize]) -> Result<Self, Error> {
        check_indices("input", inputs, self.inputs())?;
        Ok(Self::from_parts_unchecked(
            self.a().clone(),
            self.b().select_columns(inputs),
            self.c().clone(),
            self.d().select_columns(inputs),
            self.domain(),
        ))
    }

    /// The model with only the listed outputs, in the order given (repeats
    /// allowed): the rows of `C` and `D`.
    ///
    /// # Errors
    ///
    /// [`Error::OutOfRange`] (`"output"`) for an index ≥ the number of
    /// outputs.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::DynStateSpace;
    /// use ctrlab::nalgebra::dmatrix;
    ///
    /// let sys = DynStateSpace::continuous(dmatrix![-1.0], dmatrix![1.0],
    ///                                     dmatrix![1.0; 2.0], dmatrix![0.0; 0.0])?;
    /// assert_eq!(sys.select_outputs(&[1])?.c(), &dmatrix![2.0]);
    /// assert!(sys.select_outputs(&[2]).is_err());
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn select_outputs(&self, outputs: &[usize]) -> Result<Self, Error> {
        check_indices("output", outputs, self.outputs())?;
        Ok(Self::from_parts_unchecked(
            self.a().clone(),
            self.b().clone(),
            self.c().select_rows(outputs),
            self.d().select_rows(outputs),
            self.domain(),
        ))
    }
}

fn check_indices(what: &'static str, indices: &[usize], len: usize) -> Result<(), Error> {
    match indices.iter().find(|&&i| i >= len) {
        Some(&index) => Err(Error::OutOfRange { what, index, len }),
        None => Ok(()),
    }
}

/// `F⁻¹` for the algebraic loop of a feedback connection, refused when `F`
/// is singular or so ill-conditioned (Skeel condition of the row-equilibrated
/// matrix above 1e-4/ε, the bound `dc_gain` uses) that the loop is ill-posed.
fn loop_inverse(f: &DMatrix<f64>) -> Result<DMatrix<f64>, Error> {
    let operation = "feedback connection (algebraic loop I − s·D₂·D₁)";
    let n = f.nrows();
    if n == 0 {
        return Ok(DMatrix::zeros(0, 0));
    }
    // Equilibrate rows so the test does not depend on the units of the
    // inputs; undo it on the inverse's columns.
    let mut scaled = f.clone();
    let mut scale = vec![1.0; n];
    for (i, s) in scale.iter_mut().enumerate() {
        let amax = scaled.row(i).amax();
        if amax == 0.0 || !amax.is_finite() {
            return Err(Error::Singular { operation });
        }
        *s = 1.0 / pow2_floor(amax);
        scaled.row_mut(i).scale_mut(*s);
    }
    let inv = scaled
        .clone()
        .try_inverse()
        .ok_or(Error::Singular { operation })?;
    let skeel = (inv.abs() * scaled.abs())
        .row_iter()
        .map(|r| r.sum())
        .fold(0.0, f64::max);
    if !skeel.is_finite() || skeel * f64::EPSILON > 1e-4 {
        return Err(Error::Singular { operation });
    }
    // F⁻¹ = (S F)⁻¹ S.
    let mut out = inv;
    for (j, s) in scale.iter().enumerate() {
        out.column_mut(j).scale_mut(*s);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::dmatrix;

    fn gain(k: f64) -> DynStateSpace {
        DynStateSpace::continuous(
            DMatrix::zeros(0, 0),
            DMatrix::zeros(0, 1),
            DMatrix::zeros(1, 0),
            dmatrix![k],
        )
        .unwrap()
    }

    #[test]
    fn feedback_of_pure_gains_is_the_loop_formula() {
        // k/(1 + k h) for static gains, both signs.
        let (k, h) = (4.0, 0.5);
        let neg = gain(k).feedback(&gain(h), Sign::Negative).unwrap();
        assert!((neg.d()[(0, 0)] - k / (1.0 + k * h)).abs() < 1e-15);
        let pos = gain(k).feedback(&gain(h), Sign::Positive).unwrap();
        assert!((pos.d()[(0, 0)] - k / (1.0 - k * h)).abs() < 1e-15);
        // k h = 1 with positive feedback: no solution.
        let err = gain(2.0).feedback(&gain(0.5), Sign::Positive).unwrap_err();
        assert!(matches!(err, Error::Singular { .. }), "{err}");
    }

    #[test]
    fn mismatched_parts_are_refused() {
        let siso = gain(1.0);
        let two_in = DynStateSpace::continuous(
            dmatrix![-1.0],
            dmatrix![1.0, 1.0],
            dmatrix![1.0],
            dmatrix![0.0, 0.0],
        )
        .unwrap();
        assert!(matches!(
            two_in.series(&two_in),
            Err(Error::LengthMismatch { .. })
        ));
        assert!(matches!(
            siso.parallel(&two_in),
            Err(Error::LengthMismatch { .. })
        ));
        assert!(matches!(
            two_in.feedback(&siso, Sign::Negative),
            Err(Error::LengthMismatch { .. })
        ));
        let d1 = DynStateSpace::discrete(
            dmatrix![0.5],
            dmatrix![1.0],
            dmatrix![1.0],
            dmatrix![0.0],
            0.1,
        )
        .unwrap();
        let d2 = DynStateSpace::discrete(
            dmatrix![0.5],
            dmatrix![1.0],
            dmatrix![1.0],
            dmatrix![0.0],
            0.2,
        )
        .unwrap();
        assert!(matches!(
            d1.series(&d2),
            Err(Error::InvalidParameter { name: "dt", .. })
        ));
        assert!(d1.series(&d1).is_ok());
    }

    #[test]
    fn overflow_is_an_error_not_an_infinite_model() {
        let big = DynStateSpace::continuous(
            dmatrix![-1.0],
            dmatrix![1e300],
            dmatrix![1e300],
            dmatrix![0.0],
        )
        .unwrap();
        assert!(matches!(big.series(&big), Err(Error::Overflow { .. })));
    }
}
