//! Static state feedback `u = N r − K x`, in the lab's and the textbook's form.

use nalgebra::{SMatrix, SVector};

use crate::design::Controller;
use crate::error::{Error, check_finite};
use crate::model::{Continuous, Discrete, Domain, Output, StateSpace};

/// Millimetres per metre: the lab's gains are per millimetre of state.
const MM_PER_M: f64 = 1000.0;

/// Static state feedback `u = N r − K x` with a scalar reference `r`.
///
/// Both of the lab's forms are this law:
///
/// - the lab's `u = Kf (G r − x)` (LAB.md, Figure 8) is `K = Kf`, `N = Kf G`;
///   [`from_lab_gains`](Self::from_lab_gains) builds it from the lab's
///   per-millimetre gains;
/// - the textbook's `u = N r − K x` with `N` chosen for zero steady-state
///   error is [`with_prefilter`](Self::with_prefilter).
///
/// Everything is stored in SI: `K` in input units per SI state unit (N/m and
/// N·s/m for the lab plant with force input), `N` in input units per metre
/// of reference.
///
/// # Examples
///
/// ```
/// use ctrlab::{Controller, design::StateFeedback};
/// use nalgebra::{matrix, vector};
///
/// let mut c = StateFeedback::new(matrix![2.0, 0.5], vector![3.0])?;
/// assert_eq!(c.update(1.0, &vector![1.0, 2.0]), vector![3.0 - 2.0 - 1.0]);
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StateFeedback<const N: usize, const M: usize> {
    k: SMatrix<f64, M, N>,
    n: SVector<f64, M>,
}

impl<const N: usize, const M: usize> StateFeedback<N, M> {
    /// The law `u = n r − K x` from its two gains, SI units.
    ///
    /// # Errors
    ///
    /// [`Error::NonFinite`] naming `"K"` or `"N"` for a NaN or infinite gain.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{Error, design::StateFeedback};
    /// use nalgebra::{matrix, vector};
    ///
    /// let err = StateFeedback::new(matrix![f64::NAN], vector![1.0]).unwrap_err();
    /// assert!(matches!(err, Error::NonFinite { matrix: "K", .. }));
    /// ```
    pub fn new(k: SMatrix<f64, M, N>, n: SVector<f64, M>) -> Result<Self, Error> {
        check_finite("K", &k)?;
        check_finite("N", &n)?;
        Ok(Self { k, n })
    }

    /// The state gain `K` (SI: input unit per state unit).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{Output, design::StateFeedback};
    /// use nalgebra::matrix;
    ///
    /// let c = StateFeedback::from_lab_gains([0.0, 0.0, 10.0, 0.1], Output::Cart2)?;
    /// // 10 per mm is 10 000 per metre.
    /// assert_eq!(*c.gain(), matrix![0.0, 0.0, 10_000.0, 100.0]);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn gain(&self) -> &SMatrix<f64, M, N> {
        &self.k
    }

    /// The reference gain `N` (input unit per metre of reference).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{Output, design::StateFeedback};
    /// use nalgebra::vector;
    ///
    /// let c = StateFeedback::from_lab_gains([1.0, 0.002, 0.0, 0.0], Output::Cart1)?;
    /// // N = K G: the cart-1 position gain.
    /// assert_eq!(*c.reference_gain(), vector![1000.0]);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn reference_gain(&self) -> &SVector<f64, M> {
        &self.n
    }

    /// The closed loop around `plant`: `A − B K`, input `B N` (the
    /// reference, m for the lab), output `(C − D K) x + D N r` (the plant's
    /// own output: build the lab plant with the same [`Output`] the gains
    /// control). Works for continuous and discrete plants alike.
    ///
    /// # Errors
    ///
    /// [`Error::Overflow`] if the product overflows.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{MassSpring, Output, design::StateFeedback};
    ///
    /// let plant = MassSpring::nominal().state_space(Output::Cart2)?;
    /// let cl = StateFeedback::from_lab_gains([0.0, 0.0, 0.1, 0.0], Output::Cart2)?.closed_loop(&plant)?;
    /// // The lab's law leaves a steady-state error: 30 mm asked, 5 mm reached.
    /// assert!((cl.dc_gain()?[(0, 0)] * 30.0 - 5.0).abs() < 1e-12);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn closed_loop<const P: usize, D: Domain>(
        &self,
        plant: &StateSpace<N, M, P, D>,
    ) -> Result<StateSpace<N, 1, P, D>, Error> {
        let a = plant.a() - plant.b() * self.k;
        let b = plant.b() * self.n;
        let c = plant.c() - plant.d() * self.k;
        let d = plant.d() * self.n;
        let overflow = |_| Error::Overflow {
            operation: "closed loop",
        };
        check_finite("A", &a).map_err(overflow)?;
        check_finite("B", &b).map_err(overflow)?;
        check_finite("C", &c).map_err(overflow)?;
        check_finite("D", &d).map_err(overflow)?;
        Ok(StateSpace::from_parts_unchecked(a, b, c, d, plant.domain()))
    }
}

impl StateFeedback<4, 1> {
    /// The lab's law `u = Kf (G r − x_mm)` from its per-millimetre gains
    /// `[Kf1, Kf2, Kf3, Kf4]` (input unit per mm and per mm/s), with `G`
    /// selecting the position of `output`'s cart.
    ///
    /// The conversion to SI is done here and only here: `K = 1000 · Kf` (per
    /// metre), and `N = K G`, so [`update`](Controller::update) takes the
    /// reference and the state in metres. With `r` in metres,
    /// `K (G r − x) = Kf (G r_mm − x_mm)` exactly as in the lab's diagram.
    ///
    /// # Errors
    ///
    /// [`Error::NonFinite`] naming `"K"` for a NaN or infinite gain.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{Controller, Output, design::StateFeedback};
    /// use nalgebra::vector;
    ///
    /// let mut c = StateFeedback::from_lab_gains([0.0, 0.0, 0.1, 0.0], Output::Cart2)?;
    /// // Setpoint 30 mm, cart 2 at 5 mm: u = 0.1 · (30 − 5) = 2.5.
    /// let u = c.update(0.030, &vector![0.0025, 0.0, 0.005, 0.0]);
    /// assert!((u[0] - 2.5).abs() < 1e-12);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn from_lab_gains(kf: [f64; 4], output: Output) -> Result<Self, Error> {
        let k = SMatrix::<f64, 1, 4>::from_row_slice(&kf) * MM_PER_M;
        check_finite("K", &k)?;
        let n = SVector::<f64, 1>::new(k[output.state_index()]);
        Self::new(k, n)
    }
}

impl<const N: usize> StateFeedback<N, 1> {
    /// The textbook law `u = N r − K x` on a continuous single-input,
    /// single-output plant, with `N = 1 / G_cl(0)` chosen so the output
    /// settles exactly at the reference (`G_cl(0)` is the DC gain of the
    /// closed loop with `N = 1`). This zero error holds only for the nominal
    /// plant; the closed loop should be stable for it to mean anything.
    ///
    /// # Errors
    ///
    /// [`Error::NonFinite`] for a non-finite `k`; [`Error::Singular`] when
    /// the closed loop has a pole at `s = 0` or zero DC gain (no `N` can fix
    /// the error).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{MassSpring, Output, design::StateFeedback};
    /// use nalgebra::matrix;
    ///
    /// let plant = MassSpring::nominal().state_space(Output::Cart2)?;
    /// let c = StateFeedback::with_prefilter(&plant, matrix![0.0, 0.0, 100.0, 0.0])?;
    /// assert!((c.closed_loop(&plant)?.dc_gain()?[(0, 0)] - 1.0).abs() < 1e-12);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn with_prefilter(
        plant: &StateSpace<N, 1, 1, Continuous>,
        k: SMatrix<f64, 1, N>,
    ) -> Result<Self, Error> {
        let unit = Self::new(k, SVector::<f64, 1>::new(1.0))?;
        Self::prefilter(k, unit.closed_loop(plant)?.dc_gain()?[(0, 0)])
    }

    /// [`with_prefilter`](Self::with_prefilter) for a discrete plant (e.g.
    /// with a gain from [`dlqr`](crate::design::dlqr)): `N = 1 / G_cl(z = 1)`.
    ///
    /// # Errors
    ///
    /// As [`with_prefilter`](Self::with_prefilter), with the pole at `z = 1`.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{StateSpace, design::StateFeedback};
    /// use nalgebra::matrix;
    ///
    /// let plant = StateSpace::discrete(matrix![1.0], matrix![0.5], matrix![1.0], matrix![0.0], 0.1)?;
    /// let c = StateFeedback::with_prefilter_discrete(&plant, matrix![1.0])?;
    /// assert!((c.closed_loop(&plant)?.dc_gain()?[(0, 0)] - 1.0).abs() < 1e-12);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn with_prefilter_discrete(
        plant: &StateSpace<N, 1, 1, Discrete>,
        k: SMatrix<f64, 1, N>,
    ) -> Result<Self, Error> {
        let unit = Self::new(k, SVector::<f64, 1>::new(1.0))?;
        Self::prefilter(k, unit.closed_loop(plant)?.dc_gain()?[(0, 0)])
    }

    fn prefilter(k: SMatrix<f64, 1, N>, dc: f64) -> Result<Self, Error> {
        let n = 1.0 / dc;
        if dc == 0.0 || !n.is_finite() {
            return Err(Error::Singular {
                operation: "prefilter (closed loop has zero DC gain)",
            });
        }
        Self::new(k, SVector::<f64, 1>::new(n))
    }
}

impl<const N: usize, const M: usize> Controller<N, M> for StateFeedback<N, M> {
    /// `u = N r − K x`; a handful of multiply-adds, no allocation.
    #[inline]
    fn update(&mut self, reference: f64, state: &SVector<f64, N>) -> SVector<f64, M> {
        self.n * reference - self.k * state
    }
}
