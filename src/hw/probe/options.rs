//! [`ProbeOptions`]: what the probe checks, how it moves and waits.

use crate::hw::{ConfigError, RegisterMap};

/// What the probe checks, and how it moves and waits.
///
/// By default the probe confirms the register map it is given
/// ([`map`](Self::map), from a card file or the lab's driver) and touches
/// no address outside it. The blind scan, which discovers a map by writing
/// test patterns to addresses nobody has described, runs only with
/// [`scan`](Self::scan) set.
///
/// # Examples
///
/// ```
/// use ctrlab::hw::{RegisterMap, probe::ProbeOptions};
/// let options = ProbeOptions::default();
/// assert!(!options.scan); // confirm a given map; no blind scan
/// assert_eq!(options.map, RegisterMap::default());
/// assert_eq!(options.pulse_duties, [48, 96, 120]); // per mille
/// assert!(options.validate().is_ok());
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProbeOptions {
    /// Run the blind scan (`--scan` in the `probe` example) instead of
    /// confirming [`map`](Self::map). Default `false`.
    ///
    /// **Warning:** the blind scan writes test patterns to card addresses
    /// it knows nothing about (every address that reads as an open bus,
    /// until the counter latch answers; then PWM duties to pairs of them
    /// until a cart moves). On an FPGA such an address can be a
    /// configuration register — a clock divider, an output mode, a
    /// watchdog setting — and a write there can leave the card in a state
    /// only a power cycle or a reload of its bitstream undoes. Use it only
    /// when no map can be had from the lab's existing driver or the FPGA's
    /// sources, with the motor supply off for the search.
    pub scan: bool,
    /// The register map to confirm (ignored by the blind scan): the card
    /// file's `[map]`. Default [`RegisterMap::default`], the simulated
    /// card's.
    pub map: RegisterMap,
    /// What the map's ID register must read, if known (the card file's
    /// `calibration.card_id`); `None` accepts any constant other than
    /// `0x00` and `0xff`. Default `None`.
    pub card_id: Option<u8>,
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
            scan: false,
            map: RegisterMap::default(),
            card_id: None,
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
    /// [`ConfigError`] naming the first bad field (`map.control` for one
    /// of the map's).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::{RegisterMap, probe::ProbeOptions};
    /// let bad = ProbeOptions { pulse_duties: [48, 96, 400], ..Default::default() };
    /// assert!(bad.validate().is_err());
    /// let clash = RegisterMap { control: 0x10, ..RegisterMap::default() };
    /// let bad = ProbeOptions { map: clash, ..Default::default() };
    /// assert_eq!(bad.validate().unwrap_err().key(), "map.pwm_low[0]");
    /// let idle = ProbeOptions { card_id: Some(0xff), ..Default::default() };
    /// assert_eq!(idle.validate().unwrap_err().key(), "card_id");
    /// ```
    pub fn validate(&self) -> Result<(), ConfigError> {
        self.map.validate().map_err(|e| e.in_table("map"))?;
        if let Some(id) = self.card_id.filter(|id| matches!(id, 0x00 | 0xff)) {
            return Err(ConfigError::invalid(
                "card_id",
                f64::from(id),
                "must not be 0x00 or 0xff (what an idle bus reads)",
            ));
        }
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
