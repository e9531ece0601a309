//! Fakes for testing code built on [`EppPort`]: a memory-backed card
//! ([`RegisterFile`]) and a port wrapper that records every EPP cycle and can
//! inject a failure at a chosen cycle ([`RecordingPort`]).
//!
//! They are public so integration tests and users can pin the exact bus
//! traffic of their own drivers and check fail-safe behaviour.
//!
//! # Examples
//!
//! ```
//! use ctrlab::hw::{EppPort, PortErrorKind, testing::{Cycle, RecordingPort}};
//!
//! // Every cycle from the third on times out.
//! let mut port = RecordingPort::default().fail_from(2);
//! port.write_register(0x10, 7)?;
//! let err = port.read_register(0x10).unwrap_err();
//! assert_eq!(err.kind(), PortErrorKind::Timeout);
//! assert_eq!(port.log(), &[Cycle::AddressWrite(0x10), Cycle::DataWrite(7)]);
//! # Ok::<(), ctrlab::hw::PortError>(())
//! ```

use super::{CycleKind, EppPort, PortError};

/// A fake card: 256 bytes of memory behind an EPP port. A data write stores
/// the byte at the selected address, a data read returns it.
///
/// # Examples
///
/// ```
/// use ctrlab::hw::{EppPort, testing::RegisterFile};
/// let mut card = RegisterFile::new();
/// card.set_u32_le(0x20, 0x1234_5678);
/// assert_eq!(card.get(0x20), 0x78);
/// assert_eq!(card.read_register(0x23)?, 0x12);
/// # Ok::<(), ctrlab::hw::PortError>(())
/// ```
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RegisterFile {
    memory: [u8; 256],
    address: u8,
}

impl Default for RegisterFile {
    fn default() -> Self {
        Self::new()
    }
}

impl RegisterFile {
    /// All registers zero, address 0 selected.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::hw::testing::RegisterFile;
    /// assert_eq!(RegisterFile::new().get(0xff), 0);
    /// ```
    pub fn new() -> Self {
        Self {
            memory: [0; 256],
            address: 0,
        }
    }

    /// The byte at `address`.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::hw::testing::RegisterFile;
    /// let mut card = RegisterFile::new();
    /// card.set(3, 9);
    /// assert_eq!(card.get(3), 9);
    /// ```
    pub fn get(&self, address: u8) -> u8 {
        self.memory[usize::from(address)]
    }

    /// Sets the byte at `address` (as the card's hardware would).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::hw::testing::RegisterFile;
    /// let mut card = RegisterFile::new();
    /// card.set(0, 0xa5);
    /// assert_eq!(card.get(0), 0xa5);
    /// ```
    pub fn set(&mut self, address: u8, value: u8) {
        self.memory[usize::from(address)] = value;
    }

    /// Stores `value` little-endian at `base..base + 4` (wrapping at 0xff),
    /// as a card's 32-bit counter.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::hw::testing::RegisterFile;
    /// let mut card = RegisterFile::new();
    /// card.set_u32_le(0x24, 0x8000_0001);
    /// assert_eq!((card.get(0x24), card.get(0x27)), (0x01, 0x80));
    /// ```
    pub fn set_u32_le(&mut self, base: u8, value: u32) {
        for (i, byte) in value.to_le_bytes().into_iter().enumerate() {
            self.set(base.wrapping_add(i as u8), byte);
        }
    }

    /// The currently selected address (the last address cycle).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::hw::{EppPort, testing::RegisterFile};
    /// let mut card = RegisterFile::new();
    /// card.write_address(0x42)?;
    /// assert_eq!(card.address(), 0x42);
    /// # Ok::<(), ctrlab::hw::PortError>(())
    /// ```
    pub fn address(&self) -> u8 {
        self.address
    }
}

impl EppPort for RegisterFile {
    fn write_address(&mut self, address: u8) -> Result<(), PortError> {
        self.address = address;
        Ok(())
    }
    fn read_data(&mut self) -> Result<u8, PortError> {
        Ok(self.get(self.address))
    }
    fn write_data(&mut self, value: u8) -> Result<(), PortError> {
        self.set(self.address, value);
        Ok(())
    }
}

/// One EPP cycle as seen on the bus, with its byte.
///
/// # Examples
///
/// ```
/// use ctrlab::hw::{CycleKind, testing::Cycle};
/// assert_eq!(Cycle::DataRead(0x12).kind(), CycleKind::DataRead);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Cycle {
    /// An address write of this address.
    AddressWrite(u8),
    /// A data read that returned this byte.
    DataRead(u8),
    /// A data write of this byte.
    DataWrite(u8),
}

impl Cycle {
    /// Which primitive this cycle is.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::{CycleKind, testing::Cycle};
    /// assert_eq!(Cycle::AddressWrite(1).kind(), CycleKind::AddressWrite);
    /// ```
    pub fn kind(self) -> CycleKind {
        match self {
            Cycle::AddressWrite(_) => CycleKind::AddressWrite,
            Cycle::DataRead(_) => CycleKind::DataRead,
            Cycle::DataWrite(_) => CycleKind::DataWrite,
        }
    }
}

/// When a [`RecordingPort`] fails.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Fault {
    None,
    /// Only this cycle (0-based) fails; later cycles work again.
    Once(usize),
    /// This cycle and every later one fail (the cable was pulled).
    From(usize),
}

/// Wraps any [`EppPort`] (by default a [`RegisterFile`]), logs every
/// successful cycle as a [`Cycle`], and can make cycle `k` fail with
/// [`PortError::Timeout`].
///
/// Cycles are counted from 0 over all attempts, failed ones included. A
/// failed cycle does not reach the inner port and is not logged.
///
/// # Examples
///
/// ```
/// use ctrlab::hw::{EppPort, PortErrorKind, testing::{Cycle, RecordingPort}};
///
/// // Only cycle 1 (the first data write) fails.
/// let mut port = RecordingPort::default().fail_at(1);
/// assert_eq!(port.write_register(0x10, 5).unwrap_err().kind(), PortErrorKind::Timeout);
/// port.write_register(0x10, 6)?;
/// assert_eq!(port.attempts(), 4);
/// assert_eq!(port.inner().get(0x10), 6);
/// assert_eq!(
///     port.log(),
///     &[Cycle::AddressWrite(0x10), Cycle::AddressWrite(0x10), Cycle::DataWrite(6)]
/// );
/// # Ok::<(), ctrlab::hw::PortError>(())
/// ```
#[derive(Debug, Clone)]
pub struct RecordingPort<P = RegisterFile> {
    inner: P,
    log: Vec<Cycle>,
    attempts: usize,
    fault: Fault,
}

impl Default for RecordingPort<RegisterFile> {
    fn default() -> Self {
        Self::new(RegisterFile::new())
    }
}

impl<P: EppPort> RecordingPort<P> {
    /// Records the traffic to `inner`; no fault injected.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::{EppPort, testing::{RecordingPort, RegisterFile}};
    /// let mut port = RecordingPort::new(RegisterFile::new());
    /// port.write_address(3)?;
    /// assert_eq!(port.log().len(), 1);
    /// # Ok::<(), ctrlab::hw::PortError>(())
    /// ```
    pub fn new(inner: P) -> Self {
        Self {
            inner,
            log: Vec::new(),
            attempts: 0,
            fault: Fault::None,
        }
    }

    /// Makes cycle `k` (0-based, counting every attempt) and only that one
    /// fail with a timeout. Replaces any earlier fault.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::{EppPort, testing::RecordingPort};
    /// let mut port = RecordingPort::default().fail_at(0);
    /// assert!(port.write_address(1).is_err());
    /// assert!(port.write_address(1).is_ok());
    /// ```
    pub fn fail_at(mut self, k: usize) -> Self {
        self.fault = Fault::Once(k);
        self
    }

    /// Makes cycle `k` and every later cycle fail with a timeout. Replaces
    /// any earlier fault.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::{EppPort, testing::RecordingPort};
    /// let mut port = RecordingPort::default().fail_from(1);
    /// assert!(port.write_address(1).is_ok());
    /// assert!(port.write_address(1).is_err());
    /// assert!(port.write_address(1).is_err());
    /// ```
    pub fn fail_from(mut self, k: usize) -> Self {
        self.fault = Fault::From(k);
        self
    }

    /// Removes any injected fault (the cable is back).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::{EppPort, testing::RecordingPort};
    /// let mut port = RecordingPort::default().fail_from(0);
    /// port.heal();
    /// assert!(port.write_address(1).is_ok());
    /// ```
    pub fn heal(&mut self) {
        self.fault = Fault::None;
    }

    /// The successful cycles so far, oldest first.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::{EppPort, testing::{Cycle, RecordingPort}};
    /// let mut port = RecordingPort::default();
    /// port.read_register(0)?;
    /// assert_eq!(port.log(), &[Cycle::AddressWrite(0), Cycle::DataRead(0)]);
    /// # Ok::<(), ctrlab::hw::PortError>(())
    /// ```
    pub fn log(&self) -> &[Cycle] {
        &self.log
    }

    /// Empties the log (the attempt counter keeps counting).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::{EppPort, testing::RecordingPort};
    /// let mut port = RecordingPort::default();
    /// port.write_address(0)?;
    /// port.clear_log();
    /// assert!(port.log().is_empty());
    /// assert_eq!(port.attempts(), 1);
    /// # Ok::<(), ctrlab::hw::PortError>(())
    /// ```
    pub fn clear_log(&mut self) {
        self.log.clear();
    }

    /// Cycles attempted so far, failed ones included.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::{EppPort, testing::RecordingPort};
    /// let mut port = RecordingPort::default().fail_at(0);
    /// assert!(port.write_address(0).is_err());
    /// assert_eq!(port.attempts(), 1);
    /// ```
    pub fn attempts(&self) -> usize {
        self.attempts
    }

    /// The wrapped port.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::testing::RecordingPort;
    /// assert_eq!(RecordingPort::default().inner().get(0), 0);
    /// ```
    pub fn inner(&self) -> &P {
        &self.inner
    }

    /// The wrapped port, mutably (to set what the card will answer).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::{EppPort, testing::RecordingPort};
    /// let mut port = RecordingPort::default();
    /// port.inner_mut().set(0, 0xa5);
    /// assert_eq!(port.read_register(0)?, 0xa5);
    /// # Ok::<(), ctrlab::hw::PortError>(())
    /// ```
    pub fn inner_mut(&mut self) -> &mut P {
        &mut self.inner
    }

    /// Counts an attempt and reports whether it is injected to fail.
    fn attempt(&mut self, cycle: CycleKind) -> Result<(), PortError> {
        let k = self.attempts;
        self.attempts += 1;
        let fails = match self.fault {
            Fault::None => false,
            Fault::Once(at) => k == at,
            Fault::From(at) => k >= at,
        };
        if fails {
            Err(PortError::Timeout {
                cycle,
                register: None,
            })
        } else {
            Ok(())
        }
    }
}

impl<P: EppPort> EppPort for RecordingPort<P> {
    fn write_address(&mut self, address: u8) -> Result<(), PortError> {
        self.attempt(CycleKind::AddressWrite)?;
        self.inner.write_address(address)?;
        self.log.push(Cycle::AddressWrite(address));
        Ok(())
    }
    fn read_data(&mut self) -> Result<u8, PortError> {
        self.attempt(CycleKind::DataRead)?;
        let value = self.inner.read_data()?;
        self.log.push(Cycle::DataRead(value));
        Ok(value)
    }
    fn write_data(&mut self, value: u8) -> Result<(), PortError> {
        self.attempt(CycleKind::DataWrite)?;
        self.inner.write_data(value)?;
        self.log.push(Cycle::DataWrite(value));
        Ok(())
    }
}
