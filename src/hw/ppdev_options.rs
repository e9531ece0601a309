//! [`PpdevOptions`]: how `Ppdev` drives a particular parallel port. Not
//! behind the `ppdev` feature, so a card file (`lab::RigConfig`, its
//! `[port]` table) reads the same on every platform.

/// How `Ppdev` (feature `ppdev`, Linux) drives a particular parallel port:
/// what differs between ports rather than between cards.
///
/// In a card file (`lab::RigConfig`) these are the `[port]` table's keys;
/// the table and each key may be left out, and then take the defaults
/// below.
///
/// # `data_dir`: the data-direction bit on reads
///
/// An EPP data read needs the port's data lines turned round (driven by
/// the card, not the PC). Whether the port does that by itself differs
/// between ports:
///
/// - a port set to EPP through its ECP mode register ("EPP+ECP" in the
///   BIOS) does: Linux's `parport_pc` sets the direction bit itself before
///   each EPP read on such a port;
/// - most EPP-only ports turn the lines round in hardware during an EPP
///   read cycle (LinuxCNC's driver for the Mesa 7i43 reads EPP without
///   touching the bit);
/// - some need the direction bit (bit 5 of the control register) set by
///   software first, as LinuxCNC's `hal_ppmc` does before every read.
///
/// With `data_dir = true`, every data read is bracketed by `PPDATADIR`
/// ioctls: the direction bit set (reverse) before it and cleared (forward)
/// after it, so address and data writes always find the port driving. It
/// costs two more system calls per byte read: 16 more per tick of the
/// lab's rig (8 bytes read), 60 instead of 44.
///
/// **Default `false`**: the two common cases above need nothing, and it
/// keeps a tick at 44 system calls. Turn it on when the card answers on
/// writes (the motor moves) but reads are wrong — typically the ID register
/// reading back the address just written, or `0xff` — on an EPP-only port.
///
/// # Examples
///
/// ```
/// use ctrlab::hw::PpdevOptions;
/// let options = PpdevOptions::default();
/// assert!(!options.data_dir); // the port turns its data lines round itself
/// let bracketed = PpdevOptions { data_dir: true };
/// assert_ne!(bracketed, options);
/// ```
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Hash, Default, serde::Serialize, serde::Deserialize,
)]
#[serde(default, deny_unknown_fields)]
pub struct PpdevOptions {
    /// Set the data-direction bit (`PPDATADIR`) before each EPP data read
    /// and clear it after (see the [type docs](Self)). Default `false`.
    pub data_dir: bool,
}
