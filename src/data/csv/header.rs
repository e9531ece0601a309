//! A CSV header: a column's channel and unit, and the header the writer
//! gives a channel.

use super::KNOWN_UNITS;
use crate::data::Channel;

/// Splits a header into a channel (SI unit) and the divisor to SI: the
/// bracket form `name [unit]` / `name (unit)` or a known suffix `name_unit`;
/// otherwise the whole header is the name, without a unit.
pub(super) fn parse_header(header: &str) -> (Channel, f64) {
    let bracketed = header
        .strip_suffix(']')
        .and_then(|h| h.rsplit_once('['))
        .or_else(|| header.strip_suffix(')').and_then(|h| h.rsplit_once('(')));
    if let Some((name, unit)) = bracketed {
        let (name, unit) = (name.trim(), unit.trim());
        let suffix = unit.replace('/', "_");
        return match KNOWN_UNITS.iter().find(|k| k.0 == suffix) {
            Some(&(_, si, divisor)) => (Channel::new(name, si), divisor),
            None => (Channel::new(name, unit), 1.0),
        };
    }
    for &(suffix, si, divisor) in &KNOWN_UNITS {
        if let Some(name) = header
            .strip_suffix(suffix)
            .and_then(|h| h.strip_suffix('_'))
            .filter(|n| !n.is_empty())
        {
            return (Channel::new(name, si), divisor);
        }
    }
    (Channel::new(header, ""), 1.0)
}

/// The header the writer uses for `channel`: `name_unit` for a unit in
/// [`KNOWN_UNITS`](crate::data::KNOWN_UNITS) (`/` written as `_`), `name [unit]` for any other unit,
/// `name` alone without one.
pub(super) fn header_of(channel: &Channel) -> String {
    if channel.unit.is_empty() {
        return channel.name.clone();
    }
    let suffix = channel.unit.replace('/', "_");
    if KNOWN_UNITS.iter().any(|k| k.0 == suffix && k.2 == 1.0) {
        format!("{}_{suffix}", channel.name)
    } else {
        format!("{} [{}]", channel.name, channel.unit)
    }
}
