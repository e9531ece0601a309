//! [`Recording`]: time stamps and one column per channel, in SI.

use nalgebra::SVector;

use super::{MAX_JITTER, Schema};
use crate::error::Error;

/// One run of a rig or of a simulation: time stamps and one column per
/// channel of its [`Schema`], all of equal length, in SI units.
///
/// `input[k]` is the input applied (held) from `t[k]` until `t[k + 1]`, as a
/// digital controller applies it; measurements are taken at `t[k]`.
///
/// Pushing a sample allocates nothing while the capacity lasts
/// ([`with_capacity`](Self::with_capacity)); the rig's loop relies on that.
///
/// # Examples
///
/// ```
/// use ctrlab::data::{Recording, Schema};
/// use ctrlab::nalgebra::vector;
///
/// let mut rec = Recording::with_capacity(Schema::numbered(1, 2)?, 2);
/// rec.push_vectors(0.0, &vector![1.0], &vector![0.0, 0.0])?;
/// rec.push_vectors(0.002, &vector![1.0], &vector![0.001, 0.002])?;
/// assert_eq!(rec.len(), 2);
/// assert_eq!(rec.channel("y2")?[1], 0.002);
/// assert_eq!(rec.measurement(0), Some(&[0.0, 0.001][..]));
/// assert!(rec.channel("x2").unwrap_err().to_string().contains("t, u, y1, y2"));
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct Recording {
    pub(super) schema: Schema,
    pub(super) t: Vec<f64>,
    /// One column per channel, in the schema's order.
    pub(super) columns: Vec<Vec<f64>>,
}

impl Recording {
    /// An empty recording of `schema`.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::data::{Recording, Schema};
    /// let rec = Recording::new(Schema::numbered(1, 1)?);
    /// assert!(rec.is_empty());
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn new(schema: Schema) -> Self {
        Self::with_capacity(schema, 0)
    }

    /// An empty recording of `schema` with room for `n` samples in every
    /// column, so that pushing the first `n` does not allocate. `n` is a
    /// hint: room the allocator refuses (`usize::MAX` samples) is not
    /// reserved, and the columns grow as samples come.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::data::{Recording, Schema};
    /// let rec = Recording::with_capacity(Schema::numbered(1, 4)?, 5000);
    /// assert!(rec.capacity() >= 5000);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn with_capacity(schema: Schema, n: usize) -> Self {
        // A hint: a capacity the allocator refuses (usize::MAX) is not
        // reserved, and the columns grow as samples come.
        let column = || {
            let mut v = Vec::new();
            let _ = v.try_reserve_exact(n);
            v
        };
        let columns = (0..schema.len()).map(|_| column()).collect();
        Self {
            schema,
            t: column(),
            columns,
        }
    }

    /// A recording from columns already in memory: time stamps `t` (s) and
    /// one column per channel of `schema`, in its order.
    ///
    /// # Errors
    ///
    /// [`Error::LengthMismatch`] for a wrong number of columns or a column
    /// whose length differs from `t`'s; [`Error::InvalidRecording`] for a
    /// non-finite value or a time that does not increase.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::data::{Recording, Schema};
    /// let rec = Recording::from_columns(Schema::numbered(1, 1)?, vec![0.0, 0.1], vec![vec![1.0, 1.0], vec![0.0, 0.5]])?;
    /// assert_eq!(rec.channel("y")?, &[0.0, 0.5]);
    /// assert!(Recording::from_columns(Schema::numbered(1, 1)?, vec![0.0, 0.1], vec![vec![1.0]]).is_err());
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn from_columns(
        schema: Schema,
        t: Vec<f64>,
        columns: Vec<Vec<f64>>,
    ) -> Result<Self, Error> {
        if columns.len() != schema.len() {
            return Err(Error::LengthMismatch {
                what: "columns (one per channel)",
                expected: schema.len(),
                found: columns.len(),
            });
        }
        if columns.iter().any(|c| c.len() != t.len()) {
            let found = columns
                .iter()
                .map(Vec::len)
                .find(|&n| n != t.len())
                .unwrap_or(0);
            return Err(Error::LengthMismatch {
                what: "a channel column",
                expected: t.len(),
                found,
            });
        }
        let rec = Self { schema, t, columns };
        rec.check_values()?;
        if let Some(k) = (1..rec.t.len()).find(|&k| rec.t[k] <= rec.t[k - 1]) {
            return Err(Error::InvalidRecording {
                index: k,
                reason: format!(
                    "time {} s does not increase (previous {} s)",
                    rec.t[k],
                    rec.t[k - 1]
                ),
            });
        }
        Ok(rec)
    }

    /// The schema: which channels there are.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::data::{Recording, Schema};
    /// assert_eq!(Recording::new(Schema::numbered(2, 3)?).schema().len(), 5);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn schema(&self) -> &Schema {
        &self.schema
    }

    /// Number of samples.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::data::{Recording, Schema};
    /// let mut rec = Recording::new(Schema::numbered(1, 1)?);
    /// rec.push(0.0, &[0.0], &[0.0])?;
    /// assert_eq!(rec.len(), 1);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn len(&self) -> usize {
        self.t.len()
    }

    /// True when there are no samples.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::data::{Recording, Schema};
    /// assert!(Recording::new(Schema::numbered(1, 1)?).is_empty());
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }

    /// Samples every column can take without allocating.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::data::{Recording, Schema};
    /// assert!(Recording::with_capacity(Schema::numbered(1, 1)?, 10).capacity() >= 10);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn capacity(&self) -> usize {
        self.columns
            .iter()
            .map(Vec::capacity)
            .fold(self.t.capacity(), usize::min)
    }

    /// The time stamps, s.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::data::{Recording, Schema};
    /// let mut rec = Recording::new(Schema::numbered(1, 1)?);
    /// rec.push(0.5, &[0.0], &[0.0])?;
    /// assert_eq!(rec.time(), &[0.5]);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn time(&self) -> &[f64] {
        &self.t
    }

    /// The time stamps, mutably (to shift or perturb them; the length is
    /// fixed).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::data::{Recording, Schema};
    /// let mut rec = Recording::new(Schema::numbered(1, 1)?);
    /// rec.push(0.5, &[0.0], &[0.0])?;
    /// rec.time_mut()[0] = 0.0;
    /// assert_eq!(rec.time(), &[0.0]);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn time_mut(&mut self) -> &mut [f64] {
        &mut self.t
    }

    /// The samples of channel `name` (input or measurement).
    ///
    /// # Errors
    ///
    /// [`Error::Channel`] when there is no such channel; the message lists
    /// the channels there are.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::data::{Recording, Schema};
    /// let mut rec = Recording::new(Schema::numbered(1, 1)?);
    /// rec.push(0.0, &[2.0], &[0.1])?;
    /// assert_eq!(rec.channel("u")?, &[2.0]);
    /// assert!(rec.channel("x1").is_err());
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn channel(&self, name: &str) -> Result<&[f64], Error> {
        let k = self.position(name)?;
        Ok(&self.columns[k])
    }

    /// The samples of channel `name`, mutably (to add noise, scale, …; the
    /// length is fixed).
    ///
    /// # Errors
    ///
    /// As [`channel`](Self::channel).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::data::{Recording, Schema};
    /// let mut rec = Recording::new(Schema::numbered(1, 1)?);
    /// rec.push(0.0, &[2.0], &[0.1])?;
    /// rec.channel_mut("y")?[0] += 0.05;
    /// assert_eq!(rec.channel("y")?, &[0.1 + 0.05]);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn channel_mut(&mut self, name: &str) -> Result<&mut [f64], Error> {
        let k = self.position(name)?;
        Ok(&mut self.columns[k])
    }

    fn position(&self, name: &str) -> Result<usize, Error> {
        self.schema.position(name).ok_or_else(|| Error::Channel {
            name: name.to_string(),
            reason: format!(
                "no such channel; the recording has: {}",
                self.schema.names()
            ),
        })
    }

    /// Input `i`'s samples, if there is an input `i`.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::data::{Recording, Schema};
    /// let mut rec = Recording::new(Schema::numbered(1, 1)?);
    /// rec.push(0.0, &[2.0], &[0.1])?;
    /// assert_eq!(rec.input(0), Some(&[2.0][..]));
    /// assert_eq!(rec.input(1), None);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn input(&self, i: usize) -> Option<&[f64]> {
        (i < self.schema.inputs.len()).then(|| &self.columns[i][..])
    }

    /// Measurement `i`'s samples, if there is a measurement `i`.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::data::{Recording, Schema};
    /// let mut rec = Recording::new(Schema::numbered(1, 1)?);
    /// rec.push(0.0, &[2.0], &[0.1])?;
    /// assert_eq!(rec.measurement(0), Some(&[0.1][..]));
    /// assert_eq!(rec.measurement(1), None);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn measurement(&self, i: usize) -> Option<&[f64]> {
        let m = self.schema.inputs.len();
        (i < self.schema.measurements.len()).then(|| &self.columns[m + i][..])
    }

    /// Appends one sample: time `t` (s), the inputs as applied `u` and the
    /// measurements `y`, in the schema's order. Allocates nothing while the
    /// capacity lasts.
    ///
    /// # Errors
    ///
    /// [`Error::LengthMismatch`] when `u` or `y` does not have one value per
    /// channel (nothing is appended).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::data::{Recording, Schema};
    /// let mut rec = Recording::new(Schema::numbered(1, 2)?);
    /// rec.push(0.0, &[1.5], &[0.010, 0.020])?;
    /// assert_eq!(rec.channel("y2")?, &[0.020]);
    /// assert!(rec.push(0.1, &[1.5], &[0.0]).is_err());
    /// assert_eq!(rec.len(), 1);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn push(&mut self, t: f64, u: &[f64], y: &[f64]) -> Result<(), Error> {
        let (m, p) = (self.schema.inputs.len(), self.schema.measurements.len());
        if u.len() != m {
            return Err(Error::LengthMismatch {
                what: "inputs of a sample",
                expected: m,
                found: u.len(),
            });
        }
        if y.len() != p {
            return Err(Error::LengthMismatch {
                what: "measurements of a sample",
                expected: p,
                found: y.len(),
            });
        }
        self.t.push(t);
        for (col, &v) in self.columns.iter_mut().zip(u.iter().chain(y)) {
            col.push(v);
        }
        Ok(())
    }

    /// [`push`](Self::push) from nalgebra vectors.
    ///
    /// # Errors
    ///
    /// As [`push`](Self::push).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::data::{Recording, Schema};
    /// # use ctrlab::nalgebra::vector;
    /// let mut rec = Recording::with_capacity(Schema::numbered(1, 4)?, 1);
    /// rec.push_vectors(0.0, &vector![1.0], &vector![0.001, 0.01, 0.002, 0.02])?;
    /// assert_eq!(rec.channel("y2")?, &[0.01]);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn push_vectors<const M: usize, const P: usize>(
        &mut self,
        t: f64,
        u: &SVector<f64, M>,
        y: &SVector<f64, P>,
    ) -> Result<(), Error> {
        self.push(t, u.as_slice(), y.as_slice())
    }

    /// Touches every column's spare capacity so its pages are mapped (and,
    /// under `mlockall`, locked) before a real-time loop pushes into it.
    #[cfg(feature = "hw")]
    pub(crate) fn prefault(&mut self) {
        for col in std::iter::once(&mut self.t).chain(self.columns.iter_mut()) {
            let (len, capacity) = (col.len(), col.capacity());
            col.resize(capacity, 0.0);
            col.truncate(len);
        }
    }

    /// Checks every value is finite (time included).
    pub(super) fn check_values(&self) -> Result<(), Error> {
        let named = std::iter::once(("t", &self.t)).chain(
            self.schema
                .channels()
                .map(|c| c.name.as_str())
                .zip(&self.columns),
        );
        for (name, col) in named {
            if let Some(k) = crate::kernels::reduce::first_non_finite(col) {
                return Err(Error::InvalidRecording {
                    index: k,
                    reason: format!("{name} = {} is not finite", col[k]),
                });
            }
        }
        Ok(())
    }

    /// Checks the recording is uniformly sampled and returns its mean
    /// sampling period, s: every value finite, time strictly increasing,
    /// each interval within [`MAX_JITTER`] of the mean.
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
    /// # use ctrlab::{Error, data::{Recording, Schema}};
    /// let mut rec = Recording::new(Schema::numbered(1, 1)?);
    /// for k in 0..10 {
    ///     rec.push(k as f64 * 0.002, &[0.0], &[0.0])?;
    /// }
    /// assert!((rec.sample_period()? - 0.002).abs() < 1e-15);
    /// rec.time_mut()[5] = 0.0101; // one interval 5 % long, the next 5 % short
    /// assert!(matches!(rec.sample_period(), Err(Error::InvalidRecording { index: 5, .. })));
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn sample_period(&self) -> Result<f64, Error> {
        self.check_values()?;
        let n = self.len();
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
    let worst = crate::kernels::reduce::max_step_deviation(t, dt);
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
