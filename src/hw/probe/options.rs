//! [`ProbeOptions`]: how the probe moves and waits.

use crate::hw::ConfigError;

/// How the probe moves and waits.
///
/// # Examples
///
/// ```
/// use ctrlab::hw::probe::ProbeOptions;
/// let options = ProbeOptions::default();
/// assert_eq!(options.pulse_duties, [48, 96, 120]); // per mille
/// assert!(options.validate().is_ok());
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProbeOptions {
    /// PWM duties tried in turn (per mille of full scale, > 0 and ≤ 250):
    /// the first that moves a cart is used. Each has bits 0, 1 and 7 clear,
    /// so written by mistake to a *high* byte it commands zero duty.
    pub pulse_duties: [i16; 3],
    /// How long each pulse lasts, s (0.01–1).
    pub pulse_time: f64,
    /// Samples taken while a cart is moved by hand (4–1000).
    pub samples: usize,
    /// Time between those samples, s (0.001–1).
    pub sample_interval: f64,
    /// The count change that means a cart moved (≥ 2, above the encoder
    /// noise).
    pub min_counts: i64,
    /// The longest watchdog timeout looked for, s (0.05–10); a PWM write
    /// still obeyed after this long without a kick means no watchdog.
    pub max_watchdog: f64,
}

impl Default for ProbeOptions {
    fn default() -> Self {
        Self {
            pulse_duties: [48, 96, 120],
            pulse_time: 0.15,
            samples: 30,
            sample_interval: 0.1,
            min_counts: 3,
            max_watchdog: 2.0,
        }
    }
}

impl ProbeOptions {
    /// Checks every field.
    ///
    /// # Errors
    ///
    /// [`ConfigError`] naming the first bad field.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::probe::ProbeOptions;
    /// let bad = ProbeOptions { pulse_duties: [48, 96, 400], ..Default::default() };
    /// assert!(bad.validate().is_err());
    /// ```
    pub fn validate(&self) -> Result<(), ConfigError> {
        if let Some(i) = self
            .pulse_duties
            .iter()
            .position(|d| !(1..=250).contains(d))
        {
            return Err(ConfigError::invalid(
                format!("pulse_duties[{i}]"),
                f64::from(self.pulse_duties[i]),
                "must be 1–250 per mille",
            ));
        }
        let ranges = [
            ("pulse_time", self.pulse_time, 0.01, 1.0),
            ("sample_interval", self.sample_interval, 0.001, 1.0),
            ("max_watchdog", self.max_watchdog, 0.05, 10.0),
            ("samples", self.samples as f64, 4.0, 1000.0),
            ("min_counts", self.min_counts as f64, 2.0, 1e6),
        ];
        for (name, value, low, high) in ranges {
            if !(low..=high).contains(&value) {
                return Err(ConfigError::invalid(name, value, "out of its range"));
            }
        }
        Ok(())
    }
}
