//! Where the tests that run an example program find its binary.

use std::path::PathBuf;

/// The example `name`'s binary: `$VAR`, else `examples/<name>` of this
/// test's profile (`target/release/deps/<test>-…` →
/// `target/release/examples/<name>`); `build` is the command that builds it,
/// for the message when it is missing.
pub fn example_binary(name: &str, var: &str, build: &str) -> PathBuf {
    if let Some(path) = std::env::var_os(var) {
        return path.into();
    }
    let exe = std::env::current_exe().expect("the test's own path");
    let profile = exe.ancestors().nth(2).expect("target/<profile>/deps/…");
    let bin = profile
        .join("examples")
        .join(format!("{name}{}", std::env::consts::EXE_SUFFIX));
    assert!(
        bin.is_file(),
        "{} is missing: {build} (or set {var})",
        bin.display()
    );
    bin
}
