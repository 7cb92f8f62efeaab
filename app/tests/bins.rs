//! Both binaries start and name their version. The end-to-end tests live in
//! the volcad-tests crate (`tests/`); this one stays here because cargo
//! builds a package's binaries only for that package's own integration
//! tests, so with it `cargo test --workspace` builds `volcad` and
//! `volcad-studio` before the end-to-end tests run them.

use std::process::Command;

/// `NAME --version` succeeds and prints `NAME <crate version>`.
fn prints_its_version(name: &str, path: &str) {
    let o = Command::new(path)
        .arg("--version")
        .output()
        .unwrap_or_else(|e| panic!("running {path}: {e}"));
    assert!(o.status.success(), "{name} --version: {o:?}");
    let out = String::from_utf8_lossy(&o.stdout);
    assert_eq!(
        out.trim(),
        format!("{name} {}", env!("CARGO_PKG_VERSION")),
        "{name} --version"
    );
}

#[test]
fn volcad_prints_its_version() {
    prints_its_version("volcad", env!("CARGO_BIN_EXE_volcad"));
}

#[test]
fn volcad_studio_prints_its_version_without_opening_a_window() {
    prints_its_version("volcad-studio", env!("CARGO_BIN_EXE_volcad-studio"));
}
