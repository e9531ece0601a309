//! The bring-up probe (`hw::probe`) against the simulated card, a port
//! with no card, and an operator who says no: by default it confirms the
//! map it is given without a cycle outside it; the blind scan runs only
//! when asked for, writing each unknown address at most twice in its latch
//! search; a stop during a pulse leaves no duty on.

// Built on the two-cart lab (its plant, simulated rig or card).
#![cfg(feature = "lab")]

use std::collections::{BTreeMap, BTreeSet};

use ctrlab::hw::probe::{Hands, Operator, Probe, ProbeError, ProbeOptions};
use ctrlab::hw::testing::{Cycle, RecordingPort, RegisterFile};
use ctrlab::hw::{Clock, CycleKind, EppPort, RegisterMap, SimulatedCard, StopSignal, VirtualClock};
use ctrlab::lab::{
    Calibration, CardSettings, FrictionPlant, RigConfig, SimulatedOperator, SimulatedRig,
};

type Card = SimulatedCard<FrictionPlant, 4>;

/// The blind scan, as the `probe` example's `--scan` asks for it.
fn blind() -> ProbeOptions {
    ProbeOptions {
        scan: true,
        ..ProbeOptions::default()
    }
}

/// The default probe, given the simulated card's map and ID as a card file
/// would give them.
fn given(rig: &SimulatedRig) -> ProbeOptions {
    ProbeOptions {
        map: rig.card.map,
        card_id: Some(rig.calibration.card_id),
        ..ProbeOptions::default()
    }
}

fn probe_with(
    rig: &SimulatedRig,
    answers: &[bool],
    options: ProbeOptions,
) -> Probe<RecordingPort<Card>, SimulatedOperator> {
    let clock = VirtualClock::new();
    let card = rig.card(&Clock::Virtual(clock.clone())).unwrap();
    let operator = SimulatedOperator::new(clock, answers.iter().copied());
    Probe::new(RecordingPort::new(card), operator, options).unwrap()
}

fn probe_of(rig: &SimulatedRig, answers: &[bool]) -> Probe<RecordingPort<Card>, SimulatedOperator> {
    probe_with(rig, answers, blind())
}

/// Every address a map names: the ID, the control register, the PWM
/// bytes and all four bytes of each counter.
fn addresses_of(map: &RegisterMap) -> BTreeSet<u8> {
    let mut all = BTreeSet::from([map.id, map.control]);
    all.extend(map.pwm_low.iter().chain(&map.pwm_high));
    all.extend(map.encoder.iter().flat_map(|&a| a..=a + 3));
    all
}

/// The data writes of `log`, as (address, value), each with the address
/// of the address cycle before it.
fn writes(log: &[Cycle]) -> Vec<(u8, u8)> {
    let mut address = None;
    let mut out = Vec::new();
    for cycle in log {
        match *cycle {
            Cycle::AddressWrite(a) => address = Some(a),
            Cycle::DataWrite(v) => out.push((address.unwrap(), v)),
            Cycle::DataRead(_) => {}
        }
    }
    out
}

/// A map unlike the default, the card ID and channels moved too.
fn other_rig() -> SimulatedRig {
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
    SimulatedRig {
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
    }
}

#[test]
fn by_default_the_probe_confirms_the_given_map_with_no_cycle_outside_it() {
    for rig in [SimulatedRig::default(), other_rig()] {
        let mut probe = probe_with(&rig, &[true, true], given(&rig));
        let report = probe.run().unwrap();
        assert_eq!(report.map, rig.card.map);
        let calibration = Calibration::from_probe(&report, &Calibration::default());
        assert_eq!(
            (
                calibration.card_id,
                calibration.encoder_channels,
                calibration.watchdog_timeout
            ),
            (
                rig.calibration.card_id,
                rig.calibration.encoder_channels,
                rig.calibration.watchdog_timeout
            )
        );
        assert_eq!(calibration.sign, rig.calibration.sign);
        assert_eq!(report.pwm_channel, rig.calibration.pwm_channel);
        let log = probe.port().log();
        let map = rig.card.map;
        let named = addresses_of(&map);
        // Not a cycle, read or write, at an address the map does not name.
        for cycle in log {
            if let Cycle::AddressWrite(a) = cycle {
                assert!(named.contains(a), "address {a:#04x} is outside the map");
            }
        }
        // Writes go to the control register and the PWM bytes only, and
        // the control register gets only the map's bits.
        let writable: BTreeSet<u8> = std::iter::once(map.control)
            .chain(map.pwm_low)
            .chain(map.pwm_high)
            .collect();
        let bits = map.latch_bit | map.clear_bit | map.watchdog_bit;
        for (address, value) in writes(log) {
            assert!(writable.contains(&address), "write to {address:#04x}");
            if address == map.control {
                assert_eq!(value & !bits, 0, "control bits {value:#04x}");
            }
        }
        // The steps said what they would do before asking or doing it.
        let said = &probe.operator().transcript;
        let at = |needle: &str| said.iter().position(|m| m.contains(needle)).unwrap();
        assert!(at("step 1/4, ID") < at("step 2/4"));
        assert!(at("step 2/4") < at("motor supply switched OFF"));
        assert!(at("step 3/4") < at("pulse the motor?"));
        assert_eq!(probe.port().inner().pwm_duty(report.pwm_channel), 0);
    }
}

#[test]
fn a_map_the_card_does_not_answer_to_stops_the_probe_before_any_write() {
    let rig = SimulatedRig::default();
    // The card file says another card's ID.
    let options = ProbeOptions {
        card_id: Some(0x3c),
        ..given(&rig)
    };
    let mut probe = probe_with(&rig, &[true, true], options);
    let err = probe.run().unwrap_err();
    assert!(matches!(err, ProbeError::WrongMap { .. }), "{err}");
    assert!(err.to_string().contains("card file says 0x3c"), "{err}");
    // The ID is elsewhere than the map says: that address reads open bus.
    let options = ProbeOptions {
        map: other_rig().card.map,
        card_id: None,
        ..given(&rig)
    };
    let mut probe = probe_with(&rig, &[true, true], options);
    let err = probe.run().unwrap_err();
    assert!(matches!(err, ProbeError::WrongMap { .. }), "{err}");
    assert!(err.to_string().contains("nothing was written"), "{err}");
    assert!(writes(probe.port().log()).is_empty());
}

#[test]
fn the_blind_scan_runs_only_when_asked_for() {
    let rig = SimulatedRig::default();
    let mut probe = probe_with(&rig, &[true, true], given(&rig));
    let err = probe.scan().unwrap_err();
    assert!(matches!(err, ProbeError::ScanNotEnabled), "{err}");
    assert!(err.to_string().contains("configuration registers"), "{err}");
    assert!(matches!(
        probe.find_encoders(),
        Err(ProbeError::OutOfOrder { .. })
    ));
    assert!(probe.port().log().is_empty(), "{:?}", probe.port().log());
}

#[test]
fn the_blind_latch_search_writes_each_unknown_address_ten_times_at_most() {
    for rig in [SimulatedRig::default(), other_rig()] {
        let mut probe = probe_of(&rig, &[true, true]);
        probe.scan().unwrap();
        probe.port_mut().clear_log();
        probe.find_encoders().unwrap();
        let control = rig.card.map.control;
        let mut per_address: BTreeMap<u8, Vec<u8>> = BTreeMap::new();
        for (address, value) in writes(probe.port().log()) {
            per_address.entry(address).or_default().push(value);
        }
        assert!(per_address.contains_key(&control));
        let patterns = [0x0f, 0x00, 0x71, 0x00, 0x92, 0x00, 0xa4, 0x00, 0x48, 0x00];
        for (address, values) in per_address.iter().filter(|(a, _)| **a != control) {
            assert_eq!(values, &patterns, "{address:#04x}");
        }
        // Only addresses below the control register were tried before it.
        assert!(per_address.keys().all(|&a| a <= control));
    }
}

/// The simulated hand, and Ctrl-C pressed while a PWM duty is on.
struct Impatient {
    hand: SimulatedOperator,
    stop: StopSignal,
}

impl Operator<RecordingPort<Card>> for Impatient {
    fn tell(&mut self, message: &str) {
        self.hand.tell(message);
    }
    fn confirm(&mut self, question: &str) -> bool {
        self.hand.confirm(question)
    }
    fn hands(&mut self, hands: Hands) {
        self.hand.hands(hands);
    }
    fn wait(&mut self, port: &mut RecordingPort<Card>, seconds: f64) {
        self.hand.wait(port.inner_mut(), seconds);
        if (0..4).any(|channel| port.inner().pwm_duty(channel) != 0) {
            self.stop.request();
        }
    }
}

#[test]
fn a_stop_during_a_pulse_zeroes_the_pwm() {
    for options in [given(&SimulatedRig::default()), blind()] {
        let rig = SimulatedRig::default();
        let clock = VirtualClock::new();
        let card = rig.card(&Clock::Virtual(clock.clone())).unwrap();
        let stop = StopSignal::new();
        let hand = Impatient {
            hand: SimulatedOperator::new(clock.clone(), [true, true]),
            stop: stop.clone(),
        };
        let mut probe = Probe::new(RecordingPort::new(card), hand, options)
            .unwrap()
            .with_stop(stop.clone());
        let err = probe.run().unwrap_err();
        assert!(matches!(err, ProbeError::Interrupted), "{err}");
        assert!(stop.is_requested());
        // Once the card's PWM delay has passed, no duty is on.
        clock.advance(0.05).unwrap();
        let card = probe.port_mut().inner_mut();
        card.read_register(rig.card.map.id).unwrap();
        assert!((0..4).all(|channel| card.pwm_duty(channel) == 0));
        // The last writes: zero to the low byte, then to the high byte.
        let map = rig.card.map;
        let last = writes(probe.port().log());
        assert_eq!(
            last[last.len() - 2..],
            [(map.pwm_low[0], 0x00), (map.pwm_high[0], 0x00)]
        );
    }
}

#[test]
fn the_blind_scan_rediscovers_the_simulated_cards_map_and_calibration() {
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
    assert!(at("writing 5 patterns") < at("latch: bit"));
}

#[test]
fn the_blind_scan_finds_a_map_other_than_the_default() {
    let rig = other_rig();
    let map = rig.card.map;
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
        let mut probe = Probe::new(RecordingPort::new(bus.clone()), Nobody, blind()).unwrap();
        let err = probe.run().unwrap_err();
        assert!(matches!(err, ProbeError::NoCard { .. }), "{err}");
        assert!(err.to_string().contains("nothing was written"), "{err}");
        let log = probe.port().log();
        assert_eq!(log.len(), 2 * 2 * 256);
        assert!(log.iter().all(|c| c.kind() != CycleKind::DataWrite));
        // The default probe reads the map's ID register twice, and stops.
        let mut probe =
            Probe::new(RecordingPort::new(bus), Nobody, ProbeOptions::default()).unwrap();
        let err = probe.run().unwrap_err();
        assert!(matches!(err, ProbeError::WrongMap { .. }), "{err}");
        assert!(err.to_string().contains("nothing was written"), "{err}");
        let log = probe.port().log();
        assert_eq!(
            log,
            [Cycle::AddressWrite(0x00), Cycle::DataRead(idle)].repeat(2)
        );
    }
}

#[test]
fn epp_timeouts_mean_no_card() {
    for options in [blind(), ProbeOptions::default()] {
        let port = RecordingPort::new(RegisterFile::new()).fail_from(0);
        let mut probe = Probe::new(port, Nobody, options).unwrap();
        let err = probe.run().unwrap_err();
        assert!(matches!(err, ProbeError::NoCard { .. }), "{err}");
        assert!(
            probe
                .port()
                .log()
                .iter()
                .all(|c| c.kind() != CycleKind::DataWrite)
        );
    }
}
