//! [`Calibration`]: how the lab's rig maps counts and volts to SI, and
//! what it checks.

use crate::hw::{ConfigError, ENCODER_CHANNELS, PWM_CHANNELS, check_all_positive, check_positive};

/// How the rig's counts and volts map to SI, and which channels are wired
/// where.
///
/// The default is the lab's rig as [`SimulatedRig`](super::SimulatedRig)
/// models it (the simulated card's ID and watchdog among it, so it is the
/// simulated card's calibration only: a real card's is measured by the probe
/// and read from its card file, [`RigConfig`](super::RigConfig)): 80 mm per 8192 counts (9.765625 µm per count), both encoders
/// counting up when the carts move away from the wall, 24 V full scale, the
/// motor on PWM channel 0, cart 1 on encoder 0, cart 2 on encoder 1, travel
/// limits ±50 mm on both carts, the simulated card's ID `0xa5` and 100 ms
/// watchdog, and the plausibility checks: no cart faster than 2 m/s (a
/// faster count change is a bus fault); a change of drive of 6 V held for
/// 0.5 s must move the driven cart's (cart 2's) encoder by 3 counts (or the
/// motor or that encoder is not responding), and within 10 ms if it moves
/// cart 1 (or cart 2's encoder is dead); the drive may stay at its limit
/// (±24 V) for at most 2 s.
///
/// # The driven cart
///
/// The motor pushes cart 2 ([`Cart::Two`](super::Cart::Two), see
/// [`MassSpring`](super::MassSpring)); cart 1 moves only through the spring
/// between them. So a change of drive must show first on cart 2's encoder
/// (`encoder_channels[1]`): the response checks watch that encoder, not
/// whichever moved more. A dead or disconnected cart-2 encoder reads a
/// cart at rest while the motor pushes the real one towards its end stop,
/// and its travel limit cannot be checked; cart 1 moving the way the drive
/// pushes while cart 2's encoder does not is how the rig tells, within
/// [`follow_time`](Self::follow_time). (Cart 1 moving *against* the drive
/// can hold cart 2 still: a controller feeding back cart 1's position does
/// that, Table 6's among them.)
///
/// # Examples
///
/// ```
/// use ctrlab::lab::Calibration;
/// let cal = Calibration::default();
/// assert_eq!(cal.metres_per_count * 8192.0, 0.080);
/// let flipped = Calibration { sign: [1.0, -1.0], ..cal };
/// assert!(flipped.validate().is_ok());
/// ```
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Calibration {
    /// Cart travel per encoder count, m (> 0).
    pub metres_per_count: f64,
    /// Sign of each encoder (cart 1, cart 2): +1 when counting up means the
    /// cart moves away from the wall, −1 otherwise.
    pub sign: [f64; 2],
    /// Motor voltage at 100 % duty, V (> 0); commands saturate at ±this.
    pub volts_full_scale: f64,
    /// The PWM channel driving the motor (0–3).
    pub pwm_channel: usize,
    /// The encoder channels of cart 1 and cart 2 (0–3, distinct).
    pub encoder_channels: [usize; 2],
    /// Software travel limits of cart 1 and cart 2, m (> 0, symmetric about
    /// the position where the counters were cleared).
    pub travel_limits: [f64; 2],
    /// What the card's ID register must read; the rig checks it when it is
    /// built (and tells an open bus, `0x00` or `0xff`, from a card). Neither
    /// `0x00` nor `0xff`: an ID an open bus also reads proves nothing.
    pub card_id: u8,
    /// The card's watchdog timeout, s, if it has one: the control loop
    /// halts before half of it passes without a sample. In a TOML file, a
    /// number of seconds or `"none"` (said explicitly, never by leaving the
    /// key out).
    #[serde(with = "watchdog")]
    pub watchdog_timeout: Option<f64>,
    /// Drive this card although it has no watchdog (`watchdog_timeout`
    /// `None`): then nothing on the card stops the motor if the PC stops
    /// driving it (a crash, a hung process, a pulled cable), and only the
    /// software's own limits and an emergency stop within reach remain.
    /// Building a rig from a card file without a watchdog
    /// ([`RigConfig::rig`](super::RigConfig::rig)) is refused unless this
    /// is `true` (lab5: `--no-watchdog-acknowledged`). Default `false`;
    /// meaningless on a card with a watchdog.
    pub no_watchdog_acknowledged: bool,
    /// The fastest a cart can physically move, m/s (> 0): a count change
    /// implying more is a bus or counter fault, not a measurement.
    pub max_speed: f64,
    /// A drive that has changed by this much, V (> 0), since the driven
    /// cart's encoder (cart 2's, see [the driven cart](Self#the-driven-cart))
    /// last moved [`stall_counts`](Self::stall_counts) counts, held for
    /// [`stall_time`](Self::stall_time) without that encoder moving, means
    /// the motor or that encoder is not responding. (A steady drive
    /// holding the carts against the springs or their friction is not a
    /// fault; a new command the carts do not follow is: 6 V is 6.7 N on the
    /// lab's motor, millimetres on its springs.)
    pub stall_volts: f64,
    /// See [`stall_volts`](Self::stall_volts), s (> 0).
    pub stall_time: f64,
    /// See [`stall_volts`](Self::stall_volts), counts (≥ 1).
    pub stall_counts: i64,
    /// How long, s (> 0), the driven cart's encoder may lag a change of
    /// drive of [`stall_volts`](Self::stall_volts) from what held the cart
    /// at rest (at the run's start, or with its encoder still for this
    /// long) once that change has moved the other cart
    /// [`stall_counts`](Self::stall_counts) counts the way the drive
    /// pushes: the motor works and cart 2 must be moving, so an encoder
    /// that still has not moved is dead or on the wrong channel
    /// ([`LoopFault::EncoderNotFollowing`]). Short, because at full drive
    /// the lab's cart 2 reaches its ±50 mm within about 60 ms: by default
    /// 10 ms (the real cart answers 6 V within a few milliseconds, and
    /// cart 1 only moves after it). The check needs `stall_volts` to push
    /// well beyond what holds cart 2 in its friction (6 V is 6.7 N against
    /// the lab's 2.4 N).
    ///
    /// [`LoopFault::EncoderNotFollowing`]: crate::hw::LoopFault::EncoderNotFollowing
    pub follow_time: f64,
    /// The longest the drive may stay at one of its limits
    /// (+`volts_full_scale` or −`volts_full_scale`), s (> 0; default 2 s):
    /// a controller pushing one way with everything it has for longer
    /// cannot reach its reference, or acts on a wrong measurement, and the
    /// rig is halted. A flip from one limit to the other starts the time
    /// again: a bang-bang drive (a square wave at full scale) is not
    /// pushing one way against a limit
    /// ([`LoopFault::Saturated`](crate::hw::LoopFault::Saturated)). The
    /// lab's closed-loop runs saturate for a fraction of a second at a
    /// step.
    pub max_saturation_time: f64,
}

impl Default for Calibration {
    fn default() -> Self {
        Self {
            metres_per_count: 0.080 / 8192.0,
            sign: [1.0, 1.0],
            volts_full_scale: 24.0,
            pwm_channel: 0,
            encoder_channels: [0, 1],
            travel_limits: [0.050, 0.050],
            card_id: crate::hw::SIMULATED_CARD_ID,
            watchdog_timeout: Some(0.100),
            no_watchdog_acknowledged: false,
            max_speed: 2.0,
            stall_volts: 6.0,
            stall_time: 0.5,
            stall_counts: 3,
            follow_time: 0.010,
            max_saturation_time: 2.0,
        }
    }
}

impl Calibration {
    /// Checks every field.
    ///
    /// # Errors
    ///
    /// [`ConfigError`] naming the first bad field, indexed for an array
    /// (`travel_limits[1]`): [`Conflict`](ConfigError::Conflict) for cart 2
    /// on cart 1's encoder, [`Invalid`](ConfigError::Invalid) otherwise.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::Calibration;
    /// let bad = Calibration { sign: [1.0, 0.5], ..Calibration::default() };
    /// let err = bad.validate().unwrap_err();
    /// assert_eq!((err.key(), err.value()), ("sign[1]", 0.5));
    /// let never = Calibration { max_saturation_time: 0.0, ..Calibration::default() };
    /// assert_eq!(never.validate().unwrap_err().key(), "max_saturation_time");
    /// ```
    pub fn validate(&self) -> Result<(), ConfigError> {
        check_positive("metres_per_count", self.metres_per_count)?;
        check_positive("volts_full_scale", self.volts_full_scale)?;
        check_all_positive("travel_limits", &self.travel_limits)?;
        if let Some(timeout) = self.watchdog_timeout {
            check_positive("watchdog_timeout", timeout)?;
        }
        check_positive("max_speed", self.max_speed)?;
        check_positive("stall_volts", self.stall_volts)?;
        check_positive("stall_time", self.stall_time)?;
        check_positive("follow_time", self.follow_time)?;
        check_positive("max_saturation_time", self.max_saturation_time)?;
        if let Some(i) = self.sign.iter().position(|&s| s != 1.0 && s != -1.0) {
            return Err(ConfigError::invalid(
                format!("sign[{i}]"),
                self.sign[i],
                "must be +1 or -1",
            ));
        }
        if self.pwm_channel >= PWM_CHANNELS {
            return Err(ConfigError::invalid(
                "pwm_channel",
                self.pwm_channel as f64,
                "must be 0–3",
            ));
        }
        if self.card_id == 0x00 || self.card_id == 0xff {
            return Err(ConfigError::invalid(
                "card_id",
                f64::from(self.card_id),
                "must be neither 0x00 nor 0xff, which an open bus reads",
            ));
        }
        if self.stall_counts < 1 {
            return Err(ConfigError::invalid(
                "stall_counts",
                self.stall_counts as f64,
                "must be at least 1",
            ));
        }
        let [e1, e2] = self.encoder_channels;
        for (i, e) in [e1, e2].into_iter().enumerate() {
            if e >= ENCODER_CHANNELS {
                return Err(ConfigError::invalid(
                    format!("encoder_channels[{i}]"),
                    e as f64,
                    "must be two distinct channels 0–3",
                ));
            }
        }
        if e1 == e2 {
            return Err(ConfigError::conflict(
                "encoder_channels[1]",
                e2 as f64,
                "must be two distinct channels 0–3",
            ));
        }
        Ok(())
    }

    /// Checks that a card without a watchdog is driven only when that is
    /// acknowledged ([`no_watchdog_acknowledged`](Self::no_watchdog_acknowledged)).
    /// [`RigConfig::rig`](super::RigConfig::rig) calls it before touching
    /// the card; a simulated rig built in code does not need it.
    ///
    /// # Errors
    ///
    /// [`ConfigError::Conflict`] under `no_watchdog_acknowledged` (value 0,
    /// false) when `watchdog_timeout` is `None` and nothing acknowledged
    /// it; its message says what to add.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::Calibration;
    /// let bare = Calibration { watchdog_timeout: None, ..Calibration::default() };
    /// let err = bare.check_watchdog().unwrap_err();
    /// assert_eq!(err.key(), "no_watchdog_acknowledged");
    /// assert!(err.to_string().contains("no_watchdog_acknowledged = true"));
    /// let acknowledged = Calibration { no_watchdog_acknowledged: true, ..bare };
    /// assert!(acknowledged.check_watchdog().is_ok());
    /// assert!(Calibration::default().check_watchdog().is_ok()); // it has one
    /// ```
    pub fn check_watchdog(&self) -> Result<(), ConfigError> {
        if self.watchdog_timeout.is_none() && !self.no_watchdog_acknowledged {
            return Err(ConfigError::conflict(
                "no_watchdog_acknowledged",
                0.0,
                "the card has no watchdog (`watchdog_timeout = \"none\"`): nothing on it stops \
                 the motor if the PC stops driving it. To drive it anyway, with an emergency stop \
                 at hand, add `no_watchdog_acknowledged = true` under [calibration] in the card \
                 file (lab5: --no-watchdog-acknowledged)",
            ));
        }
        Ok(())
    }
}

/// `watchdog_timeout` in a file: a number of seconds, or `"none"` for a card
/// without a watchdog. A required key either way (no `Option` default), so
/// a file that forgets it is refused rather than read as "no watchdog".
mod watchdog {
    use std::fmt;

    use serde::de::{self, Visitor};
    use serde::{Deserializer, Serializer};

    /// The word for "no watchdog".
    const NONE: &str = "none";

    pub fn serialize<S: Serializer>(value: &Option<f64>, s: S) -> Result<S::Ok, S::Error> {
        match value {
            Some(seconds) => s.serialize_f64(*seconds),
            None => s.serialize_str(NONE),
        }
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Option<f64>, D::Error> {
        d.deserialize_any(Timeout)
    }

    struct Timeout;

    impl Visitor<'_> for Timeout {
        type Value = Option<f64>;

        fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
            write!(
                f,
                "a timeout in seconds, or \"{NONE}\" for a card without a watchdog"
            )
        }

        fn visit_f64<E: de::Error>(self, v: f64) -> Result<Self::Value, E> {
            Ok(Some(v))
        }

        fn visit_i64<E: de::Error>(self, v: i64) -> Result<Self::Value, E> {
            Ok(Some(v as f64))
        }

        fn visit_u64<E: de::Error>(self, v: u64) -> Result<Self::Value, E> {
            Ok(Some(v as f64))
        }

        fn visit_str<E: de::Error>(self, v: &str) -> Result<Self::Value, E> {
            if v == NONE {
                Ok(None)
            } else {
                Err(E::invalid_value(de::Unexpected::Str(v), &self))
            }
        }
    }
}
