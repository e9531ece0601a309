//! [`Ppdev`]: the real parallel port through Linux's `ppdev` driver
//! (`/dev/parportN`), in IEEE 1284 EPP mode. Feature `ppdev`, Linux only.
//!
//! This is the only file of the crate with `unsafe` code: the `ioctl`
//! calls. Reads and writes go through `std::fs::File`.
#![allow(unsafe_code)]

use std::fs::{File, OpenOptions};
use std::io::{self, Read, Write};
use std::os::fd::AsRawFd;
use std::os::unix::fs::OpenOptionsExt;
use std::path::Path;

use super::{CycleKind, EppPort, PortError};

mod diagnosis;

pub use diagnosis::PortModes;
use diagnosis::{port_error, require_epp};

/// The `ppdev` ioctl request numbers and `parport` mode and control bits
/// this driver uses, computed like the kernel's `_IO`/`_IOR`/`_IOW` macros
/// for the target architecture (from `linux/ppdev.h` and
/// `linux/parport.h`).
///
/// # Examples
///
/// ```
/// use ctrlab::hw::ioctl;
/// #[cfg(target_arch = "x86_64")]
/// assert_eq!((ioctl::PPSETMODE, ioctl::PPWCONTROL), (0x4004_7080, 0x4001_7084));
/// assert_eq!(ioctl::IEEE1284_MODE_EPP | ioctl::IEEE1284_ADDR, 0x2040);
/// assert_eq!(ioctl::EPP_CONTROL, 0x04);
/// ```
pub mod ioctl {
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
    pub const PPSETMODE: u32 = ioc(layout::WRITE, 0x80, size_of::<c_int>());
    /// `_IO('p', 0x8b)`: claim the port.
    pub const PPCLAIM: u32 = ioc(layout::NONE, 0x8b, 0);
    /// `_IO('p', 0x8c)`: release the port.
    pub const PPRELEASE: u32 = ioc(layout::NONE, 0x8c, 0);
    /// `_IO('p', 0x8f)`: register exclusively (before `PPCLAIM`).
    pub const PPEXCL: u32 = ioc(layout::NONE, 0x8f, 0);
    /// `_IOR('p', 0x97, unsigned int)`: the port's hardware modes.
    pub const PPGETMODES: u32 = ioc(layout::READ, 0x97, size_of::<c_uint>());
    /// `_IOW('p', 0x84, unsigned char)`: write the control register.
    pub const PPWCONTROL: u32 = ioc(layout::WRITE, 0x84, size_of::<c_uchar>());

    /// `PARPORT_MODE_PCSPP` in `PPGETMODES`: IBM PC registers available.
    pub const PARPORT_MODE_PCSPP: c_uint = 1 << 0;
    /// `PARPORT_MODE_TRISTATE`: the data lines can be tristated.
    pub const PARPORT_MODE_TRISTATE: c_uint = 1 << 1;
    /// `PARPORT_MODE_EPP` in `PPGETMODES`: the port has hardware EPP.
    pub const PARPORT_MODE_EPP: c_uint = 1 << 2;
    /// `PARPORT_MODE_ECP`: hardware ECP.
    pub const PARPORT_MODE_ECP: c_uint = 1 << 3;
    /// `PARPORT_MODE_COMPAT`: hardware printer protocol.
    pub const PARPORT_MODE_COMPAT: c_uint = 1 << 4;
    /// `PARPORT_MODE_DMA`: the hardware can DMA.
    pub const PARPORT_MODE_DMA: c_uint = 1 << 5;
    /// `PARPORT_MODE_SAFEININT`: SPP registers accessible in an interrupt.
    pub const PARPORT_MODE_SAFEININT: c_uint = 1 << 6;

    /// `PARPORT_CONTROL_INIT`, the control register's bit 2 (nInit, not
    /// inverted on the connector).
    pub const PARPORT_CONTROL_INIT: c_uchar = 0x04;
    /// The control register for EPP cycles, written once after claiming
    /// (`PPWCONTROL`), as LinuxCNC's EPP drivers (`hm2_7i43`) do: nInit
    /// high (EPP's nReset, not asserted); nStrobe, nAutoFd and nSelectIn
    /// released (bits 0, 1, 3 clear: EPP's nWrite, nDataStrobe and
    /// nAddrStrobe, which the port's EPP hardware drives; the kernel leaves
    /// a claimed port at `0x0c`, nSelectIn asserted); interrupts off; data
    /// direction forward (bit 5 clear).
    pub const EPP_CONTROL: c_uchar = PARPORT_CONTROL_INIT;
    /// `IEEE1284_MODE_EPP` for `PPSETMODE`.
    pub const IEEE1284_MODE_EPP: c_int = 1 << 6;
    /// `IEEE1284_ADDR`, or'ed into the mode for address cycles.
    pub const IEEE1284_ADDR: c_int = 1 << 13;
}

/// A Linux parallel port in EPP mode through `ppdev`.
///
/// [`open`](Self::open) opens `/dev/parportN` non-blocking, registers
/// exclusively (`PPEXCL`), claims the port (`PPCLAIM`), checks the hardware
/// has EPP (`PPGETMODES`), selects EPP data cycles (`PPSETMODE`) and sets
/// the control register for EPP ([`ioctl::EPP_CONTROL`], `PPWCONTROL`).
/// Address cycles switch the mode to EPP | `IEEE1284_ADDR` and back (only
/// when the cycle kind changes). There is no `PPNEGOT`: the card is not an
/// IEEE 1284 peripheral that negotiates. Dropping the port releases it
/// (`PPRELEASE`).
///
/// # What a register access costs
///
/// Each EPP cycle is one `read` or `write` system call of one byte, and a
/// change between address and data cycles is one more, a `PPSETMODE`
/// ioctl. The card does not auto-increment its address, so every register
/// access is an address cycle then a data cycle, and the mode changes on
/// every cycle: one tick of the lab's rig
/// ([`MassSpringRig`](crate::lab::MassSpringRig): latch and kick, two
/// 32-bit counters, one PWM duty) is 22 EPP cycles and 22 mode switches,
/// 44 system calls. No batching saves any without auto-increment (see
/// `tests/hw.rs`, `one_rig_tick_costs_22_cycles_and_22_mode_switches`).
///
/// Errors say what is wrong and what to do: a short read or write is
/// [`PortError::Timeout`]; `EACCES`/`EPERM` are [`PortError::Permission`]
/// (the `lp` group); `ENXIO`/`EBUSY` when claiming are [`PortError::Busy`]
/// (the printer driver `lp` holds the port: how to free it); `ENOENT`,
/// `ENODEV` and `ENXIO` otherwise, and a port without hardware EPP, are
/// [`PortError::NotPresent`] (with the likely causes); anything else is
/// [`PortError::Io`] naming the failed step.
///
/// # Examples
///
/// ```
/// use ctrlab::hw::{PortErrorKind, Ppdev};
/// let err = Ppdev::open("/dev/nonexistent").unwrap_err();
/// assert_eq!(err.kind(), PortErrorKind::NotPresent);
/// ```
#[derive(Debug)]
pub struct Ppdev {
    file: File,
    device: String,
    modes: PortModes,
    /// `Some(true)` in address mode, `Some(false)` in data mode.
    address_mode: Option<bool>,
}

impl Ppdev {
    /// Opens and claims `path` (e.g. `/dev/parport0`) in EPP mode.
    ///
    /// # Errors
    ///
    /// [`PortError::NotPresent`] (no such device, or no hardware EPP),
    /// [`PortError::Permission`], [`PortError::Busy`] (another driver holds
    /// the port), [`PortError::Io`] naming the failed step.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::{PortErrorKind, Ppdev};
    /// // /dev/null opens but is no parallel port: the first ioctl fails.
    /// let err = Ppdev::open("/dev/null").unwrap_err();
    /// assert_eq!(err.kind(), PortErrorKind::Io);
    /// assert!(err.to_string().contains("PPEXCL"));
    /// ```
    pub fn open(path: impl AsRef<Path>) -> Result<Self, PortError> {
        let (file, device) = open_device(path.as_ref())?;
        ioctl_none(&file, ioctl::PPEXCL).map_err(|e| port_error(&device, "PPEXCL", e))?;
        ioctl_none(&file, ioctl::PPCLAIM).map_err(|e| port_error(&device, "PPCLAIM", e))?;
        let modes = get_modes(&file).map_err(|e| port_error(&device, "PPGETMODES", e))?;
        // Claimed: from here on, dropping `port` releases it.
        let mut port = Self {
            file,
            device,
            modes,
            address_mode: None,
        };
        require_epp(&port.device, modes)?;
        port.set_mode(false)?;
        port.write_control(ioctl::EPP_CONTROL)?;
        Ok(port)
    }

    /// The modes of the port at `path` (`PPGETMODES`), without claiming it:
    /// what a port can do, even while another driver holds it or when it
    /// has no EPP (which [`open`](Self::open) refuses).
    ///
    /// # Errors
    ///
    /// As [`open`](Self::open), for the `open` and `PPGETMODES` steps.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::{PortErrorKind, Ppdev};
    /// let err = Ppdev::modes_of("/dev/nonexistent").unwrap_err();
    /// assert_eq!(err.kind(), PortErrorKind::NotPresent);
    /// ```
    pub fn modes_of(path: impl AsRef<Path>) -> Result<PortModes, PortError> {
        let (file, device) = open_device(path.as_ref())?;
        get_modes(&file).map_err(|e| port_error(&device, "PPGETMODES", e))
    }

    /// The port's hardware modes (`PPGETMODES`, read when it was opened).
    ///
    /// # Examples
    ///
    /// ```no_run
    /// use ctrlab::hw::Ppdev;
    /// let port = Ppdev::open("/dev/parport0")?;
    /// assert!(port.modes().epp); // open refuses a port without
    /// println!("{}: {}", port.device(), port.modes()); // PCSPP,TRISTATE,EPP,ECP,COMPAT
    /// # Ok::<(), ctrlab::hw::PortError>(())
    /// ```
    pub fn modes(&self) -> PortModes {
        self.modes
    }

    /// The device path.
    ///
    /// # Examples
    ///
    /// ```no_run
    /// use ctrlab::hw::Ppdev;
    /// let port = Ppdev::open("/dev/parport0")?;
    /// assert_eq!(port.device(), "/dev/parport0");
    /// # Ok::<(), ctrlab::hw::PortError>(())
    /// ```
    pub fn device(&self) -> &str {
        &self.device
    }

    /// Writes the port's control register (`PPWCONTROL`).
    fn write_control(&mut self, value: u8) -> Result<(), PortError> {
        let value: libc::c_uchar = value;
        // SAFETY: PPWCONTROL reads one `unsigned char` through its pointer
        // argument; `value` is a live c_uchar for the whole call, and the fd
        // is owned by `self.file`, open for the call's duration.
        let rc = unsafe {
            libc::ioctl(
                self.file.as_raw_fd(),
                ioctl::PPWCONTROL as libc::Ioctl,
                &value as *const libc::c_uchar,
            )
        };
        if rc < 0 {
            return Err(port_error(
                &self.device,
                "PPWCONTROL",
                io::Error::last_os_error(),
            ));
        }
        Ok(())
    }

    /// Selects EPP address (`true`) or data (`false`) cycles, if not already.
    fn set_mode(&mut self, address: bool) -> Result<(), PortError> {
        if self.address_mode == Some(address) {
            return Ok(());
        }
        let mode: libc::c_int = if address {
            ioctl::IEEE1284_MODE_EPP | ioctl::IEEE1284_ADDR
        } else {
            ioctl::IEEE1284_MODE_EPP
        };
        // SAFETY: PPSETMODE reads one `int` through its pointer argument;
        // `mode` is a live, aligned c_int for the whole call, and the fd is
        // owned by `self.file`, open for the call's duration.
        let rc = unsafe {
            libc::ioctl(
                self.file.as_raw_fd(),
                ioctl::PPSETMODE as libc::Ioctl,
                &mode as *const libc::c_int,
            )
        };
        if rc < 0 {
            self.address_mode = None;
            return Err(port_error(
                &self.device,
                "PPSETMODE",
                io::Error::last_os_error(),
            ));
        }
        self.address_mode = Some(address);
        Ok(())
    }

    fn write_byte(&mut self, cycle: CycleKind, byte: u8) -> Result<(), PortError> {
        match self.file.write(&[byte]) {
            Ok(1) => Ok(()),
            Ok(_) => Err(timeout(cycle)),
            Err(e) => Err(transfer_error(&self.device, cycle, e)),
        }
    }
}

impl EppPort for Ppdev {
    fn write_address(&mut self, address: u8) -> Result<(), PortError> {
        self.set_mode(true)?;
        self.write_byte(CycleKind::AddressWrite, address)
    }

    fn read_data(&mut self) -> Result<u8, PortError> {
        self.set_mode(false)?;
        let mut byte = [0u8; 1];
        match self.file.read(&mut byte) {
            Ok(1) => Ok(byte[0]),
            Ok(_) => Err(timeout(CycleKind::DataRead)),
            Err(e) => Err(transfer_error(&self.device, CycleKind::DataRead, e)),
        }
    }

    fn write_data(&mut self, value: u8) -> Result<(), PortError> {
        self.set_mode(false)?;
        self.write_byte(CycleKind::DataWrite, value)
    }
}

impl Drop for Ppdev {
    fn drop(&mut self) {
        // Nothing to do about a failed release in a destructor; closing the
        // file (which follows) releases the port in the kernel as well.
        if ioctl_none(&self.file, ioctl::PPRELEASE).is_err() {}
    }
}

/// Opens the device at `path` for reading and writing, non-blocking (a
/// read or write the card does not answer is a timeout, not a hang); the
/// file and the path as errors name it.
fn open_device(path: &Path) -> Result<(File, String), PortError> {
    let device = path.display().to_string();
    let file = OpenOptions::new()
        .read(true)
        .write(true)
        .custom_flags(libc::O_NONBLOCK)
        .open(path)
        .map_err(|e| port_error(&device, "open", e))?;
    Ok((file, device))
}

/// The port's hardware modes (`PPGETMODES`, which needs no claim).
fn get_modes(file: &File) -> io::Result<PortModes> {
    let mut modes: libc::c_uint = 0;
    // SAFETY: PPGETMODES writes one `unsigned int` through its pointer
    // argument; `modes` is a live, aligned c_uint for the whole call, and the
    // fd is owned by `file`, open for the call's duration.
    let rc = unsafe {
        libc::ioctl(
            file.as_raw_fd(),
            ioctl::PPGETMODES as libc::Ioctl,
            &mut modes as *mut libc::c_uint,
        )
    };
    if rc < 0 {
        Err(io::Error::last_os_error())
    } else {
        Ok(PortModes::from_bits(modes))
    }
}

/// An argumentless (`_IO`) ppdev ioctl.
fn ioctl_none(file: &File, request: u32) -> io::Result<()> {
    // SAFETY: `request` is one of ppdev's `_IO` requests, which take no
    // argument and touch no user memory; the fd is owned by `file`, open for
    // the call's duration.
    let rc = unsafe { libc::ioctl(file.as_raw_fd(), request as libc::Ioctl) };
    if rc < 0 {
        Err(io::Error::last_os_error())
    } else {
        Ok(())
    }
}

fn timeout(cycle: CycleKind) -> PortError {
    PortError::Timeout {
        cycle,
        register: None,
    }
}

/// A failed read or write: would-block and timeouts are EPP timeouts.
fn transfer_error(device: &str, cycle: CycleKind, e: io::Error) -> PortError {
    match e.raw_os_error() {
        Some(libc::EAGAIN | libc::ETIMEDOUT) => timeout(cycle),
        _ => port_error(
            device,
            match cycle {
                CycleKind::DataRead => "read",
                CycleKind::AddressWrite | CycleKind::DataWrite => "write",
            },
            e,
        ),
    }
}
