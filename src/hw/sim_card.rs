//! [`SimulatedCard`]: the lab's card emulated at the register level, with
//! the two-cart plant inside.

use std::time::Instant;

use nalgebra::{SVector, vector};

use super::pc104::{ENCODER_CHANNELS, PWM_CHANNELS, duty_from_bytes};
use super::{EppPort, HwError, SimulatedCardConfig, VirtualClock};
use crate::MassSpring;
use crate::integrate::{Dynamics, Integrator, Rk4};

/// Where a [`SimulatedCard`] takes its time from.
///
/// # Examples
///
/// ```
/// use ctrlab::hw::{SimulatedCard, SimulatedCardConfig, TimeBase, VirtualClock};
/// let clock = VirtualClock::new();
/// let card = SimulatedCard::new(SimulatedCardConfig::default(), TimeBase::Virtual(clock.clone()))?;
/// assert!(card.clock().is_some());
/// # Ok::<(), ctrlab::hw::HwError>(())
/// ```
#[derive(Debug, Clone)]
pub enum TimeBase {
    /// Simulated time: the plant follows this clock.
    Virtual(VirtualClock),
    /// Wall-clock time (`std::time::Instant`) from the card's creation.
    RealTime,
}

/// The plant with stick–slip Coulomb friction, input in volts.
///
/// `direction[i]` is cart i's sliding direction (±1) for the current
/// sub-step, or 0 while it sticks (its speed is then exactly zero and held).
/// It is only used for a cart with friction.
#[derive(Debug, Clone, Copy)]
struct CardPlant {
    truth: MassSpring,
    friction: [f64; 2],
    direction: [f64; 2],
}

impl CardPlant {
    fn mass(&self, cart: usize) -> f64 {
        if cart == 0 {
            self.truth.m1
        } else {
            self.truth.m2
        }
    }

    /// Net force on `cart` from everything but Coulomb friction, N.
    fn other_force(&self, x: &SVector<f64, 4>, u: &SVector<f64, 1>, cart: usize) -> f64 {
        self.truth.derivative(0.0, x, u)[2 * cart + 1] * self.mass(cart)
    }

    /// Before a sub-step: a sticking cart breaks away when the other forces
    /// exceed its friction; a sliding one slides the way it moves.
    fn before_step(&mut self, x: &mut SVector<f64, 4>, u: &SVector<f64, 1>) {
        for cart in 0..2 {
            if self.friction[cart] == 0.0 {
                continue;
            }
            let v = x[2 * cart + 1];
            if self.direction[cart] == 0.0 {
                let force = self.other_force(x, u, cart);
                if force.abs() > self.friction[cart] {
                    self.direction[cart] = force.signum();
                } else {
                    x[2 * cart + 1] = 0.0;
                }
            } else if v != 0.0 {
                self.direction[cart] = v.signum();
            }
        }
    }

    /// After a sub-step: a cart whose speed reached or crossed zero sticks
    /// if the other forces are within its friction, otherwise reverses.
    fn after_step(&mut self, x: &mut SVector<f64, 4>, u: &SVector<f64, 1>) {
        for cart in 0..2 {
            let direction = self.direction[cart];
            if self.friction[cart] == 0.0 || direction == 0.0 {
                continue;
            }
            let v = x[2 * cart + 1];
            if v * direction <= 0.0 {
                let force = self.other_force(x, u, cart);
                if force.abs() <= self.friction[cart] {
                    x[2 * cart + 1] = 0.0;
                    self.direction[cart] = 0.0;
                } else {
                    self.direction[cart] = force.signum();
                }
            }
        }
    }
}

impl Dynamics<4, 1> for CardPlant {
    #[inline]
    fn derivative(&self, t: f64, x: &SVector<f64, 4>, u: &SVector<f64, 1>) -> SVector<f64, 4> {
        let mut dx = self.truth.derivative(t, x, u);
        for cart in 0..2 {
            if self.friction[cart] > 0.0 {
                if self.direction[cart] == 0.0 {
                    dx[2 * cart] = 0.0;
                    dx[2 * cart + 1] = 0.0;
                } else {
                    dx[2 * cart + 1] -=
                        self.friction[cart] * self.direction[cart] / self.mass(cart);
                }
            }
        }
        dx
    }
}

/// What lives at an address of the simulated card.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Reg {
    Open,
    Id,
    Control,
    PwmLow(usize),
    PwmHigh(usize),
    Encoder(usize, usize),
}

#[derive(Debug, Clone)]
enum Time {
    Virtual(VirtualClock),
    Real(Instant),
}

/// The lab's card emulated at the register level, with a two-cart plant
/// inside: an [`EppPort`] that a [`Pc104`](super::Pc104) driver talks to
/// exactly as to the real card.
///
/// - Registers as in its [`RegisterMap`](super::RegisterMap); unmapped and write-only addresses
///   read `0xff` (an open bus), writes to them are ignored.
/// - Every access first advances the plant to the current time of its
///   [`TimeBase`] with RK4 sub-steps (≤ `max_substep`), holding the motor
///   voltage `supply × duty / 1000` constant in between (zero-order hold).
///   A latch at time t therefore captures the encoder counts of the plant
///   state at time t: `round(x / metres_per_count + noise)`, relative to the
///   last clear.
/// - PWM duties take effect when the high byte is written; magnitudes above
///   1000 saturate.
/// - The watchdog: with no kick for `watchdog_timeout`, every PWM output is
///   zeroed at exactly that instant of card time, and PWM writes are zeroed
///   until the next kick.
/// - Nothing allocates after construction.
///
/// # Examples
///
/// ```
/// use ctrlab::hw::{Pc104, SimulatedCard, SimulatedCardConfig, VirtualClock};
///
/// let clock = VirtualClock::new();
/// let mut pc104 = Pc104::new(SimulatedCard::virtual_time(SimulatedCardConfig::default(), &clock)?);
/// pc104.set_pwm(0, 250)?; // 6 V
/// for _ in 0..1000 {
///     clock.advance_nanos(2_000_000);
///     pc104.kick_watchdog()?;
/// }
/// pc104.latch()?;
/// let x2 = pc104.read_counter(1)? as f64 * 0.080 / 8192.0;
/// // Static deflection of the default truth: F = 8.5 N/V · 6 V = 51 N.
/// assert!((x2 - (51.0 / 950.0 + 51.0 / 1020.0)).abs() < 1e-4);
/// assert_eq!(pc104.port().voltage(), 6.0);
/// # Ok::<(), ctrlab::hw::HwError>(())
/// ```
#[derive(Debug, Clone)]
pub struct SimulatedCard {
    config: SimulatedCardConfig,
    plant: CardPlant,
    decode: [Reg; 256],
    time: Time,
    t_nanos: u64,
    state: SVector<f64, 4>,
    address: u8,
    pwm_low: [u8; PWM_CHANNELS],
    duty: [i16; PWM_CHANNELS],
    latched: [u32; ENCODER_CHANNELS],
    offset: [i64; ENCODER_CHANNELS],
    last_kick_nanos: u64,
    rng: u64,
}

impl Default for SimulatedCard {
    /// The default configuration on a private [`VirtualClock`] (reach it with
    /// [`clock`](SimulatedCard::clock)).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::SimulatedCard;
    /// let card = SimulatedCard::default();
    /// assert_eq!((card.time(), card.voltage()), (0.0, 0.0));
    /// ```
    fn default() -> Self {
        Self::virtual_time(SimulatedCardConfig::default(), &VirtualClock::new())
            .expect("the default configuration is valid")
    }
}

impl SimulatedCard {
    /// A card with `config`, its plant following `time`.
    ///
    /// # Errors
    ///
    /// [`HwError::InvalidConfig`] from [`SimulatedCardConfig::validate`].
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::{SimulatedCard, SimulatedCardConfig, TimeBase};
    /// let card = SimulatedCard::new(SimulatedCardConfig::default(), TimeBase::RealTime)?;
    /// assert!(card.clock().is_none());
    /// # Ok::<(), ctrlab::hw::HwError>(())
    /// ```
    pub fn new(config: SimulatedCardConfig, time: TimeBase) -> Result<Self, HwError> {
        config.validate()?;
        let map = config.map;
        let mut decode = [Reg::Open; 256];
        decode[usize::from(map.id)] = Reg::Id;
        decode[usize::from(map.control)] = Reg::Control;
        for n in 0..PWM_CHANNELS {
            decode[usize::from(map.pwm_low[n])] = Reg::PwmLow(n);
            decode[usize::from(map.pwm_high[n])] = Reg::PwmHigh(n);
        }
        for (n, base) in map.encoder.iter().enumerate() {
            for i in 0..4 {
                decode[usize::from(*base) + i] = Reg::Encoder(n, i);
            }
        }
        let v0 = [config.initial_state[1], config.initial_state[3]];
        let plant = CardPlant {
            truth: config.truth,
            friction: config.coulomb_friction,
            direction: v0.map(|v| if v == 0.0 { 0.0 } else { v.signum() }),
        };
        let (time, t_nanos) = match time {
            TimeBase::Virtual(clock) => {
                let now = clock.now_nanos();
                (Time::Virtual(clock), now)
            }
            TimeBase::RealTime => (Time::Real(Instant::now()), 0),
        };
        let mut card = Self {
            state: config.initial_state,
            rng: config.seed,
            config,
            plant,
            decode,
            time,
            t_nanos,
            address: 0,
            pwm_low: [0; PWM_CHANNELS],
            duty: [0; PWM_CHANNELS],
            latched: [0; ENCODER_CHANNELS],
            offset: [0; ENCODER_CHANNELS],
            last_kick_nanos: t_nanos,
        };
        card.latch();
        Ok(card)
    }

    /// A card with `config` on the virtual clock `clock` (which it clones).
    ///
    /// # Errors
    ///
    /// [`HwError::InvalidConfig`] from [`SimulatedCardConfig::validate`].
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::{SimulatedCard, SimulatedCardConfig, VirtualClock};
    /// let clock = VirtualClock::new();
    /// clock.advance(1.0)?;
    /// let card = SimulatedCard::virtual_time(SimulatedCardConfig::default(), &clock)?;
    /// assert_eq!(card.time(), 1.0); // starts at the clock's time
    /// # Ok::<(), ctrlab::hw::HwError>(())
    /// ```
    pub fn virtual_time(
        config: SimulatedCardConfig,
        clock: &VirtualClock,
    ) -> Result<Self, HwError> {
        Self::new(config, TimeBase::Virtual(clock.clone()))
    }

    /// A card with `config` following wall-clock time.
    ///
    /// # Errors
    ///
    /// [`HwError::InvalidConfig`] from [`SimulatedCardConfig::validate`].
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::{SimulatedCard, SimulatedCardConfig};
    /// let card = SimulatedCard::real_time(SimulatedCardConfig::default())?;
    /// assert_eq!(card.time(), 0.0);
    /// # Ok::<(), ctrlab::hw::HwError>(())
    /// ```
    pub fn real_time(config: SimulatedCardConfig) -> Result<Self, HwError> {
        Self::new(config, TimeBase::RealTime)
    }

    /// The configuration.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::SimulatedCard;
    /// assert_eq!(SimulatedCard::default().config().supply_voltage, 24.0);
    /// ```
    pub fn config(&self) -> &SimulatedCardConfig {
        &self.config
    }

    /// The virtual clock the card follows, if it follows one.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::SimulatedCard;
    /// let card = SimulatedCard::default();
    /// card.clock().unwrap().advance(0.5)?;
    /// assert_eq!(card.clock().unwrap().now(), 0.5);
    /// # Ok::<(), ctrlab::hw::HwError>(())
    /// ```
    pub fn clock(&self) -> Option<&VirtualClock> {
        match &self.time {
            Time::Virtual(clock) => Some(clock),
            Time::Real(_) => None,
        }
    }

    /// The card's own time, s: the instant of its last access (or of
    /// [`sync`](Self::sync)). [`true_state`](Self::true_state) is the plant
    /// at this instant.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::SimulatedCard;
    /// let mut card = SimulatedCard::default();
    /// card.clock().unwrap().advance(0.002)?;
    /// assert_eq!(card.time(), 0.0);
    /// card.sync();
    /// assert_eq!(card.time(), 0.002);
    /// # Ok::<(), ctrlab::hw::HwError>(())
    /// ```
    pub fn time(&self) -> f64 {
        self.t_nanos as f64 * 1e-9
    }

    /// Advances the plant to the current time without a bus access.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::SimulatedCard;
    /// let mut card = SimulatedCard::default();
    /// card.clock().unwrap().advance(1.0)?;
    /// card.sync();
    /// assert_eq!(card.time(), 1.0);
    /// # Ok::<(), ctrlab::hw::HwError>(())
    /// ```
    pub fn sync(&mut self) {
        let now = match &self.time {
            Time::Virtual(clock) => clock.now_nanos(),
            Time::Real(start) => u64::try_from(start.elapsed().as_nanos()).unwrap_or(u64::MAX),
        };
        self.advance_to(now);
    }

    /// The true plant state `[x1, v1, x2, v2]` (m, m/s) at
    /// [`time`](Self::time): what the encoders measure, before quantisation
    /// and noise. For tests.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::{SimulatedCard, SimulatedCardConfig};
    /// use nalgebra::vector;
    /// let config = SimulatedCardConfig { initial_state: vector![0.01, 0.0, 0.02, 0.0], ..Default::default() };
    /// let card = SimulatedCard::real_time(config)?;
    /// assert_eq!(card.true_state()[2], 0.02);
    /// # Ok::<(), ctrlab::hw::HwError>(())
    /// ```
    pub fn true_state(&self) -> SVector<f64, 4> {
        self.state
    }

    /// The duty PWM `channel` currently applies, −1000…1000 (0 for a channel
    /// beyond 3).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::{Pc104, SimulatedCard};
    /// let mut pc104 = Pc104::new(SimulatedCard::default());
    /// pc104.set_pwm(2, -125)?;
    /// assert_eq!(pc104.port().pwm_duty(2), -125);
    /// # Ok::<(), ctrlab::hw::HwError>(())
    /// ```
    pub fn pwm_duty(&self, channel: usize) -> i16 {
        self.duty.get(channel).copied().unwrap_or(0)
    }

    /// The voltage applied to the motor now, V: `supply × duty / 1000` of
    /// the motor's PWM channel.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::{Pc104, SimulatedCard};
    /// let mut pc104 = Pc104::new(SimulatedCard::default());
    /// pc104.set_pwm(0, -1000)?;
    /// assert_eq!(pc104.port().voltage(), -24.0);
    /// # Ok::<(), ctrlab::hw::HwError>(())
    /// ```
    pub fn voltage(&self) -> f64 {
        self.config.supply_voltage * f64::from(self.duty[self.config.pwm_channel]) / 1000.0
    }

    /// The instant (ns) the watchdog expires, if it is enabled.
    fn watchdog_deadline(&self) -> Option<u64> {
        self.config.watchdog_timeout.map(|timeout| {
            self.last_kick_nanos
                .saturating_add((timeout * 1e9).round() as u64)
        })
    }

    /// Integrates the plant from the card's time to `target` (ns), holding
    /// the voltage, tripping the watchdog at its deadline on the way.
    fn advance_to(&mut self, target: u64) {
        if let Some(deadline) = self.watchdog_deadline()
            && deadline <= target
            && self.duty.iter().any(|&d| d != 0)
        {
            if deadline > self.t_nanos {
                self.integrate_to(deadline);
            }
            self.duty = [0; PWM_CHANNELS];
        }
        self.integrate_to(target);
    }

    fn integrate_to(&mut self, target: u64) {
        if target <= self.t_nanos {
            return;
        }
        let span = target - self.t_nanos;
        let max_step = ((self.config.max_substep * 1e9) as u64).max(1);
        let steps = span.div_ceil(max_step);
        let h = span as f64 * 1e-9 / steps as f64;
        let u = vector![self.voltage()];
        let t0 = self.t_nanos as f64 * 1e-9;
        let friction = self.plant.friction.iter().any(|&f| f > 0.0);
        for k in 0..steps {
            if friction {
                self.plant.before_step(&mut self.state, &u);
            }
            Rk4.step_mut(&self.plant, t0 + k as f64 * h, h, &mut self.state, &u);
            if friction {
                self.plant.after_step(&mut self.state, &u);
            }
        }
        self.t_nanos = target;
    }

    /// The exact (noiseless) count of encoder `channel` now, before the
    /// clear offset.
    fn raw_count(&self, channel: usize) -> f64 {
        let [c1, c2] = self.config.encoder_channels;
        let x = if channel == c1 {
            self.state[0]
        } else if channel == c2 {
            self.state[2]
        } else {
            return 0.0;
        };
        x / self.config.metres_per_count()
    }

    fn latch(&mut self) {
        for n in 0..ENCODER_CHANNELS {
            let mut count = self.raw_count(n);
            if self.config.encoder_noise > 0.0 && self.config.encoder_channels.contains(&n) {
                count += self.config.encoder_noise * self.gaussian();
            }
            // `as` saturates at the i64 range; the card's counter then wraps.
            self.latched[n] = ((count.round() as i64).wrapping_sub(self.offset[n])) as u32;
        }
    }

    fn clear(&mut self) {
        for n in 0..ENCODER_CHANNELS {
            self.offset[n] = self.raw_count(n).round() as i64;
        }
    }

    /// splitmix64: a small, fast, seedable generator (no dependency).
    fn next_u64(&mut self) -> u64 {
        self.rng = self.rng.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.rng;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// A standard normal sample (Box–Muller).
    fn gaussian(&mut self) -> f64 {
        // Uniform in (0, 1]: never 0, so the logarithm is finite.
        let u1 = ((self.next_u64() >> 11) + 1) as f64 / (1u64 << 53) as f64;
        let u2 = (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
        (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
    }
}

impl EppPort for SimulatedCard {
    fn write_address(&mut self, address: u8) -> Result<(), HwError> {
        self.sync();
        self.address = address;
        Ok(())
    }

    fn read_data(&mut self) -> Result<u8, HwError> {
        self.sync();
        Ok(match self.decode[usize::from(self.address)] {
            Reg::Id => self.config.card_id,
            Reg::Encoder(n, i) => self.latched[n].to_le_bytes()[i],
            Reg::Open | Reg::Control | Reg::PwmLow(_) | Reg::PwmHigh(_) => 0xff,
        })
    }

    fn write_data(&mut self, value: u8) -> Result<(), HwError> {
        self.sync();
        match self.decode[usize::from(self.address)] {
            Reg::Control => {
                let map = self.config.map;
                if value & map.watchdog_bit != 0 {
                    self.last_kick_nanos = self.t_nanos;
                }
                if value & map.clear_bit != 0 {
                    self.clear();
                }
                if value & map.latch_bit != 0 {
                    self.latch();
                }
            }
            Reg::PwmLow(n) => self.pwm_low[n] = value,
            Reg::PwmHigh(n) => {
                let expired = self
                    .watchdog_deadline()
                    .is_some_and(|deadline| deadline <= self.t_nanos);
                self.duty[n] = if expired {
                    0
                } else {
                    duty_from_bytes(self.pwm_low[n], value)
                };
            }
            Reg::Open | Reg::Id | Reg::Encoder(..) => {}
        }
        Ok(())
    }
}
