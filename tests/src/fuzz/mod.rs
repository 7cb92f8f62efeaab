//! The fuzzing harness (issue 39 item 10): generated cases run through the
//! real `volcad` binary with a time and memory cap, each classified by what
//! it did: a clean refusal or success, or one of the faults below.
//!
//! Pipeline: [`generate::case`] (seeded; `arbitrary` draws every choice from the
//! seed's bytes) → [`run_case`] in a scratch folder → [`Verdict`]. Faulty
//! cases are kept in `tests/fuzz-corpus/` ([`corpus`]) and replayed by
//! `cargo test`.

pub mod corpus;
pub mod generate;
pub mod session;

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use serde::{Deserialize, Serialize};

/// What a case must do.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Expect {
    /// The input is known to be bad: a clean error (exit 1 or 2).
    Fail,
    /// The input is known to be good: exit 0.
    Succeed,
    /// Either, as long as it is clean.
    Any,
}

/// One generated run: files written into a scratch folder, then
/// `volcad ARGS` run there (paths in `args` are relative to it).
#[derive(Clone, Debug, PartialEq)]
pub struct Case {
    /// Generator and number (`script-17`), for the report.
    pub name: String,
    /// The command line after `volcad`.
    pub args: Vec<String>,
    /// Input files: name and bytes.
    pub files: Vec<(String, Vec<u8>)>,
    /// What a clean run does.
    pub expect: Expect,
    /// Set where the case tries a fault that is known and owned by another
    /// part of the work (which issue and item): its faults are counted
    /// apart, not against the harness's verdict.
    pub open: Option<String>,
}

/// How a run went.
#[derive(Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub enum Verdict {
    /// Clean: the expected exit and nothing left over.
    Clean,
    /// stderr says "panicked".
    Panic,
    /// Ended by a signal (abort, stack overflow, segfault, the memory cap).
    Signal,
    /// Still running at the time cap.
    Timeout,
    /// Exit 0 on a known-bad input.
    WrongSuccess,
    /// A non-zero exit on a known-good input.
    WrongFailure,
    /// A failed run left files, or a run left a `.partial` file.
    PartialOutput,
    /// An exit status other than 0, 1 or 2.
    OddExit,
}

/// The caps each case runs under.
#[derive(Clone, Copy, Debug)]
pub struct Limits {
    /// Wall time.
    pub time: Duration,
    /// Address space (bytes).
    pub memory: u64,
}

/// The verdict and what it is based on.
#[derive(Clone, Debug)]
pub struct Report {
    /// Classification.
    pub verdict: Verdict,
    /// Exit code, if it exited.
    pub code: Option<i32>,
    /// The last lines of stderr.
    pub stderr_tail: String,
    /// Files left behind that should not be.
    pub leftovers: Vec<String>,
    /// Wall time.
    pub seconds: f64,
}

/// The `volcad` binary: `$VOLCAD_BIN`, else beside this executable in the
/// target folder ([`crate::bins::find`]).
pub fn find_binary() -> Option<PathBuf> {
    crate::bins::find("volcad")
}

/// Run `case` with `bin` under `limits` in a fresh folder below `scratch`.
pub fn run_case(
    bin: &Path,
    case: &Case,
    limits: Limits,
    scratch: &Path,
) -> std::io::Result<Report> {
    let dir = tempfile::Builder::new()
        .prefix("case-")
        .tempdir_in(scratch)?;
    let work = dir.path().join("work");
    std::fs::create_dir(&work)?;
    for (name, bytes) in &case.files {
        std::fs::write(work.join(name), bytes)?;
    }
    let err_path = dir.path().join("stderr");
    let mut cmd = Command::new(bin);
    cmd.args(&case.args)
        .current_dir(&work)
        .env("XDG_RUNTIME_DIR", dir.path())
        .env("RAYON_NUM_THREADS", "2")
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(std::fs::File::create(&err_path)?);
    cap_memory(&mut cmd, limits.memory);
    let start = Instant::now();
    let mut child = cmd.spawn()?;
    let status = loop {
        if let Some(s) = child.try_wait()? {
            break Some(s);
        }
        if start.elapsed() > limits.time {
            let _ = child.kill();
            let _ = child.wait();
            break None;
        }
        std::thread::sleep(Duration::from_millis(10));
    };
    let seconds = start.elapsed().as_secs_f64();
    let stderr = String::from_utf8_lossy(&std::fs::read(&err_path)?).to_string();
    let inputs: Vec<&str> = case.files.iter().map(|(n, _)| n.as_str()).collect();
    let mut left: Vec<String> = std::fs::read_dir(&work)?
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().to_string())
        .filter(|n| !inputs.contains(&n.as_str()))
        .collect();
    left.sort();
    let code = status.and_then(|s| s.code());
    let verdict = classify(case.expect, status, &stderr, &left);
    if verdict != Verdict::PartialOutput {
        left.clear();
    }
    let tail: Vec<&str> = stderr.lines().rev().take(4).collect();
    let stderr_tail: String = tail.into_iter().rev().collect::<Vec<_>>().join("\n");
    Ok(Report {
        verdict,
        code,
        stderr_tail: stderr_tail.chars().take(600).collect(),
        leftovers: left,
        seconds,
    })
}

/// The verdict of one run (`status` None: killed at the time cap).
pub fn classify(
    expect: Expect,
    status: Option<std::process::ExitStatus>,
    stderr: &str,
    left: &[String],
) -> Verdict {
    let Some(status) = status else {
        return Verdict::Timeout;
    };
    if stderr.contains("panicked") {
        return Verdict::Panic;
    }
    let Some(code) = status.code() else {
        return Verdict::Signal;
    };
    if !matches!(code, 0..=2) {
        return Verdict::OddExit;
    }
    let ok = code == 0;
    if (!ok && !left.is_empty()) || left.iter().any(|n| n.contains(".partial")) {
        return Verdict::PartialOutput;
    }
    match (expect, ok) {
        (Expect::Fail, true) => Verdict::WrongSuccess,
        (Expect::Succeed, false) => Verdict::WrongFailure,
        _ => Verdict::Clean,
    }
}

/// The address-space cap, set in the child before `exec` (`ulimit -v`).
#[cfg(unix)]
fn cap_memory(cmd: &mut Command, bytes: u64) {
    use rustix::process::{Resource, Rlimit, setrlimit};
    use std::os::unix::process::CommandExt;
    let limit = Rlimit {
        current: Some(bytes),
        maximum: Some(bytes),
    };
    // SAFETY: the closure runs between fork and exec, where only
    // async-signal-safe calls are allowed: setrlimit is one system call,
    // and nothing is allocated (the limit is built before the fork).
    unsafe {
        cmd.pre_exec(move || setrlimit(Resource::As, limit).map_err(std::io::Error::from));
    }
}

#[cfg(not(unix))]
fn cap_memory(_cmd: &mut Command, _bytes: u64) {}

#[cfg(test)]
mod tests {
    use super::*;

    #[cfg(unix)]
    #[test]
    fn classification_follows_exit_stderr_and_leftovers() {
        use std::os::unix::process::ExitStatusExt;
        let exit = |c: i32| Some(std::process::ExitStatus::from_raw(c << 8));
        let none: [String; 0] = [];
        assert_eq!(
            classify(Expect::Any, exit(1), "error: x", &none),
            Verdict::Clean
        );
        assert_eq!(
            classify(Expect::Fail, exit(0), "", &none),
            Verdict::WrongSuccess
        );
        assert_eq!(
            classify(Expect::Succeed, exit(1), "", &none),
            Verdict::WrongFailure
        );
        assert_eq!(
            classify(Expect::Any, exit(101), "thread 'main' panicked", &none),
            Verdict::Panic
        );
        assert_eq!(classify(Expect::Any, exit(3), "", &none), Verdict::OddExit);
        let sig = Some(std::process::ExitStatus::from_raw(6));
        assert_eq!(classify(Expect::Any, sig, "", &none), Verdict::Signal);
        assert_eq!(classify(Expect::Any, None, "", &none), Verdict::Timeout);
        let left = ["out".to_string()];
        assert_eq!(
            classify(Expect::Any, exit(1), "", &left),
            Verdict::PartialOutput
        );
        assert_eq!(classify(Expect::Any, exit(0), "", &left), Verdict::Clean);
        let partial = [".out.partial-7".to_string()];
        assert_eq!(
            classify(Expect::Any, exit(0), "", &partial),
            Verdict::PartialOutput
        );
    }
}
