//! What a parallel port can do ([`PortModes`]) and what a failed `ppdev`
//! step means, as pure functions of the step and the OS error, so every
//! message is tested without hardware.

use std::fmt;
use std::io;

use super::ioctl;
use crate::hw::PortError;

/// Every `PARPORT_MODE_*` bit of `linux/parport.h`.
const KNOWN: u32 = ioctl::PARPORT_MODE_PCSPP
    | ioctl::PARPORT_MODE_TRISTATE
    | ioctl::PARPORT_MODE_EPP
    | ioctl::PARPORT_MODE_ECP
    | ioctl::PARPORT_MODE_COMPAT
    | ioctl::PARPORT_MODE_DMA
    | ioctl::PARPORT_MODE_SAFEININT;

/// A port's hardware modes: the `PARPORT_MODE_*` bits that `PPGETMODES`
/// reports (`linux/parport.h`), decoded, as the kernel logs them when it
/// finds the port (`parport0: PC-style at 0x378, … [PCSPP,TRISTATE,COMPAT,EPP,ECP]`).
///
/// # Examples
///
/// ```
/// use ctrlab::hw::PortModes;
/// let modes = PortModes::from_bits(0x1f); // a typical on-board port, set to EPP+ECP
/// assert!(modes.epp && modes.ecp && !modes.dma);
/// assert_eq!(modes.to_string(), "PCSPP,TRISTATE,EPP,ECP,COMPAT");
/// assert_eq!(PortModes::from_bits(0).to_string(), "none");
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct PortModes {
    /// `PCSPP`: the IBM PC registers are there (a PC-style port).
    pub pcspp: bool,
    /// `TRISTATE`: the data lines can be turned round (bidirectional).
    pub tristate: bool,
    /// `EPP`: hardware EPP, which the card needs.
    pub epp: bool,
    /// `ECP`: hardware ECP (an ECP port's EPP is its mode 4).
    pub ecp: bool,
    /// `COMPAT`: the hardware does the printer protocol by itself.
    pub compat: bool,
    /// `DMA`: the port can use DMA.
    pub dma: bool,
    /// `SAFEININT`: the SPP registers may be accessed in an interrupt.
    pub safe_in_interrupt: bool,
    /// Bits this crate does not know (none in `linux/parport.h` today).
    pub unknown: u32,
}

impl PortModes {
    /// The modes from `PPGETMODES`' bits.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::{PortModes, ioctl};
    /// assert!(PortModes::from_bits(ioctl::PARPORT_MODE_EPP).epp);
    /// assert_eq!(PortModes::from_bits(0x100).unknown, 0x100);
    /// ```
    pub fn from_bits(bits: u32) -> Self {
        let has = |bit: u32| bits & bit != 0;
        Self {
            pcspp: has(ioctl::PARPORT_MODE_PCSPP),
            tristate: has(ioctl::PARPORT_MODE_TRISTATE),
            epp: has(ioctl::PARPORT_MODE_EPP),
            ecp: has(ioctl::PARPORT_MODE_ECP),
            compat: has(ioctl::PARPORT_MODE_COMPAT),
            dma: has(ioctl::PARPORT_MODE_DMA),
            safe_in_interrupt: has(ioctl::PARPORT_MODE_SAFEININT),
            unknown: bits & !KNOWN,
        }
    }

    /// The known modes and the kernel's names for them, in bit order.
    fn named(self) -> [(bool, &'static str); 7] {
        [
            (self.pcspp, "PCSPP"),
            (self.tristate, "TRISTATE"),
            (self.epp, "EPP"),
            (self.ecp, "ECP"),
            (self.compat, "COMPAT"),
            (self.dma, "DMA"),
            (self.safe_in_interrupt, "SAFEININT"),
        ]
    }

    /// The bits again (the inverse of [`from_bits`](Self::from_bits)).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::PortModes;
    /// assert_eq!(PortModes::from_bits(0x145).bits(), 0x145);
    /// ```
    pub fn bits(self) -> u32 {
        self.named()
            .iter()
            .enumerate()
            .filter(|(_, (set, _))| *set)
            .fold(self.unknown, |bits, (i, _)| bits | 1 << i)
    }
}

/// The kernel's names, comma-separated in bit order; unknown bits in hex;
/// `none` for no bit.
impl fmt::Display for PortModes {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mut names: Vec<String> = self
            .named()
            .iter()
            .filter(|(set, _)| *set)
            .map(|(_, name)| (*name).to_owned())
            .collect();
        if self.unknown != 0 {
            names.push(format!("{:#x}", self.unknown));
        }
        if names.is_empty() {
            f.write_str("none")
        } else {
            f.write_str(&names.join(","))
        }
    }
}

/// Refuses a port without hardware EPP, saying what to check.
pub(super) fn require_epp(device: &str, modes: PortModes) -> Result<(), PortError> {
    if modes.epp {
        return Ok(());
    }
    Err(PortError::NotPresent {
        device: device.to_owned(),
        reason: format!(
            "the port has no hardware EPP (PPGETMODES: {modes}). Likely causes: the BIOS \
             setup has the parallel port in SPP, bidirectional or ECP mode, not EPP or \
             EPP+ECP (often under Super I/O or onboard devices); the port is on a PCIe card \
             or a USB adapter without EPP (USB printer adapters have none); the kernel lacks \
             IEEE 1284 support (CONFIG_PARPORT_1284). Without hardware EPP, ppdev falls back \
             to EPP emulated in software through the control lines, far too slow for a \
             2 ms loop, so the port is refused"
        ),
    })
}

/// Maps a failed `ppdev` step (`"open"`, `"PPEXCL"`, `"PPCLAIM"`,
/// `"read"`, …) and its OS error to the [`PortError`] that says what is
/// wrong and what to do.
pub(super) fn port_error(device: &str, operation: &'static str, error: io::Error) -> PortError {
    let errno = error.raw_os_error();
    let claiming = matches!(operation, "PPEXCL" | "PPCLAIM");
    match errno {
        Some(libc::EACCES | libc::EPERM) => PortError::Permission {
            device: device.to_owned(),
            source: error,
        },
        Some(libc::ENXIO | libc::EBUSY) if claiming => PortError::Busy {
            device: device.to_owned(),
            reason: format!(
                "{operation} failed ({error}), so the port cannot be had exclusively. Most \
                 likely the printer driver `lp` holds it (loaded for CUPS and other \
                 printing): free it with `sudo systemctl stop cups` and `sudo rmmod lp`, and \
                 keep it from coming back with `blacklist lp` in a file in /etc/modprobe.d/ \
                 and `lp` taken out of /etc/modules and /etc/modules-load.d/*.conf (which \
                 load it by name). A program with {device} open holds it too: \
                 `sudo fuser -v {device}` names it. (ENXIO can also mean no port is behind \
                 {device}: see `dmesg | grep parport`.)"
            ),
        },
        Some(libc::ENOENT | libc::ENODEV | libc::ENXIO) => PortError::NotPresent {
            device: device.to_owned(),
            reason: format!(
                "{operation}: {error}. Load the parallel-port drivers \
                 (`sudo modprobe parport_pc ppdev`), then look for the port with \
                 `ls /dev/parport*` and `dmesg | grep parport`"
            ),
        },
        _ => PortError::Io {
            device: device.to_owned(),
            operation,
            source: error,
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hw::PortErrorKind;

    const PORT: &str = "/dev/parport0";

    fn error(operation: &'static str, errno: i32) -> PortError {
        port_error(PORT, operation, io::Error::from_raw_os_error(errno))
    }

    /// Checks `e` is of `kind` and its message says every one of `hints`.
    fn says(e: &PortError, kind: PortErrorKind, hints: &[&str]) {
        assert_eq!(e.kind(), kind, "{e}");
        let text = e.to_string();
        for hint in hints {
            assert!(text.contains(hint), "{hint} missing from: {text}");
        }
    }

    #[test]
    fn another_driver_holding_the_port_says_how_to_free_it() {
        let hints = [
            PORT,
            "`lp`",
            "sudo rmmod lp",
            "cups",
            "blacklist lp",
            "/etc/modprobe.d",
            "fuser",
        ];
        for operation in ["PPEXCL", "PPCLAIM"] {
            for errno in [libc::ENXIO, libc::EBUSY] {
                says(&error(operation, errno), PortErrorKind::Busy, &hints);
                says(&error(operation, errno), PortErrorKind::Busy, &[operation]);
            }
        }
    }

    #[test]
    fn no_permission_explains_the_lp_group() {
        let hints = [PORT, "`lp` group", "sudo usermod -aG lp $USER", "log out"];
        for operation in ["open", "PPCLAIM"] {
            for errno in [libc::EACCES, libc::EPERM] {
                says(&error(operation, errno), PortErrorKind::Permission, &hints);
            }
        }
    }

    #[test]
    fn no_such_port_says_how_to_load_the_drivers() {
        for (operation, errno) in [
            ("open", libc::ENOENT),
            ("open", libc::ENODEV),
            ("open", libc::ENXIO),
            ("PPGETMODES", libc::ENODEV),
        ] {
            let hints = [operation, "modprobe parport_pc ppdev"];
            says(&error(operation, errno), PortErrorKind::NotPresent, &hints);
        }
    }

    #[test]
    fn anything_else_is_an_io_error_naming_the_step() {
        let hints = ["PPEXCL on /dev/parport0"];
        says(&error("PPEXCL", libc::ENOTTY), PortErrorKind::Io, &hints);
        says(&error("read", libc::EIO), PortErrorKind::Io, &["read"]);
    }

    #[test]
    fn a_port_without_hardware_epp_lists_the_likely_causes() {
        // An on-board port left in the BIOS's default "ECP" mode.
        let hints = [
            "PCSPP,TRISTATE,ECP,COMPAT",
            "BIOS",
            "EPP+ECP",
            "PCIe",
            "USB",
            "CONFIG_PARPORT_1284",
            "software",
            "too slow",
        ];
        let e = require_epp(PORT, PortModes::from_bits(0x1b)).unwrap_err();
        says(&e, PortErrorKind::NotPresent, &hints);
        assert!(require_epp(PORT, PortModes::from_bits(0x1f)).is_ok());
    }

    #[test]
    fn modes_decode_every_bit_of_linux_parport_h() {
        let all = PortModes::from_bits(0x7f);
        assert_eq!(
            all,
            PortModes {
                pcspp: true,
                tristate: true,
                epp: true,
                ecp: true,
                compat: true,
                dma: true,
                safe_in_interrupt: true,
                unknown: 0,
            }
        );
        assert_eq!(
            all.to_string(),
            "PCSPP,TRISTATE,EPP,ECP,COMPAT,DMA,SAFEININT"
        );
        for bits in [0, 0x01, 0x04, 0x1f, 0x40, 0x7f, 0x104, 0xffff_ffff] {
            assert_eq!(PortModes::from_bits(bits).bits(), bits, "{bits:#x}");
        }
        assert_eq!(PortModes::from_bits(0x104).to_string(), "EPP,0x100");
    }
}
