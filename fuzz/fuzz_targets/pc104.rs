//! The PC104 driver on a port that answers every read with the next fuzz
//! byte (and fails some cycles): every call returns, and nothing panics.
#![no_main]

use ctrlab::hw::{CycleKind, EppPort, PortError, Pc104};
use libfuzzer_sys::fuzz_target;

/// A port whose reads return the fuzz input byte by byte; a byte whose top
/// two bits are set makes that cycle time out instead. Past the end every
/// read returns 0.
struct FuzzPort<'a> {
    data: &'a [u8],
    at: usize,
    address: u8,
}

impl FuzzPort<'_> {
    fn next(&mut self) -> u8 {
        let b = self.data.get(self.at).copied().unwrap_or(0);
        self.at += 1;
        b
    }
}

impl EppPort for FuzzPort<'_> {
    fn write_address(&mut self, address: u8) -> Result<(), PortError> {
        self.address = address;
        Ok(())
    }
    fn read_data(&mut self) -> Result<u8, PortError> {
        let b = self.next();
        if b & 0xc0 == 0xc0 && self.next() & 1 == 1 {
            return Err(PortError::Timeout {
                cycle: CycleKind::DataRead,
                register: Some(self.address),
            });
        }
        Ok(b)
    }
    fn write_data(&mut self, _value: u8) -> Result<(), PortError> {
        if self.next() == 0xff {
            return Err(PortError::Timeout {
                cycle: CycleKind::DataWrite,
                register: Some(self.address),
            });
        }
        Ok(())
    }
}

fuzz_target!(|data: &[u8]| {
    let mut card = Pc104::new(FuzzPort {
        data,
        at: 0,
        address: 0,
    });
    let _ = card.read_id();
    let _ = card.probe_id(0x5a);
    for round in 0..4u8 {
        let _ = card.latch_and_kick();
        for channel in 0..6 {
            let _ = card.read_raw_counter(channel);
            let _ = card.read_counter(channel);
            let _ = card.set_pwm(channel, i16::from(round) * 1000 - 2000);
        }
        let _ = card.clear_counters();
    }
});
