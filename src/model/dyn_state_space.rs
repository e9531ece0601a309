//! `DynStateSpace`: a linear model whose sizes are known only at run time,
//! with its time domain still in the type.

use nalgebra::{DMatrix, DVector, SMatrix};

use crate::error::{Error, check_dt, check_finite_dyn, check_shape};
use crate::model::{Continuous, Discrete, Domain, StateSpace};

/// A linear time-invariant state-space model whose numbers of states, inputs
/// and outputs are chosen at run time (a model read from a file, the result
/// of connecting two models), in time domain `D`.
///
/// The equations are those of [`StateSpace`]: `x' = A x + B u`,
/// `y = C x + D u` in continuous time, `x[k+1] = A x[k] + B u[k]` with period
/// `dt` s in discrete time. The matrices are nalgebra [`DMatrix`]es on the
/// heap; the design-time algorithms (poles, Riccati equations, frequency
/// responses) run on them through faer. Its properties are methods, as on
/// [`StateSpace`]: analysis (`poles`, `is_stable`, `dc_gain`,
/// `controllability`, `damping`, …), `discretize`, `zeros`, the
/// interconnections (`series`, `parallel`, `feedback`, `append`) and input
/// and output selection. What is computed *from* a model (a design, a
/// response, step figures, a frequency response) is a free function that
/// takes either model type (`lqr(&sys, ..)`, `place(&sys, ..)`,
/// `step_response(&sys, ..)`, `step_info_of(&sys, ..)`, `bode(&sys, ..)`;
/// see [`LinearSystem`](crate::LinearSystem)), running the same code as
/// for a fixed-size model. Convert from a fixed-size model with `From`,
/// and back with `TryFrom`, which checks the sizes:
///
/// # Examples
///
/// ```
/// use ctrlab::{DynStateSpace, StateSpace};
/// use ctrlab::nalgebra::{dmatrix, matrix};
///
/// // A first-order lag, time constant 0.5 s, DC gain 2, sized at run time.
/// let sys = DynStateSpace::continuous(dmatrix![-2.0], dmatrix![4.0], dmatrix![1.0], dmatrix![0.0])?;
/// assert_eq!((sys.states(), sys.inputs(), sys.outputs()), (1, 1, 1));
///
/// // Back to the fixed-size type where the sizes match…
/// let fixed: StateSpace<1, 1, 1> = (&sys).try_into()?;
/// assert_eq!(fixed.a(), &matrix![-2.0]);
/// // …and an error naming the matrix where they do not.
/// assert!(StateSpace::<2, 1, 1>::try_from(&sys).is_err());
///
/// // Shapes are checked at construction.
/// assert!(DynStateSpace::continuous(dmatrix![-2.0], dmatrix![4.0; 1.0], dmatrix![1.0], dmatrix![0.0]).is_err());
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct DynStateSpace<D: Domain = Continuous> {
    a: DMatrix<f64>,
    b: DMatrix<f64>,
    c: DMatrix<f64>,
    d: DMatrix<f64>,
    domain: D,
}

/// Checks the shapes (`A` square, `B`, `C`, `D` conforming) and entries.
fn check_all(
    a: &DMatrix<f64>,
    b: &DMatrix<f64>,
    c: &DMatrix<f64>,
    d: &DMatrix<f64>,
) -> Result<(), Error> {
    let (n, m, p) = (a.nrows(), b.ncols(), c.nrows());
    check_shape("A", a, n, n)?;
    check_shape("B", b, n, m)?;
    check_shape("C", c, p, n)?;
    check_shape("D", d, p, m)?;
    check_finite_dyn("A", a)?;
    check_finite_dyn("B", b)?;
    check_finite_dyn("C", c)?;
    check_finite_dyn("D", d)
}

impl DynStateSpace<Continuous> {
    /// A continuous-time model `x' = A x + B u`, `y = C x + D u`. The sizes
    /// are taken from the matrices: `n` from `A`'s rows, `m` from `B`'s
    /// columns, `p` from `C`'s rows.
    ///
    /// # Errors
    ///
    /// [`Error::DimensionMismatch`] naming the first matrix whose shape does
    /// not conform (`A` not square, `B` not `n × m`, `C` not `p × n`, `D` not
    /// `p × m`); [`Error::NonFinite`] naming the matrix and entry of a NaN or
    /// infinite entry.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::{DynStateSpace, Error};
    /// # use ctrlab::nalgebra::dmatrix;
    /// let err = DynStateSpace::continuous(dmatrix![-1.0, 0.0], dmatrix![1.0], dmatrix![1.0], dmatrix![0.0])
    ///     .unwrap_err();
    /// assert!(matches!(err, Error::DimensionMismatch { matrix: "A", found_rows: 1, found_cols: 2, .. }));
    /// ```
    pub fn continuous(
        a: DMatrix<f64>,
        b: DMatrix<f64>,
        c: DMatrix<f64>,
        d: DMatrix<f64>,
    ) -> Result<Self, Error> {
        check_all(&a, &b, &c, &d)?;
        Ok(Self {
            a,
            b,
            c,
            d,
            domain: Continuous,
        })
    }
}

impl DynStateSpace<Discrete> {
    /// A discrete-time model `x[k+1] = A x[k] + B u[k]`, `y[k] = C x[k] + D u[k]`
    /// with sampling period `dt` (s).
    ///
    /// # Errors
    ///
    /// As [`DynStateSpace::continuous`], and [`Error::InvalidParameter`] for a
    /// `dt` that is not finite and positive.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::DynStateSpace;
    /// # use ctrlab::nalgebra::dmatrix;
    /// let sys = DynStateSpace::discrete(dmatrix![0.5], dmatrix![1.0], dmatrix![1.0], dmatrix![0.0], 0.002)?;
    /// assert_eq!(sys.dt(), 0.002);
    /// assert!(DynStateSpace::discrete(dmatrix![0.5], dmatrix![1.0], dmatrix![1.0], dmatrix![0.0], 0.0).is_err());
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn discrete(
        a: DMatrix<f64>,
        b: DMatrix<f64>,
        c: DMatrix<f64>,
        d: DMatrix<f64>,
        dt: f64,
    ) -> Result<Self, Error> {
        check_dt(dt)?;
        check_all(&a, &b, &c, &d)?;
        Ok(Self {
            a,
            b,
            c,
            d,
            domain: Discrete::new_unchecked(dt),
        })
    }

    /// The sampling period in seconds.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::DynStateSpace;
    /// # use ctrlab::nalgebra::dmatrix;
    /// let sys = DynStateSpace::discrete(dmatrix![0.5], dmatrix![1.0], dmatrix![1.0], dmatrix![0.0], 0.01)?;
    /// assert_eq!(sys.dt(), 0.01);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn dt(&self) -> f64 {
        self.domain.dt()
    }

    /// One step of the state equation, `x[k+1] = A x[k] + B u[k]`.
    ///
    /// # Errors
    ///
    /// [`Error::LengthMismatch`] if `x` does not have `n` entries or `u`
    /// does not have `m`; [`Error::InvalidData`] naming `x` or `u` for a
    /// non-finite entry; [`Error::Overflow`] if the next state does.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::{DynStateSpace, Error};
    /// # use ctrlab::nalgebra::{dmatrix, dvector};
    /// let sys = DynStateSpace::discrete(dmatrix![0.5], dmatrix![1.0], dmatrix![1.0], dmatrix![0.0], 0.01)?;
    /// assert_eq!(sys.advance(&dvector![2.0], &dvector![1.0])?, dvector![2.0]);
    /// // 0.5 · 1e308 + 1.5e308 exceeds f64::MAX: refused, not Ok([inf]).
    /// let err = sys.advance(&dvector![1e308], &dvector![1.5e308]).unwrap_err();
    /// assert!(matches!(err, Error::Overflow { .. }));
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn advance(&self, x: &DVector<f64>, u: &DVector<f64>) -> Result<DVector<f64>, Error> {
        self.check_vectors(x, u)?;
        finite_result(
            &self.a * x + &self.b * u,
            "DynStateSpace::advance (A x + B u)",
        )
    }
}

impl<D: Domain> DynStateSpace<D> {
    /// The number of states `n`.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::{DynStateSpace, MassSpring, Cart};
    /// let sys = DynStateSpace::from(MassSpring::nominal().state_space(Cart::Two)?);
    /// assert_eq!(sys.states(), 4);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn states(&self) -> usize {
        self.a.nrows()
    }

    /// The number of inputs `m`.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::{DynStateSpace, MassSpring, Cart};
    /// let sys = DynStateSpace::from(MassSpring::nominal().state_space(Cart::Two)?);
    /// assert_eq!(sys.inputs(), 1);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn inputs(&self) -> usize {
        self.b.ncols()
    }

    /// The number of outputs `p`.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::{DynStateSpace, MassSpring, Cart};
    /// let sys = DynStateSpace::from(MassSpring::nominal().state_space(Cart::Two)?);
    /// assert_eq!(sys.outputs(), 1);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn outputs(&self) -> usize {
        self.c.nrows()
    }

    /// The state matrix `A` (`n × n`).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::DynStateSpace;
    /// # use ctrlab::nalgebra::dmatrix;
    /// let sys = DynStateSpace::continuous(dmatrix![-2.0], dmatrix![4.0], dmatrix![1.0], dmatrix![0.0])?;
    /// assert_eq!(sys.a(), &dmatrix![-2.0]);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn a(&self) -> &DMatrix<f64> {
        &self.a
    }

    /// The input matrix `B` (`n × m`).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::DynStateSpace;
    /// # use ctrlab::nalgebra::dmatrix;
    /// let sys = DynStateSpace::continuous(dmatrix![-2.0], dmatrix![4.0], dmatrix![1.0], dmatrix![0.0])?;
    /// assert_eq!(sys.b(), &dmatrix![4.0]);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn b(&self) -> &DMatrix<f64> {
        &self.b
    }

    /// The output matrix `C` (`p × n`).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::DynStateSpace;
    /// # use ctrlab::nalgebra::dmatrix;
    /// let sys = DynStateSpace::continuous(dmatrix![-2.0], dmatrix![4.0], dmatrix![1.0], dmatrix![0.0])?;
    /// assert_eq!(sys.c(), &dmatrix![1.0]);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn c(&self) -> &DMatrix<f64> {
        &self.c
    }

    /// The feedthrough matrix `D` (`p × m`).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::DynStateSpace;
    /// # use ctrlab::nalgebra::dmatrix;
    /// let sys = DynStateSpace::continuous(dmatrix![-2.0], dmatrix![4.0], dmatrix![1.0], dmatrix![0.5])?;
    /// assert_eq!(sys.d(), &dmatrix![0.5]);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn d(&self) -> &DMatrix<f64> {
        &self.d
    }

    /// The time domain: [`Continuous`], or [`Discrete`] with its period.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::DynStateSpace;
    /// # use ctrlab::nalgebra::dmatrix;
    /// let sys = DynStateSpace::discrete(dmatrix![0.5], dmatrix![1.0], dmatrix![1.0], dmatrix![0.0], 0.002)?;
    /// assert_eq!(sys.domain().dt(), 0.002);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn domain(&self) -> D {
        self.domain
    }

    /// The output `y = C x + D u`.
    ///
    /// # Errors
    ///
    /// [`Error::LengthMismatch`] if `x` does not have `n` entries or `u`
    /// does not have `m`; [`Error::InvalidData`] naming `x` or `u` for a
    /// non-finite entry; [`Error::Overflow`] if the output does.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::{DynStateSpace, Error};
    /// # use ctrlab::nalgebra::{dmatrix, dvector};
    /// let sys = DynStateSpace::continuous(dmatrix![-2.0], dmatrix![4.0], dmatrix![3.0], dmatrix![0.5])?;
    /// assert_eq!(sys.output(&dvector![1.0], &dvector![2.0])?, dvector![4.0]);
    /// assert!(sys.output(&dvector![1.0, 0.0], &dvector![2.0]).is_err());
    /// // 3 · 1e308 exceeds f64::MAX: refused, not Ok([inf]).
    /// let err = sys.output(&dvector![1e308], &dvector![0.0]).unwrap_err();
    /// assert!(matches!(err, Error::Overflow { .. }));
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn output(&self, x: &DVector<f64>, u: &DVector<f64>) -> Result<DVector<f64>, Error> {
        self.check_vectors(x, u)?;
        finite_result(
            &self.c * x + &self.d * u,
            "DynStateSpace::output (C x + D u)",
        )
    }

    fn check_vectors(&self, x: &DVector<f64>, u: &DVector<f64>) -> Result<(), Error> {
        if x.len() != self.states() {
            return Err(Error::LengthMismatch {
                what: "x",
                expected: self.states(),
                found: x.len(),
            });
        }
        if u.len() != self.inputs() {
            return Err(Error::LengthMismatch {
                what: "u",
                expected: self.inputs(),
                found: u.len(),
            });
        }
        for (what, v) in [("x", x), ("u", u)] {
            if let Some(index) = v.iter().position(|e| !e.is_finite()) {
                return Err(Error::InvalidData {
                    what,
                    index,
                    reason: "must be finite",
                });
            }
        }
        Ok(())
    }

    /// A model from matrices the caller has already checked (shapes
    /// conforming, entries finite).
    pub(crate) fn from_parts_unchecked(
        a: DMatrix<f64>,
        b: DMatrix<f64>,
        c: DMatrix<f64>,
        d: DMatrix<f64>,
        domain: D,
    ) -> Self {
        debug_assert!(check_all(&a, &b, &c, &d).is_ok());
        Self { a, b, c, d, domain }
    }

    /// A model from computed matrices: shapes are the caller's, but an entry
    /// that overflowed is reported as [`Error::Overflow`] of `operation`.
    pub(crate) fn from_computed(
        a: DMatrix<f64>,
        b: DMatrix<f64>,
        c: DMatrix<f64>,
        d: DMatrix<f64>,
        domain: D,
        operation: &'static str,
    ) -> Result<Self, Error> {
        if check_all(&a, &b, &c, &d).is_err() {
            return Err(Error::Overflow { operation });
        }
        Ok(Self { a, b, c, d, domain })
    }
}

impl<const N: usize, const M: usize, const P: usize, D: Domain> From<&StateSpace<N, M, P, D>>
    for DynStateSpace<D>
{
    fn from(sys: &StateSpace<N, M, P, D>) -> Self {
        fn heap<const R: usize, const C: usize>(m: &SMatrix<f64, R, C>) -> DMatrix<f64> {
            DMatrix::from_column_slice(R, C, m.as_slice())
        }
        Self {
            a: heap(sys.a()),
            b: heap(sys.b()),
            c: heap(sys.c()),
            d: heap(sys.d()),
            domain: sys.domain(),
        }
    }
}

impl<const N: usize, const M: usize, const P: usize, D: Domain> From<StateSpace<N, M, P, D>>
    for DynStateSpace<D>
{
    fn from(sys: StateSpace<N, M, P, D>) -> Self {
        Self::from(&sys)
    }
}

impl<const N: usize, const M: usize, const P: usize, D: Domain> TryFrom<&DynStateSpace<D>>
    for StateSpace<N, M, P, D>
{
    type Error = Error;

    /// The fixed-size model with the same matrices.
    ///
    /// # Errors
    ///
    /// [`Error::DimensionMismatch`] naming the first matrix whose shape is
    /// not `N × N`, `N × M`, `P × N` or `P × M`.
    fn try_from(sys: &DynStateSpace<D>) -> Result<Self, Error> {
        fn fixed<const R: usize, const C: usize>(
            name: &'static str,
            m: &DMatrix<f64>,
        ) -> Result<SMatrix<f64, R, C>, Error> {
            check_shape(name, m, R, C)?;
            Ok(SMatrix::from_column_slice(m.as_slice()))
        }
        Ok(StateSpace::from_parts_unchecked(
            fixed("A", &sys.a)?,
            fixed("B", &sys.b)?,
            fixed("C", &sys.c)?,
            fixed("D", &sys.d)?,
            sys.domain,
        ))
    }
}

impl<const N: usize, const M: usize, const P: usize, D: Domain> TryFrom<DynStateSpace<D>>
    for StateSpace<N, M, P, D>
{
    type Error = Error;

    fn try_from(sys: DynStateSpace<D>) -> Result<Self, Error> {
        Self::try_from(&sys)
    }
}

/// `v` if every entry is finite, else [`Error::Overflow`] of `operation`
/// (finite inputs and matrices, so only the products can have overflowed).
fn finite_result(v: DVector<f64>, operation: &'static str) -> Result<DVector<f64>, Error> {
    if v.iter().all(|e| e.is_finite()) {
        Ok(v)
    } else {
        Err(Error::Overflow { operation })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{dmatrix, matrix};

    #[test]
    fn round_trip_keeps_every_entry_and_the_period() {
        let fixed = StateSpace::discrete(
            matrix![0.5, 0.1; 0.0, 0.9],
            matrix![1.0, 0.0; 0.0, 2.0],
            matrix![1.0, -1.0],
            matrix![0.0, 0.25],
            0.002,
        )
        .unwrap();
        let dynamic = DynStateSpace::from(&fixed);
        assert_eq!(
            (dynamic.states(), dynamic.inputs(), dynamic.outputs()),
            (2, 2, 1)
        );
        assert_eq!(dynamic.dt(), 0.002);
        let back: StateSpace<2, 2, 1, Discrete> = dynamic.try_into().unwrap();
        assert_eq!(back, fixed);
    }

    #[test]
    fn wrong_sizes_name_the_matrix() {
        let sys = DynStateSpace::continuous(
            dmatrix![-1.0, 0.0; 0.0, -2.0],
            dmatrix![1.0; 1.0],
            dmatrix![1.0, 0.0],
            dmatrix![0.0],
        )
        .unwrap();
        let err = StateSpace::<2, 2, 1>::try_from(&sys).unwrap_err();
        assert!(matches!(err, Error::DimensionMismatch { matrix: "B", .. }));
        for (a, b, c, d, name) in [
            (
                dmatrix![-1.0],
                dmatrix![1.0, 2.0],
                dmatrix![1.0],
                dmatrix![0.0],
                "D",
            ),
            (
                dmatrix![-1.0],
                dmatrix![1.0],
                dmatrix![1.0, 2.0],
                dmatrix![0.0],
                "C",
            ),
            (
                dmatrix![-1.0],
                dmatrix![1.0; 2.0],
                dmatrix![1.0],
                dmatrix![0.0],
                "B",
            ),
        ] {
            let err = DynStateSpace::continuous(a, b, c, d).unwrap_err();
            assert!(
                matches!(err, Error::DimensionMismatch { matrix, .. } if matrix == name),
                "{err}"
            );
        }
        let err = DynStateSpace::continuous(
            dmatrix![f64::NAN],
            dmatrix![1.0],
            dmatrix![1.0],
            dmatrix![0.0],
        )
        .unwrap_err();
        assert!(matches!(err, Error::NonFinite { matrix: "A", .. }));
    }

    #[test]
    fn empty_models_are_allowed() {
        // A static gain: no states, y = D u.
        let sys = DynStateSpace::continuous(
            DMatrix::zeros(0, 0),
            DMatrix::zeros(0, 1),
            DMatrix::zeros(1, 0),
            dmatrix![3.0],
        )
        .unwrap();
        assert_eq!(sys.states(), 0);
        let y = sys
            .output(&DVector::zeros(0), &DVector::from_element(1, 2.0))
            .unwrap();
        assert_eq!(y[0], 6.0);
    }
}
