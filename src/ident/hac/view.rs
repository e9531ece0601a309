//! How the passes see one segment of a series at a time: a stored one in
//! place ([`Direct`]), one handed out in blocks through a window of rows
//! ([`Windowed`]).

use super::Series;

/// How the passes see one segment of a series at a time: rows `from ..
/// to` of a column, made present first by [`ensure`](Self::ensure).
pub(super) trait View {
    fn begin(&mut self, start: usize, len: usize);
    /// Makes rows `from .. to` of the segment present (`from` never less
    /// than an earlier call's, `to − from` at most the window's room).
    fn ensure(&mut self, from: usize, to: usize);
    fn col(&self, j: usize, from: usize, to: usize) -> &[f64];
}

/// A stored series, read in place.
pub(super) struct Direct<'a> {
    pub x: &'a [f64],
    pub n: usize,
    pub start: usize,
}

impl View for Direct<'_> {
    fn begin(&mut self, start: usize, _len: usize) {
        self.start = start;
    }
    fn ensure(&mut self, _from: usize, _to: usize) {}
    fn col(&self, j: usize, from: usize, to: usize) -> &[f64] {
        let at = j * self.n + self.start;
        &self.x[at + from..at + to]
    }
}

/// A series handed out in blocks, through a [`Window`] of `cap` rows.
pub(super) struct Windowed<'a, S> {
    pub source: &'a mut S,
    pub window: &'a mut Window,
    pub p: usize,
    pub cap: usize,
}

impl<S: Series> View for Windowed<'_, S> {
    fn begin(&mut self, start: usize, len: usize) {
        self.window.begin(self.p, self.cap, start, len);
    }
    fn ensure(&mut self, from: usize, to: usize) {
        self.window.ensure(self.source, from, to);
    }
    fn col(&self, j: usize, from: usize, to: usize) -> &[f64] {
        self.window.col(j, from, to)
    }
}

/// Rows `lo .. hi` of one segment of a series, per column (`cap` rows
/// each), read ahead from the source as far as they fit.
#[derive(Debug, Clone, Default)]
pub(crate) struct Window {
    buf: Vec<f64>,
    p: usize,
    cap: usize,
    lo: usize,
    hi: usize,
    /// The segment: its first row in the series, and its length.
    start: usize,
    len: usize,
}

impl Window {
    pub(super) fn begin(&mut self, p: usize, cap: usize, start: usize, len: usize) {
        self.buf.resize(p * cap, 0.0);
        (self.p, self.cap, self.start, self.len) = (p, cap, start, len);
        (self.lo, self.hi) = (0, 0);
    }

    /// Makes rows `from .. to` of the segment present (`from` never less
    /// than an earlier call's, `to − from ≤ cap`).
    pub(super) fn ensure(&mut self, source: &mut impl Series, from: usize, to: usize) {
        debug_assert!(from >= self.lo && to <= self.len && to - from <= self.cap);
        if to <= self.hi {
            return;
        }
        if to > self.lo + self.cap {
            let keep = from.min(self.hi);
            for j in 0..self.p {
                let at = j * self.cap;
                self.buf
                    .copy_within(at + keep - self.lo..at + self.hi - self.lo, at);
            }
            self.lo = keep;
        }
        let end = self.len.min(self.lo + self.cap);
        let offset = self.hi - self.lo;
        source.fill(
            self.start + self.hi,
            end - self.hi,
            &mut self.buf[offset..],
            self.cap,
        );
        self.hi = end;
    }

    /// Rows `from .. to` of column `j`.
    pub(super) fn col(&self, j: usize, from: usize, to: usize) -> &[f64] {
        &self.buf[j * self.cap + from - self.lo..j * self.cap + to - self.lo]
    }
}
