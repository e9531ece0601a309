//! Rows read by several threads at once: a block of whole lines is cut at
//! line breaks into a part per thread; the lines of each part are counted,
//! so each thread's rows have their place in the columns, and every thread
//! reads its part on the fast path into that place. The parts are then
//! taken in order, as one thread would have read them: a part's first
//! time must follow the part before, and a part that stops (a comment, a
//! value the fast path leaves to the general path, a time that does not
//! increase) ends the block there; the general path reads on from that
//! row, so errors and values are the single-threaded read's, bit for bit.

use std::sync::mpsc;
use std::thread::Builder;

use super::columns::{Columns, Part, Sink};
use super::fast::{Fast, Stop, follows};

/// How many threads read a large file at most.
const MAX_WORKERS: usize = 8;

/// The bytes of rows each thread reads of a block, for a large file.
const PART: usize = 2 << 20;

/// A file shorter than this is read on one thread: starting threads
/// would cost more than they save.
const PARALLEL_FROM: u64 = 4 << 20;

/// How a read goes: which path reads the usual rows, on how many threads.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct Pace {
    /// Whether rows as a logger writes them are read on the fast path
    /// (else all on the general path).
    pub(super) fast: bool,
    /// Threads reading a block of rows (1: the calling thread alone).
    pub(super) workers: usize,
    /// Bytes of rows per thread in a block.
    pub(super) part: usize,
}

impl Pace {
    /// Every row on the general path.
    #[cfg(test)]
    pub(super) const GENERAL: Self = Self {
        fast: false,
        workers: 1,
        part: PART,
    };

    /// The usual rows on the fast path, on the calling thread.
    pub(super) const FAST: Self = Self {
        fast: true,
        workers: 1,
        part: PART,
    };

    /// For a file of `size` bytes: a thread per CPU (at most
    /// [`MAX_WORKERS`]) for a large file, else [`FAST`](Self::FAST).
    pub(super) fn for_size(size: Option<u64>) -> Self {
        match size {
            Some(size) if size >= PARALLEL_FROM => Self {
                workers: std::thread::available_parallelism()
                    .map_or(1, |n| n.get())
                    .min(MAX_WORKERS),
                ..Self::FAST
            },
            _ => Self::FAST,
        }
    }

    /// The threads that read the usual rows: `workers` on the fast path,
    /// else the calling thread alone.
    fn threads(&self) -> usize {
        if self.fast { self.workers.max(1) } else { 1 }
    }

    /// The reading buffer's size, bytes: a block of parts when several
    /// threads read, else `chunk`.
    pub(super) fn buffer(&self, chunk: usize) -> usize {
        match self.threads() {
            1 => chunk,
            threads => threads.saturating_mul(self.part).max(chunk),
        }
    }
}

/// The threads' readers, one [`Fast`] each.
pub(super) struct Parallel {
    fasts: Vec<Fast>,
    part: usize,
    /// Off once a block stopped early: a file with comments or unusual rows
    /// is read on the calling thread from there, each byte once.
    on: bool,
}

impl Parallel {
    /// The readers for `pace`'s threads; none (and off) for one thread,
    /// whose rows [`Fast::rows`] reads.
    pub(super) fn new(fast: &Fast, pace: Pace) -> Self {
        let threads = pace.threads();
        let on = threads > 1;
        Self {
            fasts: if on {
                (0..threads).map(|_| fast.for_thread()).collect()
            } else {
                Vec::new()
            },
            part: pace.part.max(1),
            on,
        }
    }

    /// Reads the whole lines at the start of `bytes` into `cols`, a part
    /// on each thread, as [`Fast::rows`] would read them: how many bytes
    /// and lines (one a row) were read, and why it stopped. `None` when it
    /// does not apply (one thread, less than a part of whole lines, or no
    /// thread could start): then [`Fast::rows`] reads them.
    pub(super) fn rows(&mut self, bytes: &[u8], cols: &mut Columns) -> Option<(usize, u64, Stop)> {
        if !self.on || bytes.len() < self.part {
            return None;
        }
        let Some(last) = memchr::memrchr(b'\n', bytes) else {
            // A part's worth and no `\n`: `\r` line breaks, or a line
            // longer than a part, for the calling thread (searched once).
            self.on = false;
            return None;
        };
        let end = last + 1;
        if end < self.part {
            return None;
        }
        let block = &bytes[..end];
        let pieces = cut(block, self.fasts.len());
        let Some((read, counts)) = on_threads(&pieces, &mut self.fasts, cols) else {
            // No thread started: the calling thread reads on alone.
            self.on = false;
            return None;
        };
        // The parts in order, as one thread reads them.
        let mut before = cols.last_time();
        let (mut taken, mut rows) = (0, 0);
        let mut stop = Stop::Partial;
        for (&(bytes, lines, times), &count) in read.iter().zip(&counts) {
            if let Some((first, last)) = times {
                if before.is_some_and(|before| !follows(before, first)) {
                    stop = Stop::Unusual;
                    break;
                }
                before = Some(last);
            }
            taken += bytes;
            rows += lines;
            if lines < count as u64 {
                stop = Stop::Unusual;
                break;
            }
        }
        if stop == Stop::Unusual {
            self.on = false;
        }
        cols.advance(rows as usize);
        Some((taken, rows, stop))
    }
}

/// `block` (whole lines) cut at line breaks into `n` pieces of about the
/// same length (some may be empty).
fn cut(block: &[u8], n: usize) -> Vec<&[u8]> {
    let mut pieces = Vec::with_capacity(n);
    let mut start = 0;
    for i in 1..n {
        let from = (block.len() / n * i).max(start);
        let end = memchr::memchr(b'\n', &block[from..]).map_or(block.len(), |k| from + k + 1);
        pieces.push(&block[start..end]);
        start = end;
    }
    pieces.push(&block[start..]);
    pieces
}

/// How many `\n` `bytes` holds.
fn line_breaks(bytes: &[u8]) -> usize {
    memchr::memchr_iter(b'\n', bytes).count()
}

/// What a thread read of its piece: bytes, lines (one a row), and the
/// first and last time.
type Read = (usize, u64, Option<(f64, f64)>);

/// Reads `pieces` into the room after the rows of `cols`, the first on the
/// calling thread, each other on a thread of its own: each thread counts
/// its piece's lines, the calling thread cuts the room into parts of those
/// lengths and hands them out, and each reads its piece into its part.
/// What each read, and the counts; `None` when a thread cannot start.
fn on_threads(
    pieces: &[&[u8]],
    fasts: &mut [Fast],
    cols: &mut Columns,
) -> Option<(Vec<Read>, Vec<usize>)> {
    let (first, others) = fasts.split_first_mut()?;
    std::thread::scope(|scope| {
        let mut links = Vec::with_capacity(others.len());
        for (&piece, fast) in pieces.iter().skip(1).zip(others) {
            let (count_tx, count_rx) = mpsc::sync_channel(1);
            let (part_tx, part_rx) = mpsc::sync_channel::<Vec<&mut [f64]>>(1);
            let handle = Builder::new()
                .spawn_scoped(scope, move || {
                    let count = line_breaks(piece);
                    count_tx.send(count).ok()?;
                    // No part comes when the calling thread gave up.
                    let part = part_rx.recv().ok()?;
                    Some(read_part(fast, piece, part, count))
                })
                .ok()?;
            links.push((count_rx, part_tx, handle));
        }
        let mut counts = Vec::with_capacity(pieces.len());
        counts.push(line_breaks(pieces.first()?));
        for (count_rx, _, _) in &links {
            counts.push(count_rx.recv().ok()?);
        }
        let mut parts = cols.parts(&counts).into_iter();
        let mine = parts.next()?;
        for ((_, part_tx, _), part) in links.iter().zip(parts) {
            part_tx.send(part).ok()?;
        }
        let mut read = Vec::with_capacity(pieces.len());
        read.push(read_part(first, pieces.first()?, mine, counts[0]));
        for (_, _, handle) in links {
            let got = handle
                .join()
                .unwrap_or_else(|panic| std::panic::resume_unwind(panic));
            read.push(got?);
        }
        Some((read, counts))
    })
}

/// Reads the `count` lines of `piece` into `cols` (a slice per channel).
fn read_part(fast: &mut Fast, piece: &[u8], cols: Vec<&mut [f64]>, count: usize) -> Read {
    let mut sink = Part { cols, len: 0 };
    let (bytes, lines, _) = fast.rows(piece, &mut sink, count);
    (bytes, lines, sink.times())
}
