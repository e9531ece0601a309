//! The rig's plausibility checks on each read: a drive the driven cart's
//! encoder does not answer.

use super::{DRIVEN, Episode, MassSpringRig, OTHER, Rest};
use crate::hw::{EppPort, LoopFault, RigError};

impl<P: EppPort> MassSpringRig<P> {
    /// A change of drive must move the driven cart's encoder (see
    /// [`Calibration::stall_volts`] and [the driven
    /// cart](Calibration#the-driven-cart)): the drive is compared with what
    /// it was when that encoder last moved, so a deflection held against
    /// the springs, or carts stuck in their friction under a steady drive,
    /// is not a fault, while a motor that does not answer a new command is
    /// ([`LoopFault::NotResponding`], after `stall_time`). Only the driven
    /// cart's own encoder counts: the other cart's motion never stands in
    /// for it. It only excuses it: the other cart moving *against* the
    /// change of drive stretches the spring against it, which may be what
    /// holds the driven cart (a controller feeding back cart 1's position
    /// does that, Table 6's among them).
    ///
    /// Then [`check_follow`](Self::check_follow).
    pub(super) fn check_response(&mut self, counts: [i64; 2], now: f64) -> Result<(), RigError> {
        let cal = self.calibration;
        if self.motion.is_none() {
            // A run starts with the carts at rest.
            self.rest = Some(Rest {
                other: counts[OTHER],
                drive: self.volts,
                pushed: None,
            });
        }
        let (reference, drive, moved_at) = *self.motion.get_or_insert((counts, self.volts, now));
        let motion = counts[DRIVEN]
            .saturating_sub(reference[DRIVEN])
            .saturating_abs();
        if motion >= cal.stall_counts {
            self.motion = Some((counts, self.volts, now));
            self.stall = None;
            self.rest = None;
            self.quiet = None;
            return Ok(());
        }
        self.check_quiet(counts, moved_at, now)?;
        if self.rest.is_none() && now - moved_at >= cal.follow_time {
            self.rest = Some(Rest {
                other: counts[OTHER],
                drive: self.volts,
                pushed: None,
            });
        }
        self.check_follow(counts, now)?;
        let change = self.volts - drive;
        let other = counts[OTHER].saturating_sub(reference[OTHER]);
        if change.abs() < cal.stall_volts
            || along(other, cal.sign[OTHER], change) <= -cal.stall_counts
        {
            self.stall = None;
            return Ok(());
        }
        let stall = self.stall.get_or_insert(Episode {
            since: now,
            weakest: change.abs(),
        });
        stall.weakest = stall.weakest.min(change.abs());
        let Episode { since, weakest } = *stall;
        if now - since >= cal.stall_time {
            return self.fault(LoopFault::NotResponding {
                volts: weakest,
                seconds: now - since,
                counts: cal.stall_counts,
            });
        }
        Ok(())
    }

    /// The driven cart at rest must move when the drive changes by
    /// `stall_volts` and the other cart moves the way it pushes
    /// ([`LoopFault::EncoderNotFollowing`] after `follow_time`, see
    /// [`Calibration::follow_time`]). At rest the force on the driven cart,
    /// the drive's plus the spring's, is within its stiction; a change of
    /// drive of `stall_volts` (far more than the stiction) with the other
    /// cart pulling the spring the same way can only set it moving, and
    /// the other cart only moves after it: if its encoder stays still, the
    /// encoder is dead. (With the calibration's signs, a positive drive
    /// pushes cart 2 away from the wall, as the probe checks.) A cart that
    /// has just stopped is not at rest in this sense (the force that
    /// stopped it is still changing): the baseline is the run's first read,
    /// or the driven cart's encoder still for `follow_time`.
    pub(super) fn check_follow(&mut self, counts: [i64; 2], now: f64) -> Result<(), RigError> {
        let cal = self.calibration;
        let volts = self.volts;
        let Some(rest) = self.rest.as_mut() else {
            return Ok(());
        };
        let change = volts - rest.drive;
        if change.abs() < cal.stall_volts {
            rest.pushed = None;
            return Ok(());
        }
        let pushed = rest.pushed.get_or_insert(Episode {
            since: now,
            weakest: change.abs(),
        });
        pushed.weakest = pushed.weakest.min(change.abs());
        let Episode { since, weakest } = *pushed;
        let moved = along(
            counts[OTHER].saturating_sub(rest.other),
            cal.sign[OTHER],
            change,
        );
        if moved >= cal.stall_counts && now - since >= cal.follow_time {
            return self.fault(LoopFault::EncoderNotFollowing {
                cart: DRIVEN + 1,
                channel: cal.encoder_channels[DRIVEN],
                other: OTHER + 1,
                volts: weakest,
                seconds: now - since,
                moved,
                counts: cal.stall_counts,
            });
        }
        Ok(())
    }
}

/// How far the other cart (cart 1) must move within one
/// [`QUIET_WINDOW`] for [`MassSpringRig::check_quiet`], m: 1 mm.
const QUIET_DISTANCE: f64 = 0.001;

/// The window over which the other cart's motion is measured, as a
/// fraction of [`Calibration::stall_time`](crate::lab::Calibration::stall_time):
/// a fifth (0.1 s by default).
const QUIET_WINDOW: f64 = 0.2;

impl<P: EppPort> MassSpringRig<P> {
    /// The other cart (cart 1) keeps moving while the driven cart's
    /// encoder stays still, under a drive of either sign: the encoder is
    /// dead ([`LoopFault::EncoderNotFollowing`]), whatever the amplitude.
    /// [`check_follow`](Self::check_follow) needs a change of drive of
    /// `stall_volts` (6 V) from rest, so a dead encoder under a small drive
    /// (the 2 V and 4 V probe runs of `lab::ident_input`) went unnoticed,
    /// and its cart 2 read as a cart that does not move.
    ///
    /// Cart 1 moves only through the spring from cart 2. While cart 2 is
    /// held in its friction, cart 1 may still ring or settle for a while,
    /// but every millimetre it moves changes the spring's force on cart 2
    /// by about a newton (the lab's springs are about 1000 N/m, cart 2's
    /// stiction 2.4 N), so it cannot keep moving long without setting
    /// cart 2 moving too. The fault is: cart 2's encoder has not moved
    /// `stall_counts` for [`stall_time`](Calibration::stall_time) (0.5 s)
    /// and cart 1 moved at least [`QUIET_DISTANCE`] (1 mm) within the
    /// last [`QUIET_WINDOW`] of it (0.1 s), the drive not zero. Measured on
    /// the simulated default and a lighter-damped rig (square wave, PRBS,
    /// multisine, 1 to 8 V, five seeds): cart 2's encoder was still for at
    /// most 0.19 s while cart 1 had moved 1 mm since; with a dead encoder,
    /// cart 1 moves 1 mm within 0.05 to 0.15 s of a square wave that moves
    /// the carts at all (2 V on the lighter rig, 3 V on the default one,
    /// whose friction holds both carts at 2 V).
    ///
    /// [`Calibration`]: crate::lab::Calibration
    pub(super) fn check_quiet(
        &mut self,
        counts: [i64; 2],
        moved_at: f64,
        now: f64,
    ) -> Result<(), RigError> {
        let cal = self.calibration;
        let window = QUIET_WINDOW * cal.stall_time;
        let quiet = *self.quiet.get_or_insert((counts[OTHER], now));
        if now - quiet.1 < window {
            return Ok(());
        }
        self.quiet = Some((counts[OTHER], now));
        let threshold =
            ((QUIET_DISTANCE / cal.metres_per_count).ceil() as i64).max(cal.stall_counts);
        let moved = counts[OTHER].saturating_sub(quiet.0).saturating_abs();
        let seconds = now - moved_at;
        if moved >= threshold && seconds >= cal.stall_time && self.volts != 0.0 {
            return self.fault(LoopFault::EncoderNotFollowing {
                cart: DRIVEN + 1,
                channel: cal.encoder_channels[DRIVEN],
                other: OTHER + 1,
                volts: self.volts.abs(),
                seconds,
                moved,
                counts: cal.stall_counts,
            });
        }
        Ok(())
    }
}

/// How far a cart moved, `counts` with encoder sign `sign`, the way a
/// change of drive `change` (V) pushes: positive along it, negative
/// against it.
fn along(counts: i64, sign: f64, change: f64) -> i64 {
    if counts as f64 * sign * change > 0.0 {
        counts.saturating_abs()
    } else {
        -counts.saturating_abs()
    }
}
