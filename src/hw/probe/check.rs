//! The default probe: confirms a given register map
//! ([`ProbeOptions::map`](super::ProbeOptions::map)), reading and writing
//! only the addresses that map names.

use super::{Counter, Drive, Hands, Latch, Operator, Probe, ProbeError, ProbeReport};
use crate::hw::{ENCODER_CHANNELS, EppPort, PWM_CHANNELS, PortError};

impl<P: EppPort, O: Operator<P>> Probe<P, O> {
    /// Step 1 (the default probe): reads the given map's ID register twice,
    /// a moment apart; it must read the same constant, other than `0x00`
    /// and `0xff`, and the card file's ID when one was given
    /// ([`ProbeOptions::card_id`](super::ProbeOptions::card_id)). Reads
    /// only; no other address.
    ///
    /// # Errors
    ///
    /// [`ProbeError::NoCard`] when EPP cycles time out;
    /// [`ProbeError::WrongMap`] for an ID register that reads otherwise;
    /// nothing is written.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::hw::probe::{Probe, ProbeError, ProbeOptions};
    /// use ctrlab::hw::testing::{RecordingPort, RegisterFile};
    /// use ctrlab::hw::{CycleKind, RegisterMap};
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
    /// let options = ProbeOptions { card_id: Some(0xa5), ..Default::default() };
    /// let mut probe = Probe::new(RecordingPort::new(card.clone()), Nobody, options)?;
    /// assert_eq!(probe.check_id()?, 0xa5);
    /// assert!(probe.port().log().iter().all(|c| c.kind() != CycleKind::DataWrite));
    /// // The card file says another card.
    /// let other = ProbeOptions { card_id: Some(0x3c), ..Default::default() };
    /// let mut probe = Probe::new(card, Nobody, other)?;
    /// assert!(matches!(probe.check_id(), Err(ProbeError::WrongMap { .. })));
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn check_id(&mut self) -> Result<u8, ProbeError> {
        self.check_stop()?;
        let id = self.options.map.id;
        self.operator.tell(&format!(
            "step 1/4, ID: reading the map's ID register {id:#04x} twice (read-only); the \
             probe reads and writes only the addresses the given map names"
        ));
        let no_card = |e: PortError| match e {
            PortError::Timeout { .. } => ProbeError::NoCard {
                reason: format!("EPP cycles time out ({e})"),
            },
            other => ProbeError::Port(other),
        };
        let first = self.port.read_register(id).map_err(no_card)?;
        self.wait(0.05)?;
        let second = self.port.read_register(id).map_err(no_card)?;
        let wrong = |reason: String| ProbeError::WrongMap {
            reason: format!("{reason}; nothing was written to the card"),
        };
        if first != second {
            return Err(wrong(format!(
                "the ID register {id:#04x} read {first:#04x}, then {second:#04x}: not a constant"
            )));
        }
        if matches!(first, 0x00 | 0xff) {
            return Err(wrong(format!(
                "the ID register {id:#04x} reads {first:#04x}, what an idle bus or an empty \
                 register reads: no card answers there (check the cable, the card's power, the \
                 BIOS EPP mode), or the ID is elsewhere"
            )));
        }
        if let Some(expected) = self.options.card_id.filter(|&e| e != first) {
            return Err(wrong(format!(
                "the ID register {id:#04x} reads {first:#04x}, the card file says {expected:#04x}: \
                 another card, or another map"
            )));
        }
        self.operator
            .tell(&format!("  ID register {id:#04x} reads {first:#04x}"));
        self.id = Some((id, first));
        Ok(first)
    }

    /// Step 2 (the default probe): with the motor supply off (the operator
    /// confirms), latches and reads the map's four counters while the user
    /// moves each cart by hand: the counter that follows each cart, and
    /// its sign (the user holds the cart away from the wall); then checks
    /// that the map's clear bit zeroes them. Writes only the map's control
    /// register (latch and clear bits).
    ///
    /// # Errors
    ///
    /// [`ProbeError::OutOfOrder`] before [`check_id`](Self::check_id);
    /// [`ProbeError::Declined`] when the operator does not confirm that the
    /// motor supply is off (nothing written); [`ProbeError::NotFound`] for
    /// no counter that follows a cart, no direction away from the wall, or
    /// a clear bit that does not clear.
    ///
    /// # Examples
    ///
    /// The simulated rig's counters, found where its calibration says:
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
    /// let [cart1, cart2] = probe.check_encoders()?; // the hand confirms: supply off
    /// let (map, cal) = (&rig.card.map, &rig.calibration);
    /// assert_eq!(cart1.address, map.encoder[cal.encoder_channels[0]]);
    /// assert_eq!(cart2.address, map.encoder[cal.encoder_channels[1]]);
    /// assert_eq!([f64::from(cart1.sign), f64::from(cart2.sign)], cal.sign);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn check_encoders(&mut self) -> Result<[Counter; 2], ProbeError> {
        self.check_stop()?;
        self.id.ok_or(ProbeError::OutOfOrder {
            step: "the encoder step",
            needs: "the ID check",
        })?;
        let map = self.options.map;
        let latch = Latch {
            control: map.control,
            latch_bit: map.latch_bit,
            clear_bit: map.clear_bit,
        };
        self.operator.tell(&format!(
            "step 2/4, encoders: you move each cart by hand while the probe latches the \
             counters (bit {:#04x} of register {:#04x}) and reads the map's four counters; then \
             it clears them once (bit {:#04x}) to check the clear bit",
            latch.latch_bit, latch.control, latch.clear_bit
        ));
        self.motor_off()?;
        let rest = self.map_counts(&latch)?;
        let mut channels = [0usize; 2];
        let mut counters = [Counter {
            address: 0,
            sign: 1,
        }; 2];
        for axis in 1..=2 {
            let other = (axis == 2).then_some(channels[0]);
            let (channel, sign) = self.follow(&latch, &rest, axis, other)?;
            channels[axis - 1] = channel;
            counters[axis - 1] = Counter {
                address: map.encoder[channel],
                sign,
            };
        }
        // Cart 2 is held away from the wall: a clear reads zero.
        self.check_clear(&latch, map.encoder[channels[1]])?;
        self.operator.hands(Hands::Off);
        self.operator.tell(&format!(
            "  counters: cart 1 on encoder {} (sign {:+}), cart 2 on encoder {} (sign {:+}); \
             the clear bit clears them",
            channels[0], counters[0].sign, channels[1], counters[1].sign
        ));
        self.latch = Some(latch);
        self.counters = Some(counters);
        self.channels = Some(channels);
        Ok(counters)
    }

    /// All four of the map's counters, latched.
    fn map_counts(&mut self, latch: &Latch) -> Result<[u32; ENCODER_CHANNELS], ProbeError> {
        self.write(latch.control, latch.latch_bit)?;
        let mut counts = [0u32; ENCODER_CHANNELS];
        for (count, address) in counts.iter_mut().zip(self.options.map.encoder) {
            *count = self.read_u32_le(address)?;
        }
        Ok(counts)
    }

    /// The map's encoder channel that follows cart `axis` while the user
    /// moves it (not `other`, the other cart's), and its sign: held away
    /// from the wall, the cart must count away from `rest`.
    fn follow(
        &mut self,
        latch: &Latch,
        rest: &[u32; ENCODER_CHANNELS],
        axis: usize,
        other: Option<usize>,
    ) -> Result<(usize, i8), ProbeError> {
        self.operator.tell(&format!(
            "  cart {axis}: sampling the counters every {} s while you move it",
            self.options.sample_interval
        ));
        self.operator.hands(Hands::Move(axis));
        let mut travel = [0u64; ENCODER_CHANNELS];
        let mut last = *rest;
        for _ in 0..self.options.samples {
            self.wait(self.options.sample_interval)?;
            let now = self.map_counts(latch)?;
            for (t, (n, l)) in travel.iter_mut().zip(now.iter().zip(&last)) {
                *t += u64::from((n.wrapping_sub(*l) as i32).unsigned_abs());
            }
            last = now;
        }
        let best = (0..ENCODER_CHANNELS)
            .filter(|&c| Some(c) != other)
            .max_by_key(|&c| (travel[c], usize::MAX - c));
        let Some(channel) =
            best.filter(|&c| travel[c] >= 4 * self.options.min_counts.unsigned_abs())
        else {
            return Err(ProbeError::NotFound {
                what: "a counter of the map that follows the cart",
                hint: "move the cart further and faster (a few centimetres back and forth) while \
                       the probe samples; if it did move, the map's encoder addresses or its \
                       latch bit are wrong",
            });
        };
        self.operator.tell(&format!(
            "  cart {axis}: encoder {channel} (from {:#04x}) moved {} counts in all",
            self.options.map.encoder[channel], travel[channel]
        ));
        self.operator.hands(Hands::Away(axis));
        self.wait(0.2)?;
        let away = self.map_counts(latch)?;
        let moved = i64::from(away[channel].wrapping_sub(rest[channel]) as i32);
        if moved.abs() < self.options.min_counts {
            return Err(ProbeError::NotFound {
                what: "the direction away from the wall",
                hint: "hold the cart a few centimetres away from the wall when asked",
            });
        }
        Ok((channel, if moved > 0 { 1 } else { -1 }))
    }

    /// The map's clear bit, with a counter held away from zero: after it,
    /// the latched counter must read near zero.
    fn check_clear(&mut self, latch: &Latch, counter: u8) -> Result<(), ProbeError> {
        self.write(latch.control, latch.latch_bit)?;
        let held = i64::from(self.read_u32_le(counter)? as i32);
        self.write(latch.control, latch.clear_bit)?;
        self.write(latch.control, latch.latch_bit)?;
        let after = i64::from(self.read_u32_le(counter)? as i32);
        if held.abs() >= self.options.min_counts && after.abs() * 4 <= held.abs() {
            Ok(())
        } else {
            Err(ProbeError::NotFound {
                what: "a clear bit that clears the counters",
                hint: "hold cart 2 away from the wall while the probe clears; if it was held \
                       away, the map's clear bit is wrong",
            })
        }
    }

    /// Step 3 (the default probe): after the operator confirms, pulses the
    /// map's PWM channels in turn, at the
    /// [`pulse_duties`](super::ProbeOptions::pulse_duties) in rising order,
    /// kicking with the map's watchdog bit, until a cart moves; checks that
    /// positive duty moves it away from the wall. Writes only the map's PWM
    /// and control registers; every pulse ends in zero duty, as does any
    /// error or stop.
    ///
    /// # Errors
    ///
    /// [`ProbeError::OutOfOrder`] before
    /// [`check_encoders`](Self::check_encoders); [`ProbeError::Declined`]
    /// without the confirmation (nothing written);
    /// [`ProbeError::NotFound`] when no channel moves a cart;
    /// [`ProbeError::ReversedMotor`] when positive duty moves it towards
    /// the wall.
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
    /// probe.check_encoders()?;
    /// let drive = probe.check_drive()?; // the hand confirms: supply on
    /// let channel = rig.calibration.pwm_channel;
    /// assert_eq!((drive.low, drive.high), (rig.card.map.pwm_low[channel], rig.card.map.pwm_high[channel]));
    /// assert!(drive.duty > 0); // per mille, away from the wall
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn check_drive(&mut self) -> Result<Drive, ProbeError> {
        self.driving(Self::check_drive_unguarded)
    }

    fn check_drive_unguarded(&mut self) -> Result<Drive, ProbeError> {
        let (latch, counters) = self.found_encoders("the drive step")?;
        if self.channels.is_none() {
            return Err(ProbeError::OutOfOrder {
                step: "the drive step",
                needs: "the encoder check",
            });
        }
        let map = self.options.map;
        let [d0, d1, d2] = self.options.pulse_duties;
        self.operator.tell(&format!(
            "step 3/4, drive: with the motor supply ON, the probe writes PWM duties of {d0}, \
             {d1} and {d2} per mille (of full scale) for {} s to the map's PWM channels 0-3 \
             (low bytes {}) in turn until a cart moves, kicking the watchdog with bit {:#04x} \
             of register {:#04x}; the carts must be free to move",
            self.options.pulse_time,
            map.pwm_low.map(|a| format!("{a:#04x}")).join(", "),
            map.watchdog_bit,
            map.control
        ));
        self.motor_on(&latch, &counters)?;
        for channel in 0..PWM_CHANNELS {
            let (low, high) = (map.pwm_low[channel], map.pwm_high[channel]);
            if let Some(drive) = self.try_pair(&latch, &counters, low, high)? {
                self.operator
                    .tell(&format!("  the motor is on PWM channel {channel}"));
                self.pwm_channel = Some(channel);
                return Ok(drive);
            }
        }
        Err(ProbeError::NotFound {
            what: "a PWM channel of the map that moves a cart",
            hint: "check that the motor supply is on and the motor connected, and that the carts \
                   are free to move; if they are, the map's PWM addresses or watchdog bit are \
                   wrong",
        })
    }

    /// Step 4 (the default probe): times the watchdog kicked with the
    /// map's watchdog bit — whether a PWM write on the channel found is
    /// still obeyed after a silence without a kick, bisected to the timeout
    /// (to 0.5 ms) — or finds none within
    /// [`max_watchdog`](super::ProbeOptions::max_watchdog).
    ///
    /// # Errors
    ///
    /// [`ProbeError::OutOfOrder`] before [`check_drive`](Self::check_drive);
    /// [`ProbeError::NotFound`] when a write 10 ms after a kick is not
    /// obeyed.
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
    /// probe.check_encoders()?;
    /// probe.check_drive()?;
    /// assert_eq!(probe.check_watchdog()?, Some(0.1)); // s, the simulated card's
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn check_watchdog(&mut self) -> Result<Option<f64>, ProbeError> {
        self.driving(Self::check_watchdog_unguarded)
    }

    fn check_watchdog_unguarded(&mut self) -> Result<Option<f64>, ProbeError> {
        self.found_encoders("the watchdog step")?;
        if self.pwm_channel.is_none() {
            return Err(ProbeError::OutOfOrder {
                step: "the watchdog step",
                needs: "the drive check",
            });
        }
        let kick = self.options.map.watchdog_bit;
        let max = self.options.max_watchdog;
        self.operator.tell(&format!(
            "step 4/4, watchdog: short pulses of the drive found in step 3, each after a \
             silence without a kick (bit {kick:#04x}), from 10 ms to {max} s, to time the \
             watchdog"
        ));
        self.operator.hands(Hands::Off);
        let timeout = self.time_watchdog(kick)?.map(|(_, _, timeout)| timeout);
        if timeout.is_none() {
            self.notes.push(format!(
                "no watchdog: PWM writes are still obeyed {max} s after the last kick (bit \
                 {kick:#04x})"
            ));
        }
        self.watchdog = Some((kick, timeout));
        Ok(timeout)
    }

    /// The report of the default probe: the given map, and what the four
    /// checks found.
    pub(super) fn check_report(&self) -> Result<ProbeReport, ProbeError> {
        let missing = |needs| ProbeError::OutOfOrder {
            step: "the report",
            needs,
        };
        let (_, card_id) = self.id.ok_or(missing("the ID check"))?;
        let channels = self.channels.ok_or(missing("the encoder check"))?;
        let counters = self.counters.ok_or(missing("the encoder check"))?;
        let pwm_channel = self.pwm_channel.ok_or(missing("the drive check"))?;
        let (_, watchdog_timeout) = self.watchdog.ok_or(missing("the watchdog check"))?;
        Ok(ProbeReport {
            map: self.options.map,
            card_id,
            encoder_channels: channels,
            signs: [f64::from(counters[0].sign), f64::from(counters[1].sign)],
            pwm_channel,
            watchdog_timeout,
            notes: self.notes.clone(),
        })
    }
}
