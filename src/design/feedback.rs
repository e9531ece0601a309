//! Static state feedback `u = N r − K x`.

use nalgebra::{SMatrix, SVector};

use crate::design::Controller;
use crate::error::{Error, check_finite};
use crate::model::{Domain, StateSpace};

/// Static state feedback `u = N r − K x` on a measured state `x` (`N`
/// values), with `R` references (one by default) and `M` inputs.
///
/// The textbook's law with `N` chosen for zero steady-state error is
/// [`with_prefilter`](Self::with_prefilter). The lab's `u = Kf (G r − x)`
/// (the lab's Figure 8, `docs/lab.md`) is the same law with `K = Kf`, `N = Kf G`; the lab
/// module's [`LabGains`](crate::lab) builds it from the lab's
/// per-millimetre gains.
///
/// Everything is stored in SI: `K` in input units per SI state unit (N/m and
/// N·s/m for the lab plant with force input), `N` in input units per SI unit
/// of reference.
///
/// As a [`Controller`], its measurements are the full state (`P = N`).
///
/// # Examples
///
/// ```
/// use ctrlab::{Controller, design::StateFeedback};
/// use ctrlab::nalgebra::{matrix, vector};
///
/// let mut c = StateFeedback::new(matrix![2.0, 0.5], vector![3.0])?;
/// assert_eq!(c.update(&vector![1.0, 2.0], &vector![1.0]), vector![3.0 - 2.0 - 1.0]);
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StateFeedback<const N: usize, const M: usize, const R: usize = 1> {
    k: SMatrix<f64, M, N>,
    n: SMatrix<f64, M, R>,
}

impl<const N: usize, const M: usize, const R: usize> StateFeedback<N, M, R> {
    /// The law `u = N r − K x` from its two gains, SI units.
    ///
    /// # Errors
    ///
    /// [`Error::NonFinite`] naming `"K"` or `"N"` for a NaN or infinite gain.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{Error, design::StateFeedback};
    /// use ctrlab::nalgebra::{matrix, vector};
    ///
    /// let err = StateFeedback::new(matrix![f64::NAN], vector![1.0]).unwrap_err();
    /// assert!(matches!(err, Error::NonFinite { matrix: "K", .. }));
    /// ```
    pub fn new(k: SMatrix<f64, M, N>, n: SMatrix<f64, M, R>) -> Result<Self, Error> {
        check_finite("K", &k)?;
        check_finite("N", &n)?;
        Ok(Self { k, n })
    }

    /// The state gain `K` (SI: input unit per state unit).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::design::StateFeedback;
    /// use ctrlab::nalgebra::{matrix, vector};
    ///
    /// let c = StateFeedback::new(matrix![10.0, 0.1], vector![10.0])?;
    /// assert_eq!(*c.gain(), matrix![10.0, 0.1]);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn gain(&self) -> &SMatrix<f64, M, N> {
        &self.k
    }

    /// The reference gain `N` (input unit per SI unit of reference).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::design::StateFeedback;
    /// use ctrlab::nalgebra::{matrix, vector};
    ///
    /// let c = StateFeedback::new(matrix![10.0, 0.1], vector![10.0])?;
    /// assert_eq!(*c.reference_gain(), vector![10.0]);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn reference_gain(&self) -> &SMatrix<f64, M, R> {
        &self.n
    }

    /// The closed loop around `plant`: `A − B K`, input `B N` (the
    /// reference), output `(C − D K) x + D N r` (the plant's own output).
    /// Works for continuous and discrete plants alike. MATLAB's and
    /// python-control's `feedback` for this law.
    ///
    /// # Errors
    ///
    /// [`Error::Overflow`] if the product overflows.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{StateSpace, design::StateFeedback};
    /// use ctrlab::nalgebra::{matrix, vector};
    ///
    /// // A lag x' = −x + u under u = r − 3x: x' = −4x + r, DC gain 1/4.
    /// let plant = StateSpace::continuous(matrix![-1.0], matrix![1.0], matrix![1.0], matrix![0.0])?;
    /// let cl = StateFeedback::new(matrix![3.0], vector![1.0])?.closed_loop(&plant)?;
    /// assert_eq!(*cl.a(), matrix![-4.0]);
    /// assert!((cl.dc_gain()?[(0, 0)] - 0.25).abs() < 1e-15);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    #[doc(alias = "feedback")]
    pub fn closed_loop<const P: usize, D: Domain>(
        &self,
        plant: &StateSpace<N, M, P, D>,
    ) -> Result<StateSpace<N, R, P, D>, Error> {
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

impl<const N: usize> StateFeedback<N, 1, 1> {
    /// The textbook law `u = N r − K x` on a single-input, single-output
    /// plant, continuous or discrete (e.g. with a gain from
    /// [`dlqr`](crate::design::dlqr)), with `N = 1 / G_cl(0)` chosen so the
    /// output settles exactly at the reference (`G_cl(0)` is the DC gain of
    /// the closed loop with `N = 1`: at `s = 0` or `z = 1`). This zero error
    /// holds only for the nominal plant; the closed loop should be stable for
    /// it to mean anything.
    ///
    /// # Errors
    ///
    /// [`Error::NonFinite`] for a non-finite `k`; [`Error::Singular`] when
    /// the closed loop has a pole at `s = 0` / `z = 1` or zero DC gain (no
    /// `N` can fix the error).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{Cart, MassSpring, Discretization, StateSpace, design::StateFeedback};
    /// use ctrlab::nalgebra::matrix;
    ///
    /// let plant = MassSpring::nominal().state_space(Cart::Two)?;
    /// let c = StateFeedback::with_prefilter(&plant, matrix![0.0, 0.0, 100.0, 0.0])?;
    /// assert!((c.closed_loop(&plant)?.dc_gain()?[(0, 0)] - 1.0).abs() < 1e-12);
    ///
    /// // The same call on a discrete plant.
    /// let d = StateSpace::discrete(matrix![1.0], matrix![0.5], matrix![1.0], matrix![0.0], 0.1)?;
    /// let c = StateFeedback::with_prefilter(&d, matrix![1.0])?;
    /// assert!((c.closed_loop(&d)?.dc_gain()?[(0, 0)] - 1.0).abs() < 1e-12);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn with_prefilter<D: Domain>(
        plant: &StateSpace<N, 1, 1, D>,
        k: SMatrix<f64, 1, N>,
    ) -> Result<Self, Error> {
        let unit = Self::new(k, SVector::<f64, 1>::new(1.0))?;
        let dc = unit.closed_loop(plant)?.dc_gain()?[(0, 0)];
        let n = 1.0 / dc;
        if dc == 0.0 || !n.is_finite() {
            return Err(Error::Singular {
                operation: "prefilter (closed loop has zero DC gain)",
            });
        }
        Self::new(k, SVector::<f64, 1>::new(n))
    }
}

impl<const N: usize, const M: usize, const R: usize> Controller<N, R, M>
    for StateFeedback<N, M, R>
{
    /// `u = N r − K y` with `y` the measured state; a handful of
    /// multiply-adds, no allocation.
    #[inline]
    fn update(&mut self, y: &SVector<f64, N>, r: &SVector<f64, R>) -> SVector<f64, M> {
        self.n * r - self.k * y
    }
}
