//! The lab's rig in simulation: the two-cart plant with stick–slip Coulomb
//! friction ([`FrictionPlant`]) inside the register-level simulated card,
//! and the whole simulated rig in one call ([`SimulatedRig`]), made of its
//! parts: the truth, its [`Friction`], what the model lacks
//! ([`Unmodelled`]), the card's [`CardSettings`] and the rig's
//! [`Calibration`].

mod checks;
mod parts;
mod unmodelled;

pub use parts::{CardSettings, Friction};
pub use unmodelled::Unmodelled;

use nalgebra::SVector;

use super::file::{self, FileError};
use super::ident_input::IdentInput;
use super::{Calibration, EncoderSensor, FrictionPlant, MassSpring, MassSpringRig, schema};
use crate::hw::{
    Clock, ConfigError, ENCODER_CHANNELS, MAX_DUTY, Pc104, RigError, SimulatedCard,
    SimulatedCardConfig,
};
use crate::sim::SampledConfig;

/// The lab's rig in simulation, in one call: the plant with friction inside
/// the register-level [`SimulatedCard`], read through [`Pc104`] by a
/// [`MassSpringRig`] with the rig's [`Calibration`].
///
/// It is made of its parts: the plant's truth ([`MassSpring`]), its
/// [`Friction`], what the identification's model lacks ([`Unmodelled`]),
/// the card's own [`CardSettings`], the [`Calibration`] the
/// software uses, and where the carts start and how often they are read.
/// The simulated card is built to match the calibration: its ID register
/// reads [`card_id`](Calibration::card_id), its watchdog is
/// [`watchdog_timeout`](Calibration::watchdog_timeout), its drive gives
/// ±[`volts_full_scale`](Calibration::volts_full_scale), it counts
/// [`metres_per_count`](Calibration::metres_per_count), and the motor and
/// the carts are on the calibration's channels; each of these is said in
/// one place, the calibration. (The simulated encoders count up as the
/// carts move away from the wall: the calibration's signs are +1.)
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
/// - **Coulomb friction and stiction** ([`Friction::default`]): 1 N sliding
///   and 1.2 N breakaway on cart 1, 2 N and 2.4 N on cart 2 (the motor's
///   brushes and gears): small carts on a rail stop short of where the
///   springs alone would put them.
/// - **What the model lacks** ([`Unmodelled::default`]), so that the
///   identification is not judged on its own model:
///   - *the rotor*: the motor's rotor and pinion, J ≈ 1.35 × 10⁻⁵ kg·m²
///     (a 24 V motor of kt = 0.05 N·m/A, 1.2 × 10⁻⁵ kg·m² of rotor and
///     0.15 × 10⁻⁵ of pinion), turn with cart 2 and add J / r² =
///     1.35 × 10⁻⁵ / 0.015² = 0.06 kg to its mass: cart 2 is 0.76 kg
///     ([`effective_truth`](Self::effective_truth)) where the scale and
///     the identification say 0.7 kg;
///   - *a deadband* of 0.3 V: |u| ≤ 0.3 V gives no force, a larger input
///     acts as 0.3 V less (an H-bridge's dead time and the brushes' drop);
///   - *friction along the rail*: the Coulomb and breakaway forces vary by
///     ±15 % over a 20 mm period (rail finish, a worn spot);
///   - *friction from run to run*: each run's card draws its carts' Coulomb
///     and breakaway forces with σ = 5 % from its
///     [`seed`](CardSettings::seed) (lab5 gives run n the seed n), so runs
///     differ as a student's do ([`run_friction`](Self::run_friction)).
///
///   On it lab5's identification (5 square-wave runs at 8 V, seeds 1–5
///   and five more sets, `tests/lab_unmodelled.rs`) finds k1 and k2 within
///   0.1 %, b1 within 0.8 %, but K 2.3 to 2.6 % low and b2 3.7 to 4.8 %
///   high (the deadband and the rotor's mass), and the Coulomb forces
///   within 7 % of their nominal values.
/// - **Delay:** 0.15 ms from the PWM write to the drive applying it.
/// - **Sensing:** encoders of 8192 counts (2048 pulses × 4) per 80 mm,
///   9.765625 µm per count, with σ = 0.3 count of noise (edge jitter).
/// - **Safety:** travel limits ±50 mm (full drive, 24 V, would deflect
///   cart 2 by 54 mm), the card's 100 ms watchdog.
///
/// Everything else is the default [`Calibration`] and [`CardSettings`]:
/// register map, ID `0xa5`, motor on PWM channel 0, cart 1 on encoder 0 and
/// cart 2 on encoder 1, RK4 sub-steps of at most 0.25 ms; both carts at
/// rest at 0, read every 2 ms.
///
/// # In a file
///
/// Every field can be set from a TOML file ([`from_toml`](Self::from_toml),
/// `lab5 --truth truth.toml`), in the tables of the parts: `[truth]`,
/// `[friction]`, `[unmodelled]`, `[card]` (with `[card.map]`),
/// `[calibration]` and `[ident]` (the keys of a card file's,
/// [`RigConfig`](super::RigConfig): lab5's identification input on this
/// rig), and `period` and `initial_state` on top. Keys left out keep their default (a table given
/// in part keeps the default of the keys it lacks); unknown keys are an
/// error, as is a value [`validate`](Self::validate) refuses, named by the
/// key the file spells:
///
/// ```
/// use ctrlab::lab::SimulatedRig;
///
/// let rig = SimulatedRig::from_toml(r#"
///     period = 0.002                  # s
///
///     [truth]                         # SI: kg, N/m, N·s/m, N/V
///     m1 = 1.3
///     m2 = 0.72
///     k1 = 980.0
///     k2 = 1010.0
///     b1 = 11.0
///     b2 = 6.0
///     gain = 1.2
///
///     [friction]                      # N, cart 1 and cart 2
///     coulomb = [0.5, 1.5]
///     stiction = [0.6, 1.8]           # breakaway
///
///     [unmodelled]                    # all 0: the plant is the model
///     rotor_mass = 0.05               # kg on cart 2 (J / r²)
///     deadband = 0.2                  # V
///     friction_ripple = 0.1           # ±10 % along the rail...
///     ripple_period = 0.025           # ...over 25 mm
///     friction_variation = 0.03       # σ from run to run
///
///     [card]
///     pwm_delay = 0.0002              # s
///     encoder_noise = 0.5             # counts
///     seed = 42
///
///     [calibration]
///     travel_limits = [0.04, 0.05]    # m
///
///     [ident]                         # lab5's identification input
///     signal = "prbs"
///     volts = 6.0                     # V, peak asked for
/// "#)?;
/// assert_eq!((rig.truth.gain, rig.friction.coulomb[1]), (1.2, 1.5));
/// assert_eq!((rig.ident.signal.name(), rig.ident.volts), ("prbs", 6.0));
/// assert_eq!(rig.calibration.travel_limits, [0.04, 0.05]);
/// assert_eq!(rig.calibration.watchdog_timeout, Some(0.1)); // a default
/// assert_eq!((rig.unmodelled.rotor_mass, rig.effective_truth().m2), (0.05, 0.72 + 0.05));
/// assert!(SimulatedRig::from_toml("[truth]\ngian = 1.2").is_err()); // a typo is refused
/// let err = SimulatedRig::from_toml("[friction]\ncoulomb = [1.0, -2.0]").unwrap_err();
/// assert_eq!((err.key(), err.line()), (Some("friction.coulomb[1]"), Some(2)));
/// // More than the drive's ±24 V is refused, as in a card file.
/// let err = SimulatedRig::from_toml("[ident]\nvolts = 30.0").unwrap_err();
/// assert_eq!(err.key(), Some("ident.volts"));
/// # Ok::<(), ctrlab::lab::FileError>(())
/// ```
///
/// # Examples
///
/// ```
/// use ctrlab::hw::{Clock, VirtualClock};
/// use ctrlab::lab::{Calibration, MassSpring, SimulatedRig};
///
/// let clock = VirtualClock::new();
/// let sim = SimulatedRig {
///     // nobody kicks the watchdog in this example
///     calibration: Calibration { watchdog_timeout: None, ..Calibration::default() },
///     ..SimulatedRig::ideal(MassSpring::nominal())
/// };
/// let mut rig = sim.rig(&Clock::Virtual(clock.clone()))?;
/// rig.apply_voltage(10.0)?;
/// clock.advance(5.0)?;
/// assert!((rig.read_state()?[2] - 0.020).abs() < 1e-4); // 10 N: 20 mm
/// # Ok::<(), ctrlab::hw::RigError>(())
/// ```
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SimulatedRig {
    /// The rig's sampling period, s (finite, ≥ 1 µs).
    pub period: f64,
    /// Plant state `[x1, v1, x2, v2]` (m, m/s) when the card is created:
    /// within the travel limits, no faster than the calibration's
    /// `max_speed`.
    pub initial_state: [f64; 4],
    /// The linear plant inside; `truth.gain` is the motor's N per volt.
    pub truth: MassSpring,
    /// The Coulomb friction and stiction on the carts: their nominal
    /// values, which each run's card varies (see
    /// [`Unmodelled::friction_variation`]).
    pub friction: Friction,
    /// What the real rig has and the identification's model does not:
    /// rotor mass on cart 2, drive deadband, friction along the rail and
    /// from run to run.
    pub unmodelled: Unmodelled,
    /// The simulated card's own settings.
    pub card: CardSettings,
    /// What the software uses, and what the simulated card is built to
    /// match (see [`SimulatedRig`]).
    pub calibration: Calibration,
    /// The identification input lab5 asks for on this rig (`[ident]`,
    /// optional, as in a card file: [`RigConfig::ident`](super::RigConfig::ident));
    /// its volts at most the calibration's `volts_full_scale`. The command
    /// line's `--ident-*` flags go on top.
    #[serde(default, skip_serializing_if = "IdentInput::is_default")]
    pub ident: IdentInput,
}

impl Default for SimulatedRig {
    fn default() -> Self {
        Self {
            period: 0.002,
            initial_state: [0.0; 4],
            truth: Self::default_truth(),
            friction: Friction::default(),
            unmodelled: Unmodelled::default(),
            card: CardSettings::default(),
            calibration: Calibration::default(),
            ident: IdentInput::default(),
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
    /// Coulomb friction or stiction, none of the [`Unmodelled`] effects,
    /// no PWM delay, no encoder noise (the
    /// counts' quantisation, the ±24 V drive in 0.1 % steps, the watchdog
    /// and the travel limits stay). For comparing the rig with linear
    /// predictions exactly.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::{Friction, MassSpring, SimulatedRig};
    /// let rig = SimulatedRig::ideal(MassSpring::nominal());
    /// assert_eq!((rig.friction, rig.card.pwm_delay, rig.card.encoder_noise), (Friction::NONE, 0.0, 0.0));
    /// assert_eq!(rig.calibration, SimulatedRig::default().calibration);
    /// ```
    pub fn ideal(truth: MassSpring) -> Self {
        Self {
            truth,
            friction: Friction::NONE,
            unmodelled: Unmodelled::NONE,
            card: CardSettings::ideal(),
            ..Self::default()
        }
    }

    /// A simulated rig from TOML text (see [In a file](Self#in-a-file)),
    /// checked ([`validate`](Self::validate)).
    ///
    /// # Errors
    ///
    /// [`FileError`] with the line and the dotted key at fault: a syntax
    /// error, an unknown key, a value of the wrong type, or a value
    /// [`validate`](Self::validate) refuses
    /// ([`FileError::Invalid`], holding the same [`ConfigError`] as the
    /// same value in code).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::{FileError, SimulatedRig};
    /// assert_eq!(SimulatedRig::from_toml("")?, SimulatedRig::default());
    /// let err = SimulatedRig::from_toml("[truth]\nm1 = \"heavy\"").unwrap_err();
    /// assert!(err.to_string().contains("key `truth.m1`"), "{err}");
    /// let err = SimulatedRig::from_toml("[card]\nmax_substep = 0.0").unwrap_err();
    /// let FileError::Invalid { error, .. } = err else { panic!("{err}") };
    /// let code = SimulatedRig { card: ctrlab::lab::CardSettings { max_substep: 0.0, ..Default::default() }, ..Default::default() };
    /// assert_eq!(code.validate(), Err(error));
    /// # Ok::<(), FileError>(())
    /// ```
    pub fn from_toml(text: &str) -> Result<Self, FileError> {
        let rig: Self = file::parse_over(text, &Self::default())?;
        rig.validate().map_err(|e| FileError::invalid(text, e))?;
        Ok(rig)
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
    /// use ctrlab::lab::{FileErrorKind, SimulatedRig};
    /// let err = SimulatedRig::read_toml("no/such/truth.toml").unwrap_err();
    /// assert_eq!(err.kind(), FileErrorKind::Io);
    /// ```
    pub fn read_toml(path: impl AsRef<std::path::Path>) -> Result<Self, FileError> {
        file::read_with(path.as_ref(), Self::from_toml)
    }

    /// The rig as TOML text, every key written, in the tables of its
    /// parts; reads back equal when the rig is valid (and its seed within
    /// TOML's integers, below 2⁶³).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::SimulatedRig;
    /// let rig = SimulatedRig::default();
    /// let text = rig.to_toml();
    /// assert!(text.contains("[friction]") && text.contains("[card.map]"));
    /// assert_eq!(SimulatedRig::from_toml(&text)?, rig);
    /// # Ok::<(), ctrlab::lab::FileError>(())
    /// ```
    pub fn to_toml(&self) -> String {
        // Plain numbers, arrays and tables: serialisation cannot fail but
        // for a seed beyond TOML's integers.
        toml::to_string(self).unwrap_or_default()
    }

    /// Cart travel per encoder count, m: the calibration's, which the
    /// simulated card counts in.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::SimulatedRig;
    /// assert_eq!(SimulatedRig::default().metres_per_count(), 9.765625e-6);
    /// ```
    pub fn metres_per_count(&self) -> f64 {
        self.calibration.metres_per_count
    }

    /// The linear plant the carts really are: the truth with cart 2's
    /// mass `m2 + rotor_mass` (kg; see [`Unmodelled::rotor_mass`]), the
    /// rest as [`truth`](Self::truth) says. What an identification that
    /// fits cart 2's effective mass should find.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::SimulatedRig;
    /// let sim = SimulatedRig::default();
    /// assert!((sim.effective_truth().m2 - 0.76).abs() < 1e-12);
    /// assert_eq!(sim.effective_truth().gain, sim.truth.gain);
    /// ```
    pub fn effective_truth(&self) -> MassSpring {
        MassSpring {
            m2: self.truth.m2 + self.unmodelled.rotor_mass,
            ..self.truth
        }
    }

    /// The friction of this rig's run: the nominal [`friction`](Self::friction)
    /// drawn for the card's seed ([`Unmodelled::draw_friction`]).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::{CardSettings, SimulatedRig};
    /// let sim = SimulatedRig::default();
    /// let other = SimulatedRig { card: CardSettings { seed: 2, ..sim.card }, ..sim.clone() };
    /// assert_ne!(sim.run_friction(), other.run_friction());
    /// assert_eq!(SimulatedRig::ideal(sim.truth).run_friction().coulomb, [0.0; 2]);
    /// ```
    pub fn run_friction(&self) -> crate::lab::Friction {
        self.unmodelled
            .draw_friction(&self.friction, self.card.seed)
    }

    /// The plant inside the card: the [effective truth](Self::effective_truth)
    /// with this run's friction ([`run_friction`](Self::run_friction)),
    /// varying along the rail, behind the drive's deadband.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::{Friction, SimulatedRig, Unmodelled};
    /// let sim = SimulatedRig {
    ///     friction: Friction::coulomb([1.0, 2.0]),
    ///     unmodelled: Unmodelled::NONE,
    ///     ..Default::default()
    /// };
    /// assert_eq!(sim.plant().friction(), [1.0, 2.0]);
    /// let real = SimulatedRig::default().plant();
    /// assert_eq!((real.deadband(), real.friction_ripple()), (0.3, (0.15, 0.02)));
    /// ```
    pub fn plant(&self) -> FrictionPlant {
        let friction = self.run_friction();
        let u = &self.unmodelled;
        let plant = FrictionPlant::new(self.effective_truth(), friction.coulomb)
            .with_stiction(friction.stiction)
            .with_deadband(u.deadband);
        if u.friction_ripple > 0.0 {
            plant.with_friction_ripple(u.friction_ripple, u.ripple_period)
        } else {
            plant
        }
    }

    /// The card's configuration: the card's settings, what the calibration
    /// says of the card (ID, watchdog, supply, resolution, PWM channel),
    /// and encoders on the carts' positions as the calibration wires them.
    ///
    /// The card counts `counts_per_revolution` (its default 8192) per
    /// `8192 × metres_per_count` of travel: exactly the calibration's
    /// resolution, since scaling by a power of two is exact.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::SimulatedRig;
    /// let sim = SimulatedRig::default();
    /// let card = sim.card_config();
    /// assert_eq!(card.encoders, [Some(0), Some(2), None, None]);
    /// assert_eq!(card.units_per_count(), sim.metres_per_count());
    /// ```
    pub fn card_config(&self) -> SimulatedCardConfig<4> {
        let cal = &self.calibration;
        let mut encoders = [None; ENCODER_CHANNELS];
        for (cart, &channel) in cal.encoder_channels.iter().enumerate() {
            if let Some(slot) = encoders.get_mut(channel) {
                *slot = Some(2 * cart);
            }
        }
        let counts_per_revolution = SimulatedCardConfig::<4>::default().counts_per_revolution;
        SimulatedCardConfig {
            map: self.card.map,
            card_id: cal.card_id,
            supply_voltage: cal.volts_full_scale,
            counts_per_revolution,
            travel_per_revolution: cal.metres_per_count * counts_per_revolution,
            pwm_channel: cal.pwm_channel,
            encoders,
            encoder_noise: self.card.encoder_noise,
            seed: self.card.seed,
            watchdog_timeout: cal.watchdog_timeout,
            max_substep: self.card.max_substep,
            pwm_delay: self.card.pwm_delay,
            initial_state: SVector::from(self.initial_state),
        }
    }

    /// The simulated card alone, on `clock`.
    ///
    /// # Errors
    ///
    /// [`ConfigError`] from [`validate`](Self::validate).
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

    /// The whole simulated rig on `clock`: card, driver (with the card's
    /// register map) and [`MassSpringRig`], ready for
    /// [`hw::run`](crate::hw::run).
    ///
    /// # Errors
    ///
    /// [`RigError::Config`] from [`validate`](Self::validate).
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
            Pc104::with_map(self.card(clock)?, self.card.map)?,
            self.calibration,
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
            self.card.encoder_noise,
            self.card.seed,
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
        let supply = self.calibration.volts_full_scale;
        SampledConfig {
            max_substep: self.card.max_substep,
            input_delay: self.card.pwm_delay,
            saturation: [supply],
            input_quantisation: [supply / f64::from(MAX_DUTY)],
            schema: Some(schema()),
            seed: self.card.seed,
            ..SampledConfig::new(self.period, duration)
        }
    }

    /// The structure that reproduces this rig in output-error validation
    /// and refinement: its sub-step, its PWM delay and each cart's
    /// breakaway over Coulomb force ([`Friction::stiction_ratio`]).
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
        crate::lab::ident::SimulationModel {
            max_substep: self.card.max_substep,
            input_delay: self.card.pwm_delay,
            stiction_ratio: self.friction.stiction_ratio(),
        }
    }
}
