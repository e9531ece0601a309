//! The card driver's exact EPP traffic (golden tests), counter unwrapping
//! across ±2³¹, error context, and the ppdev ioctl numbers. The simulated
//! card and the rig are in `hw_sim.rs`.

// Built on the two-cart lab (its plant, simulated rig or card).
#![cfg(feature = "lab")]

use ctrlab::hw::testing::{Cycle, RecordingPort, RegisterFile};
use ctrlab::hw::{CycleKind, Pc104, PortError, RegisterMap, duty_from_bytes, pwm_bytes};
use ctrlab::lab::{Calibration, MassSpringRig};
use nalgebra::vector;
use proptest::prelude::*;

use Cycle::{AddressWrite as A, DataRead as R, DataWrite as W};

// ---- golden EPP traffic -------------------------------------------------

#[test]
fn golden_pwm_write_is_low_byte_then_high_byte() {
    let mut pc104 = Pc104::new(RecordingPort::default());
    pc104.set_pwm(0, -300).unwrap(); // 300 = 0x12c, negative
    pc104.set_pwm(3, 1000).unwrap(); // 1000 = 0x3e8
    pc104.set_pwm(1, 0).unwrap();
    assert_eq!(
        pc104.port().log(),
        &[
            A(0x10),
            W(0x2c),
            A(0x11),
            W(0x81),
            A(0x16),
            W(0xe8),
            A(0x17),
            W(0x03),
            A(0x12),
            W(0x00),
            A(0x13),
            W(0x00),
        ]
    );
}

#[test]
fn golden_latch_kick_clear() {
    let mut pc104 = Pc104::new(RecordingPort::default());
    pc104.latch().unwrap();
    pc104.kick_watchdog().unwrap();
    pc104.latch_and_kick().unwrap();
    pc104.clear_counters().unwrap();
    assert_eq!(
        pc104.port().log(),
        &[
            A(0x01),
            W(0x01),
            A(0x01),
            W(0x04),
            A(0x01),
            W(0x05),
            A(0x01),
            W(0x02)
        ]
    );
}

#[test]
fn golden_counter_read_is_four_addressed_bytes_low_first() {
    let mut pc104 = Pc104::new(RecordingPort::default());
    pc104.port_mut().inner_mut().set_u32_le(0x24, 0x8765_4321);
    assert_eq!(pc104.read_raw_counter(1).unwrap(), 0x8765_4321);
    assert_eq!(
        pc104.port().log(),
        &[
            A(0x24),
            R(0x21),
            A(0x25),
            R(0x43),
            A(0x26),
            R(0x65),
            A(0x27),
            R(0x87)
        ]
    );
}

#[test]
fn golden_rig_iteration() {
    // Building the rig probes the ID register (read only, nothing
    // written); then one loop iteration: latch+kick, cart 1, cart 2, PWM.
    let mut port = RecordingPort::default();
    port.inner_mut().set(0x00, 0xa5); // the card's ID
    port.inner_mut().set_u32_le(0x20, 1024); // cart 1: 10 mm
    port.inner_mut().set_u32_le(0x24, 0xffff_fc00); // cart 2: -1024 counts
    let mut rig = MassSpringRig::new(Pc104::new(&mut port), Calibration::default(), 0.002).unwrap();
    let x = rig.read_state().unwrap();
    rig.apply_voltage(-6.0).unwrap(); // -250 = 0x0fa, negative
    drop(rig); // drop writes PWM 0 on every channel, the motor's (0) first
    assert_eq!(x, vector![0.010, 0.0, -0.010, 0.0]);
    assert_eq!(
        port.log(),
        &[
            A(0x00),
            R(0xa5),
            A(0x01),
            W(0x05),
            A(0x20),
            R(0x00),
            A(0x21),
            R(0x04),
            A(0x22),
            R(0x00),
            A(0x23),
            R(0x00),
            A(0x24),
            R(0x00),
            A(0x25),
            R(0xfc),
            A(0x26),
            R(0xff),
            A(0x27),
            R(0xff),
            A(0x10),
            W(0xfa),
            A(0x11),
            W(0x80),
            A(0x10),
            W(0x00),
            A(0x11),
            W(0x00),
            A(0x12),
            W(0x00),
            A(0x13),
            W(0x00),
            A(0x14),
            W(0x00),
            A(0x15),
            W(0x00),
            A(0x16),
            W(0x00),
            A(0x17),
            W(0x00),
        ]
    );
}

/// Mode switches a ppdev port makes for `log`: one `PPSETMODE` each time
/// the cycle kind changes between address and data, starting in data mode
/// (where `Ppdev::open` leaves it, and where every tick ends).
fn mode_switches(log: &[Cycle]) -> usize {
    let mut address = false;
    let mut switches = 0;
    for cycle in log {
        let is_address = matches!(cycle, Cycle::AddressWrite(_));
        if is_address != address {
            switches += 1;
            address = is_address;
        }
    }
    switches
}

#[test]
fn one_rig_tick_costs_22_cycles_and_22_mode_switches() {
    // One control tick of the lab's rig: read_state (latch and kick, cart 1's
    // and cart 2's 32-bit counters) and apply_voltage (one PWM duty). Without
    // auto-increment every byte is an address cycle then a data cycle, so on
    // ppdev every cycle is a read or write call and every one of them
    // follows a PPSETMODE: 44 system calls a tick. (Batching address cycles
    // apart from data cycles would need an auto-incrementing card.)
    let mut port = RecordingPort::default();
    port.inner_mut().set(0x00, 0xa5);
    let mut rig = MassSpringRig::new(Pc104::new(&mut port), Calibration::default(), 0.002).unwrap();
    rig.card_mut().port_mut().clear_log();
    for _ in 0..3 {
        rig.read_state().unwrap();
        rig.apply_voltage(1.0).unwrap();
    }
    let log = rig.card().port().log().to_vec();
    assert_eq!(log.len(), 3 * 22);
    assert_eq!(mode_switches(&log), 3 * 22);
    let tick = &log[..22];
    let count = |kind: CycleKind| tick.iter().filter(|c| c.kind() == kind).count();
    assert_eq!(
        (
            count(CycleKind::AddressWrite),
            count(CycleKind::DataRead),
            count(CycleKind::DataWrite)
        ),
        (11, 8, 3)
    );
}

#[test]
fn pwm_bytes_round_trip_every_duty() {
    for duty in -1000..=1000i16 {
        let (low, high) = pwm_bytes(duty);
        assert_eq!(duty_from_bytes(low, high), duty, "duty {duty}");
        assert_eq!(high & 0x7c, 0, "unused bits stay clear for {duty}");
    }
}

#[test]
fn a_custom_register_map_moves_the_traffic() {
    let map = RegisterMap {
        control: 0x03,
        pwm_low: [0x40, 0x42, 0x44, 0x46],
        pwm_high: [0x41, 0x43, 0x45, 0x47],
        ..RegisterMap::default()
    };
    let mut pc104 = Pc104::with_map(RecordingPort::default(), map).unwrap();
    pc104.latch().unwrap();
    pc104.set_pwm(2, 1).unwrap();
    assert_eq!(
        pc104.port().log(),
        &[A(0x03), W(0x01), A(0x44), W(0x01), A(0x45), W(0x00)]
    );
}

#[test]
fn register_maps_with_clashes_are_refused() {
    let default = RegisterMap::default();
    for (bad, name) in [
        (
            RegisterMap {
                id: 0x01,
                ..default
            },
            "control",
        ),
        (
            RegisterMap {
                encoder: [0x20, 0x22, 0x28, 0x2c],
                ..default
            },
            "encoder[1]",
        ),
        (
            RegisterMap {
                encoder: [0x20, 0x24, 0x28, 0xfd],
                ..default
            },
            "encoder[3]",
        ),
        (
            RegisterMap {
                clear_bit: 0x01,
                ..default
            },
            "clear_bit",
        ),
        (
            RegisterMap {
                watchdog_bit: 0,
                ..default
            },
            "watchdog_bit",
        ),
    ] {
        match Pc104::with_map(RegisterFile::new(), bad) {
            Err(e) => assert_eq!(e.key(), name),
            Ok(_) => panic!("expected {name} refused"),
        }
    }
}

#[test]
fn out_of_range_commands_write_nothing() {
    let mut pc104 = Pc104::new(RecordingPort::default());
    for (result, what) in [
        (pc104.set_pwm(4, 0), "PWM channel"),
        (pc104.set_pwm(0, -1001), "PWM duty"),
        (pc104.read_counter(4).map(|_| ()), "encoder channel"),
    ] {
        match result {
            Err(PortError::InvalidCommand { what: got, .. }) => assert_eq!(got, what),
            other => panic!("expected InvalidCommand for {what}, got {other:?}"),
        }
    }
    assert_eq!(pc104.port().attempts(), 0);
}

#[test]
fn a_failed_cycle_names_the_register() {
    // Cycles 0–1 latch, 2–9 read counter 0; cycle 7 is the data read of 0x22.
    let mut pc104 = Pc104::new(RecordingPort::default().fail_at(7));
    pc104.latch().unwrap();
    let err = pc104.read_counter(0).unwrap_err();
    assert!(matches!(
        err,
        PortError::Timeout {
            cycle: CycleKind::DataRead,
            register: Some(0x22)
        }
    ));
    // The failed read left the position alone; the next read works.
    pc104.port_mut().inner_mut().set_u32_le(0x20, 7);
    assert_eq!(pc104.read_counter(0).unwrap(), 7);
}

// ---- counter unwrapping ---------------------------------------------------

/// Drives the fake card's raw counter through `positions` (true positions in
/// counts, any i64) and checks the driver reports each one.
fn check_unwrap(start: i64, deltas: &[i64]) {
    let mut pc104 = Pc104::new(RegisterFile::new());
    let mut truth = start;
    pc104.port_mut().set_u32_le(0x28, truth as u32);
    // The first read takes the raw count as a signed 32-bit number.
    let first = pc104.read_counter(2).unwrap();
    assert_eq!(first, i64::from(truth as u32 as i32));
    let offset = truth - first;
    for &d in deltas {
        truth += d;
        pc104.port_mut().set_u32_le(0x28, truth as u32); // the card's counter wraps
        assert_eq!(pc104.read_counter(2).unwrap() + offset, truth);
    }
}

#[test]
fn counter_unwraps_across_plus_and_minus_two_to_the_31() {
    let two31 = 1i64 << 31;
    // Up across +2³¹ (raw 0x7fff_ffff → 0x8000_0000), on beyond 2³².
    check_unwrap(
        two31 - 3,
        &[1, 1, 1, 1, 1_000_000, (1 << 31) - 1, (1 << 31) - 1],
    );
    // Down across −2³¹ (raw 0x8000_0000 → 0x7fff_ffff).
    check_unwrap(-two31 + 2, &[-1, -1, -1, -1, -1_000_000, -((1 << 31) - 1)]);
    // Across zero both ways.
    check_unwrap(1, &[-2, 2, -5, 5]);
}

proptest! {
    #[test]
    fn unwrapped_counter_equals_the_sum_of_the_moves(
        start in any::<i32>(),
        deltas in proptest::collection::vec(-(1i64 << 31) + 1..(1i64 << 31), 1..40),
    ) {
        check_unwrap(i64::from(start), &deltas);
    }
}

// ---- ppdev -------------------------------------------------------------------

#[cfg(all(feature = "ppdev", target_os = "linux"))]
mod ppdev {
    use ctrlab::hw::{PortErrorKind, Ppdev, ioctl};

    #[cfg(target_arch = "x86_64")]
    #[test]
    fn ioctl_numbers_match_linux_ppdev_h_on_x86_64() {
        // <linux/ppdev.h> on x86-64, where _IOC(dir, 'p', nr, size) is
        // dir<<30 | size<<16 | 0x70<<8 | nr (the issue quotes PPSETMODE).
        assert_eq!(ioctl::PPSETMODE, 0x4004_7080);
        assert_eq!(ioctl::PPCLAIM, 0x0000_708b);
        assert_eq!(ioctl::PPRELEASE, 0x0000_708c);
        assert_eq!(ioctl::PPEXCL, 0x0000_708f);
        assert_eq!(ioctl::PPGETMODES, 0x8004_7097);
        assert_eq!(ioctl::PPWCONTROL, 0x4001_7084);
    }

    #[test]
    fn ioctl_numbers_match_the_libc_crate() {
        // An independent encoder of _IOC for the target architecture.
        let p = u32::from(b'p');
        assert_eq!(
            ioctl::PPSETMODE as libc::Ioctl,
            libc::_IOW::<libc::c_int>(p, 0x80)
        );
        assert_eq!(
            ioctl::PPGETMODES as libc::Ioctl,
            libc::_IOR::<libc::c_uint>(p, 0x97)
        );
        assert_eq!(ioctl::PPCLAIM as libc::Ioctl, libc::_IO(p, 0x8b));
        assert_eq!(ioctl::PPRELEASE as libc::Ioctl, libc::_IO(p, 0x8c));
        assert_eq!(ioctl::PPEXCL as libc::Ioctl, libc::_IO(p, 0x8f));
        assert_eq!(
            ioctl::PPWCONTROL as libc::Ioctl,
            libc::_IOW::<libc::c_uchar>(p, 0x84)
        );
    }

    #[test]
    fn mode_bits_match_linux_parport_h() {
        assert_eq!(ioctl::IEEE1284_MODE_EPP, 0x40);
        assert_eq!(ioctl::IEEE1284_ADDR, 0x2000);
        assert_eq!(ioctl::PARPORT_MODE_EPP, 0x04);
        assert_eq!(
            [
                ioctl::PARPORT_MODE_PCSPP,
                ioctl::PARPORT_MODE_TRISTATE,
                ioctl::PARPORT_MODE_EPP,
                ioctl::PARPORT_MODE_ECP,
                ioctl::PARPORT_MODE_COMPAT,
                ioctl::PARPORT_MODE_DMA,
                ioctl::PARPORT_MODE_SAFEININT,
            ],
            [0x01, 0x02, 0x04, 0x08, 0x10, 0x20, 0x40]
        );
        // PARPORT_CONTROL_INIT; EPP wants nothing else set (LinuxCNC's
        // hm2_7i43 writes the same 0x04 after claiming).
        assert_eq!(ioctl::PARPORT_CONTROL_INIT, 0x04);
        assert_eq!(ioctl::EPP_CONTROL, 0x04);
    }

    #[test]
    fn modes_of_a_missing_port_is_not_present() {
        let err = Ppdev::modes_of("/dev/nonexistent").unwrap_err();
        assert_eq!(err.kind(), PortErrorKind::NotPresent);
        assert!(err.to_string().contains("modprobe"), "{err}");
    }

    #[test]
    fn a_missing_port_is_not_present() {
        let err = Ppdev::open("/dev/nonexistent").unwrap_err();
        assert_eq!(err.kind(), PortErrorKind::NotPresent);
        assert!(err.to_string().contains("/dev/nonexistent"), "{err}");
    }

    #[test]
    fn a_device_that_is_no_parallel_port_is_an_io_error() {
        let err = Ppdev::open("/dev/null").unwrap_err();
        assert_eq!(err.kind(), PortErrorKind::Io);
        assert!(err.to_string().contains("PPEXCL"), "{err}");
    }
}
