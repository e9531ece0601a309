//! [`Options`] of the identification.

use super::{DEFAULT_MAX_JITTER, GAP_RATIO, Scheme};
use crate::error::Error;
use crate::ident::Covariance;

/// Default speed above which a cart counts as moving for the Coulomb
/// column, m/s ([`Options::min_speed`]): 5 mm/s, just above one encoder
/// count (9.8 µm) per 2 ms sample.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::ident::{DEFAULT_MIN_SPEED, Options};
/// assert_eq!(Options::default().min_speed, DEFAULT_MIN_SPEED);
/// ```
pub const DEFAULT_MIN_SPEED: f64 = 0.005;

/// Which springs the identification fits ([`Options::springs`]).
///
/// The lab's model (`docs/lab.md`, equations (4)–(11)) takes the two springs as
/// equal, `k1 = k2 = k12`: stage 1 fits `[k12, b1]`. Real springs are never
/// exactly equal; [`Separate`](Self::Separate) fits `[k1, k2, b1]` from the
/// same equation of cart 1, which needs a run that moves the carts in both
/// modes (the lab's square wave does). Either way the result is one
/// [`MassSpringEstimate`](super::MassSpringEstimate), its
/// [`Springs`](super::Springs) saying which.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::ident::{Options, SpringModel};
/// assert_eq!(SpringModel::default(), SpringModel::Equal); // the lab's
/// assert_eq!(Options::default().springs, SpringModel::Equal);
/// ```
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash)]
pub enum SpringModel {
    /// `k1 = k2 = k12`, the lab's assumption (equations (6)–(11)).
    #[default]
    Equal,
    /// `k1` (wall to cart 1) and `k2` (between the carts) apart.
    Separate,
}

impl SpringModel {
    /// How many spring constants stage 1 fits, first in its `θ`: 1
    /// (`k12`) or 2 (`k1`, `k2`); the last of them is the spring between
    /// the carts that stage 2 takes.
    pub(super) fn parameters(self) -> usize {
        match self {
            SpringModel::Equal => 1,
            SpringModel::Separate => 2,
        }
    }
}

/// How [`identify_with`](super::identify_with) fits.
///
/// The default is the lab's equal springs, [`Scheme::Central`] without
/// Coulomb friction, both masses as given, the [`DEFAULT_MIN_SPEED`] and
/// [`DEFAULT_MAX_JITTER`], and Newey–West standard errors with the
/// bandwidth chosen from the data: exactly
/// `identify(rec, m1, m2, Scheme::Central)`.
///
/// # Examples
///
/// ```
/// use ctrlab::ident::Covariance;
/// use ctrlab::lab::ident::{Options, Scheme, SpringModel};
///
/// // The rig's carts have dry friction and unequal springs: fit both.
/// let options = Options { springs: SpringModel::Separate, coulomb: true, ..Options::default() };
/// assert_eq!(options.scheme, Scheme::Central);
/// assert_eq!((options.min_speed, options.max_jitter), (0.005, 0.05));
/// assert_eq!(options.covariance, Covariance::NeweyWest { lags: None });
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Options {
    /// Equal springs (the lab's, the default) or separate ones: what the
    /// estimate's [`springs`](super::MassSpringEstimate::springs) holds.
    pub springs: SpringModel,
    /// How derivatives and the input are taken from the samples.
    pub scheme: Scheme,
    /// Fit a Coulomb friction force `F sign(v)` on each cart: a `sign(v1)`
    /// column in stage 1 (`F1`) and a `sign(v2)` column in stage 2 (`F2`),
    /// each stage then using only the rows where its cart clearly moves
    /// (see [`min_speed`](Self::min_speed)). The estimates' `coulomb` holds
    /// the forces.
    ///
    /// Use it with [`Scheme::Central`]: the lab's backward-difference
    /// velocity is half a sample late, and the friction columns absorb that
    /// lag (on the simulated rig: `F1` −21 %, `b1` +6 %, `b2` −6 %, against
    /// +0.4 %, −0.1 %, +0.1 % with Central). Without the column, a rig with dry
    /// friction gives viscous frictions far too high (there `b1` +31 %,
    /// `b2` +71 %, `k2` +3.7 %).
    pub coulomb: bool,
    /// With [`coulomb`](Self::coulomb): the speed, m/s, a cart must exceed
    /// for a row to be used (≥ 0; default [`DEFAULT_MIN_SPEED`]). Unused
    /// without Coulomb friction.
    ///
    /// Why rows are dropped: `sign(v)` is undefined at rest, and a cart
    /// that sticks is held by whatever static friction balances the other
    /// forces, anywhere within ±its breakaway force, so its equation holds
    /// for no particular `F`; a row whose window holds a stop or a reversal
    /// sees a friction force that changes within it. Both would bias `F`
    /// and, through it, the other parameters.
    ///
    /// The row at `k` (window `[t(k−1), t(k+1)]`) is used when the cart
    /// moves the same way faster than `min_speed` over the sampling interval
    /// just before the window, `[t(k−3), t(k−2)]`, and the one just after
    /// it, `[t(k+2), t(k+3)]`: moving the same way 10 ms apart (at 2 ms),
    /// it has neither stopped nor reversed in between (that would take two
    /// reversals, far above the plant's modes). Those samples are not the
    /// row's own, so the choice does not depend on the row's measurement
    /// noise: choosing by the speeds at the window's ends, from the row's
    /// own samples, selects rows by the noise in their second difference,
    /// which biased `K` by +0.2 % and the springs by up to −0.3 % on the
    /// simulated rig. Rows within three samples of a segment's ends are
    /// not used. The default, 5 mm/s, is just above one encoder count per
    /// 2 ms sample (4.9 mm/s), so a cart at rest whose count flickers by
    /// one does not count as moving.
    pub min_speed: f64,
    /// Leave cart 2's mass free: stage 2 fits `m2` beside `K` and `b2`
    /// (`θ₂ = [K, b2, m2]`, then `F2`), the springs still coming from cart
    /// 1's equation with `m1` known; the `m2` argument is then only checked
    /// (finite, > 0), and the estimate's `m2` is the fitted one (with its
    /// standard error in `m2_estimate`).
    ///
    /// Why: what the motor pushes is cart 2 plus the motor's own rotor and
    /// gears, whose inertia reflected through the pinion (`J / r²`) adds to
    /// the weighed mass; with the weighed mass the gain and friction absorb
    /// the difference. Stage 2's equation is homogeneous in
    /// `[m2, b2, k2, K, F2]`, so one of them must be known: `k2`, from cart
    /// 1's equation, sets the scale, and every stage-2 estimate scales with
    /// the `m1` given.
    ///
    /// When it is identifiable: cart 2's acceleration must not be a fixed
    /// combination of the input, its velocity and the spring force over
    /// the run. Any run rich in frequencies (the lab's square wave, a PRBS,
    /// a chirp, a multisine of two or more lines) separates them: on the
    /// simulated rig with cart 2 at 0.85 kg (0.7 kg weighed), the square
    /// wave finds `m2` within 0.4 % and `K` within 0.3 %, where the weighed
    /// mass puts `K` 9 to 13 % high. A single sine does not: in steady
    /// state those signals span only `sin` and `cos`, the estimate rests on
    /// the start-up transient, and it is wrong without a warning (a 2 Hz
    /// sine on the ideal rig with equal springs fitted: `m2` 0.50 kg for
    /// 0.7 kg, 7 standard errors off). Its standard
    /// error is computed from the normalised fit by the delta method (see
    /// [`covariance`](Self::covariance)).
    pub free_m2: bool,
    /// Largest deviation of a sampling interval from the median interval,
    /// as a fraction of it, that rows may difference across (default
    /// [`DEFAULT_MAX_JITTER`], 5 %; at most `GAP_RATIO − 1`, 0.5); the
    /// recording is split at any interval further off. Within a segment
    /// every row uses the segment's mean period, so jitter acts as noise on
    /// the differences, and as a small bias: with sampling instants up to
    /// 2.5 % of a period late, `b2` +0.15 to +0.35 % and `K` +0.1 to
    /// +0.2 % (5 %: +0.4 % and +0.2 %).
    pub max_jitter: f64,
    /// How the standard errors are estimated (default
    /// `Covariance::NeweyWest { lags: None }`, the bandwidth chosen from
    /// the data); the estimates do not depend on it, bit for bit.
    ///
    /// With Newey–West, lags count samples: a row left out (a cart at
    /// rest, with [`coulomb`](Self::coulomb)) is a zero in the sums, and no
    /// sum pairs rows across a gap in the time stamps. Stage 2's errors
    /// also carry stage 1's: its `λ` holds the `k2` (`k12`) stage 1
    /// estimated, so each row's influence on `K`, `b2` (and `F2`) gets
    /// `∂θ̂₂/∂k2` times its influence on `k2` (the two stages'
    /// residuals come from the same samples, so this is summed row by
    /// row, not added as variances). On the simulated rig half of `K`'s
    /// run-to-run variance comes that way.
    ///
    /// Why it is the default: the rows' errors are second differences of
    /// the encoder's noise and quantisation, which cancel from row to row,
    /// and the classical errors, which assume they do not, came out 4 to
    /// 10 times the spread of the estimates over repeated runs on the
    /// simulated rig; Newey–West's are within 6 to 22 % of it (the
    /// measurement: [`Covariance`]). [`Covariance::Classical`] gives the
    /// formula of the lab's textbook (`σ̂² (ΦᵀΦ)⁻¹`, stage 2 taking `k2` as
    /// exact), as before this option existed.
    pub covariance: Covariance,
}

impl Default for Options {
    fn default() -> Self {
        Self::DEFAULT
    }
}

impl Options {
    /// The defaults, usable in a `const`.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::ident::Options;
    /// const FRICTION: Options = Options { coulomb: true, ..Options::DEFAULT };
    /// assert_eq!(Options { coulomb: false, ..FRICTION }, Options::default());
    /// ```
    pub const DEFAULT: Self = Self {
        springs: SpringModel::Equal,
        scheme: Scheme::Central,
        coulomb: false,
        min_speed: DEFAULT_MIN_SPEED,
        free_m2: false,
        max_jitter: DEFAULT_MAX_JITTER,
        covariance: Covariance::NeweyWest { lags: None },
    };

    /// The options of [`identify`](super::identify): the defaults (equal
    /// springs) with `scheme`.
    pub(super) fn with_scheme(scheme: Scheme) -> Self {
        Self {
            scheme,
            ..Self::default()
        }
    }

    pub(super) fn validate(&self) -> Result<(), Error> {
        if !(self.min_speed.is_finite() && self.min_speed >= 0.0) {
            return Err(Error::InvalidParameter {
                name: "min_speed",
                value: self.min_speed,
                reason: "must be finite and ≥ 0 m/s",
            });
        }
        if !(self.max_jitter >= 0.0 && self.max_jitter <= GAP_RATIO - 1.0) {
            return Err(Error::InvalidParameter {
                name: "max_jitter",
                value: self.max_jitter,
                reason: "must be within 0 … 0.5 (GAP_RATIO − 1) of the period",
            });
        }
        Ok(())
    }
}
