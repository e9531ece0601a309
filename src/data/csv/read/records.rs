//! The records of a log for the general path: content lines split into
//! fields by `csv-core`, or in place when a line holds no quote.

use std::io::Read;

use csv_core::ReadRecordResult;

use super::super::lines::{Kind, Line, Lines};

/// The records of a log: its content lines, fed one by one to `csv-core`,
/// which splits them into fields. A record is one line, or more when a
/// quoted field holds a line break; comment and blank lines are skipped
/// wherever they are, so the tokenizer sees what the reader before the
/// port to `csv-core` gave the `csv` crate: content lines, each ending in a
/// line break. A row without a quote (the usual row) is split at the
/// separator in place ([`split`]): the same fields, a tenth fewer
/// instructions a row, no copy.
pub(super) struct Records<R> {
    pub(super) lines: Lines<R>,
    core: csv_core::Reader,
    separator: u8,
    /// The tokenizer's output: fields back to back, and where each ends.
    fields: Vec<u8>,
    ends: Vec<usize>,
    /// The current record: where its bytes are (`None`: the first `out`
    /// bytes of `fields`; else a line, in `lines`), and where each of its
    /// fields is in them.
    line: Option<std::ops::Range<usize>>,
    out: usize,
    bounds: Vec<(usize, usize)>,
}

impl<R: Read> Records<R> {
    pub(super) fn new(lines: Lines<R>, separator: u8) -> Self {
        Self {
            lines,
            core: csv_core::ReaderBuilder::new().delimiter(separator).build(),
            separator,
            fields: vec![0; 1024],
            ends: vec![0; 64],
            line: None,
            out: 0,
            bounds: Vec::new(),
        }
    }

    /// The next content line, or `None` at the end.
    fn content_line(&mut self) -> std::io::Result<Option<Line>> {
        loop {
            match self.lines.next()? {
                Some(line) if line.kind != Kind::Content => {}
                other => return Ok(other),
            }
        }
    }

    /// Reads the next record, starting with `first` when given (a content
    /// line already read); returns the file's line it starts on, or `None`
    /// at the end.
    pub(super) fn next(&mut self, mut first: Option<Line>) -> std::io::Result<Option<u64>> {
        let at_header = first.is_some();
        let (mut out, mut end) = (0, 0);
        let mut start = None;
        loop {
            let line = match first.take() {
                Some(line) => Some(line),
                None => self.content_line()?,
            };
            let Some(line) = line else {
                // The end of the input: a last record without a line break.
                loop {
                    let (res, _, _, n) =
                        self.core
                            .read_record(&[], &mut self.fields[out..], &mut self.ends[end..]);
                    end += n;
                    match res {
                        ReadRecordResult::Record => {
                            self.tokenized(end, out);
                            return Ok(Some(start.unwrap_or(self.lines.line())));
                        }
                        ReadRecordResult::OutputEndsFull => grow(&mut self.ends),
                        ReadRecordResult::OutputFull => grow(&mut self.fields),
                        ReadRecordResult::End | ReadRecordResult::InputEmpty => return Ok(None),
                    }
                }
            };
            if start.is_none() && !at_header {
                let range = line.range.start..line.range.end - usize::from(line.has_break);
                if split(
                    self.lines.bytes(range.clone()),
                    self.separator,
                    &mut self.bounds,
                ) {
                    self.line = Some(range);
                    return Ok(Some(line.number));
                }
            }
            start.get_or_insert(line.number);
            let bytes = self.lines.bytes(line.range);
            let mut input = bytes;
            loop {
                let (res, nin, nout, n) =
                    self.core
                        .read_record(input, &mut self.fields[out..], &mut self.ends[end..]);
                input = &input[nin..];
                out += nout;
                end += n;
                match res {
                    ReadRecordResult::InputEmpty => break,
                    ReadRecordResult::OutputFull => grow(&mut self.fields),
                    ReadRecordResult::OutputEndsFull => grow(&mut self.ends),
                    ReadRecordResult::Record => {
                        self.tokenized(end, out);
                        return Ok(Some(start.unwrap_or(line.number)));
                    }
                    ReadRecordResult::End => return Ok(None),
                }
            }
            // A line break in a quoted field: the tokenizer copied a `\r`
            // where the file has `\r` or `\r\n`; it stands for `\n`, as
            // any line break.
            if bytes.last() == Some(&b'\r') && out > 0 && self.fields[out - 1] == b'\r' {
                self.fields[out - 1] = b'\n';
            }
        }
    }

    /// Takes the record the tokenizer wrote: `len` fields in `out` bytes.
    fn tokenized(&mut self, len: usize, out: usize) {
        self.bounds.clear();
        let mut from = 0;
        for &end in &self.ends[..len] {
            self.bounds.push((from, end));
            from = end;
        }
        self.line = None;
        self.out = out;
    }

    /// The number of fields of the current record.
    pub(super) fn len(&self) -> usize {
        self.bounds.len()
    }

    /// The current record's bytes.
    #[inline(always)]
    pub(super) fn bytes(&self) -> &[u8] {
        match &self.line {
            Some(range) => self.lines.bytes(range.clone()),
            None => &self.fields[..self.out],
        }
    }

    /// Where field `i` of the current record is in its bytes.
    #[inline(always)]
    pub(super) fn bounds(&self, i: usize) -> std::ops::Range<usize> {
        let (start, end) = self.bounds[i];
        start..end
    }

    /// Field `i` of the current record, as found (quotes removed).
    pub(super) fn field(&self, i: usize) -> &[u8] {
        &self.bytes()[self.bounds(i)]
    }

    /// The current record's bytes as text, when they are UTF-8.
    #[inline(always)]
    pub(super) fn text(&self) -> Option<&str> {
        std::str::from_utf8(self.bytes()).ok()
    }

    /// The current record's fields as found, joined by `separator`.
    pub(super) fn joined(&self, separator: u8) -> String {
        let fields: Vec<String> = (0..self.len())
            .map(|i| String::from_utf8_lossy(self.field(i)).into_owned())
            .collect();
        fields.join(&(separator as char).to_string())
    }
}

/// Splits a line (without its line break) at `separator` into `bounds`,
/// unless it holds a quote: then returns false, and the tokenizer reads it.
/// Without a quote, and a content line holds no line break, the tokenizer
/// would find exactly these fields; this is the same split in one pass
/// over the line, without copying it.
pub(super) fn split(line: &[u8], separator: u8, bounds: &mut Vec<(usize, usize)>) -> bool {
    bounds.clear();
    let mut from = 0;
    for (at, &b) in line.iter().enumerate() {
        if b == separator {
            bounds.push((from, at));
            from = at + 1;
        } else if b == b'"' {
            return false;
        }
    }
    bounds.push((from, line.len()));
    true
}

/// Doubles a buffer of the tokenizer's output.
fn grow<T: Default + Clone>(buf: &mut Vec<T>) {
    let n = buf.len().max(16);
    buf.resize(2 * n, T::default());
}

/// `text` trimmed as `str::trim` trims it, at once when it starts and ends
/// with a printable ASCII character (a number does).
#[inline(always)]
pub(super) fn trim(text: &str) -> &str {
    match text.as_bytes() {
        [a, .., z] if a.is_ascii_graphic() && z.is_ascii_graphic() => text,
        [a] if a.is_ascii_graphic() => text,
        _ => text.trim(),
    }
}

/// A field's text, trimmed as `str::trim` trims it (Unicode whitespace),
/// or `None` when its bytes are not UTF-8.
pub(super) fn field_text(raw: &[u8]) -> Option<&str> {
    std::str::from_utf8(raw).ok().map(trim)
}
