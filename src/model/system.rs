//! [`LinearSystem`]: what [`StateSpace`] and [`DynStateSpace`] have in
//! common, so that one free function (`lqr(&sys, ..)`,
//! `step_response(&sys, ..)`, `step_info_of(&sys, ..)`, …) serves both.

use std::borrow::Cow;
use std::fmt::Debug;

use nalgebra::{Const, DVector, Dim, Dyn, SVector};

use super::{Domain, DynStateSpace, StateSpace};

pub(crate) mod sealed {
    /// Seals [`LinearSystem`](super::LinearSystem) and the traits built on
    /// it: only the crate's two model types implement them.
    pub trait Sealed {}

    /// Made only inside the crate: the hidden methods of the model traits
    /// take one, so that they are not a second way to call an operation.
    #[derive(Debug, Clone, Copy)]
    pub struct Token(pub(crate) ());
}

pub(crate) use sealed::Token;

/// A linear state-space model of either size: [`StateSpace`] (sizes in the
/// type) or [`DynStateSpace`] (sizes at run time). The crate's free
/// functions take any `LinearSystem`.
///
/// Sealed: implemented by these two types only.
///
/// # One calling style for both sizes
///
/// An operation that produces something from a model (a design, a
/// response, step figures, a frequency response) is a free function with
/// the MATLAB / python-control name, generic over a sealed trait that both
/// model types implement: `LinearSystem`, and the traits of the
/// layers above it that add what their results need
/// ([`Design`](crate::design::Design), [`Simulate`](crate::sim::Simulate),
/// [`FrequencyDomain`](crate::freq::FrequencyDomain)). A property of the
/// model itself (`poles`, `dc_gain`, `is_stable`, `discretize`, …) is a
/// method, on both types.
///
/// The sizes are the model's: a fixed-size model's arguments and results
/// are stack matrices of its sizes (`SMatrix`, checked at compile time), a
/// run-time-sized model's are `DMatrix`es (checked at run time). The traits
/// name them as associated types ([`State`](LinearSystem::State),
/// [`Gain`](crate::design::Design::Gain), …), and each result is one
/// struct written over nalgebra's dimensions ([`Const<N>`](nalgebra::Const)
/// or [`Dyn`](nalgebra::Dyn)), so that its fields and methods are the same
/// for both sizes: [`Lqr`](crate::design::Lqr),
/// [`Response`](crate::sim::Response), … with aliases for the run-time
/// sizes ([`DynLqr`](crate::design::DynLqr),
/// [`DynResponse`](crate::sim::DynResponse)).
///
/// Associated types rather than the dimensions in the signatures: a
/// signature over nalgebra's dimensions needs a `DefaultAllocator` bound for
/// every matrix shape it names, which would stand in every function's
/// documentation and in every generic function a user writes; with
/// associated types the bound is written once, in the crate, for the two
/// concrete model types.
///
/// Where a fixed-size model's sizes constrain an operation today, they
/// still do at compile time: [`SingleInput`] and [`Siso`] are implemented
/// for `StateSpace<N, 1, P, D>` and `StateSpace<N, 1, 1, D>` only (and for
/// every `DynStateSpace`, which is checked when called).
///
/// # Examples
///
/// A function written once for both sizes:
///
/// ```
/// use ctrlab::{DynStateSpace, LinearSystem, StateSpace};
/// use ctrlab::nalgebra::matrix;
///
/// fn describe(sys: &impl LinearSystem) -> String {
///     format!("{} states, {} inputs, {} outputs", sys.states(), sys.inputs(), sys.outputs())
/// }
///
/// let fixed = StateSpace::continuous(matrix![-1.0], matrix![1.0, 2.0], matrix![1.0], matrix![0.0, 0.0])?;
/// assert_eq!(describe(&fixed), "1 states, 2 inputs, 1 outputs");
/// assert_eq!(describe(&DynStateSpace::from(&fixed)), "1 states, 2 inputs, 1 outputs");
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub trait LinearSystem: sealed::Sealed {
    /// The time domain: [`Continuous`](super::Continuous) or
    /// [`Discrete`](super::Discrete).
    type Domain: Domain;
    /// The number of states as a nalgebra dimension: `Const<N>` for a
    /// `StateSpace<N, M, P, _>`, `Dyn` for a `DynStateSpace`.
    type States: Dim;
    /// The number of inputs: `Const<M>` or `Dyn`.
    type Inputs: Dim;
    /// The number of outputs: `Const<P>` or `Dyn`.
    type Outputs: Dim;
    /// A state vector: `SVector<f64, N>` or `DVector<f64>`.
    type State: Clone + Debug + PartialEq;
    /// An input vector: `SVector<f64, M>` or `DVector<f64>`.
    type Input: Clone + Debug + PartialEq;

    /// The number of states `n`.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{LinearSystem, StateSpace};
    /// use ctrlab::nalgebra::matrix;
    ///
    /// let sys = StateSpace::continuous(matrix![-1.0], matrix![1.0], matrix![1.0], matrix![0.0])?;
    /// assert_eq!(LinearSystem::states(&sys), 1);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    fn states(&self) -> usize;

    /// The number of inputs `m`.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{LinearSystem, StateSpace};
    /// use ctrlab::nalgebra::matrix;
    ///
    /// let sys = StateSpace::continuous(matrix![-1.0], matrix![1.0, 0.0], matrix![1.0], matrix![0.0, 0.0])?;
    /// assert_eq!(LinearSystem::inputs(&sys), 2);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    fn inputs(&self) -> usize;

    /// The number of outputs `p`.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{LinearSystem, StateSpace};
    /// use ctrlab::nalgebra::matrix;
    ///
    /// let sys = StateSpace::continuous(matrix![-1.0], matrix![1.0], matrix![1.0; 2.0], matrix![0.0; 0.0])?;
    /// assert_eq!(LinearSystem::outputs(&sys), 2);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    fn outputs(&self) -> usize;

    /// The model sized at run time (the model itself for a
    /// `DynStateSpace`, a copy on the heap for a fixed-size one), for the
    /// design-time code written once on run-time-sized matrices.
    #[doc(hidden)]
    fn to_dyn(&self, _: Token) -> Cow<'_, DynStateSpace<Self::Domain>>;
}

/// A model with one input: `StateSpace<N, 1, P, D>` (known at compile time)
/// or any [`DynStateSpace`] (checked when called). The step and impulse
/// responses and Ackermann's formula take one.
///
/// # Examples
///
/// ```compile_fail
/// use ctrlab::{StateSpace, sim::step_response};
/// use ctrlab::nalgebra::matrix;
///
/// // Two inputs: pick one with `select_input` first.
/// let sys = StateSpace::continuous(matrix![-1.0], matrix![1.0, 2.0], matrix![1.0], matrix![0.0, 0.0]).unwrap();
/// step_response(&sys, 1.0, 0.1);
/// ```
///
/// ```
/// use ctrlab::{StateSpace, sim::step_response};
/// use ctrlab::nalgebra::matrix;
///
/// let sys = StateSpace::continuous(matrix![-1.0], matrix![1.0, 2.0], matrix![1.0], matrix![0.0, 0.0])?;
/// let r = step_response(&sys.select_input(1)?, 1.0, 0.1)?;
/// assert!((r.y[10][0] - 2.0 * (1.0 - (-1.0f64).exp())).abs() < 1e-12);
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub trait SingleInput: LinearSystem {}

/// A model with one input and one output: `StateSpace<N, 1, 1, D>` or any
/// [`DynStateSpace`] (checked when called). [`step_info_of`](crate::step_info_of)
/// takes one.
///
/// # Examples
///
/// ```
/// use ctrlab::{DynStateSpace, StateSpace, StepInfoOptions, step_info_of};
/// use ctrlab::nalgebra::matrix;
///
/// let lag = StateSpace::continuous(matrix![-10.0], matrix![10.0], matrix![1.0], matrix![0.0])?;
/// let fixed = step_info_of(&lag, 2.0, 0.01, &StepInfoOptions::default())?;
/// let dynamic = step_info_of(&DynStateSpace::from(&lag), 2.0, 0.01, &StepInfoOptions::default())?;
/// assert_eq!(fixed, dynamic);
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub trait Siso: SingleInput {}

impl<const N: usize, const M: usize, const P: usize, D: Domain> sealed::Sealed
    for StateSpace<N, M, P, D>
{
}

impl<const N: usize, const M: usize, const P: usize, D: Domain> LinearSystem
    for StateSpace<N, M, P, D>
{
    type Domain = D;
    type States = Const<N>;
    type Inputs = Const<M>;
    type Outputs = Const<P>;
    type State = SVector<f64, N>;
    type Input = SVector<f64, M>;

    fn states(&self) -> usize {
        N
    }

    fn inputs(&self) -> usize {
        M
    }

    fn outputs(&self) -> usize {
        P
    }

    fn to_dyn(&self, _: Token) -> Cow<'_, DynStateSpace<D>> {
        Cow::Owned(DynStateSpace::from(self))
    }
}

impl<const N: usize, const P: usize, D: Domain> SingleInput for StateSpace<N, 1, P, D> {}
impl<const N: usize, D: Domain> Siso for StateSpace<N, 1, 1, D> {}

impl<D: Domain> sealed::Sealed for DynStateSpace<D> {}

impl<D: Domain> LinearSystem for DynStateSpace<D> {
    type Domain = D;
    type States = Dyn;
    type Inputs = Dyn;
    type Outputs = Dyn;
    type State = DVector<f64>;
    type Input = DVector<f64>;

    fn states(&self) -> usize {
        DynStateSpace::states(self)
    }

    fn inputs(&self) -> usize {
        DynStateSpace::inputs(self)
    }

    fn outputs(&self) -> usize {
        DynStateSpace::outputs(self)
    }

    fn to_dyn(&self, _: Token) -> Cow<'_, DynStateSpace<D>> {
        Cow::Borrowed(self)
    }
}

impl<D: Domain> SingleInput for DynStateSpace<D> {}
impl<D: Domain> Siso for DynStateSpace<D> {}
