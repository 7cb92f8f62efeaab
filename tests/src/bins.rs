//! Where the project's binaries are, for tests that run them as a user does.
//!
//! Cargo sets `CARGO_BIN_EXE_<name>` only for the integration tests of the
//! package that owns the binary (volcad-studio), so the tests here find the
//! binaries in the target folder instead: `cargo test --workspace` builds
//! them first, because volcad-studio keeps one integration test of its own
//! (`app/tests/bins.rs`), and cargo builds a package's binaries for its
//! integration tests.

use std::path::PathBuf;

/// The environment variable that names binary `name` explicitly
/// (`VOLCAD_BIN` for `volcad`, `VOLCAD_STUDIO_BIN` for `volcad-studio`).
pub fn env_var(name: &str) -> String {
    format!("{}_BIN", name.to_ascii_uppercase().replace('-', "_"))
}

/// Binary `name`: the path in [`env_var`] when set, else the file of that
/// name beside the running executable in the target folder (tests run from
/// `target/<profile>/deps/`, binaries live in `target/<profile>/`).
/// `None` when neither exists.
pub fn find(name: &str) -> Option<PathBuf> {
    if let Some(p) = std::env::var_os(env_var(name)) {
        return Some(PathBuf::from(p));
    }
    let exe = std::env::current_exe().ok()?;
    let file = format!("{name}{}", std::env::consts::EXE_SUFFIX);
    exe.ancestors()
        .skip(1)
        .take(3)
        .map(|d| d.join(&file))
        .find(|p| p.is_file())
}

/// Binary `name` for a test: as [`find`], and when it is not built, a
/// panic (the test's failure) that says how to build it.
pub fn bin(name: &str) -> PathBuf {
    find(name).unwrap_or_else(|| {
        panic!(
            "the `{name}` binary is not built: run `cargo build --bins` \
             (`cargo test --workspace` and scripts/test build it), \
             or set {} to its path",
            env_var(name)
        )
    })
}
