//! The real rig in real time, and safe when it goes wrong: the fail-safes
//! behind the loop, each through the full stack (`hw::run` →
//! `MassSpringRig` → `Pc104` → the simulated card).
//!
//! - a dead encoder on the driven cart (cart 2), from the start or dying
//!   mid-run, halts the rig before the true cart passes its travel limit,
//!   and a drive held at its limit is halted after
//!   `Calibration::max_saturation_time`;
//! - a card without a watchdog is driven only when acknowledged, and the
//!   loop keeps a gap limit of its own;
//! - SIGINT, SIGTERM, SIGHUP, SIGQUIT and SIGTSTP each stop the run with its
//!   recording;
//! - a panic in `Controller::applied` or `Controller::reset` ends the run
//!   named, with the recording and the PWM at zero;
//! - halting zeroes every PWM channel of the card, not only the motor's.
//!
//! At small drives and at both drive limits: `tests/failsafe_small_drive.rs`.
//!
//! The true plant state comes from the simulated card
//! (`SimulatedCard::true_state`), never from the encoders under test.

// Built on the two-cart lab (its plant, simulated rig or card).
#![cfg(feature = "lab")]

#[path = "../common/mod.rs"]
mod common;

use common::{assert_recorded, loop_config as config};
use std::time::Duration;

use ctrlab::hw::testing::{Cycle, RecordingPort};
use ctrlab::hw::{
    Clock, ConfigErrorKind, GAP_PERIODS, LoopConfig, LoopFault, LoopFaultKind, PWM_CHANNELS, Pc104,
    Rig, RigError, RunError, SimulatedCard, VirtualClock, run,
};
use ctrlab::lab::{
    Calibration, Cart, FrictionPlant, LabGains, MassSpring, MassSpringRig, RigConfig, SimulatedRig,
};
use ctrlab::nalgebra::{SVector, vector};
use ctrlab::{Controller, OpenLoop, Schema};

const PERIOD: f64 = 0.002;

/// The lab's simulated card (two carts with friction inside).
type Card = SimulatedCard<FrictionPlant, 4>;
/// The lab's rig on it.
type SimRig = MassSpringRig<Card>;

/// `sim`'s card on `clock` read by a rig with `calibration` (which may wire
/// the carts differently from the card).
fn rig_with(sim: &SimulatedRig, calibration: Calibration, clock: &Clock) -> SimRig {
    let card = Pc104::with_map(sim.card(clock).unwrap(), sim.card.map).unwrap();
    MassSpringRig::with_clock(card, calibration, sim.period, clock.clone()).unwrap()
}

/// Every PWM channel of the card applies 0, once the PWM delay has passed.
fn assert_every_channel_off(rig: &mut SimRig, clock: &VirtualClock) {
    clock
        .advance(SimulatedRig::default().card.pwm_delay)
        .unwrap();
    let card = rig.card_mut().port_mut();
    card.sync().unwrap();
    for channel in 0..PWM_CHANNELS {
        assert_eq!(card.pwm_duty(channel), 0, "PWM channel {channel}");
    }
}

/// A rig that passes everything to the lab's rig inside and, at every read,
/// notes how far each true cart has gone from its rest position (m).
struct Watched<'a> {
    rig: &'a mut SimRig,
    furthest: [f64; 2],
}

impl Watched<'_> {
    fn note(&mut self) {
        let x = self.rig.card().port().true_state();
        for cart in 0..2 {
            self.furthest[cart] = self.furthest[cart].max(x[2 * cart].abs());
        }
    }
}

impl Rig<1, 4> for Watched<'_> {
    fn read(&mut self) -> Result<SVector<f64, 4>, RigError> {
        let y = self.rig.read();
        self.note();
        y
    }
    fn apply(&mut self, u: &SVector<f64, 1>) -> Result<SVector<f64, 1>, RigError> {
        self.rig.apply(u)
    }
    fn halt(&mut self) -> Result<(), RigError> {
        self.rig.halt()
    }
    fn period(&self) -> f64 {
        Rig::period(&*self.rig)
    }
    fn schema(&self) -> Schema {
        self.rig.schema()
    }
    fn watchdog_timeout(&self) -> Option<f64> {
        self.rig.watchdog_timeout()
    }
    fn restart(&mut self) {
        self.rig.restart();
    }
}

/// Lets the halted carts coast for `seconds` on the card's clock and
/// returns how far each true cart went meanwhile (m), `furthest` included.
fn coast(rig: &mut SimRig, clock: &VirtualClock, seconds: f64, furthest: [f64; 2]) -> [f64; 2] {
    let mut furthest = furthest;
    for _ in 0..(seconds / 1e-3).round() as usize {
        clock.advance(1e-3).unwrap();
        let card = rig.card_mut().port_mut();
        card.sync().unwrap();
        let x = card.true_state();
        for cart in 0..2 {
            furthest[cart] = furthest[cart].max(x[2 * cart].abs());
        }
    }
    furthest
}

// The driven cart's encoder: encoders.rs; the drive's limit and a card
// without a watchdog: limits.rs; signals, panics and halting: stops.rs.

mod encoders;
mod limits;
mod stops;
