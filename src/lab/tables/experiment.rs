//! One closed-loop experiment of the lab, as a student runs it: a cart, the
//! lab's gains, a setpoint and a duration ([`Experiment`]); run on a rig
//! and measured ([`ExperimentRun`]). Every row of Tables 5 and 6 is one
//! ([`GainTable::experiment`]), so a row run alone and the same row run in
//! the batch go through the same controller, reference and metrics.

use crate::readable::Readable;
use std::fmt;

use nalgebra::SVector;

use super::{GainTable, RIG_TABLES, RigOutcome};
use crate::data::Recording;
use crate::design::StateFeedback;
use crate::error::Error;
use crate::hw::{self, Clock, EppPort, LoopConfig, LoopStats, RigError, RunError, RunOutcome};
use crate::lab::ident_input::TRAVEL_FRACTION;
use crate::lab::protocol::STEP_DURATION;
use crate::lab::{Calibration, Cart, LabGains, MassSpringRig};

/// The simulated card's noise seed of a table's first row; row `i` (from
/// 0) has `ROW_SEEDS_FROM + i`, as lab5 runs them
/// ([`GainTable::row_seed`]).
///
/// # Examples
///
/// ```
/// use ctrlab::lab::tables::{ROW_SEEDS_FROM, TABLE5, TABLE6};
/// assert_eq!(TABLE5.experiment(0).unwrap().seed(), ROW_SEEDS_FROM);
/// // Each table numbers its rows' seeds afresh.
/// assert_eq!(TABLE6.row_seed(0), TABLE5.row_seed(0));
/// ```
pub const ROW_SEEDS_FROM: u64 = 100;

/// The longest experiment accepted, s: the lab's runs are 3 s; a minute
/// bounds the recording and the time a spring rig is held under drive.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::{Calibration, protocol::STEP_DURATION, tables::{ExperimentError, MAX_DURATION, TABLE5}};
/// assert_eq!(MAX_DURATION / STEP_DURATION, 20.0); // twenty lab runs' worth
/// let long = ctrlab::lab::tables::Experiment { duration: MAX_DURATION + 1.0, ..TABLE5.experiment(0).unwrap() };
/// assert_eq!(long.validate(&Calibration::default()), Err(ExperimentError::Duration(61.0)));
/// ```
pub const MAX_DURATION: f64 = 60.0;

impl GainTable {
    /// Row `row` (from 0) as an experiment: the table's cart and setpoint,
    /// the lab's `G`, [`STEP_DURATION`]. `None` past the last row.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::tables::TABLE5;
    /// let e = TABLE5.experiment(7).unwrap();
    /// assert_eq!((e.gains.kf, e.setpoint_mm, e.duration), ([0.0, 0.0, 10.0, 0.1], 30.0, 3.0));
    /// assert_eq!(e.to_string(), "cart2_kf_0_0_10_0.1_to_30mm");
    /// assert!(TABLE5.experiment(9).is_none());
    /// ```
    pub fn experiment(&self, row: usize) -> Option<Experiment> {
        self.rows().get(row).map(|&kf| Experiment {
            cart: self.cart,
            gains: LabGains::new(kf, self.cart),
            setpoint_mm: self.setpoint_mm,
            duration: STEP_DURATION,
        })
    }

    /// The simulated card's noise seed of row `row` (from 0), as lab5 runs
    /// it: [`ROW_SEEDS_FROM`] + `row`.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::tables::TABLE6;
    /// assert_eq!(TABLE6.row_seed(4), 104);
    /// ```
    pub fn row_seed(&self, row: usize) -> u64 {
        ROW_SEEDS_FROM + row as u64
    }
}

/// One closed-loop experiment: the lab's law `u = Kf (G r − x_mm)` on
/// `cart`, from rest to `setpoint_mm` for `duration` s.
///
/// Its [`Display`](fmt::Display) is a file name that says what ran:
/// `cart2_kf_0_0_10_0.1_to_30mm`, with `_g_…` when `G` is not the lab's
/// and `_5s` when the duration is not the lab's 3 s.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::{Calibration, Cart, LabGains, tables::{Experiment, TABLE5}};
///
/// let e = Experiment {
///     cart: Cart::Two,
///     gains: LabGains::new([0.0, 0.0, 10.0, 0.1], Cart::Two),
///     setpoint_mm: 30.0,
///     duration: 3.0,
/// };
/// e.validate(&Calibration::default())?;
/// // Table 5's eighth row: run alone, it gets the batch's seed.
/// assert_eq!(e.table_row(), Some((TABLE5, 7)));
/// assert_eq!(e.seed(), 107);
/// // 40 mm is beyond 60 % of cart 2's ±50 mm.
/// let far = Experiment { setpoint_mm: 40.0, ..e };
/// assert!(far.validate(&Calibration::default()).unwrap_err().to_string().contains("±30 mm"));
/// # Ok::<(), ctrlab::lab::tables::ExperimentError>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Experiment {
    /// The cart whose position is controlled.
    pub cart: Cart,
    /// `Kf` (V/mm, V/(mm/s)) and `G` (dimensionless).
    pub gains: LabGains,
    /// The setpoint, mm.
    pub setpoint_mm: f64,
    /// The run's length, s.
    pub duration: f64,
}

/// Why an [`Experiment`] is refused before anything is driven.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::{Calibration, LabGains, tables::{ExperimentError, TABLE5}};
/// let e = TABLE5.experiment(0).unwrap();
/// let bad = ctrlab::lab::tables::Experiment { gains: LabGains { kf: [0.0, 0.0, f64::NAN, 0.0], ..e.gains }, ..e };
/// let err = bad.validate(&Calibration::default()).unwrap_err();
/// assert!(matches!(&err, ExperimentError::Gain { name, .. } if name == "Kf3"));
/// assert!(err.to_string().contains("not a finite number"));
/// ```
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ExperimentError {
    /// A gain is NaN or infinite.
    #[error("{name} = {} is not a finite number", Readable(*.value))]
    Gain {
        /// `"Kf1"` … `"Kf4"`, `"G1"` … `"G4"`.
        name: String,
        /// The value given.
        value: f64,
    },
    /// The setpoint is not finite, or beyond [`TRAVEL_FRACTION`] of the
    /// cart's travel limit.
    #[error(
        "setpoint {} mm is not within ±{max_mm} mm, 60 % of cart {cart}'s travel (±{limit_mm} mm): the response overshoots, and the rig halts at its travel limit", Readable(*.setpoint_mm)
    )]
    Setpoint {
        /// The cart, 1 or 2.
        cart: usize,
        /// The setpoint given, mm.
        setpoint_mm: f64,
        /// The largest accepted, mm.
        max_mm: f64,
        /// The cart's travel limit, mm.
        limit_mm: f64,
    },
    /// The duration is not finite, not positive, or above [`MAX_DURATION`].
    #[error("duration {} s must be > 0 and at most {MAX_DURATION} s", Readable(*.0))]
    Duration(f64),
}

impl Experiment {
    /// Checks the experiment against the rig's `calibration` (its travel
    /// limits, m) before anything is driven.
    ///
    /// # Errors
    ///
    /// [`ExperimentError`]: a non-finite gain, a setpoint beyond
    /// [`TRAVEL_FRACTION`] of the cart's travel, a duration not in
    /// (0, [`MAX_DURATION`]] s.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::{Calibration, tables::{Experiment, ExperimentError}};
    /// # use ctrlab::lab::tables::TABLE5;
    /// # let e = TABLE5.experiment(7).unwrap(); // Kf = [0 0 10 0.1], cart 2 to 30 mm
    /// let c = Calibration::default();
    /// assert!(Experiment { setpoint_mm: -30.0, ..e }.validate(&c).is_ok()); // 60 % of 50 mm
    /// assert!(matches!(Experiment { setpoint_mm: 31.0, ..e }.validate(&c), Err(ExperimentError::Setpoint { cart: 2, .. })));
    /// assert_eq!(Experiment { duration: 0.0, ..e }.validate(&c), Err(ExperimentError::Duration(0.0)));
    /// ```
    pub fn validate(&self, calibration: &Calibration) -> Result<(), ExperimentError> {
        let named = |prefix: &str, values: [f64; 4]| {
            values
                .into_iter()
                .enumerate()
                .find(|(_, v)| !v.is_finite())
                .map(|(i, value)| ExperimentError::Gain {
                    name: format!("{prefix}{}", i + 1),
                    value,
                })
        };
        if let Some(e) = named("Kf", self.gains.kf).or_else(|| named("G", self.gains.g)) {
            return Err(e);
        }
        let limit_mm = calibration.travel_limits[self.cart.number() - 1] * 1e3;
        let max_mm = TRAVEL_FRACTION * limit_mm;
        if self.setpoint_mm.is_nan() || self.setpoint_mm.abs() > max_mm {
            return Err(ExperimentError::Setpoint {
                cart: self.cart.number(),
                setpoint_mm: self.setpoint_mm,
                max_mm,
                limit_mm,
            });
        }
        if !(self.duration > 0.0 && self.duration <= MAX_DURATION) {
            return Err(ExperimentError::Duration(self.duration));
        }
        Ok(())
    }

    /// The rig table and row (from 0) this experiment is, if it is one:
    /// the same cart, gains, `G`, setpoint and duration.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::tables::{Experiment, TABLE6};
    /// let e = TABLE6.experiment(14).unwrap();
    /// assert_eq!(e.table_row(), Some((TABLE6, 14)));
    /// // The same gains for 5 s are no row of the lab's.
    /// assert_eq!(Experiment { duration: 5.0, ..e }.table_row(), None);
    /// ```
    pub fn table_row(&self) -> Option<(GainTable, usize)> {
        RIG_TABLES.into_iter().find_map(|table| {
            (0..table.rows().len())
                .find(|&row| table.experiment(row).as_ref() == Some(self))
                .map(|row| (table, row))
        })
    }

    /// The simulated card's noise seed: the matching row's
    /// ([`GainTable::row_seed`]), so that the row run alone gives the
    /// batch's numbers; [`ROW_SEEDS_FROM`] for any other experiment.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::tables::{Experiment, ROW_SEEDS_FROM, TABLE6};
    /// let e = TABLE6.experiment(3).unwrap();
    /// assert_eq!(e.seed(), 103); // as in the batch
    /// assert_eq!(Experiment { setpoint_mm: 10.0, ..e }.seed(), ROW_SEEDS_FROM);
    /// ```
    pub fn seed(&self) -> u64 {
        self.table_row()
            .map_or(ROW_SEEDS_FROM, |(table, row)| table.row_seed(row))
    }

    /// The controller, in SI ([`LabGains::state_feedback`]).
    ///
    /// # Errors
    ///
    /// [`Error::NonFinite`] for a non-finite gain.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::lab::tables::TABLE5;
    /// # let e = TABLE5.experiment(7).unwrap(); // Kf = [0 0 10 0.1], cart 2 to 30 mm
    /// let c = e.controller()?;
    /// // Kf3 = 10 V/mm is 10 000 V/m in SI; Kf4 = 0.1 V/(mm/s) is 100 V/(m/s).
    /// assert!((c.gain()[(0, 2)] - 1e4).abs() < 1e-9 && (c.gain()[(0, 3)] - 100.0).abs() < 1e-9);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn controller(&self) -> Result<StateFeedback<4, 1>, Error> {
        self.gains.state_feedback()
    }

    /// The reference the loop takes: the setpoint in metres, constant.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::lab::tables::TABLE5;
    /// # let e = TABLE5.experiment(7).unwrap(); // Kf = [0 0 10 0.1], cart 2 to 30 mm
    /// let mut r = e.reference();
    /// assert_eq!(r(0.0)[0], 0.030); // m: 30 mm
    /// assert_eq!(r(2.5)[0], r(0.0)[0]);
    /// ```
    pub fn reference(&self) -> impl FnMut(f64) -> SVector<f64, 1> + use<> {
        let setpoint = self.setpoint_mm / 1e3;
        move |_| SVector::<f64, 1>::new(setpoint)
    }

    /// What a run of this experiment measured: a completed run's metrics
    /// ([`RigOutcome::classify`]), or a halted one's cause
    /// ([`RigOutcome::halted`]), with its recording; `volts_full_scale`
    /// (V) is the drive's limit, for telling saturation.
    ///
    /// # Errors
    ///
    /// [`Error::Channel`] when the recording lacks the lab's channels.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::Recording;
    /// use ctrlab::hw::{LoopFault, LoopStats, RigError, RunError};
    /// use ctrlab::lab::tables::{Halt, RigOutcome};
    /// # use ctrlab::lab::tables::TABLE5;
    /// # let e = TABLE5.experiment(7).unwrap(); // Kf = [0 0 10 0.1], cart 2 to 30 mm
    /// # let recording = Recording::from_columns(ctrlab::lab::schema(), vec![0.0, 0.002], vec![vec![0.0; 2]; 5])?;
    /// let error = RigError::Fault(LoopFault::TravelLimit { axis: 2, position: 0.051, limit: 0.05 });
    /// let halted = RunError { error, recording, last_measurement: None, stats: LoopStats::default() };
    /// let run = e.measure(Err(Box::new(halted)), 24.0)?;
    /// assert!(run.fault.is_some());
    /// assert!(matches!(run.outcome, RigOutcome::Diverged { why: Halt::TravelLimit { cart: 2, .. }, .. }));
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn measure(
        &self,
        run: Result<RunOutcome, Box<RunError>>,
        volts_full_scale: f64,
    ) -> Result<ExperimentRun, Error> {
        Ok(match run {
            Ok(out) => ExperimentRun {
                outcome: RigOutcome::classify(
                    &out.recording,
                    self.cart,
                    self.setpoint_mm,
                    volts_full_scale,
                )?,
                recording: out.recording,
                stats: out.stats,
                fault: None,
            },
            Err(e) => {
                let e = *e;
                ExperimentRun {
                    outcome: RigOutcome::halted(&e.recording, &e.error),
                    recording: e.recording,
                    stats: e.stats,
                    fault: Some(e.error),
                }
            }
        })
    }

    /// Runs the experiment on `rig` (simulated or real) timed by `clock`,
    /// with `config`'s loop settings (its duration replaced by this
    /// experiment's), and measures it ([`measure`](Self::measure)).
    ///
    /// # Errors
    ///
    /// [`Error::NonFinite`] for a non-finite gain; a fault of the rig or
    /// the loop is not an error but the run's [`fault`](ExperimentRun::fault).
    ///
    /// # Examples
    ///
    /// Table 5's `Kf = [0 0 10 0.1]` on the default simulated rig, in
    /// virtual time:
    ///
    /// ```
    /// use ctrlab::hw::{Clock, LoopConfig, VirtualClock};
    /// use ctrlab::lab::{CardSettings, SimulatedRig, tables::TABLE5};
    ///
    /// let e = TABLE5.experiment(7).unwrap();
    /// let sim = SimulatedRig::default();
    /// let sim = SimulatedRig { card: CardSettings { seed: e.seed(), ..sim.card }, ..sim };
    /// let clock = Clock::Virtual(VirtualClock::new());
    /// let run = e.run(sim.rig(&clock)?, &clock, &LoopConfig::default())?;
    /// assert!(run.fault.is_none() && run.recording.len() == 1500);
    /// let step = run.outcome.step().expect("settles");
    /// assert!(step.overshoot < 10.0 && step.steady_state_error.unwrap().abs() < 5.0);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn run<P: EppPort>(
        &self,
        rig: MassSpringRig<P>,
        clock: &Clock,
        config: &LoopConfig,
    ) -> Result<ExperimentRun, Error> {
        let volts_full_scale = rig.calibration().volts_full_scale;
        let config = LoopConfig {
            duration: self.duration,
            ..config.clone()
        };
        let outcome = hw::run(rig, self.controller()?, self.reference(), clock, &config);
        self.measure(outcome, volts_full_scale)
    }
}

impl fmt::Display for Experiment {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let join = |v: [f64; 4]| v.map(|x| x.to_string()).join("_");
        write!(f, "cart{}_kf_{}", self.cart.number(), join(self.gains.kf))?;
        if self.gains.g != LabGains::new(self.gains.kf, self.cart).g {
            write!(f, "_g_{}", join(self.gains.g))?;
        }
        write!(f, "_to_{}mm", self.setpoint_mm)?;
        if self.duration != STEP_DURATION {
            write!(f, "_{}s", self.duration)?;
        }
        Ok(())
    }
}

/// A run of an [`Experiment`]: how it ended, with its recording (to the
/// halt, if it halted) and the loop's timing.
///
/// # Examples
///
/// ```
/// use ctrlab::Recording;
/// use ctrlab::hw::LoopStats;
/// use ctrlab::lab::tables::{ExperimentRun, RigOutcome};
/// # let columns = vec![vec![0.0, 12.0, 24.0], vec![0.0; 3], vec![0.0; 3], vec![0.0, 0.004, 0.012], vec![0.0; 3]];
/// # let recording = Recording::from_columns(ctrlab::lab::schema(), vec![0.0, 0.002, 0.004], columns)?;
/// let run = ExperimentRun { outcome: RigOutcome::TooSlow { y_end_mm: 12.0 }, recording, stats: LoopStats::default(), fault: None };
/// assert_eq!(run.recording.channel("x2")?.last(), Some(&0.012)); // m, where the outcome says 12 mm
/// assert!(run.fault.is_none() && run.outcome.step().is_none()); // ran to the end, no metrics
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug)]
pub struct ExperimentRun {
    /// The metrics, or why there are none.
    pub outcome: RigOutcome,
    /// Every sample: `t` (s), `u` (V), `x1`, `v1`, `x2`, `v2` (m, m/s).
    pub recording: Recording,
    /// The loop's timing.
    pub stats: LoopStats,
    /// What halted the run, when something did: a travel limit, a fault of
    /// the rig (a dead encoder, a stalled motor, the drive held at its
    /// limit), the loop's timing, or a stop request (Ctrl-C).
    pub fault: Option<RigError>,
}

impl ExperimentRun {
    /// The drive's peak |u|, V, and the fraction of samples (0–1) at or
    /// above 99 % of `volts_full_scale` (V).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::Recording;
    /// use ctrlab::hw::LoopStats;
    /// use ctrlab::lab::tables::{ExperimentRun, RigOutcome};
    /// let u = vec![24.0, -24.0, 3.0, 0.0];
    /// let columns = vec![u, vec![0.0; 4], vec![0.0; 4], vec![0.0; 4], vec![0.0; 4]];
    /// let recording = Recording::from_columns(ctrlab::lab::schema(), vec![0.0, 0.002, 0.004, 0.006], columns)?;
    /// let run = ExperimentRun {
    ///     outcome: RigOutcome::TooSlow { y_end_mm: 0.0 },
    ///     recording,
    ///     stats: LoopStats::default(),
    ///     fault: None,
    /// };
    /// assert_eq!(run.drive(24.0), (24.0, 0.5));
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn drive(&self, volts_full_scale: f64) -> (f64, f64) {
        drive(&self.recording, volts_full_scale)
    }
}

/// A recording's peak |u|, V, and the fraction of its samples (0–1) at or
/// above 99 % of `volts_full_scale` (V); `(0, 0)` without a `u` channel.
///
/// # Examples
///
/// ```
/// use ctrlab::Recording;
/// let u = vec![24.0, -24.0, 3.0, 0.0];
/// let columns = vec![u, vec![0.0; 4], vec![0.0; 4], vec![0.0; 4], vec![0.0; 4]];
/// let rec = Recording::from_columns(ctrlab::lab::schema(), vec![0.0, 0.002, 0.004, 0.006], columns)?;
/// assert_eq!(ctrlab::lab::tables::drive(&rec, 24.0), (24.0, 0.5));
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub fn drive(recording: &Recording, volts_full_scale: f64) -> (f64, f64) {
    let u = recording.channel("u").unwrap_or(&[]);
    let peak = u.iter().fold(0.0, |m: f64, v| m.max(v.abs()));
    let saturated = u
        .iter()
        .filter(|v| v.abs() >= 0.99 * volts_full_scale)
        .count();
    (peak, saturated as f64 / u.len().max(1) as f64)
}
