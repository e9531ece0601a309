//! Recordings of a run: time stamps, the inputs as applied and the
//! measurements, each a named [`Channel`] with its unit, in SI.
//!
//! A [`Recording`] is what the sampled-data simulator
//! ([`sim::run_sampled`](crate::sim::run_sampled)) and the rig's loop
//! ([`hw::run`](crate::hw::run)) both produce, and what identification and
//! step metrics consume, reading channels by name. Its [`Schema`] says which
//! channels it has; the two-cart lab's layout (`u`; `x1, v1, x2, v2`) is one
//! schema, [`lab::schema`](crate::lab::schema). It reads and writes CSV with
//! the unit in each header, and reads the logs students have: `;` or tab
//! separators, decimal commas, comment lines, any case, raw encoder counts
//! (see [`Recording::from_reader_with`]); what goes wrong doing so is a
//! [`CsvError`].
//!
//! # Examples
//!
//! ```
//! use ctrlab::data::{Channel, Recording, Schema};
//!
//! let schema = Schema::new(vec![Channel::new("u", "V")], vec![Channel::new("x", "m")])?;
//! let mut rec = Recording::with_capacity(schema, 100);
//! rec.push(0.000, &[1.0], &[0.0])?;
//! rec.push(0.002, &[1.0], &[0.0011])?;
//! assert_eq!(rec.channel("x")?, &[0.0, 0.0011]);
//!
//! let mut out = Vec::new();
//! rec.to_writer(&mut out)?; // SI, the unit in each header
//! assert!(String::from_utf8(out).unwrap().starts_with("t_s,u_V,x_m\n"));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod csv;

use nalgebra::SVector;

use crate::error::Error;

pub use self::csv::{CsvError, CsvErrorKind, CsvOptions, KNOWN_UNITS};

/// Largest accepted deviation of one sampling interval from the mean
/// interval, as a fraction of the mean (1 %), when a recording is checked
/// for uniform sampling ([`Recording::sample_period`], the CSV reader).
///
/// # Examples
///
/// ```
/// # use ctrlab::data::{MAX_JITTER, Recording, Schema};
/// let mut rec = Recording::new(Schema::numbered(1, 1)?);
/// for k in 0..10 {
///     rec.push(k as f64 * 0.002, &[0.0], &[0.0])?;
/// }
/// rec.time_mut()[5] += 0.5 * MAX_JITTER * 0.002; // half the limit: accepted
/// assert!(rec.sample_period().is_ok());
/// rec.time_mut()[5] += 1.0 * MAX_JITTER * 0.002; // 1.5 times the limit: refused
/// assert!(rec.sample_period().is_err());
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub const MAX_JITTER: f64 = 0.01;

/// The most channels [`Schema::numbered`] makes: far above any rig's
/// (the lab's has 5), far below what would exhaust memory.
///
/// # Examples
///
/// ```
/// use ctrlab::data::{MAX_CHANNELS, Schema};
/// assert!(Schema::numbered(MAX_CHANNELS, 1).is_err());
/// assert!(Schema::numbered(1 << 40, 0).is_err());
/// # Ok::<(), ctrlab::Error>(())
/// ```
pub const MAX_CHANNELS: usize = 1 << 16;

/// One recorded signal's name and unit.
///
/// The unit is the SI symbol the values are in (`"m"`, `"m/s"`, `"V"`,
/// `"N"`), or empty for a dimensionless or unspecified quantity. Names are
/// what code looks channels up by (`rec.channel("x2")`), and what CSV
/// headers start with.
///
/// # Examples
///
/// ```
/// use ctrlab::data::Channel;
/// let v = Channel::new("v1", "m/s");
/// assert_eq!((v.name.as_str(), v.unit.as_str()), ("v1", "m/s"));
/// assert_eq!(v.to_string(), "v1 (m/s)");
/// ```
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct Channel {
    /// The name, unique within a recording (not `t`, which is time).
    pub name: String,
    /// The SI unit symbol, or empty.
    pub unit: String,
}

impl Channel {
    /// A channel named `name` in `unit`.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::data::Channel;
    /// assert_eq!(Channel::new("u", "V").unit, "V");
    /// ```
    pub fn new(name: impl Into<String>, unit: impl Into<String>) -> Self {
        Self {
            name: name.into(),
            unit: unit.into(),
        }
    }
}

impl std::fmt::Display for Channel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.unit.is_empty() {
            write!(f, "{}", self.name)
        } else {
            write!(f, "{} ({})", self.name, self.unit)
        }
    }
}

/// Which channels a [`Recording`] holds: the inputs (as applied) and the
/// measurements, in order. Time is always there and is not a channel.
///
/// # Examples
///
/// ```
/// use ctrlab::data::{Channel, Schema};
///
/// let s = Schema::numbered(1, 2)?;
/// assert_eq!(s.inputs()[0].name, "u");
/// assert_eq!(s.measurements()[1].name, "y2");
/// assert!(Schema::new(vec![Channel::new("u", "V")], vec![Channel::new("u", "m")]).is_err());
/// # Ok::<(), ctrlab::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Schema {
    inputs: Vec<Channel>,
    measurements: Vec<Channel>,
}

impl Schema {
    /// A schema from its input and measurement channels.
    ///
    /// # Errors
    ///
    /// [`Error::Channel`] for an empty name, a name used twice (or `t`,
    /// which is time), or a name or unit with a character a CSV header
    /// cannot hold (`,` `;` `"` `[` `]` or a control character).
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{Error, data::{Channel, Schema}};
    /// let s = Schema::new(vec![Channel::new("u", "V")], vec![Channel::new("x2", "m")])?;
    /// assert_eq!(s.len(), 2);
    /// let err = Schema::new(vec![], vec![Channel::new("t", "s")]).unwrap_err();
    /// assert!(matches!(err, Error::Channel { .. }));
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn new(inputs: Vec<Channel>, measurements: Vec<Channel>) -> Result<Self, Error> {
        let bad = |name: &str, reason: &str| Error::Channel {
            name: name.to_string(),
            reason: reason.to_string(),
        };
        let mut seen = std::collections::HashSet::with_capacity(inputs.len() + measurements.len());
        for c in inputs.iter().chain(&measurements) {
            if c.name.is_empty() {
                return Err(bad(&c.name, "a channel needs a name"));
            }
            if c.name == "t" {
                return Err(bad(&c.name, "`t` is the time stamps, not a channel"));
            }
            let unusable = |s: &str| {
                s.chars()
                    .any(|ch| ch.is_control() || matches!(ch, ',' | ';' | '"' | '[' | ']'))
            };
            if unusable(&c.name) || unusable(&c.unit) {
                return Err(bad(
                    &c.name,
                    "names and units cannot hold , ; \" [ ] or control characters",
                ));
            }
            // A set, not a scan of the names before: linear in the channels.
            if !seen.insert(c.name.as_str()) {
                return Err(bad(&c.name, "the name is used twice"));
            }
        }
        Ok(Self {
            inputs,
            measurements,
        })
    }

    /// `m` inputs and `p` measurements without units, named as
    /// python-control names signals: `u` (one input) or `u1, u2, …`, and
    /// `y` (one measurement) or `y1, y2, …`.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::data::Schema;
    /// let s = Schema::numbered(2, 1)?;
    /// let names: Vec<_> = s.channels().map(|c| c.name.as_str()).collect();
    /// assert_eq!(names, ["u1", "u2", "y"]);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    ///
    /// # Errors
    ///
    /// [`Error::InvalidParameter`] named `"channels"` for more than
    /// [`MAX_CHANNELS`] channels in all (1 << 40 of them would exhaust
    /// memory).
    pub fn numbered(m: usize, p: usize) -> Result<Self, Error> {
        match m.checked_add(p) {
            Some(n) if n <= MAX_CHANNELS => Ok(Self::numbered_within(m, p)),
            _ => Err(Error::InvalidParameter {
                name: "channels",
                value: m as f64 + p as f64,
                reason: "more inputs and measurements than data::MAX_CHANNELS",
            }),
        }
    }

    /// [`numbered`](Self::numbered) for sizes known small: the const
    /// generic `M`, `P` of a model or rig, checked at compile time.
    pub(crate) fn numbered_const<const M: usize, const P: usize>() -> Self {
        const {
            assert!(
                M + P <= MAX_CHANNELS,
                "more channels than data::MAX_CHANNELS"
            )
        };
        Self::numbered_within(M, P)
    }

    fn numbered_within(m: usize, p: usize) -> Self {
        let names = |prefix: &str, n: usize| -> Vec<Channel> {
            if n == 1 {
                vec![Channel::new(prefix, "")]
            } else {
                (1..=n)
                    .map(|k| Channel::new(format!("{prefix}{k}"), ""))
                    .collect()
            }
        };
        Self {
            inputs: names("u", m),
            measurements: names("y", p),
        }
    }

    /// The input channels, in order.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::data::Schema;
    /// assert_eq!(Schema::numbered(3, 0)?.inputs().len(), 3);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn inputs(&self) -> &[Channel] {
        &self.inputs
    }

    /// The measurement channels, in order.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::data::Schema;
    /// assert_eq!(Schema::numbered(1, 4)?.measurements()[3].name, "y4");
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn measurements(&self) -> &[Channel] {
        &self.measurements
    }

    /// Every channel: the inputs, then the measurements.
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::data::Schema;
    /// assert_eq!(Schema::numbered(1, 1)?.channels().count(), 2);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn channels(&self) -> impl Iterator<Item = &Channel> {
        self.inputs.iter().chain(&self.measurements)
    }

    /// Number of channels (inputs and measurements).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::data::Schema;
    /// assert_eq!(Schema::numbered(1, 4)?.len(), 5);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn len(&self) -> usize {
        self.inputs.len() + self.measurements.len()
    }

    /// True for a schema with no channels (time only).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::data::Schema;
    /// assert!(Schema::numbered(0, 0)?.is_empty());
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Position of channel `name` among [`channels`](Self::channels).
    ///
    /// # Examples
    ///
    /// ```
    /// # use ctrlab::data::Schema;
    /// assert_eq!(Schema::numbered(1, 2)?.position("y2"), Some(2));
    /// assert_eq!(Schema::numbered(1, 2)?.position("x"), None);
    /// # Ok::<(), ctrlab::Error>(())
    /// ```
    pub fn position(&self, name: &str) -> Option<usize> {
        self.channels().position(|c| c.name == name)
    }

    fn names(&self) -> String {
        let mut names = vec!["t".to_string()];
        names.extend(self.channels().map(|c| c.name.clone()));
        names.join(", ")
    }
}

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
    schema: Schema,
    t: Vec<f64>,
    /// One column per channel, in the schema's order.
    columns: Vec<Vec<f64>>,
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
    fn check_values(&self) -> Result<(), Error> {
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
