//! What a real rig has and the identification's model does not: the
//! [`Unmodelled`] part of a [`SimulatedRig`](super::SimulatedRig).

use super::Friction;
use crate::hw::ConfigError;
use crate::signal::Rng;

/// Mixed into the card's seed for the per-run friction draw, so that the
/// draw is not the first number of the encoder noise's stream.
const DRAW_SALT: u64 = 0x0f71_c710_4a11_0e5d;

/// The largest relative σ of the per-run friction draw: with the draw
/// clipped at ±3σ, a force stays above 10 % of its nominal value.
const MAX_FRICTION_VARIATION: f64 = 0.3;

/// What the lab's real rig has and the identification's linear model with
/// Coulomb friction does not fit: cart 2's extra effective mass from the
/// motor's rotor, the drive's deadband, Coulomb friction that varies along
/// the rail, and friction that differs from run to run. The `[unmodelled]`
/// table of a [`SimulatedRig`](super::SimulatedRig)'s file.
///
/// The default is the lab's rig's (see [the reasoning
/// there](super::SimulatedRig#the-default-rig-and-why)): 0.06 kg of rotor on
/// cart 2, a 0.3 V deadband, ±15 % of Coulomb friction along the rail over
/// a 20 mm period, and σ = 5 % of friction from run to run.
/// [`Unmodelled::NONE`] turns them all off, as
/// [`SimulatedRig::ideal`](super::SimulatedRig::ideal) has it.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::Unmodelled;
/// let u = Unmodelled::default();
/// assert_eq!((u.rotor_mass, u.deadband), (0.06, 0.3));
/// assert_eq!((u.friction_ripple, u.ripple_period, u.friction_variation), (0.15, 0.02, 0.05));
/// assert!(Unmodelled::NONE.validate().is_ok() && u.validate().is_ok());
/// ```
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Unmodelled {
    /// Cart 2's extra effective mass from the motor's rotor and pinion,
    /// kg (finite, ≥ 0): J / r², the rotor's inertia (kg·m²) over the
    /// pinion's radius (m) squared. The plant's cart 2 has mass
    /// `m2 + rotor_mass`; the identification is told the weighed `m2`.
    pub rotor_mass: f64,
    /// The drive's deadband, V (finite, ≥ 0, below the drive's full
    /// scale): an input of |u| ≤ `deadband` gives no force, a larger one
    /// acts as `u − deadband·sign(u)` (an H-bridge's dead time and the
    /// motor's brush drop).
    pub deadband: f64,
    /// Relative amplitude of the Coulomb and breakaway forces' variation
    /// along the rail (finite, 0 ≤ a < 1): cart 1 feels
    /// `F·(1 + a·sin(2π x1 / ripple_period))`, cart 2
    /// `F·(1 + a·cos(2π x2 / ripple_period))`.
    pub friction_ripple: f64,
    /// Spatial period of that variation, m (finite, > 0).
    pub ripple_period: f64,
    /// Relative standard deviation of each cart's Coulomb and breakaway
    /// forces from run to run (finite, 0 ≤ σ ≤ 0.3): each card draws one
    /// factor per cart from
    /// its seed (see [`draw_friction`](Self::draw_friction)).
    pub friction_variation: f64,
}

impl Default for Unmodelled {
    fn default() -> Self {
        Self {
            rotor_mass: 0.06,
            deadband: 0.3,
            friction_ripple: 0.15,
            ripple_period: 0.02,
            friction_variation: 0.05,
        }
    }
}

impl Unmodelled {
    /// None of it: the plant is the truth with its [`Friction`].
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::{Friction, Unmodelled};
    /// assert_eq!(Unmodelled::NONE.rotor_mass, 0.0);
    /// let f = Friction::default();
    /// assert_eq!(Unmodelled::NONE.draw_friction(&f, 7), f);
    /// ```
    pub const NONE: Self = Self {
        rotor_mass: 0.0,
        deadband: 0.0,
        friction_ripple: 0.0,
        ripple_period: 0.02,
        friction_variation: 0.0,
    };

    /// The friction of one run: each cart's Coulomb and breakaway forces
    /// (N) times `1 + σ·z`, with σ = [`friction_variation`](Self::friction_variation)
    /// and z a standard normal number clipped to ±3, one per cart, drawn
    /// from `seed` (the card's [`seed`](super::CardSettings::seed), which
    /// lab5 sets to the run's number). The same seed gives the same
    /// friction; each cart keeps its breakaway over Coulomb ratio. With
    /// σ = 0 it is `friction` unchanged.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::{Friction, Unmodelled};
    /// let (u, f) = (Unmodelled::default(), Friction::default());
    /// let (a, b) = (u.draw_friction(&f, 1), u.draw_friction(&f, 2));
    /// assert_eq!(a, u.draw_friction(&f, 1));
    /// assert_ne!(a, b);
    /// assert!(a.coulomb.iter().zip(f.coulomb).all(|(a, f)| (a / f - 1.0).abs() <= 0.15));
    /// ```
    pub fn draw_friction(&self, friction: &Friction, seed: u64) -> Friction {
        let sigma = self.friction_variation;
        if sigma == 0.0 {
            return *friction;
        }
        let mut rng = Rng::new(seed ^ DRAW_SALT);
        let factor = [0, 1].map(|_| 1.0 + sigma * rng.gaussian().clamp(-3.0, 3.0));
        Friction {
            coulomb: [0, 1].map(|c| friction.coulomb[c] * factor[c]),
            stiction: [0, 1].map(|c| friction.stiction[c] * factor[c]),
        }
    }

    /// Checks every value against its range (see the fields).
    ///
    /// # Errors
    ///
    /// [`ConfigError`] naming the first bad value as the file does
    /// (`rotor_mass`, `deadband`, `friction_ripple`, `ripple_period`,
    /// `friction_variation`).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::Unmodelled;
    /// let bad = Unmodelled { friction_ripple: 1.0, ..Unmodelled::default() };
    /// assert_eq!(bad.validate().unwrap_err().key(), "friction_ripple");
    /// let bad = Unmodelled { rotor_mass: f64::NAN, ..Unmodelled::default() };
    /// assert_eq!(bad.validate().unwrap_err().key(), "rotor_mass");
    /// ```
    pub fn validate(&self) -> Result<(), ConfigError> {
        let checks: [(&str, f64, bool, &'static str); 5] = [
            (
                "rotor_mass",
                self.rotor_mass,
                self.rotor_mass >= 0.0,
                "must be finite and ≥ 0",
            ),
            (
                "deadband",
                self.deadband,
                self.deadband >= 0.0,
                "must be finite and ≥ 0",
            ),
            (
                "friction_ripple",
                self.friction_ripple,
                (0.0..1.0).contains(&self.friction_ripple),
                "must be finite, ≥ 0 and below 1",
            ),
            (
                "ripple_period",
                self.ripple_period,
                self.ripple_period > 0.0,
                "must be finite and > 0",
            ),
            (
                "friction_variation",
                self.friction_variation,
                (0.0..=MAX_FRICTION_VARIATION).contains(&self.friction_variation),
                "must be finite, ≥ 0 and at most 0.3",
            ),
        ];
        for (key, value, ok, reason) in checks {
            if !(ok && value.is_finite()) {
                return Err(ConfigError::invalid(key, value, reason));
            }
        }
        Ok(())
    }
}
