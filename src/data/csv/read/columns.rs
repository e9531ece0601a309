//! The columns a read fills: one per channel, time first, written by index
//! into room reserved up front, so that rows read by several threads land
//! in place without a copy.

/// Where the fast path puts the rows it reads.
pub(super) trait Sink {
    /// The time of the last row put, if any.
    fn last_time(&self) -> Option<f64>;
    /// Puts one row: channel `k`'s value is `row[map[k]]`.
    fn put(&mut self, row: &[f64], map: &[usize]);
}

/// The channels' columns, time first: the first `len` values of each are
/// the rows read; what follows is room, zeros or a row not kept.
pub(super) struct Columns {
    cols: Vec<Vec<f64>>,
    len: usize,
}

impl Columns {
    /// `channels` empty columns (time included).
    pub(super) fn new(channels: usize) -> Self {
        Self {
            cols: (0..channels.max(1)).map(|_| Vec::new()).collect(),
            len: 0,
        }
    }

    /// The rows read.
    pub(super) fn len(&self) -> usize {
        self.len
    }

    /// The times of the last two rows, when there are two.
    pub(super) fn last_two(&self) -> Option<(f64, f64)> {
        let t = self.cols.first()?;
        (self.len >= 2).then(|| (t[self.len - 2], t[self.len - 1]))
    }

    /// Appends one row, a value per channel in order.
    pub(super) fn push(&mut self, values: &[f64]) {
        self.append(|k| values[k]);
    }

    /// Appends one row, `value(k)` for channel `k`: into the room when
    /// there is some, else pushed.
    #[inline]
    fn append(&mut self, value: impl Fn(usize) -> f64) {
        let at = self.len;
        for (k, col) in self.cols.iter_mut().enumerate() {
            if at < col.len() {
                col[at] = value(k);
            } else {
                col.push(value(k));
            }
        }
        self.len += 1;
    }

    /// Makes room for `more` rows after the ones read. Zeroed room of a
    /// fresh allocation is not touched until written (its pages are mapped
    /// on first write, by the thread that writes them).
    pub(super) fn reserve(&mut self, more: usize) {
        let want = self.len.saturating_add(more);
        for col in &mut self.cols {
            if col.len() >= want {
                continue;
            }
            // A fresh zeroed allocation, twice as long at least: amortised
            // growth, and the room stays untouched.
            let grow = want.max(col.len().saturating_mul(2));
            let mut fresh = vec![0.0; grow];
            fresh[..self.len].copy_from_slice(&col[..self.len]);
            *col = fresh;
        }
    }

    /// The room for the next `rows` rows (reserved first), per channel, cut
    /// into consecutive parts of `counts` rows each: `parts[i][k]` is part
    /// `i`'s slice of channel `k`.
    pub(super) fn parts(&mut self, counts: &[usize]) -> Vec<Vec<&mut [f64]>> {
        let rows: usize = counts.iter().sum();
        self.reserve(rows);
        let mut parts: Vec<Vec<&mut [f64]>> = counts
            .iter()
            .map(|_| Vec::with_capacity(self.cols.len()))
            .collect();
        for col in &mut self.cols {
            let mut rest = &mut col[self.len..self.len + rows];
            for (part, &n) in parts.iter_mut().zip(counts) {
                let (head, tail) = std::mem::take(&mut rest).split_at_mut(n);
                part.push(head);
                rest = tail;
            }
        }
        parts
    }

    /// Counts `rows` more rows as read, written through [`parts`](Self::parts).
    pub(super) fn advance(&mut self, rows: usize) {
        self.len += rows;
    }

    /// The columns, the rows read only.
    pub(super) fn into_vecs(self) -> Vec<Vec<f64>> {
        let len = self.len;
        self.cols
            .into_iter()
            .map(|mut col| {
                col.truncate(len);
                col
            })
            .collect()
    }
}

/// The last of the first `len` times in `t`, if any.
#[inline]
fn last_time(t: Option<&[f64]>, len: usize) -> Option<f64> {
    t.zip(len.checked_sub(1)).map(|(t, last)| t[last])
}

impl Sink for Columns {
    #[inline]
    fn last_time(&self) -> Option<f64> {
        last_time(self.cols.first().map(Vec::as_slice), self.len)
    }

    #[inline]
    fn put(&mut self, row: &[f64], map: &[usize]) {
        self.append(|k| row[map[k]]);
    }
}

/// How many rows a file of `size` bytes holds, from the first `rows` rows
/// in `bytes` bytes: an estimate a little high, to size the columns once.
/// Each row of `width` fields needs at least `2 width - 1` bytes.
pub(super) fn estimate_rows(
    size: u64,
    consumed: u64,
    rows: usize,
    bytes: u64,
    width: usize,
) -> usize {
    let left = size.saturating_sub(consumed);
    let at_most = left / (2 * width as u64 - 1).max(1) + 1;
    let guess = (left as f64 * rows as f64 / bytes.max(1) as f64 * 1.05) as u64 + 16;
    usize::try_from(guess.min(at_most)).unwrap_or(0)
}

/// After how many rows the columns are sized from the file's length.
pub(super) const ESTIMATE_AFTER: usize = 256;

/// Once `cols` hold [`ESTIMATE_AFTER`] rows (`sized` still false), reserves
/// room for the rows a file of `size` bytes has left, from the first rows
/// (`bytes` long, from byte `start`), and sets `sized`.
pub(super) fn size_columns(
    sized: &mut bool,
    cols: &mut Columns,
    size: Option<u64>,
    bytes: u64,
    start: u64,
    width: usize,
) {
    let rows = cols.len();
    if *sized || rows < ESTIMATE_AFTER {
        return;
    }
    *sized = true;
    let Some(size) = size else {
        return;
    };
    cols.reserve(estimate_rows(size, start + bytes, rows, bytes, width));
}

/// One thread's share of a block of rows: its slice of each column, filled
/// from the start.
pub(super) struct Part<'a> {
    pub(super) cols: Vec<&'a mut [f64]>,
    pub(super) len: usize,
}

impl Part<'_> {
    /// The first and last time put, when any.
    pub(super) fn times(&self) -> Option<(f64, f64)> {
        let t = self.cols.first()?;
        (self.len > 0).then(|| (t[0], t[self.len - 1]))
    }
}

impl Sink for Part<'_> {
    #[inline]
    fn last_time(&self) -> Option<f64> {
        last_time(self.cols.first().map(|t| &**t), self.len)
    }

    #[inline]
    fn put(&mut self, row: &[f64], map: &[usize]) {
        for (col, &from) in self.cols.iter_mut().zip(map) {
            col[self.len] = row[from];
        }
        self.len += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_pushed_and_written_in_parts_come_out_in_order() {
        let mut cols = Columns::new(2);
        cols.push(&[0.0, 10.0]);
        cols.reserve(3);
        cols.push(&[1.0, 11.0]);
        {
            let mut parts = cols.parts(&[2, 0, 1]);
            parts[0][0].copy_from_slice(&[2.0, 3.0]);
            parts[0][1].copy_from_slice(&[12.0, 13.0]);
            assert!(parts[1][0].is_empty());
            parts[2][0][0] = 4.0;
            parts[2][1][0] = 14.0;
        }
        cols.advance(3);
        assert_eq!(cols.last_two(), Some((3.0, 4.0)));
        cols.put(&[15.0, 5.0], &[1, 0]);
        assert_eq!(cols.last_time(), Some(5.0));
        assert_eq!(cols.len(), 6);
        assert_eq!(
            cols.into_vecs(),
            [
                vec![0.0, 1.0, 2.0, 3.0, 4.0, 5.0],
                vec![10.0, 11.0, 12.0, 13.0, 14.0, 15.0]
            ]
        );
    }
}
