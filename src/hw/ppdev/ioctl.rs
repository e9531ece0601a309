//! The `ppdev` ioctl request numbers and `parport` mode and control bits
//! this driver uses, computed like the kernel's `_IO`/`_IOR`/`_IOW` macros
//! for the target architecture (from `linux/ppdev.h` and
//! `linux/parport.h`).
//!
//! # Examples
//!
//! ```
//! use ctrlab::hw::ioctl;
//! #[cfg(target_arch = "x86_64")]
//! assert_eq!((ioctl::PPSETMODE, ioctl::PPWCONTROL), (0x4004_7080, 0x4001_7084));
//! #[cfg(target_arch = "x86_64")]
//! assert_eq!(ioctl::PPDATADIR, 0x4004_7090);
//! assert_eq!(ioctl::IEEE1284_MODE_EPP | ioctl::IEEE1284_ADDR, 0x2040);
//! assert_eq!(ioctl::IEEE1284_MODE_COMPAT, 0x100);
//! assert_eq!(ioctl::EPP_CONTROL, 0x04);
//! ```

use std::ffi::{c_int, c_uchar, c_uint};
use std::mem::size_of;

#[cfg(any(
    target_arch = "powerpc",
    target_arch = "powerpc64",
    target_arch = "mips",
    target_arch = "mips64",
    target_arch = "sparc",
    target_arch = "sparc64"
))]
mod layout {
    pub const NONE: u32 = 1;
    pub const READ: u32 = 2;
    pub const WRITE: u32 = 4;
    pub const SIZE_BITS: u32 = 13;
}
#[cfg(not(any(
    target_arch = "powerpc",
    target_arch = "powerpc64",
    target_arch = "mips",
    target_arch = "mips64",
    target_arch = "sparc",
    target_arch = "sparc64"
)))]
mod layout {
    pub const NONE: u32 = 0;
    pub const WRITE: u32 = 1;
    pub const READ: u32 = 2;
    pub const SIZE_BITS: u32 = 14;
}

/// `PP_IOCTL`, the ioctl type of ppdev.
const PP: u32 = b'p' as u32;

/// The kernel's `_IOC(dir, 'p', nr, size)`.
const fn ioc(dir: u32, nr: u32, size: usize) -> u32 {
    (dir << (16 + layout::SIZE_BITS)) | ((size as u32) << 16) | (PP << 8) | nr
}

/// `_IOW('p', 0x80, int)`: set the IEEE 1284 mode for read/write.
///
/// # Examples
///
/// ```
/// use ctrlab::hw::ioctl::PPSETMODE;
/// // _IOW('p', 0x80, int) by asm-generic/ioctl.h (x86-64, AArch64):
/// // direction (none 0, write 1, read 2) << 30 | size << 16 | 'p' << 8 | number.
/// #[cfg(any(target_arch = "x86_64", target_arch = "aarch64"))]
/// assert_eq!(PPSETMODE, 1 << 30 | 4 << 16 | (b'p' as u32) << 8 | 0x80); // sizeof(int) = 4
/// ```
pub const PPSETMODE: u32 = ioc(layout::WRITE, 0x80, size_of::<c_int>());
/// `_IO('p', 0x8b)`: claim the port.
///
/// # Examples
///
/// ```
/// use ctrlab::hw::ioctl::PPCLAIM;
/// // _IO('p', 0x8b) by asm-generic/ioctl.h (x86-64, AArch64):
/// // direction (none 0, write 1, read 2) << 30 | size << 16 | 'p' << 8 | number.
/// #[cfg(any(target_arch = "x86_64", target_arch = "aarch64"))]
/// assert_eq!(PPCLAIM, (b'p' as u32) << 8 | 0x8b); // no data: 0x708b
/// ```
pub const PPCLAIM: u32 = ioc(layout::NONE, 0x8b, 0);
/// `_IO('p', 0x8c)`: release the port.
///
/// # Examples
///
/// ```
/// use ctrlab::hw::ioctl::PPRELEASE;
/// // _IO('p', 0x8c) by asm-generic/ioctl.h (x86-64, AArch64):
/// // direction (none 0, write 1, read 2) << 30 | size << 16 | 'p' << 8 | number.
/// #[cfg(any(target_arch = "x86_64", target_arch = "aarch64"))]
/// assert_eq!(PPRELEASE, (b'p' as u32) << 8 | 0x8c); // no data: 0x708c
/// ```
pub const PPRELEASE: u32 = ioc(layout::NONE, 0x8c, 0);
/// `_IO('p', 0x8f)`: register exclusively (before `PPCLAIM`).
///
/// # Examples
///
/// ```
/// use ctrlab::hw::ioctl::PPEXCL;
/// // _IO('p', 0x8f) by asm-generic/ioctl.h (x86-64, AArch64):
/// // direction (none 0, write 1, read 2) << 30 | size << 16 | 'p' << 8 | number.
/// #[cfg(any(target_arch = "x86_64", target_arch = "aarch64"))]
/// assert_eq!(PPEXCL, (b'p' as u32) << 8 | 0x8f); // no data: 0x708f
/// ```
pub const PPEXCL: u32 = ioc(layout::NONE, 0x8f, 0);
/// `_IOR('p', 0x97, unsigned int)`: the port's hardware modes.
///
/// # Examples
///
/// ```
/// use ctrlab::hw::ioctl::PPGETMODES;
/// // _IOR('p', 0x97, unsigned int) by asm-generic/ioctl.h (x86-64, AArch64):
/// // direction (none 0, write 1, read 2) << 30 | size << 16 | 'p' << 8 | number.
/// #[cfg(any(target_arch = "x86_64", target_arch = "aarch64"))]
/// assert_eq!(PPGETMODES, 2 << 30 | 4 << 16 | (b'p' as u32) << 8 | 0x97); // read, 4 bytes
/// ```
pub const PPGETMODES: u32 = ioc(layout::READ, 0x97, size_of::<c_uint>());
/// `_IOW('p', 0x84, unsigned char)`: write the control register's
/// bits 0–3 (nStrobe, nAutoFd, nInit, nSelectIn). The PC-style driver
/// (`parport_pc`) masks the value to those four bits: it never writes
/// bit 4 (the port's interrupt enable, which the kernel manages), and a
/// set bit 5 only turns the data lines round (reverse, as `PPDATADIR`
/// 1 does, with a kernel log line saying to use that instead).
///
/// # Examples
///
/// ```
/// use ctrlab::hw::ioctl::PPWCONTROL;
/// // _IOW('p', 0x84, unsigned char) by asm-generic/ioctl.h (x86-64, AArch64):
/// // direction (none 0, write 1, read 2) << 30 | size << 16 | 'p' << 8 | number.
/// #[cfg(any(target_arch = "x86_64", target_arch = "aarch64"))]
/// assert_eq!(PPWCONTROL, 1 << 30 | 1 << 16 | (b'p' as u32) << 8 | 0x84); // write, 1 byte
/// ```
pub const PPWCONTROL: u32 = ioc(layout::WRITE, 0x84, size_of::<c_uchar>());
/// `_IOW('p', 0x90, int)`: data direction; non-zero turns the data
/// lines round (reverse, the peripheral drives them: bit 5 of the
/// control register set), zero sets them forward (the PC drives).
///
/// # Examples
///
/// ```
/// use ctrlab::hw::ioctl::PPDATADIR;
/// // _IOW('p', 0x90, int) by asm-generic/ioctl.h (x86-64, AArch64):
/// // direction (none 0, write 1, read 2) << 30 | size << 16 | 'p' << 8 | number.
/// #[cfg(any(target_arch = "x86_64", target_arch = "aarch64"))]
/// assert_eq!(PPDATADIR, 1 << 30 | 4 << 16 | (b'p' as u32) << 8 | 0x90); // sizeof(int) = 4
/// ```
pub const PPDATADIR: u32 = ioc(layout::WRITE, 0x90, size_of::<c_int>());

/// `PARPORT_MODE_PCSPP` in `PPGETMODES`: IBM PC registers available.
///
/// # Examples
///
/// ```
/// use ctrlab::hw::{PortModes, ioctl::PARPORT_MODE_PCSPP};
/// assert_eq!(PARPORT_MODE_PCSPP, 1 << 0); // linux/parport.h
/// assert!(PortModes::from_bits(PARPORT_MODE_PCSPP).pcspp); // IBM PC registers
/// ```
pub const PARPORT_MODE_PCSPP: c_uint = 1 << 0;
/// `PARPORT_MODE_TRISTATE`: the data lines can be tristated.
///
/// # Examples
///
/// ```
/// use ctrlab::hw::{PortModes, ioctl::PARPORT_MODE_TRISTATE};
/// assert_eq!(PARPORT_MODE_TRISTATE, 1 << 1); // linux/parport.h
/// assert!(PortModes::from_bits(PARPORT_MODE_TRISTATE).tristate); // bidirectional data lines
/// ```
pub const PARPORT_MODE_TRISTATE: c_uint = 1 << 1;
/// `PARPORT_MODE_EPP` in `PPGETMODES`: the port has hardware EPP.
///
/// # Examples
///
/// ```
/// use ctrlab::hw::{PortModes, ioctl::PARPORT_MODE_EPP};
/// assert_eq!(PARPORT_MODE_EPP, 1 << 2); // linux/parport.h
/// assert!(PortModes::from_bits(PARPORT_MODE_EPP).epp); // hardware EPP, which the card needs
/// ```
pub const PARPORT_MODE_EPP: c_uint = 1 << 2;
/// `PARPORT_MODE_ECP`: hardware ECP.
///
/// # Examples
///
/// ```
/// use ctrlab::hw::{PortModes, ioctl::PARPORT_MODE_ECP};
/// assert_eq!(PARPORT_MODE_ECP, 1 << 3); // linux/parport.h
/// assert!(PortModes::from_bits(PARPORT_MODE_ECP).ecp); // hardware ECP
/// ```
pub const PARPORT_MODE_ECP: c_uint = 1 << 3;
/// `PARPORT_MODE_COMPAT`: hardware printer protocol.
///
/// # Examples
///
/// ```
/// use ctrlab::hw::{PortModes, ioctl::PARPORT_MODE_COMPAT};
/// assert_eq!(PARPORT_MODE_COMPAT, 1 << 4); // linux/parport.h
/// assert!(PortModes::from_bits(PARPORT_MODE_COMPAT).compat); // hardware printer protocol
/// ```
pub const PARPORT_MODE_COMPAT: c_uint = 1 << 4;
/// `PARPORT_MODE_DMA`: the hardware can DMA.
///
/// # Examples
///
/// ```
/// use ctrlab::hw::{PortModes, ioctl::PARPORT_MODE_DMA};
/// assert_eq!(PARPORT_MODE_DMA, 1 << 5); // linux/parport.h
/// assert!(PortModes::from_bits(PARPORT_MODE_DMA).dma); // DMA
/// ```
pub const PARPORT_MODE_DMA: c_uint = 1 << 5;
/// `PARPORT_MODE_SAFEININT`: SPP registers accessible in an interrupt.
///
/// # Examples
///
/// ```
/// use ctrlab::hw::{PortModes, ioctl::PARPORT_MODE_SAFEININT};
/// assert_eq!(PARPORT_MODE_SAFEININT, 1 << 6); // linux/parport.h
/// assert!(PortModes::from_bits(PARPORT_MODE_SAFEININT).safe_in_interrupt); // SPP registers usable in an interrupt
/// ```
pub const PARPORT_MODE_SAFEININT: c_uint = 1 << 6;

/// `PARPORT_CONTROL_INIT`, the control register's bit 2 (nInit, not
/// inverted on the connector).
///
/// # Examples
///
/// ```
/// use ctrlab::hw::ioctl::PARPORT_CONTROL_INIT;
/// // linux/parport.h: STROBE 0x1, AUTOFD 0x2, INIT 0x4, SELECT 0x8.
/// assert_eq!(PARPORT_CONTROL_INIT, 1 << 2);
/// ```
pub const PARPORT_CONTROL_INIT: c_uchar = 0x04;
/// The control register's bits 0–3 for EPP cycles, written once after
/// claiming (`PPWCONTROL`, which writes only those four bits), as
/// LinuxCNC's EPP drivers (`hm2_7i43`) do: nInit high (bit 2 set: EPP's
/// nReset, not asserted); nStrobe, nAutoFd and nSelectIn high (bits 0,
/// 1, 3 clear: EPP's nWrite, nDataStrobe and nAddrStrobe, which the
/// port's EPP hardware then drives; the kernel leaves a claimed port at
/// `0x0c`, nSelectIn low). Bit 4 (interrupt enable) and bit 5 (data
/// direction) are not written by this: direction is `PPDATADIR`'s (see
/// [`PpdevOptions::data_dir`](crate::hw::PpdevOptions::data_dir)).
///
/// # Examples
///
/// ```
/// use ctrlab::hw::ioctl::{EPP_CONTROL, PARPORT_CONTROL_INIT};
/// assert_eq!(EPP_CONTROL & 0xf0, 0); // only bits 0–3: no IRQ enable, no direction
/// assert_eq!(EPP_CONTROL & PARPORT_CONTROL_INIT, PARPORT_CONTROL_INIT); // nReset released
/// assert_eq!(EPP_CONTROL & 0x0b, 0); // nStrobe, nAutoFd, nSelectIn high
/// ```
pub const EPP_CONTROL: c_uchar = PARPORT_CONTROL_INIT;
/// `IEEE1284_MODE_COMPAT` for `PPSETMODE`: compatibility (printer)
/// mode, what the kernel expects a port to be left in.
///
/// # Examples
///
/// ```
/// use ctrlab::hw::ioctl::{IEEE1284_MODE_COMPAT, IEEE1284_MODE_EPP};
/// assert_eq!(IEEE1284_MODE_COMPAT, 1 << 8); // linux/parport.h
/// assert_eq!(IEEE1284_MODE_COMPAT & IEEE1284_MODE_EPP, 0); // distinct modes
/// ```
pub const IEEE1284_MODE_COMPAT: c_int = 1 << 8;
/// `IEEE1284_MODE_EPP` for `PPSETMODE`.
///
/// # Examples
///
/// ```
/// use ctrlab::hw::ioctl::IEEE1284_MODE_EPP;
/// assert_eq!(IEEE1284_MODE_EPP, 1 << 6); // linux/parport.h
/// ```
pub const IEEE1284_MODE_EPP: c_int = 1 << 6;
/// `IEEE1284_ADDR`, or'ed into the mode for address cycles.
///
/// # Examples
///
/// EPP address cycles: the EPP mode with the address flag (`linux/parport.h`).
///
/// ```
/// use ctrlab::hw::ioctl::{IEEE1284_ADDR, IEEE1284_MODE_EPP};
/// assert_eq!(IEEE1284_ADDR, 1 << 13);
/// assert_eq!(IEEE1284_MODE_EPP | IEEE1284_ADDR, 0x2040);
/// ```
pub const IEEE1284_ADDR: c_int = 1 << 13;
