//! State observers: [`Observer`], a discrete Luenberger observer or
//! steady-state Kalman filter, in predictor or current-estimator form.

use nalgebra::{SMatrix, SVector};

use crate::analysis::{eigenvalues, first_unstable};
use crate::error::{Error, check_finite};
use crate::kernels::linalg::Lu;
use crate::model::{Discrete, StateSpace};

/// Which estimate an [`Observer`] hands the control law at sample `k`.
///
/// # Examples
///
/// ```
/// use ctrlab::design::EstimatorForm;
/// assert_ne!(EstimatorForm::Current, EstimatorForm::Predictor);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EstimatorForm {
    /// `x̂[k|k−1]`, predicted from the samples before `k`: the law does not
    /// wait for the new measurement's correction (python-control's `dlqe`
    /// form).
    Predictor,
    /// `x̂[k|k] = x̂[k|k−1] + M (y[k] − C x̂[k|k−1])` with `M = A⁻¹ L`:
    /// corrected by the measurement just taken, a period fresher (MATLAB's
    /// `dlqe` `M`, the "current estimator" of Franklin, Powell and
    /// Workman). Needs an invertible `A` (any ZOH model has one) and
    /// `D = 0`.
    Current,
}

/// A discrete state observer on a model `x[k+1] = A x[k] + B u[k]`,
/// `y[k] = C x[k] + D u[k]`, with gain `L` (`N × P`): a Luenberger observer
/// (`L` from [`place_observer`](crate::design::place_observer)) or a
/// steady-state Kalman filter (`L` the [`dlqe`](crate::design::dlqe)
/// gain). Every period it is corrected with the measurements and then
/// advanced with the input that was applied:
///
/// ```text
/// correct(y[k]):   ν = y[k] − C x̂[k|k−1]
///                  returns x̂[k|k−1] (Predictor) or x̂[k|k] = x̂[k|k−1] + A⁻¹L ν (Current)
/// predict(u[k]):   x̂[k+1|k] = A x̂[k|k−1] + B u[k] + L (ν − D u[k])
///                             = (A − L C) x̂[k|k−1] + (B − L D) u[k] + L y[k]
/// ```
///
/// (in the current form `A x̂[k|k] + B u[k]` is the same recursion;
/// `predict` evaluates the second line, with the `y` of the last `correct`,
/// zero before the first). The
/// estimation error obeys `e[k+1] = (A − L C) e[k]` in both forms, so its
/// poles are the eigenvalues of `A − L C`, checked stable on construction.
/// The estimate starts at zero (the rig's carts at rest at the origin).
/// `correct` and `predict` allocate nothing.
///
/// # Examples
///
/// ```
/// use ctrlab::{MassSpring, Cart, Discretization, lab};
/// use ctrlab::design::{EstimatorForm, Observer, place_observer};
/// use ctrlab::nalgebra::{Complex, matrix, vector};
///
/// let plant = MassSpring::nominal().state_space(Cart::Two)?
///     .with_output(lab::position_output_matrix(), matrix![0.0; 0.0])?
///     .discretize(0.002, Discretization::Zoh)?;
/// let poles = [0.6, 0.6, 0.7, 0.7].map(|z| Complex::new(z, 0.0));
/// let mut obs = Observer::new(&plant, place_observer(&plant, &poles)?, EstimatorForm::Current)?;
///
/// // The true plant starts displaced; the observer at zero catches up.
/// let mut x = vector![0.001, 0.0, 0.002, 0.0];
/// for _ in 0..100 {
///     obs.correct(&(plant.c() * x));
///     obs.predict(&vector![0.5]);
///     x = plant.advance(&x, &vector![0.5]);
/// }
/// let estimate = obs.correct(&(plant.c() * x));
/// assert!((estimate - x).norm() < 1e-12);
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Observer<const N: usize, const M: usize, const P: usize> {
    model: StateSpace<N, M, P, Discrete>,
    gain: SMatrix<f64, N, P>,
    /// `A⁻¹ L` in the current form, zero in the predictor form.
    correction: SMatrix<f64, N, P>,
    // A − L C and B − L D: `predict` as x̂⁺ = (A − L C) x̂ + (B − L D) u + L y,
    // whose chain from one prediction to the next is one product long.
    error_dynamics: SMatrix<f64, N, N>,
    input_path: SMatrix<f64, N, M>,
    form: EstimatorForm,
    prior: SVector<f64, N>,
    // The prediction the last `correct` started from, with its `measured`:
    // the estimate is formed from them only when asked for.
    corrected_from: SVector<f64, N>,
    measured: SVector<f64, P>,
}

impl<const N: usize, const M: usize, const P: usize> Observer<N, M, P> {
    /// The observer of `model` (its outputs are the measurements) with the
    /// predictor gain `gain` (`L`, as [`place_observer`] and
    /// [`dlqe`](crate::design::dlqe) return it), handing out estimates in
    /// `form`.
    ///
    /// [`place_observer`]: crate::design::place_observer
    ///
    /// # Errors
    ///
    /// [`Error::NonFinite`] naming `"L"` for a non-finite gain;
    /// [`Error::Overflow`] if `A − L C`, `B − L D` or (current form) `A⁻¹ L`
    /// overflows; [`Error::Unstable`] if `A − L C` has a pole on or outside the unit
    /// circle (the estimate would not converge); for
    /// [`EstimatorForm::Current`], [`Error::InvalidMatrix`] named `"D"`
    /// unless `D = 0`, and [`Error::Singular`] for a singular `A`.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{Error, StateSpace, design::{EstimatorForm, Observer}};
    /// use ctrlab::nalgebra::matrix;
    ///
    /// let model = StateSpace::discrete(matrix![1.0], matrix![0.1], matrix![1.0], matrix![0.0], 0.1)?;
    /// assert!(Observer::new(&model, matrix![0.5], EstimatorForm::Predictor).is_ok());
    /// // A − L C = 1 − 2.5 = −1.5: the estimate would diverge.
    /// let err = Observer::new(&model, matrix![2.5], EstimatorForm::Predictor).unwrap_err();
    /// assert!(matches!(err, Error::Unstable { .. }));
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn new(
        model: &StateSpace<N, M, P, Discrete>,
        gain: SMatrix<f64, N, P>,
        form: EstimatorForm,
    ) -> Result<Self, Error> {
        check_finite("L", &gain)?;
        let error_dynamics = finite(
            model.a() - gain * model.c(),
            "observer: A − L C (the gain L overflows the error dynamics)",
        )?;
        let input_path = finite(
            model.b() - gain * model.d(),
            "observer: B − L D (the gain L overflows the input path)",
        )?;
        let poles = eigenvalues(&error_dynamics)?;
        if let Some(p) = first_unstable(&poles, &error_dynamics, Some(model.dt())) {
            return Err(Error::Unstable {
                operation: "observer: the estimation error (A − L C) does not decay",
                re: p.re,
                im: p.im,
            });
        }
        let correction = match form {
            EstimatorForm::Predictor => SMatrix::zeros(),
            EstimatorForm::Current => {
                if model.d().iter().any(|&v| v != 0.0) {
                    return Err(Error::InvalidMatrix {
                        matrix: "D",
                        reason: "the current-estimator form needs D = 0 (the input depends on \
                                 the estimate)",
                    });
                }
                finite(
                    Lu::new(model.a(), "current estimator (A⁻¹ L)")?.solve(&gain),
                    "current estimator: A⁻¹ L (the gain L is too large for this A)",
                )?
            }
        };
        Ok(Self {
            model: *model,
            gain,
            correction,
            error_dynamics,
            input_path,
            form,
            prior: SVector::zeros(),
            corrected_from: SVector::zeros(),
            measured: SVector::zeros(),
        })
    }

    /// The measurement update at a sampling instant: takes `y[k]` and
    /// returns the estimate for the control law (see [`EstimatorForm`]).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{StateSpace, design::{EstimatorForm, Observer}};
    /// use ctrlab::nalgebra::{matrix, vector};
    /// let model = StateSpace::discrete(matrix![1.0], matrix![0.1], matrix![1.0], matrix![0.0], 0.1)?;
    /// let mut obs = Observer::new(&model, matrix![0.5], EstimatorForm::Current)?;
    /// // x̂[0|−1] = 0; corrected by A⁻¹ L (2 − 0) = 1.
    /// assert_eq!(obs.correct(&vector![2.0]), vector![1.0]);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[inline]
    pub fn correct(&mut self, y: &SVector<f64, P>) -> SVector<f64, N> {
        self.measure(y);
        self.estimate()
    }

    /// `correct` without forming the estimate (the compensator's input does
    /// not go through it).
    #[inline]
    pub(crate) fn measure(&mut self, y: &SVector<f64, P>) {
        self.measured = *y;
        self.corrected_from = self.prior;
    }

    /// The time update after the input `u[k]` was applied: the prediction
    /// `x̂[k+1|k]` for the next sample.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{StateSpace, design::{EstimatorForm, Observer}};
    /// use ctrlab::nalgebra::{matrix, vector};
    /// let model = StateSpace::discrete(matrix![1.0], matrix![0.1], matrix![1.0], matrix![0.0], 0.1)?;
    /// let mut obs = Observer::new(&model, matrix![0.5], EstimatorForm::Predictor)?;
    /// obs.correct(&vector![2.0]);
    /// obs.predict(&vector![10.0]);
    /// // A·0 + B·10 + L·(2 − 0) = 1 + 1.
    /// assert_eq!(obs.correct(&vector![0.0]), vector![2.0]);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[inline]
    pub fn predict(&mut self, u: &SVector<f64, M>) {
        self.prior =
            self.error_dynamics * self.prior + self.input_path * u + self.gain * self.measured;
    }

    /// The prediction `x̂[k|k−1]` the next `correct` starts from, and the
    /// correction gain `M` (`A⁻¹ L`, or zero in the predictor form).
    pub(crate) fn prior_and_correction(&self) -> (&SVector<f64, N>, &SMatrix<f64, N, P>) {
        (&self.prior, &self.correction)
    }

    /// The estimate at the last [`correct`](Self::correct) (zero before
    /// the first), formed on demand.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{StateSpace, design::{EstimatorForm, Observer}};
    /// use ctrlab::nalgebra::{matrix, vector};
    /// let model = StateSpace::discrete(matrix![1.0], matrix![0.1], matrix![1.0], matrix![0.0], 0.1)?;
    /// let obs = Observer::new(&model, matrix![0.5], EstimatorForm::Current)?;
    /// assert_eq!(obs.estimate(), vector![0.0]);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[inline]
    pub fn estimate(&self) -> SVector<f64, N> {
        let from = self.corrected_from;
        match self.form {
            EstimatorForm::Predictor => from,
            EstimatorForm::Current => {
                from + self.correction * (self.measured - self.model.c() * from)
            }
        }
    }

    /// The model the observer runs on.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{StateSpace, design::{EstimatorForm, Observer}};
    /// use ctrlab::nalgebra::matrix;
    /// let model = StateSpace::discrete(matrix![1.0], matrix![0.1], matrix![1.0], matrix![0.0], 0.1)?;
    /// let obs = Observer::new(&model, matrix![0.5], EstimatorForm::Current)?;
    /// assert_eq!(obs.model().dt(), 0.1);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn model(&self) -> &StateSpace<N, M, P, Discrete> {
        &self.model
    }

    /// Forgets the run: the estimate back to zero.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{StateSpace, design::{EstimatorForm, Observer}};
    /// use ctrlab::nalgebra::{matrix, vector};
    /// let model = StateSpace::discrete(matrix![1.0], matrix![0.1], matrix![1.0], matrix![0.0], 0.1)?;
    /// let mut obs = Observer::new(&model, matrix![0.5], EstimatorForm::Current)?;
    /// obs.correct(&vector![2.0]);
    /// obs.reset();
    /// assert_eq!(obs.estimate(), vector![0.0]);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn reset(&mut self) {
        self.prior = SVector::zeros();
        self.corrected_from = SVector::zeros();
        self.measured = SVector::zeros();
    }
}

/// `m` if every entry is finite, else [`Error::Overflow`] of `operation`
/// (the factors were checked finite: only the product can have overflowed).
pub(crate) fn finite<const R: usize, const C: usize>(
    m: SMatrix<f64, R, C>,
    operation: &'static str,
) -> Result<SMatrix<f64, R, C>, Error> {
    if m.iter().all(|v| v.is_finite()) {
        Ok(m)
    } else {
        Err(Error::Overflow { operation })
    }
}
