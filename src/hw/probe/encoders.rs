//! Step 2: the latch, the counters, their signs and the clear bit, found
//! by moving the carts by hand with the motor supply off.

use super::scan::{Snapshot, snapshot};
use super::{Counter, Hands, Latch, Operator, Probe, ProbeError, RegisterClass, Scan};
use crate::hw::EppPort;

/// Pause between two latch candidates, s: the hand moves the cart a little
/// in between, so a latch after a clear still reads a new value.
const DWELL: f64 = 0.01;

/// How long the carts get to come to rest, s.
const SETTLE: f64 = 1.0;

/// The test patterns of the latch search: bit `i` is in the two patterns
/// named by the `i`-th pair of {0, …, 4} (01, 02, 03, 04, 12, 13, 14, 23),
/// so for any two bits — the latch and the clear — one pattern has the
/// first without the second: a write that latches without clearing. Five
/// patterns is the fewest with that property for eight bits.
const PATTERNS: [u8; 5] = [0x0f, 0x71, 0x92, 0xa4, 0x48];

impl<P: EppPort, O: Operator<P>> Probe<P, O> {
    /// The encoder step's confirmation, shared by the confirmed map and the
    /// blind scan: the operator confirms the motor cannot move (else
    /// [`ProbeError::Declined`]), hands go off, and the carts settle for
    /// [`SETTLE`] before the first read.
    pub(super) fn motor_off(&mut self) -> Result<(), ProbeError> {
        if !self.operator.confirm(
            "Is the motor supply switched OFF (or the motor unplugged), and the e-stop at hand?",
        ) {
            return Err(ProbeError::Declined {
                step: "the encoder step",
            });
        }
        self.operator.hands(Hands::Off);
        self.wait(SETTLE)
    }

    /// Step 2 of the blind scan: with the motor supply off (the operator
    /// confirms), finds the
    /// control register and its latch bit, both carts' counters with their
    /// signs, and the clear bit, asking the user to move each cart by hand.
    ///
    /// # Errors
    ///
    /// [`ProbeError::OutOfOrder`] before [`scan`](Self::scan);
    /// [`ProbeError::Declined`] when the operator does not confirm that the
    /// motor supply is off (nothing written); [`ProbeError::Unsupported`]
    /// for counters that change without a latch or are big-endian;
    /// [`ProbeError::NotFound`] for a latch, counter or clear bit not found.
    ///
    /// # Examples
    ///
    /// Blind, on the simulated card: the counters its map and calibration name.
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
    /// let [cart1, cart2] = probe.find_encoders()?; // the hand confirms: supply off
    /// let (map, cal) = (&rig.card.map, &rig.calibration);
    /// assert_eq!(cart1.address, map.encoder[cal.encoder_channels[0]]);
    /// assert_eq!(cart2.address, map.encoder[cal.encoder_channels[1]]);
    /// assert_eq!([f64::from(cart1.sign), f64::from(cart2.sign)], cal.sign);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn find_encoders(&mut self) -> Result<[Counter; 2], ProbeError> {
        let scan = *self.scan.as_ref().ok_or(ProbeError::OutOfOrder {
            step: "the encoder step",
            needs: "the scan",
        })?;
        self.operator.tell(
            "step 2/4, encoders: you move each cart by hand while the probe reads the card; to \
             find the counter latch it writes test bits to the card's write-only registers, so \
             the motor must not be able to move",
        );
        self.motor_off()?;
        let still = snapshot(&mut self.port)?;
        self.operator.hands(Hands::Move(1));
        let interval = self.options.sample_interval;
        for _ in 0..self.options.samples {
            self.wait(interval)?;
            if scan.changed(&still, &snapshot(&mut self.port)?) {
                return Err(ProbeError::Unsupported {
                    what: "registers change with the carts without a latch (transparent \
                           counters); the PC104 driver latches through a control register",
                });
            }
        }
        let (control, latch_bit) = self.find_latch(&scan)?;
        self.operator.tell(&format!(
            "  latch: bit {latch_bit:#04x} of register {control:#04x}"
        ));
        self.operator.hands(Hands::Off);
        let rest = self.settled(control, latch_bit)?;
        let first = self.find_counter(&scan, control, latch_bit, &rest, 1, None)?;
        let second = self.find_counter(&scan, control, latch_bit, &rest, 2, Some(first.address))?;
        // Cart 2 is held away from the wall: a clear reads zero.
        let clear_bit = self.find_clear(control, latch_bit, second.address)?;
        self.operator.hands(Hands::Off);
        self.operator.tell(&format!(
            "  clear: bit {clear_bit:#04x}; counters: cart 1 at {:#04x} (sign {:+}), cart 2 at \
             {:#04x} (sign {:+}), little-endian",
            first.address, first.sign, second.address, second.sign
        ));
        self.latch = Some(Latch {
            control,
            latch_bit,
            clear_bit,
        });
        self.counters = Some([first, second]);
        Ok([first, second])
    }

    /// A latched snapshot once two of them [`SETTLE`] apart agree (the
    /// carts at rest), or after 10 tries.
    fn settled(&mut self, control: u8, latch_bit: u8) -> Result<Snapshot, ProbeError> {
        let mut before = self.latched(control, latch_bit)?;
        for _ in 0..10 {
            self.wait(SETTLE)?;
            let now = self.latched(control, latch_bit)?;
            if now == before {
                return Ok(now);
            }
            before = now;
        }
        self.notes
            .push("the carts did not come to rest before the counters were read".to_owned());
        Ok(before)
    }

    /// One latch, then a read of every address.
    fn latched(&mut self, control: u8, latch_bit: u8) -> Result<Snapshot, ProbeError> {
        self.write(control, latch_bit)?;
        Ok(snapshot(&mut self.port)?)
    }

    /// The control register and its latch bit, with as few writes to
    /// addresses nobody described as the search allows.
    ///
    /// Nothing tells a write-only register from an unmapped address, or
    /// from an FPGA's configuration register, before a write: every
    /// open-bus address is a candidate, and each write to one is a risk.
    /// So each candidate gets the five [`PATTERNS`], each followed by a
    /// zero (ten writes, where each of the eight bits in turn would be
    /// sixteen), and the search ends at the first address that latches;
    /// only there are single bits tried, and only the bits of the pattern
    /// that latched. One pattern of every bit (`0xff`) would not do: where
    /// the clear bit shares the register, a write of both clears and
    /// latches, and counters that read zero before read zero again. The
    /// motor supply is off (the operator confirmed): a pattern in a PWM
    /// high byte commands duty for the time of one read of every address.
    fn find_latch(&mut self, scan: &Scan) -> Result<(u8, u8), ProbeError> {
        let candidates: Vec<u8> = scan.addresses(|c| c == RegisterClass::Open).collect();
        self.operator.tell(&format!(
            "  writing 5 patterns ({}), each followed by 0x00, to each of the {} write-only \
             addresses in turn, each pattern followed by a read of every address, until the \
             counters change; then single bits at the one address that changed them; keep \
             moving cart 1",
            PATTERNS.map(|p| format!("{p:#04x}")).join(", "),
            candidates.len()
        ));
        let mut before = snapshot(&mut self.port)?;
        for &address in &candidates {
            for pattern in PATTERNS {
                self.wait(DWELL)?;
                let after = self.latch_try(address, pattern)?;
                let changed = scan.changed(&before, &after);
                before = after;
                if changed
                    && let Some(bit) = self.find_latch_bit(scan, address, pattern, &mut before)?
                {
                    return Ok((address, bit));
                }
            }
        }
        Err(ProbeError::NotFound {
            what: "the counter latch",
            hint: "keep the cart moving during the search; check the encoder cables and the \
                   card's power",
        })
    }

    /// The bit of `pattern` at `address` that latches the counters: each
    /// bit alone, written and then zeroed, until the counters read new
    /// values, twice more to be sure.
    fn find_latch_bit(
        &mut self,
        scan: &Scan,
        address: u8,
        pattern: u8,
        before: &mut Snapshot,
    ) -> Result<Option<u8>, ProbeError> {
        for bit in (0..8).map(|b| 1u8 << b).filter(|b| pattern & b != 0) {
            self.wait(DWELL)?;
            let after = self.latch_try(address, bit)?;
            if scan.changed(before, &after) && self.confirm_latch(scan, address, bit, after)? {
                return Ok(Some(bit));
            }
            *before = after;
        }
        Ok(None)
    }

    fn latch_try(&mut self, address: u8, bit: u8) -> Result<Snapshot, ProbeError> {
        self.write(address, bit)?;
        let after = snapshot(&mut self.port)?;
        self.write(address, 0)?;
        Ok(after)
    }

    /// Whether two more tries of `bit` at `address`, a sample interval
    /// apart, each read new values again.
    fn confirm_latch(
        &mut self,
        scan: &Scan,
        address: u8,
        bit: u8,
        mut before: Snapshot,
    ) -> Result<bool, ProbeError> {
        for _ in 0..2 {
            self.wait(self.options.sample_interval)?;
            let after = self.latch_try(address, bit)?;
            if !scan.changed(&before, &after) {
                return Ok(false);
            }
            before = after;
        }
        Ok(true)
    }

    /// The counter of `axis`: sampled while the user moves the cart, the
    /// most active byte is its least significant; the byte order is the
    /// one whose values move smoothly. Its sign: held away from the wall,
    /// it must count away from `rest`.
    fn find_counter(
        &mut self,
        scan: &Scan,
        control: u8,
        latch_bit: u8,
        rest: &Snapshot,
        axis: usize,
        other: Option<u8>,
    ) -> Result<Counter, ProbeError> {
        self.operator.tell(&format!(
            "  cart {axis}: sampling every {} s while you move it",
            self.options.sample_interval
        ));
        self.operator.hands(Hands::Move(axis));
        let mut samples = Vec::with_capacity(self.options.samples + 1);
        samples.push(*rest);
        let mut changes = [0usize; 256];
        for _ in 0..self.options.samples {
            self.wait(self.options.sample_interval)?;
            let s = self.latched(control, latch_bit)?;
            let last = samples.last().unwrap_or(rest);
            for (a, n) in changes.iter_mut().enumerate() {
                let taken =
                    other.is_some_and(|o| (usize::from(o)..usize::from(o) + 4).contains(&a));
                if s[a] != last[a] && !taken && scan.class(a as u8) != RegisterClass::Volatile {
                    *n += 1;
                }
            }
            samples.push(s);
        }
        // The counter's least significant byte is the one that moves
        // furthest, each step read as a wrapping 8-bit difference: the
        // higher bytes of a moving counter step by a few, and the low byte
        // of an idle one flickers by the encoder noise.
        let wiggle = |a: usize| -> u64 {
            samples
                .windows(2)
                .map(|w| u64::from((w[1][a].wrapping_sub(w[0][a]) as i8).unsigned_abs()))
                .sum()
        };
        let best = (0..=252usize)
            .filter(|&a| changes[a] > 0)
            .map(|a| (wiggle(a), a))
            .max_by_key(|&(t, a)| (t, usize::MAX - a));
        let Some((_, low)) = best.filter(|&(t, _)| t >= 4 * self.options.min_counts as u64) else {
            return Err(ProbeError::NotFound {
                what: "a counter that follows the cart",
                hint: "move the cart further and faster (a few centimetres back and forth) \
                       while the probe samples, and check its encoder cable",
            });
        };
        let value = |s: &Snapshot| u32::from_le_bytes([s[low], s[low + 1], s[low + 2], s[low + 3]]);
        let moved: u64 = samples
            .windows(2)
            .map(|w| u64::from((value(&w[1]).wrapping_sub(value(&w[0])) as i32).unsigned_abs()))
            .sum();
        let low = low as u8;
        self.operator.tell(&format!(
            "  cart {axis}: the counter at {low:#04x} moved {moved} counts in all"
        ));
        // The byte above the low one carries in a little-endian counter,
        // the byte below in a big-endian one.
        let carries = |a: Option<u8>| a.map_or(0, |a| changes[usize::from(a)]);
        match (carries(low.checked_sub(1)), carries(low.checked_add(1))) {
            (0, 0) => {
                return Err(ProbeError::NotFound {
                    what: "the counter's byte order",
                    hint: "move the cart further (more than 3 mm, 256 counts) while the probe \
                           samples",
                });
            }
            (below, 0) if below > 0 => {
                return Err(ProbeError::Unsupported {
                    what: "big-endian counters (the PC104 driver reads them little-endian)",
                });
            }
            _ => {}
        }
        self.operator.hands(Hands::Away(axis));
        self.wait(0.2)?;
        self.write(control, latch_bit)?;
        let away = self.read_u32_le(low)?;
        let moved = i64::from(away.wrapping_sub(value(rest)) as i32);
        if moved.abs() < self.options.min_counts {
            return Err(ProbeError::NotFound {
                what: "the direction away from the wall",
                hint: "hold the cart a few centimetres away from the wall when asked",
            });
        }
        Ok(Counter {
            address: low,
            sign: if moved > 0 { 1 } else { -1 },
        })
    }

    /// The control bit (other than the latch) after which a latched
    /// counter held away from zero reads near zero.
    fn find_clear(&mut self, control: u8, latch_bit: u8, counter: u8) -> Result<u8, ProbeError> {
        for bit in (0..8).map(|b| 1u8 << b).filter(|&b| b != latch_bit) {
            self.write(control, latch_bit)?;
            let held = i64::from(self.read_u32_le(counter)? as i32);
            self.write(control, bit)?;
            self.write(control, latch_bit)?;
            let after = i64::from(self.read_u32_le(counter)? as i32);
            if held.abs() >= self.options.min_counts && after.abs() * 4 <= held.abs() {
                return Ok(bit);
            }
        }
        Err(ProbeError::NotFound {
            what: "the counters' clear bit",
            hint: "hold cart 2 away from the wall while the probe searches",
        })
    }
}
