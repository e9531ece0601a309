//! The [`EppPort`] trait: the three IEEE 1284 EPP primitives a card driver
//! is built on.

use super::PortError;

/// An IEEE 1284 EPP port: address write, data read, data write.
///
/// An address cycle selects a register on the card; the data cycles that
/// follow read or write that register. The card of this crate does **not**
/// auto-increment the address, so every byte is preceded by its own address
/// cycle ([`write_register`](Self::write_register),
/// [`read_register`](Self::read_register)).
///
/// Implemented by `Ppdev` (the real port, feature `ppdev`, Linux),
/// [`SimulatedCard`](super::SimulatedCard) and the fakes in
/// [`testing`](super::testing); and, like embedded-hal traits, by `&mut T`
/// for any port `T`, so a driver can borrow a port instead of owning it.
///
/// # Examples
///
/// ```
/// use ctrlab::hw::{EppPort, testing::RegisterFile};
///
/// let mut card = RegisterFile::new();
/// card.write_register(0x10, 0x2c)?;
/// assert_eq!(card.read_register(0x10)?, 0x2c);
/// // Through a `&mut` borrow, as a driver would use it.
/// let mut borrowed = &mut card;
/// assert_eq!(borrowed.read_register(0x10)?, 0x2c);
/// # Ok::<(), ctrlab::hw::PortError>(())
/// ```
pub trait EppPort {
    /// Writes `address` in an EPP address cycle, selecting a card register.
    ///
    /// # Errors
    ///
    /// [`PortError::Timeout`] when the card does not answer, or an OS error.
    fn write_address(&mut self, address: u8) -> Result<(), PortError>;

    /// Reads one byte from the selected register in an EPP data cycle.
    ///
    /// # Errors
    ///
    /// [`PortError::Timeout`] when the card does not answer, or an OS error.
    fn read_data(&mut self) -> Result<u8, PortError>;

    /// Writes one byte to the selected register in an EPP data cycle.
    ///
    /// # Errors
    ///
    /// [`PortError::Timeout`] when the card does not answer, or an OS error.
    fn write_data(&mut self, value: u8) -> Result<(), PortError>;

    /// Writes `value` to register `address`: an address cycle, then a data
    /// write. A timeout names the register.
    ///
    /// # Errors
    ///
    /// As [`write_address`](Self::write_address) and
    /// [`write_data`](Self::write_data).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::{EppPort, testing::{Cycle, RecordingPort}};
    /// let mut port = RecordingPort::default();
    /// port.write_register(0x01, 0x04)?;
    /// assert_eq!(port.log(), &[Cycle::AddressWrite(0x01), Cycle::DataWrite(0x04)]);
    /// # Ok::<(), ctrlab::hw::PortError>(())
    /// ```
    #[inline]
    fn write_register(&mut self, address: u8, value: u8) -> Result<(), PortError> {
        self.write_address(address)
            .and_then(|()| self.write_data(value))
            .map_err(|e| e.at_register(address))
    }

    /// Reads register `address`: an address cycle, then a data read. A
    /// timeout names the register.
    ///
    /// # Errors
    ///
    /// As [`write_address`](Self::write_address) and
    /// [`read_data`](Self::read_data).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::{EppPort, testing::RegisterFile};
    /// let mut card = RegisterFile::new();
    /// card.set(0x00, 0xa5);
    /// assert_eq!(card.read_register(0x00)?, 0xa5);
    /// # Ok::<(), ctrlab::hw::PortError>(())
    /// ```
    #[inline]
    fn read_register(&mut self, address: u8) -> Result<u8, PortError> {
        self.write_address(address)
            .and_then(|()| self.read_data())
            .map_err(|e| e.at_register(address))
    }
}

impl<T: EppPort + ?Sized> EppPort for &mut T {
    #[inline]
    fn write_address(&mut self, address: u8) -> Result<(), PortError> {
        (**self).write_address(address)
    }
    #[inline]
    fn read_data(&mut self) -> Result<u8, PortError> {
        (**self).read_data()
    }
    #[inline]
    fn write_data(&mut self, value: u8) -> Result<(), PortError> {
        (**self).write_data(value)
    }
    #[inline]
    fn write_register(&mut self, address: u8, value: u8) -> Result<(), PortError> {
        (**self).write_register(address, value)
    }
    #[inline]
    fn read_register(&mut self, address: u8) -> Result<u8, PortError> {
        (**self).read_register(address)
    }
}
