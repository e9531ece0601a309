//! A prediction against the rig's run: where they agree, how each cart
//! comes to rest, how fast the integrator frees a stuck cart, and what a
//! simulated rig is known to have that the prediction has not.

use super::{DRIVE_DELAY, Design, Metrics, Spec};
use crate::data::Recording;
use crate::lab::{Cart, MassSpring, SimulatedRig, position_channel};

/// The tail of a run in which a cart's rest is judged, s: the second half
/// of a [`DURATION`](super::DURATION) run.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::{lqi::{DURATION, REST_TAIL}, protocol::PERIOD};
/// assert_eq!(2.0 * REST_TAIL, DURATION); // the second half of a run
/// assert!((REST_TAIL / PERIOD - 750.0).abs() < 1e-9); // samples judged
/// ```
pub const REST_TAIL: f64 = 1.5;
/// Identified parameters within this (relative) of a simulated card's truth
/// are not offered as a reason for a difference.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::{MassSpring, SimulatedRig, lqi::KnownDifferences};
/// let sim = SimulatedRig::default();
/// let close = MassSpring { k2: 1.015 * sim.truth.k2, ..sim.truth }; // 1.5 % off
/// let far = MassSpring { k2: 1.025 * sim.truth.k2, ..sim.truth }; // 2.5 % off
/// assert!(KnownDifferences::of(&close, &sim).off().is_empty());
/// assert_eq!(KnownDifferences::of(&far, &sim).off()[0].0, "k2");
/// ```
pub const IDENT_TOLERANCE: f64 = 0.02;

/// How a cart rests over a run's tail: its lowest and highest reading,
/// counts from the setpoint (positive past it).
///
/// # Examples
///
/// ```
/// use ctrlab::lab::lqi::{Rest, RestKind};
/// assert_eq!(Rest { lo: -1.0, hi: -1.0 }.kind(), RestKind::Still);
/// assert_eq!(Rest { lo: -1.0, hi: 1.0 }.kind(), RestKind::Jitter);
/// assert_eq!(Rest { lo: -4.0, hi: 3.0 }.kind(), RestKind::Hunting);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rest {
    /// Lowest reading, counts from the setpoint.
    pub lo: f64,
    /// Highest reading, counts from the setpoint.
    pub hi: f64,
}

/// How still a cart rests.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::lqi::{Rest, RestKind};
/// // Counts from the setpoint over the run's tail.
/// let kinds = [(0.0, 0.0), (-1.0, 1.0), (-2.0, 3.0)].map(|(lo, hi)| Rest { lo, hi }.kind());
/// assert_eq!(kinds, [RestKind::Still, RestKind::Jitter, RestKind::Hunting]);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RestKind {
    /// One reading throughout.
    Still,
    /// Readings within two counts: encoder noise on a cart at rest.
    Jitter,
    /// Wider: sticking and slipping.
    Hunting,
}

impl Rest {
    /// How the tracked cart of `spec` rests over the last [`REST_TAIL`] s of
    /// `rec` (sampled every `period` s), in counts of `metres_per_count`;
    /// `None` without that channel or samples.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::Recording;
    /// use ctrlab::lab::{Cart, lqi::{Rest, RestKind, Spec}};
    /// let count = 0.080 / 8192.0; // m
    /// // Cart 2 at 30 mm, its reading flickering one count past it.
    /// let t: Vec<f64> = (0..1500).map(|k| k as f64 * 0.002).collect();
    /// let x2: Vec<f64> = (0..1500).map(|k| 0.030 + (k % 2) as f64 * count).collect();
    /// # let z = vec![0.0; 1500];
    /// let rec = Recording::from_columns(ctrlab::lab::schema(), t, vec![z.clone(), z.clone(), z.clone(), x2, z])?;
    /// let rest = Rest::of(&rec, &Spec::new(Cart::Two, 0.030, 24.0), count, 0.002).unwrap();
    /// assert_eq!((rest.lo, rest.hi, rest.kind()), (0.0, 1.0, RestKind::Jitter));
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn of(rec: &Recording, spec: &Spec, metres_per_count: f64, period: f64) -> Option<Self> {
        let y = rec.channel(position_channel(spec.cart)).ok()?;
        let from = y
            .len()
            .saturating_sub((REST_TAIL / period).round() as usize);
        let off = y[from..]
            .iter()
            .map(|v| ((v - spec.setpoint) / metres_per_count).round());
        let (lo, hi) = off.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
        lo.is_finite().then_some(Self { lo, hi })
    }

    /// Still, jittering or hunting.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::lqi::{Rest, RestKind};
    /// // Three counts between lowest and highest: more than encoder noise.
    /// assert_eq!(Rest { lo: -3.0, hi: 0.0 }.kind(), RestKind::Hunting);
    /// assert_eq!(Rest { lo: -3.0, hi: -1.0 }.kind(), RestKind::Jitter);
    /// ```
    pub fn kind(&self) -> RestKind {
        if self.lo == self.hi {
            RestKind::Still
        } else if self.hi - self.lo <= 2.0 {
            RestKind::Jitter
        } else {
            RestKind::Hunting
        }
    }
}

/// `a` and `b` agree to within `abs` or `rel` of `a`.
fn agree(a: f64, b: f64, abs: f64, rel: f64) -> bool {
    (a - b).abs() <= abs.max(rel * a.abs())
}

/// Which of the transient's figures agree between prediction and rig: rise
/// within a sample or 10 %, overshoot within a percentage point, settling
/// within 10 ms or 10 %.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::lqi::Transient;
/// let t = Transient { rise: true, overshoot: true, settling: false };
/// assert!(!t.agrees()); // one figure off is a disagreement
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Transient {
    /// The rise times agree.
    pub rise: bool,
    /// The overshoots agree.
    pub overshoot: bool,
    /// The settling times agree.
    pub settling: bool,
}

impl Transient {
    /// Whether every figure agrees.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::lqi::Transient;
    /// assert!(Transient { rise: true, overshoot: true, settling: true }.agrees());
    /// assert!(!Transient { rise: false, overshoot: true, settling: true }.agrees());
    /// ```
    pub fn agrees(&self) -> bool {
        self.rise && self.overshoot && self.settling
    }
}

/// A design's prediction against its run on the rig.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::{Cart, SimulatedRig, lqi::{self, Comparison, Metrics, Spec}};
/// use ctrlab::lab::LabGains;
///
/// let sim = SimulatedRig::default();
/// let spec = Spec::new(Cart::Two, 0.030, 24.0);
/// let law = LabGains::new([0.0, 0.0, 10.0, 0.1], Cart::Two).state_feedback()?;
/// let rec = lqi::predict(&sim, law, spec.setpoint, 3.0)?;
/// let m = Metrics::of(&rec, &spec, sim.metres_per_count())?;
/// // A run against itself agrees everywhere.
/// let c = Comparison::of((&rec, &m), (&rec, &m), &spec, sim.metres_per_count(), sim.period);
/// assert!(c.transient.is_some_and(|t| t.agrees()) && c.rest_agrees && c.voltage_agrees);
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Comparison {
    /// Which transient figures agree; `None` when either step has no
    /// figures.
    pub transient: Option<Transient>,
    /// How each cart rests (predicted, rig), when both recordings have the
    /// channel.
    pub rest: Option<(Rest, Rest)>,
    /// The rests agree: steady-state errors within half a count, and the
    /// rig's spread of readings at most two counts wider.
    pub rest_agrees: bool,
    /// The peak voltages agree within 0.5 V, and either both or neither
    /// run reached the drive's limit.
    pub voltage_agrees: bool,
}

impl Comparison {
    /// The prediction `(recording, figures)` against the rig's, for `spec`,
    /// in counts of `metres_per_count` (m), sampled every `period` s.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::{Cart, lqi::{Comparison, Metrics, Spec, Transient}};
    /// # use ctrlab::Recording;
    /// # // Cart 2 from rest to 30 mm, a first-order approach of `tau` s, 1 V drive.
    /// # let approach = |tau: f64| {
    /// #     let t: Vec<f64> = (0..1500).map(|k| k as f64 * 0.002).collect();
    /// #     let x2: Vec<f64> = t.iter().map(|t| 0.030 * (1.0 - (-t / tau).exp())).collect();
    /// #     let z = vec![0.0; 1500];
    /// #     Recording::from_columns(ctrlab::lab::schema(), t, vec![vec![1.0; 1500], z.clone(), z.clone(), x2, z])
    /// # };
    /// let (spec, count) = (Spec::new(Cart::Two, 0.030, 24.0), 0.080 / 8192.0);
    /// let (fast, slow) = (approach(0.1)?, approach(0.2)?);
    /// let (mf, ms) = (Metrics::of(&fast, &spec, count)?, Metrics::of(&slow, &spec, count)?);
    /// let c = Comparison::of((&fast, &mf), (&slow, &ms), &spec, count, 0.002);
    /// // Twice as slow: rise and settling disagree; both rest on the setpoint.
    /// assert_eq!(c.transient, Some(Transient { rise: false, overshoot: true, settling: false }));
    /// assert!(c.rest_agrees && c.voltage_agrees);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn of(
        predicted: (&Recording, &Metrics),
        rig: (&Recording, &Metrics),
        spec: &Spec,
        metres_per_count: f64,
        period: f64,
    ) -> Self {
        let ((prec, p), (mrec, m)) = (predicted, rig);
        let transient = match (&p.step, &m.step) {
            (Ok(ps), Ok(ms)) => Some(Transient {
                rise: agree(ps.rise, ms.rise, period, 0.1),
                overshoot: agree(ps.overshoot, ms.overshoot, 1.0, 0.0),
                settling: agree(ps.settling, ms.settling, 0.01, 0.1),
            }),
            _ => None,
        };
        let rest = Rest::of(prec, spec, metres_per_count, period).zip(Rest::of(
            mrec,
            spec,
            metres_per_count,
            period,
        ));
        let rest_agrees = rest.is_some_and(|(pr, mr)| {
            agree(error_counts(p), error_counts(m), 0.5, 0.0)
                && (mr.hi - mr.lo) <= (pr.hi - pr.lo) + 2.0
        });
        let voltage_agrees =
            agree(p.peak_u, m.peak_u, 0.5, 0.0) && (p.clipped == 0) == (m.clipped == 0);
        Self {
            transient,
            rest,
            rest_agrees,
            voltage_agrees,
        }
    }
}

/// A run's steady-state error in counts, NaN without figures.
fn error_counts(m: &Metrics) -> f64 {
    m.step.as_ref().map_or(f64::NAN, |s| s.error_counts)
}

/// How fast the integrator frees a stuck cart: the drive's rate under the
/// rig's steady-state error against the band of drive it must cross (cart
/// 2: twice its own breakaway; cart 1: twice both carts', as cart 2 must
/// move to push it through the spring).
///
/// # Examples
///
/// ```
/// use ctrlab::lab::lqi::IntegratorWalk;
/// // |K_z| = 1e4 V/(m·s), 2 counts of 10 µm off: 0.2 V/s; a band of 4 V takes 20 s.
/// let w = IntegratorWalk { kz: 1e4, error_counts: 2.0, rate: 0.2, band: 4.0, time: 20.0, left: 2.5 };
/// assert!(w.exceeds_run());
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IntegratorWalk {
    /// |K_z|, V/(m·s).
    pub kz: f64,
    /// The rig's |steady-state error|, counts.
    pub error_counts: f64,
    /// The drive's rate under that error, V/s.
    pub rate: f64,
    /// The band of drive to cross, V.
    pub band: f64,
    /// How long crossing it can take, s.
    pub time: f64,
    /// How much of the run is left after settling, s.
    pub left: f64,
}

impl IntegratorWalk {
    /// The walk of `design`'s integrator on its rig run `rig` with figures
    /// `measured`, for carts breaking away at `breakaway` (N, cart 1 and 2)
    /// on a drive of `gain` (N/V), in counts of `metres_per_count` (m).
    /// A run without figures (not settled) has no steady-state error:
    /// `error_counts`, `rate` and `time` are then NaN.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::lqi::IntegratorWalk;
    /// # use ctrlab::lab::{Cart, MassSpring, lqi::{self, Candidate, Choice, Design, Metrics, Spec, Step}};
    /// # let spec = Spec::new(Cart::Two, 0.030, 24.0);
    /// # let model = lqi::position_model(&MassSpring::nominal(), 0.002)?;
    /// # let (rho, q) = (1e7, lqi::weights(Cart::Two, 1e7));
    /// # let lqi = lqi::positions_lqi(&model, Cart::Two, &q, 1e-5)?;
    /// # let step = Step { rise: 0.1, overshoot: 2.0, settling: 0.3, error_mm: 0.0, error_counts: 0.0 };
    /// # let good = Metrics { step: Ok(step), peak_u: 10.0, clipped: 0 };
    /// # let slow = Metrics { step: Ok(Step { settling: 0.8, ..step }), ..good.clone() };
    /// # let candidates = vec![Candidate { rho: 1e6, metrics: Some(slow) },
    /// #     Candidate { rho: 1e7, metrics: Some(good.clone()) }, Candidate { rho: 1e8, metrics: None }];
    /// # let predicted = ctrlab::Recording::new(ctrlab::lab::schema());
    /// # let design = Design { spec, rho, q, lqi, choice: Choice::Isolated, predicted, metrics: good, candidates };
    /// let rec = ctrlab::Recording::from_columns(ctrlab::lab::schema(), vec![0.0, 3.0], vec![vec![0.0; 2]; 5])?;
    /// let measured = Metrics { step: Ok(Step { error_counts: -2.0, settling: 0.5, ..step }), ..design.metrics.clone() };
    /// let w = IntegratorWalk::of(&design, (&rec, &measured), [1.0, 1.5], 8.5, 1e-5);
    /// assert!((w.rate - w.kz * 2.0 * 1e-5).abs() < 1e-12); // V/s under 2 counts
    /// assert!((w.band - 2.0 * 1.5 / 8.5).abs() < 1e-12); // V: twice cart 2's breakaway
    /// assert_eq!((w.time, w.left), (w.band / w.rate, 2.5)); // s
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn of(
        design: &Design,
        rig: (&Recording, &Metrics),
        breakaway: [f64; 2],
        gain: f64,
        metres_per_count: f64,
    ) -> Self {
        let (rec, measured) = rig;
        let error_counts = error_counts(measured).abs();
        let kz = design.lqi.gain[4].abs();
        let rate = kz * error_counts * metres_per_count;
        let band = match design.spec.cart {
            Cart::Two => 2.0 * breakaway[1],
            Cart::One => 2.0 * (breakaway[0] + breakaway[1]),
        } / gain;
        let settled = measured.step.as_ref().map_or(0.0, |s| s.settling);
        let left = rec.time().last().copied().unwrap_or(0.0) - settled;
        Self {
            kz,
            error_counts,
            rate,
            band,
            time: band / rate,
            left,
        }
    }

    /// Whether crossing the band can take longer than the run has left.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::lqi::IntegratorWalk;
    /// // 1 V/s across a 0.5 V band: freed in 0.5 s, with 2.5 s of the run left.
    /// let w = IntegratorWalk { kz: 5e4, error_counts: 2.0, rate: 1.0, band: 0.5, time: 0.5, left: 2.5 };
    /// assert!(!w.exceeds_run());
    /// ```
    pub fn exceeds_run(&self) -> bool {
        self.time > self.left
    }
}

/// What a simulated rig is known to have that the prediction has not: the
/// identification's error against its truth, its PWM delay, stiction and
/// encoder noise.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::{SimulatedRig, lqi::KnownDifferences};
/// let sim = SimulatedRig::default();
/// let model = ctrlab::lab::MassSpring { gain: 1.2 * sim.truth.gain, ..sim.truth };
/// let d = KnownDifferences::of(&model, &sim);
/// assert_eq!(d.off().len(), 1); // K, 20 % high
/// assert!(d.stiction && d.delay.is_none() && d.encoder_noise == Some(0.3));
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KnownDifferences {
    /// K, k1, k2, b1, b2: (name, identified, truth).
    pub parameters: [(&'static str, f64, f64); 5],
    /// The card's PWM delay (s), when it differs from [`DRIVE_DELAY`].
    pub delay: Option<f64>,
    /// A cart breaks away above its Coulomb force.
    pub stiction: bool,
    /// The encoders' noise σ (counts), when there is any.
    pub encoder_noise: Option<f64>,
}

impl KnownDifferences {
    /// The identified `model` against `truth`'s card.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::{SimulatedRig, lqi::KnownDifferences};
    /// let sim = SimulatedRig::default();
    /// let d = KnownDifferences::of(&sim.truth, &sim); // identified exactly
    /// assert_eq!((d.worst(), d.off().len()), (0.0, 0));
    /// assert_eq!(d.parameters[0], ("K", sim.truth.gain, sim.truth.gain));
    /// ```
    pub fn of(model: &MassSpring, truth: &SimulatedRig) -> Self {
        let t = &truth.truth;
        Self {
            parameters: [
                ("K", model.gain, t.gain),
                ("k1", model.k1, t.k1),
                ("k2", model.k2, t.k2),
                ("b1", model.b1, t.b1),
                ("b2", model.b2, t.b2),
            ],
            delay: ((truth.card.pwm_delay - DRIVE_DELAY).abs() > 1e-6)
                .then_some(truth.card.pwm_delay),
            stiction: (0..2).any(|i| truth.friction.stiction[i] > truth.friction.coulomb[i]),
            encoder_noise: (truth.card.encoder_noise > 0.0).then_some(truth.card.encoder_noise),
        }
    }

    /// The parameters identified off the truth by more than
    /// [`IDENT_TOLERANCE`].
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::{MassSpring, SimulatedRig, lqi::KnownDifferences};
    /// let sim = SimulatedRig::default();
    /// let model = MassSpring { b1: 0.9 * sim.truth.b1, ..sim.truth };
    /// let off = KnownDifferences::of(&model, &sim).off();
    /// assert_eq!(off, [("b1", model.b1, sim.truth.b1)]); // N·s/m, 10 % low
    /// ```
    pub fn off(&self) -> Vec<(&'static str, f64, f64)> {
        self.parameters
            .iter()
            .copied()
            .filter(|(_, got, want)| (got / want - 1.0).abs() > IDENT_TOLERANCE)
            .collect()
    }

    /// The largest relative identification error of the five.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::{MassSpring, SimulatedRig, lqi::KnownDifferences};
    /// let sim = SimulatedRig::default();
    /// let model = MassSpring { k1: 1.01 * sim.truth.k1, gain: 0.95 * sim.truth.gain, ..sim.truth };
    /// assert!((KnownDifferences::of(&model, &sim).worst() - 0.05).abs() < 1e-12); // K, 5 % low
    /// ```
    pub fn worst(&self) -> f64 {
        self.parameters
            .iter()
            .map(|(_, got, want)| (got / want - 1.0).abs())
            .fold(0.0, f64::max)
    }
}
