//! The fast path: rows read straight from the buffered bytes, one pass,
//! no copy, no UTF-8 check of numbers, for the rows a logger writes (one
//! line each, ending in `\n` or `\r\n`, plain numbers between separators).
//!
//! It reads a row only when it knows the general path would read the same
//! values from it, and stops at anything else (a comment or blank line, a
//! quote, a lone `\r`, a row of the wrong width, a value that is not a
//! finite number, a time that does not increase): the general path then
//! reads that record, so every error is the general path's own, on the
//! same line.

use super::Slot;
use super::columns::Sink;
use super::records::trim;
use crate::data::csv::value;

/// Why [`Fast::rows`] stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Stop {
    /// The next row is for the general path.
    Unusual,
    /// The bytes hold no whole line more.
    Partial,
    /// The rows asked for are read.
    Limit,
}

/// What the fast path needs to know of a file, from its header (one for
/// each thread that reads rows: [`for_thread`](Self::for_thread)).
pub(super) struct Fast {
    separator: u8,
    decimal_comma: bool,
    /// Per column of a row, as in the file: (divisor, factor) to SI.
    scales: Vec<(f64, f64)>,
    /// Per channel, time first: the column it is read from.
    columns: Vec<usize>,
    /// The current row's values, per column, in SI.
    row: Vec<f64>,
    scratch: String,
}

impl Fast {
    pub(super) fn new(slots: &[Slot], width: usize, separator: u8, decimal_comma: bool) -> Self {
        let mut scales = vec![(1.0, 1.0); width];
        for slot in slots {
            if let Some(scale) = scales.get_mut(slot.index) {
                *scale = (slot.divisor, slot.factor);
            }
        }
        Self {
            separator,
            decimal_comma,
            scales,
            columns: slots.iter().map(|s| s.index).collect(),
            row: vec![0.0; width],
            scratch: String::new(),
        }
    }

    /// A copy for another thread. Its row, written for every row read,
    /// is allocated a cache line longer than needed, so that it shares no
    /// line with another thread's: a shared one costs half the speed.
    pub(super) fn for_thread(&self) -> Self {
        let mut row = Vec::with_capacity(self.row.len() + 16);
        row.resize(self.row.len(), 0.0);
        Self {
            separator: self.separator,
            decimal_comma: self.decimal_comma,
            scales: self.scales.clone(),
            columns: self.columns.clone(),
            row,
            scratch: String::new(),
        }
    }

    /// Reads at most `limit` rows from the start of `bytes` into `cols`
    /// (a value per channel, time first); returns how many bytes and lines
    /// (one a row) it read, and why it stopped.
    pub(super) fn rows<S: Sink>(
        &mut self,
        bytes: &[u8],
        cols: &mut S,
        limit: usize,
    ) -> (usize, u64, Stop) {
        let mut at = 0;
        let mut rows = 0;
        while rows < limit {
            let rest = &bytes[at..];
            let used = match self.quick(rest) {
                Some(used) => used,
                None => {
                    // The line's end: a `\n` or `\r\n`; a lone `\r` is the
                    // general path's. Found within the line, so that a file
                    // with `\r` line breaks is not searched to its end for a
                    // `\n` at every row.
                    let Some(end) = memchr::memchr2(b'\n', b'\r', rest) else {
                        return (at, rows as u64, Stop::Partial);
                    };
                    let end = match (rest[end], rest.get(end + 1)) {
                        (b'\n', _) => end,
                        (_, Some(b'\n')) => end + 1,
                        (_, Some(_)) => return (at, rows as u64, Stop::Unusual),
                        // A `\r` last: its `\n` may come in the next read.
                        (_, None) => return (at, rows as u64, Stop::Partial),
                    };
                    let line = match &rest[..end] {
                        [line @ .., b'\r'] => line,
                        line => line,
                    };
                    if !self.row(line) {
                        return (at, rows as u64, Stop::Unusual);
                    }
                    end + 1
                }
            };
            if !self.increases(cols.last_time()) {
                return (at, rows as u64, Stop::Unusual);
            }
            cols.put(&self.row, &self.columns);
            at += used;
            rows += 1;
        }
        (at, rows as u64, Stop::Limit)
    }

    /// Whether the current row's time comes after the last one read
    /// (`before`), and the interval is finite (else the general path says
    /// what is wrong).
    #[inline]
    fn increases(&self, before: Option<f64>) -> bool {
        let now = self.columns.first().map_or(0.0, |&c| self.row[c]);
        before.is_none_or(|before| follows(before, now))
    }

    /// Reads the row at the start of `bytes` into `self.row`, in SI, when
    /// every field is a plain number and the line ends in `\n` or `\r\n`:
    /// the usual row, read without looking for its end first. Returns its
    /// length with the line break; `None` leaves the row to [`row`](Self::row).
    #[inline]
    fn quick(&mut self, bytes: &[u8]) -> Option<usize> {
        let width = self.row.len();
        let mut at = 0;
        for column in 0..width {
            let (value, n) = plain(bytes.get(at..)?, self.decimal_comma)?;
            self.row[column] = self.scaled(column, value)?;
            at += n;
            let next = *bytes.get(at)?;
            if column + 1 < width {
                if next != self.separator {
                    return None;
                }
                at += 1;
            } else if next == b'\n' {
                return Some(at + 1);
            } else if next == b'\r' && bytes.get(at + 1) == Some(&b'\n') {
                return Some(at + 2);
            }
        }
        None
    }

    /// Column `column`'s `value` in SI, as the general path converts it;
    /// `None` when not finite.
    #[inline(always)]
    fn scaled(&self, column: usize, value: f64) -> Option<f64> {
        let (divisor, factor) = self.scales[column];
        // Dividing or multiplying by 1 changes no bit, and is skipped.
        let value = if divisor == 1.0 {
            value
        } else {
            value / divisor
        };
        let value = if factor == 1.0 { value } else { value * factor };
        value.is_finite().then_some(value)
    }

    /// Reads a line (without its line break) into `self.row`, in SI; false
    /// when the general path must read it.
    fn row(&mut self, line: &[u8]) -> bool {
        // A comment, blank or indented line, or one the general path
        // splits at a `\r`.
        if matches!(line.first(), None | Some(b' ' | b'\t' | b'#' | b'%')) {
            return false;
        }
        let width = self.row.len();
        let mut rest = line;
        for column in 0..width {
            let (value, used) = match plain(rest, self.decimal_comma) {
                Some((value, n)) if rest.get(n).is_none_or(|&b| b == self.separator) => (value, n),
                _ => {
                    let n = memchr::memchr(self.separator, rest).unwrap_or(rest.len());
                    match self.general(&rest[..n]) {
                        Some(value) => (value, n),
                        None => return false,
                    }
                }
            };
            let Some(value) = self.scaled(column, value) else {
                return false;
            };
            self.row[column] = value;
            // The last column must end the line, any other a separator.
            match rest.get(used) {
                None => return column + 1 == width,
                Some(_) if column + 1 == width => return false,
                Some(_) => rest = &rest[used + 1..],
            }
        }
        false
    }

    /// A field that is not a plain number, read as the general path reads
    /// it (trimmed, any number `str::parse` reads); `None` for a quote or
    /// `\r` in it (the general path's tokenizer or line breaks see them),
    /// or a field that is not a number.
    #[cold]
    fn general(&mut self, field: &[u8]) -> Option<f64> {
        if field.iter().any(|&b| b == b'"' || b == b'\r') {
            return None;
        }
        let text = trim(std::str::from_utf8(field).ok()?);
        value::parse(text, self.decimal_comma, &mut self.scratch).ok()
    }
}

/// Whether time `now` may follow `before` on the fast path: it increases,
/// by a finite interval.
#[inline]
pub(super) fn follows(before: f64, now: f64) -> bool {
    now > before && (now - before).is_finite()
}

/// Exact powers of ten, as doubles.
const POWERS: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
    1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
];

/// The number at the start of `bytes` when it is plain, `-12.345` (a sign,
/// digits, one decimal point or with `decimal_comma` comma, digits on both
/// sides of it), with its length; `None` for anything else (an exponent,
/// more than 2^53 in its digits, more than 22 decimals), left to
/// `str::parse`.
///
/// Its digits `m` and decimals `k` make it `m / 10^k`, both exact doubles:
/// one IEEE division rounds the exact quotient to nearest, which is the
/// correctly rounded value `str::parse` gives (Clinger's fast path).
#[inline]
pub(super) fn plain(bytes: &[u8], decimal_comma: bool) -> Option<(f64, usize)> {
    let negative = bytes.first() == Some(&b'-');
    let start = usize::from(matches!(bytes.first(), Some(b'-' | b'+')));
    let mut at = start;
    let mut m: u64 = 0;
    while let Some(d) = digit(bytes, at) {
        m = m.wrapping_mul(10).wrapping_add(d);
        at += 1;
    }
    let whole = at - start;
    let mut decimals = 0;
    if let Some(&b) = bytes.get(at)
        && (b == b'.' || (decimal_comma && b == b','))
    {
        at += 1;
        let from = at;
        while let Some(d) = digit(bytes, at) {
            m = m.wrapping_mul(10).wrapping_add(d);
            at += 1;
        }
        decimals = at - from;
        if decimals == 0 {
            return None;
        }
    }
    // At most 19 digits cannot overflow the u64 (10^19 < 2^64).
    if whole == 0 || whole + decimals > 19 || decimals >= POWERS.len() || m > 1 << 53 {
        return None;
    }
    let value = m as f64 / POWERS[decimals];
    Some((if negative { -value } else { value }, at))
}

/// The digit at `at`, if there is one.
#[inline(always)]
fn digit(bytes: &[u8], at: usize) -> Option<u64> {
    let d = bytes.get(at)?.wrapping_sub(b'0');
    (d < 10).then_some(u64::from(d))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plain_numbers_are_read_as_str_parse_reads_them() {
        let cases = [
            "0",
            "-0",
            "+1",
            "12.5",
            "-2",
            "0.002",
            "1999.998",
            "-12.345678",
            "9007199254740992",
            "0.1",
            "1234567.012345678",
            "0.000000000000000001",
        ];
        for text in cases {
            let (value, n) = plain(text.as_bytes(), false).unwrap();
            assert_eq!(n, text.len(), "{text}");
            assert_eq!(
                value.to_bits(),
                text.parse::<f64>().unwrap().to_bits(),
                "{text}"
            );
            let comma = text.replace('.', ",");
            let (value, _) = plain(comma.as_bytes(), true).unwrap();
            assert_eq!(
                value.to_bits(),
                text.parse::<f64>().unwrap().to_bits(),
                "{text}"
            );
        }
        // Left to `str::parse`.
        for text in [
            "",
            "-",
            ".5",
            "1.",
            "1e3",
            "9007199254740993",
            "12345678901234567890",
            "0.00000000000000000000001",
            "inf",
            "nan",
        ] {
            assert!(
                plain(text.as_bytes(), false).is_none_or(|(_, n)| n < text.len()),
                "{text}"
            );
        }
        assert_eq!(plain(b"1,5", false), Some((1.0, 1)));
        assert_eq!(plain(b"1.5;2", true), Some((1.5, 3)));
        assert_eq!(plain(b"1,5,2", true), Some((1.5, 3)));
    }
}
