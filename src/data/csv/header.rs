//! A CSV header: a column's channel, unit and conversion to SI, and the
//! header the writer gives a channel.
//!
//! Names are read in lower case (`X1 [mm]` is channel `x1`). Units keep
//! their SI spelling. How a written unit is matched:
//!
//! - in brackets (`x1 [mm]`, `Time (s)`), a unit of
//!   [`KNOWN_UNITS`](crate::data::KNOWN_UNITS) is matched ignoring case,
//!   except for the letters `m` and `s`: SI gives `M` (mega) and `S`
//!   (siemens) other meanings, so `[MM]` or `[S]` are not taken for
//!   millimetres or seconds (they are kept as written, an unknown unit). So
//!   `[v]` is `V` and `[RAD/s]` is `rad/s`, but `[Mm]` stays `Mm`;
//! - as a suffix (`x1_mm`, `u_V`), the unit must be written as SI writes it:
//!   a suffix such as `_v` or `_n` is as often part of a name (`x_v`,
//!   `mode_n`) as a unit;
//! - raw encoder counts: `[counts]`, `[count]`, `[cnt]` or the suffix
//!   `_counts`, in any case (words, not SI symbols).

use super::KNOWN_UNITS;
use crate::data::Channel;

/// How a column's values become SI.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Scale {
    /// Divide by this (1 for a unit already SI, 1000 for `mm`): a division,
    /// so `0.001` mm is exactly the double nearest 1e-6 m.
    Divide(f64),
    /// Raw encoder counts, read in metres with the caller's calibration
    /// ([`CsvOptions::metres_per_count`](super::CsvOptions::metres_per_count)).
    Counts,
}

/// The spellings of an encoder count in brackets, matched ignoring case.
const COUNT_UNITS: [&str; 3] = ["counts", "count", "cnt"];

/// The suffix of a column in encoder counts, matched ignoring case.
const COUNT_SUFFIX: &str = "_counts";

/// True when `written` spells the unit `spelling`: the same letters,
/// ignoring case except for `m` and `s` (`M` is mega, `S` siemens).
fn same_unit(written: &str, spelling: &str) -> bool {
    written.len() == spelling.len()
        && written.bytes().zip(spelling.bytes()).all(|(w, s)| {
            w == s || (w.eq_ignore_ascii_case(&s) && !matches!(s, b'm' | b's' | b'M' | b'S'))
        })
}

/// Splits a header into a channel (name in lower case, SI unit) and how its
/// values become SI: the bracket form `name [unit]` / `name (unit)` or a
/// known suffix `name_unit`; otherwise the whole header is the name,
/// without a unit. See the module documentation for how units are matched.
pub(super) fn parse_header(header: &str) -> (Channel, Scale) {
    let bracketed = header
        .strip_suffix(']')
        .and_then(|h| h.rsplit_once('['))
        .or_else(|| header.strip_suffix(')').and_then(|h| h.rsplit_once('(')));
    if let Some((name, unit)) = bracketed {
        let (name, unit) = (name.trim().to_lowercase(), unit.trim());
        if COUNT_UNITS.iter().any(|c| unit.eq_ignore_ascii_case(c)) {
            return (Channel::new(name, "m"), Scale::Counts);
        }
        let suffix = unit.replace('/', "_");
        return match KNOWN_UNITS.iter().find(|k| same_unit(&suffix, k.0)) {
            Some(&(_, si, divisor)) => (Channel::new(name, si), Scale::Divide(divisor)),
            None => (Channel::new(name, unit), Scale::Divide(1.0)),
        };
    }
    let split = header.len().checked_sub(COUNT_SUFFIX.len());
    if let Some(at) = split.filter(|&at| at > 0 && header.is_char_boundary(at))
        && header[at..].eq_ignore_ascii_case(COUNT_SUFFIX)
    {
        return (
            Channel::new(header[..at].to_lowercase(), "m"),
            Scale::Counts,
        );
    }
    for &(suffix, si, divisor) in &KNOWN_UNITS {
        if let Some(name) = header
            .strip_suffix(suffix)
            .and_then(|h| h.strip_suffix('_'))
            .filter(|n| !n.is_empty())
        {
            return (
                Channel::new(name.to_lowercase(), si),
                Scale::Divide(divisor),
            );
        }
    }
    (Channel::new(header.to_lowercase(), ""), Scale::Divide(1.0))
}

/// The header the writer uses for `channel`: `name_unit` for a unit in
/// [`KNOWN_UNITS`](crate::data::KNOWN_UNITS) (`/` written as `_`),
/// `name [unit]` for any other unit, `name` alone without one.
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

#[cfg(test)]
mod tests {
    use super::*;

    fn parsed(header: &str) -> (String, String, Scale) {
        let (c, scale) = parse_header(header);
        (c.name, c.unit, scale)
    }

    #[test]
    fn students_spellings_read_as_lower_case_names_in_si() {
        let cases = [
            ("T_s", "t", "s", 1.0),
            ("t [s]", "t", "s", 1.0),
            ("Time (s)", "time", "s", 1.0),
            ("time_s", "time", "s", 1.0),
            ("t_ms", "t", "s", 1000.0),
            ("T [ms]", "t", "s", 1000.0),
            ("u_V", "u", "V", 1.0),
            ("U [V]", "u", "V", 1.0),
            ("U [v]", "u", "V", 1.0),
            ("x1_mm", "x1", "m", 1000.0),
            ("X1 [mm]", "x1", "m", 1000.0),
            ("x2 [m]", "x2", "m", 1.0),
            ("v1 [mm/s]", "v1", "m/s", 1000.0),
            ("F [n]", "f", "N", 1.0),
            ("w [RAD/s]", "w", "rad/s", 1.0),
        ];
        for (header, name, unit, divisor) in cases {
            assert_eq!(
                parsed(header),
                (name.into(), unit.into(), Scale::Divide(divisor)),
                "{header}"
            );
        }
    }

    #[test]
    fn m_and_s_keep_their_case() {
        // Mega and siemens are not milli, metres or seconds: kept as
        // written, units the reader does not know.
        for (header, unit) in [("x [MM]", "MM"), ("x [Mm]", "Mm"), ("t [S]", "S")] {
            assert_eq!(
                parsed(header),
                (header[..1].into(), unit.into(), Scale::Divide(1.0))
            );
        }
        // As a suffix, the unit must be spelled as SI spells it.
        assert_eq!(parsed("u_v"), ("u_v".into(), "".into(), Scale::Divide(1.0)));
        assert_eq!(parsed("T_S"), ("t_s".into(), "".into(), Scale::Divide(1.0)));
        assert!(same_unit("V", "V") && same_unit("v", "V") && same_unit("Rad_s", "rad_s"));
        assert!(!same_unit("mS", "ms") && !same_unit("M", "m") && !same_unit("vv", "V"));
    }

    #[test]
    fn counts_in_any_spelling() {
        for header in [
            "x1_counts",
            "X1_COUNTS",
            "x1 [counts]",
            "x1 [cnt]",
            "X1 (Count)",
        ] {
            assert_eq!(
                parsed(header),
                ("x1".into(), "m".into(), Scale::Counts),
                "{header}"
            );
        }
        // Not a suffix of nothing, nor a word ending in "counts".
        assert_eq!(parsed("_counts").2, Scale::Divide(1.0));
        assert_eq!(parsed("xcounts").2, Scale::Divide(1.0));
        // Multi-byte names do not trip the suffix test.
        assert_eq!(parsed("ü_counts").0, "ü");
        assert_eq!(parsed("éééé").0, "éééé");
    }

    #[test]
    fn written_headers_read_back() {
        for (name, unit) in [
            ("u", "V"),
            ("x1", "m"),
            ("v1", "m/s"),
            ("a", "deg"),
            ("k", ""),
        ] {
            let c = Channel::new(name, unit);
            assert_eq!(parse_header(&header_of(&c)), (c, Scale::Divide(1.0)));
        }
    }
}
