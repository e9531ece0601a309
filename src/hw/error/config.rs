//! [`ConfigError`]: a configuration value is invalid, named by its key.

use crate::readable::Readable;

/// The category of a [`ConfigError`].
///
/// `#[non_exhaustive]`: match with a wildcard arm.
///
/// # Examples
///
/// ```
/// use ctrlab::hw::{ConfigErrorKind, RegisterMap};
/// let clash = RegisterMap { control: 0x10, ..RegisterMap::default() };
/// assert_eq!(clash.validate().unwrap_err().kind(), ConfigErrorKind::Conflict);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum ConfigErrorKind {
    /// A value outside what it may be on its own (not finite, not
    /// positive, a channel that does not exist).
    Invalid,
    /// A value that clashes with another setting (two registers at one
    /// address, one channel for two carts, a period the controller was not
    /// designed for).
    Conflict,
}

/// A configuration value is invalid: which key, the value, and why. What
/// the validators of the register map, the calibration, the simulated card
/// and rig, the loop and the real-time options return.
///
/// The key is the field's name as the configuration spells it, dotted and
/// indexed where the value sits in a table or an array
/// (`travel_limits[1]`, `calibration.card_id`, `friction.coulomb[0]`); a
/// configuration made of parts names its parts' errors under their table
/// ([`in_table`](Self::in_table)), so code and file name a bad value alike.
///
/// `#[non_exhaustive]`: match with a wildcard arm, or on [`kind`](Self::kind).
///
/// # Examples
///
/// ```
/// use ctrlab::hw::{ConfigError, ConfigErrorKind};
/// let e = ConfigError::invalid("max_substep", 0.0, "must be finite and > 0");
/// assert_eq!((e.kind(), e.key(), e.value()), (ConfigErrorKind::Invalid, "max_substep", 0.0));
/// assert_eq!(e.to_string(), "invalid configuration `max_substep` = 0: must be finite and > 0");
/// ```
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ConfigError {
    /// A value outside what it may be on its own.
    #[error("invalid configuration `{key}` = {}: {reason}", Readable(*.value))]
    Invalid {
        /// The field's key (see [`ConfigError`]).
        key: String,
        /// The offending value.
        value: f64,
        /// What the value must satisfy.
        reason: &'static str,
    },
    /// A value that clashes with another setting (named in the reason).
    #[error("conflicting configuration `{key}` = {}: {reason}", Readable(*.value))]
    Conflict {
        /// The field's key (see [`ConfigError`]): of two that clash, the
        /// one checked last.
        key: String,
        /// The offending value.
        value: f64,
        /// What it clashes with.
        reason: &'static str,
    },
}

impl ConfigError {
    /// An [`Invalid`](ConfigError::Invalid) value.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::ConfigError;
    /// let e = ConfigError::invalid("period", -1.0, "must be finite and > 0 s");
    /// assert!(matches!(e, ConfigError::Invalid { ref key, .. } if key == "period"));
    /// ```
    pub fn invalid(key: impl Into<String>, value: f64, reason: &'static str) -> Self {
        ConfigError::Invalid {
            key: key.into(),
            value,
            reason,
        }
    }

    /// A [`Conflict`](ConfigError::Conflict) with another setting.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::{ConfigError, ConfigErrorKind};
    /// let e = ConfigError::conflict("encoder_channels[1]", 1.0, "the same channel as cart 1's");
    /// assert_eq!(e.kind(), ConfigErrorKind::Conflict);
    /// ```
    pub fn conflict(key: impl Into<String>, value: f64, reason: &'static str) -> Self {
        ConfigError::Conflict {
            key: key.into(),
            value,
            reason,
        }
    }

    /// The category of this error.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::{ConfigError, ConfigErrorKind};
    /// assert_eq!(ConfigError::invalid("x", 0.0, "must be > 0").kind(), ConfigErrorKind::Invalid);
    /// ```
    pub fn kind(&self) -> ConfigErrorKind {
        match self {
            ConfigError::Invalid { .. } => ConfigErrorKind::Invalid,
            ConfigError::Conflict { .. } => ConfigErrorKind::Conflict,
        }
    }

    /// The key of the field at fault.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::ConfigError;
    /// assert_eq!(ConfigError::invalid("seed", 0.0, "why").key(), "seed");
    /// ```
    pub fn key(&self) -> &str {
        match self {
            ConfigError::Invalid { key, .. } | ConfigError::Conflict { key, .. } => key,
        }
    }

    /// The offending value.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::ConfigError;
    /// assert_eq!(ConfigError::invalid("seed", 7.0, "why").value(), 7.0);
    /// ```
    pub fn value(&self) -> f64 {
        match self {
            ConfigError::Invalid { value, .. } | ConfigError::Conflict { value, .. } => *value,
        }
    }

    /// What the value must satisfy, or what it clashes with.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::ConfigError;
    /// assert_eq!(ConfigError::invalid("seed", 7.0, "why").reason(), "why");
    /// ```
    pub fn reason(&self) -> &'static str {
        match self {
            ConfigError::Invalid { reason, .. } | ConfigError::Conflict { reason, .. } => reason,
        }
    }

    /// The same error with its key under `table`: `table.key`. A
    /// configuration made of parts names its parts' errors so.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::ConfigError;
    /// let e = ConfigError::invalid("travel_limits[1]", -0.05, "must be finite and > 0");
    /// assert_eq!(e.in_table("calibration").key(), "calibration.travel_limits[1]");
    /// ```
    #[must_use]
    pub fn in_table(mut self, table: &str) -> Self {
        let (ConfigError::Invalid { key, .. } | ConfigError::Conflict { key, .. }) = &mut self;
        *key = format!("{table}.{key}");
        self
    }

    /// The same error under another key (a value derived from a
    /// configuration's field, reported under that field's key).
    #[must_use]
    #[cfg(feature = "lab")]
    pub(crate) fn with_key(mut self, new: String) -> Self {
        let (ConfigError::Invalid { key, .. } | ConfigError::Conflict { key, .. }) = &mut self;
        *key = new;
        self
    }
}

/// Checks that `value` is finite and > 0 (the validators' most common rule).
pub(crate) fn check_positive(key: &'static str, value: f64) -> Result<(), ConfigError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(ConfigError::invalid(key, value, "must be finite and > 0"))
    }
}

/// Each of `values` finite and > 0, the key of a bad one indexed
/// (`travel_limits[1]`).
#[cfg(feature = "lab")]
pub(crate) fn check_all_positive(key: &'static str, values: &[f64]) -> Result<(), ConfigError> {
    match values.iter().position(|v| !(v.is_finite() && *v > 0.0)) {
        None => Ok(()),
        Some(i) => Err(ConfigError::invalid(
            format!("{key}[{i}]"),
            values[i],
            "must be finite and > 0",
        )),
    }
}
