//! [`RigConfig`]: a real card's register map and the rig's calibration in
//! one TOML file, the "card file" (`card.toml`).
//!
//! The file is documented on [`RigConfig`].

use std::fmt;
use std::path::Path;

use super::file::{self, FileError};
use super::ident_input::IdentInput;
use super::{Calibration, MassSpringRig};
use crate::hw::{ConfigError, EppPort, Pc104, PpdevOptions, RegisterMap, RigError};

mod fields;

use fields::{hex, lookup};

/// A rig's card file (`card.toml`): where the card's registers are and how
/// the rig's counts and volts map to SI.
///
/// The probe (`cargo run --example probe --features ppdev -- --port
/// /dev/parport0`) measures a card and writes its card file;
/// `lab5 --port /dev/parport0 --card card.toml` drives the rig from it. The
/// built-in [`RegisterMap::default`] and [`Calibration::default`] describe
/// the *simulated* card; a real card is driven from its card file only.
///
/// # The file
///
/// Two tables, every key required, and an optional third. Units: m, V, s,
/// m/s; addresses, bit masks and the ID may be written in hex (`0x20`) or
/// decimal.
///
/// ```
/// use ctrlab::lab::RigConfig;
///
/// let config = RigConfig::from_toml(r#"
///     ## Where the card's registers are (EPP addresses, one byte each).
///     [map]
///     id = 0x00                         # card ID register (read)
///     control = 0x01                    # control register (write): strobes below
///     latch_bit = 0x01                  # latches all four counters at once
///     clear_bit = 0x02                  # clears all four counters
///     watchdog_bit = 0x04               # kicks the watchdog
///     pwm_low = [0x10, 0x12, 0x14, 0x16]  # PWM channel 0-3, duty bits 0-7
///     pwm_high = [0x11, 0x13, 0x15, 0x17] # duty bits 8-9, bit 7 direction; applies the duty
///     encoder = [0x20, 0x24, 0x28, 0x2c]  # 32-bit counter 0-3, little-endian, 4 addresses each
///
///     ## How counts and volts map to SI, and what is wired where.
///     [calibration]
///     metres_per_count = 9.765625e-6    # m per encoder count (80 mm per 8192 counts)
///     sign = [1.0, -1.0]                # +1: counting up moves the cart away from the wall
///     volts_full_scale = 24.0           # V at 100 % duty; commands saturate at ± this
///     pwm_channel = 0                   # the motor's PWM channel (0-3)
///     encoder_channels = [0, 1]         # cart 1's and cart 2's encoder (0-3, distinct)
///     travel_limits = [0.04, 0.05]      # m, ± about where the counters were cleared
///     card_id = 0x3c                    # what the ID register must read
///     watchdog_timeout = 0.1            # s, or "none" for a card without one
///     no_watchdog_acknowledged = false  # true: drive a card without a watchdog anyway
///     max_speed = 2.0                   # m/s: a faster count change is a bus fault
///     stall_volts = 6.0                 # V of new drive that must move cart 2's encoder
///     stall_time = 0.5                  # s cart 2 may take to answer it
///     stall_counts = 3                  # counts that answer it
///     follow_time = 0.01                # s cart 2's encoder may lag cart 1's in answering it
///     max_saturation_time = 2.0         # s the drive may stay at ± volts_full_scale
///
///     ## How this PC's parallel port is driven (optional; keys default).
///     [port]
///     data_dir = true                   # PPDATADIR around each EPP read (default false)
/// "#)?;
/// assert_eq!((config.calibration.card_id, config.map.encoder[1]), (0x3c, 0x24));
/// assert_eq!(config.calibration.sign[1], -1.0);
/// assert!(config.port.data_dir);
/// # Ok::<(), ctrlab::lab::FileError>(())
/// ```
///
/// # Why every key is required
///
/// [`SimulatedRig`](super::SimulatedRig)'s file fills the fields it lacks
/// with defaults: it describes a simulation. A card file describes hardware
/// that moves: a key left out would silently take the simulated card's value
/// (its ID `0xa5`, its register addresses, its 100 ms watchdog), and the
/// driver would write registers nobody checked on this card. So a missing
/// key is refused, like an unknown one (a typo) and a value of the wrong
/// type, and the values are checked on load: each error names the key, as
/// `calibration.travel_limits` or `map.encoder[2]`.
///
/// The `[port]` table is the exception: it describes the PC's parallel
/// port, not the card ([`PpdevOptions`]), and its defaults are what works
/// on most ports, so the table and each of its keys may be left out. An
/// unknown key in it is refused all the same, and a value of the wrong type
/// (`data_dir = "yes"`) is named `port.data_dir`.
///
/// The `[ident]` table is optional too: the identification input for
/// this rig ([`IdentInput`]: `signal`, `volts`, `half_period`,
/// `scale_to_travel`), each key defaulting to the lab's ±8 V square wave
/// scaled to the travel. Its values are checked as in code, and named
/// `ident.volts`:
///
/// ```
/// use ctrlab::{hw::RegisterMap, lab::{Calibration, FileError, RigConfig}};
/// use ctrlab::lab::ident_input::{IdentInput, IdentSignal};
/// let text = RigConfig::new(RegisterMap::default(), Calibration::default()).to_toml();
/// let config = RigConfig::from_toml(&format!("{text}\n[ident]\nsignal = \"prbs\"\nvolts = 5.0\n"))?;
/// assert_eq!((config.ident.signal, config.ident.volts), (IdentSignal::Prbs, 5.0));
/// assert_eq!(config.ident.half_period, IdentInput::default().half_period);
/// let err = RigConfig::from_toml(&format!("{text}\n[ident]\nvolts = -5.0\n")).unwrap_err();
/// let FileError::Invalid { error, .. } = err else { panic!("{err}") };
/// let code = IdentInput { volts: -5.0, ..IdentInput::default() }.validate().unwrap_err();
/// assert_eq!((error.key(), error.reason()), ("ident.volts", code.reason()));
/// # Ok::<(), FileError>(())
/// ```
///
/// The safety keys added in 0.4 (`no_watchdog_acknowledged`, `follow_time`,
/// `max_saturation_time`) are required like the others: a card file written
/// before them is refused, naming the first one missing; add them (the
/// example above has their defaults: `false`, `0.01`, `2.0`).
///
/// # A card without a watchdog
///
/// `watchdog_timeout = "none"` describes a card; driving it also takes
/// `no_watchdog_acknowledged = true` (or lab5's `--no-watchdog-acknowledged`):
/// [`rig`](Self::rig) refuses it otherwise, with a message saying what to
/// add. The control loop then still halts after 25 periods without a sample
/// ([`LoopConfig::max_gap`](crate::hw::LoopConfig::max_gap)), but nothing
/// on the card stops a motor the PC stopped driving.
///
/// # Examples
///
/// ```
/// use ctrlab::{hw::RegisterMap, lab::{Calibration, FileError, FileErrorKind, RigConfig}};
///
/// let config = RigConfig::new(RegisterMap::default(), Calibration::default());
/// let text = config.to_toml();
/// assert_eq!(RigConfig::from_toml(&text)?, config);
/// // A key left out is refused, and named.
/// let without = text.replace("card_id = 0xa5", "");
/// let err = RigConfig::from_toml(&without).unwrap_err();
/// assert_eq!((err.kind(), err.key()), (FileErrorKind::MissingKey, Some("calibration.card_id")));
/// # Ok::<(), FileError>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RigConfig {
    /// Where the card's registers are.
    pub map: RegisterMap,
    /// How the rig's counts and volts map to SI, its channels and limits.
    pub calibration: Calibration,
    /// How the PC's parallel port is driven (`[port]`, optional: each key
    /// defaults, see [`PpdevOptions`]).
    #[serde(default)]
    pub port: PpdevOptions,
    /// The identification input for this rig (`[ident]`, optional: each
    /// key defaults, see [`IdentInput`]; written only when it is not the
    /// default).
    #[serde(default, skip_serializing_if = "IdentInput::is_default")]
    pub ident: IdentInput,
}

impl RigConfig {
    /// A card file of `map` and `calibration`, its port driven the default
    /// way ([`PpdevOptions::default`]).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{hw::{PpdevOptions, RegisterMap}, lab::{Calibration, RigConfig}};
    /// let config = RigConfig::new(RegisterMap::default(), Calibration::default());
    /// assert_eq!(config.port, PpdevOptions::default());
    /// assert!(!config.port.data_dir);
    /// ```
    pub fn new(map: RegisterMap, calibration: Calibration) -> Self {
        Self {
            map,
            calibration,
            port: PpdevOptions::default(),
            ident: IdentInput::default(),
        }
    }

    /// The card file's `text`, checked ([`validate`](Self::validate)).
    ///
    /// # Errors
    ///
    /// [`FileError`] with the line and the dotted key at fault: a syntax
    /// error, an unknown or missing key, a value of the wrong type, or a
    /// value the checks refuse ([`FileError::Invalid`], holding the
    /// [`ConfigError`] of [`validate`](Self::validate); its message says
    /// what the value must be).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{hw::RegisterMap, lab::{Calibration, FileError, RigConfig}};
    /// let good = RigConfig::new(RegisterMap::default(), Calibration::default());
    /// let bad = good.to_toml().replace("travel_limits = [0.05, 0.05]", "travel_limits = [0.05, -0.05]");
    /// match RigConfig::from_toml(&bad) {
    ///     Err(FileError::Invalid { error, line: Some(_), .. }) => {
    ///         assert_eq!(error.key(), "calibration.travel_limits[1]")
    ///     }
    ///     other => panic!("{other:?}"),
    /// }
    /// ```
    pub fn from_toml(text: &str) -> Result<Self, FileError> {
        let config: Self = file::parse(text)?;
        config.validate().map_err(|e| FileError::invalid(text, e))?;
        Ok(config)
    }

    /// The card file at `path` ([`from_toml`](Self::from_toml)).
    ///
    /// # Errors
    ///
    /// [`FileError`] with the path: [`FileError::Io`] when it cannot be
    /// read, and the errors of [`from_toml`](Self::from_toml).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::{FileError, RigConfig};
    /// assert!(matches!(RigConfig::read_toml("no/such/card.toml"), Err(FileError::Io { .. })));
    /// ```
    pub fn read_toml(path: impl AsRef<Path>) -> Result<Self, FileError> {
        file::read_with(path.as_ref(), Self::from_toml)
    }

    /// The card file's text: every key, with what it means and its unit in
    /// a comment, addresses, bit masks and the ID in hex. Reads back equal
    /// ([`from_toml`](Self::from_toml)) when the configuration is valid.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{hw::RegisterMap, lab::{Calibration, RigConfig}};
    /// let config = RigConfig::new(RegisterMap::default(), Calibration::default());
    /// let text = config.to_toml();
    /// assert!(text.contains("encoder = [0x20, 0x24, 0x28, 0x2c]"));
    /// assert!(text.contains("# m per encoder count"));
    /// assert_eq!(RigConfig::from_toml(&text)?, config);
    /// # Ok::<(), ctrlab::lab::FileError>(())
    /// ```
    pub fn to_toml(&self) -> String {
        // Plain numbers, arrays, a string and two tables: serialisation
        // cannot fail.
        let plain = toml::to_string(self).unwrap_or_default();
        let mut out = String::from(
            "# A rig's card file (ctrlab::lab::RigConfig): where the card's registers are\n\
             # ([map]), how its counts and volts map to SI ([calibration]) and how\n\
             # this PC's parallel port is driven ([port]). Every key of [map] and\n\
             # [calibration] is required; [port]'s keys default. Units: m, V, s, m/s.\n",
        );
        let mut section = "";
        for line in plain.lines().filter(|l| !l.is_empty()) {
            if let Some(header) = line.strip_prefix('[') {
                section = header.trim_end_matches(']');
                out.push('\n');
                out.push_str(line);
            } else if let Some((key, value)) = line.split_once(" = ")
                && let Some(f) = lookup(section, key)
            {
                let value = if f.hex { hex(value) } else { value.to_owned() };
                let assignment = format!("{key} = {value}");
                out.push_str(&format!("{assignment:<40} # {}", f.comment));
            } else {
                out.push_str(line);
            }
            out.push('\n');
        }
        out
    }

    /// Writes the card file to `path` ([`to_toml`](Self::to_toml)), after
    /// checking it ([`validate`](Self::validate)): a file it writes loads.
    /// The file is written whole or not at all (into `path.tmp`, then
    /// renamed).
    ///
    /// # Errors
    ///
    /// [`FileError::Invalid`] naming the key of an invalid value (nothing
    /// is written); [`FileError::Io`] with the path.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{hw::RegisterMap, lab::{Calibration, RigConfig}};
    /// let config = RigConfig::new(RegisterMap::default(), Calibration::default());
    /// let path = std::env::temp_dir().join(format!("ctrlab-doc-card-{}.toml", std::process::id()));
    /// config.write_toml(&path)?;
    /// assert_eq!(RigConfig::read_toml(&path)?, config);
    /// # std::fs::remove_file(&path).ok();
    /// # Ok::<(), ctrlab::lab::FileError>(())
    /// ```
    pub fn write_toml(&self, path: impl AsRef<Path>) -> Result<(), FileError> {
        let text = self.to_toml();
        // The same checks, with the same errors, as reading the file back.
        Self::from_toml(&text)?;
        file::write(path.as_ref(), &text)
    }

    /// Checks the map ([`RegisterMap::validate`]), the calibration
    /// ([`Calibration::validate`]) and the identification input
    /// ([`IdentInput::validate`], and its volts within the drive's range:
    /// [`IdentInput::check_drive`]). The port's one key, a boolean, has no
    /// value to refuse: its type is checked when the file is read.
    ///
    /// # Errors
    ///
    /// [`ConfigError`] whose key is the file's dotted key (`map.encoder[3]`,
    /// `calibration.travel_limits[1]`, `ident.volts`).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{hw::RegisterMap, lab::{Calibration, RigConfig}};
    /// let config = RigConfig::new(
    ///     RegisterMap { encoder: [0x20, 0x24, 0x28, 0xfe], ..RegisterMap::default() },
    ///     Calibration::default(),
    /// );
    /// assert_eq!(config.validate().unwrap_err().key(), "map.encoder[3]");
    /// ```
    pub fn validate(&self) -> Result<(), ConfigError> {
        self.map.validate().map_err(|e| e.in_table("map"))?;
        self.calibration
            .validate()
            .map_err(|e| e.in_table("calibration"))?;
        self.ident.validate().map_err(|e| e.in_table("ident"))?;
        self.ident.check_drive(self.calibration.volts_full_scale).map_err(|e| {
            // With [ident] left out the conflict is the full scale's, the
            // key the file has.
            if self.ident == crate::lab::ident_input::IdentInput::default() {
                ConfigError::conflict(
                    "calibration.volts_full_scale",
                    self.calibration.volts_full_scale,
                    "below the identification's drive (`ident.volts`, 8 V by default): raise it, or set a lower `volts` under [ident]",
                )
            } else {
                e.in_table("ident")
            }
        })
    }

    /// The rig this card file describes, on the card behind `port`, read
    /// every `period` seconds on the wall clock: the file is checked
    /// ([`validate`](Self::validate)), a card without a watchdog must be
    /// acknowledged ([`Calibration::check_watchdog`]), then the driver
    /// takes the file's map and the rig probes the card's ID (a read, the
    /// first access). Nothing is written to the card.
    ///
    /// # Errors
    ///
    /// [`RigError::Config`] naming the key (`calibration.…`, `map.…`): an
    /// invalid value, or `calibration.no_watchdog_acknowledged` for a card
    /// without a watchdog that nobody acknowledged (the message says what
    /// to add); the errors of [`MassSpringRig::new`] (a bad period, no card
    /// or another card answering, port errors).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::{Clock, ConfigErrorKind, RegisterMap, RigError};
    /// use ctrlab::lab::{Calibration, RigConfig, SimulatedRig};
    ///
    /// let sim = SimulatedRig {
    ///     calibration: Calibration { watchdog_timeout: None, ..Calibration::default() },
    ///     ..SimulatedRig::default()
    /// };
    /// let mut file = RigConfig::new(RegisterMap::default(), sim.calibration);
    /// let err = file.rig(sim.card(&Clock::RealTime)?, 0.002).unwrap_err();
    /// assert_eq!(err.kind(), ConfigErrorKind::Conflict);
    /// assert!(err.to_string().contains("add `no_watchdog_acknowledged = true`"), "{err}");
    ///
    /// file.calibration.no_watchdog_acknowledged = true;
    /// let rig = file.rig(sim.card(&Clock::RealTime)?, 0.002)?;
    /// assert_eq!(rig.calibration().watchdog_timeout, None);
    /// # Ok::<(), RigError>(())
    /// ```
    pub fn rig<P: EppPort>(&self, port: P, period: f64) -> Result<MassSpringRig<P>, RigError> {
        self.validate()?;
        self.calibration
            .check_watchdog()
            .map_err(|e| e.in_table("calibration"))?;
        let card = Pc104::with_map(port, self.map).map_err(|e| e.in_table("map"))?;
        MassSpringRig::new(card, self.calibration, period)
    }
}

/// What the rig will use, for a person to check before anything moves: the
/// ID it expects and where, the motor's channel, registers and voltage
/// range, the carts' encoders, the travel limits, the watchdog and how the
/// port is driven.
///
/// # Examples
///
/// ```
/// use ctrlab::{hw::RegisterMap, lab::{Calibration, RigConfig}};
/// let config = RigConfig::new(RegisterMap::default(), Calibration::default());
/// let text = config.to_string();
/// assert!(text.contains("register 0x00 must read 0xa5"));
/// assert!(text.contains("PWM channel 0 (registers 0x10, 0x11), -24 V to +24 V"));
/// assert!(text.contains("±50.0 mm"));
/// assert!(text.contains("watchdog: 100 ms"));
/// assert!(text.ends_with("port: EPP reads without the data-direction bit (the default)"));
/// ```
impl fmt::Display for RigConfig {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (map, cal) = (&self.map, &self.calibration);
        let register = |addresses: &[u8], channel: usize| {
            addresses.get(channel).map_or_else(
                || "none: no such channel".to_owned(),
                |a| format!("{a:#04x}"),
            )
        };
        writeln!(
            f,
            "card ID: register {:#04x} must read {:#04x}",
            map.id, cal.card_id
        )?;
        let full = cal.volts_full_scale;
        writeln!(
            f,
            "motor: PWM channel {} (registers {}, {}), -{full} V to +{full} V in 0.1 % duty steps",
            cal.pwm_channel,
            register(&map.pwm_low, cal.pwm_channel),
            register(&map.pwm_high, cal.pwm_channel),
        )?;
        for cart in 0..2 {
            let channel = cal.encoder_channels[cart];
            writeln!(
                f,
                "cart {}: encoder {channel} (registers from {}), {} µm per count, sign {:+}; travel limit ±{:.1} mm",
                cart + 1,
                register(&map.encoder, channel),
                cal.metres_per_count * 1e6,
                cal.sign[cart],
                cal.travel_limits[cart] * 1e3,
            )?;
        }
        match cal.watchdog_timeout {
            Some(timeout) => writeln!(
                f,
                "watchdog: {:.0} ms, kicked with every latch (bit {:#04x} of control register {:#04x}); \
                 the loop halts after {:.0} ms without a sample",
                timeout * 1e3,
                map.watchdog_bit,
                map.control,
                timeout * 5e2,
            )?,
            None if cal.no_watchdog_acknowledged => writeln!(
                f,
                "watchdog: NONE (acknowledged: no_watchdog_acknowledged = true); nothing on the \
                 card stops the motor if the PC stops driving it: keep a hand on the emergency \
                 stop. The loop still halts after 25 periods without a sample"
            )?,
            None => writeln!(
                f,
                "watchdog: none; nothing on the card stops the motor if the PC stops driving it. \
                 Not acknowledged: the rig is not driven until no_watchdog_acknowledged = true"
            )?,
        }
        writeln!(
            f,
            "plausibility: a count change faster than {} m/s is a bus fault; {} V of new drive \
             that does not move cart 2's encoder {} counts within {} s is a stalled motor or \
             encoder, and within {} s while it moves cart 1 the way it pushes a dead cart-2 \
             encoder; the rig halts after {} s of drive at ±{} V",
            cal.max_speed,
            cal.stall_volts,
            cal.stall_counts,
            cal.stall_time,
            cal.follow_time,
            cal.max_saturation_time,
            cal.volts_full_scale
        )?;
        write!(
            f,
            "port: {}",
            if self.port.data_dir {
                "data-direction bit set around each EPP read (PPDATADIR)"
            } else {
                "EPP reads without the data-direction bit (the default)"
            }
        )
    }
}
