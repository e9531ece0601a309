//! The lab's plant: two carts joined by springs, the second pushed by a DC motor
//! (equations (1)–(3) and (14) of the lab, `docs/lab.md`).

use crate::nalgebra::{SMatrix, SVector, matrix};

use crate::error::Error;
use crate::model::{Continuous, Dynamics, StateSpace};

/// One of the rig's two carts: which cart's position a model outputs, a
/// controller moves, or a report talks about.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::Cart;
/// let carts = [Cart::One, Cart::Two];
/// assert_eq!(carts.map(Cart::number), [1, 2]);
/// // Their positions x1 and x2 in the state [x1, v1, x2, v2].
/// assert_eq!(carts.map(Cart::state_index), [0, 2]);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Cart {
    /// Cart 1, the one tied to the wall; position `x1`, m.
    One,
    /// Cart 2, the one the motor drives; position `x2`, m.
    Two,
}

impl Cart {
    /// Index of this cart's position in the state `[x1, v1, x2, v2]`.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::Cart;
    /// assert_eq!(Cart::One.state_index(), 0);
    /// assert_eq!(Cart::Two.state_index(), 2);
    /// ```
    pub fn state_index(self) -> usize {
        match self {
            Cart::One => 0,
            Cart::Two => 2,
        }
    }

    /// The cart's number as the lab writes it (1 or 2).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::lab::Cart;
    /// assert_eq!(Cart::One.number(), 1);
    /// ```
    pub fn number(self) -> usize {
        match self {
            Cart::One => 1,
            Cart::Two => 2,
        }
    }

    /// The selection row `C` that picks this cart's position out of the state.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::Cart;
    /// # use ctrlab::nalgebra::matrix;
    /// assert_eq!(Cart::Two.selection(), matrix![0.0, 0.0, 1.0, 0.0]);
    /// ```
    pub fn selection(self) -> SMatrix<f64, 1, 4> {
        let mut c = SMatrix::<f64, 1, 4>::zeros();
        c[self.state_index()] = 1.0;
        c
    }
}

/// Physical parameters of the two-cart mass-spring rig, SI units.
///
/// ```text
///  wall |--k1--[ m1 ]--k2--[ m2 ]<== F = gain · u
///            x1 ->        x2 ->
/// ```
///
/// State `x = [x1 (m), x1' (m/s), x2 (m), x2' (m/s)]`, input `u`: the motor
/// drive in whatever unit `gain` converts to newtons (volts on the rig,
/// newtons with `gain = 1` in simulation).
///
/// # Examples
///
/// ```
/// use ctrlab::{MassSpring, Cart};
///
/// let plant = MassSpring::nominal();
/// let sys = plant.state_space(Cart::Two)?;
/// assert_eq!(sys.a()[(1, 0)], -(1000.0 + 1000.0) / 1.3);
/// // A 10 N push deflects the carts 10 mm and 20 mm at rest.
/// let (x1, x2) = plant.static_deflection(10.0)?;
/// assert!((x1 - 0.010).abs() < 1e-15 && (x2 - 0.020).abs() < 1e-15);
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MassSpring {
    /// Mass of cart 1, kg (> 0).
    pub m1: f64,
    /// Mass of cart 2, kg (> 0).
    pub m2: f64,
    /// Spring between the wall and cart 1, N/m (≥ 0).
    pub k1: f64,
    /// Spring between the carts, N/m (≥ 0).
    pub k2: f64,
    /// Viscous friction on cart 1, N·s/m (≥ 0).
    pub b1: f64,
    /// Viscous friction on cart 2, N·s/m (≥ 0).
    pub b2: f64,
    /// Motor gain K in `F = K u`, N per input unit (N/V on the rig; 1 for a
    /// force input) (≥ 0).
    pub gain: f64,
}

impl MassSpring {
    /// The lab's simulation values: m1 = 1.3 kg, m2 = 0.7 kg,
    /// k1 = k2 = 1000 N/m, b1 = 10 N·s/m, b2 = 5 N·s/m, gain 1 (force input).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::MassSpring;
    /// let p = MassSpring::nominal();
    /// assert_eq!((p.m1, p.m2, p.k1, p.k2, p.b1, p.b2, p.gain), (1.3, 0.7, 1000.0, 1000.0, 10.0, 5.0, 1.0));
    /// ```
    pub fn nominal() -> Self {
        Self {
            m1: 1.3,
            m2: 0.7,
            k1: 1000.0,
            k2: 1000.0,
            b1: 10.0,
            b2: 5.0,
            gain: 1.0,
        }
    }

    /// Checks every parameter: masses finite and > 0, springs, frictions and
    /// gain finite and ≥ 0.
    ///
    /// # Errors
    ///
    /// [`Error::InvalidParameter`] naming the first bad field.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::{MassSpring, Error};
    /// let p = MassSpring { k2: f64::NAN, ..MassSpring::nominal() };
    /// assert!(matches!(p.validate(), Err(Error::InvalidParameter { name: "k2", .. })));
    /// ```
    pub fn validate(&self) -> Result<(), Error> {
        for (name, value) in [("m1", self.m1), ("m2", self.m2)] {
            if !(value.is_finite() && value > 0.0) {
                return Err(Error::InvalidParameter {
                    name,
                    value,
                    reason: "mass must be finite and > 0 kg",
                });
            }
        }
        for (name, value) in [
            ("k1", self.k1),
            ("k2", self.k2),
            ("b1", self.b1),
            ("b2", self.b2),
            ("gain", self.gain),
        ] {
            if !(value.is_finite() && value >= 0.0) {
                return Err(Error::InvalidParameter {
                    name,
                    value,
                    reason: "must be finite and >= 0",
                });
            }
        }
        Ok(())
    }

    /// The state matrix `A` of equation (3), without validation.
    pub(crate) fn a_matrix(&self) -> SMatrix<f64, 4, 4> {
        let Self {
            m1,
            m2,
            k1,
            k2,
            b1,
            b2,
            ..
        } = *self;
        matrix![
            0.0, 1.0, 0.0, 0.0;
            -(k1 + k2) / m1, -b1 / m1, k2 / m1, 0.0;
            0.0, 0.0, 0.0, 1.0;
            k2 / m2, 0.0, -k2 / m2, -b2 / m2
        ]
    }

    /// The continuous model of equations (3)/(14) with output `y` the chosen
    /// cart's position (m).
    ///
    /// # Errors
    ///
    /// [`Error::InvalidParameter`] from [`validate`](Self::validate).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::{MassSpring, Cart};
    /// let sys = MassSpring::nominal().state_space(Cart::One)?;
    /// assert_eq!(sys.c()[(0, 0)], 1.0);
    /// assert_eq!(sys.b()[(3, 0)], 1.0 / 0.7);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn state_space(&self, cart: Cart) -> Result<StateSpace<4, 1, 1, Continuous>, Error> {
        self.validate()?;
        let b = matrix![0.0; 0.0; 0.0; self.gain / self.m2];
        StateSpace::continuous(self.a_matrix(), b, cart.selection(), SMatrix::zeros())
    }

    /// Rest positions `(x1, x2)` in metres under a constant force `force` (N) on
    /// cart 2: `x1 = F/k1`, `x2 = F/k1 + F/k2` (the springs are in series).
    ///
    /// # Errors
    ///
    /// [`Error::InvalidParameter`] for invalid parameters, a zero spring (no
    /// rest position) or a non-finite force; [`Error::Overflow`] for a
    /// deflection beyond `f64::MAX` m (a spring of 1e-320 N/m).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::{Error, MassSpring};
    /// let (x1, x2) = MassSpring::nominal().static_deflection(50.0)?;
    /// assert!((x1 - 0.05).abs() < 1e-15 && (x2 - 0.10).abs() < 1e-15);
    /// let soft = MassSpring { k1: 1e-320, ..MassSpring::nominal() };
    /// assert!(matches!(soft.static_deflection(1.0), Err(Error::Overflow { .. })));
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn static_deflection(&self, force: f64) -> Result<(f64, f64), Error> {
        self.validate()?;
        if !force.is_finite() {
            return Err(Error::InvalidParameter {
                name: "force",
                value: force,
                reason: "must be finite",
            });
        }
        for (name, value) in [("k1", self.k1), ("k2", self.k2)] {
            if value == 0.0 {
                return Err(Error::InvalidParameter {
                    name,
                    value,
                    reason: "a zero spring has no rest position",
                });
            }
        }
        let x1 = force / self.k1;
        let x2 = x1 + force / self.k2;
        if !x2.is_finite() {
            return Err(Error::Overflow {
                operation: "static deflection (force / spring exceeds f64::MAX m)",
            });
        }
        Ok((x1, x2))
    }
}

/// The plant's equations of motion (1) as a [`Dynamics`], input in the unit
/// `gain` converts to newtons. Parameters are used as they are: call
/// [`validate`](MassSpring::validate) first.
impl Dynamics<4, 1> for MassSpring {
    #[inline]
    fn derivative(&self, _t: f64, x: &SVector<f64, 4>, u: &SVector<f64, 1>) -> SVector<f64, 4> {
        let mut dx = self.a_matrix() * x;
        dx[3] += self.gain / self.m2 * u[0];
        dx
    }
}
