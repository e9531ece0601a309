//! [`SimulatedCardConfig`]: how a [`SimulatedCard`](super::SimulatedCard)
//! sees the plant inside it.

use nalgebra::SVector;

use super::pc104::{ENCODER_CHANNELS, PWM_CHANNELS};
use super::{ConfigError, RegisterMap, check_positive};

/// The ID the simulated card answers in its ID register (`0xa5`).
///
/// # Examples
///
/// ```
/// use ctrlab::hw::{Pc104, SIMULATED_CARD_ID};
/// use ctrlab::lab::SimulatedRig;
/// let mut card = SimulatedRig::default().card(&ctrlab::hw::Clock::Virtual(Default::default()))?;
/// assert_eq!(Pc104::new(card).read_id()?, SIMULATED_CARD_ID);
/// # Ok::<(), ctrlab::hw::RigError>(())
/// ```
pub const SIMULATED_CARD_ID: u8 = 0xa5;

/// How a [`SimulatedCard`](super::SimulatedCard) connects to the plant
/// inside it (`N` states, input in volts): which PWM channel drives it,
/// which state each encoder counts, and the card's own behaviour.
///
/// The defaults: the default [`RegisterMap`], 24 V supply, 8192 counts
/// (2048 pulses × 4) per revolution and 80 mm of travel per revolution (the
/// lab's figures, so 9.765625 µm per count), the plant on PWM channel 0,
/// no encoder connected, no noise, a 100 ms watchdog, RK4 sub-steps of at
/// most 0.25 ms, the plant at rest at 0. The lab's two-cart rig
/// ([`lab::SimulatedRig`](crate::lab::SimulatedRig)) connects encoders 0
/// and 1 to the carts' positions.
///
/// # Examples
///
/// ```
/// use ctrlab::hw::SimulatedCardConfig;
///
/// // A motor whose angle is state 0, on encoder 2.
/// let mut config = SimulatedCardConfig::<2>::default();
/// config.encoders[2] = Some(0);
/// assert!(config.validate().is_ok());
/// assert_eq!(config.units_per_count(), 0.080 / 8192.0);
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct SimulatedCardConfig<const N: usize> {
    /// Where the card's registers are.
    pub map: RegisterMap,
    /// What the ID register reads.
    pub card_id: u8,
    /// Driver voltage at 100 % duty, V (the lab's motor: 24 V).
    pub supply_voltage: f64,
    /// Encoder counts per revolution after ×4 decoding (> 0).
    pub counts_per_revolution: f64,
    /// Travel per encoder revolution, in the unit of the state it counts
    /// (m for a cart) (> 0).
    pub travel_per_revolution: f64,
    /// The PWM channel whose voltage is the plant's input (0–3).
    pub pwm_channel: usize,
    /// For each encoder channel 0–3, the index of the state it counts, or
    /// `None` when nothing is connected (it then counts 0). A state may be
    /// counted by one channel only.
    pub encoders: [Option<usize>; ENCODER_CHANNELS],
    /// Standard deviation of Gaussian noise added to each latched count of
    /// a connected encoder, counts (≥ 0; 0 = noiseless).
    pub encoder_noise: f64,
    /// Seed of the noise generator ([`Rng`](crate::signal::Rng)): the same
    /// seed gives the same noise.
    pub seed: u64,
    /// Watchdog timeout, s: with no kick for this long (card time), all PWM
    /// outputs go to zero. `None` disables the watchdog.
    pub watchdog_timeout: Option<f64>,
    /// Largest RK4 sub-step, s (> 0).
    pub max_substep: f64,
    /// Delay from writing a PWM duty to the drive applying it, s (≥ 0,
    /// below 1 s): the card's latch-to-PWM and the driver's own delay.
    pub pwm_delay: f64,
    /// Plant state when the card is created.
    pub initial_state: SVector<f64, N>,
}

impl<const N: usize> Default for SimulatedCardConfig<N> {
    fn default() -> Self {
        Self {
            map: RegisterMap::default(),
            card_id: SIMULATED_CARD_ID,
            supply_voltage: 24.0,
            counts_per_revolution: 8192.0,
            travel_per_revolution: 0.080,
            pwm_channel: 0,
            encoders: [None; ENCODER_CHANNELS],
            encoder_noise: 0.0,
            seed: 0x5eed,
            watchdog_timeout: Some(0.100),
            max_substep: 0.25e-3,
            pwm_delay: 0.0,
            initial_state: SVector::zeros(),
        }
    }
}

impl<const N: usize> SimulatedCardConfig<N> {
    /// Travel per encoder count, in the counted state's unit (m for a cart).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::SimulatedCardConfig;
    /// assert_eq!(SimulatedCardConfig::<4>::default().units_per_count(), 9.765625e-6);
    /// ```
    pub fn units_per_count(&self) -> f64 {
        self.travel_per_revolution / self.counts_per_revolution
    }

    /// Checks every field, and the resolution they make.
    ///
    /// # Errors
    ///
    /// [`ConfigError`] naming the first bad field by its name (indexed for
    /// an array, `encoders[2]`; the map's under `map.`, `map.encoder[3]`);
    /// a resolution that is not a finite positive number
    /// ([`units_per_count`](Self::units_per_count) over- or underflowing) is
    /// named `travel_per_revolution`.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::SimulatedCardConfig;
    /// let bad = SimulatedCardConfig::<4> { supply_voltage: 0.0, ..Default::default() };
    /// assert_eq!(bad.validate().unwrap_err().key(), "supply_voltage");
    /// let overflow = SimulatedCardConfig::<4> {
    ///     travel_per_revolution: 1e300,
    ///     counts_per_revolution: 1e-300,
    ///     ..Default::default()
    /// };
    /// assert_eq!(overflow.validate().unwrap_err().key(), "travel_per_revolution");
    /// ```
    pub fn validate(&self) -> Result<(), ConfigError> {
        self.map.validate().map_err(|e| e.in_table("map"))?;
        check_positive("supply_voltage", self.supply_voltage)?;
        check_positive("counts_per_revolution", self.counts_per_revolution)?;
        check_positive("travel_per_revolution", self.travel_per_revolution)?;
        let units = self.units_per_count();
        if !(units.is_finite() && units > 0.0) {
            return Err(ConfigError::invalid(
                "travel_per_revolution",
                self.travel_per_revolution,
                "its ratio to counts_per_revolution (the travel per count) must be finite and > 0",
            ));
        }
        check_positive("max_substep", self.max_substep)?;
        if let Some(timeout) = self.watchdog_timeout {
            check_positive("watchdog_timeout", timeout)?;
        }
        if self.max_substep < 1e-9 {
            return Err(ConfigError::invalid(
                "max_substep",
                self.max_substep,
                "must be ≥ 1 ns",
            ));
        }
        if !(self.pwm_delay.is_finite() && (0.0..1.0).contains(&self.pwm_delay)) {
            return Err(ConfigError::invalid(
                "pwm_delay",
                self.pwm_delay,
                "must be finite, ≥ 0 and below 1 s",
            ));
        }
        if !(self.encoder_noise.is_finite() && self.encoder_noise >= 0.0) {
            return Err(ConfigError::invalid(
                "encoder_noise",
                self.encoder_noise,
                "must be finite and ≥ 0",
            ));
        }
        if self.pwm_channel >= PWM_CHANNELS {
            return Err(ConfigError::invalid(
                "pwm_channel",
                self.pwm_channel as f64,
                "must be 0–3",
            ));
        }
        for (i, state) in self.encoders.iter().enumerate() {
            let Some(state) = *state else { continue };
            if state >= N {
                return Err(ConfigError::invalid(
                    format!("encoders[{i}]"),
                    state as f64,
                    "names a state beyond the plant's",
                ));
            }
            if self.encoders[..i].contains(&Some(state)) {
                return Err(ConfigError::conflict(
                    format!("encoders[{i}]"),
                    state as f64,
                    "two encoder channels count the same state",
                ));
            }
        }
        if let Some(i) = self.initial_state.iter().position(|v| !v.is_finite()) {
            return Err(ConfigError::invalid(
                format!("initial_state[{i}]"),
                self.initial_state[i],
                "must be finite",
            ));
        }
        Ok(())
    }
}
