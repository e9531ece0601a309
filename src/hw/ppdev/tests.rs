//! The ppdev driver's ioctl sequences, recorded on a fake device.

use std::cell::RefCell;
use std::rc::Rc;

use super::*;
use crate::hw::PortErrorKind;

/// One step on the device, as recorded.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Op {
    Ioctl(Request),
    Read,
    Write(u8),
}

use Op::{Ioctl, Read as R, Write as W};
use Request::{Claim, DataDir, Excl, GetModes, Release, SetMode, WriteControl};

const EPP: c_int = ioctl::IEEE1284_MODE_EPP;
const ADDR: c_int = ioctl::IEEE1284_MODE_EPP | ioctl::IEEE1284_ADDR;
const COMPAT: c_int = ioctl::IEEE1284_MODE_COMPAT;

/// A device that records every step, shares its log with the test,
/// reports `modes` and reads `0xa5`; `fail` fails that ioctl, `short`
/// makes reads return no byte (an EPP timeout).
#[derive(Debug, Default)]
struct Recorder {
    log: Rc<RefCell<Vec<Op>>>,
    modes: c_uint,
    fail: Option<Request>,
    short: bool,
}

impl Device for Recorder {
    fn ioctl(&mut self, request: Request) -> io::Result<c_uint> {
        self.log.borrow_mut().push(Ioctl(request));
        if self.fail == Some(request) {
            return Err(io::Error::from_raw_os_error(libc::EIO));
        }
        Ok(if request == GetModes { self.modes } else { 0 })
    }
    fn read_byte(&mut self, byte: &mut [u8; 1]) -> io::Result<usize> {
        self.log.borrow_mut().push(R);
        byte[0] = 0xa5;
        Ok(if self.short { 0 } else { 1 })
    }
    fn write_byte(&mut self, byte: u8) -> io::Result<usize> {
        self.log.borrow_mut().push(W(byte));
        Ok(1)
    }
}

/// A port opened on a recorder with hardware EPP, and its log.
fn opened(options: PpdevOptions) -> (Port<Recorder>, Rc<RefCell<Vec<Op>>>) {
    let dev = Recorder {
        modes: 0x1f,
        ..Recorder::default()
    };
    let log = Rc::clone(&dev.log);
    let port = Port::open(dev, "/dev/parport0".into(), options).unwrap();
    (port, log)
}

fn taken(log: &Rc<RefCell<Vec<Op>>>) -> Vec<Op> {
    std::mem::take(&mut *log.borrow_mut())
}

#[test]
fn open_claims_checks_epp_then_selects_data_cycles_and_the_control_bits() {
    let (_port, log) = opened(PpdevOptions::default());
    assert_eq!(
        taken(&log),
        [
            Ioctl(Excl),
            Ioctl(Claim),
            Ioctl(GetModes),
            Ioctl(SetMode(EPP)),
            Ioctl(WriteControl(0x04)),
        ]
    );
}

#[test]
fn by_default_a_register_read_is_two_mode_switches_and_two_cycles() {
    let (mut port, log) = opened(PpdevOptions::default());
    taken(&log);
    port.write_address(0x20).unwrap();
    assert_eq!(port.read_data().unwrap(), 0xa5);
    port.write_address(0x10).unwrap();
    port.write_data(0x07).unwrap();
    assert_eq!(
        taken(&log),
        [
            Ioctl(SetMode(ADDR)),
            W(0x20),
            Ioctl(SetMode(EPP)),
            R,
            Ioctl(SetMode(ADDR)),
            W(0x10),
            Ioctl(SetMode(EPP)),
            W(0x07),
        ]
    );
}

#[test]
fn with_data_dir_every_read_is_bracketed_by_ppdatadir_and_writes_are_not() {
    let (mut port, log) = opened(PpdevOptions { data_dir: true });
    taken(&log);
    port.write_address(0x20).unwrap();
    assert_eq!(port.read_data().unwrap(), 0xa5);
    assert_eq!(port.read_data().unwrap(), 0xa5);
    port.write_data(0x01).unwrap();
    assert_eq!(
        taken(&log),
        [
            Ioctl(SetMode(ADDR)),
            W(0x20),
            Ioctl(SetMode(EPP)),
            Ioctl(DataDir(true)),
            R,
            Ioctl(DataDir(false)),
            Ioctl(DataDir(true)),
            R,
            Ioctl(DataDir(false)),
            W(0x01),
        ]
    );
}

#[test]
fn a_read_that_times_out_still_turns_the_data_lines_forward() {
    let (mut port, log) = opened(PpdevOptions { data_dir: true });
    port.dev.short = true;
    taken(&log);
    let err = port.read_data().unwrap_err();
    assert_eq!(err.kind(), PortErrorKind::Timeout);
    assert_eq!(
        taken(&log),
        [Ioctl(DataDir(true)), R, Ioctl(DataDir(false))]
    );
}

#[test]
fn dropping_sets_compatibility_mode_then_releases_without_negotiating() {
    for options in [PpdevOptions::default(), PpdevOptions { data_dir: true }] {
        let (mut port, log) = opened(options);
        port.write_address(0x00).unwrap();
        port.read_data().unwrap();
        taken(&log);
        drop(port);
        // PPSETMODE records the mode and drives no line; the kernel's
        // own close then has nothing to negotiate (no nInit pulse).
        assert_eq!(taken(&log), [Ioctl(SetMode(COMPAT)), Ioctl(Release)]);
    }
}

#[test]
fn an_explicit_close_does_the_same_once_and_reports_a_failed_step() {
    let (mut port, log) = opened(PpdevOptions::default());
    port.write_address(0x00).unwrap(); // left in address mode
    taken(&log);
    port.close().unwrap();
    drop(port);
    assert_eq!(taken(&log), [Ioctl(SetMode(COMPAT)), Ioctl(Release)]);

    let (mut port, log) = opened(PpdevOptions::default());
    port.dev.fail = Some(SetMode(COMPAT));
    taken(&log);
    let err = port.close().unwrap_err();
    assert!(err.to_string().contains("PPSETMODE"), "{err}");
    // The release is tried all the same.
    assert_eq!(taken(&log), [Ioctl(SetMode(COMPAT)), Ioctl(Release)]);
}

#[test]
fn a_port_without_epp_is_refused_and_released_in_compatibility_mode() {
    let dev = Recorder {
        modes: 0x1b, // PCSPP,TRISTATE,ECP,COMPAT: no EPP
        ..Recorder::default()
    };
    let log = Rc::clone(&dev.log);
    let err = Port::open(dev, "/dev/parport0".into(), PpdevOptions::default()).unwrap_err();
    assert_eq!(err.kind(), PortErrorKind::NotPresent);
    assert_eq!(
        taken(&log),
        [
            Ioctl(Excl),
            Ioctl(Claim),
            Ioctl(GetModes),
            Ioctl(SetMode(COMPAT)),
            Ioctl(Release),
        ]
    );
}

#[test]
fn a_failed_claim_has_nothing_to_release() {
    let dev = Recorder {
        fail: Some(Claim),
        ..Recorder::default()
    };
    let log = Rc::clone(&dev.log);
    assert!(Port::open(dev, "/dev/parport0".into(), PpdevOptions::default()).is_err());
    assert_eq!(taken(&log), [Ioctl(Excl), Ioctl(Claim)]);
}
