//! `StateSpace`: a linear time-invariant model whose sizes and time domain are
//! part of its type.

use nalgebra::{SMatrix, SVector};

use crate::error::{Error, check_dt, check_finite};

mod sealed {
    /// Seals [`Domain`](super::Domain) and lets crate code ask a domain for
    /// its period without a public method.
    pub trait Sealed {
        /// `None` in continuous time, `Some(dt)` in discrete time.
        fn period(&self) -> Option<f64>;
    }
    impl Sealed for super::Continuous {
        fn period(&self) -> Option<f64> {
            None
        }
    }
    impl Sealed for super::Discrete {
        fn period(&self) -> Option<f64> {
            Some(self.dt)
        }
    }
}

/// The time domain of a [`StateSpace`]: [`Continuous`] or [`Discrete`].
///
/// Sealed: the crate's algorithms are written for exactly these two.
///
/// # Examples
///
/// Code generic over the domain: the same `A = 0.5` is unstable in
/// continuous time (`s = 0.5`) and stable in discrete time (`z = 0.5`).
///
/// ```
/// use ctrlab::{Domain, StateSpace};
/// use ctrlab::nalgebra::matrix;
///
/// fn stable<D: Domain>(sys: &StateSpace<1, 1, 1, D>) -> Result<bool, ctrlab::Error> {
///     sys.is_stable()
/// }
/// let (a, b, c, d) = (matrix![0.5], matrix![1.0], matrix![1.0], matrix![0.0]);
/// assert!(!stable(&StateSpace::continuous(a, b, c, d)?)?);
/// assert!(stable(&StateSpace::discrete(a, b, c, d, 0.01)?)?);
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub trait Domain: sealed::Sealed + Copy + core::fmt::Debug + PartialEq {}

/// Marker for continuous-time models, `x' = A x + B u`.
///
/// # Examples
///
/// ```
/// use ctrlab::{Continuous, Discretization, StateSpace};
/// use ctrlab::nalgebra::matrix;
///
/// let sys = StateSpace::continuous(matrix![-1.0], matrix![1.0], matrix![1.0], matrix![0.0])?;
/// assert_eq!(sys.domain(), Continuous); // no period
/// assert_eq!(sys.discretize(0.002, Discretization::Zoh)?.domain().dt(), 0.002); // s
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Continuous;

/// Marker for discrete-time models, `x[k+1] = A x[k] + B u[k]`; carries the
/// sampling period.
///
/// # Examples
///
/// ```
/// use ctrlab::StateSpace;
/// use ctrlab::nalgebra::matrix;
///
/// let (a, b, c, d) = (matrix![0.5], matrix![1.0], matrix![1.0], matrix![0.0]);
/// assert_eq!(StateSpace::discrete(a, b, c, d, 0.002)?.domain().dt(), 0.002); // s
/// assert!(StateSpace::discrete(a, b, c, d, 0.0).is_err()); // a period must be > 0
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Discrete {
    dt: f64,
}

impl Discrete {
    /// The sampling period in seconds.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::{StateSpace, Discrete};
    /// # use ctrlab::nalgebra::{matrix};
    /// let sys = StateSpace::discrete(matrix![0.5], matrix![1.0], matrix![1.0], matrix![0.0], 0.002)?;
    /// assert_eq!(sys.domain().dt(), 0.002);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn dt(&self) -> f64 {
        self.dt
    }

    /// A discrete domain with a period the caller has checked (`check_dt`).
    pub(crate) fn new_unchecked(dt: f64) -> Self {
        Self { dt }
    }
}

impl Domain for Continuous {}
impl Domain for Discrete {}

/// The sampling period of a domain: `None` in continuous time (crate-wide
/// helper for algorithms written once for both domains).
pub(crate) fn period_of<D: Domain>(domain: &D) -> Option<f64> {
    sealed::Sealed::period(domain)
}

/// A linear time-invariant state-space model with `N` states, `M` inputs and
/// `P` outputs, in time domain `D`.
///
/// Continuous: `x' = A x + B u`, `y = C x + D u`.
/// Discrete: `x[k+1] = A x[k] + B u[k]`, `y[k] = C x[k] + D u[k]`, period `dt` s.
///
/// Matrices are nalgebra [`SMatrix`]es on the stack. The domain is in the
/// type: [`discretize`](StateSpace::discretize) exists only on continuous
/// models and [`advance`](StateSpace::advance) only on discrete ones, so
/// mixing them up is a compile error:
///
/// ```compile_fail
/// # use ctrlab::StateSpace;
/// # use ctrlab::nalgebra::matrix;
/// let sys = StateSpace::continuous(matrix![-1.0], matrix![1.0], matrix![1.0], matrix![0.0]).unwrap();
/// sys.advance(&matrix![0.0], &matrix![1.0]); // no `advance` on a continuous model
/// ```
///
/// # Examples
///
/// ```
/// use ctrlab::StateSpace;
/// use ctrlab::nalgebra::matrix;
///
/// // A first-order lag, time constant 0.5 s, DC gain 2.
/// let sys = StateSpace::continuous(matrix![-2.0], matrix![4.0], matrix![1.0], matrix![0.0])?;
/// assert_eq!(sys.a()[(0, 0)], -2.0);
///
/// // Constructors refuse non-finite entries.
/// assert!(StateSpace::continuous(matrix![f64::NAN], matrix![1.0], matrix![1.0], matrix![0.0]).is_err());
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StateSpace<const N: usize, const M: usize, const P: usize, D: Domain = Continuous> {
    a: SMatrix<f64, N, N>,
    b: SMatrix<f64, N, M>,
    c: SMatrix<f64, P, N>,
    d: SMatrix<f64, P, M>,
    domain: D,
}

fn check_all<const N: usize, const M: usize, const P: usize>(
    a: &SMatrix<f64, N, N>,
    b: &SMatrix<f64, N, M>,
    c: &SMatrix<f64, P, N>,
    d: &SMatrix<f64, P, M>,
) -> Result<(), Error> {
    check_finite("A", a)?;
    check_finite("B", b)?;
    check_finite("C", c)?;
    check_finite("D", d)
}

impl<const N: usize, const M: usize, const P: usize> StateSpace<N, M, P, Continuous> {
    /// A continuous-time model `x' = A x + B u`, `y = C x + D u`.
    ///
    /// # Errors
    ///
    /// [`Error::NonFinite`] naming the matrix and entry if any entry is NaN or
    /// infinite.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::{StateSpace, Error};
    /// # use ctrlab::nalgebra::matrix;
    /// let err = StateSpace::continuous(matrix![-1.0], matrix![f64::INFINITY], matrix![1.0], matrix![0.0]).unwrap_err();
    /// assert!(matches!(err, Error::NonFinite { matrix: "B", row: 0, col: 0, .. }));
    /// ```
    pub fn continuous(
        a: SMatrix<f64, N, N>,
        b: SMatrix<f64, N, M>,
        c: SMatrix<f64, P, N>,
        d: SMatrix<f64, P, M>,
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

    /// The state derivative `A x + B u`.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::StateSpace;
    /// # use ctrlab::nalgebra::{matrix, vector};
    /// let sys = StateSpace::continuous(matrix![-2.0], matrix![4.0], matrix![1.0], matrix![0.0])?;
    /// assert_eq!(sys.derivative(&vector![1.0], &vector![0.5]), vector![0.0]);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[inline]
    pub fn derivative(&self, x: &SVector<f64, N>, u: &SVector<f64, M>) -> SVector<f64, N> {
        self.a * x + self.b * u
    }
}

impl<const N: usize, const M: usize, const P: usize> StateSpace<N, M, P, Discrete> {
    /// A discrete-time model `x[k+1] = A x[k] + B u[k]` with sampling period
    /// `dt` seconds.
    ///
    /// # Errors
    ///
    /// [`Error::NonFinite`] for a NaN or infinite entry;
    /// [`Error::InvalidParameter`] named `"dt"` unless `dt` is finite and > 0.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::{StateSpace, Error};
    /// # use ctrlab::nalgebra::matrix;
    /// let sys = StateSpace::discrete(matrix![0.9], matrix![0.1], matrix![1.0], matrix![0.0], 0.01)?;
    /// assert_eq!(sys.dt(), 0.01);
    /// let err = StateSpace::discrete(matrix![0.9], matrix![0.1], matrix![1.0], matrix![0.0], 0.0).unwrap_err();
    /// assert!(matches!(err, Error::InvalidParameter { name: "dt", .. }));
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn discrete(
        a: SMatrix<f64, N, N>,
        b: SMatrix<f64, N, M>,
        c: SMatrix<f64, P, N>,
        d: SMatrix<f64, P, M>,
        dt: f64,
    ) -> Result<Self, Error> {
        check_dt(dt)?;
        check_all(&a, &b, &c, &d)?;
        Ok(Self {
            a,
            b,
            c,
            d,
            domain: Discrete { dt },
        })
    }

    /// The sampling period in seconds.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::StateSpace;
    /// # use ctrlab::nalgebra::matrix;
    /// let sys = StateSpace::discrete(matrix![1.0], matrix![0.0], matrix![1.0], matrix![0.0], 0.002)?;
    /// assert_eq!(sys.dt(), 0.002);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[inline]
    pub fn dt(&self) -> f64 {
        self.domain.dt
    }

    /// Advances the state one sample in place: `x ← A x + B u`. Allocates
    /// nothing; this is the inner loop of discrete simulation. (Not MATLAB's
    /// `step`, the step response: that is
    /// [`step_response`](crate::sim::step_response).)
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::StateSpace;
    /// # use ctrlab::nalgebra::{matrix, vector};
    /// let sys = StateSpace::discrete(matrix![0.5], matrix![1.0], matrix![1.0], matrix![0.0], 0.1)?;
    /// let mut x = vector![2.0];
    /// sys.advance_mut(&mut x, &vector![1.0]);
    /// assert_eq!(x, vector![2.0]);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[inline]
    pub fn advance_mut(&self, x: &mut SVector<f64, N>, u: &SVector<f64, M>) {
        *x = self.a * *x + self.b * u;
    }

    /// The next state `A x + B u`; the returning twin of
    /// [`advance_mut`](Self::advance_mut).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::StateSpace;
    /// # use ctrlab::nalgebra::{matrix, vector};
    /// let sys = StateSpace::discrete(matrix![0.5], matrix![1.0], matrix![1.0], matrix![0.0], 0.1)?;
    /// assert_eq!(sys.advance(&vector![4.0], &vector![0.0]), vector![2.0]);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[inline]
    #[must_use]
    pub fn advance(&self, x: &SVector<f64, N>, u: &SVector<f64, M>) -> SVector<f64, N> {
        self.a * x + self.b * u
    }
}

impl<const N: usize, const M: usize, const P: usize, D: Domain> StateSpace<N, M, P, D> {
    /// The number of states `N`, as [`DynStateSpace::states`](crate::DynStateSpace::states).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::MassSpring;
    /// let sys = MassSpring::nominal().state_space(ctrlab::Cart::Two)?;
    /// assert_eq!((sys.states(), sys.inputs(), sys.outputs()), (4, 1, 1));
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[inline]
    pub const fn states(&self) -> usize {
        N
    }

    /// The number of inputs `M`.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::StateSpace;
    /// # use ctrlab::nalgebra::matrix;
    /// let sys = StateSpace::continuous(matrix![-1.0], matrix![1.0, 2.0], matrix![1.0], matrix![0.0, 0.0])?;
    /// assert_eq!(sys.inputs(), 2);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[inline]
    pub const fn inputs(&self) -> usize {
        M
    }

    /// The number of outputs `P`.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::StateSpace;
    /// # use ctrlab::nalgebra::matrix;
    /// let sys = StateSpace::continuous(matrix![-1.0], matrix![1.0], matrix![1.0; 2.0], matrix![0.0; 0.0])?;
    /// assert_eq!(sys.outputs(), 2);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[inline]
    pub const fn outputs(&self) -> usize {
        P
    }

    /// The state matrix `A` (N×N).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::MassSpring;
    /// let sys = MassSpring::nominal().state_space(ctrlab::Cart::Two)?;
    /// assert_eq!(sys.a()[(0, 1)], 1.0);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[inline]
    pub fn a(&self) -> &SMatrix<f64, N, N> {
        &self.a
    }

    /// The input matrix `B` (N×M).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::MassSpring;
    /// let sys = MassSpring::nominal().state_space(ctrlab::Cart::Two)?;
    /// assert_eq!(sys.b()[(3, 0)], 1.0 / 0.7);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[inline]
    pub fn b(&self) -> &SMatrix<f64, N, M> {
        &self.b
    }

    /// The output matrix `C` (P×N).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::MassSpring;
    /// let sys = MassSpring::nominal().state_space(ctrlab::Cart::Two)?;
    /// assert_eq!(sys.c()[(0, 2)], 1.0);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[inline]
    pub fn c(&self) -> &SMatrix<f64, P, N> {
        &self.c
    }

    /// The feedthrough matrix `D` (P×M).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::MassSpring;
    /// let sys = MassSpring::nominal().state_space(ctrlab::Cart::Two)?;
    /// assert_eq!(sys.d()[(0, 0)], 0.0);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[inline]
    pub fn d(&self) -> &SMatrix<f64, P, M> {
        &self.d
    }

    /// The time domain: [`Continuous`], or [`Discrete`] with its period.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::{MassSpring, Continuous};
    /// let sys = MassSpring::nominal().state_space(ctrlab::Cart::Two)?;
    /// assert_eq!(sys.domain(), Continuous);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[inline]
    pub fn domain(&self) -> D {
        self.domain
    }

    /// The output `C x + D u`.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::MassSpring;
    /// # use ctrlab::nalgebra::vector;
    /// let sys = MassSpring::nominal().state_space(ctrlab::Cart::One)?;
    /// let y = sys.output(&vector![0.01, 0.0, 0.02, 0.0], &vector![0.0]);
    /// assert_eq!(y[0], 0.01);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[inline]
    pub fn output(&self, x: &SVector<f64, N>, u: &SVector<f64, M>) -> SVector<f64, P> {
        self.c * x + self.d * u
    }

    /// Replaces the output equation, keeping `A`, `B` and the domain; used to
    /// look at another combination of the states.
    ///
    /// # Errors
    ///
    /// [`Error::NonFinite`] for a NaN or infinite entry in `c` or `d`.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::MassSpring;
    /// # use ctrlab::nalgebra::{SMatrix, matrix};
    /// let sys = MassSpring::nominal().state_space(ctrlab::Cart::One)?;
    /// let full = sys.with_output(SMatrix::<f64, 4, 4>::identity(), SMatrix::<f64, 4, 1>::zeros())?;
    /// assert_eq!(full.c().nrows(), 4);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn with_output<const Q: usize>(
        &self,
        c: SMatrix<f64, Q, N>,
        d: SMatrix<f64, Q, M>,
    ) -> Result<StateSpace<N, M, Q, D>, Error> {
        check_finite("C", &c)?;
        check_finite("D", &d)?;
        Ok(StateSpace {
            a: self.a,
            b: self.b,
            c,
            d,
            domain: self.domain,
        })
    }

    /// The single-input model from input `j`: column `j` of `B` and `D`,
    /// the rest unchanged (python-control's `sys[:, j]`). The step and
    /// impulse responses of [`sim`](crate::sim) take one input.
    ///
    /// # Errors
    ///
    /// [`Error::OutOfRange`] unless `j < M`.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::{Error, StateSpace};
    /// # use ctrlab::nalgebra::matrix;
    /// let sys = StateSpace::continuous(matrix![-1.0], matrix![1.0, 2.0], matrix![1.0], matrix![0.0, 0.5])?;
    /// let second = sys.select_input(1)?;
    /// assert_eq!((second.b()[(0, 0)], second.d()[(0, 0)]), (2.0, 0.5));
    /// assert!(matches!(sys.select_input(2), Err(Error::OutOfRange { index: 2, len: 2, .. })));
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn select_input(&self, j: usize) -> Result<StateSpace<N, 1, P, D>, Error> {
        if j >= M {
            return Err(Error::OutOfRange {
                what: "input",
                index: j,
                len: M,
            });
        }
        Ok(StateSpace {
            a: self.a,
            b: self.b.column(j).into_owned(),
            c: self.c,
            d: self.d.column(j).into_owned(),
            domain: self.domain,
        })
    }

    /// Builds a model from parts already known to be finite (crate-internal:
    /// discretisation output is checked by its caller).
    pub(crate) fn from_parts_unchecked(
        a: SMatrix<f64, N, N>,
        b: SMatrix<f64, N, M>,
        c: SMatrix<f64, P, N>,
        d: SMatrix<f64, P, M>,
        domain: D,
    ) -> Self {
        Self { a, b, c, d, domain }
    }
}

impl<const N: usize, const M: usize, const P: usize> StateSpace<N, M, P, Discrete> {
    /// Builds a discrete model whose matrices came out of a computation;
    /// refuses overflowed results instead of returning NaN-filled models.
    pub(crate) fn from_computed(
        a: SMatrix<f64, N, N>,
        b: SMatrix<f64, N, M>,
        c: SMatrix<f64, P, N>,
        d: SMatrix<f64, P, M>,
        dt: f64,
        operation: &'static str,
    ) -> Result<Self, Error> {
        if check_all(&a, &b, &c, &d).is_err() {
            return Err(Error::Overflow { operation });
        }
        Ok(Self::from_parts_unchecked(a, b, c, d, Discrete { dt }))
    }
}
