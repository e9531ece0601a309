//! [`Channel`]: a signal's name and unit; [`Schema`]: a recording's inputs
//! and measurements.

use super::MAX_CHANNELS;
use crate::error::Error;

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

/// Which channels a [`Recording`](super::Recording) holds: the inputs (as applied) and the
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
    pub(super) inputs: Vec<Channel>,
    pub(super) measurements: Vec<Channel>,
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

    pub(super) fn names(&self) -> String {
        let mut names = vec!["t".to_string()];
        names.extend(self.channels().map(|c| c.name.clone()));
        names.join(", ")
    }
}
