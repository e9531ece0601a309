//! [`Prediction`]: what the identified linear model predicts for a row of
//! Tables 5 and 6.

use nalgebra::Complex;

use crate::discretize::Discretization;
use crate::error::Error;
use crate::lab::{Cart, LabGains, MassSpring};

/// What the identified linear model predicts for a row: the closed loop
/// sampled at the rig's period (ZOH, no saturation, no friction) is stable
/// when its spectral radius is below 1; the continuous poles for reference;
/// where a stable loop comes to rest, and how far friction can hold a cart
/// from there.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::{Cart, MassSpring, tables::Prediction};
/// let plant = MassSpring::nominal();
/// let p = Prediction::of(&plant, [0.0, 0.0, 1.0, 0.0], Cart::Two, 0.002)?;
/// assert!(p.is_stable() && p.radius > 0.9);
/// // u = Kf3 (r − x2), with 1 V/mm acting on the springs' 500 N/m in
/// // series (K = 1 N/V): x2 rests at 1000 / 1500 of the setpoint.
/// assert!((p.steady_state_error_mm(30.0) - 10.0).abs() < 1e-9);
/// // Cart 1 through the spring k2 destabilises far sooner.
/// assert!(!Prediction::of(&plant, [2.0, 0.0, 0.0, 0.0], Cart::One, 0.002)?.is_stable());
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Prediction {
    /// The sampled closed loop's spectral radius `max |z|` (< 1: stable).
    pub radius: f64,
    /// The sampled closed loop's pole of largest modulus (`|z| = radius`;
    /// of a conjugate pair, the one with `arg z ≥ 0`).
    pub dominant: Complex<f64>,
    /// The continuous closed loop's poles, 1/s.
    pub poles: [Complex<f64>; 4],
    /// The closed loop's DC gain from the setpoint to the tracked cart's
    /// position (the same sampled or not): where a stable loop rests, as a
    /// fraction of the setpoint.
    pub dc_gain: f64,
    /// How far a constant force of 1 N on cart 1, and on cart 2, moves the
    /// tracked cart's rest position in the closed loop, m/N (signed).
    /// Coulomb friction `F` on a cart can hold it anywhere within
    /// `|compliance| · F` of the linear rest position.
    pub compliance: [f64; 2],
}

impl Prediction {
    /// The prediction for gains `kf` (per mm) on `cart` of `model`, sampled
    /// every `period` s.
    ///
    /// # Errors
    ///
    /// A non-finite gain, an invalid model or period, or an eigenvalue
    /// iteration that fails. A closed loop with a pole at `s = 0` has no
    /// rest position: `dc_gain` and `compliance` are then infinite or NaN.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::{Cart, MassSpring, tables::Prediction};
    /// let plant = MassSpring::nominal();
    /// let p = Prediction::of(&plant, [0.0, 0.0, 10.0, 0.1], Cart::Two, 0.002)?;
    /// // 10 V/mm = 10 000 N/m against the springs' 500 N/m in series.
    /// assert!(p.is_stable() && (p.dc_gain - 10_000.0 / 10_500.0).abs() < 1e-9);
    /// assert!(p.poles.iter().all(|s| s.re < 0.0)); // 1/s
    /// assert!(Prediction::of(&plant, [0.0, 0.0, 10.0, 0.1], Cart::Two, 0.0).is_err());
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn of(model: &MassSpring, kf: [f64; 4], cart: Cart, period: f64) -> Result<Self, Error> {
        let sys = model.state_space(cart)?;
        // The rig samples every period: the loop that can be stable or not
        // is the sampled one, so predict with the ZOH-discretised model.
        let sampled = sys.discretize(period, Discretization::Zoh)?;
        let ctrl = LabGains::new(kf, cart).state_feedback()?;
        let closed = ctrl.closed_loop(&sys)?;
        let poles = closed.poles()?;
        let dominant = ctrl
            .closed_loop(&sampled)?
            .poles()?
            .into_iter()
            .map(|z| if z.im < 0.0 { z.conj() } else { z })
            .fold(Complex::new(0.0, 0.0), |m, z| {
                if z.norm() > m.norm() { z } else { m }
            });
        let dc_gain = closed.dc_gain().map_or(f64::NAN, |g| g[(0, 0)]);
        // At rest a force F on cart i is a constant input F / m_i on its
        // velocity: x = −A⁻¹ e_i F / m_i, read through the output row.
        let compliance = match closed.a().try_inverse() {
            Some(inv) => {
                let at = |state: usize, mass: f64| -(closed.c() * inv.column(state))[0] / mass;
                [at(1, model.m1), at(3, model.m2)]
            }
            None => [f64::NAN; 2],
        };
        Ok(Self {
            radius: dominant.norm(),
            dominant,
            poles,
            dc_gain,
            compliance,
        })
    }

    /// Whether the sampled loop is stable.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::lab::tables::Prediction;
    /// # use ctrlab::nalgebra::Complex;
    /// # let tau = std::f64::consts::TAU;
    /// # // A lightly damped mode of 50 samples per cycle (10 Hz at 2 ms).
    /// # let p = Prediction { radius: 0.99, dominant: Complex::from_polar(0.99, tau / 50.0),
    /// #     poles: [Complex::new(-1.0, 0.0); 4], dc_gain: 0.95, compliance: [-1e-4, 2e-4] };
    /// assert!(p.is_stable());
    /// // A pole on the unit circle never decays: not stable.
    /// assert!(!Prediction { radius: 1.0, ..p }.is_stable());
    /// ```
    pub fn is_stable(&self) -> bool {
        self.radius < 1.0
    }

    /// The linear model's steady-state error for a setpoint of
    /// `setpoint_mm`, mm: `r (1 − dc_gain)`.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::{Cart, MassSpring, tables::Prediction};
    /// let p = Prediction::of(&MassSpring::nominal(), [0.0, 0.0, 10.0, 0.0], Cart::Two, 0.002)?;
    /// // Table 5's 30 mm: short by 30 · 500 / 10 500 mm.
    /// assert!((p.steady_state_error_mm(30.0) - 30.0 / 21.0).abs() < 1e-9);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn steady_state_error_mm(&self, setpoint_mm: f64) -> f64 {
        setpoint_mm * (1.0 - self.dc_gain)
    }

    /// How far Coulomb friction `coulomb` (N on cart 1 and cart 2) can hold
    /// the tracked cart from the linear rest position, mm.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::lab::tables::Prediction;
    /// # use ctrlab::nalgebra::Complex;
    /// # let tau = std::f64::consts::TAU;
    /// # // A lightly damped mode of 50 samples per cycle (10 Hz at 2 ms).
    /// # let p = Prediction { radius: 0.99, dominant: Complex::from_polar(0.99, tau / 50.0),
    /// #     poles: [Complex::new(-1.0, 0.0); 4], dc_gain: 0.95, compliance: [-1e-4, 2e-4] };
    /// // |−0.1 mm/N| · 0.5 N + 0.2 mm/N · 1 N.
    /// assert!((p.friction_band_mm([0.5, 1.0]) - 0.25).abs() < 1e-12);
    /// assert_eq!(p.friction_band_mm([0.0; 2]), 0.0); // no friction, no band
    /// ```
    pub fn friction_band_mm(&self, coulomb: [f64; 2]) -> f64 {
        1e3 * (self.compliance[0].abs() * coulomb[0] + self.compliance[1].abs() * coulomb[1])
    }

    /// How much the sampled loop's slowest-decaying (or growing) mode's
    /// amplitude changes over one of its cycles: `radius^(2π / arg z)`,
    /// e.g. 1.18 for 18 % growth per cycle; `None` for a real pole.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::lab::tables::Prediction;
    /// # use ctrlab::nalgebra::Complex;
    /// # let tau = std::f64::consts::TAU;
    /// # // A lightly damped mode of 50 samples per cycle (10 Hz at 2 ms).
    /// # let p = Prediction { radius: 0.99, dominant: Complex::from_polar(0.99, tau / 50.0),
    /// #     poles: [Complex::new(-1.0, 0.0); 4], dc_gain: 0.95, compliance: [-1e-4, 2e-4] };
    /// // 0.99 per sample over 50 samples: 40 % of the amplitude is gone per cycle.
    /// assert!((p.per_cycle().unwrap() - 0.99f64.powi(50)).abs() < 1e-12);
    /// let real = Prediction { dominant: Complex::new(0.99, 0.0), ..p };
    /// assert_eq!(real.per_cycle(), None);
    /// ```
    pub fn per_cycle(&self) -> Option<f64> {
        let angle = self.dominant.arg();
        (angle > 1e-9).then(|| self.radius.powf(std::f64::consts::TAU / angle))
    }

    /// The dominant mode's frequency, rad/s, on a rig sampled every
    /// `period` s.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::lab::tables::Prediction;
    /// # use ctrlab::nalgebra::Complex;
    /// # let tau = std::f64::consts::TAU;
    /// # // A lightly damped mode of 50 samples per cycle (10 Hz at 2 ms).
    /// # let p = Prediction { radius: 0.99, dominant: Complex::from_polar(0.99, tau / 50.0),
    /// #     poles: [Complex::new(-1.0, 0.0); 4], dc_gain: 0.95, compliance: [-1e-4, 2e-4] };
    /// let w = p.dominant_frequency(0.002); // rad/s
    /// assert!((w / tau - 10.0).abs() < 1e-9); // 10 Hz
    /// ```
    pub fn dominant_frequency(&self, period: f64) -> f64 {
        self.dominant.arg() / period
    }
}
