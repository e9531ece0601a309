//! What a parallel port can do ([`PortModes`]) and what a failed `ppdev`
//! step means, as pure functions of the step and the OS error, so every
//! message is tested without hardware.

use std::fmt;
use std::io;

use super::ioctl;
use crate::hw::HwError;

/// A port's hardware modes: the `PARPORT_MODE_*` bits that `PPGETMODES`
/// reports (`linux/parport.h`), as the kernel logs them when it finds the
/// port (`parport0: PC-style at 0x378, … [PCSPP,TRISTATE,COMPAT,EPP,ECP]`).
///
/// # Examples
///
/// ```
/// use ctrlab::hw::PortModes;
/// let modes = PortModes::from_bits(0x1f); // a typical on-board port, set to EPP+ECP
/// assert!(modes.epp() && modes.ecp() && !modes.dma());
/// assert_eq!(modes.to_string(), "PCSPP,TRISTATE,EPP,ECP,COMPAT");
/// assert_eq!(PortModes::from_bits(0).to_string(), "none");
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct PortModes {
    bits: u32,
}

/// Each mode's bit and the kernel's name for it, in bit order.
const NAMES: [(u32, &str); 7] = [
    (ioctl::PARPORT_MODE_PCSPP, "PCSPP"),
    (ioctl::PARPORT_MODE_TRISTATE, "TRISTATE"),
    (ioctl::PARPORT_MODE_EPP, "EPP"),
    (ioctl::PARPORT_MODE_ECP, "ECP"),
    (ioctl::PARPORT_MODE_COMPAT, "COMPAT"),
    (ioctl::PARPORT_MODE_DMA, "DMA"),
    (ioctl::PARPORT_MODE_SAFEININT, "SAFEININT"),
];

impl PortModes {
    /// The modes from `PPGETMODES`' bits.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::{PortModes, ioctl};
    /// assert!(PortModes::from_bits(ioctl::PARPORT_MODE_EPP).epp());
    /// ```
    pub const fn from_bits(bits: u32) -> Self {
        Self { bits }
    }

    /// The raw bits.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::PortModes;
    /// assert_eq!(PortModes::from_bits(0x45).bits(), 0x45);
    /// ```
    pub const fn bits(self) -> u32 {
        self.bits
    }

    const fn has(self, bit: u32) -> bool {
        self.bits & bit != 0
    }

    /// `PCSPP`: the IBM PC registers are there (a PC-style port).
    ///
    /// # Examples
    ///
    /// ```
    /// assert!(ctrlab::hw::PortModes::from_bits(0x01).pcspp());
    /// ```
    pub const fn pcspp(self) -> bool {
        self.has(ioctl::PARPORT_MODE_PCSPP)
    }

    /// `TRISTATE`: the data lines can be turned round (bidirectional).
    ///
    /// # Examples
    ///
    /// ```
    /// assert!(ctrlab::hw::PortModes::from_bits(0x02).tristate());
    /// ```
    pub const fn tristate(self) -> bool {
        self.has(ioctl::PARPORT_MODE_TRISTATE)
    }

    /// `EPP`: hardware EPP, which the card needs.
    ///
    /// # Examples
    ///
    /// ```
    /// assert!(!ctrlab::hw::PortModes::from_bits(0x1b).epp());
    /// ```
    pub const fn epp(self) -> bool {
        self.has(ioctl::PARPORT_MODE_EPP)
    }

    /// `ECP`: hardware ECP (an ECP port's EPP is its mode 4).
    ///
    /// # Examples
    ///
    /// ```
    /// assert!(ctrlab::hw::PortModes::from_bits(0x08).ecp());
    /// ```
    pub const fn ecp(self) -> bool {
        self.has(ioctl::PARPORT_MODE_ECP)
    }

    /// `COMPAT`: the hardware does the printer protocol by itself.
    ///
    /// # Examples
    ///
    /// ```
    /// assert!(ctrlab::hw::PortModes::from_bits(0x10).compat());
    /// ```
    pub const fn compat(self) -> bool {
        self.has(ioctl::PARPORT_MODE_COMPAT)
    }

    /// `DMA`: the port can use DMA.
    ///
    /// # Examples
    ///
    /// ```
    /// assert!(ctrlab::hw::PortModes::from_bits(0x20).dma());
    /// ```
    pub const fn dma(self) -> bool {
        self.has(ioctl::PARPORT_MODE_DMA)
    }

    /// `SAFEININT`: the SPP registers may be accessed in an interrupt.
    ///
    /// # Examples
    ///
    /// ```
    /// assert!(ctrlab::hw::PortModes::from_bits(0x40).safe_in_interrupt());
    /// ```
    pub const fn safe_in_interrupt(self) -> bool {
        self.has(ioctl::PARPORT_MODE_SAFEININT)
    }
}

/// The kernel's names, comma-separated in bit order; unknown bits in hex;
/// `none` for no bit.
impl fmt::Display for PortModes {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mut names: Vec<String> = NAMES
            .iter()
            .filter(|(bit, _)| self.has(*bit))
            .map(|(_, name)| (*name).to_owned())
            .collect();
        let known = NAMES.iter().fold(0, |all, (bit, _)| all | bit);
        if self.bits & !known != 0 {
            names.push(format!("{:#x}", self.bits & !known));
        }
        if names.is_empty() {
            f.write_str("none")
        } else {
            f.write_str(&names.join(","))
        }
    }
}

/// Refuses a port without hardware EPP, saying what to check.
pub(super) fn require_epp(device: &str, modes: PortModes) -> Result<(), HwError> {
    if modes.epp() {
        return Ok(());
    }
    Err(HwError::NotPresent {
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
/// `"read"`, …) and its OS error to the [`HwError`] that says what is
/// wrong and what to do.
pub(super) fn port_error(device: &str, operation: &'static str, error: io::Error) -> HwError {
    let errno = error.raw_os_error();
    let claiming = matches!(operation, "PPEXCL" | "PPCLAIM");
    match errno {
        Some(libc::EACCES | libc::EPERM) => HwError::Permission {
            device: device.to_owned(),
            source: error,
        },
        Some(libc::ENXIO | libc::EBUSY) if claiming => HwError::Busy {
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
        Some(libc::ENOENT | libc::ENODEV | libc::ENXIO) => HwError::NotPresent {
            device: device.to_owned(),
            reason: format!(
                "{operation}: {error}. Load the parallel-port drivers \
                 (`sudo modprobe parport_pc ppdev`), then look for the port with \
                 `ls /dev/parport*` and `dmesg | grep parport`"
            ),
        },
        _ => HwError::Io {
            device: device.to_owned(),
            operation,
            source: error,
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hw::HwErrorKind;

    const PORT: &str = "/dev/parport0";

    fn error(operation: &'static str, errno: i32) -> HwError {
        port_error(PORT, operation, io::Error::from_raw_os_error(errno))
    }

    #[test]
    fn another_driver_holding_the_port_says_how_to_free_it() {
        for (operation, errno) in [
            ("PPEXCL", libc::ENXIO),
            ("PPCLAIM", libc::ENXIO),
            ("PPCLAIM", libc::EBUSY),
            ("PPEXCL", libc::EBUSY),
        ] {
            let e = error(operation, errno);
            assert_eq!(e.kind(), HwErrorKind::Busy, "{operation} {errno}");
            let text = e.to_string();
            for hint in [
                PORT,
                operation,
                "`lp`",
                "sudo rmmod lp",
                "cups",
                "blacklist lp",
                "/etc/modprobe.d",
                "fuser",
            ] {
                assert!(text.contains(hint), "{hint} missing from: {text}");
            }
        }
    }

    #[test]
    fn no_permission_explains_the_lp_group() {
        for operation in ["open", "PPCLAIM"] {
            for errno in [libc::EACCES, libc::EPERM] {
                let e = error(operation, errno);
                assert_eq!(e.kind(), HwErrorKind::Permission);
                let text = e.to_string();
                for hint in [PORT, "`lp` group", "sudo usermod -aG lp $USER", "log out"] {
                    assert!(text.contains(hint), "{hint} missing from: {text}");
                }
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
            let e = error(operation, errno);
            assert_eq!(e.kind(), HwErrorKind::NotPresent, "{operation} {errno}");
            let text = e.to_string();
            assert!(text.contains(operation) && text.contains("modprobe parport_pc ppdev"));
        }
    }

    #[test]
    fn anything_else_is_an_io_error_naming_the_step() {
        let e = error("PPEXCL", libc::ENOTTY);
        assert_eq!(e.kind(), HwErrorKind::Io);
        assert!(e.to_string().contains("PPEXCL on /dev/parport0"), "{e}");
        assert_eq!(error("read", libc::EIO).kind(), HwErrorKind::Io);
    }

    #[test]
    fn a_port_without_hardware_epp_lists_the_likely_causes() {
        // An on-board port left in the BIOS's default "ECP" mode.
        let modes = PortModes::from_bits(0x1b);
        let e = require_epp(PORT, modes).unwrap_err();
        assert_eq!(e.kind(), HwErrorKind::NotPresent);
        let text = e.to_string();
        for hint in [
            "PCSPP,TRISTATE,ECP,COMPAT",
            "BIOS",
            "EPP+ECP",
            "PCIe",
            "USB",
            "CONFIG_PARPORT_1284",
            "software",
            "too slow",
        ] {
            assert!(text.contains(hint), "{hint} missing from: {text}");
        }
        assert!(require_epp(PORT, PortModes::from_bits(0x1f)).is_ok());
    }

    #[test]
    fn modes_decode_every_bit_of_linux_parport_h() {
        let all = PortModes::from_bits(0x7f);
        assert!(
            all.pcspp()
                && all.tristate()
                && all.epp()
                && all.ecp()
                && all.compat()
                && all.dma()
                && all.safe_in_interrupt()
        );
        assert_eq!(
            all.to_string(),
            "PCSPP,TRISTATE,EPP,ECP,COMPAT,DMA,SAFEININT"
        );
        for (i, (bit, _)) in NAMES.iter().enumerate() {
            assert_eq!(*bit, 1 << i);
        }
        assert_eq!(PortModes::from_bits(0x104).to_string(), "EPP,0x100");
    }
}
