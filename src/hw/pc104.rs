//! [`Pc104`], the driver of the lab's FPGA card, and its [`RegisterMap`].
//!
//! The default register map is documented on [`RegisterMap`] and in the
//! README.

use super::{ConfigError, EppPort, PortError};

/// Number of PWM channels on the card.
///
/// # Examples
///
/// ```
/// use ctrlab::hw::{PWM_CHANNELS, RegisterMap};
/// assert_eq!(RegisterMap::default().pwm_low.len(), PWM_CHANNELS);
/// ```
pub const PWM_CHANNELS: usize = 4;
/// Number of encoder counters on the card.
///
/// # Examples
///
/// ```
/// use ctrlab::hw::{ENCODER_CHANNELS, RegisterMap};
/// assert_eq!(RegisterMap::default().encoder.len(), ENCODER_CHANNELS);
/// ```
pub const ENCODER_CHANNELS: usize = 4;
/// Largest PWM duty magnitude: 1000 = 100 %, in steps of 0.1 %.
///
/// # Examples
///
/// ```
/// use ctrlab::hw::{MAX_DUTY, Pc104, testing::RegisterFile};
/// let mut pc104 = Pc104::new(RegisterFile::new());
/// assert!(pc104.set_pwm(0, MAX_DUTY).is_ok());
/// assert!(pc104.set_pwm(0, MAX_DUTY + 1).is_err());
/// ```
pub const MAX_DUTY: i16 = 1000;
/// Direction bit in a PWM high byte: set for a negative duty.
///
/// # Examples
///
/// ```
/// use ctrlab::hw::{PWM_DIRECTION_BIT, pwm_bytes};
/// assert_eq!(pwm_bytes(-1).1, PWM_DIRECTION_BIT);
/// ```
pub const PWM_DIRECTION_BIT: u8 = 0x80;

/// Where the card's registers are, and which control bits do what.
///
/// # The default map
///
/// No register map of the real "PC104CARD" is published, so this crate
/// assumes the one below ([`RegisterMap::default`]); a card that differs is
/// described by another [`RegisterMap`] without forking the driver. Every
/// byte is accessed with its own EPP address cycle (no auto-increment).
///
/// The default is the *simulated* card's map. A real card is driven with
/// the map its probe measured, read from its card file
/// ([`lab::RigConfig`](crate::lab::RigConfig)), never with this default
/// unchecked.
///
/// | address | register | access |
/// |---|---|---|
/// | `0x00` | card ID | read |
/// | `0x01` | control: bit 0 latch all counters, bit 1 clear all counters, bit 2 kick the watchdog (strobes, self-clearing) | write |
/// | `0x10 + 2n` | PWM channel n (0–3), low byte: duty bits 0–7 | write |
/// | `0x11 + 2n` | PWM channel n, high byte: duty bits 8–9 in bits 0–1, bit 7 direction (1 = negative); the channel takes the new duty when this byte is written | write |
/// | `0x20 + 4n … 0x23 + 4n` | encoder counter n (0–3), the latched 32-bit count, little-endian, low byte at the lowest address | read |
///
/// A PWM duty is a magnitude 0…1000 (0.1 % steps) plus a direction bit; the
/// driver writes the low byte first and the high byte last, so the card
/// applies magnitude and direction together and they cannot glitch apart.
/// The counters are latched together by one control write, so the counts of
/// all four encoders belong to the same instant; they are read as 32-bit
/// counts that wrap, and the driver unwraps them into `i64` positions.
///
/// # Examples
///
/// ```
/// use ctrlab::hw::RegisterMap;
///
/// let map = RegisterMap::default();
/// assert_eq!((map.id, map.control, map.pwm_low[1], map.pwm_high[1], map.encoder[1]),
///            (0x00, 0x01, 0x12, 0x13, 0x24));
/// // A card with its encoders at 0x40…: change only what differs.
/// let other = RegisterMap { encoder: [0x40, 0x44, 0x48, 0x4c], ..map };
/// assert!(other.validate().is_ok());
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RegisterMap {
    /// Address of the read-only card ID register.
    pub id: u8,
    /// Address of the control (strobe) register.
    pub control: u8,
    /// Control bit mask that latches all counters.
    pub latch_bit: u8,
    /// Control bit mask that clears all counters to zero.
    pub clear_bit: u8,
    /// Control bit mask that kicks the watchdog.
    pub watchdog_bit: u8,
    /// Address of each PWM channel's low byte (duty bits 0–7).
    pub pwm_low: [u8; PWM_CHANNELS],
    /// Address of each PWM channel's high byte (duty bits 8–9 in bits 0–1,
    /// direction in bit 7); writing it applies the duty.
    pub pwm_high: [u8; PWM_CHANNELS],
    /// Address of each encoder counter's lowest byte; the counter occupies
    /// this and the next three addresses, little-endian.
    pub encoder: [u8; ENCODER_CHANNELS],
}

impl Default for RegisterMap {
    fn default() -> Self {
        Self {
            id: 0x00,
            control: 0x01,
            latch_bit: 0x01,
            clear_bit: 0x02,
            watchdog_bit: 0x04,
            pwm_low: [0x10, 0x12, 0x14, 0x16],
            pwm_high: [0x11, 0x13, 0x15, 0x17],
            encoder: [0x20, 0x24, 0x28, 0x2c],
        }
    }
}

impl RegisterMap {
    /// Checks the map: control bits non-zero and distinct, no two registers
    /// (counting all four bytes of each counter) at the same address, no
    /// counter running past `0xff`.
    ///
    /// # Errors
    ///
    /// [`ConfigError`] naming the first bad field and its value, indexed
    /// for an array (`encoder[3]`): [`Invalid`](ConfigError::Invalid) for a
    /// zero bit mask or a counter past `0xfc`,
    /// [`Conflict`](ConfigError::Conflict) for a mask or an address that
    /// another field already uses (the later of the two is named).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::{ConfigErrorKind, RegisterMap};
    /// let clash = RegisterMap { control: 0x10, ..RegisterMap::default() };
    /// let err = clash.validate().unwrap_err();
    /// assert_eq!((err.kind(), err.key()), (ConfigErrorKind::Conflict, "pwm_low[0]"));
    /// ```
    pub fn validate(&self) -> Result<(), ConfigError> {
        let bits = [
            ("latch_bit", self.latch_bit),
            ("clear_bit", self.clear_bit),
            ("watchdog_bit", self.watchdog_bit),
        ];
        let mut seen_bits = 0u8;
        for (name, bit) in bits {
            if bit == 0 {
                return Err(ConfigError::invalid(
                    name,
                    f64::from(bit),
                    "control bit masks must be non-zero and must not overlap",
                ));
            }
            if seen_bits & bit != 0 {
                return Err(ConfigError::conflict(
                    name,
                    f64::from(bit),
                    "control bit masks must be non-zero and must not overlap",
                ));
            }
            seen_bits |= bit;
        }
        let mut used = [false; 256];
        let mut claim = |key: String, address: u8| {
            let slot = &mut used[usize::from(address)];
            if *slot {
                return Err(ConfigError::conflict(
                    key,
                    f64::from(address),
                    "two registers share this address",
                ));
            }
            *slot = true;
            Ok(())
        };
        claim("id".to_owned(), self.id)?;
        claim("control".to_owned(), self.control)?;
        for n in 0..PWM_CHANNELS {
            claim(format!("pwm_low[{n}]"), self.pwm_low[n])?;
            claim(format!("pwm_high[{n}]"), self.pwm_high[n])?;
        }
        for (n, base) in self.encoder.into_iter().enumerate() {
            if base > 0xfc {
                return Err(ConfigError::invalid(
                    format!("encoder[{n}]"),
                    f64::from(base),
                    "a 4-byte counter must start at or below 0xfc",
                ));
            }
            for i in 0..4 {
                claim(format!("encoder[{n}]"), base + i)?;
            }
        }
        Ok(())
    }
}

/// The two bytes the card expects for a signed duty, `(low, high)`.
///
/// # Examples
///
/// ```
/// use ctrlab::hw::pwm_bytes;
/// assert_eq!(pwm_bytes(-300), (0x2c, 0x81)); // 300 = 0x12c, direction bit set
/// assert_eq!(pwm_bytes(1000), (0xe8, 0x03));
/// ```
pub fn pwm_bytes(duty: i16) -> (u8, u8) {
    let magnitude = duty.unsigned_abs().min(MAX_DUTY as u16);
    let low = (magnitude & 0xff) as u8;
    let mut high = ((magnitude >> 8) & 0x03) as u8;
    if duty < 0 {
        high |= PWM_DIRECTION_BIT;
    }
    (low, high)
}

/// The signed duty the card applies for a `(low, high)` byte pair; the
/// inverse of [`pwm_bytes`]. Magnitudes above 1000 saturate at 1000, as the
/// card does.
///
/// # Examples
///
/// ```
/// use ctrlab::hw::{duty_from_bytes, pwm_bytes};
/// assert_eq!(duty_from_bytes(0x2c, 0x81), -300);
/// assert_eq!(duty_from_bytes(pwm_bytes(-1000).0, pwm_bytes(-1000).1), -1000);
/// assert_eq!(duty_from_bytes(0xff, 0x03), 1000); // 1023 saturates
/// ```
pub fn duty_from_bytes(low: u8, high: u8) -> i16 {
    let magnitude = ((u16::from(high & 0x03) << 8) | u16::from(low)).min(MAX_DUTY as u16) as i16;
    if high & PWM_DIRECTION_BIT != 0 {
        -magnitude
    } else {
        magnitude
    }
}

/// The lab's FPGA card over an [`EppPort`]: 4 PWM outputs, 4 encoder
/// counters latched together, a watchdog, an ID register.
///
/// The driver keeps, per counter, the last raw 32-bit count and an `i64`
/// position, so [`read_counter`](Self::read_counter) is continuous across the
/// counter's wrap-around (as long as it moves less than 2³¹ counts between
/// two reads). Nothing allocates.
///
/// # Examples
///
/// ```
/// use ctrlab::hw::{Clock, Pc104, VirtualClock};
/// use ctrlab::lab::SimulatedRig;
///
/// let clock = VirtualClock::new();
/// let card = SimulatedRig::default().card(&Clock::Virtual(clock.clone()))?;
/// let mut pc104 = Pc104::new(card);
/// pc104.probe_id(ctrlab::hw::SIMULATED_CARD_ID)?;
/// pc104.set_pwm(0, 500)?; // +50 %: 12 V
/// clock.advance(0.1)?;
/// pc104.latch()?;
/// assert!(pc104.read_counter(1)? > 0); // cart 2 moved forward
/// # Ok::<(), ctrlab::hw::RigError>(())
/// ```
#[derive(Debug, Clone)]
pub struct Pc104<P> {
    port: P,
    map: RegisterMap,
    last_raw: [u32; ENCODER_CHANNELS],
    position: [i64; ENCODER_CHANNELS],
}

impl<P: EppPort> Pc104<P> {
    /// The driver over `port` with the default [`RegisterMap`]. Positions
    /// start from the counters' values read as signed 32-bit numbers.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::{Pc104, RegisterMap, testing::RegisterFile};
    /// let pc104 = Pc104::new(RegisterFile::new());
    /// assert_eq!(pc104.map(), &RegisterMap::default());
    /// ```
    pub fn new(port: P) -> Self {
        Self {
            port,
            map: RegisterMap::default(),
            last_raw: [0; ENCODER_CHANNELS],
            position: [0; ENCODER_CHANNELS],
        }
    }

    /// The driver over `port` with the register map `map`.
    ///
    /// # Errors
    ///
    /// [`ConfigError`] from [`RegisterMap::validate`].
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::{Pc104, RegisterMap, testing::RegisterFile};
    /// let map = RegisterMap { id: 0x0f, ..RegisterMap::default() };
    /// assert_eq!(Pc104::with_map(RegisterFile::new(), map)?.map().id, 0x0f);
    /// # Ok::<(), ctrlab::hw::ConfigError>(())
    /// ```
    pub fn with_map(port: P, map: RegisterMap) -> Result<Self, ConfigError> {
        map.validate()?;
        Ok(Self {
            map,
            ..Self::new(port)
        })
    }

    /// The register map in use.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::{Pc104, testing::RegisterFile};
    /// assert_eq!(Pc104::new(RegisterFile::new()).map().control, 0x01);
    /// ```
    pub fn map(&self) -> &RegisterMap {
        &self.map
    }

    /// The port.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::{Pc104, testing::RegisterFile};
    /// assert_eq!(Pc104::new(RegisterFile::new()).port().address(), 0);
    /// ```
    pub fn port(&self) -> &P {
        &self.port
    }

    /// The port, mutably.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::{Pc104, testing::RegisterFile};
    /// let mut pc104 = Pc104::new(RegisterFile::new());
    /// pc104.port_mut().set(0x00, 0x5a);
    /// assert_eq!(pc104.read_id()?, 0x5a);
    /// # Ok::<(), ctrlab::hw::PortError>(())
    /// ```
    pub fn port_mut(&mut self) -> &mut P {
        &mut self.port
    }

    /// Gives the port back.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::{Pc104, testing::RegisterFile};
    /// let mut pc104 = Pc104::new(RegisterFile::new());
    /// pc104.set_pwm(0, 7)?;
    /// assert_eq!(pc104.into_port().get(0x10), 7);
    /// # Ok::<(), ctrlab::hw::PortError>(())
    /// ```
    pub fn into_port(self) -> P {
        self.port
    }

    /// Reads the card ID register.
    ///
    /// # Errors
    ///
    /// Port errors, naming the ID register.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::{Clock, Pc104, SIMULATED_CARD_ID};
    /// let mut pc104 = Pc104::new(ctrlab::lab::SimulatedRig::default().card(&Clock::RealTime)?);
    /// assert_eq!(pc104.read_id()?, SIMULATED_CARD_ID);
    /// # Ok::<(), ctrlab::hw::RigError>(())
    /// ```
    pub fn read_id(&mut self) -> Result<u8, PortError> {
        self.port.read_register(self.map.id)
    }

    /// Checks that the card answers with ID `expected` (optional: the real
    /// card's ID is not documented).
    ///
    /// # Errors
    ///
    /// [`PortError::NotPresent`] when the ID differs, saying whether the bus
    /// is open (`0x00` or `0xff`: no card answers) or another card answers;
    /// port errors otherwise.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::{PortErrorKind, Pc104, testing::RegisterFile};
    /// let mut pc104 = Pc104::new(RegisterFile::new());
    /// assert_eq!(pc104.probe_id(0xa5).unwrap_err().kind(), PortErrorKind::NotPresent);
    /// ```
    pub fn probe_id(&mut self, expected: u8) -> Result<u8, PortError> {
        let found = self.read_id()?;
        if found == expected {
            return Ok(found);
        }
        let reason = if found == 0x00 || found == 0xff {
            format!(
                "no card answers: the ID register {:#04x} reads {found:#04x}, an open bus \
                 (no card, card unpowered, or the port not in EPP mode); expected {expected:#04x}",
                self.map.id
            )
        } else {
            format!(
                "another card answers: the ID register {:#04x} reads {found:#04x}, expected {expected:#04x}",
                self.map.id
            )
        };
        Err(PortError::NotPresent {
            device: "PC104 card".to_owned(),
            reason,
        })
    }

    /// Sets PWM `channel` (0–3) to `duty` in −1000…1000 (0.1 % steps; the
    /// sign is the direction). Low byte first, then the high byte that
    /// applies both: four EPP cycles.
    ///
    /// # Errors
    ///
    /// [`PortError::InvalidCommand`] for a channel beyond 3 or a duty beyond
    /// ±1000 (nothing is written); port errors naming the register.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::{PortErrorKind, Pc104, testing::RegisterFile};
    /// let mut pc104 = Pc104::new(RegisterFile::new());
    /// pc104.set_pwm(1, -300)?;
    /// assert_eq!((pc104.port().get(0x12), pc104.port().get(0x13)), (0x2c, 0x81));
    /// assert_eq!(pc104.set_pwm(1, 1001).unwrap_err().kind(), PortErrorKind::InvalidCommand);
    /// # Ok::<(), ctrlab::hw::PortError>(())
    /// ```
    pub fn set_pwm(&mut self, channel: usize, duty: i16) -> Result<(), PortError> {
        check_channel("PWM channel", channel, PWM_CHANNELS)?;
        if !(-MAX_DUTY..=MAX_DUTY).contains(&duty) {
            return Err(PortError::InvalidCommand {
                what: "PWM duty",
                channel: Some(channel),
                value: f64::from(duty),
                limit: f64::from(MAX_DUTY),
            });
        }
        let (low, high) = pwm_bytes(duty);
        self.port.write_register(self.map.pwm_low[channel], low)?;
        self.port.write_register(self.map.pwm_high[channel], high)
    }

    /// Strobes control bits (one register write).
    fn control(&mut self, bits: u8) -> Result<(), PortError> {
        self.port.write_register(self.map.control, bits)
    }

    /// Latches all four counters at once (one control write).
    ///
    /// # Errors
    ///
    /// Port errors naming the control register.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::{Pc104, testing::{Cycle, RecordingPort}};
    /// let mut pc104 = Pc104::new(RecordingPort::default());
    /// pc104.latch()?;
    /// assert_eq!(pc104.port().log(), &[Cycle::AddressWrite(0x01), Cycle::DataWrite(0x01)]);
    /// # Ok::<(), ctrlab::hw::PortError>(())
    /// ```
    pub fn latch(&mut self) -> Result<(), PortError> {
        self.control(self.map.latch_bit)
    }

    /// Kicks the watchdog (one control write).
    ///
    /// # Errors
    ///
    /// Port errors naming the control register.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::{Pc104, testing::RegisterFile};
    /// let mut pc104 = Pc104::new(RegisterFile::new());
    /// pc104.kick_watchdog()?;
    /// assert_eq!(pc104.port().get(0x01), 0x04);
    /// # Ok::<(), ctrlab::hw::PortError>(())
    /// ```
    pub fn kick_watchdog(&mut self) -> Result<(), PortError> {
        self.control(self.map.watchdog_bit)
    }

    /// Latches all counters and kicks the watchdog in the same control write
    /// (what a control loop does every period).
    ///
    /// # Errors
    ///
    /// Port errors naming the control register.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::{Pc104, testing::RegisterFile};
    /// let mut pc104 = Pc104::new(RegisterFile::new());
    /// pc104.latch_and_kick()?;
    /// assert_eq!(pc104.port().get(0x01), 0x05);
    /// # Ok::<(), ctrlab::hw::PortError>(())
    /// ```
    pub fn latch_and_kick(&mut self) -> Result<(), PortError> {
        self.control(self.map.latch_bit | self.map.watchdog_bit)
    }

    /// Clears all four counters to zero on the card, and the driver's
    /// positions with them.
    ///
    /// # Errors
    ///
    /// Port errors naming the control register; the driver's positions are
    /// kept when the write fails.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::{Pc104, testing::RegisterFile};
    /// let mut pc104 = Pc104::new(RegisterFile::new());
    /// pc104.port_mut().set_u32_le(0x20, 42);
    /// assert_eq!(pc104.read_counter(0)?, 42);
    /// pc104.clear_counters()?;
    /// pc104.port_mut().set_u32_le(0x20, 0); // what the card does
    /// assert_eq!(pc104.read_counter(0)?, 0);
    /// # Ok::<(), ctrlab::hw::PortError>(())
    /// ```
    pub fn clear_counters(&mut self) -> Result<(), PortError> {
        self.control(self.map.clear_bit)?;
        self.last_raw = [0; ENCODER_CHANNELS];
        self.position = [0; ENCODER_CHANNELS];
        Ok(())
    }

    /// Reads counter `channel`'s latched raw 32-bit count: four address and
    /// data-read pairs, low byte first.
    ///
    /// # Errors
    ///
    /// [`PortError::InvalidCommand`] for a channel beyond 3; port errors
    /// naming the register.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::{Pc104, testing::RegisterFile};
    /// let mut pc104 = Pc104::new(RegisterFile::new());
    /// pc104.port_mut().set_u32_le(0x2c, 0xdead_beef);
    /// assert_eq!(pc104.read_raw_counter(3)?, 0xdead_beef);
    /// # Ok::<(), ctrlab::hw::PortError>(())
    /// ```
    pub fn read_raw_counter(&mut self, channel: usize) -> Result<u32, PortError> {
        check_channel("encoder channel", channel, ENCODER_CHANNELS)?;
        let base = self.map.encoder[channel];
        let mut bytes = [0u8; 4];
        for (i, byte) in bytes.iter_mut().enumerate() {
            *byte = self.port.read_register(base + i as u8)?;
        }
        Ok(u32::from_le_bytes(bytes))
    }

    /// Reads counter `channel` and unwraps it: the position in counts, as an
    /// `i64` continuous across the 32-bit counter's wrap-around. Each read
    /// adds the signed 32-bit difference to the previous raw count.
    ///
    /// # Errors
    ///
    /// As [`read_raw_counter`](Self::read_raw_counter); the position is
    /// unchanged when the read fails.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::{Pc104, testing::RegisterFile};
    /// let mut pc104 = Pc104::new(RegisterFile::new());
    /// pc104.port_mut().set_u32_le(0x20, 0x7fff_fffe);
    /// assert_eq!(pc104.read_counter(0)?, 0x7fff_fffe);
    /// pc104.port_mut().set_u32_le(0x20, 0x8000_0002); // wrapped to negative
    /// assert_eq!(pc104.read_counter(0)?, 0x8000_0002); // but still counting up
    /// # Ok::<(), ctrlab::hw::PortError>(())
    /// ```
    pub fn read_counter(&mut self, channel: usize) -> Result<i64, PortError> {
        let raw = self.read_raw_counter(channel)?;
        let delta = raw.wrapping_sub(self.last_raw[channel]) as i32;
        self.last_raw[channel] = raw;
        self.position[channel] += i64::from(delta);
        Ok(self.position[channel])
    }
}

fn check_channel(what: &'static str, channel: usize, count: usize) -> Result<(), PortError> {
    if channel < count {
        Ok(())
    } else {
        Err(PortError::InvalidCommand {
            what,
            channel: Some(channel),
            value: channel as f64,
            limit: (count - 1) as f64,
        })
    }
}
