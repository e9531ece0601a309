//! The two-cart plant with stick–slip Coulomb friction, inside the lab's
//! simulated card and the sampled-data simulator.

use nalgebra::SVector;

use super::MassSpring;
use crate::model::Dynamics;

/// The two-cart plant with stick–slip Coulomb friction on each cart, input
/// in volts (through `truth.gain`): a nonlinear [`Dynamics`] for the
/// simulated card and the sampled-data simulator.
///
/// A cart at rest stays at rest while the other forces on it are within
/// ±F_s (its stiction, the breakaway force, at least its Coulomb force
/// F); a sliding cart feels −F·sign(v); a cart whose speed reaches zero in a
/// sub-step sticks if the other forces are within ±F_s. The stick and slip
/// decisions are taken in [`update_mode`](Dynamics::update_mode) between
/// integration steps, so a stuck cart's speed is exactly zero.
///
/// The equations' coefficients (`k/m`, `b/m`, `K/m`, `F/m`) are computed
/// once, when the plant is built, not on each of an RK4 step's four
/// derivatives: the parameters are read through accessors for that reason.
///
/// # Examples
///
/// ```
/// use ctrlab::Dynamics;
/// use ctrlab::integrate::{Integrator, Rk4};
/// use ctrlab::lab::{FrictionPlant, MassSpring};
/// use ctrlab::nalgebra::vector;
///
/// // 1 V (1 N) against 2 N of friction on cart 2: nothing moves.
/// let mut plant = FrictionPlant::new(MassSpring::nominal(), [0.0, 2.0]);
/// let (mut x, u) = (vector![0.0, 0.0, 0.0, 0.0], vector![1.0]);
/// for k in 0..100 {
///     plant.update_mode(k as f64 * 1e-3, &mut x, &u);
///     Rk4.step_mut(&plant, k as f64 * 1e-3, 1e-3, &mut x, &u);
/// }
/// assert_eq!(x, vector![0.0, 0.0, 0.0, 0.0]);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrictionPlant {
    truth: MassSpring,
    friction: [f64; 2],
    stiction: [f64; 2],
    /// Each cart's sliding direction (±1) for the current step, or 0 while
    /// it sticks; only used for a cart with friction.
    direction: [f64; 2],
    /// The linear plant's accelerations per unit state and input, 1/s²,
    /// 1/s, N/(kg·unit): the entries of A's rows 1 and 3 and of B as
    /// [`MassSpring`]'s equations give them.
    accel: Accelerations,
    /// Coulomb force over mass per cart, m/s².
    friction_accel: [f64; 2],
    /// The drive's deadband, V (0: none).
    deadband: f64,
    /// Relative amplitude (0: none) and spatial period (m) of the friction
    /// forces' variation along the rail.
    ripple: [f64; 2],
}

/// The nonzero entries of the rows of `[A B]` that give the accelerations.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Accelerations {
    /// `[−(k1 + k2)/m1, −b1/m1, k2/m1]` on `[x1, v1, x2]`.
    cart1: [f64; 3],
    /// `[k2/m2, −k2/m2, −b2/m2, K/m2]` on `[x1, x2, v2, u]`.
    cart2: [f64; 4],
}

impl Accelerations {
    fn of(p: &MassSpring) -> Self {
        Self {
            cart1: [-(p.k1 + p.k2) / p.m1, -p.b1 / p.m1, p.k2 / p.m1],
            cart2: [p.k2 / p.m2, -p.k2 / p.m2, -p.b2 / p.m2, p.gain / p.m2],
        }
    }

    /// Each cart's acceleration from everything but Coulomb friction, m/s².
    #[inline]
    fn at(&self, x: &SVector<f64, 4>, u: f64) -> [f64; 2] {
        let [a10, a11, a12] = self.cart1;
        let [a30, a32, a33, b3] = self.cart2;
        [
            a10 * x[0] + a11 * x[1] + a12 * x[2],
            a30 * x[0] + a32 * x[2] + a33 * x[3] + b3 * u,
        ]
    }
}

impl FrictionPlant {
    /// The plant `truth` with Coulomb friction `friction` (N, cart 1 and
    /// cart 2), both carts sticking until the first mode update.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::lab::{FrictionPlant, MassSpring};
    /// let p = FrictionPlant::new(MassSpring::nominal(), [1.0, 2.0]);
    /// assert_eq!(p.friction(), [1.0, 2.0]);
    /// assert_eq!(p.stiction(), [1.0, 2.0]);
    /// ```
    pub fn new(truth: MassSpring, friction: [f64; 2]) -> Self {
        Self {
            truth,
            friction,
            stiction: friction,
            direction: [0.0; 2],
            accel: Accelerations::of(&truth),
            friction_accel: [friction[0] / truth.m1, friction[1] / truth.m2],
            deadband: 0.0,
            ripple: [0.0, 1.0],
        }
    }

    /// The same plant behind a drive with a deadband of `volts` V (≥ 0):
    /// an input of |u| ≤ `volts` gives no force, a larger one acts as
    /// `u − volts·sign(u)`. 0 (the default) leaves the input as it is.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::Dynamics;
    /// use ctrlab::lab::{FrictionPlant, MassSpring};
    /// use ctrlab::nalgebra::vector;
    /// let p = FrictionPlant::new(MassSpring::nominal(), [0.0; 2]).with_deadband(0.3);
    /// assert_eq!(p.deadband(), 0.3);
    /// let x = vector![0.0, 0.0, 0.0, 0.0];
    /// assert_eq!(p.derivative(0.0, &x, &vector![0.25])[3], 0.0); // inside: no force
    /// let a = p.derivative(0.0, &x, &vector![1.3])[3]; // 1 V acts: 1 N on 0.7 kg
    /// assert!((a - 1.0 / 0.7).abs() < 1e-12);
    /// ```
    #[must_use]
    pub fn with_deadband(mut self, volts: f64) -> Self {
        self.deadband = volts;
        self
    }

    /// The same plant with Coulomb and breakaway forces that vary along
    /// the rail by the relative `amplitude` (0 ≤ a < 1) over `period` m
    /// (> 0): cart 1 feels `F·(1 + a·sin(2π x1 / period))`, cart 2
    /// `F·(1 + a·cos(2π x2 / period))`. An amplitude of 0 (the default)
    /// keeps them constant.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::{FrictionPlant, MassSpring};
    /// let p = FrictionPlant::new(MassSpring::nominal(), [1.0, 2.0]).with_friction_ripple(0.15, 0.02);
    /// assert_eq!(p.friction_ripple(), (0.15, 0.02));
    /// // Cart 2 at 0 is at the ripple's crest, 10 mm on at its trough.
    /// assert!((p.coulomb_at(1, 0.0) - 2.3).abs() < 1e-12);
    /// assert!((p.coulomb_at(1, 0.01) - 1.7).abs() < 1e-12);
    /// assert_eq!(p.coulomb_at(0, 0.0), 1.0);
    /// ```
    #[must_use]
    pub fn with_friction_ripple(mut self, amplitude: f64, period: f64) -> Self {
        self.ripple = [amplitude, period];
        self
    }

    /// The drive's deadband, V.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::lab::{FrictionPlant, MassSpring};
    /// assert_eq!(FrictionPlant::new(MassSpring::nominal(), [1.0, 2.0]).deadband(), 0.0);
    /// ```
    pub fn deadband(&self) -> f64 {
        self.deadband
    }

    /// The friction's variation along the rail: relative amplitude and
    /// period, m (see [`with_friction_ripple`](Self::with_friction_ripple)).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::lab::{FrictionPlant, MassSpring};
    /// assert_eq!(FrictionPlant::new(MassSpring::nominal(), [1.0, 2.0]).friction_ripple().0, 0.0);
    /// ```
    pub fn friction_ripple(&self) -> (f64, f64) {
        (self.ripple[0], self.ripple[1])
    }

    /// The Coulomb force on `cart` (0 or 1; any other is cart 2) at
    /// position `x` m, N: its [`friction`](Self::friction) times the
    /// variation along the rail.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::lab::{FrictionPlant, MassSpring};
    /// let p = FrictionPlant::new(MassSpring::nominal(), [1.0, 2.0]);
    /// assert_eq!((p.coulomb_at(0, 0.3), p.coulomb_at(1, -0.2)), (1.0, 2.0));
    /// ```
    pub fn coulomb_at(&self, cart: usize, x: f64) -> f64 {
        let cart = cart.min(1);
        self.friction[cart] * self.ripple_factor(cart, x)
    }

    /// The friction's factor along the rail on `cart` (0 or 1) at `x` m.
    #[inline]
    fn ripple_factor(&self, cart: usize, x: f64) -> f64 {
        let [amplitude, period] = self.ripple;
        if amplitude == 0.0 {
            return 1.0;
        }
        let phase = std::f64::consts::TAU * x / period;
        1.0 + amplitude * if cart == 0 { phase.sin() } else { phase.cos() }
    }

    /// The input that acts, V: `u` less the deadband.
    #[inline]
    fn acting(&self, u: f64) -> f64 {
        let d = self.deadband;
        if d == 0.0 {
            u
        } else if u.abs() <= d {
            0.0
        } else {
            u - d.copysign(u)
        }
    }

    /// The same plant with breakaway forces `stiction` (N, cart 1 and cart
    /// 2; each taken as at least the Coulomb force).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::lab::{FrictionPlant, MassSpring};
    /// let p = FrictionPlant::new(MassSpring::nominal(), [1.0, 2.0]).with_stiction([1.3, 2.5]);
    /// assert_eq!(p.stiction(), [1.3, 2.5]);
    /// ```
    #[must_use]
    pub fn with_stiction(mut self, stiction: [f64; 2]) -> Self {
        self.stiction = stiction;
        self
    }

    /// The linear plant (masses, springs, viscous friction, motor gain).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::lab::{FrictionPlant, MassSpring};
    /// let p = FrictionPlant::new(MassSpring::nominal(), [1.0, 2.0]);
    /// assert_eq!(p.truth(), MassSpring::nominal());
    /// ```
    pub fn truth(&self) -> MassSpring {
        self.truth
    }

    /// Coulomb (sliding) friction force on cart 1 and cart 2, N.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::lab::{FrictionPlant, MassSpring};
    /// assert_eq!(FrictionPlant::new(MassSpring::nominal(), [1.0, 2.0]).friction(), [1.0, 2.0]);
    /// ```
    pub fn friction(&self) -> [f64; 2] {
        self.friction
    }

    /// Breakaway (static) friction force on cart 1 and cart 2, N, as given
    /// (the plant holds a cart with at least its Coulomb force).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::lab::{FrictionPlant, MassSpring};
    /// let p = FrictionPlant::new(MassSpring::nominal(), [1.0, 2.0]).with_stiction([1.2, 2.4]);
    /// assert_eq!(p.stiction(), [1.2, 2.4]);
    /// ```
    pub fn stiction(&self) -> [f64; 2] {
        self.stiction
    }

    /// Each cart's sliding direction for the coming step: ±1, or 0 while
    /// it sticks (and always 0 for a cart without friction).
    pub(crate) fn directions(&self) -> [f64; 2] {
        self.direction
    }

    /// The force that holds a cart at rest at position `x` m, N.
    fn breakaway(&self, cart: usize, x: f64) -> f64 {
        self.stiction[cart].max(self.friction[cart]) * self.ripple_factor(cart, x)
    }

    fn mass(&self, cart: usize) -> f64 {
        if cart == 0 {
            self.truth.m1
        } else {
            self.truth.m2
        }
    }

    /// Net force on `cart` from everything but Coulomb friction, N.
    fn other_force(&self, x: &SVector<f64, 4>, u: &SVector<f64, 1>, cart: usize) -> f64 {
        self.accel.at(x, self.acting(u[0]))[cart] * self.mass(cart)
    }
}

impl Dynamics<4, 1> for FrictionPlant {
    #[inline]
    fn derivative(&self, _t: f64, x: &SVector<f64, 4>, u: &SVector<f64, 1>) -> SVector<f64, 4> {
        let mut dx = SVector::from([x[1], 0.0, x[3], 0.0]);
        let accel = self.accel.at(x, self.acting(u[0]));
        for cart in 0..2 {
            dx[2 * cart + 1] = accel[cart];
            if self.friction[cart] > 0.0 {
                if self.direction[cart] == 0.0 {
                    dx[2 * cart] = 0.0;
                    dx[2 * cart + 1] = 0.0;
                } else {
                    dx[2 * cart + 1] -= self.friction_accel[cart]
                        * self.ripple_factor(cart, x[2 * cart])
                        * self.direction[cart];
                }
            }
        }
        dx
    }
    /// First, a sliding cart whose speed reached or crossed zero sticks if
    /// the other forces are within its breakaway force, otherwise reverses;
    /// then a sticking cart breaks away when the other forces (under the
    /// input held next) exceed its breakaway force, and a sliding one
    /// slides the way it moves.
    fn update_mode(&mut self, _t: f64, x: &mut SVector<f64, 4>, u: &SVector<f64, 1>) {
        for cart in 0..2 {
            if self.friction[cart] == 0.0 {
                continue;
            }
            let v = x[2 * cart + 1];
            let direction = self.direction[cart];
            if direction != 0.0 && v * direction <= 0.0 {
                let force = self.other_force(x, u, cart);
                if force.abs() <= self.breakaway(cart, x[2 * cart]) {
                    x[2 * cart + 1] = 0.0;
                    self.direction[cart] = 0.0;
                } else {
                    self.direction[cart] = force.signum();
                }
            }
            let v = x[2 * cart + 1];
            if self.direction[cart] == 0.0 && v != 0.0 {
                // Moving without a mode yet (an initial speed): it slides.
                self.direction[cart] = v.signum();
            } else if self.direction[cart] == 0.0 {
                let force = self.other_force(x, u, cart);
                if force.abs() > self.breakaway(cart, x[2 * cart]) {
                    self.direction[cart] = force.signum();
                }
            } else if v != 0.0 {
                self.direction[cart] = v.signum();
            }
        }
    }
}
