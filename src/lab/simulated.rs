//! The lab's rig in simulation: the two-cart plant with stick–slip Coulomb
//! friction ([`FrictionPlant`]) inside the register-level simulated card,
//! and the whole simulated rig in one call ([`SimulatedRig`]).

use nalgebra::SVector;

use super::file::{self, FileError};
use super::{Calibration, EncoderSensor, MassSpring, MassSpringRig, schema};
use crate::hw::{
    Clock, ConfigError, ENCODER_CHANNELS, MAX_DUTY, Pc104, RegisterMap, RigError,
    SIMULATED_CARD_ID, SimulatedCard, SimulatedCardConfig,
};
use crate::model::Dynamics;
use crate::sim::SampledConfig;

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
/// use ctrlab::integrate::{Dynamics, Integrator, Rk4};
/// use ctrlab::lab::{FrictionPlant, MassSpring};
/// use nalgebra::vector;
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

    /// The force that holds a cart at rest, N.
    fn breakaway(&self, cart: usize) -> f64 {
        self.stiction[cart].max(self.friction[cart])
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
        self.accel.at(x, u[0])[cart] * self.mass(cart)
    }
}

impl Dynamics<4, 1> for FrictionPlant {
    #[inline]
    fn derivative(&self, _t: f64, x: &SVector<f64, 4>, u: &SVector<f64, 1>) -> SVector<f64, 4> {
        let mut dx = SVector::from([x[1], 0.0, x[3], 0.0]);
        let accel = self.accel.at(x, u[0]);
        for cart in 0..2 {
            dx[2 * cart + 1] = accel[cart];
            if self.friction[cart] > 0.0 {
                if self.direction[cart] == 0.0 {
                    dx[2 * cart] = 0.0;
                    dx[2 * cart + 1] = 0.0;
                } else {
                    dx[2 * cart + 1] -= self.friction_accel[cart] * self.direction[cart];
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
                if force.abs() <= self.breakaway(cart) {
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
                if force.abs() > self.breakaway(cart) {
                    self.direction[cart] = force.signum();
                }
            } else if v != 0.0 {
                self.direction[cart] = v.signum();
            }
        }
    }
}

/// The lab's rig in simulation, in one call: the plant with friction inside
/// the register-level [`SimulatedCard`], read through [`Pc104`] by a
/// [`MassSpringRig`] whose [`Calibration`] matches the card.
///
/// # The default rig, and why
///
/// The default is meant to behave like the lab's real rig, not like the
/// textbook model, so that a student's results on it look like theirs:
///
/// - **The plant** ([`default_truth`](Self::default_truth)): the lab's
///   masses m1 = 1.3 kg and m2 = 0.7 kg, springs k1 = 950 N/m and
///   k2 = 1020 N/m (real springs never match the nominal 1000 N/m or each
///   other), b1 = 12 N·s/m of viscous friction on cart 1.
/// - **The motor.** A 24 V DC motor on a voltage-mode PWM drive pushes with
///   `F = (kt / r)(V − (kt / r) v) / R`. With a torque constant
///   kt = 0.05 N·m/A, pinion radius r = 15 mm and armature resistance
///   R = 3 Ω (8 A at stall), that is a gain K = kt / (r R) = 1.11 N/V
///   (26.7 N at 24 V) and a back-EMF damping (kt / r)² / R = 3.7 N·s/m on
///   cart 2, which with 1.8 N·s/m of rail friction makes b2 = 5.5 N·s/m.
///   (A gain of 8.5 N/V would need R ≤ 0.084 Ω and 285 A at stall.)
/// - **Coulomb friction and stiction:** 1 N sliding and 1.2 N breakaway on
///   cart 1, 2 N and 2.4 N on cart 2 (the motor's brushes and gears): small
///   carts on a rail stop short of where the springs alone would put them.
/// - **Delay:** 0.15 ms from the PWM write to the drive applying it.
/// - **Sensing:** encoders of 8192 counts (2048 pulses × 4) per 80 mm,
///   9.765625 µm per count, with σ = 0.3 count of noise (edge jitter).
/// - **Safety:** travel limits ±50 mm (full drive, 24 V, would deflect
///   cart 2 by 54 mm), the card's 100 ms watchdog.
///
/// Everything else is the card's default: register map, ID `0xa5`, motor on
/// PWM channel 0, cart 1 on encoder 0 and cart 2 on encoder 1, RK4
/// sub-steps of at most 0.25 ms, both carts at rest at 0, read every 2 ms.
///
/// # In a file
///
/// Every field can be set from a TOML file ([`from_toml`](Self::from_toml),
/// `lab5 --truth truth.toml`); fields left out keep their default, unknown
/// fields are an error:
///
/// ```
/// use ctrlab::lab::SimulatedRig;
///
/// let rig = SimulatedRig::from_toml(r#"
///     coulomb_friction = [0.5, 1.5]   # N, cart 1 and cart 2
///     stiction = [0.6, 1.8]           # N, breakaway
///     pwm_delay = 0.0002              # s
///     encoder_noise = 0.5             # counts
///     seed = 42
///
///     [truth]                         # SI: kg, N/m, N·s/m, N/V
///     m1 = 1.3
///     m2 = 0.72
///     k1 = 980.0
///     k2 = 1010.0
///     b1 = 11.0
///     b2 = 6.0
///     gain = 1.2
/// "#)?;
/// assert_eq!((rig.truth.gain, rig.coulomb_friction[1]), (1.2, 1.5));
/// assert_eq!(rig.travel_limits, [0.05, 0.05]); // a default
/// assert!(SimulatedRig::from_toml("gian = 1.2").is_err()); // a typo is refused
/// # Ok::<(), ctrlab::lab::FileError>(())
/// ```
///
/// # Examples
///
/// ```
/// use ctrlab::hw::{Clock, VirtualClock};
/// use ctrlab::lab::{MassSpring, SimulatedRig};
///
/// let clock = VirtualClock::new();
/// let sim = SimulatedRig {
///     watchdog_timeout: None, // nobody kicks it in this example
///     ..SimulatedRig::ideal(MassSpring::nominal())
/// };
/// let mut rig = sim.rig(&Clock::Virtual(clock.clone()))?;
/// rig.apply_voltage(10.0)?;
/// clock.advance(5.0)?;
/// assert!((rig.read_state()?[2] - 0.020).abs() < 1e-4); // 10 N: 20 mm
/// # Ok::<(), ctrlab::hw::RigError>(())
/// ```
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SimulatedRig {
    /// The linear plant inside; `truth.gain` is the motor's N per volt.
    pub truth: MassSpring,
    /// Coulomb (sliding) friction force on cart 1 and cart 2, N (≥ 0), see
    /// [`FrictionPlant`].
    pub coulomb_friction: [f64; 2],
    /// Breakaway (static) friction force on cart 1 and cart 2, N (taken as
    /// at least the Coulomb force).
    pub stiction: [f64; 2],
    /// Delay from a PWM write to the drive applying it, s (≥ 0, < 1).
    pub pwm_delay: f64,
    /// Where the card's registers are.
    pub map: RegisterMap,
    /// What the ID register reads.
    pub card_id: u8,
    /// Driver voltage at 100 % duty, V (the lab's motor: 24 V).
    pub supply_voltage: f64,
    /// Encoder counts per revolution after ×4 decoding (> 0).
    pub counts_per_revolution: f64,
    /// Cart travel per encoder revolution, m (> 0).
    pub travel_per_revolution: f64,
    /// The PWM channel that drives the motor (0–3).
    pub pwm_channel: usize,
    /// The encoder channels that see cart 1 and cart 2 (0–3, distinct).
    pub encoder_channels: [usize; 2],
    /// Standard deviation of Gaussian noise added to each latched count,
    /// counts (≥ 0; 0 = noiseless).
    pub encoder_noise: f64,
    /// Seed of the noise generator: the same seed gives the same noise.
    pub seed: u64,
    /// Watchdog timeout, s: with no kick for this long (card time), all PWM
    /// outputs go to zero. `None` disables the watchdog.
    pub watchdog_timeout: Option<f64>,
    /// Largest RK4 sub-step, s (> 0).
    pub max_substep: f64,
    /// Plant state `[x1, v1, x2, v2]` (m, m/s) when the card is created.
    pub initial_state: [f64; 4],
    /// The rig's sampling period, s.
    pub period: f64,
    /// Software travel limits of cart 1 and cart 2, m.
    pub travel_limits: [f64; 2],
}

impl Default for SimulatedRig {
    fn default() -> Self {
        let card = SimulatedCardConfig::<4>::default();
        Self {
            truth: Self::default_truth(),
            coulomb_friction: [1.0, 2.0],
            stiction: [1.2, 2.4],
            pwm_delay: 0.15e-3,
            map: card.map,
            card_id: SIMULATED_CARD_ID,
            supply_voltage: card.supply_voltage,
            counts_per_revolution: card.counts_per_revolution,
            travel_per_revolution: card.travel_per_revolution,
            pwm_channel: 0,
            encoder_channels: [0, 1],
            encoder_noise: 0.3,
            seed: card.seed,
            watchdog_timeout: card.watchdog_timeout,
            max_substep: card.max_substep,
            initial_state: [0.0; 4],
            period: 0.002,
            travel_limits: Calibration::default().travel_limits,
        }
    }
}

impl SimulatedRig {
    /// The default plant inside the simulated card (see [the reasoning
    /// above](Self#the-default-rig-and-why)): m1 = 1.3 kg, m2 = 0.7 kg,
    /// k1 = 950 N/m, k2 = 1020 N/m, b1 = 12 N·s/m, b2 = 5.5 N·s/m
    /// (including the motor's back-EMF), motor gain K = 1.11 N/V.
    /// Deliberately not [`MassSpring::nominal`], so identification has
    /// something to find.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::{MassSpring, SimulatedRig};
    /// let truth = SimulatedRig::default_truth();
    /// assert_eq!((truth.k1, truth.k2, truth.gain), (950.0, 1020.0, 1.11));
    /// assert_ne!(truth, MassSpring::nominal());
    /// ```
    pub fn default_truth() -> MassSpring {
        MassSpring {
            m1: 1.3,
            m2: 0.7,
            k1: 950.0,
            k2: 1020.0,
            b1: 12.0,
            b2: 5.5,
            gain: 1.11,
        }
    }

    /// The rig with `truth` inside and nothing a linear model lacks: no
    /// Coulomb friction or stiction, no PWM delay, no encoder noise (the
    /// counts' quantisation, the ±24 V drive in 0.1 % steps, the watchdog
    /// and the travel limits stay). For comparing the rig with linear
    /// predictions exactly.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::{MassSpring, SimulatedRig};
    /// let rig = SimulatedRig::ideal(MassSpring::nominal());
    /// assert_eq!((rig.coulomb_friction, rig.pwm_delay, rig.encoder_noise), ([0.0; 2], 0.0, 0.0));
    /// assert_eq!(rig.travel_limits, SimulatedRig::default().travel_limits);
    /// ```
    pub fn ideal(truth: MassSpring) -> Self {
        Self {
            truth,
            coulomb_friction: [0.0; 2],
            stiction: [0.0; 2],
            pwm_delay: 0.0,
            encoder_noise: 0.0,
            ..Self::default()
        }
    }

    /// A simulated rig from TOML text: every field of [`SimulatedRig`],
    /// each optional (see [In a file](Self#in-a-file)).
    ///
    /// # Errors
    ///
    /// [`FileError`] with the line, the dotted key at fault (an unknown
    /// field, a value of the wrong type) and the parser's message. The values
    /// themselves are checked when the rig is built
    /// ([`validate`](Self::validate)).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::SimulatedRig;
    /// assert_eq!(SimulatedRig::from_toml("")?, SimulatedRig::default());
    /// let err = SimulatedRig::from_toml("[truth]\nm1 = \"heavy\"").unwrap_err();
    /// assert!(err.to_string().contains("key `truth.m1`"), "{err}");
    /// # Ok::<(), ctrlab::lab::FileError>(())
    /// ```
    pub fn from_toml(text: &str) -> Result<Self, FileError> {
        file::parse(text)
    }

    /// The simulated rig in `path` ([`from_toml`](Self::from_toml)).
    ///
    /// # Errors
    ///
    /// [`FileError`] with the path: [`FileError::Io`] when it cannot be
    /// read, and the errors of [`from_toml`](Self::from_toml).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::{FileError, SimulatedRig};
    /// assert!(matches!(SimulatedRig::read_toml("no/such/truth.toml"), Err(FileError::Io { .. })));
    /// ```
    pub fn read_toml(path: impl AsRef<std::path::Path>) -> Result<Self, FileError> {
        file::read_with(path.as_ref(), Self::from_toml)
    }

    /// The rig as TOML text, every field written; reads back equal.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::SimulatedRig;
    /// let rig = SimulatedRig::default();
    /// assert_eq!(SimulatedRig::from_toml(&rig.to_toml())?, rig);
    /// # Ok::<(), ctrlab::lab::FileError>(())
    /// ```
    pub fn to_toml(&self) -> String {
        // Plain numbers, arrays and tables: serialisation cannot fail.
        toml::to_string(self).unwrap_or_default()
    }

    /// Cart travel per encoder count, m.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::SimulatedRig;
    /// assert_eq!(SimulatedRig::default().metres_per_count(), 9.765625e-6);
    /// ```
    pub fn metres_per_count(&self) -> f64 {
        self.travel_per_revolution / self.counts_per_revolution
    }

    /// The plant inside the card: the truth with its Coulomb friction.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::SimulatedRig;
    /// let sim = SimulatedRig { coulomb_friction: [1.0, 2.0], ..Default::default() };
    /// assert_eq!(sim.plant().friction(), [1.0, 2.0]);
    /// ```
    pub fn plant(&self) -> FrictionPlant {
        FrictionPlant::new(self.truth, self.coulomb_friction).with_stiction(self.stiction)
    }

    /// The card's configuration: encoders on the carts' positions.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::SimulatedRig;
    /// let card = SimulatedRig::default().card_config();
    /// assert_eq!(card.encoders, [Some(0), Some(2), None, None]);
    /// ```
    pub fn card_config(&self) -> SimulatedCardConfig<4> {
        let mut encoders = [None; ENCODER_CHANNELS];
        for (cart, &channel) in self.encoder_channels.iter().enumerate() {
            if let Some(slot) = encoders.get_mut(channel) {
                *slot = Some(2 * cart);
            }
        }
        SimulatedCardConfig {
            map: self.map,
            card_id: self.card_id,
            supply_voltage: self.supply_voltage,
            counts_per_revolution: self.counts_per_revolution,
            travel_per_revolution: self.travel_per_revolution,
            pwm_channel: self.pwm_channel,
            encoders,
            encoder_noise: self.encoder_noise,
            seed: self.seed,
            watchdog_timeout: self.watchdog_timeout,
            max_substep: self.max_substep,
            pwm_delay: self.pwm_delay,
            initial_state: SVector::from(self.initial_state),
        }
    }

    /// The calibration that matches the card: its counts per metre, supply
    /// and channels, and the travel limits.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::{Calibration, SimulatedRig};
    /// assert_eq!(SimulatedRig::default().calibration(), Calibration::default());
    /// ```
    pub fn calibration(&self) -> Calibration {
        Calibration {
            metres_per_count: self.metres_per_count(),
            sign: [1.0, 1.0],
            volts_full_scale: self.supply_voltage,
            pwm_channel: self.pwm_channel,
            encoder_channels: self.encoder_channels,
            travel_limits: self.travel_limits,
            card_id: self.card_id,
            watchdog_timeout: self.watchdog_timeout,
            ..Calibration::default()
        }
    }

    /// The simulated card alone, on `clock`.
    ///
    /// # Errors
    ///
    /// [`ConfigError`] naming the first bad field (of the truth or the
    /// card).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{hw::{Clock, Pc104, SIMULATED_CARD_ID}, lab::SimulatedRig};
    /// let card = SimulatedRig::default().card(&Clock::RealTime)?;
    /// assert_eq!(Pc104::new(card).read_id()?, SIMULATED_CARD_ID);
    /// # Ok::<(), ctrlab::hw::RigError>(())
    /// ```
    pub fn card(&self, clock: &Clock) -> Result<SimulatedCard<FrictionPlant, 4>, ConfigError> {
        self.validate()?;
        SimulatedCard::new(self.plant(), self.card_config(), clock.clone())
    }

    /// The whole simulated rig on `clock`: card, driver and
    /// [`MassSpringRig`], ready for [`hw::run`](crate::hw::run).
    ///
    /// # Errors
    ///
    /// As [`card`](Self::card), and for an invalid period or travel limit.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{hw::{Clock, Rig}, lab::SimulatedRig};
    /// let rig = SimulatedRig::default().rig(&Clock::RealTime)?;
    /// assert_eq!(Rig::period(&rig), 0.002);
    /// # Ok::<(), ctrlab::hw::RigError>(())
    /// ```
    pub fn rig(
        &self,
        clock: &Clock,
    ) -> Result<MassSpringRig<SimulatedCard<FrictionPlant, 4>>, RigError> {
        MassSpringRig::with_clock(
            Pc104::new(self.card(clock)?),
            self.calibration(),
            self.period,
            clock.clone(),
        )
    }

    /// What the rig measures, for the sampled-data simulator: the card's
    /// encoder resolution and noise, speeds differenced over the period.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::SimulatedRig;
    /// assert_eq!(SimulatedRig::default().sensor().metres_per_count(), 9.765625e-6);
    /// ```
    pub fn sensor(&self) -> EncoderSensor {
        EncoderSensor::new(
            self.metres_per_count(),
            self.period,
            self.encoder_noise,
            self.seed,
        )
    }

    /// The sampled-data simulation of this rig for `duration` s: its
    /// period and sub-steps, the drive's ±supply saturation in 0.1 % duty
    /// steps, and the lab's [`schema`]. With [`plant`](Self::plant) and
    /// [`sensor`](Self::sensor), [`run_sampled`](crate::sim::run_sampled)
    /// predicts what [`rig`](Self::rig) records.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::SimulatedRig;
    /// let config = SimulatedRig::default().sampled_config(3.0);
    /// assert_eq!((config.saturation, config.input_quantisation), ([24.0], [0.024]));
    /// assert_eq!(config.validate()?, 1500);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn sampled_config(&self, duration: f64) -> SampledConfig<1, 4> {
        SampledConfig {
            max_substep: self.max_substep,
            input_delay: self.pwm_delay,
            saturation: [self.supply_voltage],
            input_quantisation: [self.supply_voltage / f64::from(MAX_DUTY)],
            schema: Some(schema()),
            seed: self.seed,
            ..SampledConfig::new(self.period, duration)
        }
    }

    /// The structure that reproduces this rig in output-error validation
    /// and refinement: its sub-step, its PWM delay and each cart's
    /// breakaway over Coulomb force (1 for a cart without friction).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::SimulatedRig;
    /// let m = SimulatedRig::default().simulation_model();
    /// assert_eq!((m.max_substep, m.input_delay), (0.25e-3, 0.15e-3));
    /// assert!(m.stiction_ratio.iter().all(|r| (r - 1.2).abs() < 1e-12));
    /// ```
    pub fn simulation_model(&self) -> crate::lab::ident::SimulationModel {
        let ratio = |c: usize| {
            let f = self.coulomb_friction[c];
            if f > 0.0 {
                (self.stiction[c] / f).max(1.0)
            } else {
                1.0
            }
        };
        crate::lab::ident::SimulationModel {
            max_substep: self.max_substep,
            input_delay: self.pwm_delay,
            stiction_ratio: [ratio(0), ratio(1)],
        }
    }

    /// Checks the truth and the friction (the card's fields are checked by
    /// [`SimulatedCardConfig::validate`]).
    ///
    /// # Errors
    ///
    /// [`ConfigError`] naming the first bad field.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::SimulatedRig;
    /// let bad = SimulatedRig { coulomb_friction: [-1.0, 0.0], ..Default::default() };
    /// assert_eq!(bad.validate().unwrap_err().key(), "coulomb_friction");
    /// ```
    pub fn validate(&self) -> Result<(), ConfigError> {
        self.truth.validate().map_err(|e| match e {
            crate::Error::InvalidParameter {
                name,
                value,
                reason,
            } => ConfigError::invalid(name, value, reason),
            _ => ConfigError::invalid("truth", f64::NAN, "invalid plant parameters"),
        })?;
        for (name, forces) in [
            ("coulomb_friction", self.coulomb_friction),
            ("stiction", self.stiction),
        ] {
            for f in forces {
                if !(f.is_finite() && f >= 0.0) {
                    return Err(ConfigError::invalid(name, f, "must be finite and ≥ 0"));
                }
            }
        }
        Calibration {
            encoder_channels: self.encoder_channels,
            ..Calibration::default()
        }
        .validate()?;
        self.card_config().validate()
    }
}
