//! The lines of a log, read once: a UTF-8 byte-order mark, line breaks
//! (`\n`, `\r\n` or `\r`), comment lines (`#` or `%`) and blank lines, and
//! the separator the header line shows.
//!
//! [`Lines`] hands out the file's lines in place, in its own buffer, each
//! with its number and what it is; the reader feeds the content lines to the
//! CSV tokenizer and skips the others, so a line number is the file's own.
//! The reader's fast path reads whole rows from what is buffered
//! ([`Lines::pending`]) and hands them out in one step ([`Lines::skip`]).

use std::io::{self, Read};
use std::ops::Range;

const BOM: &[u8] = b"\xef\xbb\xbf";

/// How much is read from the source at a time, usually.
pub(super) const CHUNK: usize = 64 * 1024;

/// What a line of a log is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Kind {
    /// Spaces and tabs only, or nothing: skipped.
    Blank,
    /// Its first byte other than space or tab is `#` or `%`: skipped.
    Comment,
    /// Anything else: the header or a row (or part of a quoted field).
    Content,
}

/// One line of a log, in [`Lines::bytes`].
#[derive(Debug, Clone, PartialEq, Eq)]
pub(super) struct Line {
    /// Where it is, with its line break (`\n` or `\r`; not the `\n` of a
    /// `\r\n`) if it has one: the last line of a file may have none.
    pub(super) range: Range<usize>,
    /// The file's one-based line number.
    pub(super) number: u64,
    pub(super) kind: Kind,
    /// Whether `range` ends with a line break.
    pub(super) has_break: bool,
}

/// What a line is, from its bytes without the line break.
fn kind(line: &[u8]) -> Kind {
    match line.iter().find(|&&b| b != b' ' && b != b'\t') {
        None => Kind::Blank,
        Some(b'#' | b'%') => Kind::Comment,
        Some(_) => Kind::Content,
    }
}

/// The lines of `inner`, split at `\n`, `\r\n` or `\r`, a UTF-8 byte-order
/// mark at its start dropped. A last line without a line break is a line if
/// it holds anything.
pub(super) struct Lines<R> {
    inner: R,
    buf: Vec<u8>,
    /// The first byte not handed out yet, and the end of what was read.
    pos: usize,
    end: usize,
    /// Bytes dropped from the front of `buf` so far.
    dropped: u64,
    eof: bool,
    /// The last line break was a `\r`: a `\n` right after it belongs to it.
    after_cr: bool,
    started: bool,
    /// The number of the last line handed out.
    line: u64,
}

impl<R: Read> Lines<R> {
    /// The lines of `inner`, read `capacity` bytes at a time (at least 4;
    /// [`CHUNK`] usually); the buffer grows for a longer line.
    pub(super) fn with_capacity(inner: R, capacity: usize) -> Self {
        Self {
            inner,
            buf: vec![0; capacity.max(4)],
            pos: 0,
            end: 0,
            dropped: 0,
            eof: false,
            after_cr: false,
            started: false,
            line: 0,
        }
    }

    /// The bytes of a [`Line`] just handed out (valid until the next call
    /// to [`next`](Self::next)).
    pub(super) fn bytes(&self, range: Range<usize>) -> &[u8] {
        &self.buf[range]
    }

    /// The number of the last line handed out (0 before the first).
    pub(super) fn line(&self) -> u64 {
        self.line
    }

    /// How many bytes of the source have been handed out or skipped.
    pub(super) fn consumed(&self) -> u64 {
        self.dropped + self.pos as u64
    }

    /// What is read and not handed out yet, for the reader's fast path
    /// (the `\n` of a `\r\n` already handed out dropped): `None` before
    /// the first line, or after a `\r` at the end of what is read, whose
    /// `\n` may come next ([`next`](Self::next) drops it).
    pub(super) fn pending(&mut self) -> Option<&[u8]> {
        if self.after_cr && self.pos < self.end {
            self.after_cr = false;
            if self.buf[self.pos] == b'\n' {
                self.pos += 1;
            }
        }
        (self.started && !self.after_cr).then(|| &self.buf[self.pos..self.end])
    }

    /// Hands out the first `bytes` of [`pending`](Self::pending): `lines`
    /// whole lines, each ending in `\n`.
    pub(super) fn skip(&mut self, bytes: usize, lines: u64) {
        self.pos += bytes;
        self.line += lines;
    }

    /// Reads more of the source after what is pending; false at its end.
    pub(super) fn more(&mut self) -> io::Result<bool> {
        if !self.eof {
            self.refill()?;
        }
        Ok(!self.eof)
    }

    /// Moves what is not handed out yet to the front of the buffer, growing
    /// it when full, and reads more after it. At the end of the source sets
    /// `eof`.
    fn refill(&mut self) -> io::Result<()> {
        if self.pos > 0 {
            self.buf.copy_within(self.pos..self.end, 0);
            self.dropped += self.pos as u64;
            self.end -= self.pos;
            self.pos = 0;
        }
        if self.end == self.buf.len() {
            self.buf.resize(2 * self.buf.len(), 0);
        }
        loop {
            match self.inner.read(&mut self.buf[self.end..]) {
                Ok(0) => {
                    self.eof = true;
                    return Ok(());
                }
                Ok(n) => {
                    self.end += n;
                    return Ok(());
                }
                Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
                Err(e) => return Err(e),
            }
        }
    }

    /// The next line, or `None` at the end.
    pub(super) fn next(&mut self) -> io::Result<Option<Line>> {
        if !self.started {
            while self.end - self.pos < BOM.len() && !self.eof {
                self.refill()?;
            }
            self.started = true;
            if self.buf[self.pos..self.end].starts_with(BOM) {
                self.pos += BOM.len();
            }
        }
        if self.after_cr {
            if self.pos == self.end && !self.eof {
                self.refill()?;
            }
            self.after_cr = false;
            if self.pos < self.end && self.buf[self.pos] == b'\n' {
                self.pos += 1;
            }
        }
        // Searched so far, from `pos`: a long line is searched once.
        let mut searched = 0;
        loop {
            let from = self.pos + searched;
            if let Some(k) = memchr::memchr2(b'\n', b'\r', &self.buf[from..self.end]) {
                let at = from + k;
                let line = Line {
                    range: self.pos..at + 1,
                    number: self.line + 1,
                    kind: kind(&self.buf[self.pos..at]),
                    has_break: true,
                };
                self.after_cr = self.buf[at] == b'\r';
                self.pos = at + 1;
                self.line += 1;
                return Ok(Some(line));
            }
            searched = self.end - self.pos;
            if self.eof {
                if self.pos == self.end {
                    return Ok(None);
                }
                let line = Line {
                    range: self.pos..self.end,
                    number: self.line + 1,
                    kind: kind(&self.buf[self.pos..self.end]),
                    has_break: false,
                };
                self.pos = self.end;
                self.line += 1;
                return Ok(Some(line));
            }
            self.refill()?;
        }
    }
}

/// A line without its line break.
pub(super) fn without_break(line: &[u8]) -> &[u8] {
    match line {
        [rest @ .., b'\n' | b'\r'] => rest,
        _ => line,
    }
}

/// The separator a header line (without its line break) shows: a tab if it
/// holds one, else `;` if it holds one, else `,`. A header holding a comma
/// is comma-separated whatever else it holds: a name or unit cannot hold a
/// comma, so no `;` or tab header has one, and a comma header with fields
/// padded by tabs reads as it did before the reader knew other separators.
pub(super) fn separator(header: &[u8]) -> u8 {
    if header.contains(&b',') {
        b','
    } else if header.contains(&b'\t') {
        b'\t'
    } else if header.contains(&b';') {
        b';'
    } else {
        b','
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A reader that hands out at most `n` bytes a read.
    struct Trickle<'a>(&'a [u8], usize);

    impl Read for Trickle<'_> {
        fn read(&mut self, out: &mut [u8]) -> io::Result<usize> {
            let n = self.0.len().min(out.len()).min(self.1);
            out[..n].copy_from_slice(&self.0[..n]);
            self.0 = &self.0[n..];
            Ok(n)
        }
    }

    /// Every line of `text` as (number, kind, bytes), reading `fill` bytes
    /// at a time into a buffer of `capacity`.
    fn lines(text: &[u8], fill: usize, capacity: usize) -> Vec<(u64, Kind, String)> {
        let mut lines = Lines::with_capacity(Trickle(text, fill), capacity);
        let mut out = Vec::new();
        while let Some(line) = lines.next().unwrap() {
            let bytes = lines.bytes(line.range);
            out.push((
                line.number,
                line.kind,
                String::from_utf8_lossy(bytes).into_owned(),
            ));
            assert_eq!(lines.line(), line.number);
        }
        assert_eq!(lines.consumed(), text.len() as u64);
        out
    }

    #[test]
    fn comments_and_blank_lines_are_told_from_content_and_counted() {
        use Kind::{Blank, Comment, Content};
        let text = b"\xef\xbb\xbf# lab 5\r\n% group 3\n\n  \t\r\nt_s,u\r\n  # late\n0,1\r\r\n\t1,2\n  3,4 # not a comment\n%";
        let want = vec![
            (1, Comment, "# lab 5\r".to_string()),
            (2, Comment, "% group 3\n".into()),
            (3, Blank, "\n".into()),
            (4, Blank, "  \t\r".into()),
            (5, Content, "t_s,u\r".into()),
            (6, Comment, "  # late\n".into()),
            (7, Content, "0,1\r".into()),
            (8, Blank, "\r".into()),
            (9, Content, "\t1,2\n".into()),
            (10, Content, "  3,4 # not a comment\n".into()),
            (11, Comment, "%".into()),
        ];
        for fill in [1, 2, 3, 5, 7, 64] {
            for capacity in [4, 5, 8, 64] {
                assert_eq!(
                    lines(text, fill, capacity),
                    want,
                    "fill {fill}, capacity {capacity}"
                );
            }
        }
        // A last line without a line break; a final line break ends the
        // last line, it does not start an empty one.
        let kinds = |t: &[u8]| -> Vec<Kind> { lines(t, 64, 64).iter().map(|l| l.1).collect() };
        assert_eq!(kinds(b"a\n  "), [Content, Blank]);
        assert_eq!(kinds(b"a\n b"), [Content, Content]);
        assert_eq!(kinds(b"a\n"), [Content]);
        assert_eq!(kinds(b""), []);
        assert_eq!(kinds(b"\xef\xbb\xbf"), []);
        assert_eq!(kinds(b"\n"), [Blank]);
        // Old Mac line breaks, and a `\r\n` split across reads.
        let got = lines(b"a\r\rb\rc", 64, 64);
        assert_eq!(got.iter().map(|l| l.0).collect::<Vec<_>>(), [1, 2, 3, 4]);
        assert_eq!(lines(b"a\r\nb", 2, 4)[1], (2, Content, "b".into()));
        // Only one byte-order mark is dropped, and only at the start.
        assert_eq!(lines(b"\xef\xbb\xbf\xef\xbb\xbfx", 1, 4)[0].2, "\u{feff}x");
        assert_eq!(lines(b"x\n\xef\xbb\xbf", 1, 4)[1].2, "\u{feff}");
    }

    #[test]
    fn long_lines_grow_the_buffer() {
        let long = "x".repeat(1000);
        let text = format!("{long}\n{long}\r\n# {long}\n");
        let got = lines(text.as_bytes(), 7, 4);
        assert_eq!(got.len(), 3);
        assert_eq!(got[0].2, format!("{long}\n"));
        assert_eq!(got[1].2, format!("{long}\r"));
        assert_eq!(got[2].1, Kind::Comment);
    }

    #[test]
    fn the_separator_a_header_shows() {
        assert_eq!(separator(b"t_s;u"), b';');
        assert_eq!(separator(b"t [s]\tu [V]"), b'\t');
        assert_eq!(separator(b"t;s\tu"), b'\t');
        assert_eq!(separator(b"t_s\t,u;x"), b',');
        assert_eq!(separator(b"t_s"), b',');
        assert_eq!(without_break(b"t_s;u\r"), b"t_s;u");
        assert_eq!(without_break(b"t_s;u\n"), b"t_s;u");
        assert_eq!(without_break(b"t_s;u"), b"t_s;u");
    }
}
