//! Output feedback: the observer-based compensator with integral action
//! ([`ObserverController`]) and the adaptor that picks the measurements a
//! controller uses ([`SelectOutputs`]).

use nalgebra::{SMatrix, SVector};

use super::integral::{AntiWindup, IntegralLaw};
use super::observer::Observer;
use crate::design::Controller;
use crate::error::{Error, check_finite};

/// An observer-based compensator with integral action: state feedback on
/// the [`Observer`]'s estimate plus integrators of measured outputs, the
/// controller an [`lqi`](crate::design::lqi)/[`dlqi`](crate::design::dlqi)
/// design with a Kalman filter ([`dlqe`](crate::design::dlqe)) or
/// Luenberger observer runs as when only some outputs are measured
/// (`Q` of them, e.g. the two carts' positions; `Q < N`):
///
/// ```text
/// x̂[k]   = observer.correct(y[k])                    (see EstimatorForm)
/// u[k]   = −K_x x̂[k] − K_z z[k]
/// z[k+1] = z[k] + T (r[k] − H y[k] − H D u[k])        (+ anti-windup)
/// observer.predict(u_applied[k])
/// ```
///
/// `H` (`I × Q`) picks the integrated outputs out of the measurements, so
/// the integrators act on what is *measured*, not on the estimate: with a
/// constant disturbance the model does not know (Coulomb friction, a wrong
/// gain), the measured outputs still settle at the reference. The LQI gain
/// must have been designed on the plant with outputs `H C` (`H C` of the
/// observer's model: [`StateSpace::with_output`](crate::StateSpace::with_output)).
/// The observer is advanced with the input actually applied
/// ([`Controller::applied`]), so saturation does not corrupt the estimate,
/// and the integrators follow [`AntiWindup`]. `update` and `applied`
/// allocate nothing.
///
/// Its measurements are the `Q` the observer's model outputs; to run it on
/// a loop that measures more (the lab's rig reports `[x1, v1, x2, v2]`, the
/// speeds differenced from counts), wrap it in [`SelectOutputs`].
///
/// # Examples
///
/// Cart 2 of the lab, positions measured, LQI with a Kalman filter, on the
/// model itself:
///
/// ```
/// use ctrlab::{Controller, MassSpring, Cart, Discretization, lab};
/// use ctrlab::design::{AntiWindup, EstimatorForm, Observer, ObserverController, dlqe, dlqi};
/// use ctrlab::nalgebra::{SMatrix, matrix, vector};
///
/// let model = MassSpring::nominal().state_space(Cart::Two)?
///     .with_output(lab::position_output_matrix(), matrix![0.0; 0.0])?
///     .discretize(0.002, Discretization::Zoh)?;
/// // Integrate x2, the second measurement.
/// let h = matrix![0.0, 1.0];
/// let tracked = model.with_output(h * model.c(), matrix![0.0])?;
/// let q = SMatrix::<f64, 5, 5>::from_diagonal(&vector![0.0, 0.0, 1e6, 0.0, 1e8]);
/// let lqi = dlqi(&tracked, &q, &matrix![1.0])?;
/// let kf = dlqe(&model, model.b(), &matrix![1.0], &(SMatrix::<f64, 2, 2>::identity() * 1e-10))?;
/// let observer = Observer::new(&model, kf.gain, EstimatorForm::Current)?;
/// let mut c = ObserverController::new(observer, &lqi.gain, h, AntiWindup::None)?;
///
/// let mut x = vector![0.0, 0.0, 0.0, 0.0];
/// for _ in 0..3000 {
///     let u = c.update(&(model.c() * x), &vector![0.030]);
///     c.applied(&u);
///     x = model.advance(&x, &u);
/// }
/// assert!((x[2] - 0.030).abs() < 1e-9);
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ObserverController<const N: usize, const M: usize, const Q: usize, const I: usize> {
    observer: Observer<N, M, Q>,
    law: IntegralLaw<N, M, I>,
    h: SMatrix<f64, I, Q>,
    // K_x x̂ = K_x (I − M C) x̂⁻ + K_x M y: the input does not wait for the
    // estimate (the 2 ms loop's latency, and half the update's cost).
    through_prior: SMatrix<f64, M, N>,
    through_measurement: SMatrix<f64, M, Q>,
}

impl<const N: usize, const M: usize, const Q: usize, const I: usize>
    ObserverController<N, M, Q, I>
{
    /// The compensator from its `observer` (whose model's outputs are the
    /// measurements and whose period it runs at), the augmented gain
    /// `gain = [K_x K_z]` (`NA = N + I` columns; a mismatch is a
    /// compile-time error), the selection `integrate` (`H`, `I × Q`) of the
    /// integrated outputs among the measurements, and the anti-windup.
    ///
    /// # Errors
    ///
    /// [`Error::NonFinite`] naming `"K"` or `"H"`; [`Error::InvalidParameter`]
    /// named `"tracking"` or `"deadband"`, and [`Error::Overflow`] (of
    /// `T H D` or the back-calculation gain), as
    /// [`IntegralFeedback::new`](crate::design::IntegralFeedback::new).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{Controller, StateSpace};
    /// use ctrlab::design::{AntiWindup, EstimatorForm, Observer, ObserverController};
    /// use ctrlab::nalgebra::{matrix, vector};
    ///
    /// // A double integrator at 0.1 s, position measured.
    /// let model = StateSpace::discrete(matrix![1.0, 0.1; 0.0, 1.0], matrix![0.005; 0.1],
    ///                                  matrix![1.0, 0.0], matrix![0.0], 0.1)?;
    /// let observer = Observer::new(&model, matrix![1.0; 2.0], EstimatorForm::Predictor)?;
    /// let c = ObserverController::new(observer, &matrix![1.0, 1.5, -0.5], matrix![1.0],
    ///                                 AntiWindup::BackCalculation { tracking: 0.5, deadband: 0.0 })?;
    /// assert_eq!(c.period(), Some(0.1));
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn new<const NA: usize>(
        observer: Observer<N, M, Q>,
        gain: &SMatrix<f64, M, NA>,
        integrate: SMatrix<f64, I, Q>,
        anti_windup: AntiWindup,
    ) -> Result<Self, Error> {
        check_finite("H", &integrate)?;
        let model = observer.model();
        let law = IntegralLaw::new(gain, &(integrate * model.d()), model.dt(), anti_windup)?;
        let (_, correction) = observer.prior_and_correction();
        let through_measurement = law.kx() * correction;
        let through_prior = law.kx() - through_measurement * model.c();
        check_finite("K", &through_prior)?;
        check_finite("K", &through_measurement)?;
        Ok(Self {
            observer,
            law,
            h: integrate,
            through_prior,
            through_measurement,
        })
    }

    /// The observer, with its current estimate.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{StateSpace, design::{AntiWindup, EstimatorForm, Observer, ObserverController}};
    /// use ctrlab::nalgebra::{matrix, vector};
    /// let model = StateSpace::discrete(matrix![1.0, 0.1; 0.0, 1.0], matrix![0.005; 0.1],
    ///                                  matrix![1.0, 0.0], matrix![0.0], 0.1)?;
    /// let observer = Observer::new(&model, matrix![1.0; 2.0], EstimatorForm::Predictor)?;
    /// let c = ObserverController::new(observer, &matrix![1.0, 1.5, -0.5], matrix![1.0], AntiWindup::None)?;
    /// assert_eq!(c.observer().estimate(), vector![0.0, 0.0]);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn observer(&self) -> &Observer<N, M, Q> {
        &self.observer
    }

    /// The integrators' state `z` (integrated error, output unit · s).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{StateSpace, design::{AntiWindup, EstimatorForm, Observer, ObserverController}};
    /// use ctrlab::nalgebra::matrix;
    /// let model = StateSpace::discrete(matrix![1.0, 0.1; 0.0, 1.0], matrix![0.005; 0.1],
    ///                                  matrix![1.0, 0.0], matrix![0.0], 0.1)?;
    /// let observer = Observer::new(&model, matrix![1.0; 2.0], EstimatorForm::Predictor)?;
    /// let c = ObserverController::new(observer, &matrix![1.0, 1.5, -0.5], matrix![1.0], AntiWindup::None)?;
    /// assert_eq!(c.integrators()[0], 0.0);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn integrators(&self) -> &SVector<f64, I> {
        self.law.integrators()
    }
}

impl<const N: usize, const M: usize, const Q: usize, const I: usize> Controller<Q, I, M>
    for ObserverController<N, M, Q, I>
{
    #[inline]
    fn update(&mut self, y: &SVector<f64, Q>, r: &SVector<f64, I>) -> SVector<f64, M> {
        let (prior, _) = self.observer.prior_and_correction();
        let kx_x = self.through_prior * prior + self.through_measurement * y;
        // The estimate itself is not on the input's path: `observer()`
        // forms it when asked.
        self.observer.measure(y);
        self.law.update_feedback(&kx_x, &(self.h * y), r)
    }

    #[inline]
    fn applied(&mut self, u: &SVector<f64, M>) {
        // A copy, so the writes below need not reload `u` through memory.
        let u = *u;
        self.law.applied(&u);
        self.observer.predict(&u);
    }

    fn reset(&mut self) {
        self.law.reset();
        self.observer.reset();
    }

    fn period(&self) -> Option<f64> {
        Some(self.law.period())
    }
}

/// A controller that uses only some of the measurements it is given: the
/// loop's `P` measurements `y` are mapped to `S y` (`Q` of them, `S` a
/// `Q × P` matrix, usually a selection of rows of the identity) before the
/// inner controller sees them. Everything else passes through.
///
/// On the lab's rig, whose measurements are `[x1, v1, x2, v2]` with the
/// speeds differenced from encoder counts (one count per 2 ms is 4.9 mm/s),
/// `SelectOutputs::new(c, lab::position_output_matrix())` runs an observer-based
/// controller on the positions alone.
///
/// # Examples
///
/// ```
/// use ctrlab::{Controller, StateFeedback, design::SelectOutputs};
/// use ctrlab::nalgebra::{matrix, vector};
///
/// // A law on [x1, x2] only, given the rig's four measurements.
/// let law = StateFeedback::new(matrix![1.0, 2.0], vector![0.0])?;
/// let mut c = SelectOutputs::new(law, ctrlab::lab::position_output_matrix())?;
/// let u = c.update(&vector![0.1, 99.0, 0.2, -99.0], &vector![0.0]);
/// assert!((u[0] + 0.5).abs() < 1e-15); // the speeds are ignored
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SelectOutputs<C, const P: usize, const Q: usize> {
    inner: C,
    selection: SMatrix<f64, Q, P>,
}

impl<C, const P: usize, const Q: usize> SelectOutputs<C, P, Q> {
    /// `inner` fed with `selection · y`.
    ///
    /// # Errors
    ///
    /// [`Error::NonFinite`] naming `"S"` for a non-finite selection.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{OpenLoop, design::SelectOutputs};
    /// use ctrlab::nalgebra::matrix;
    /// let err = SelectOutputs::new(OpenLoop, matrix![f64::NAN, 0.0]).unwrap_err();
    /// assert!(matches!(err, ctrlab::Error::NonFinite { matrix: "S", .. }));
    /// ```
    pub fn new(inner: C, selection: SMatrix<f64, Q, P>) -> Result<Self, Error> {
        check_finite("S", &selection)?;
        Ok(Self { inner, selection })
    }

    /// The inner controller.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{OpenLoop, design::SelectOutputs};
    /// let c = SelectOutputs::new(OpenLoop, ctrlab::lab::position_output_matrix())?;
    /// assert_eq!(*c.inner(), OpenLoop);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn inner(&self) -> &C {
        &self.inner
    }

    /// The inner controller, to change (an MPC's limits mid-run).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{OpenLoop, design::SelectOutputs};
    /// let mut c = SelectOutputs::new(OpenLoop, ctrlab::lab::position_output_matrix())?;
    /// *c.inner_mut() = OpenLoop;
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn inner_mut(&mut self) -> &mut C {
        &mut self.inner
    }
}

impl<C, const P: usize, const Q: usize, const R: usize, const M: usize> Controller<P, R, M>
    for SelectOutputs<C, P, Q>
where
    C: Controller<Q, R, M>,
{
    #[inline]
    fn update(&mut self, y: &SVector<f64, P>, r: &SVector<f64, R>) -> SVector<f64, M> {
        self.inner.update(&(self.selection * y), r)
    }

    #[inline]
    fn applied(&mut self, u: &SVector<f64, M>) {
        self.inner.applied(u);
    }

    fn reset(&mut self) {
        self.inner.reset();
    }

    fn period(&self) -> Option<f64> {
        self.inner.period()
    }
}
