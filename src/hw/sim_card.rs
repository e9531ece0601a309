//! [`SimulatedCard`]: the lab's card emulated at the register level, with
//! any plant inside.

use std::time::Instant;

use crate::nalgebra::{SVector, vector};

use super::pc104::{ENCODER_CHANNELS, PWM_CHANNELS, duty_from_bytes};
use super::{Clock, ConfigError, EppPort, PortError, SimulatedCardConfig, VirtualClock};
use crate::integrate::{Integrator, Rk4};
use crate::model::Dynamics;
use crate::signal::Rng;

/// The most RK4 sub-steps one access of a [`SimulatedCard`] takes to catch
/// its plant up with its clock (at the default `max_substep` of 0.25 ms,
/// 2500 s of plant time): a bound on the work of any single register
/// access. A card further behind refuses with [`PortError::Simulation`].
///
/// # Examples
///
/// ```
/// use ctrlab::hw::{MAX_CATCH_UP_STEPS, SimulatedCardConfig};
/// let config = SimulatedCardConfig::<4>::default();
/// assert_eq!(MAX_CATCH_UP_STEPS as f64 * config.max_substep, 2500.0);
/// ```
pub const MAX_CATCH_UP_STEPS: u64 = 10_000_000;

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

/// The lab's card emulated at the register level, with any plant inside
/// (`N` states, its input the motor voltage in V): an [`EppPort`] that a
/// [`Pc104`](super::Pc104) driver talks to exactly as to the real card.
///
/// - Registers as in its [`RegisterMap`](super::RegisterMap); unmapped and
///   write-only addresses read `0xff` (an open bus), writes to them are
///   ignored.
/// - Every access first advances the plant to the current time of its
///   [`Clock`] with RK4 sub-steps (≤ `max_substep`), holding the motor
///   voltage `supply × duty / 1000` constant in between (zero-order hold),
///   and calling the plant's [`update_mode`](Dynamics::update_mode) between
///   steps. A latch at time t therefore captures the encoder counts of the
///   plant state at time t: `round(x / units_per_count + noise)`, relative
///   to the last clear, for each connected encoder.
/// - PWM duties take effect `pwm_delay` after the high byte is written
///   (immediately by default); magnitudes above 1000 saturate.
/// - The watchdog: with no kick for `watchdog_timeout`, every PWM output is
///   zeroed at exactly that instant of card time, and PWM writes are zeroed
///   until the next kick.
/// - Nothing allocates after construction.
///
/// The lab's two-cart card in one call is
/// [`lab::SimulatedRig::card`](crate::lab::SimulatedRig::card).
///
/// # Examples
///
/// A lag `x' = −10 x + 10 V` (a motor's speed, say) counted by encoder 0:
///
/// ```
/// use ctrlab::hw::{Clock, Pc104, SimulatedCard, SimulatedCardConfig, VirtualClock};
/// use ctrlab::nalgebra::{SVector, vector};
///
/// let lag = |_t: f64, x: &SVector<f64, 1>, u: &SVector<f64, 1>| vector![-10.0 * x[0] + 10.0 * u[0]];
/// let mut config = SimulatedCardConfig::<1>::default();
/// config.encoders[0] = Some(0);
/// let clock = VirtualClock::new();
/// let mut pc104 = Pc104::new(SimulatedCard::new(lag, config, Clock::Virtual(clock.clone()))?);
/// pc104.set_pwm(0, 250)?; // 6 V
/// for _ in 0..1000 {
///     clock.advance_nanos(2_000_000);
///     pc104.kick_watchdog()?;
/// }
/// pc104.latch()?;
/// // Settled at x = 6, i.e. 6 / (0.08 / 8192) counts.
/// assert_eq!(pc104.read_counter(0)?, (6.0 * 8192.0 / 0.080f64).round() as i64);
/// assert_eq!(pc104.port().voltage(), 6.0);
/// # Ok::<(), ctrlab::hw::RigError>(())
/// ```
#[derive(Debug, Clone)]
pub struct SimulatedCard<D, const N: usize> {
    config: SimulatedCardConfig<N>,
    plant: D,
    decode: [Reg; 256],
    time: Time,
    t_nanos: u64,
    state: SVector<f64, N>,
    address: u8,
    pwm_low: [u8; PWM_CHANNELS],
    duty: [i16; PWM_CHANNELS],
    /// A written duty not applied yet, and the instant (ns) it takes effect.
    pending: [Option<(i16, u64)>; PWM_CHANNELS],
    latched: [u32; ENCODER_CHANNELS],
    offset: [i64; ENCODER_CHANNELS],
    last_kick_nanos: u64,
    /// `config.watchdog_timeout` in ns, rounded once.
    watchdog_nanos: Option<u64>,
    /// `config.pwm_delay` in ns, rounded once.
    delay_nanos: u64,
    /// The earliest instant (ns) a pending write or the watchdog may act
    /// (`u64::MAX` if none): before it, advancing only integrates. Kept by
    /// `refresh_next_event` whenever a write is
    /// queued or applied or the watchdog is kicked.
    next_event: u64,
    rng: Rng,
}

impl<D: Dynamics<N, 1>, const N: usize> SimulatedCard<D, N> {
    /// A card with `plant` inside, connected as `config` says, its plant
    /// following `clock` (a [`VirtualClock`] it shares with the control
    /// loop, or wall-clock time from the card's creation).
    ///
    /// # Errors
    ///
    /// [`ConfigError`] from [`SimulatedCardConfig::validate`].
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::{Clock, SimulatedCard, SimulatedCardConfig};
    /// use ctrlab::nalgebra::SVector;
    /// let still = |_t: f64, _x: &SVector<f64, 1>, _u: &SVector<f64, 1>| SVector::<f64, 1>::zeros();
    /// let card = SimulatedCard::new(still, SimulatedCardConfig::default(), Clock::RealTime)?;
    /// assert!(card.clock().is_none());
    /// # Ok::<(), ctrlab::hw::RigError>(())
    /// ```
    pub fn new(
        plant: D,
        config: SimulatedCardConfig<N>,
        clock: Clock,
    ) -> Result<Self, ConfigError> {
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
        let (time, t_nanos) = match clock {
            Clock::Virtual(clock) => {
                let now = clock.now_nanos();
                (Time::Virtual(clock), now)
            }
            Clock::RealTime => (Time::Real(Instant::now()), 0),
        };
        let watchdog_nanos = config
            .watchdog_timeout
            .map(|timeout| (timeout * 1e9).round() as u64);
        let delay_nanos = (config.pwm_delay * 1e9).round() as u64;
        let mut card = Self {
            state: config.initial_state,
            rng: Rng::new(config.seed),
            config,
            plant,
            decode,
            time,
            t_nanos,
            address: 0,
            pwm_low: [0; PWM_CHANNELS],
            duty: [0; PWM_CHANNELS],
            pending: [None; PWM_CHANNELS],
            latched: [0; ENCODER_CHANNELS],
            offset: [0; ENCODER_CHANNELS],
            last_kick_nanos: t_nanos,
            watchdog_nanos,
            delay_nanos,
            next_event: u64::MAX,
        };
        card.refresh_next_event();
        card.latch();
        Ok(card)
    }

    /// The configuration.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{hw::Clock, lab::SimulatedRig};
    /// let card = SimulatedRig::default().card(&Clock::RealTime)?;
    /// assert_eq!(card.config().supply_voltage, 24.0);
    /// # Ok::<(), ctrlab::hw::RigError>(())
    /// ```
    pub fn config(&self) -> &SimulatedCardConfig<N> {
        &self.config
    }

    /// The plant inside.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{hw::Clock, lab::SimulatedRig};
    /// let rig = SimulatedRig::default();
    /// let card = rig.card(&Clock::RealTime)?;
    /// assert_eq!(card.plant().truth(), rig.effective_truth()); // cart 2 with the rotor
    /// assert_eq!(card.plant(), &rig.plant());
    /// # Ok::<(), ctrlab::hw::RigError>(())
    /// ```
    pub fn plant(&self) -> &D {
        &self.plant
    }

    /// The virtual clock the card follows, if it follows one.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{hw::{Clock, VirtualClock}, lab::SimulatedRig};
    /// let card = SimulatedRig::default().card(&Clock::Virtual(VirtualClock::new()))?;
    /// card.clock().unwrap().advance(0.5)?;
    /// assert_eq!(card.clock().unwrap().now(), 0.5);
    /// # Ok::<(), ctrlab::hw::RigError>(())
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
    /// use ctrlab::{hw::{Clock, VirtualClock}, lab::SimulatedRig};
    /// let clock = VirtualClock::new();
    /// let mut card = SimulatedRig::default().card(&Clock::Virtual(clock.clone()))?;
    /// clock.advance(0.002)?;
    /// assert_eq!(card.time(), 0.0);
    /// card.sync()?;
    /// assert_eq!(card.time(), 0.002);
    /// # Ok::<(), ctrlab::hw::RigError>(())
    /// ```
    pub fn time(&self) -> f64 {
        self.t_nanos as f64 * 1e-9
    }

    /// Advances the plant to the current time without a bus access.
    ///
    /// # Errors
    ///
    /// [`PortError::Simulation`] when the clock is more than
    /// [`MAX_CATCH_UP_STEPS`] sub-steps of `max_substep` ahead (at the
    /// default 0.25 ms, 2500 s: a clock advanced by hand far past a card
    /// nobody read), or when the plant's state stops being finite. Time,
    /// state and outputs are then left as they were, and every later access
    /// fails alike.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{hw::{Clock, PortErrorKind, VirtualClock}, lab::SimulatedRig};
    /// let clock = VirtualClock::new();
    /// let mut card = SimulatedRig::default().card(&Clock::Virtual(clock.clone()))?;
    /// clock.advance(1.0)?;
    /// card.sync()?;
    /// assert_eq!(card.time(), 1.0);
    /// // A million seconds would be four billion RK4 steps: refused, not run.
    /// clock.advance(1e6)?;
    /// assert_eq!(card.sync().unwrap_err().kind(), PortErrorKind::Simulation);
    /// assert_eq!(card.time(), 1.0);
    /// # Ok::<(), ctrlab::hw::RigError>(())
    /// ```
    pub fn sync(&mut self) -> Result<(), PortError> {
        let now = match &self.time {
            Time::Virtual(clock) => clock.now_nanos(),
            Time::Real(start) => u64::try_from(start.elapsed().as_nanos()).unwrap_or(u64::MAX),
        };
        if now <= self.t_nanos {
            // Another register access in the same instant (the loop reads
            // several per tick): nothing to integrate, only writes or a
            // watchdog trip due now, if any.
            if now >= self.next_event {
                self.advance_to(now);
            }
            return Ok(());
        }
        let behind = (now - self.t_nanos) as f64 * 1e-9;
        if behind / self.config.max_substep > MAX_CATCH_UP_STEPS as f64 {
            return Err(self.too_far_behind(behind));
        }
        let before = (self.t_nanos, self.state, self.duty, self.pending);
        self.advance_to(now);
        if let Some(i) = self.state.iter().position(|v| !v.is_finite()) {
            let (value, at) = (self.state[i], self.time());
            (self.t_nanos, self.state, self.duty, self.pending) = before;
            self.refresh_next_event();
            return Err(self.diverged(i, value, at));
        }
        Ok(())
    }

    #[cold]
    fn too_far_behind(&self, behind: f64) -> PortError {
        PortError::Simulation {
            reason: format!(
                "its clock is {behind:.6e} s ahead, more than the {:.6e} s it catches up in \
                 at most {MAX_CATCH_UP_STEPS} RK4 sub-steps of {} s",
                MAX_CATCH_UP_STEPS as f64 * self.config.max_substep,
                self.config.max_substep
            ),
            at: self.time(),
        }
    }

    #[cold]
    fn diverged(&self, state: usize, value: f64, at: f64) -> PortError {
        PortError::Simulation {
            reason: format!(
                "plant state {state} became {value} on the way to this time (the model \
                 diverged); the card stays at t = {:.4} s",
                self.time()
            ),
            at,
        }
    }

    /// Puts the plant in state `x` now, as a hand moving the carts would:
    /// first advances to the current time ([`sync`](Self::sync)), then
    /// replaces the state. For tests and simulated operators.
    ///
    /// # Errors
    ///
    /// [`sync`](Self::sync)'s; [`PortError::InvalidCommand`] for a
    /// non-finite state (the plant is left unchanged).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{hw::Clock, lab::SimulatedRig};
    /// use ctrlab::nalgebra::vector;
    /// let mut card = SimulatedRig::default().card(&Clock::RealTime)?;
    /// card.set_true_state(vector![0.02, 0.0, 0.0, 0.0])?;
    /// assert_eq!(card.true_state()[0], 0.02);
    /// assert!(card.set_true_state(vector![f64::NAN, 0.0, 0.0, 0.0]).is_err());
    /// # Ok::<(), ctrlab::hw::RigError>(())
    /// ```
    pub fn set_true_state(&mut self, x: SVector<f64, N>) -> Result<(), PortError> {
        if let Some(&value) = x.iter().find(|v| !v.is_finite()) {
            return Err(PortError::InvalidCommand {
                what: "simulated plant state",
                channel: None,
                value,
                limit: f64::MAX,
            });
        }
        self.sync()?;
        self.state = x;
        Ok(())
    }

    /// The true plant state at [`time`](Self::time): what the encoders
    /// measure, before quantisation and noise. For tests.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{hw::Clock, lab::SimulatedRig};
    /// use ctrlab::nalgebra::vector;
    /// let rig = SimulatedRig { initial_state: [0.01, 0.0, 0.02, 0.0], ..Default::default() };
    /// assert_eq!(rig.card(&Clock::RealTime)?.true_state()[2], 0.02);
    /// # Ok::<(), ctrlab::hw::RigError>(())
    /// ```
    pub fn true_state(&self) -> SVector<f64, N> {
        self.state
    }

    /// The duty PWM `channel` currently applies, −1000…1000 (0 for a channel
    /// beyond 3).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{hw::{Clock, Pc104}, lab::{MassSpring, SimulatedRig}};
    /// // The ideal rig's drive has no delay: the duty applies at once.
    /// let card = SimulatedRig::ideal(MassSpring::nominal()).card(&Clock::RealTime)?;
    /// let mut pc104 = Pc104::new(card);
    /// pc104.set_pwm(2, -125)?;
    /// assert_eq!(pc104.port().pwm_duty(2), -125);
    /// # Ok::<(), ctrlab::hw::RigError>(())
    /// ```
    pub fn pwm_duty(&self, channel: usize) -> i16 {
        self.duty.get(channel).copied().unwrap_or(0)
    }

    /// The voltage applied to the plant now, V: `supply × duty / 1000` of
    /// its PWM channel.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{hw::{Clock, Pc104}, lab::{MassSpring, SimulatedRig}};
    /// let card = SimulatedRig::ideal(MassSpring::nominal()).card(&Clock::RealTime)?;
    /// let mut pc104 = Pc104::new(card);
    /// pc104.set_pwm(0, -1000)?;
    /// assert_eq!(pc104.port().voltage(), -24.0);
    /// # Ok::<(), ctrlab::hw::RigError>(())
    /// ```
    pub fn voltage(&self) -> f64 {
        self.config.supply_voltage * f64::from(self.duty[self.config.pwm_channel]) / 1000.0
    }

    /// The instant (ns) the watchdog expires, if it is enabled.
    fn watchdog_deadline(&self) -> Option<u64> {
        self.watchdog_nanos
            .map(|timeout| self.last_kick_nanos.saturating_add(timeout))
    }

    /// Integrates the plant from the card's time to `target` (ns), holding
    /// the voltage, tripping the watchdog at its deadline on the way.
    fn advance_to(&mut self, target: u64) {
        // The common case, every access of a tick: nothing due on the way.
        if target < self.next_event {
            self.integrate_to(target);
            return;
        }
        // At most one watchdog trip and one pending write per channel lie
        // ahead, so this loop ends after PWM_CHANNELS + 2 rounds.
        for _ in 0..PWM_CHANNELS + 2 {
            let watchdog = self
                .watchdog_deadline()
                .filter(|_| {
                    self.duty.iter().any(|&d| d != 0)
                        || self.pending.iter().any(|p| p.is_some_and(|(d, _)| d != 0))
                })
                .filter(|&deadline| deadline <= target);
            let write = (0..PWM_CHANNELS)
                .filter_map(|n| self.pending[n].map(|(_, at)| (at, n)))
                .filter(|&(at, _)| at <= target)
                .min();
            match (watchdog, write) {
                (Some(deadline), w) if w.is_none_or(|(at, _)| deadline <= at) => {
                    self.integrate_to(deadline);
                    // Every output goes to zero, and so would any write
                    // still in flight.
                    self.duty = [0; PWM_CHANNELS];
                    self.pending = [None; PWM_CHANNELS];
                }
                (_, Some((at, n))) => {
                    self.integrate_to(at);
                    let expired = self
                        .watchdog_deadline()
                        .is_some_and(|deadline| deadline <= at);
                    let duty = self.pending[n].take().map_or(0, |(d, _)| d);
                    self.duty[n] = if expired { 0 } else { duty };
                }
                _ => break,
            }
        }
        self.refresh_next_event();
        self.integrate_to(target);
    }

    /// Recomputes `next_event`: the earliest pending
    /// write, or the watchdog's deadline if sooner (whether or not a trip
    /// there would change an output; `advance_to` decides that).
    fn refresh_next_event(&mut self) {
        let write = self.pending.iter().flatten().map(|&(_, at)| at).min();
        self.next_event = write
            .into_iter()
            .chain(self.watchdog_deadline())
            .min()
            .unwrap_or(u64::MAX);
    }

    fn integrate_to(&mut self, target: u64) {
        if target <= self.t_nanos {
            return;
        }
        let span = target - self.t_nanos;
        // Equal steps no longer than `max_substep`, counted as the
        // sampled-data simulator counts them (the tolerance keeps T / (T / 8)
        // at 8 steps despite rounding), so both integrate alike.
        let steps = ((span as f64 * 1e-9 / self.config.max_substep) * (1.0 - 1e-12))
            .ceil()
            .max(1.0) as u64;
        let h = span as f64 * 1e-9 / steps as f64;
        let u = vector![self.voltage()];
        let t0 = self.t_nanos as f64 * 1e-9;
        // The mode hook sees each new held voltage before the first step
        // (a stuck cart may break away under it), and each step's end.
        self.plant.update_mode(t0, &mut self.state, &u);
        for k in 0..steps {
            let t = t0 + k as f64 * h;
            Rk4.step_mut(&self.plant, t, h, &mut self.state, &u);
            self.plant.update_mode(t + h, &mut self.state, &u);
        }
        self.t_nanos = target;
    }

    /// The exact (noiseless) count of encoder `channel` now, before the
    /// clear offset (0 when nothing is connected).
    fn raw_count(&self, channel: usize) -> f64 {
        match self.config.encoders[channel] {
            Some(state) => self.state[state] / self.config.units_per_count(),
            None => 0.0,
        }
    }

    fn latch(&mut self) {
        for n in 0..ENCODER_CHANNELS {
            let mut count = self.raw_count(n);
            if self.config.encoder_noise > 0.0 && self.config.encoders[n].is_some() {
                count += self.config.encoder_noise * self.rng.gaussian();
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
}

impl<D: Dynamics<N, 1>, const N: usize> EppPort for SimulatedCard<D, N> {
    fn write_address(&mut self, address: u8) -> Result<(), PortError> {
        self.sync()?;
        self.address = address;
        Ok(())
    }

    fn read_data(&mut self) -> Result<u8, PortError> {
        self.sync()?;
        Ok(match self.decode[usize::from(self.address)] {
            Reg::Id => self.config.card_id,
            Reg::Encoder(n, i) => self.latched[n].to_le_bytes()[i],
            Reg::Open | Reg::Control | Reg::PwmLow(_) | Reg::PwmHigh(_) => 0xff,
        })
    }

    fn write_data(&mut self, value: u8) -> Result<(), PortError> {
        self.sync()?;
        match self.decode[usize::from(self.address)] {
            Reg::Control => {
                let map = self.config.map;
                if value & map.watchdog_bit != 0 {
                    self.last_kick_nanos = self.t_nanos;
                    self.refresh_next_event();
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
                let duty = duty_from_bytes(self.pwm_low[n], value);
                let delay = self.delay_nanos;
                if delay == 0 {
                    let expired = self
                        .watchdog_deadline()
                        .is_some_and(|deadline| deadline <= self.t_nanos);
                    self.duty[n] = if expired { 0 } else { duty };
                } else {
                    // The drive takes the new duty `pwm_delay` later; a
                    // newer write replaces one still pending.
                    self.pending[n] = Some((duty, self.t_nanos.saturating_add(delay)));
                    self.refresh_next_event();
                }
            }
            Reg::Open | Reg::Id | Reg::Encoder(..) => {}
        }
        Ok(())
    }
}
