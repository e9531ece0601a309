//! The simulated card against independent references (the exact ZOH model,
//! static deflections, a hand-switched watchdog reference, a hand-delayed
//! PWM write), and the rig's safety: saturation, travel limits, non-finite
//! commands, drop.
//!
//! Tests of the card's and the driver's exact behaviour run on
//! [`SimulatedRig::ideal`] (no Coulomb friction, stiction, PWM delay or
//! encoder noise), so a linear reference applies to the count; tests of the
//! lab's rig as it behaves (friction dead band, travel limits under full
//! drive, the PWM delay) run on the realistic [`SimulatedRig::default`].

// Built on the two-cart lab (its plant, simulated rig or card).
#![cfg(feature = "lab")]

use ctrlab::hw::testing::RecordingPort;
use ctrlab::hw::{
    Clock, CycleKind, EppPort, LoopFault, Pc104, PortError, PortErrorKind, Rig, RigError,
    SIMULATED_CARD_ID, SimulatedCard, VirtualClock,
};
use ctrlab::lab::{
    Calibration, CardSettings, Friction, FrictionPlant, MassSpringRig, SimulatedRig, Unmodelled,
};
use ctrlab::{Cart, Discretization, MassSpring};
use nalgebra::{SVector, vector};

/// 80 mm per 8192 counts.
const MPC: f64 = 0.080 / 8192.0;
const PERIOD_NS: u64 = 2_000_000;
/// EPP cycles of the ID probe when a rig is built: address write, data read.
const PROBE_CYCLES: usize = 2;

/// The lab's simulated card (two carts, friction model inside).
type Card = SimulatedCard<FrictionPlant, 4>;

fn sim(config: SimulatedRig) -> (VirtualClock, Card) {
    let clock = VirtualClock::new();
    let card = config.card(&Clock::Virtual(clock.clone())).unwrap();
    (clock, card)
}

/// The default truth without friction, stiction, PWM delay or noise.
fn ideal() -> SimulatedRig {
    SimulatedRig::ideal(SimulatedRig::default_truth())
}

/// The nominal plant (1 N/V) without friction, stiction, PWM delay or noise.
fn nominal_config() -> SimulatedRig {
    SimulatedRig::ideal(MassSpring::nominal())
}

// ---- the simulated card: card.rs; the rig: rig.rs; bit for bit: bits.rs ----

mod bits;
mod card;
mod rig;
