//! Read-only scans of all 256 card addresses, and what they tell apart.

use super::super::{EppPort, PortError};

/// The value an EPP data read returns where nothing drives the bus (the
/// port's pull-ups): unmapped and write-only registers alike.
///
/// # Examples
///
/// ```
/// use ctrlab::hw::probe::{OPEN_BUS, RegisterClass, Scan};
/// let idle = [OPEN_BUS; 256]; // no card: the pull-ups everywhere
/// let scan = Scan { first: idle, second: idle };
/// assert_eq!(scan.class(0x42), RegisterClass::Open);
/// assert_eq!(scan.id(), None);
/// ```
pub const OPEN_BUS: u8 = 0xff;

/// One read of every address 0x00–0xff, in address order.
///
/// # Examples
///
/// ```
/// use ctrlab::hw::probe::{OPEN_BUS, Scan, Snapshot};
/// let mut first: Snapshot = [OPEN_BUS; 256];
/// first[0x07] = 0x3c; // indexed by address
/// let scan = Scan { first, second: first };
/// assert_eq!(scan.id(), Some((0x07, 0x3c)));
/// ```
pub type Snapshot = [u8; 256];

/// Reads every address once (256 address and 256 data-read cycles, no
/// register write).
///
/// # Errors
///
/// The port's, with the register named.
pub(super) fn snapshot<P: EppPort>(port: &mut P) -> Result<Snapshot, PortError> {
    let mut out = [0u8; 256];
    for (address, byte) in (0..=u8::MAX).zip(out.iter_mut()) {
        *byte = port.read_register(address)?;
    }
    Ok(out)
}

/// What two read-only scans say about one address.
///
/// # Examples
///
/// ```
/// use ctrlab::hw::probe::{RegisterClass, Scan};
/// let mut first = [0xff; 256];
/// first[0] = 0xa5;
/// first[7] = 3;
/// let mut second = first;
/// second[7] = 4;
/// let scan = Scan { first, second };
/// assert_eq!(scan.class(0), RegisterClass::Constant(0xa5));
/// assert_eq!(scan.class(7), RegisterClass::Volatile);
/// assert_eq!(scan.class(8), RegisterClass::Open);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RegisterClass {
    /// Read [`OPEN_BUS`] twice: nothing there, or a write-only register.
    Open,
    /// Read the same other value twice.
    Constant(u8),
    /// Read two different values: something that changes on its own.
    Volatile,
}

/// Two read-only scans of all 256 addresses, taken a moment apart.
///
/// # Examples
///
/// ```
/// use ctrlab::hw::probe::Scan;
/// let mut first = [0xff; 256];
/// first[0] = 0xa5;
/// let scan = Scan { first, second: first };
/// assert_eq!(scan.id(), Some((0x00, 0xa5)));
/// assert_eq!(scan.id_candidates().count(), 1);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Scan {
    /// The first scan.
    pub first: Snapshot,
    /// The second scan.
    pub second: Snapshot,
}

impl Scan {
    /// The class of `address`.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::probe::{RegisterClass, Scan};
    /// let scan = Scan { first: [0; 256], second: [0; 256] };
    /// assert_eq!(scan.class(0x20), RegisterClass::Constant(0));
    /// ```
    pub fn class(&self, address: u8) -> RegisterClass {
        let (a, b) = (
            self.first[usize::from(address)],
            self.second[usize::from(address)],
        );
        match (a, b) {
            (OPEN_BUS, OPEN_BUS) => RegisterClass::Open,
            (a, b) if a == b => RegisterClass::Constant(a),
            _ => RegisterClass::Volatile,
        }
    }

    /// The addresses of one class, ascending.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::probe::{RegisterClass, Scan};
    /// let scan = Scan { first: [0xff; 256], second: [0xff; 256] };
    /// assert_eq!(scan.addresses(|c| c == RegisterClass::Open).count(), 256);
    /// ```
    pub fn addresses<'a>(
        &'a self,
        mut keep: impl FnMut(RegisterClass) -> bool + 'a,
    ) -> impl Iterator<Item = u8> + 'a {
        (0..=u8::MAX).filter(move |&a| keep(self.class(a)))
    }

    /// Addresses that read a constant other than `0x00` and `0xff` (the two
    /// values an idle bus or an empty register reads): card ID candidates,
    /// with their values.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::probe::Scan;
    /// let scan = Scan { first: [0; 256], second: [0; 256] };
    /// assert_eq!(scan.id_candidates().count(), 0);
    /// ```
    pub fn id_candidates(&self) -> impl Iterator<Item = (u8, u8)> + '_ {
        (0..=u8::MAX).filter_map(|a| match self.class(a) {
            RegisterClass::Constant(v) if v != 0x00 => Some((a, v)),
            _ => None,
        })
    }

    /// The card's ID register and value: the lowest-addressed ID candidate
    /// ([`id_candidates`](Self::id_candidates)), or `None` (no card answers).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::probe::Scan;
    /// let mut first = [0xff; 256];
    /// (first[0x40], first[0x41]) = (0x12, 0x34);
    /// assert_eq!(Scan { first, second: first }.id(), Some((0x40, 0x12)));
    /// ```
    pub fn id(&self) -> Option<(u8, u8)> {
        self.id_candidates().next()
    }

    /// Whether `after` differs from `before` anywhere but at the addresses
    /// this scan found volatile.
    pub(super) fn changed(&self, before: &Snapshot, after: &Snapshot) -> bool {
        (0..=u8::MAX).any(|a| {
            self.class(a) != RegisterClass::Volatile
                && before[usize::from(a)] != after[usize::from(a)]
        })
    }
}
