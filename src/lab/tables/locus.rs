//! The root locus behind a table's group of rows: the closed-loop poles of
//! the lab's law as the group's gain varies with the others held
//! ([`GroupLocus`]), continuous and as the rig samples it.
//!
//! The lab's law is `u = Kf (G r − x_mm)`, so in SI the feedback gain is
//! `K = 1000 Kf` (per metre). With `Kf = base + k e_v` (the varied entry
//! `v`, [`Gain::index`]) the closed-loop poles are
//! `eig(A − B (K₀ + 1000 k e_vᵀ))`, `K₀ = 1000 base`; with
//! `A₀ = A − B K₀` this is `det(sI − A₀) · (1 + k L(s)) = 0` for
//! `L(s) = 1000 e_vᵀ (sI − A₀)⁻¹ B` (the determinant lemma for a rank-one
//! update). So the poles as `k` varies are the root locus of
//! `L = (A₀, B, 1000 e_vᵀ, 0)` ([`gain_loop`]), in the gain's own unit
//! (V/mm, or V/(mm/s)). Sampled by ZOH every `period` s, the same holds
//! with `(A_d, B_d)` in place of `(A, B)`.

use super::{Gain, GainGroup};
use crate::discretize::Discretization;
use crate::error::Error;
use crate::freq::{RootLocus, root_locus};
use crate::lab::{Cart, LabGains, MassSpring};
use crate::model::{Continuous, Discrete, StateSpace};
use nalgebra::SMatrix;

/// The open loop `L = (A − B K₀, B, 1000 e_vᵀ, 0)` whose root locus in
/// `k` is the lab's closed loop with `Kf = base + k e_v` on `cart` (see
/// the module documentation): `k` in V/mm (a position gain) or V/(mm/s)
/// (a speed gain). The entry `v` of `base` is ignored (it is `k`).
///
/// # Errors
///
/// The model's and the gains' errors.
///
/// # Examples
///
/// ```
/// use ctrlab::{Cart, MassSpring};
/// use ctrlab::lab::{LabGains, tables::{Gain, gain_loop}};
/// use ctrlab::freq::root_locus_at;
///
/// let model = MassSpring::nominal();
/// let l = gain_loop(&model, Cart::Two, [0.0; 4], Gain::Kf3)?;
/// // The locus at Kf3 = 10 is the closed loop of Kf = [0 0 10 0].
/// let at_10 = root_locus_at(&l, &[10.0])?.poles_at(0);
/// let law = LabGains::new([0.0, 0.0, 10.0, 0.0], Cart::Two).state_feedback()?;
/// for p in law.closed_loop(&model.state_space(Cart::Two)?)?.poles()? {
///     assert!(at_10.iter().any(|q| (q - p).norm() < 1e-9 * p.norm()));
/// }
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub fn gain_loop(
    model: &MassSpring,
    cart: Cart,
    base: [f64; 4],
    varied: Gain,
) -> Result<StateSpace<4, 1, 1, Continuous>, Error> {
    let sys = model.state_space(cart)?;
    let (k0, c) = split(base, varied, cart)?;
    StateSpace::continuous(sys.a() - sys.b() * k0, *sys.b(), c, SMatrix::zeros())
}

/// [`gain_loop`] as the rig samples it: the plant sampled by ZOH every
/// `period` s, `L = (A_d − B_d K₀, B_d, 1000 e_vᵀ, 0)`, a discrete model
/// whose locus crosses the unit circle where the sampled loop turns
/// unstable.
///
/// # Errors
///
/// As [`gain_loop`], and the discretisation's (a `period` that is not
/// finite and positive).
///
/// # Examples
///
/// ```
/// use ctrlab::{Cart, MassSpring};
/// use ctrlab::lab::tables::{Gain, Prediction, sampled_gain_loop};
/// use ctrlab::freq::root_locus_at;
///
/// let model = MassSpring::nominal();
/// let l = sampled_gain_loop(&model, Cart::Two, [0.0; 4], Gain::Kf3, 0.002)?;
/// let at_5 = root_locus_at(&l, &[5.0])?.poles_at(0);
/// let radius = at_5.iter().map(|z| z.norm()).fold(0.0, f64::max);
/// let p = Prediction::of(&model, [0.0, 0.0, 5.0, 0.0], Cart::Two, 0.002)?;
/// assert!((radius - p.radius).abs() < 1e-12);
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub fn sampled_gain_loop(
    model: &MassSpring,
    cart: Cart,
    base: [f64; 4],
    varied: Gain,
    period: f64,
) -> Result<StateSpace<4, 1, 1, Discrete>, Error> {
    let sys = model
        .state_space(cart)?
        .discretize(period, Discretization::Zoh)?;
    let (k0, c) = split(base, varied, cart)?;
    StateSpace::discrete(
        sys.a() - sys.b() * k0,
        *sys.b(),
        c,
        SMatrix::zeros(),
        period,
    )
}

/// `K₀` (SI, the varied entry zeroed) and the output row `1000 e_vᵀ`.
fn split(
    mut base: [f64; 4],
    varied: Gain,
    cart: Cart,
) -> Result<(SMatrix<f64, 1, 4>, SMatrix<f64, 1, 4>), Error> {
    base[varied.index()] = 0.0;
    let k0 = *LabGains::new(base, cart).state_feedback()?.gain();
    let mut c = SMatrix::<f64, 1, 4>::zeros();
    c[varied.index()] = 1000.0;
    Ok((k0, c))
}

/// The root locus of one group of a table's rows (Table 5's Kf3 alone,
/// or its Kf4 with Kf3 = 10): the closed-loop poles of the lab's law as
/// the group's gain varies from 0 with the others held at the group's
/// base, on the continuous model and on the loop the rig samples.
///
/// # Examples
///
/// ```
/// use ctrlab::{Cart, MassSpring};
/// use ctrlab::lab::tables::{GroupLocus, TABLE5};
///
/// let kf3 = GroupLocus::of(&MassSpring::nominal(), Cart::Two, &TABLE5.groups[0], 0.002)?;
/// // The continuous loop never crosses the imaginary axis; the loop the
/// // rig samples every 2 ms leaves the unit circle between Kf3 = 5 and 10.
/// assert!(kf3.continuous.crossings.is_empty());
/// let c = kf3.sampled.crossings[0];
/// assert!(c.destabilising && c.gain > 5.0 && c.gain < 10.0);
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct GroupLocus {
    /// The gain that varies.
    pub varied: Gain,
    /// The gains held (the varied entry's base value is replaced by `k`).
    pub base: [f64; 4],
    /// The group's rows' values of the varied gain (V/mm or V/(mm/s)).
    pub values: Vec<f64>,
    /// The root locus of the continuous loop, `k` in the gain's unit.
    pub continuous: RootLocus,
    /// The root locus of the loop sampled by ZOH every `period` s.
    pub sampled: RootLocus,
}

impl GroupLocus {
    /// The loci of `group` on `cart` of `model`, sampled every `period` s
    /// (the rig's 0.002), each over [`root_locus`]'s automatic range.
    ///
    /// # Errors
    ///
    /// The errors of [`gain_loop`] and [`root_locus`].
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{Cart, MassSpring};
    /// use ctrlab::lab::tables::{Gain, GroupLocus, TABLE6};
    /// let kf2 = &TABLE6.groups[1]; // Kf2 with Kf1 = 1 V/mm
    /// let l = GroupLocus::of(&MassSpring::nominal(), Cart::One, kf2, 0.002)?;
    /// assert_eq!((l.varied, l.base), (Gain::Kf2, [1.0, 0.0, 0.0, 0.0]));
    /// assert_eq!(l.values, kf2.values); // V/(mm/s), where the rows sit on the locus
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn of(
        model: &MassSpring,
        cart: Cart,
        group: &GainGroup,
        period: f64,
    ) -> Result<Self, Error> {
        let mut base = group.base;
        base[group.varied.index()] = 0.0;
        let l = gain_loop(model, cart, base, group.varied)?;
        let sampled = sampled_gain_loop(model, cart, base, group.varied, period)?;
        Ok(Self {
            varied: group.varied,
            base,
            values: group.values.to_vec(),
            continuous: root_locus(&l)?,
            sampled: root_locus(&sampled)?,
        })
    }
}

#[cfg(feature = "plot")]
impl GroupLocus {
    /// Writes the two figures (feature `plot`): the continuous locus to
    /// `continuous` and the sampled one to `sampled`, each with the
    /// group's values marked on every branch (`Kf3 = 10`). The sampled
    /// figure is zoomed on `z = 1`, where the lab's poles are (about
    /// `e^(−0.0074 ± 0.1j)` at 2 ms): the view holds the open-loop poles,
    /// the marked poles and the unit-circle crossings, padded by a third
    /// (a zero near `z = −1`, which ZOH sampling adds, stays outside).
    ///
    /// # Errors
    ///
    /// The errors of [`root_locus_svg`](crate::freq::root_locus_svg).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{Cart, MassSpring};
    /// use ctrlab::lab::tables::{GroupLocus, TABLE5};
    ///
    /// let kf3 = GroupLocus::of(&MassSpring::nominal(), Cart::Two, &TABLE5.groups[0], 0.002)?;
    /// let dir = std::env::temp_dir();
    /// let (s, z) = (dir.join("ctrlab_kf3_s.svg"), dir.join("ctrlab_kf3_z.svg"));
    /// kf3.write_svgs(&s, &z, "Table 5")?;
    /// assert!(std::fs::read_to_string(&z).unwrap().contains("Kf3 = 10"));
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn write_svgs(
        &self,
        continuous: impl AsRef<std::path::Path>,
        sampled: impl AsRef<std::path::Path>,
        title: &str,
    ) -> Result<(), crate::plot::PlotError> {
        use crate::freq::root_locus_zoomed_svg;
        let labels: Vec<String> = self
            .values
            .iter()
            .map(|v| format!("{} = {v}", self.varied))
            .collect();
        let marks: Vec<(&str, f64)> = labels
            .iter()
            .map(String::as_str)
            .zip(self.values.iter().copied())
            .collect();
        let held = super::kf_display(&self.base);
        let unit = match self.varied {
            Gain::Kf1 | Gain::Kf3 => "V/mm",
            Gain::Kf2 | Gain::Kf4 => "V/(mm/s)",
        };
        let name = |what: &str| {
            format!(
                "{title}: poles vs {} ({unit}), Kf = {held} otherwise; {what}",
                self.varied
            )
        };
        let top = self.values.iter().copied().fold(0.0, f64::max);
        for (locus, path, what, equal) in [
            (
                &self.continuous,
                continuous.as_ref(),
                "continuous".to_string(),
                false,
            ),
            (
                &self.sampled,
                sampled.as_ref(),
                format!("ZOH, {} ms", self.sampled.period.unwrap_or(0.0) * 1e3),
                true,
            ),
        ] {
            let mut pts: Vec<nalgebra::Complex<f64>> = locus.poles.clone();
            for &k in &self.values {
                pts.extend(locus.poles_at_gain(k)?);
            }
            pts.extend(
                locus
                    .crossings
                    .iter()
                    .filter(|c| c.gain <= 2.0 * top)
                    .map(|c| c.point),
            );
            let (x, y) = zoom(&pts, equal);
            let title = format!("{}, upper half", name(&what));
            root_locus_zoomed_svg(path, &title, locus, &marks, x, y)?;
        }
        Ok(())
    }
}

/// A view of the upper half-plane around `points` (the lower is its
/// mirror image): real parts padded by their span (twice on the left,
/// the imaginary axis kept in sight), imaginary parts from just below 0 to
/// a tenth above the highest; with `equal`, widened to about the plot
/// area's aspect (4 : 3) so that a unit is as long on both axes and the
/// unit circle is round.
#[cfg(feature = "plot")]
fn zoom(points: &[nalgebra::Complex<f64>], equal: bool) -> ((f64, f64), (f64, f64)) {
    let re = |f: fn(f64, f64) -> f64, start| points.iter().map(|p| p.re).fold(start, f);
    let (x0, x1) = (re(f64::min, f64::INFINITY), re(f64::max, f64::NEG_INFINITY));
    let top = points.iter().map(|p| p.im).fold(0.0, f64::max).max(1e-9);
    let (x0, x1) = if equal {
        (x0, x1)
    } else {
        (x0.min(0.0), x1.max(0.0))
    };
    let span = (x1 - x0).max(1e-9 * top);
    let (x, y) = ((x0 - 2.0 * span, x1 + span), (-0.06 * top, 1.1 * top));
    if !equal {
        return (x, y);
    }
    // Same units per pixel: stretch the narrower range about its centre.
    let unit = ((x.1 - x.0) / 4.0).max((y.1 - y.0) / 3.0);
    let cx = 0.5 * (x.0 + x.1);
    ((cx - 2.0 * unit, cx + 2.0 * unit), (y.0, y.0 + 3.0 * unit))
}
