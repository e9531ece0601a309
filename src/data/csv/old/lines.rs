//! The lines of a log before the CSV parser sees them: a UTF-8 byte-order
//! mark, line breaks (`\n`, `\r\n` or `\r`), comment lines (`#` or `%`) and
//! blank lines, the header line and the separator it shows.
//!
//! The parser sees content lines only, each ending in `\n`; [`Uncommented`]
//! remembers the lines it dropped, so an error names the file's own line.

use std::io::{self, BufRead, Read};

/// Where [`Uncommented`] is within a line.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum State {
    /// At the start of a line, holding its leading whitespace until it
    /// shows whether the line is blank, a comment or content.
    LineStart,
    /// In a content line: bytes pass through.
    Content,
    /// In a comment line: bytes are dropped up to its line break.
    Comment,
}

/// `inner` with its comment lines (first byte other than space or tab `#`
/// or `%`) and blank lines (spaces and tabs only) dropped, every line break
/// written `\n`, and a UTF-8 byte-order mark at its start dropped. Content
/// lines pass otherwise unchanged, leading whitespace included (in a
/// tab-separated file a leading tab is an empty first field).
pub(super) struct Uncommented<R> {
    inner: R,
    state: State,
    /// The last line break was a `\r`: a `\n` right after it is the same
    /// line break.
    after_cr: bool,
    /// Leading whitespace of the current line, and how much of it has been
    /// passed on.
    pending: Vec<u8>,
    flushed: usize,
    started: bool,
    /// The one-based number of the output line being written.
    out_line: u64,
    /// Lines dropped: `(output line, lines dropped before it in all)`, one
    /// entry per output line that follows dropped lines, in order.
    dropped: Vec<(u64, u64)>,
}

const BOM: &[u8] = b"\xef\xbb\xbf";

impl<R: BufRead> Uncommented<R> {
    pub(super) fn new(inner: R) -> Self {
        Self {
            inner,
            state: State::LineStart,
            after_cr: false,
            pending: Vec::new(),
            flushed: 0,
            started: false,
            out_line: 1,
            dropped: Vec::new(),
        }
    }
}

impl<R> Uncommented<R> {
    /// The file's one-based line number of output line `line`.
    pub(super) fn file_line(&self, line: u64) -> u64 {
        let k = self.dropped.partition_point(|&(at, _)| at <= line);
        line + k.checked_sub(1).map_or(0, |k| self.dropped[k].1)
    }

    /// How many lines were dropped in all.
    pub(super) fn dropped_lines(&self) -> u64 {
        self.dropped.last().map_or(0, |d| d.1)
    }
}

/// Counts one more dropped line before output line `out_line` in
/// [`Uncommented::dropped`].
fn drop_line(dropped: &mut Vec<(u64, u64)>, out_line: u64) {
    match dropped.last_mut() {
        Some(last) if last.0 == out_line => last.1 += 1,
        Some(&mut (_, total)) => dropped.push((out_line, total + 1)),
        None => dropped.push((out_line, 1)),
    }
}

/// Copies what fits of `pending[*flushed..]` to `out`; returns the count.
fn flush(pending: &[u8], flushed: &mut usize, out: &mut [u8]) -> usize {
    let n = (pending.len() - *flushed).min(out.len());
    out[..n].copy_from_slice(&pending[*flushed..*flushed + n]);
    *flushed += n;
    n
}

/// Where the first line break (`\n` or `\r`) in `bytes` is.
fn line_break(bytes: &[u8]) -> Option<usize> {
    bytes.iter().position(|&b| b == b'\n' || b == b'\r')
}

impl<R: BufRead> Read for Uncommented<R> {
    fn read(&mut self, out: &mut [u8]) -> io::Result<usize> {
        if !self.started {
            self.started = true;
            if self.inner.fill_buf()?.starts_with(BOM) {
                self.inner.consume(BOM.len());
            }
        }
        let mut w = 0;
        if self.state == State::Content && self.flushed < self.pending.len() {
            // A content line's leading whitespace that a full `out` cut short.
            w = flush(&self.pending, &mut self.flushed, out);
            if self.flushed < self.pending.len() {
                return Ok(w);
            }
            self.pending.clear();
        }
        loop {
            let buf = self.inner.fill_buf()?;
            if buf.is_empty() {
                // The end. A last line without a line break that was blank
                // or a comment is dropped too.
                if self.state == State::Comment
                    || (self.state == State::LineStart && !self.pending.is_empty())
                {
                    self.state = State::LineStart;
                    self.pending.clear();
                    drop_line(&mut self.dropped, self.out_line);
                }
                return Ok(w);
            }
            let mut i = 0;
            while i < buf.len() && w < out.len() {
                let b = buf[i];
                if std::mem::take(&mut self.after_cr) && b == b'\n' {
                    // The `\n` of a `\r\n`, already counted.
                    i += 1;
                    continue;
                }
                match self.state {
                    State::Content => {
                        let rest = &buf[i..];
                        let end = line_break(rest);
                        let n = end.unwrap_or(rest.len()).min(out.len() - w);
                        out[w..w + n].copy_from_slice(&rest[..n]);
                        w += n;
                        i += n;
                        if end == Some(n) && w < out.len() {
                            self.after_cr = rest[n] == b'\r';
                            out[w] = b'\n';
                            w += 1;
                            i += 1;
                            self.out_line += 1;
                            self.state = State::LineStart;
                        }
                    }
                    State::Comment => match line_break(&buf[i..]) {
                        Some(p) => {
                            i += p;
                            self.after_cr = buf[i] == b'\r';
                            i += 1;
                            self.state = State::LineStart;
                            drop_line(&mut self.dropped, self.out_line);
                        }
                        None => i = buf.len(),
                    },
                    State::LineStart => match b {
                        b' ' | b'\t' => {
                            self.pending.push(b);
                            i += 1;
                        }
                        b'\n' | b'\r' => {
                            self.after_cr = b == b'\r';
                            self.pending.clear();
                            drop_line(&mut self.dropped, self.out_line);
                            i += 1;
                        }
                        b'#' | b'%' => {
                            self.pending.clear();
                            self.state = State::Comment;
                            i += 1;
                        }
                        _ => {
                            self.state = State::Content;
                            self.flushed = 0;
                            w += flush(&self.pending, &mut self.flushed, &mut out[w..]);
                            if self.flushed < self.pending.len() {
                                break;
                            }
                            self.pending.clear();
                        }
                    },
                }
            }
            self.inner.consume(i);
            // Only what this read could take without waiting for more input
            // (a comment that filled the whole buffer gave nothing yet).
            if w > 0 {
                return Ok(w);
            }
        }
    }
}

/// The header line of a log, as read from an [`Uncommented`] stream.
pub(super) struct HeaderLine {
    /// The line as read, with its `\n`. The CSV parser reads it again.
    pub(super) bytes: Vec<u8>,
}

impl HeaderLine {
    /// Reads the first line of `lines`: the header, the comment and blank
    /// lines before it being dropped. `None` when there is none.
    pub(super) fn read(lines: &mut impl BufRead) -> io::Result<Option<Self>> {
        let mut bytes = Vec::new();
        Ok((lines.read_until(b'\n', &mut bytes)? > 0).then_some(Self { bytes }))
    }

    /// The header line as found, without its line break.
    pub(super) fn text(&self) -> &[u8] {
        self.bytes.strip_suffix(b"\n").unwrap_or(&self.bytes)
    }

    /// The separator the header line shows: a tab if it holds one, else `;`
    /// if it holds one, else `,`. A header holding a comma is
    /// comma-separated whatever else it holds: a name or unit cannot hold a
    /// comma, so no `;` or tab header has one, and a comma header with
    /// fields padded by tabs reads as it did before the reader knew other
    /// separators.
    pub(super) fn separator(&self) -> u8 {
        let header = self.text();
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
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `text` through [`Uncommented`], read `chunk` bytes at a time from a
    /// reader that hands out `fill` bytes at a time; and the filter.
    fn filtered(text: &[u8], fill: usize, chunk: usize) -> (Vec<u8>, Uncommented<impl BufRead>) {
        let inner = io::BufReader::with_capacity(fill, text);
        let mut f = Uncommented::new(inner);
        let mut out = Vec::new();
        let mut buf = vec![0; chunk];
        loop {
            let n = f.read(&mut buf).unwrap();
            if n == 0 {
                return (out, f);
            }
            out.extend_from_slice(&buf[..n]);
        }
    }

    #[test]
    fn comments_and_blank_lines_are_dropped_and_counted() {
        let text = b"\xef\xbb\xbf# lab 5\r\n% group 3\n\n  \t\r\nt_s,u\r\n  # late\n0,1\r\r\n\t1,2\n  3,4 # not a comment\n%";
        let want = "t_s,u\n0,1\n\t1,2\n  3,4 # not a comment\n";
        for fill in [3, 4, 5, 7, 64] {
            for chunk in [1, 2, 7, 64] {
                let (out, f) = filtered(text, fill, chunk);
                assert_eq!(
                    String::from_utf8_lossy(&out),
                    want,
                    "fill {fill}, chunk {chunk}"
                );
                // Output lines 1-4 are the file's lines 5, 7, 9 and 10
                // (line 8 is the empty line of `\r\r\n`); 11 is dropped.
                let lines: Vec<u64> = (1..=4).map(|k| f.file_line(k)).collect();
                assert_eq!(lines, [5, 7, 9, 10], "fill {fill}, chunk {chunk}");
                assert_eq!(f.dropped_lines(), 7);
            }
        }
        // Content without a final line break, and a final blank line.
        assert_eq!(filtered(b"a\n  ", 64, 64).0, b"a\n");
        assert_eq!(filtered(b"a\n b", 64, 64).0, b"a\n b");
        // Old Mac line breaks.
        let (out, f) = filtered(b"a\r\rb\rc", 64, 64);
        assert_eq!(
            (out.as_slice(), f.file_line(2), f.file_line(3)),
            (&b"a\nb\nc"[..], 3, 4)
        );
    }

    #[test]
    fn the_header_line_and_its_separator() {
        let read = |text: &[u8]| {
            let mut lines = io::BufReader::new(Uncommented::new(text));
            HeaderLine::read(&mut lines).unwrap()
        };
        let h = read(b"# c\n\nt_s;u\r\n0;1\n").unwrap();
        assert_eq!((h.text(), h.separator()), (&b"t_s;u"[..], b';'));
        assert_eq!(h.bytes, b"t_s;u\n");
        assert_eq!(read(b"t [s]\tu [V]\n").unwrap().separator(), b'\t');
        assert_eq!(read(b"t;s\tu\n").unwrap().separator(), b'\t');
        assert_eq!(read(b"t_s\t,u;x\n").unwrap().separator(), b',');
        assert_eq!(read(b"t_s").unwrap().separator(), b',');
        assert!(read(b"# only\n\n%\n").is_none());
        assert!(read(b"").is_none());
    }
}
