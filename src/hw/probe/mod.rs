//! Bringing up a card: [`Probe`] confirms a card's register map — or,
//! only when asked, finds one blind — with its encoder signs, motor
//! polarity and watchdog, on a live port, one step at a time, each step
//! saying what it does before doing it.
//!
//! # By default: confirm the map you give
//!
//! Take the register map from the lab's existing driver or the FPGA's
//! sources (a card file's `[map]`, [`ProbeOptions::map`]). The probe then
//! touches **no address outside that map** — not even to read:
//!
//! 1. **ID** ([`Probe::check_id`]): the map's ID register, read twice,
//!    must read a constant (the card file's `card_id`, when given). A
//!    wrong map or no card stops here, before any write.
//! 2. **Encoders** ([`Probe::check_encoders`]): with the motor supply
//!    *off* (the operator confirms), the user moves each cart by hand while
//!    the probe latches the map's counters and reads them: which counter
//!    follows each cart, and its sign (the user holds the cart away from
//!    the wall); then the map's clear bit must zero them.
//! 3. **Drive** ([`Probe::check_drive`]): only after the operator confirms
//!    (motor supply on, e-stop at hand), pulses of about 5 %, then 10 and
//!    12 % duty for 0.15 s on the map's PWM channels in turn until a cart
//!    moves, kicking with the map's watchdog bit, checking that positive
//!    duty moves it away from the wall.
//! 4. **Watchdog** ([`Probe::check_watchdog`]): whether a PWM write is
//!    still obeyed after a silence of T without a kick, bisected to the
//!    timeout.
//!
//! # Only with `scan`: the blind scan
//!
//! With [`ProbeOptions::scan`] the probe assumes only the card's *kind*
//! (EPP registers; 32-bit counters latched by a bit of a control register;
//! 10-bit PWM duties in a low and a high byte, the high byte applying the
//! duty, as [`RegisterMap`] documents) and finds *where* everything is:
//! [`Probe::scan`] (two read-only scans of all 256 addresses),
//! [`Probe::find_encoders`] (the latch found by writing test patterns to
//! write-only addresses), [`Probe::find_drive`] (PWM duties written to
//! pairs of them), [`Probe::find_watchdog`]. **It writes to addresses no
//! map describes, which on an FPGA can hit configuration registers**: see
//! [`ProbeOptions::scan`]. Channels without a cart or motor on them
//! cannot be observed; the map places them by the stride of the ones found
//! (say so, in [`ProbeReport::notes`]).
//!
//! # Stopping
//!
//! Give the probe a [`StopSignal`] ([`Probe::with_stop`], from
//! [`StopSignal::on_interrupt`] in a program): it is looked at after every
//! wait, pulses included, and a stop — like any error — zeroes the PWM the
//! probe drove before the step returns ([`ProbeError::Interrupted`]).
//!
//! The probe talks to the world through an [`Operator`]: a console (the
//! `probe` example) or a simulated hand
//! ([`lab::SimulatedOperator`](crate::lab::SimulatedOperator)), with which
//! the probe confirms, or rediscovers, the simulated card's map.
//!
//! Software must not be trusted for safety: keep a hardware e-stop within
//! reach whenever the motor supply is on.

mod check;
mod drive;
mod encoders;
mod error;
mod operator;
mod options;
mod report;
mod scan;

pub use error::ProbeError;
pub use operator::{Hands, Operator};
pub use options::ProbeOptions;
pub use report::{Counter, Drive, Latch, ProbeReport};
pub use scan::{OPEN_BUS, RegisterClass, Scan, Snapshot};

use super::{ConfigError, EppPort, PortError, RegisterMap, StopSignal};

/// The bring-up probe on a port, step by step (see the [module
/// docs](self)). [`run`](Self::run) takes every step in order: the map's
/// check by default, the blind scan with [`ProbeOptions::scan`].
///
/// # Examples
///
/// The simulated card, probed by a simulated hand that answers "yes" twice,
/// confirms the map it is given, touching no other address; the blind
/// scan finds the same map:
///
/// ```
/// use ctrlab::hw::probe::{Probe, ProbeOptions};
/// use ctrlab::hw::{Clock, VirtualClock};
/// use ctrlab::lab::{SimulatedOperator, SimulatedRig};
///
/// let rig = SimulatedRig::default();
/// for scan in [false, true] {
///     let clock = VirtualClock::new();
///     let card = rig.card(&Clock::Virtual(clock.clone()))?;
///     let hand = SimulatedOperator::new(clock, [true, true]);
///     let options = ProbeOptions { scan, map: rig.card.map, ..Default::default() };
///     let mut probe = Probe::new(card, hand, options)?;
///     let report = probe.run()?;
///     assert_eq!(report.map, rig.card.map);
///     assert_eq!(report.watchdog_timeout, Some(0.1));
/// }
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug)]
pub struct Probe<P, O> {
    port: P,
    operator: O,
    options: ProbeOptions,
    scan: Option<Scan>,
    id: Option<(u8, u8)>,
    latch: Option<Latch>,
    counters: Option<[Counter; 2]>,
    drive: Option<Drive>,
    watchdog: Option<(u8, Option<f64>)>,
    /// Cart 1's and cart 2's encoder channel in the given map (the check).
    channels: Option<[usize; 2]>,
    /// The motor's PWM channel in the given map (the check).
    pwm_channel: Option<usize>,
    /// The PWM register pair written with a duty and not yet zeroed.
    driven: Option<(u8, u8)>,
    /// Looked at after every wait.
    stop: Option<StopSignal>,
    /// The direction of the last watchdog test pulse.
    reverse: bool,
    notes: Vec<String>,
}

impl<P: EppPort, O: Operator<P>> Probe<P, O> {
    /// A probe on `port`, talking to `operator`.
    ///
    /// # Errors
    ///
    /// [`ProbeOptions::validate`]'s.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::probe::{Probe, ProbeOptions};
    /// use ctrlab::hw::testing::RegisterFile;
    /// # use ctrlab::hw::probe::{Hands, Operator};
    /// # struct Nobody;
    /// # impl<P> Operator<P> for Nobody {
    /// #     fn tell(&mut self, _: &str) {}
    /// #     fn confirm(&mut self, _: &str) -> bool { false }
    /// #     fn hands(&mut self, _: Hands) {}
    /// #     fn wait(&mut self, _: &mut P, _: f64) {}
    /// # }
    /// let bad = ProbeOptions { samples: 0, ..Default::default() };
    /// assert!(Probe::new(RegisterFile::new(), Nobody, bad).is_err());
    /// let probe = Probe::new(RegisterFile::new(), Nobody, ProbeOptions::default())?;
    /// let (port, _operator) = probe.into_parts();
    /// assert_eq!(port.get(0), 0);
    /// # Ok::<(), ctrlab::hw::RigError>(())
    /// ```
    pub fn new(port: P, operator: O, options: ProbeOptions) -> Result<Self, ConfigError> {
        options.validate()?;
        Ok(Self {
            port,
            operator,
            options,
            scan: None,
            id: None,
            latch: None,
            counters: None,
            drive: None,
            watchdog: None,
            channels: None,
            pwm_channel: None,
            driven: None,
            stop: None,
            reverse: false,
            notes: Vec::new(),
        })
    }

    /// The probe, stopping at `stop`: after every wait (pulses included)
    /// the probe looks at it, and once it is raised zeroes the PWM it drove
    /// and returns [`ProbeError::Interrupted`]. A program passes
    /// [`StopSignal::on_interrupt`], so Ctrl-C during a pulse cannot leave
    /// duty on.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::StopSignal;
    /// use ctrlab::hw::probe::{Probe, ProbeError, ProbeOptions};
    /// use ctrlab::hw::testing::RegisterFile;
    /// # use ctrlab::hw::probe::{Hands, Operator};
    /// # struct Nobody;
    /// # impl<P> Operator<P> for Nobody {
    /// #     fn tell(&mut self, _: &str) {}
    /// #     fn confirm(&mut self, _: &str) -> bool { false }
    /// #     fn hands(&mut self, _: Hands) {}
    /// #     fn wait(&mut self, _: &mut P, _: f64) {}
    /// # }
    /// let mut card = RegisterFile::new();
    /// card.set(0x00, 0xa5);
    /// let stop = StopSignal::new();
    /// let mut probe = Probe::new(card, Nobody, ProbeOptions::default())?.with_stop(stop.clone());
    /// stop.request(); // as Ctrl-C would
    /// assert!(matches!(probe.check_id(), Err(ProbeError::Interrupted)));
    /// # Ok::<(), ctrlab::hw::RigError>(())
    /// ```
    pub fn with_stop(mut self, stop: StopSignal) -> Self {
        self.stop = Some(stop);
        self
    }

    /// The port.
    ///
    /// # Examples
    ///
    /// The ID check reads the map's ID register, and only it:
    ///
    /// ```
    /// use ctrlab::hw::probe::{Probe, ProbeOptions};
    /// use ctrlab::hw::testing::{Cycle, RecordingPort, RegisterFile};
    /// # use ctrlab::hw::probe::{Hands, Operator};
    /// # struct Nobody;
    /// # impl<P> Operator<P> for Nobody {
    /// #     fn tell(&mut self, _: &str) {}
    /// #     fn confirm(&mut self, _: &str) -> bool { false }
    /// #     fn hands(&mut self, _: Hands) {}
    /// #     fn wait(&mut self, _: &mut P, _: f64) {}
    /// # }
    /// let mut card = RegisterFile::new();
    /// card.set(0x00, 0xa5);
    /// let mut probe = Probe::new(RecordingPort::new(card), Nobody, ProbeOptions::default())?;
    /// probe.check_id()?;
    /// let only_id = |c: &Cycle| matches!(c, Cycle::AddressWrite(0x00) | Cycle::DataRead(0xa5));
    /// assert!(probe.port().log().iter().all(only_id));
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn port(&self) -> &P {
        &self.port
    }

    /// The port, mutable.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::probe::{Probe, ProbeError, ProbeOptions};
    /// use ctrlab::hw::testing::RegisterFile;
    /// # use ctrlab::hw::probe::{Hands, Operator};
    /// # struct Nobody;
    /// # impl<P> Operator<P> for Nobody {
    /// #     fn tell(&mut self, _: &str) {}
    /// #     fn confirm(&mut self, _: &str) -> bool { false }
    /// #     fn hands(&mut self, _: Hands) {}
    /// #     fn wait(&mut self, _: &mut P, _: f64) {}
    /// # }
    /// let mut probe = Probe::new(RegisterFile::new(), Nobody, ProbeOptions::default())?;
    /// assert!(matches!(probe.check_id(), Err(ProbeError::WrongMap { .. }))); // reads 0x00
    /// probe.port_mut().set(0x00, 0xa5); // an ID appears
    /// assert_eq!(probe.check_id()?, 0xa5);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn port_mut(&mut self) -> &mut P {
        &mut self.port
    }

    /// The operator.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::hw::probe::{Probe, ProbeOptions};
    /// # use ctrlab::hw::{Clock, VirtualClock};
    /// # use ctrlab::lab::{SimulatedOperator, SimulatedRig};
    /// # let rig = SimulatedRig::default();
    /// # let clock = VirtualClock::new();
    /// # let card = rig.card(&Clock::Virtual(clock.clone()))?;
    /// let options = ProbeOptions { map: rig.card.map, ..Default::default() };
    /// let mut probe = Probe::new(card, SimulatedOperator::new(clock, [false]), options)?;
    /// probe.check_id()?;
    /// assert!(probe.check_encoders().is_err()); // the hand said no
    /// // It was asked before anything was written.
    /// assert!(probe.operator().transcript.last().unwrap().ends_with(" no"));
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn operator(&self) -> &O {
        &self.operator
    }

    /// The port and the operator back.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::hw::probe::{Probe, ProbeOptions};
    /// # use ctrlab::hw::{Clock, VirtualClock};
    /// # use ctrlab::lab::{SimulatedOperator, SimulatedRig};
    /// # let rig = SimulatedRig::default();
    /// # let clock = VirtualClock::new();
    /// # let card = rig.card(&Clock::Virtual(clock.clone()))?;
    /// let options = ProbeOptions { map: rig.card.map, ..Default::default() };
    /// let mut probe = Probe::new(card, SimulatedOperator::new(clock, [true, true]), options)?;
    /// probe.check_id()?;
    /// let (card, hand) = probe.into_parts();
    /// assert!(hand.transcript[0].starts_with("step 1/4, ID")); // told first
    /// assert_eq!(card.true_state()[0], 0.0); // nothing moved
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn into_parts(self) -> (P, O) {
        (self.port, self.operator)
    }

    /// Takes every step in order and assembles the report: the check of
    /// [`ProbeOptions::map`] ([`check_id`](Self::check_id),
    /// [`check_encoders`](Self::check_encoders),
    /// [`check_drive`](Self::check_drive),
    /// [`check_watchdog`](Self::check_watchdog)) by default, the blind
    /// scan ([`scan`](Self::scan), [`find_encoders`](Self::find_encoders),
    /// [`find_drive`](Self::find_drive),
    /// [`find_watchdog`](Self::find_watchdog)) with
    /// [`ProbeOptions::scan`]. On any error the PWM the probe drove is
    /// zeroed first.
    ///
    /// # Errors
    ///
    /// The first step's that fails; the steps' own docs say which.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::hw::probe::{Probe, ProbeOptions};
    /// # use ctrlab::hw::{Clock, VirtualClock};
    /// # use ctrlab::lab::{SimulatedOperator, SimulatedRig};
    /// # let rig = SimulatedRig::default();
    /// # let clock = VirtualClock::new();
    /// # let card = rig.card(&Clock::Virtual(clock.clone()))?;
    /// let options = ProbeOptions { map: rig.card.map, ..Default::default() };
    /// let mut probe = Probe::new(card, SimulatedOperator::new(clock, [true, true]), options)?;
    /// let report = probe.run()?;
    /// // The map confirmed, and the calibration the rig was built with found.
    /// assert_eq!(report.encoder_channels, rig.calibration.encoder_channels);
    /// assert_eq!(report.signs, rig.calibration.sign);
    /// assert_eq!(report.pwm_channel, rig.calibration.pwm_channel);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn run(&mut self) -> Result<ProbeReport, ProbeError> {
        // A second Ctrl-C during a pulse only raises the flag: the probe
        // zeroes the PWM (see StopSignal::on_interrupt).
        let _running = super::stop::Running::enter();
        let result = self.steps();
        if result.is_err() {
            self.zero_pwm();
        }
        result
    }

    fn steps(&mut self) -> Result<ProbeReport, ProbeError> {
        if self.options.scan {
            self.scan()?;
            self.find_encoders()?;
            self.find_drive()?;
            self.find_watchdog()?;
        } else {
            self.check_id()?;
            self.check_encoders()?;
            self.check_drive()?;
            self.check_watchdog()?;
        }
        self.report()
    }

    /// Step 1 of the blind scan (only with [`ProbeOptions::scan`]): two
    /// read-only scans of all 256 addresses and the card's ID.
    ///
    /// # Errors
    ///
    /// [`ProbeError::ScanNotEnabled`] without [`ProbeOptions::scan`]
    /// (nothing read or written); [`ProbeError::NoCard`] when EPP cycles
    /// time out or no address reads a constant other than `0x00`/`0xff`;
    /// no register is written.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::probe::{Probe, ProbeError, ProbeOptions, RegisterClass};
    /// use ctrlab::hw::testing::RegisterFile;
    /// # use ctrlab::hw::probe::{Hands, Operator};
    /// # struct Nobody;
    /// # impl<P> Operator<P> for Nobody {
    /// #     fn tell(&mut self, _: &str) {}
    /// #     fn confirm(&mut self, _: &str) -> bool { false }
    /// #     fn hands(&mut self, _: Hands) {}
    /// #     fn wait(&mut self, _: &mut P, _: f64) {}
    /// # }
    /// let mut card = RegisterFile::new();
    /// card.set(0x07, 0x3c); // the ID
    /// card.set(0x10, 0xff); // open bus
    /// let blind = ProbeOptions { scan: true, ..Default::default() };
    /// let mut probe = Probe::new(card.clone(), Nobody, ProbeOptions::default())?;
    /// assert!(matches!(probe.scan(), Err(ProbeError::ScanNotEnabled)));
    /// let mut probe = Probe::new(card, Nobody, blind)?;
    /// let scan = probe.scan()?;
    /// assert_eq!(scan.id(), Some((0x07, 0x3c)));
    /// assert_eq!(scan.class(0x10), RegisterClass::Open);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn scan(&mut self) -> Result<&Scan, ProbeError> {
        if !self.options.scan {
            return Err(ProbeError::ScanNotEnabled);
        }
        self.check_stop()?;
        self.operator.tell(
            "step 1/4, scan: reading all 256 addresses twice (read-only), to tell constant, \
             volatile and open-bus registers apart and find the card's ID register",
        );
        let no_card = |e: PortError| match e {
            PortError::Timeout { .. } => ProbeError::NoCard {
                reason: format!("EPP cycles time out ({e})"),
            },
            other => ProbeError::Port(other),
        };
        let first = scan::snapshot(&mut self.port).map_err(no_card)?;
        self.wait(0.05)?;
        let second = scan::snapshot(&mut self.port).map_err(no_card)?;
        let scan = Scan { first, second };
        let Some((address, value)) = scan.id() else {
            let reason = if scan.first.iter().all(|&b| b == scan.first[0]) {
                format!("every address reads {:#04x} (an idle bus)", scan.first[0])
            } else {
                "no address reads a constant other than 0x00 and 0xff (no ID register)".to_owned()
            };
            return Err(ProbeError::NoCard { reason });
        };
        let others: Vec<String> = scan
            .id_candidates()
            .skip(1)
            .map(|(a, v)| format!("{a:#04x} = {v:#04x}"))
            .collect();
        let volatile = scan.addresses(|c| c == RegisterClass::Volatile).count();
        let open = scan.addresses(|c| c == RegisterClass::Open).count();
        self.operator.tell(&format!(
            "  ID register {address:#04x} reads {value:#04x}; {open} open-bus or write-only \
             addresses, {volatile} volatile"
        ));
        if !others.is_empty() {
            self.notes.push(format!(
                "other constant registers, not taken as the ID: {}",
                others.join(", ")
            ));
        }
        self.id = Some((address, value));
        Ok(self.scan.insert(scan))
    }

    /// The report of every step taken (all four are needed).
    ///
    /// # Errors
    ///
    /// [`ProbeError::OutOfOrder`] for a step not taken;
    /// [`ProbeError::Unsupported`] when the channels inferred by stride
    /// do not fit in a valid [`RegisterMap`].
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::probe::{Probe, ProbeError, ProbeOptions};
    /// use ctrlab::hw::testing::RegisterFile;
    /// # use ctrlab::hw::probe::{Hands, Operator};
    /// # struct Nobody;
    /// # impl<P> Operator<P> for Nobody {
    /// #     fn tell(&mut self, _: &str) {}
    /// #     fn confirm(&mut self, _: &str) -> bool { false }
    /// #     fn hands(&mut self, _: Hands) {}
    /// #     fn wait(&mut self, _: &mut P, _: f64) {}
    /// # }
    /// let probe = Probe::new(RegisterFile::new(), Nobody, ProbeOptions::default())?;
    /// assert!(matches!(probe.report(), Err(ProbeError::OutOfOrder { .. })));
    /// # Ok::<(), ctrlab::hw::RigError>(())
    /// ```
    pub fn report(&self) -> Result<ProbeReport, ProbeError> {
        let missing = |needs| ProbeError::OutOfOrder {
            step: "the report",
            needs,
        };
        if !self.options.scan {
            return self.check_report();
        }
        let (id_address, card_id) = self.id.ok_or(missing("the scan"))?;
        let latch = self.latch.ok_or(missing("the encoder step"))?;
        let counters = self.counters.ok_or(missing("the encoder step"))?;
        let drive = self.drive.ok_or(missing("the drive step"))?;
        let (watchdog_bit, watchdog_timeout) = self.watchdog.ok_or(missing("the watchdog step"))?;
        let mut notes = self.notes.clone();
        // Encoder channels in address order, the unobserved ones continuing
        // the stride of the two found.
        let (lo, hi) = if counters[0].address < counters[1].address {
            (counters[0].address, counters[1].address)
        } else {
            (counters[1].address, counters[0].address)
        };
        let stride = hi - lo;
        let encoder = [
            Some(lo),
            Some(hi),
            hi.checked_add(stride),
            hi.checked_add(stride).and_then(|a| a.checked_add(stride)),
        ];
        let pwm = |base: u8, k: u8| base.checked_add(2 * k);
        let (Some(e2), Some(e3), Some(l1), Some(l2), Some(l3), Some(h1), Some(h2), Some(h3)) = (
            encoder[2],
            encoder[3],
            pwm(drive.low, 1),
            pwm(drive.low, 2),
            pwm(drive.low, 3),
            pwm(drive.high, 1),
            pwm(drive.high, 2),
            pwm(drive.high, 3),
        ) else {
            return Err(ProbeError::Unsupported {
                what: "the unobserved channels, placed by stride, run past address 0xff",
            });
        };
        let map = RegisterMap {
            id: id_address,
            control: latch.control,
            latch_bit: latch.latch_bit,
            clear_bit: latch.clear_bit,
            watchdog_bit,
            pwm_low: [drive.low, l1, l2, l3],
            pwm_high: [drive.high, h1, h2, h3],
            encoder: [lo, hi, e2, e3],
        };
        map.validate()?;
        notes.push(format!(
            "encoder channels 2 and 3 ({e2:#04x}, {e3:#04x}) and PWM channels 1–3 (low \
             {l1:#04x}, {l2:#04x}, {l3:#04x}) are placed by the stride of the channels \
             found, not observed: nothing is connected to them"
        ));
        let channel = |address| usize::from(address != lo);
        Ok(ProbeReport {
            map,
            card_id,
            encoder_channels: [channel(counters[0].address), channel(counters[1].address)],
            signs: [f64::from(counters[0].sign), f64::from(counters[1].sign)],
            pwm_channel: 0,
            watchdog_timeout,
            notes,
        })
    }

    /// Lets `seconds` pass (the operator's wait), then looks at the stop
    /// signal.
    fn wait(&mut self, seconds: f64) -> Result<(), ProbeError> {
        self.operator.wait(&mut self.port, seconds);
        self.check_stop()
    }

    /// [`ProbeError::Interrupted`] once a stop was requested.
    fn check_stop(&self) -> Result<(), ProbeError> {
        match &self.stop {
            Some(stop) if stop.is_requested() => Err(ProbeError::Interrupted),
            _ => Ok(()),
        }
    }

    /// Zeroes the PWM pair the probe left driven, if any (best effort:
    /// called on the way out of a failed step).
    fn zero_pwm(&mut self) {
        if let Some((low, high)) = self.driven
            && self
                .write(low, 0)
                .and_then(|()| self.write(high, 0))
                .is_ok()
        {
            self.driven = None;
        }
    }

    /// Runs a step that drives the motor, zeroing the PWM if it fails.
    fn driving<T>(
        &mut self,
        step: impl FnOnce(&mut Self) -> Result<T, ProbeError>,
    ) -> Result<T, ProbeError> {
        let result = self.check_stop().and_then(|()| step(self));
        if result.is_err() {
            self.zero_pwm();
        }
        result
    }

    /// Writes `value` to `address`, saying nothing (the steps say what
    /// they write before their loops).
    fn write(&mut self, address: u8, value: u8) -> Result<(), PortError> {
        self.port.write_register(address, value)
    }

    fn read_u32_le(&mut self, address: u8) -> Result<u32, PortError> {
        let mut bytes = [0u8; 4];
        for (offset, byte) in (0u8..).zip(bytes.iter_mut()) {
            let a = address
                .checked_add(offset)
                .ok_or(PortError::InvalidCommand {
                    what: "counter address",
                    channel: None,
                    value: f64::from(address),
                    limit: 252.0,
                })?;
            *byte = self.port.read_register(a)?;
        }
        Ok(u32::from_le_bytes(bytes))
    }
}
