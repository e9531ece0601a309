//! The last few reads, from which speeds are differenced.

/// One read of the counters: the counts, its time stamp (s on the rig's
/// clock, the middle of the instants bracketing the latch) and the
/// earliest the latch can have been.
#[derive(Debug, Clone, Copy)]
pub(super) struct Read {
    pub(super) counts: [i64; 2],
    pub(super) stamp: f64,
    pub(super) earliest: f64,
}

/// Reads kept for the speeds: the loop needs two (the read two ticks back
/// is always over a period old); four leave room for reads between ticks.
pub(super) const HISTORY: usize = 4;

/// The last [`HISTORY`] reads, newest at `newest`, in a fixed ring.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct History {
    reads: [Option<Read>; HISTORY],
    newest: usize,
}

impl History {
    pub(super) fn push(&mut self, read: Read) {
        self.newest = (self.newest + 1) % HISTORY;
        self.reads[self.newest] = Some(read);
    }

    /// The newest read at least `min_age` older than `now`, else the
    /// oldest read stored (`None` when there is none).
    pub(super) fn base(&self, now: f64, min_age: f64) -> Option<Read> {
        let mut oldest = None;
        for back in 0..HISTORY {
            let Some(read) = self.reads[(self.newest + HISTORY - back) % HISTORY] else {
                break;
            };
            if now - read.stamp >= min_age {
                return Some(read);
            }
            oldest = Some(read);
        }
        oldest
    }
}
