//! The lab's TOML files ([`SimulatedRig`](super::SimulatedRig),
//! [`RigConfig`](super::RigConfig)): parse errors that say the line and the
//! dotted key at fault, reads and writes that say the path.

use std::path::Path;

use serde::de::DeserializeOwned;

use crate::error::Error;

/// `T` from TOML `text`. A fault is an [`Error::Toml`] with its line and,
/// when it is in a field, the field's dotted key (`calibration.card_id`,
/// `map.encoder[2]`; for a missing field, the key that is missing).
pub(super) fn parse<T: DeserializeOwned>(text: &str) -> Result<T, Error> {
    let deserializer = toml::Deserializer::parse(text).map_err(|e| toml_error(text, None, &e))?;
    serde_path_to_error::deserialize(deserializer).map_err(|e| {
        let key = key_of(&e.path().to_string(), e.inner().message());
        toml_error(text, key, e.inner())
    })
}

/// The dotted key a deserialisation error is about: the path to where it
/// happened, plus the field's own name when serde reports it missing (the
/// path then ends at the table that lacks it).
fn key_of(path: &str, message: &str) -> Option<String> {
    let table = (path != ".").then_some(path);
    let missing = message
        .strip_prefix("missing field `")
        .and_then(|rest| rest.split('`').next());
    match (table, missing) {
        (Some(table), Some(field)) => Some(format!("{table}.{field}")),
        (None, Some(field)) => Some(field.to_owned()),
        (table, None) => table.map(str::to_owned),
    }
}

fn toml_error(text: &str, key: Option<String>, e: &toml::de::Error) -> Error {
    // The line is one more than the newlines before the fault (a span at
    // the start of a line included).
    let line = e.span().map(|span| {
        text.bytes()
            .take(span.start)
            .filter(|&b| b == b'\n')
            .count()
            + 1
    });
    let mut message = e.message().trim_end().to_owned();
    // A syntax error names no key: quote the line it is on instead.
    if let (None, Some(line)) = (&key, line)
        && let Some(content) = text.lines().nth(line - 1)
    {
        message = format!("{message} (the line reads `{}`)", content.trim());
    }
    Error::Toml { line, key, message }
}

/// The text of the file at `path`.
pub(super) fn read(path: &Path) -> Result<String, Error> {
    std::fs::read_to_string(path).map_err(|e| Error::io(format!("reading {}", path.display()), &e))
}

/// Writes `text` to `path` whole or not at all: into `path` + `.tmp`
/// first, then renamed over `path`, so a crash or a full disk never leaves
/// a half-written file where a complete one is expected.
pub(super) fn write(path: &Path, text: &str) -> Result<(), Error> {
    let mut tmp = path.as_os_str().to_owned();
    tmp.push(".tmp");
    let tmp = Path::new(&tmp);
    std::fs::write(tmp, text)
        .and_then(|()| std::fs::rename(tmp, path))
        .map_err(|e| {
            std::fs::remove_file(tmp).ok();
            Error::io(format!("writing {}", path.display()), &e)
        })
}
