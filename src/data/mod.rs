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
mod recording;
mod schema;

pub use self::csv::{CsvError, CsvErrorKind, CsvOptions, KNOWN_UNITS};
pub use self::recording::Recording;
pub use self::schema::{Channel, Schema};

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
