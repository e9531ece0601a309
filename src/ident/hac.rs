//! The Newey–West sums over a series handed out in blocks ([`Series`]):
//! stored (a fit's influence series) or computed again block by block from
//! the samples (the lab's long stages), so that no copy of a long series
//! is needed. Two passes at most: the automatic bandwidth's sums
//! ([`automatic_lags`]), then the Bartlett sum ([`bartlett`]).
//!
//! Each column is divided by a power of two near its largest entry, so
//! that no sum can overflow or underflow. It is known in advance when the
//! series comes with its [`Stats`]; otherwise it is the largest seen so
//! far, and the sums so far are rescaled (exactly, by a power of two) when
//! a later block raises it: the sums are then those the final powers give,
//! bit for bit, without a pass to find them first.

mod bandwidth;
mod bartlett;
mod running;
mod view;

pub(crate) use self::bandwidth::automatic_lags;
pub(crate) use self::bartlett::bartlett;
pub(crate) use self::view::Window;

use crate::kernels::reduce::pow2_floor;

/// A series of `p`-vectors, rows `0 … n`, handed out in blocks.
pub(crate) trait Series {
    /// Writes rows `from .. from + len`: column `j` to
    /// `out[j * stride..][..len]`.
    fn fill(&mut self, from: usize, len: usize, out: &mut [f64], stride: usize);

    /// The whole series, column-major, its length and what is known of its
    /// columns, when it is stored: then it is read in place, not copied
    /// block by block.
    fn stored(&self) -> Option<(&[f64], usize, Option<&Stats>)> {
        None
    }
}

/// Each column's largest magnitude and sum of squares, when whoever
/// stored the series found them on the way (the lab's influence kernel):
/// the sums then need no pass to find them.
#[derive(Debug, Clone, Default, PartialEq)]
pub(crate) struct Stats {
    pub max: Vec<f64>,
    pub ss: Vec<f64>,
}

/// A stored column-major series (`n` rows), with its columns' [`Stats`]
/// when known.
pub(crate) struct Stored<'a> {
    pub x: &'a [f64],
    pub n: usize,
    pub stats: Option<&'a Stats>,
}

impl Series for Stored<'_> {
    fn fill(&mut self, from: usize, len: usize, out: &mut [f64], stride: usize) {
        for (j, col) in self.x.chunks_exact(self.n).enumerate() {
            out[j * stride..j * stride + len].copy_from_slice(&col[from..from + len]);
        }
    }

    fn stored(&self) -> Option<(&[f64], usize, Option<&Stats>)> {
        Some((self.x, self.n, self.stats))
    }
}

/// The buffers of the sums, kept between calls: all of a block's size,
/// none of the series'.
#[derive(Debug, Clone, Default)]
pub(crate) struct Scratch {
    window: Window,
    /// Running sums and their products' operands.
    work: Vec<f64>,
}

/// The power of two each column is divided by, and its inverse: the
/// largest seen so far.
pub(super) struct Scales {
    scale: Vec<f64>,
    pub inverse: Vec<f64>,
}

impl Scales {
    pub fn new(p: usize) -> Self {
        Self {
            scale: vec![0.0; p],
            inverse: vec![1.0; p],
        }
    }

    /// Raises column `j`'s power to cover `largest` (a block's largest
    /// magnitude); returns the factor (a power of two ≤ 1) the sums so far
    /// in that column must be multiplied by, or `None` when unchanged.
    pub fn raise(&mut self, j: usize, largest: f64) -> Option<f64> {
        if largest == 0.0 {
            return None;
        }
        let s = pow2_floor(largest);
        if s <= self.scale[j] {
            return None;
        }
        let factor = if self.scale[j] == 0.0 {
            1.0
        } else {
            self.scale[j] / s
        };
        self.scale[j] = s;
        self.inverse[j] = 1.0 / s;
        Some(factor)
    }

    /// The final powers (1 for a column of zeros, as `pow2_floor(0)`).
    pub fn last(&self) -> Vec<f64> {
        self.scale
            .iter()
            .map(|&s| if s == 0.0 { 1.0 } else { s })
            .collect()
    }
}

/// The powers of two of columns whose largest magnitudes are `max`
/// (1 for a column of zeros, as `pow2_floor(0)`).
fn powers(max: &[f64]) -> Scales {
    let mut scales = Scales::new(max.len());
    for (j, &m) in max.iter().enumerate() {
        scales.raise(j, m);
    }
    scales
}

/// `x` (`p × p`, row-major) with row and column `j` times `factor`.
pub(super) fn rescale_square(x: &mut [f64], p: usize, j: usize, factor: f64) {
    for i in 0..p {
        x[i * p + j] *= factor;
        x[j * p + i] *= factor;
    }
}

/// `s` (the lower triangle, row by row) with row and column `j` times
/// `factor`.
pub(super) fn rescale_lower(s: &mut [f64], p: usize, j: usize, factor: f64) {
    let mut k = 0;
    for i in 0..p {
        for l in 0..=i {
            if i == j {
                s[k] *= factor;
            }
            if l == j {
                s[k] *= factor;
            }
            k += 1;
        }
    }
}

#[cfg(test)]
mod reference;
#[cfg(test)]
mod tests;
