//! The lab's per-millimetre gains, [`LabGains`]: the one place millimetres
//! become metres in a controller, and back, so a law designed in SI can be
//! typed into the lab's Simulink model.

use nalgebra::{SMatrix, SVector};

use super::Cart;
use crate::design::StateFeedback;
use crate::error::{Error, check_finite};

/// Millimetres per metre: the lab's gains are per millimetre of state.
const MM_PER_M: f64 = 1000.0;

/// A state-feedback law in the lab's units, `u = Kf (G r − x_mm)` (the
/// lab's Figure 8, `docs/lab.md`): what is typed into the lab's Simulink model, and the SI
/// [`StateFeedback`] it is ([`state_feedback`](Self::state_feedback)) or
/// comes from ([`from_state_feedback`](Self::from_state_feedback)).
///
/// Units: `kf` is `[Kf1, Kf2, Kf3, Kf4]` on `[x1, v1, x2, v2]`, per
/// millimetre of position and per mm/s of speed: on the rig, whose input is
/// the motor's voltage, V/mm and V/(mm/s) (in general, input unit per mm
/// and per mm/s). `g` is the column `G` that maps the setpoint (mm) to a
/// reference state (mm, mm/s), dimensionless: the lab's `G` is
/// `[0, 0, 1, 0]` for cart 2 and `[1, 0, 0, 0]` for cart 1
/// ([`new`](Self::new)); a law with a prefilter scales it.
///
/// # Examples
///
/// ```
/// use ctrlab::{Cart, lab::LabGains};
///
/// // Table 2's row Kf = [0 0 10 0.1]: 10 V/mm on cart 2's position, 0.1 V/(mm/s) on its speed.
/// let lab = LabGains::new([0.0, 0.0, 10.0, 0.1], Cart::Two);
/// assert_eq!(lab, LabGains { kf: [0.0, 0.0, 10.0, 0.1], g: [0.0, 0.0, 1.0, 0.0] });
/// let law = lab.state_feedback()?;
/// assert_eq!(LabGains::from_state_feedback(&law, Cart::Two)?, lab);
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LabGains {
    /// `[Kf1, Kf2, Kf3, Kf4]`: V/mm on the positions and V/(mm/s) on the
    /// speeds (input unit per mm and per mm/s).
    pub kf: [f64; 4],
    /// The reference column `G` (dimensionless).
    pub g: [f64; 4],
}

impl LabGains {
    /// The lab's law on `cart` from its per-millimetre gains
    /// `kf = [Kf1, Kf2, Kf3, Kf4]` (V/mm and V/(mm/s)): `G` selects the
    /// position of `cart`.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{Cart, lab::LabGains};
    /// let lab = LabGains::new([1.0, 0.005, 0.0, 0.0], Cart::One);
    /// assert_eq!(lab.g, [1.0, 0.0, 0.0, 0.0]);
    /// ```
    pub fn new(kf: [f64; 4], cart: Cart) -> Self {
        let mut g = [0.0; 4];
        g[cart.state_index()] = 1.0;
        Self { kf, g }
    }

    /// The same law in SI, `u = N r − K x`: the conversion to SI is done
    /// here and only here, `K = 1000 · Kf` (per metre, per m/s) and
    /// `N = K G` (per metre of setpoint), so
    /// [`update`](crate::Controller::update) takes the reference and the
    /// measured state `[x1, v1, x2, v2]` in metres and m/s. With `r` in
    /// metres, `K (G r − x) = Kf (G r_mm − x_mm)` exactly as in the lab's
    /// diagram.
    ///
    /// # Errors
    ///
    /// [`Error::NonFinite`] naming `"K"` or `"N"` for a non-finite gain.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{Cart, Controller, MassSpring, lab::LabGains};
    /// use ctrlab::nalgebra::{matrix, vector};
    ///
    /// let mut c = LabGains::new([0.0, 0.0, 0.1, 0.0], Cart::Two).state_feedback()?;
    /// // Setpoint 30 mm, cart 2 at 5 mm: u = 0.1 · (30 − 5) = 2.5.
    /// let u = c.update(&vector![0.0025, 0.0, 0.005, 0.0], &vector![0.030]);
    /// assert!((u[0] - 2.5).abs() < 1e-12);
    /// // 0.1 per mm is 100 per metre; N = K G picks cart 2's position gain.
    /// assert_eq!(*c.gain(), matrix![0.0, 0.0, 100.0, 0.0]);
    /// assert_eq!(*c.reference_gain(), vector![100.0]);
    ///
    /// // The lab's law leaves a steady-state error: 30 mm asked, 5 mm reached.
    /// let plant = MassSpring::nominal().state_space(Cart::Two)?;
    /// assert!((c.closed_loop(&plant)?.dc_gain()?[(0, 0)] * 30.0 - 5.0).abs() < 1e-12);
    ///
    /// // Cart 2 toward 1.05 times the setpoint, as a prefilter would ask.
    /// let lab = LabGains { kf: [0.0, 0.0, 1.0, 0.01], g: [0.0, 0.0, 1.05, 0.0] };
    /// let mut law = lab.state_feedback()?;
    /// // u = Kf (G r − x) in mm: 1 · (1.05 · 30 − 20) = 11.5.
    /// let u = law.update(&vector![0.0, 0.0, 0.020, 0.0], &vector![0.030]);
    /// assert!((u[0] - 11.5).abs() < 1e-12);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn state_feedback(&self) -> Result<StateFeedback<4, 1>, Error> {
        let k = SMatrix::<f64, 1, 4>::from_row_slice(&self.kf) * MM_PER_M;
        check_finite("K", &k)?;
        let g = SVector::<f64, 4>::from_row_slice(&self.g);
        StateFeedback::new(k, k * g)
    }

    /// The SI law `u = N r − K x` in the lab's units: `Kf = K / 1000` per
    /// mm (and per mm/s), with `G` the column of `cart` scaled so that
    /// `Kf G` gives back `N`: `G = (N / K_cart) e_cart`, where `K_cart` is
    /// the gain on that cart's position. For a law from
    /// [`state_feedback`](Self::state_feedback) of [`new`](Self::new) on the
    /// same cart, `G` is the lab's selection column; for one with a
    /// prefilter ([`StateFeedback::with_prefilter`], an LQR design) it is
    /// the setpoint scaling the lab's Simulink model needs to reproduce it.
    ///
    /// # Errors
    ///
    /// [`Error::InvalidParameter`] named `"K"` when the gain on `cart`'s
    /// position is zero (no `G` on that cart reproduces `N`, unless `N` is
    /// zero too, when `G = 0`); [`Error::Overflow`] for a non-finite `G`.
    ///
    /// # Examples
    ///
    /// An LQR design with a prefilter, carried to the lab's units:
    ///
    /// ```
    /// use ctrlab::{Cart, MassSpring, StateFeedback, lab::LabGains, lqr};
    /// use ctrlab::nalgebra::{SMatrix, matrix, vector};
    ///
    /// let plant = MassSpring::nominal().state_space(Cart::Two)?;
    /// let q = SMatrix::<f64, 4, 4>::from_diagonal(&vector![0.0, 0.0, 1e6, 0.0]);
    /// let law = StateFeedback::with_prefilter(&plant, lqr(&plant, &q, &matrix![1.0])?.gain)?;
    /// let lab = LabGains::from_state_feedback(&law, Cart::Two)?;
    /// // Kf3 per mm is K3 per metre / 1000; G scales the setpoint.
    /// assert!((lab.kf[2] - law.gain()[2] / 1000.0).abs() < 1e-15);
    /// assert!(lab.g[2] > 1.0 && lab.g[0] == 0.0);
    /// // Back in SI it is the same law.
    /// let again = lab.state_feedback()?;
    /// assert!((again.reference_gain()[0] - law.reference_gain()[0]).abs() < 1e-12);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn from_state_feedback(law: &StateFeedback<4, 1>, cart: Cart) -> Result<Self, Error> {
        let (k, n) = (law.gain(), law.reference_gain()[0]);
        let k_cart = k[cart.state_index()];
        let scale = if n == 0.0 {
            0.0
        } else if k_cart == 0.0 {
            return Err(Error::InvalidParameter {
                name: "K",
                value: k_cart,
                reason: "the gain on the chosen cart's position is zero: no G on that cart \
                         reproduces the reference gain",
            });
        } else {
            n / k_cart
        };
        if !scale.is_finite() {
            return Err(Error::Overflow {
                operation: "lab gains (G = N / K_cart)",
            });
        }
        let mut g = [0.0; 4];
        g[cart.state_index()] = scale;
        Ok(Self {
            kf: [0, 1, 2, 3].map(|i| k[i] / MM_PER_M),
            g,
        })
    }
}
