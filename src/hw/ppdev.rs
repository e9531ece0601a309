//! [`Ppdev`]: the real parallel port through Linux's `ppdev` driver
//! (`/dev/parportN`), in IEEE 1284 EPP mode. Feature `ppdev`, Linux only.
//!
//! One of the crate's three places with `unsafe` code, the `ioctl` calls
//! (the others: `hw::realtime`'s scheduler calls and the one signal-handler
//! registration in `hw::stop`). Reads and writes go through `std::fs::File`.
#![allow(unsafe_code)]

use std::ffi::{c_int, c_uchar, c_uint};
use std::fs::{File, OpenOptions};
use std::io::{self, Read, Write};
use std::os::fd::AsRawFd;
use std::os::unix::fs::OpenOptionsExt;
use std::path::Path;

use super::{CycleKind, EppPort, PortError, PpdevOptions};

mod diagnosis;

pub use diagnosis::PortModes;
use diagnosis::{port_error, require_epp};

pub mod ioctl;

/// A Linux parallel port in EPP mode through `ppdev`.
///
/// [`open`](Self::open) opens `/dev/parportN` non-blocking, registers
/// exclusively (`PPEXCL`), claims the port (`PPCLAIM`), checks the hardware
/// has EPP (`PPGETMODES`), selects EPP data cycles (`PPSETMODE`) and sets
/// the control register's bits 0–3 for EPP ([`ioctl::EPP_CONTROL`],
/// `PPWCONTROL`). Address cycles switch the mode to EPP | `IEEE1284_ADDR`
/// and back (only when the cycle kind changes). With
/// [`PpdevOptions::data_dir`], each data read is bracketed by `PPDATADIR`
/// (reverse before, forward after). There is no `PPNEGOT`: the card is not
/// an IEEE 1284 peripheral that negotiates.
///
/// # Closing without a reset pulse
///
/// [`close`](Self::close), and dropping the port, set the mode to
/// compatibility (`PPSETMODE` with [`ioctl::IEEE1284_MODE_COMPAT`]) and
/// then release the port (`PPRELEASE`). Left in EPP mode, the kernel would
/// end EPP itself when the file closes ("negotiated back to compatibility
/// mode because user-space forgot"): the IEEE 1284 termination from EPP
/// drives nInit — EPP's nReset, which resets the card — low for 50 µs,
/// on every close. `PPSETMODE` only records the mode and drives no line,
/// so the port closes with nInit high. (`PPNEGOT` to compatibility mode
/// would not do: it runs that same termination, and its reset pulse.)
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
/// 44 system calls (60 with [`PpdevOptions::data_dir`]: two `PPDATADIR`
/// per byte read). No batching saves any without auto-increment (see
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
    port: Port<File>,
}

impl Ppdev {
    /// Opens and claims `path` (e.g. `/dev/parport0`) in EPP mode, with the
    /// default [`PpdevOptions`] ([`open_with`](Self::open_with)).
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
        Self::open_with(path, PpdevOptions::default())
    }

    /// Opens and claims `path` in EPP mode, driving it as `options` says
    /// (a card file's `[port]` table, `lab::RigConfig::port`).
    ///
    /// # Errors
    ///
    /// As [`open`](Self::open).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::{PortErrorKind, Ppdev, PpdevOptions};
    /// let options = PpdevOptions { data_dir: true };
    /// let err = Ppdev::open_with("/dev/nonexistent", options).unwrap_err();
    /// assert_eq!(err.kind(), PortErrorKind::NotPresent);
    /// ```
    pub fn open_with(path: impl AsRef<Path>, options: PpdevOptions) -> Result<Self, PortError> {
        let (file, device) = open_device(path.as_ref())?;
        Ok(Self {
            port: Port::open(file, device, options)?,
        })
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
        let (mut file, device) = open_device(path.as_ref())?;
        file.ioctl(Request::GetModes)
            .map(PortModes::from_bits)
            .map_err(|e| port_error(&device, Request::GetModes.name(), e))
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
        self.port.modes
    }

    /// How the port is driven (as opened).
    ///
    /// # Examples
    ///
    /// ```no_run
    /// use ctrlab::hw::{Ppdev, PpdevOptions};
    /// let port = Ppdev::open_with("/dev/parport0", PpdevOptions { data_dir: true })?;
    /// assert!(port.options().data_dir);
    /// # Ok::<(), ctrlab::hw::PortError>(())
    /// ```
    pub fn options(&self) -> PpdevOptions {
        self.port.options
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
        &self.port.device
    }

    /// Closes the port as dropping it does — data lines forward, mode set
    /// to compatibility (`PPSETMODE`), released (`PPRELEASE`), without the
    /// kernel's nInit pulse (see [the type docs](Self#closing-without-a-reset-pulse))
    /// — and says whether each step succeeded. Every step is tried, even
    /// after one fails.
    ///
    /// # Errors
    ///
    /// The first failed step's [`PortError`], naming its ioctl.
    ///
    /// # Examples
    ///
    /// ```no_run
    /// use ctrlab::hw::Ppdev;
    /// let port = Ppdev::open("/dev/parport0")?;
    /// assert!(port.close().is_ok());
    /// # Ok::<(), ctrlab::hw::PortError>(())
    /// ```
    pub fn close(mut self) -> Result<(), PortError> {
        self.port.close()
    }
}

impl EppPort for Ppdev {
    fn write_address(&mut self, address: u8) -> Result<(), PortError> {
        self.port.write_address(address)
    }

    fn read_data(&mut self) -> Result<u8, PortError> {
        self.port.read_data()
    }

    fn write_data(&mut self, value: u8) -> Result<(), PortError> {
        self.port.write_data(value)
    }
}

/// One `ppdev` ioctl this driver makes, with its argument.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Request {
    /// `PPEXCL`.
    Excl,
    /// `PPCLAIM`.
    Claim,
    /// `PPGETMODES`.
    GetModes,
    /// `PPSETMODE` with this mode.
    SetMode(c_int),
    /// `PPWCONTROL` with these control bits (0–3).
    WriteControl(c_uchar),
    /// `PPDATADIR`: `true` reverse (the card drives the data lines),
    /// `false` forward.
    DataDir(bool),
    /// `PPRELEASE`.
    Release,
}

impl Request {
    /// The ioctl's name, as errors name the failed step.
    fn name(self) -> &'static str {
        match self {
            Self::Excl => "PPEXCL",
            Self::Claim => "PPCLAIM",
            Self::GetModes => "PPGETMODES",
            Self::SetMode(_) => "PPSETMODE",
            Self::WriteControl(_) => "PPWCONTROL",
            Self::DataDir(_) => "PPDATADIR",
            Self::Release => "PPRELEASE",
        }
    }
}

/// What the driver does to the device: ioctls, one-byte reads and writes.
/// A `File` on `/dev/parportN`; in the unit tests a recorder, so the order
/// of the steps is tested without a port.
trait Device {
    /// Makes the ioctl: `PPGETMODES`' bits, 0 for the others.
    fn ioctl(&mut self, request: Request) -> io::Result<c_uint>;
    /// One EPP read (data or address, as the mode says).
    fn read_byte(&mut self, byte: &mut [u8; 1]) -> io::Result<usize>;
    /// One EPP write (data or address, as the mode says).
    fn write_byte(&mut self, byte: u8) -> io::Result<usize>;
}

impl Device for File {
    fn ioctl(&mut self, request: Request) -> io::Result<c_uint> {
        let fd = self.as_raw_fd();
        let rc = match request {
            Request::Excl => ioctl_none(fd, ioctl::PPEXCL),
            Request::Claim => ioctl_none(fd, ioctl::PPCLAIM),
            Request::Release => ioctl_none(fd, ioctl::PPRELEASE),
            Request::GetModes => {
                let mut modes: c_uint = 0;
                // SAFETY: PPGETMODES writes one `unsigned int` through its
                // pointer argument; `modes` is a live, aligned c_uint for the
                // whole call, and `fd` is owned by `self`, open for the call.
                let rc = unsafe {
                    libc::ioctl(
                        fd,
                        ioctl::PPGETMODES as libc::Ioctl,
                        &mut modes as *mut c_uint,
                    )
                };
                return if rc < 0 {
                    Err(io::Error::last_os_error())
                } else {
                    Ok(modes)
                };
            }
            Request::SetMode(mode) => {
                // SAFETY: PPSETMODE reads one `int` through its pointer
                // argument; `mode` is a live, aligned c_int for the whole
                // call, and `fd` is owned by `self`, open for the call.
                unsafe { libc::ioctl(fd, ioctl::PPSETMODE as libc::Ioctl, &mode as *const c_int) }
            }
            Request::WriteControl(value) => {
                // SAFETY: PPWCONTROL reads one `unsigned char` through its
                // pointer argument; `value` is a live c_uchar for the whole
                // call, and `fd` is owned by `self`, open for the call.
                unsafe {
                    libc::ioctl(
                        fd,
                        ioctl::PPWCONTROL as libc::Ioctl,
                        &value as *const c_uchar,
                    )
                }
            }
            Request::DataDir(reverse) => {
                let direction: c_int = reverse.into();
                // SAFETY: PPDATADIR reads one `int` through its pointer
                // argument; `direction` is a live, aligned c_int for the
                // whole call, and `fd` is owned by `self`, open for the call.
                unsafe {
                    libc::ioctl(
                        fd,
                        ioctl::PPDATADIR as libc::Ioctl,
                        &direction as *const c_int,
                    )
                }
            }
        };
        if rc < 0 {
            Err(io::Error::last_os_error())
        } else {
            Ok(0)
        }
    }

    fn read_byte(&mut self, byte: &mut [u8; 1]) -> io::Result<usize> {
        self.read(byte)
    }

    fn write_byte(&mut self, byte: u8) -> io::Result<usize> {
        self.write(&[byte])
    }
}

/// An argumentless (`_IO`) ppdev ioctl; its return code.
fn ioctl_none(fd: std::os::fd::RawFd, request: u32) -> c_int {
    // SAFETY: `request` is one of ppdev's `_IO` requests, which take no
    // argument and touch no user memory; `fd` is an open descriptor its
    // caller owns for the call's duration.
    unsafe { libc::ioctl(fd, request as libc::Ioctl) }
}

/// The driver over any [`Device`]: the mode and direction it left the port
/// in, and whether it still holds the port.
#[derive(Debug)]
struct Port<D: Device> {
    dev: D,
    device: String,
    modes: PortModes,
    options: PpdevOptions,
    /// `Some(true)` in address mode, `Some(false)` in data mode.
    address_mode: Option<bool>,
    /// The data lines turned round (`PPDATADIR` 1) and not yet back.
    reversed: bool,
    /// Claimed and not yet released: what closing has to undo.
    claimed: bool,
}

impl<D: Device> Port<D> {
    /// Registers exclusively, claims, checks for EPP, selects EPP data
    /// cycles and writes the control bits. Once claimed, a failure closes
    /// the port again (dropping it).
    fn open(mut dev: D, device: String, options: PpdevOptions) -> Result<Self, PortError> {
        for request in [Request::Excl, Request::Claim] {
            dev.ioctl(request)
                .map_err(|e| port_error(&device, request.name(), e))?;
        }
        let mut port = Self {
            dev,
            device,
            modes: PortModes::default(),
            options,
            address_mode: None,
            reversed: false,
            claimed: true,
        };
        port.modes = PortModes::from_bits(port.step(Request::GetModes)?);
        require_epp(&port.device, port.modes)?;
        port.set_mode(false)?;
        port.step(Request::WriteControl(ioctl::EPP_CONTROL))?;
        Ok(port)
    }

    /// One ioctl, its failure named.
    fn step(&mut self, request: Request) -> Result<c_uint, PortError> {
        self.dev
            .ioctl(request)
            .map_err(|e| port_error(&self.device, request.name(), e))
    }

    /// Selects EPP address (`true`) or data (`false`) cycles, if not already.
    fn set_mode(&mut self, address: bool) -> Result<(), PortError> {
        if self.address_mode == Some(address) {
            return Ok(());
        }
        let mode = if address {
            ioctl::IEEE1284_MODE_EPP | ioctl::IEEE1284_ADDR
        } else {
            ioctl::IEEE1284_MODE_EPP
        };
        self.address_mode = None;
        self.step(Request::SetMode(mode))?;
        self.address_mode = Some(address);
        Ok(())
    }

    /// Data lines forward (the PC drives them), if a read left them
    /// reversed.
    fn forward(&mut self) -> Result<(), PortError> {
        if self.reversed {
            self.step(Request::DataDir(false))?;
            self.reversed = false;
        }
        Ok(())
    }

    fn write_byte(&mut self, cycle: CycleKind, byte: u8) -> Result<(), PortError> {
        self.forward()?;
        match self.dev.write_byte(byte) {
            Ok(1) => Ok(()),
            Ok(_) => Err(timeout(cycle)),
            Err(e) => Err(transfer_error(&self.device, cycle, e)),
        }
    }

    fn write_address(&mut self, address: u8) -> Result<(), PortError> {
        self.set_mode(true)?;
        self.write_byte(CycleKind::AddressWrite, address)
    }

    fn write_data(&mut self, value: u8) -> Result<(), PortError> {
        self.set_mode(false)?;
        self.write_byte(CycleKind::DataWrite, value)
    }

    /// One data read; with [`PpdevOptions::data_dir`], the data lines
    /// reversed before it and forward again after it, even when it fails.
    fn read_data(&mut self) -> Result<u8, PortError> {
        self.set_mode(false)?;
        if self.options.data_dir {
            self.reversed = true;
            self.step(Request::DataDir(true))?;
        }
        let mut byte = [0u8; 1];
        let read = match self.dev.read_byte(&mut byte) {
            Ok(1) => Ok(byte[0]),
            Ok(_) => Err(timeout(CycleKind::DataRead)),
            Err(e) => Err(transfer_error(&self.device, CycleKind::DataRead, e)),
        };
        let forward = self.forward();
        let byte = read?;
        forward?;
        Ok(byte)
    }

    /// Data lines forward, compatibility mode recorded (`PPSETMODE`, no
    /// line driven), released: every step tried; the first failure.
    fn close(&mut self) -> Result<(), PortError> {
        if !self.claimed {
            return Ok(());
        }
        self.claimed = false;
        let forward = self.forward();
        self.address_mode = None;
        let compat = self.step(Request::SetMode(ioctl::IEEE1284_MODE_COMPAT));
        let release = self.step(Request::Release);
        forward.and(compat).and(release).map(drop)
    }
}

impl<D: Device> Drop for Port<D> {
    fn drop(&mut self) {
        // Nothing to do about a failed step in a destructor; closing the
        // file (which follows) releases the port in the kernel as well.
        if self.close().is_err() {}
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

#[cfg(test)]
mod tests;
