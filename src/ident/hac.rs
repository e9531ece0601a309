//! The Newey–West sums of a stored series ([`Series`]), a block of rows
//! at a time, so that no other series of its length is formed: the
//! automatic bandwidth's sums ([`automatic_lags`]), then the Bartlett sum
//! ([`bartlett`]).
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

pub(crate) use self::bandwidth::automatic_lags;
pub(crate) use self::bartlett::bartlett;

use crate::kernels::reduce::pow2_floor;

/// Each column's largest magnitude and sum of squares, when whoever
/// stored the series found them on the way (the lab's identification):
/// the sums then need no pass to find them.
#[derive(Debug, Clone, Default, PartialEq)]
pub(crate) struct Stats {
    pub max: Vec<f64>,
    pub ss: Vec<f64>,
}

/// A column-major series of `n` rows, with its columns' [`Stats`] when
/// known.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Series<'a> {
    pub x: &'a [f64],
    pub n: usize,
    pub stats: Option<&'a Stats>,
}

impl Series<'_> {
    /// Rows `from .. to` of column `j`.
    fn col(&self, j: usize, from: usize, to: usize) -> &[f64] {
        &self.x[j * self.n + from..j * self.n + to]
    }
}

/// The buffers of the sums, kept between calls: all of a block's size,
/// none of the series'.
#[derive(Debug, Clone, Default)]
pub(crate) struct Scratch {
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
