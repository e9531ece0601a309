//! The path checks of lab5's and the single experiment's command lines
//! (`examples/experiment` includes this file).

use std::path::{Path, PathBuf};

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

/// Makes `out` and the sub-directories `dirs` a run writes into, and checks
/// that none of `files` is a directory: before anything runs, so a bad
/// `--out` stops the program at once, naming the path, instead of after
/// the runs with the report lost.
pub fn prepare_out(out: &Path, dirs: &[&str], files: &[&str]) -> Result<(), String> {
    let create = |dir: &Path| {
        std::fs::create_dir_all(dir)
            .map_err(|e| format!("cannot create the directory `{}`: {e}", dir.display()))
    };
    create(out)?;
    for dir in dirs.iter().map(|d| out.join(d)) {
        if dir.exists() && !dir.is_dir() {
            return Err(format!(
                "`{}` exists and is not a directory: the run writes files into it",
                dir.display()
            ));
        }
        create(&dir)?;
    }
    for file in files.iter().map(|f| out.join(f)) {
        if file.is_dir() {
            return Err(format!(
                "`{}` is a directory: the run writes a file there",
                file.display()
            ));
        }
    }
    Ok(())
}
