//! The bring-up probe (`hw::probe`) against the simulated card, a port
//! with no card, and an operator who says no.

// Built on the two-cart lab (its plant, simulated rig or card).
#![cfg(feature = "lab")]

use ctrlab::hw::probe::{Hands, Operator, Probe, ProbeError, ProbeOptions};
use ctrlab::hw::testing::{RecordingPort, RegisterFile};
use ctrlab::hw::{Clock, CycleKind, RegisterMap, SimulatedCard, VirtualClock};
use ctrlab::lab::{
    Calibration, CardSettings, FrictionPlant, RigConfig, SimulatedOperator, SimulatedRig,
};

type Card = SimulatedCard<FrictionPlant, 4>;

fn probe_of(rig: &SimulatedRig, answers: &[bool]) -> Probe<RecordingPort<Card>, SimulatedOperator> {
    let clock = VirtualClock::new();
    let card = rig.card(&Clock::Virtual(clock.clone())).unwrap();
    let operator = SimulatedOperator::new(clock, answers.iter().copied());
    Probe::new(RecordingPort::new(card), operator, ProbeOptions::default()).unwrap()
}

#[test]
fn the_probe_rediscovers_the_simulated_cards_map_and_calibration() {
    let rig = SimulatedRig::default();
    let mut probe = probe_of(&rig, &[true, true]);
    let report = probe.run().unwrap();
    assert_eq!(report.map, RegisterMap::default());
    assert_eq!(report.map, rig.card.map);
    assert_eq!(report.card_id, rig.calibration.card_id);
    assert_eq!(report.watchdog_timeout, Some(0.100));
    let calibration = Calibration::from_probe(&report, &Calibration::default());
    assert_eq!(calibration, rig.calibration);
    // The card file it writes is the one the rest of the crate loads.
    let file = RigConfig::new(report.map, calibration).to_toml();
    let loaded = RigConfig::from_toml(&file).unwrap();
    assert_eq!(
        (loaded.map, loaded.calibration),
        (rig.card.map, rig.calibration)
    );
    // Each step said what it would do before asking or doing it.
    let said = &probe.operator().transcript;
    let at = |needle: &str| said.iter().position(|m| m.contains(needle)).unwrap();
    assert!(at("step 2/4") < at("motor supply switched OFF"));
    assert!(at("step 3/4") < at("pulse the motor?"));
    assert!(at("writing 0x01, 0x02") < at("latch: bit"));
}

#[test]
fn the_probe_finds_a_map_other_than_the_default() {
    let map = RegisterMap {
        id: 0x33,
        control: 0x08,
        latch_bit: 0x10,
        clear_bit: 0x01,
        watchdog_bit: 0x40,
        pwm_low: [0x60, 0x62, 0x64, 0x66],
        pwm_high: [0x61, 0x63, 0x65, 0x67],
        encoder: [0x40, 0x48, 0x50, 0x58],
    };
    let rig = SimulatedRig {
        card: CardSettings {
            map,
            ..CardSettings::default()
        },
        calibration: Calibration {
            card_id: 0x5a,
            // Cart 1 on the second counter, cart 2 on the first.
            encoder_channels: [1, 0],
            watchdog_timeout: Some(0.05),
            ..Calibration::default()
        },
        ..SimulatedRig::default()
    };
    let report = probe_of(&rig, &[true, true]).run().unwrap();
    assert_eq!(report.map, map);
    assert_eq!(report.card_id, 0x5a);
    assert_eq!(report.encoder_channels, [1, 0]);
    assert_eq!(report.signs, [1.0, 1.0]);
    assert_eq!(report.watchdog_timeout, Some(0.05));
}

#[test]
fn without_the_confirmation_no_pwm_register_is_written() {
    let rig = SimulatedRig::default();
    let mut probe = probe_of(&rig, &[true, false]);
    probe.scan().unwrap();
    probe.find_encoders().unwrap();
    probe.port_mut().clear_log();
    let err = probe.find_drive().unwrap_err();
    assert!(matches!(err, ProbeError::Declined { .. }), "{err}");
    assert!(probe.port().log().is_empty(), "{:?}", probe.port().log());
    assert_eq!(probe.port().inner().pwm_duty(0), 0);
    // The next steps refuse to run without it.
    assert!(matches!(
        probe.find_watchdog(),
        Err(ProbeError::OutOfOrder { .. })
    ));
}

#[test]
fn the_encoder_step_writes_nothing_unless_the_motor_supply_is_off() {
    let mut probe = probe_of(&SimulatedRig::default(), &[false]);
    probe.scan().unwrap();
    probe.port_mut().clear_log();
    let err = probe.find_encoders().unwrap_err();
    assert!(matches!(err, ProbeError::Declined { .. }), "{err}");
    assert!(probe.port().log().is_empty());
}

/// An operator at a port with no card: answers yes, never moves anything.
struct Nobody;

impl<P> Operator<P> for Nobody {
    fn tell(&mut self, _message: &str) {}
    fn confirm(&mut self, _question: &str) -> bool {
        true
    }
    fn hands(&mut self, _hands: Hands) {}
    fn wait(&mut self, _port: &mut P, _seconds: f64) {}
}

#[test]
fn no_card_is_reported_without_writing_a_register() {
    for idle in [0x00, 0xff] {
        let mut bus = RegisterFile::new();
        for a in 0..=u8::MAX {
            bus.set(a, idle);
        }
        let mut probe =
            Probe::new(RecordingPort::new(bus), Nobody, ProbeOptions::default()).unwrap();
        let err = probe.run().unwrap_err();
        assert!(matches!(err, ProbeError::NoCard { .. }), "{err}");
        assert!(err.to_string().contains("nothing was written"), "{err}");
        let log = probe.port().log();
        assert_eq!(log.len(), 2 * 2 * 256);
        assert!(log.iter().all(|c| c.kind() != CycleKind::DataWrite));
    }
}

#[test]
fn epp_timeouts_mean_no_card() {
    let port = RecordingPort::new(RegisterFile::new()).fail_from(0);
    let mut probe = Probe::new(port, Nobody, ProbeOptions::default()).unwrap();
    let err = probe.scan().unwrap_err();
    assert!(matches!(err, ProbeError::NoCard { .. }), "{err}");
    assert!(
        probe
            .port()
            .log()
            .iter()
            .all(|c| c.kind() != CycleKind::DataWrite)
    );
}
