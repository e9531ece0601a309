//! The path checks of lab5's and the single experiment's command lines
//! (`examples/experiment` includes this file).

use std::path::PathBuf;

/// `--out`: a directory, or a path that does not exist yet.
pub fn out_dir(s: &str) -> Result<PathBuf, String> {
    let path = PathBuf::from(s);
    if path.exists() && !path.is_dir() {
        return Err(format!("`{s}` exists and is not a directory"));
    }
    Ok(path)
}

/// A file that exists.
pub fn existing_file(s: &str) -> Result<PathBuf, String> {
    let path = PathBuf::from(s);
    if !path.is_file() {
        return Err(format!("`{s}` is not a readable file"));
    }
    Ok(path)
}
