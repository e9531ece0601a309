//! The lab's TOML files ([`SimulatedRig`](super::SimulatedRig)'s truth
//! files, [`RigConfig`](super::RigConfig)'s card files) and their error,
//! [`FileError`]: a fault says the path, the line and the dotted key.

use crate::readable::Readable;
use std::path::{Path, PathBuf};

use serde::Serialize;
use serde::de::DeserializeOwned;

use crate::hw::ConfigError;

/// The category of a [`FileError`].
///
/// `#[non_exhaustive]`: match with a wildcard arm.
///
/// # Examples
///
/// ```
/// use ctrlab::lab::{FileErrorKind, SimulatedRig};
/// let err = SimulatedRig::from_toml("gian = 1.2").unwrap_err();
/// assert_eq!(err.kind(), FileErrorKind::UnknownKey);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum FileErrorKind {
    /// The file could not be read or written.
    Io,
    /// The text is not TOML.
    Syntax,
    /// A key the file may not have (a typo).
    UnknownKey,
    /// A key the file must have (card files require every key).
    MissingKey,
    /// A value of the wrong type, or outside its type's range (a string
    /// for a number, 300 for a byte).
    WrongType,
    /// A value the configuration's checks refuse (a negative mass, two
    /// carts on one encoder).
    Invalid,
}

/// Reading, parsing or writing one of the lab's TOML files failed: a
/// simulated rig's truth ([`SimulatedRig`](super::SimulatedRig)) or a real
/// card's map and calibration ([`RigConfig`](super::RigConfig)).
///
/// Each fault says where: the path (when the text came from a file), the
/// one-based line (when it is known) and the dotted key (`truth.m1`,
/// `calibration.card_id`, `map.encoder[2]`). A value the checks refuse
/// carries the [`ConfigError`] the same value gives in code, whose key is
/// the file's key.
///
/// `#[non_exhaustive]`: match with a wildcard arm, or on [`kind`](Self::kind).
///
/// # Examples
///
/// ```
/// use ctrlab::lab::{FileError, FileErrorKind, SimulatedRig};
///
/// let err = SimulatedRig::from_toml("[truth]\nm1 = \"heavy\"").unwrap_err();
/// assert_eq!(err.kind(), FileErrorKind::WrongType);
/// assert_eq!((err.line(), err.key()), (Some(2), Some("truth.m1")));
/// assert!(err.to_string().starts_with("TOML line 2, key `truth.m1`: invalid type"), "{err}");
///
/// let err = SimulatedRig::read_toml("no/such/truth.toml").unwrap_err();
/// assert!(matches!(err, FileError::Io { .. }));
/// assert!(err.to_string().starts_with("reading no/such/truth.toml: "), "{err}");
/// ```
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum FileError {
    /// Reading or writing the file failed.
    #[error("{operation} {}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// `"reading"` or `"writing"`.
        operation: &'static str,
        /// The operating system's error.
        #[source]
        source: std::io::Error,
    },
    /// The text is not TOML; the message quotes the line.
    #[error("{}: {message}", place(path, *line, None))]
    Syntax {
        /// The file, when the text came from one.
        path: Option<PathBuf>,
        /// One-based line of the fault, when the parser knows it.
        line: Option<usize>,
        /// The parser's message.
        message: String,
    },
    /// A key the file may not have.
    #[error("{}: {message}", place(path, *line, Some(key)))]
    UnknownKey {
        /// The file, when the text came from one.
        path: Option<PathBuf>,
        /// One-based line of the key, when known.
        line: Option<usize>,
        /// Its dotted key.
        key: String,
        /// The parser's message, with the keys the table may have.
        message: String,
    },
    /// A key the file must have is missing.
    #[error("{}: {message}", place(path, *line, Some(key)))]
    MissingKey {
        /// The file, when the text came from one.
        path: Option<PathBuf>,
        /// One-based line of the table that lacks it, when known.
        line: Option<usize>,
        /// The dotted key that is missing (a table's name when the whole
        /// table is).
        key: String,
        /// The parser's message.
        message: String,
    },
    /// A value of the wrong type, or outside its type's range.
    #[error("{}: {message}", place(path, *line, key.as_deref()))]
    WrongType {
        /// The file, when the text came from one.
        path: Option<PathBuf>,
        /// One-based line of the value, when known.
        line: Option<usize>,
        /// Its dotted key, when the fault is in a field.
        key: Option<String>,
        /// The parser's message (what was found, what was expected).
        message: String,
    },
    /// A value the checks refuse: the [`ConfigError`] the same value gives
    /// in code (its key is the file's dotted key).
    #[error(
        "{}: {} is refused: {}",
        place(path, *line, Some(error.key())),
        shown(error.key(), error.value()),
        error.reason()
    )]
    Invalid {
        /// The file, when the text came from one.
        path: Option<PathBuf>,
        /// One-based line of the value, when known.
        line: Option<usize>,
        /// What the checks say.
        #[source]
        error: ConfigError,
    },
}

/// `path: TOML line 3, key `k``, each part when known.
fn place(path: &Option<PathBuf>, line: Option<usize>, key: Option<&str>) -> String {
    let mut out = String::new();
    if let Some(path) = path {
        out.push_str(&format!("{}: ", path.display()));
    }
    out.push_str("TOML");
    if let Some(line) = line {
        out.push_str(&format!(" line {line}"));
    }
    if let Some(key) = key {
        out.push_str(&format!(", key `{key}`"));
    }
    out
}

/// A refused value as the file writes it: register addresses, bit masks
/// and card IDs in hex.
fn shown(key: &str, value: f64) -> String {
    let base = key.split('[').next().unwrap_or(key);
    let hex = base.contains("map.") || base.ends_with("card_id");
    if hex && (0.0..=255.0).contains(&value) && value.fract() == 0.0 {
        format!("{:#04x}", value as u8)
    } else {
        Readable(value).to_string()
    }
}

impl FileError {
    /// The category of this error.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{hw::RegisterMap, lab::{Calibration, FileErrorKind, RigConfig}};
    /// let card = RigConfig::new(RegisterMap::default(), Calibration::default());
    /// let text = card.to_toml().replace("stall_counts = 3", "stall_counts = 0");
    /// assert_eq!(RigConfig::from_toml(&text).unwrap_err().kind(), FileErrorKind::Invalid);
    /// ```
    pub fn kind(&self) -> FileErrorKind {
        match self {
            FileError::Io { .. } => FileErrorKind::Io,
            FileError::Syntax { .. } => FileErrorKind::Syntax,
            FileError::UnknownKey { .. } => FileErrorKind::UnknownKey,
            FileError::MissingKey { .. } => FileErrorKind::MissingKey,
            FileError::WrongType { .. } => FileErrorKind::WrongType,
            FileError::Invalid { .. } => FileErrorKind::Invalid,
        }
    }

    /// The file, when the text came from one.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::SimulatedRig;
    /// let err = SimulatedRig::read_toml("no/such/truth.toml").unwrap_err();
    /// assert_eq!(err.path(), Some(std::path::Path::new("no/such/truth.toml")));
    /// assert_eq!(SimulatedRig::from_toml("x = 1").unwrap_err().path(), None);
    /// ```
    pub fn path(&self) -> Option<&Path> {
        match self {
            FileError::Io { path, .. } => Some(path),
            FileError::Syntax { path, .. }
            | FileError::UnknownKey { path, .. }
            | FileError::MissingKey { path, .. }
            | FileError::WrongType { path, .. }
            | FileError::Invalid { path, .. } => path.as_deref(),
        }
    }

    /// The one-based line of the fault, when known.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::lab::SimulatedRig;
    /// let err = SimulatedRig::from_toml("period = 0.002\nperiod = 0.001").unwrap_err();
    /// assert_eq!(err.line(), Some(2));
    /// ```
    pub fn line(&self) -> Option<usize> {
        match self {
            FileError::Io { .. } => None,
            FileError::Syntax { line, .. }
            | FileError::UnknownKey { line, .. }
            | FileError::MissingKey { line, .. }
            | FileError::WrongType { line, .. }
            | FileError::Invalid { line, .. } => *line,
        }
    }

    /// The dotted key at fault, when the fault is in a field.
    ///
    /// # Examples
    ///
    /// ```
    /// use ctrlab::{hw::RegisterMap, lab::{Calibration, RigConfig}};
    /// let card = RigConfig::new(RegisterMap::default(), Calibration::default());
    /// let text = card.to_toml().replace("travel_limits = [0.05, 0.05]", "travel_limits = [0.05, 0.0]");
    /// assert_eq!(RigConfig::from_toml(&text).unwrap_err().key(), Some("calibration.travel_limits[1]"));
    /// ```
    pub fn key(&self) -> Option<&str> {
        match self {
            FileError::Io { .. } | FileError::Syntax { .. } => None,
            FileError::UnknownKey { key, .. } | FileError::MissingKey { key, .. } => Some(key),
            FileError::WrongType { key, .. } => key.as_deref(),
            FileError::Invalid { error, .. } => Some(error.key()),
        }
    }

    /// The same error, said to be in the file at `file`.
    fn in_file(mut self, file: &Path) -> Self {
        match &mut self {
            FileError::Io { .. } => {}
            FileError::Syntax { path, .. }
            | FileError::UnknownKey { path, .. }
            | FileError::MissingKey { path, .. }
            | FileError::WrongType { path, .. }
            | FileError::Invalid { path, .. } => *path = Some(file.to_owned()),
        }
        self
    }

    /// A value of `text` the checks refuse, at the line of its key.
    pub(super) fn invalid(text: &str, error: ConfigError) -> Self {
        FileError::Invalid {
            path: None,
            line: line_of(text, error.key()),
            error,
        }
    }
}

/// `T` from TOML `text`, every field required: a fault names its line and,
/// when it is in a field, the field's dotted key (`calibration.card_id`,
/// `map.encoder[2]`; for a missing field, the key that is missing).
pub(super) fn parse<T: DeserializeOwned>(text: &str) -> Result<T, FileError> {
    let deserializer = toml::Deserializer::parse(text).map_err(|e| syntax(text, &e))?;
    serde_path_to_error::deserialize(deserializer).map_err(|e| field_error(text, &e, span_line))
}

/// `T` from TOML `text` laid over `defaults`: every key the text leaves out
/// keeps its default value (a table the text gives in part keeps the
/// default of the keys it lacks), a key the text adds is refused, as is a
/// value of the wrong type, by its dotted key and line.
pub(super) fn parse_over<T: Serialize + DeserializeOwned>(
    text: &str,
    defaults: &T,
) -> Result<T, FileError> {
    let given: toml::Table = toml::from_str(text).map_err(|e| syntax(text, &e))?;
    // Plain numbers, arrays and tables: the defaults always serialise.
    let mut merged = toml::Table::try_from(defaults).unwrap_or_default();
    lay_over(&mut merged, given);
    serde_path_to_error::deserialize(merged).map_err(|e| field_error(text, &e, |_, _| None))
}

/// `given` over `base`, table by table.
fn lay_over(base: &mut toml::Table, given: toml::Table) {
    for (key, value) in given {
        match (base.get_mut(&key), value) {
            (Some(toml::Value::Table(base)), toml::Value::Table(given)) => lay_over(base, given),
            (_, value) => {
                base.insert(key, value);
            }
        }
    }
}

/// The line of a parse error's span.
fn span_line(text: &str, e: &toml::de::Error) -> Option<usize> {
    // One more than the newlines before the fault (a span at the start of
    // a line included).
    e.span().map(|span| {
        text.bytes()
            .take(span.start)
            .filter(|&b| b == b'\n')
            .count()
            + 1
    })
}

fn syntax(text: &str, e: &toml::de::Error) -> FileError {
    let line = span_line(text, e);
    let mut message = e.message().trim_end().to_owned();
    // A syntax error names no key: quote the line it is on instead.
    if let Some(line) = line
        && let Some(content) = text.lines().nth(line - 1)
    {
        message = format!("{message} (the line reads `{}`)", content.trim());
    }
    FileError::Syntax {
        path: None,
        line,
        message,
    }
}

/// A field's deserialisation error: its kind from serde's message, its key
/// from the path, its line from the parser's span or, failing that, from
/// where the key is written in `text`.
fn field_error(
    text: &str,
    e: &serde_path_to_error::Error<toml::de::Error>,
    span: impl Fn(&str, &toml::de::Error) -> Option<usize>,
) -> FileError {
    let path = e.path().to_string();
    let table = (path != ".").then_some(path);
    let message = readable_literals(e.inner().message().trim_end());
    let line = |key: &str| span(text, e.inner()).or_else(|| line_of(text, key));
    let missing = message
        .strip_prefix("missing field `")
        .and_then(|rest| rest.split('`').next());
    if let Some(field) = missing {
        let key = match &table {
            Some(table) => format!("{table}.{field}"),
            None => field.to_owned(),
        };
        return FileError::MissingKey {
            path: None,
            line: span(text, e.inner()),
            key,
            message,
        };
    }
    match table {
        Some(key) if message.starts_with("unknown field") => FileError::UnknownKey {
            path: None,
            line: line(&key),
            key,
            message,
        },
        key => FileError::WrongType {
            path: None,
            line: key.as_deref().and_then(line),
            key,
            message,
        },
    }
}

/// serde's message with each quoted number (`` `0.000…02` ``, every digit
/// of a float) printed readably (`` `2e-308` ``).
fn readable_literals(message: &str) -> String {
    let mut out = String::with_capacity(message.len());
    for (i, part) in message.split('`').enumerate() {
        if i > 0 {
            out.push('`');
        }
        // Odd parts are inside backticks.
        match part.parse::<f64>() {
            Ok(x) if i % 2 == 1 && part.len() > 24 => out += &Readable(x).to_string(),
            _ => out += part,
        }
    }
    out
}

/// The one-based line where dotted `key` (`card.map.encoder[2]`, `period`)
/// is written as `name = …` under its `[table]` header (top-level keys
/// before any header), if written that way.
pub(super) fn line_of(text: &str, key: &str) -> Option<usize> {
    let key = key.split('[').next().unwrap_or(key);
    let (table, name) = key.rsplit_once('.').unwrap_or(("", key));
    let mut current = "";
    for (i, line) in text.lines().enumerate() {
        let line = line.trim();
        if let Some(header) = line.strip_prefix('[') {
            current = header.split(']').next().unwrap_or("").trim();
        } else if current == table && line.split('=').next().map(str::trim) == Some(name) {
            return Some(i + 1);
        }
    }
    None
}

/// The text of the file at `path`.
pub(super) fn read(path: &Path) -> Result<String, FileError> {
    std::fs::read_to_string(path).map_err(|source| FileError::Io {
        path: path.to_owned(),
        operation: "reading",
        source,
    })
}

/// `T` from the file at `path`, by `from_text`; every error names the path.
pub(super) fn read_with<T>(
    path: &Path,
    from_text: impl FnOnce(&str) -> Result<T, FileError>,
) -> Result<T, FileError> {
    from_text(&read(path)?).map_err(|e| e.in_file(path))
}

/// Writes `text` to `path` whole or not at all: into `path` + `.tmp`
/// first, then renamed over `path`, so a crash or a full disk never leaves
/// a half-written file where a complete one is expected.
pub(super) fn write(path: &Path, text: &str) -> Result<(), FileError> {
    let mut tmp = path.as_os_str().to_owned();
    tmp.push(".tmp");
    let tmp = Path::new(&tmp);
    std::fs::write(tmp, text)
        .and_then(|()| std::fs::rename(tmp, path))
        .map_err(|source| {
            std::fs::remove_file(tmp).ok();
            FileError::Io {
                path: path.to_owned(),
                operation: "writing",
                source,
            }
        })
}
