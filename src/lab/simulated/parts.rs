//! A simulated rig's parts besides its truth and calibration: the carts'
//! [`Friction`] and the simulated card's own [`CardSettings`].

use crate::hw::{ConfigError, RegisterMap, SimulatedCardConfig};

/// Coulomb (sliding) and breakaway (static) friction on the lab's two
/// carts, N: part of a [`SimulatedRig`](super::SimulatedRig)'s truth, the `[friction]` table of
/// its file. The default is the lab's rig's (see [the reasoning
/// there](super::SimulatedRig#the-default-rig-and-why)): 1 N sliding and 1.2 N
/// breakaway on cart 1, 2 N and 2.4 N on cart 2.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::Friction;
/// let f = Friction::default();
/// assert_eq!((f.coulomb, f.stiction), ([1.0, 2.0], [1.2, 2.4]));
/// assert!(Friction::NONE.validate().is_ok());
/// ```
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Friction {
    /// Coulomb (sliding) friction force on cart 1 and cart 2, N (≥ 0), see
    /// [`FrictionPlant`](crate::lab::FrictionPlant).
    pub coulomb: [f64; 2],
    /// Breakaway (static) friction force on cart 1 and cart 2, N (≥ 0;
    /// taken as at least the Coulomb force).
    pub stiction: [f64; 2],
}

impl Default for Friction {
    fn default() -> Self {
        Self {
            coulomb: [1.0, 2.0],
            stiction: [1.2, 2.4],
        }
    }
}

impl Friction {
    /// No friction on either cart (a linear plant).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::Friction;
    /// assert_eq!(Friction::NONE.coulomb, [0.0; 2]);
    /// ```
    pub const NONE: Self = Self {
        coulomb: [0.0; 2],
        stiction: [0.0; 2],
    };

    /// Coulomb friction `coulomb` (N, cart 1 and cart 2) that breaks away
    /// at the same force: no stiction beyond it.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::Friction;
    /// let f = Friction::coulomb([0.5, 1.5]);
    /// assert_eq!((f.coulomb, f.stiction), ([0.5, 1.5], [0.5, 1.5]));
    /// assert_eq!(f.stiction_ratio(), [1.0, 1.0]);
    /// ```
    pub fn coulomb(coulomb: [f64; 2]) -> Self {
        Self {
            coulomb,
            stiction: coulomb,
        }
    }

    /// Each cart's breakaway over Coulomb force (at least 1; 1 for a cart
    /// without friction), as
    /// [`SimulationModel::stiction_ratio`](crate::lab::ident::SimulationModel::stiction_ratio)
    /// takes it.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::Friction;
    /// let r = Friction::default().stiction_ratio();
    /// assert!(r.iter().all(|r| (r - 1.2).abs() < 1e-12));
    /// ```
    pub fn stiction_ratio(&self) -> [f64; 2] {
        [0, 1].map(|c| {
            let f = self.coulomb[c];
            if f > 0.0 {
                (self.stiction[c] / f).max(1.0)
            } else {
                1.0
            }
        })
    }

    /// Checks the forces: finite and ≥ 0, and each cart's breakaway over
    /// Coulomb force ([`stiction_ratio`](Self::stiction_ratio)) finite.
    ///
    /// # Errors
    ///
    /// [`ConfigError`] naming the first bad force as the file does
    /// (`coulomb[1]`, `stiction[0]`); a ratio that overflows (a Coulomb
    /// force too small for the stiction over it) is named by the Coulomb
    /// force.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::Friction;
    /// let bad = Friction { coulomb: [1.0, -2.0], ..Friction::default() };
    /// assert_eq!(bad.validate().unwrap_err().key(), "coulomb[1]");
    /// let tiny = Friction { coulomb: [5e-324, 2.0], ..Friction::default() };
    /// assert_eq!(tiny.validate().unwrap_err().key(), "coulomb[0]");
    /// ```
    pub fn validate(&self) -> Result<(), ConfigError> {
        for (name, forces) in [("coulomb", self.coulomb), ("stiction", self.stiction)] {
            if let Some(c) = forces.iter().position(|f| !(f.is_finite() && *f >= 0.0)) {
                return Err(ConfigError::invalid(
                    format!("{name}[{c}]"),
                    forces[c],
                    "must be finite and ≥ 0",
                ));
            }
        }
        let ratio = self.stiction_ratio();
        if let Some(c) = ratio.iter().position(|r| !r.is_finite()) {
            return Err(ConfigError::conflict(
                format!("coulomb[{c}]"),
                self.coulomb[c],
                "too small for the stiction over it: stiction / coulomb overflows",
            ));
        }
        Ok(())
    }
}

/// The simulated card's own settings, those the rig's [`Calibration`](crate::lab::Calibration) does
/// not describe: where its registers are, the noise on its counts, the
/// delay of its drive and how finely it integrates the plant. The
/// `[card]` table of a [`SimulatedRig`](super::SimulatedRig)'s file. (Its ID, watchdog, supply,
/// resolution and channels are the calibration's: the simulated card is
/// built to match it.)
///
/// The default is the lab's rig's (see [the reasoning
/// there](super::SimulatedRig#the-default-rig-and-why)): the default
/// [`RegisterMap`], σ = 0.3 count of noise from seed `0x5eed`, a 0.15 ms PWM
/// delay, RK4 sub-steps of at most 0.25 ms.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::CardSettings;
/// let card = CardSettings::default();
/// assert_eq!((card.encoder_noise, card.pwm_delay, card.max_substep), (0.3, 0.15e-3, 0.25e-3));
/// ```
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CardSettings {
    /// Standard deviation of Gaussian noise added to each latched count,
    /// counts (≥ 0; 0 = noiseless).
    pub encoder_noise: f64,
    /// Seed of the noise generator: the same seed gives the same noise.
    pub seed: u64,
    /// Delay from a PWM write to the drive applying it, s (≥ 0, below the
    /// rig's period).
    pub pwm_delay: f64,
    /// Largest RK4 sub-step, s (≥ 1 ns, at most 10⁶ per period).
    pub max_substep: f64,
    /// Where the card's registers are (the `[card.map]` table).
    pub map: RegisterMap,
}

impl CardSettings {
    /// The card without what a linear model lacks: no PWM delay, no noise
    /// on the counts (the default map, seed and sub-step), as
    /// [`SimulatedRig::ideal`](super::SimulatedRig::ideal) has it.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::CardSettings;
    /// let card = CardSettings::ideal();
    /// assert_eq!((card.pwm_delay, card.encoder_noise), (0.0, 0.0));
    /// assert_eq!(card.max_substep, CardSettings::default().max_substep);
    /// ```
    pub fn ideal() -> Self {
        Self {
            pwm_delay: 0.0,
            encoder_noise: 0.0,
            ..Self::default()
        }
    }
}

impl Default for CardSettings {
    fn default() -> Self {
        let card = SimulatedCardConfig::<4>::default();
        Self {
            encoder_noise: 0.3,
            seed: card.seed,
            pwm_delay: 0.15e-3,
            max_substep: card.max_substep,
            map: card.map,
        }
    }
}
