//! Recordings of a run: time, input and the carts' measured states, in SI.
//!
//! A [`Recording`] is what simulation and the rig produce and what
//! identification and step metrics consume. It reads and writes CSV whose
//! header names carry the unit (see [`Recording::from_reader`]).
//!
//! # Examples
//!
//! ```
//! use ctrlab::Recording;
//!
//! let log = "t_s,u,x1_mm,x2_mm\n0,1,0,0\n0.002,1,0,0.05\n0.004,1,0.01,0.2\n\
//!            0.006,1,0.05,0.4\n0.008,1,0.1,0.7\n0.010,1,0.2,1.1\n";
//! let rec = Recording::from_reader(log.as_bytes())?;
//! assert_eq!(rec.x2[5], 0.0011); // metres inside
//! let mut out = Vec::new();
//! rec.to_writer(&mut out)?; // written back in metres
//! assert!(String::from_utf8(out).unwrap().starts_with("t_s,u,x1_m,x2_m\n"));
//! # Ok::<(), ctrlab::Error>(())
//! ```

mod csv;

use nalgebra::SVector;

use crate::error::Error;

/// Fewest data rows [`Recording::from_reader`] accepts: the fewest samples
/// the identifiers in [`ident::mass_spring`](crate::ident::mass_spring)
/// can use (three unknowns, one residual degree of freedom, and the two
/// samples the finite differences consume).
///
/// # Examples
///
/// ```
/// # use ctrlab::{data::MIN_ROWS, Error, Recording};
/// let header_and_five_rows = "t_s,u,x1_m,x2_m\n0,0,0,0\n1,0,0,0\n2,0,0,0\n3,0,0,0\n4,0,0,0\n";
/// assert_eq!(MIN_ROWS, 6);
/// assert!(matches!(Recording::from_reader(header_and_five_rows.as_bytes()), Err(Error::Csv { line: 6, .. })));
/// ```
pub const MIN_ROWS: usize = 6;

/// Largest accepted deviation of one sampling interval from the mean
/// interval, as a fraction of the mean (1 %). The identifiers assume a
/// uniform sampling period.
///
/// # Examples
///
/// ```
/// # use ctrlab::{data::MAX_JITTER, Recording};
/// let mut rec = Recording::new();
/// for k in 0..10 {
///     rec.push(k as f64 * 0.002, 0.0, 0.0, 0.0);
/// }
/// rec.t[5] += 0.5 * MAX_JITTER * 0.002; // half the limit: accepted
/// assert!(rec.sample_period().is_ok());
/// rec.t[5] += 1.0 * MAX_JITTER * 0.002; // 1.5 times the limit: refused
/// assert!(rec.sample_period().is_err());
/// ```
pub const MAX_JITTER: f64 = 0.01;

/// One run of the rig or of a simulation: column vectors of equal length,
/// SI units.
///
/// `u[k]` is the input applied (held) from `t[k]` until `t[k + 1]`, as a
/// digital controller applies it; `x1[k]`, `x2[k]` (and the velocities) are
/// measured at `t[k]`. The velocity columns are `Some` only while every
/// sample has them.
///
/// # Examples
///
/// ```
/// use ctrlab::Recording;
/// use nalgebra::vector;
///
/// let mut rec = Recording::with_capacity(2);
/// rec.push(0.0, 1.0, 0.0, 0.0);
/// rec.push(0.002, 1.0, 0.001, 0.002);
/// assert_eq!(rec.len(), 2);
/// assert_eq!(rec.x2[1], 0.002);
/// assert!(rec.v1.is_none()); // `push` records positions only
///
/// let mut with_v = Recording::new();
/// with_v.push_state(0.0, 2.0, &vector![0.001, 0.1, 0.002, 0.2]);
/// assert_eq!(with_v.v2.as_deref(), Some(&[0.2][..]));
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct Recording {
    /// Sample times, s, strictly increasing.
    pub t: Vec<f64>,
    /// Input held from `t[k]` to `t[k+1]` (V on the rig, N in simulation).
    pub u: Vec<f64>,
    /// Position of cart 1, m.
    pub x1: Vec<f64>,
    /// Position of cart 2, m.
    pub x2: Vec<f64>,
    /// Velocity of cart 1, m/s, when measured.
    pub v1: Option<Vec<f64>>,
    /// Velocity of cart 2, m/s, when measured.
    pub v2: Option<Vec<f64>>,
}

/// Same as [`Recording::new`].
impl Default for Recording {
    fn default() -> Self {
        Self::new()
    }
}

impl Recording {
    /// An empty recording, ready to take samples with or without velocities.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::Recording;
    /// let rec = Recording::new();
    /// assert!(rec.is_empty());
    /// ```
    pub fn new() -> Self {
        Self::with_capacity(0)
    }

    /// An empty recording with room for `n` samples in every column
    /// (velocities included), so that [`push`](Self::push) and
    /// [`push_state`](Self::push_state) do not allocate for the first `n`.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::Recording;
    /// let rec = Recording::with_capacity(5000);
    /// assert!(rec.t.capacity() >= 5000);
    /// assert!(rec.v1.as_ref().unwrap().capacity() >= 5000);
    /// ```
    pub fn with_capacity(n: usize) -> Self {
        Self {
            t: Vec::with_capacity(n),
            u: Vec::with_capacity(n),
            x1: Vec::with_capacity(n),
            x2: Vec::with_capacity(n),
            v1: Some(Vec::with_capacity(n)),
            v2: Some(Vec::with_capacity(n)),
        }
    }

    /// Number of samples (length of the time column).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::Recording;
    /// let mut rec = Recording::new();
    /// rec.push(0.0, 0.0, 0.0, 0.0);
    /// assert_eq!(rec.len(), 1);
    /// ```
    pub fn len(&self) -> usize {
        self.t.len()
    }

    /// True when there are no samples.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::Recording;
    /// assert!(Recording::new().is_empty());
    /// ```
    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }

    /// Appends one sample without velocities: time `t` (s), input `u`,
    /// positions `x1`, `x2` (m). Does not allocate when capacity suffices.
    ///
    /// A recording holds velocities only if every sample has them, so this
    /// drops velocity columns that already hold samples.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::Recording;
    /// let mut rec = Recording::new();
    /// rec.push(0.0, 1.5, 0.010, 0.020);
    /// assert_eq!((rec.t[0], rec.u[0], rec.x1[0], rec.x2[0]), (0.0, 1.5, 0.010, 0.020));
    /// assert!(rec.v1.is_none());
    /// ```
    pub fn push(&mut self, t: f64, u: f64, x1: f64, x2: f64) {
        self.t.push(t);
        self.u.push(u);
        self.x1.push(x1);
        self.x2.push(x2);
        self.v1 = None;
        self.v2 = None;
    }

    /// Appends one sample from a state `[x1 (m), v1 (m/s), x2 (m), v2 (m/s)]`,
    /// velocities included, at time `t` (s) with input `u`. Does not allocate
    /// when capacity suffices.
    ///
    /// On a recording whose earlier samples have no velocities, only the
    /// positions are recorded (the velocity columns stay `None`).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::Recording;
    /// # use nalgebra::vector;
    /// let mut rec = Recording::with_capacity(1);
    /// rec.push_state(0.0, 1.0, &vector![0.001, 0.01, 0.002, 0.02]);
    /// assert_eq!(rec.v1.as_deref(), Some(&[0.01][..]));
    /// assert_eq!(rec.x2, vec![0.002]);
    /// ```
    pub fn push_state(&mut self, t: f64, u: f64, state: &SVector<f64, 4>) {
        let n = self.t.len();
        let keep_velocities = match (&self.v1, &self.v2) {
            (Some(a), Some(b)) => a.len() == n && b.len() == n,
            (None, None) => n == 0,
            _ => false,
        };
        self.t.push(t);
        self.u.push(u);
        self.x1.push(state[0]);
        self.x2.push(state[2]);
        if keep_velocities {
            self.v1.get_or_insert_with(Vec::new).push(state[1]);
            self.v2.get_or_insert_with(Vec::new).push(state[3]);
        } else {
            self.v1 = None;
            self.v2 = None;
        }
    }

    /// Checks the recording is usable: all columns as long as `t`, every
    /// value finite, `t` strictly increasing and uniformly sampled (each
    /// interval within [`MAX_JITTER`] of the mean). Returns the mean sampling
    /// period, s.
    ///
    /// # Errors
    ///
    /// [`Error::InvalidRecording`] naming the first sample at fault (and the
    /// jitter for an irregular time column); [`Error::TooFewSamples`] for
    /// fewer than two samples.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::{Error, Recording};
    /// let mut rec = Recording::new();
    /// for k in 0..10 {
    ///     rec.push(k as f64 * 0.002, 0.0, 0.0, 0.0);
    /// }
    /// assert!((rec.sample_period()? - 0.002).abs() < 1e-15);
    /// rec.t[5] = 0.0101; // one interval 5 % long, the next 5 % short
    /// assert!(matches!(rec.sample_period(), Err(Error::InvalidRecording { index: 5, .. })));
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn sample_period(&self) -> Result<f64, Error> {
        let n = self.len();
        let mut columns: Vec<(&str, &[f64])> =
            vec![("u", &self.u), ("x1", &self.x1), ("x2", &self.x2)];
        if let Some(v) = &self.v1 {
            columns.push(("v1", v));
        }
        if let Some(v) = &self.v2 {
            columns.push(("v2", v));
        }
        for (name, col) in &columns {
            if col.len() != n {
                return Err(Error::InvalidRecording {
                    index: col.len().min(n),
                    reason: format!("column {name} has {} samples, t has {n}", col.len()),
                });
            }
        }
        columns.push(("t", &self.t));
        for (name, col) in &columns {
            if let Some(k) = crate::reduce::first_non_finite(col) {
                return Err(Error::InvalidRecording {
                    index: k,
                    reason: format!("{name} = {} is not finite", col[k]),
                });
            }
        }
        if n < 2 {
            return Err(Error::TooFewSamples {
                what: "a sampling period",
                needed: 2,
                got: n,
            });
        }
        check_time(&self.t).map_err(|(index, reason)| Error::InvalidRecording { index, reason })
    }
}

/// Checks a time column (at least two finite values) is strictly increasing
/// and uniformly sampled; returns the mean period, or the index of the first
/// offending sample and why.
fn check_time(t: &[f64]) -> Result<f64, (usize, String)> {
    let dt = (t[t.len() - 1] - t[0]) / (t.len() - 1) as f64;
    let limit = MAX_JITTER * dt;
    // Fast vectorisable pass: every interval within 1 % of a positive mean
    // implies a strictly increasing column. The loops below find and
    // describe the culprit otherwise.
    let worst = crate::reduce::max_step_deviation(t, dt);
    // A finite period only: alternating ±1e308 overflows the mean to inf,
    // and every step then looks within the (infinite) jitter limit.
    if dt.is_finite() && dt > 0.0 && worst <= limit {
        return Ok(dt);
    }
    for k in 1..t.len() {
        if t[k] <= t[k - 1] {
            return Err((
                k,
                format!(
                    "time {} s does not increase (previous {} s)",
                    t[k],
                    t[k - 1]
                ),
            ));
        }
    }
    for k in 1..t.len() {
        let jitter = (t[k] - t[k - 1] - dt) / dt;
        // NaN comes from a span that overflows to inf: irregular too.
        if jitter.is_nan() || jitter.abs() > MAX_JITTER {
            return Err((
                k,
                format!(
                    "irregular sampling: interval {:.6e} s differs from the mean {:.6e} s by {:+.2} % (limit {} %)",
                    t[k] - t[k - 1],
                    dt,
                    jitter * 100.0,
                    MAX_JITTER * 100.0
                ),
            ));
        }
    }
    Ok(dt)
}
