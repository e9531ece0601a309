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
            return Ok(());
        }
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
