//! The checks of a [`SimulatedRig`]: each part, and what the parts make
//! together.

use super::SimulatedRig;
use crate::hw::ConfigError;

impl SimulatedRig {
    /// Checks everything: each part, and what the parts make together, so
    /// that a rig this accepts builds ([`card`](Self::card),
    /// [`rig`](Self::rig)), runs ([`hw::run`](crate::hw::run) with the
    /// default [`LoopConfig`](crate::hw::LoopConfig)) and simulates
    /// ([`sampled_config`](Self::sampled_config),
    /// [`simulation_model`](Self::simulation_model)) without a later
    /// configuration error:
    ///
    /// - the truth ([`MassSpring::validate`](crate::lab::MassSpring::validate)) and the accelerations it
    ///   gives with the friction, finite;
    /// - the friction ([`Friction::validate`](super::Friction::validate));
    /// - what the model lacks ([`Unmodelled::validate`](super::Unmodelled::validate)),
    ///   with a deadband below the drive's full scale;
    /// - the calibration ([`Calibration::validate`](crate::lab::Calibration::validate)), with signs +1 (the
    ///   simulated encoders count up away from the wall), a resolution the
    ///   card's 32-bit counters hold over the travel limits, and a watchdog
    ///   of at least two periods (the loop halts at half of it);
    /// - the card's settings, and the card they make with the calibration
    ///   ([`SimulatedCardConfig::validate`](crate::hw::SimulatedCardConfig::validate));
    /// - the period (finite, ≥ 1 µs, at most 10⁶ sub-steps), a PWM delay
    ///   below it, and the initial state within the travel limits and the
    ///   calibration's `max_speed`;
    /// - the identification input
    ///   ([`IdentInput::validate`](crate::lab::ident_input::IdentInput::validate)),
    ///   its volts within the drive's `volts_full_scale`.
    ///
    /// # Errors
    ///
    /// [`ConfigError`] naming the first bad value by its key in the file
    /// ([`from_toml`](Self::from_toml) reports the same error):
    /// `truth.m1`, `friction.coulomb[1]`, `unmodelled.deadband`, `card.max_substep`,
    /// `card.map.encoder[3]`, `calibration.travel_limits[0]`, `period`,
    /// `initial_state[2]`, `ident.volts`. A derived quantity that fails is reported under
    /// the key it comes from: a stiction over a Coulomb force that overflows
    /// under `friction.coulomb[i]`, an acceleration that overflows under the
    /// mass, a resolution the card cannot count in under
    /// `calibration.metres_per_count`.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::{Calibration, Friction, SimulatedRig};
    /// let bad = SimulatedRig { friction: Friction { coulomb: [-1.0, 0.0], ..Friction::NONE }, ..Default::default() };
    /// assert_eq!(bad.validate().unwrap_err().key(), "friction.coulomb[0]");
    /// let quick = SimulatedRig {
    ///     calibration: Calibration { watchdog_timeout: Some(0.003), ..Calibration::default() },
    ///     ..Default::default()
    /// };
    /// assert_eq!(quick.validate().unwrap_err().key(), "calibration.watchdog_timeout");
    /// ```
    pub fn validate(&self) -> Result<(), ConfigError> {
        self.truth.validate().map_err(|e| {
            match e {
                crate::Error::InvalidParameter {
                    name,
                    value,
                    reason,
                } => ConfigError::invalid(name, value, reason),
                _ => ConfigError::invalid("m1", self.truth.m1, "invalid plant parameters"),
            }
            .in_table("truth")
        })?;
        self.friction
            .validate()
            .map_err(|e| e.in_table("friction"))?;
        self.unmodelled
            .validate()
            .map_err(|e| e.in_table("unmodelled"))?;
        self.check_accelerations()?;
        self.calibration
            .validate()
            .map_err(|e| e.in_table("calibration"))?;
        let cal = &self.calibration;
        if self.unmodelled.deadband >= cal.volts_full_scale {
            return Err(ConfigError::conflict(
                "unmodelled.deadband",
                self.unmodelled.deadband,
                "must be below the drive's full scale (calibration.volts_full_scale): the drive would give no force",
            ));
        }
        if let Some(c) = cal.sign.iter().position(|&s| s != 1.0) {
            return Err(ConfigError::invalid(
                format!("calibration.sign[{c}]"),
                cal.sign[c],
                "must be +1: the simulated encoders count up as the carts move away from the wall",
            ));
        }
        self.card_config().validate().map_err(Self::card_key)?;
        self.check_timing()?;
        self.check_counts()?;
        self.ident.validate().map_err(|e| e.in_table("ident"))?;
        self.ident.check_drive(cal.volts_full_scale).map_err(|e| {
            // With [ident] left out the conflict is the full scale's, the
            // key the file has.
            if self.ident == crate::lab::ident_input::IdentInput::default() {
                ConfigError::conflict(
                    "calibration.volts_full_scale",
                    cal.volts_full_scale,
                    "below the identification's drive (`ident.volts`, 8 V by default): raise it, or set a lower `volts` under [ident]",
                )
            } else {
                e.in_table("ident")
            }
        })
    }

    /// A [`SimulatedCardConfig::validate`](crate::hw::SimulatedCardConfig::validate) error under the key of the
    /// file's value it comes from.
    fn card_key(e: ConfigError) -> ConfigError {
        let key = e.key().to_owned();
        let (name, index) = key.split_at(key.find('[').unwrap_or(key.len()));
        let file_key = match name {
            "supply_voltage" => "calibration.volts_full_scale".to_owned(),
            "counts_per_revolution" | "travel_per_revolution" => {
                "calibration.metres_per_count".to_owned()
            }
            "watchdog_timeout" | "pwm_channel" => format!("calibration.{name}"),
            "encoders" => "calibration.encoder_channels".to_owned(),
            "initial_state" => key.clone(),
            _ => format!("card.{name}{index}"),
        };
        e.with_key(file_key)
    }

    /// Each cart's acceleration per unit of what acts on it, finite: a mass
    /// too small for its springs, damping, motor or friction would make
    /// the simulated card diverge at its first step.
    fn check_accelerations(&self) -> Result<(), ConfigError> {
        let p = &self.effective_truth();
        let friction = self.friction.coulomb;
        let per_mass = [
            ("truth.m1", p.m1, [p.k1 + p.k2, p.b1, p.k2, friction[0]]),
            ("truth.m2", p.m2, [p.k2, p.b2, p.gain, friction[1]]),
        ];
        for (key, mass, forces) in per_mass {
            if forces.iter().any(|f| !(f / mass).is_finite()) {
                return Err(ConfigError::conflict(
                    key,
                    mass,
                    "too small for the forces on it: an acceleration overflows",
                ));
            }
        }
        Ok(())
    }

    /// The period against what the card, the loop and the sampled-data
    /// simulation need of it.
    fn check_timing(&self) -> Result<(), ConfigError> {
        let period = self.period;
        if !(period.is_finite() && period >= 1e-6) {
            return Err(ConfigError::invalid(
                "period",
                period,
                "must be finite and ≥ 1 µs",
            ));
        }
        let card = &self.card;
        if card.pwm_delay >= period {
            return Err(ConfigError::conflict(
                "card.pwm_delay",
                card.pwm_delay,
                "must be below the period (the sampled-data simulation delays the input by less than one)",
            ));
        }
        if period / card.max_substep > 1e6 {
            return Err(ConfigError::conflict(
                "card.max_substep",
                card.max_substep,
                "more than 10^6 sub-steps per period",
            ));
        }
        if let Some(timeout) = self.calibration.watchdog_timeout
            && 0.5 * timeout < period
        {
            return Err(ConfigError::conflict(
                "calibration.watchdog_timeout",
                timeout,
                "must be at least two periods: the loop halts when half of it passes without a sample",
            ));
        }
        Ok(())
    }

    /// The counts the card makes: within its 32-bit counters over the
    /// travel limits, and the carts starting inside them.
    fn check_counts(&self) -> Result<(), ConfigError> {
        let cal = &self.calibration;
        let widest = cal.travel_limits[0].max(cal.travel_limits[1]);
        if widest / cal.metres_per_count >= f64::from(i32::MAX) {
            return Err(ConfigError::conflict(
                "calibration.metres_per_count",
                cal.metres_per_count,
                "too fine for the card's 32-bit counters over the travel limits",
            ));
        }
        for cart in 0..2 {
            let (x, v) = (
                self.initial_state[2 * cart],
                self.initial_state[2 * cart + 1],
            );
            if x.abs() > cal.travel_limits[cart] {
                return Err(ConfigError::conflict(
                    format!("initial_state[{}]", 2 * cart),
                    x,
                    "beyond the cart's travel limit: the first sample would halt the rig",
                ));
            }
            if v.abs() > cal.max_speed {
                return Err(ConfigError::conflict(
                    format!("initial_state[{}]", 2 * cart + 1),
                    v,
                    "faster than the calibration's max_speed: the first samples would read a bus fault",
                ));
            }
        }
        Ok(())
    }
}
