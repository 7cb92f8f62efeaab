//! Helpers shared by the `volcad` binary's end-to-end tests.
#![allow(dead_code)]
// A failed setup step (a scratch folder, a file read) fails the test.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::PathBuf;
use std::process::{Command, Output};

pub fn volcad(args: &[&str]) -> Output {
    Command::new(volcad_tests::bin("volcad"))
        .args(args)
        .env("XDG_RUNTIME_DIR", runtime_dir())
        .output()
        .expect("run volcad")
}

/// One runtime folder for every run of these tests (a fixed name, so runs
/// do not leave one each behind).
pub fn runtime_dir() -> PathBuf {
    let d = std::env::temp_dir().join("volcad-cli-tests-xdg");
    std::fs::create_dir_all(&d).unwrap();
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        let _ = std::fs::set_permissions(&d, std::fs::Permissions::from_mode(0o700));
    }
    d
}

pub fn example(name: &str) -> String {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../assets/examples")
        .join(name)
        .display()
        .to_string()
}

/// A scratch folder for one test, removed when the test ends (passed or
/// failed).
pub fn tmp(name: &str) -> tempfile::TempDir {
    tempfile::Builder::new()
        .prefix(&format!("volcad-cli-{name}-"))
        .tempdir()
        .unwrap()
}

pub fn ok(o: &Output) -> String {
    assert!(
        o.status.success(),
        "exit {:?}\nstdout: {}\nstderr: {}",
        o.status,
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    String::from_utf8_lossy(&o.stdout).to_string()
}

pub fn fails(o: &Output) -> String {
    assert!(!o.status.success(), "expected failure, got success");
    assert!(
        matches!(o.status.code(), Some(1) | Some(2)),
        "exit {:?}",
        o.status
    );
    let err = String::from_utf8_lossy(&o.stderr).to_string();
    assert!(!err.contains("panicked"), "{err}");
    err
}
