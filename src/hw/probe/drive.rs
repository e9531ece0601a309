//! Steps 3 and 4: the motor's PWM registers, its polarity, and the
//! watchdog, found by short low-duty pulses after the operator confirms.

use super::{Counter, Drive, Hands, Latch, Operator, Probe, ProbeError, RegisterClass};
use crate::hw::{EppPort, pwm_bytes};

/// How often the probe looks whether the carts have come to rest, s.
const SETTLE: f64 = 0.25;

/// Longest wait between two kicks during a pulse, s.
const KICK_EVERY: f64 = 0.02;

/// The watchdog bracket's width at which bisection stops, s.
const RESOLUTION: f64 = 0.5e-3;

impl<P: EppPort, O: Operator<P>> Probe<P, O> {
    pub(super) fn found_encoders(
        &self,
        step: &'static str,
    ) -> Result<(Latch, [Counter; 2]), ProbeError> {
        match (self.latch, self.counters) {
            (Some(latch), Some(counters)) => Ok((latch, counters)),
            _ => Err(ProbeError::OutOfOrder {
                step,
                needs: "the encoder step",
            }),
        }
    }

    /// The control bits that kick the watchdog during pulses: the given
    /// map's watchdog bit; in the blind scan, every control bit but the
    /// latch and the clear (one of them kicks).
    pub(super) fn kick_bits(&self, latch: &Latch) -> u8 {
        if self.options.scan {
            !(latch.latch_bit | latch.clear_bit)
        } else {
            self.options.map.watchdog_bit
        }
    }

    /// Both counters now (latched), as raw 32-bit counts.
    fn counts(&mut self, latch: &Latch, counters: &[Counter; 2]) -> Result<[u32; 2], ProbeError> {
        self.write(latch.control, latch.latch_bit)?;
        Ok([
            self.read_u32_le(counters[0].address)?,
            self.read_u32_le(counters[1].address)?,
        ])
    }

    /// The drive step's confirmation, shared by the confirmed map and the
    /// blind scan: the operator switches the motor supply on and confirms
    /// (else [`ProbeError::Declined`]), hands go off, and the carts settle
    /// before the first pulse.
    pub(super) fn motor_on(
        &mut self,
        latch: &Latch,
        counters: &[Counter; 2],
    ) -> Result<(), ProbeError> {
        if !self.operator.confirm(
            "Switch the motor supply ON now. Carts free, hands off, e-stop within reach: \
             pulse the motor?",
        ) {
            return Err(ProbeError::Declined {
                step: "the drive step",
            });
        }
        self.operator.hands(Hands::Off);
        self.settle(latch, counters)
    }

    /// Waits until both counters stay within `min_counts` over [`SETTLE`]
    /// (the carts at rest), at most 40 looks (10 s).
    pub(super) fn settle(
        &mut self,
        latch: &Latch,
        counters: &[Counter; 2],
    ) -> Result<(), ProbeError> {
        let mut before = self.counts(latch, counters)?;
        for _ in 0..40 {
            self.wait(SETTLE)?;
            let now = self.counts(latch, counters)?;
            if self.moved(counters, before, now).is_none() {
                return Ok(());
            }
            before = now;
        }
        self.notes
            .push("the carts did not come to rest between two pulses".to_owned());
        Ok(())
    }

    /// Step 3: after the operator confirms, pulses each candidate PWM
    /// register pair (two consecutive write-only addresses, low byte first)
    /// at the [`pulse_duties`](super::ProbeOptions::pulse_duties) in turn
    /// until a cart moves, and checks that positive duty moves it away from
    /// the wall.
    ///
    /// # Errors
    ///
    /// [`ProbeError::OutOfOrder`] before [`find_encoders`](Self::find_encoders);
    /// [`ProbeError::Declined`] without the confirmation (nothing written);
    /// [`ProbeError::NotFound`] when no pair moves a cart;
    /// [`ProbeError::ReversedMotor`] when positive duty moves it towards
    /// the wall (the PWM is zeroed first).
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
    /// let options = ProbeOptions { scan: true, ..Default::default() };
    /// let mut probe = Probe::new(card, SimulatedOperator::new(clock, [true, true]), options)?;
    /// probe.scan()?;
    /// probe.find_encoders()?;
    /// let drive = probe.find_drive()?; // the hand confirms: supply on
    /// let channel = rig.calibration.pwm_channel;
    /// assert_eq!((drive.low, drive.high), (rig.card.map.pwm_low[channel], rig.card.map.pwm_high[channel]));
    /// assert!(drive.duty > 0); // per mille, away from the wall
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn find_drive(&mut self) -> Result<Drive, ProbeError> {
        self.driving(Self::find_drive_unguarded)
    }

    fn find_drive_unguarded(&mut self) -> Result<Drive, ProbeError> {
        let (latch, counters) = self.found_encoders("the drive step")?;
        let scan = self.scan.ok_or(ProbeError::OutOfOrder {
            step: "the drive step",
            needs: "the scan",
        })?;
        let [d0, d1, d2] = self.options.pulse_duties;
        self.operator.tell(&format!(
            "step 3/4, drive: with the motor supply ON, the probe writes PWM duties of {d0}, \
             {d1} and {d2} per mille (of full scale) for {} s to each pair of consecutive \
             write-only registers until a cart moves, kicking the watchdog with bits {:#04x} of \
             register {:#04x} every {KICK_EVERY} s; the carts must be free to move",
            self.options.pulse_time,
            self.kick_bits(&latch),
            latch.control
        ));
        self.motor_on(&latch, &counters)?;
        let open = |a: u8| scan.class(a) == RegisterClass::Open && a != latch.control;
        let pairs: Vec<(u8, u8)> = (0..u8::MAX)
            .map(|a| (a, a + 1))
            .filter(|&(l, h)| open(l) && open(h))
            .collect();
        // Every pair of write-only addresses is a candidate: nothing tells a
        // PWM register from any other write-only one before it moves a
        // cart. The pulses are kept few: the duties in rising order, each
        // pair left at the first that moves a cart, the search at the first
        // pair that does; and every pulse ends in a write of zero to both.
        for (low, high) in pairs {
            if let Some(drive) = self.try_pair(&latch, &counters, low, high)? {
                return Ok(drive);
            }
        }
        Err(ProbeError::NotFound {
            what: "the motor's PWM registers",
            hint: "check that the motor supply is on and the motor connected, and that the carts \
                   are free to move",
        })
    }

    /// Pulses (`low`, `high`) at each of the
    /// [`pulse_duties`](super::ProbeOptions::pulse_duties) in turn until a
    /// cart moves: the drive, once the carts have settled again, if one
    /// did.
    ///
    /// # Errors
    ///
    /// [`ProbeError::ReversedMotor`] when positive duty moved a cart towards
    /// the wall (the PWM already zeroed); the port's.
    pub(super) fn try_pair(
        &mut self,
        latch: &Latch,
        counters: &[Counter; 2],
        low: u8,
        high: u8,
    ) -> Result<Option<Drive>, ProbeError> {
        for duty in self.options.pulse_duties {
            let moved = self.pulse(latch, counters, low, high, duty)?;
            let Some((axis, counts)) = moved else {
                continue;
            };
            self.settle(latch, counters)?;
            if counts < 0 {
                return Err(ProbeError::ReversedMotor { axis, counts });
            }
            self.operator.tell(&format!(
                "  PWM low byte {low:#04x}, high byte {high:#04x}: {duty} per mille moved \
                 cart {axis} {counts} counts away from the wall"
            ));
            let drive = Drive { low, high, duty };
            self.drive = Some(drive);
            return Ok(Some(drive));
        }
        Ok(None)
    }

    /// One pulse of `duty` on (`low`, `high`), kicked throughout with every
    /// control bit but the latch and the clear; see [`pulse_with`](Self::pulse_with).
    pub(super) fn pulse(
        &mut self,
        latch: &Latch,
        counters: &[Counter; 2],
        low: u8,
        high: u8,
        duty: i16,
    ) -> Result<Option<(usize, i64)>, ProbeError> {
        let kick = self.kick_bits(latch);
        self.write(latch.control, kick)?;
        let before = self.counts(latch, counters)?;
        self.pulse_with(latch, counters, (low, high), duty, kick, before)
    }

    /// Writes `duty` to the (`low`, `high`) pair, kicks with `kick` at
    /// once and every [`KICK_EVERY`] for the pulse time, and returns the
    /// cart that moved most since `before` and how far (sign-corrected
    /// counts), if either moved `min_counts` or more. The PWM is zeroed
    /// before returning, errors included.
    fn pulse_with(
        &mut self,
        latch: &Latch,
        counters: &[Counter; 2],
        (low, high): (u8, u8),
        duty: i16,
        kick: u8,
        before: [u32; 2],
    ) -> Result<Option<(usize, i64)>, ProbeError> {
        self.driven = Some((low, high));
        let result = (|| {
            let (low_byte, high_byte) = pwm_bytes(duty);
            self.write(low, low_byte)?;
            self.write(high, high_byte)?;
            self.write(latch.control, kick)?;
            let steps = (self.options.pulse_time / KICK_EVERY).ceil().max(1.0) as usize;
            for _ in 0..steps {
                self.wait(self.options.pulse_time / steps as f64)?;
                self.write(latch.control, kick)?;
            }
            let after = self.counts(latch, counters)?;
            Ok::<_, ProbeError>(self.moved(counters, before, after))
        })();
        let stop = self.write(low, 0).and_then(|()| self.write(high, 0));
        if stop.is_ok() {
            self.driven = None;
        }
        let moved = result?;
        stop?;
        Ok(moved)
    }

    /// The cart that moved most between two readings and how far, counts
    /// (positive away from the wall), if `min_counts` or more.
    pub(super) fn moved(
        &self,
        counters: &[Counter; 2],
        before: [u32; 2],
        after: [u32; 2],
    ) -> Option<(usize, i64)> {
        let delta = |i: usize| {
            i64::from(after[i].wrapping_sub(before[i]) as i32) * i64::from(counters[i].sign)
        };
        let (d1, d2) = (delta(0), delta(1));
        let (axis, counts) = if d1.abs() >= d2.abs() {
            (1, d1)
        } else {
            (2, d2)
        };
        (counts.abs() >= self.options.min_counts).then_some((axis, counts))
    }

    /// Whether a PWM write `silence` s after kicking with `kick` is obeyed:
    /// the write, then a pulse kicked with `kick` throughout. Before the
    /// watchdog trips the write stands and a cart moves; after, the card
    /// has zeroed it and the kicks that follow do not bring it back, so
    /// the answer flips sharply at the timeout. The pulse uses the largest
    /// of the [`pulse_duties`](super::ProbeOptions::pulse_duties), for a
    /// clear margin over friction, in alternating directions. The PWM is
    /// zeroed and the watchdog re-armed afterwards, then the carts settle.
    pub(super) fn obeyed(&mut self, silence: f64, kick: u8) -> Result<bool, ProbeError> {
        let (latch, counters) = self.found_encoders("the watchdog step")?;
        let drive = self.drive.ok_or(ProbeError::OutOfOrder {
            step: "the watchdog step",
            needs: "the drive step",
        })?;
        let largest = self
            .options
            .pulse_duties
            .iter()
            .copied()
            .max()
            .unwrap_or(drive.duty);
        // Friction holds a cart where a pulse left it, against its springs,
        // and a pulse one way may not break it loose: a write counts as
        // ignored only if neither direction moves a cart.
        for _ in 0..2 {
            self.reverse = !self.reverse;
            let duty = if self.reverse { -largest } else { largest };
            self.write(latch.control, kick)?;
            self.wait(silence)?;
            let before = self.counts(&latch, &counters)?;
            let moved = self.pulse_with(
                &latch,
                &counters,
                (drive.low, drive.high),
                duty,
                kick,
                before,
            )?;
            self.write(latch.control, self.kick_bits(&latch))?;
            self.settle(&latch, &counters)?;
            if moved.is_some() {
                return Ok(true);
            }
        }
        Ok(false)
    }

    /// Times the watchdog kicked with `kick`: `None` when a PWM write is
    /// still obeyed [`max_watchdog`](super::ProbeOptions::max_watchdog)
    /// after a kick, else the bracket it trips in (s) and the timeout,
    /// rounded to the millisecond.
    ///
    /// # Errors
    ///
    /// [`ProbeError::NotFound`] when a write 10 ms after a kick is not
    /// obeyed; the port's.
    pub(super) fn time_watchdog(
        &mut self,
        kick: u8,
    ) -> Result<Option<(f64, f64, f64)>, ProbeError> {
        let max = self.options.max_watchdog;
        if !self.obeyed(0.01, kick)? {
            return Err(ProbeError::NotFound {
                what: "a watchdog kick",
                hint: "a PWM write 10 ms after writing the kick bits to the control register \
                       was not obeyed",
            });
        }
        if self.obeyed(max, kick)? {
            self.operator.tell(&format!("  no watchdog within {max} s"));
            return Ok(None);
        }
        let (mut lo, mut hi) = (0.01, max);
        // Halving from at most 10 s to 0.5 ms: at most 15 rounds.
        while hi - lo > RESOLUTION {
            let mid = 0.5 * (lo + hi);
            if self.obeyed(mid, kick)? {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let timeout = (500.0 * (lo + hi)).round() / 1000.0;
        self.operator.tell(&format!(
            "  the watchdog trips between {lo:.4} s and {hi:.4} s without a kick: {timeout} s"
        ));
        Ok(Some((lo, hi, timeout)))
    }

    /// Step 4 of the blind scan: whether a PWM write is still obeyed after
    /// a silence without a kick, bisected to the watchdog timeout (to 0.5
    /// ms), and which control bit kicks it.
    ///
    /// # Errors
    ///
    /// [`ProbeError::OutOfOrder`] before [`find_drive`](Self::find_drive);
    /// [`ProbeError::NotFound`] when a write 10 ms after a kick is not
    /// obeyed, or no single bit kicks.
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
    /// let options = ProbeOptions { scan: true, ..Default::default() };
    /// let mut probe = Probe::new(card, SimulatedOperator::new(clock, [true, true]), options)?;
    /// probe.scan()?;
    /// probe.find_encoders()?;
    /// probe.find_drive()?;
    /// assert_eq!(probe.find_watchdog()?, Some(0.1)); // s, the simulated card's
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn find_watchdog(&mut self) -> Result<Option<f64>, ProbeError> {
        self.driving(Self::find_watchdog_unguarded)
    }

    fn find_watchdog_unguarded(&mut self) -> Result<Option<f64>, ProbeError> {
        let (latch, _) = self.found_encoders("the watchdog step")?;
        let kick_all = self.kick_bits(&latch);
        let max = self.options.max_watchdog;
        self.operator.tell(&format!(
            "step 4/4, watchdog: short pulses of the drive found in step 3, each after a \
             silence without a kick, from 10 ms to {max} s, to time the watchdog; then each \
             control bit alone as the kick"
        ));
        self.operator.hands(Hands::Off);
        let Some((_, hi, timeout)) = self.time_watchdog(kick_all)? else {
            let bit = kick_all & kick_all.wrapping_neg();
            self.notes.push(format!(
                "no watchdog: PWM writes are still obeyed {max} s after the last kick; \
                 watchdog_bit set to {bit:#04x}, unverified"
            ));
            self.watchdog = Some((bit, None));
            return Ok(None);
        };
        for bit in (0..8).map(|b| 1u8 << b).filter(|&b| kick_all & b != 0) {
            // Let the watchdog trip, then kick with this bit alone.
            self.wait(hi + KICK_EVERY)?;
            if self.obeyed(0.01, bit)? {
                self.operator
                    .tell(&format!("  the watchdog is kicked by bit {bit:#04x}"));
                self.watchdog = Some((bit, Some(timeout)));
                return Ok(Some(timeout));
            }
        }
        Err(ProbeError::NotFound {
            what: "the watchdog's kick bit",
            hint: "no single control bit re-arms the PWM; the card may need several",
        })
    }
}
