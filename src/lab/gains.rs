//! The lab's per-millimetre gains: the one place millimetres become metres
//! in a controller.

use nalgebra::{SMatrix, SVector};

use super::Cart;
use crate::design::StateFeedback;
use crate::error::{Error, check_finite};

/// Millimetres per metre: the lab's gains are per millimetre of state.
const MM_PER_M: f64 = 1000.0;

impl StateFeedback<4, 1> {
    /// The lab's law `u = Kf (G r − x_mm)` from its per-millimetre gains
    /// `[Kf1, Kf2, Kf3, Kf4]` (input unit per mm and per mm/s), with `G`
    /// selecting the position of `cart`.
    ///
    /// The conversion to SI is done here and only here: `K = 1000 · Kf` (per
    /// metre), and `N = K G`, so [`update`](crate::Controller::update) takes
    /// the reference and the measured state `[x1, v1, x2, v2]` in metres and
    /// m/s. With `r` in metres, `K (G r − x) = Kf (G r_mm − x_mm)` exactly as
    /// in the lab's diagram.
    ///
    /// # Errors
    ///
    /// [`Error::NonFinite`] naming `"K"` for a NaN or infinite gain.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{Cart, Controller, MassSpring, StateFeedback};
    /// use nalgebra::{matrix, vector};
    ///
    /// let mut c = StateFeedback::from_lab_gains([0.0, 0.0, 0.1, 0.0], Cart::Two)?;
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
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn from_lab_gains(kf: [f64; 4], cart: Cart) -> Result<Self, Error> {
        let k = SMatrix::<f64, 1, 4>::from_row_slice(&kf) * MM_PER_M;
        check_finite("K", &k)?;
        let n = SVector::<f64, 1>::new(k[cart.state_index()]);
        Self::new(k, n)
    }
}
