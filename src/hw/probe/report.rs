//! What the probe found: the [`ProbeReport`] and the registers it names.

use crate::hw::RegisterMap;

/// The control register and its latch and clear bits.
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
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Counter {
    /// Address of its least significant byte (little-endian, 4 bytes).
    pub address: u8,
    /// +1 when it counts up as the cart moves away from the wall, −1
    /// otherwise.
    pub sign: i8,
}

/// The motor's PWM register pair as found.
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
