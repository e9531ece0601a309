//! The frequency domain: transfer functions ([`TransferFunction`],
//! [`TransferMatrix`], [`Zpk`]) and their conversions to and from state
//! space (`ss2tf`, `tf2ss`), invariant zeros, frequency responses
//! ([`FrequencyResponse`], [`Bode`], [`Nyquist`]), [`stability_margins`]
//! and [`bandwidth`], Padé approximations of a delay ([`pade`]), root loci
//! ([`root_locus`]), pole-zero maps ([`pole_zero_map`]), and (feature `plot`) Bode,
//! Nyquist, root-locus and pole-zero figures.
//!
//! Units: angular frequencies `ω` in rad/s everywhere (`frequency_hz`
//! converts to Hz), magnitudes absolute or in dB (`20 log₁₀`), phases in
//! rad or degrees. Continuous models are evaluated at `s = jω`, discrete
//! ones at `z = e^(jω dt)`. Polynomials are in descending powers, as
//! python-control and MATLAB write them.
//!
//! A state-space frequency response reduces `(A, b_j)` to
//! controller-Hessenberg form once per input; each frequency is then an
//! `O(n²)` recurrence and one complex division per input (a pivoted
//! Hessenberg solve where the recurrence cannot be used), in a workspace
//! reused across frequencies.
//!
//! # Examples
//!
//! ```
//! use ctrlab::{Cart, MassSpring};
//! use ctrlab::freq::{TransferFunction, bode, logspace, stability_margins};
//!
//! let plant = MassSpring::nominal().state_space(Cart::Two)?;
//! let w = logspace(0.0, 3.0, 500)?; // 1 to 1000 rad/s
//! let b = bode(&plant, &w)?;
//! assert_eq!(b.magnitude.len(), 500);
//!
//! // Margins of a proportional loop, 2000 N/m on the position of cart 2.
//! let g = TransferFunction::try_from(&plant)?;
//! let loop_tf = TransferFunction::continuous(
//!     &g.num().iter().map(|c| 2000.0 * c).collect::<Vec<_>>(), g.den())?;
//! let m = stability_margins(&loop_tf)?;
//! assert!(m.phase.is_some());
//! # Ok::<(), ctrlab::Error>(())
//! ```

mod bode;
mod kernel;
#[cfg(feature = "plot")]
mod locus_svg;
mod margins;
mod matrix;
mod minreal;
mod models;
mod pade;
mod phase;
mod poly;
mod pzmap;
mod response;
mod rlocus;
#[cfg(feature = "plot")]
mod svg;
mod tf;
mod zeros;
mod zpk;

pub use bode::{Bode, Nyquist};
pub(crate) use kernel::Evaluator;
#[cfg(feature = "plot")]
#[cfg_attr(docsrs, doc(cfg(feature = "plot")))]
pub use locus_svg::{pole_zero_svg, root_locus_svg, root_locus_zoomed_svg};
pub use margins::{DelayMargin, GainMargin, Margins, PhaseMargin, bandwidth, stability_margins};
pub use matrix::TransferMatrix;
pub use pade::{MAX_PADE_ORDER, pade, pade_with_degrees};
pub use phase::{BodeOptions, WrapPhase, bode_with};
pub use pzmap::{PoleZero, PoleZeroMap, pole_zero_map};
pub use response::{FrequencyDomain, FrequencyResponse, bode, frequency_response, nyquist};
pub use rlocus::{
    Asymptotes, BoundaryCrossing, Breakaway, MAX_GAINS, RootLocus, root_locus, root_locus_at,
};
#[cfg(feature = "plot")]
#[cfg_attr(docsrs, doc(cfg(feature = "plot")))]
pub use svg::{FrequencyUnit, bode_marked_svg, bode_svg, nyquist_svg};
pub use tf::TransferFunction;
pub use zpk::Zpk;

use crate::error::Error;

/// The most frequencies [`logspace`] makes (2^24, 128 MiB): a Bode plot
/// needs hundreds.
///
/// # Examples
///
/// ```
/// use ctrlab::freq::{MAX_FREQUENCIES, logspace};
/// assert!(logspace(0.0, 1.0, MAX_FREQUENCIES + 1).is_err());
/// assert!(logspace(0.0, 1.0, usize::MAX).is_err());
/// ```
pub const MAX_FREQUENCIES: usize = 1 << 24;

/// `n` frequencies spaced evenly in log scale from `10^start` to
/// `10^stop` (NumPy's and MATLAB's `logspace`): the usual grid for a Bode
/// plot, in rad/s when used as `ω`. `n = 1` gives `[10^start]`, `n = 0`
/// an empty grid.
///
/// # Errors
///
/// [`Error::InvalidParameter`] for a non-finite decade, or one whose power
/// of ten overflows or underflows to zero (|decade| > 307), or `n` above
/// [`MAX_FREQUENCIES`].
///
/// # Examples
///
/// ```
/// use ctrlab::freq::logspace;
///
/// let w = logspace(-1.0, 2.0, 4)?;
/// assert_eq!(w, vec![0.1, 1.0, 10.0, 100.0]);
/// assert!(logspace(0.0, f64::NAN, 10).is_err());
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub fn logspace(start: f64, stop: f64, n: usize) -> Result<Vec<f64>, Error> {
    if n > MAX_FREQUENCIES {
        return Err(Error::InvalidParameter {
            name: "n",
            value: n as f64,
            reason: "more frequencies than freq::MAX_FREQUENCIES",
        });
    }
    for (name, v) in [("start", start), ("stop", stop)] {
        if !(v.is_finite() && v.abs() <= 307.0) {
            return Err(Error::InvalidParameter {
                name,
                value: v,
                reason: "decade must be finite and within ±307 (10^decade a normal f64)",
            });
        }
    }
    let step = if n > 1 {
        (stop - start) / (n - 1) as f64
    } else {
        0.0
    };
    Ok((0..n)
        .map(|k| {
            // Exact decades stay exact: 10^k for integer exponents.
            let e = if k + 1 == n {
                stop
            } else {
                start + step * k as f64
            };
            10f64.powf(e)
        })
        .collect())
}
