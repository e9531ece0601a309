//! What the probe found: the [`ProbeReport`] and the registers it names.

use crate::hw::RegisterMap;

/// The control register and its latch and clear bits.
///
/// # Examples
///
/// Masks, as in a [`RegisterMap`]: one bit each, distinct.
///
/// ```
/// use ctrlab::hw::RegisterMap;
/// use ctrlab::hw::probe::Latch;
/// let map = RegisterMap::default();
/// let latch = Latch { control: map.control, latch_bit: map.latch_bit, clear_bit: map.clear_bit };
/// assert_eq!((latch.latch_bit.count_ones(), latch.clear_bit.count_ones()), (1, 1));
/// assert_eq!(latch.latch_bit & latch.clear_bit, 0);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Latch {
    /// Address of the control register.
    pub control: u8,
    /// Bit that latches the counters.
    pub latch_bit: u8,
    /// Bit that clears the counters.
    pub clear_bit: u8,
}

/// One encoder counter as found.
///
/// # Examples
///
/// A counter with sign −1 counts down as its cart moves away from the
/// wall: its counts times the sign, times the metres per count, are the
/// distance from the wall.
///
/// ```
/// use ctrlab::hw::probe::Counter;
/// let counter = Counter { address: 0x10, sign: -1 };
/// let (raw, metres_per_count) = (-2048, 9.765625e-6); // counts; m per count, the rig's
/// let away = f64::from(counter.sign) * f64::from(raw) * metres_per_count;
/// assert_eq!(away, 0.02); // m
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Counter {
    /// Address of its least significant byte (little-endian, 4 bytes).
    pub address: u8,
    /// +1 when it counts up as the cart moves away from the wall, −1
    /// otherwise.
    pub sign: i8,
}

/// The motor's PWM register pair as found.
///
/// # Examples
///
/// ```
/// use ctrlab::hw::RegisterMap;
/// use ctrlab::hw::probe::Drive;
/// let map = RegisterMap::default();
/// let drive = Drive { low: map.pwm_low[0], high: map.pwm_high[0], duty: 96 };
/// // Per mille of the supply: 9.6 % of a 24 V supply.
/// assert!((f64::from(drive.duty) / 1000.0 * 24.0 - 2.304).abs() < 1e-12); // V
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Drive {
    /// Low byte address.
    pub low: u8,
    /// High byte address.
    pub high: u8,
    /// The duty (per mille) that moved the carts.
    pub duty: i16,
}

/// Everything the probe found.
///
/// # Examples
///
/// Everything the probe can measure of a calibration: probed on the
/// simulated rig, the report gives back the calibration it was built with.
///
/// ```
/// use ctrlab::hw::probe::{Probe, ProbeOptions};
/// use ctrlab::hw::{Clock, VirtualClock};
/// use ctrlab::lab::{Calibration, SimulatedOperator, SimulatedRig};
///
/// let (rig, clock) = (SimulatedRig::default(), VirtualClock::new());
/// let card = rig.card(&Clock::Virtual(clock.clone()))?;
/// let options = ProbeOptions { map: rig.card.map, ..Default::default() };
/// let report = Probe::new(card, SimulatedOperator::new(clock, [true, true]), options)?.run()?;
/// assert_eq!(report.map, rig.card.map);
/// assert_eq!(Calibration::from_probe(&report, &rig.calibration), rig.calibration);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct ProbeReport {
    /// The register map, with channels that could not be observed placed
    /// by stride (see [`notes`](Self::notes)).
    pub map: RegisterMap,
    /// What the ID register reads.
    pub card_id: u8,
    /// Cart 1's and cart 2's encoder channel (index into `map.encoder`).
    pub encoder_channels: [usize; 2],
    /// Cart 1's and cart 2's encoder sign (+1: counts up away from the
    /// wall).
    pub signs: [f64; 2],
    /// The motor's PWM channel (index into `map.pwm_low`).
    pub pwm_channel: usize,
    /// The watchdog timeout, s (the longest silence still obeyed, rounded
    /// down to the millisecond), or `None` when writes were still obeyed
    /// after [`ProbeOptions::max_watchdog`](super::ProbeOptions::max_watchdog).
    pub watchdog_timeout: Option<f64>,
    /// What was inferred rather than observed, and anything odd.
    pub notes: Vec<String>,
}
