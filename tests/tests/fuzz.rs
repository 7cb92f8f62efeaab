//! The fuzzing harness (volcad-tests' `fuzz` module) against the
//! `volcad` binary: every corpus case replayed, and a bounded generated run
//! (a fixed seed and case count, so every run tries the same cases).

use std::path::PathBuf;
use std::time::Duration;

use volcad_tests::fuzz::{Limits, Verdict, corpus, run_case, session};

fn bin() -> PathBuf {
    volcad_tests::bin("volcad")
}

/// Generous caps: the debug binary on a busy machine is slow (the slowest
/// clean case of the bounded run took a few seconds).
const LIMITS: Limits = Limits {
    time: Duration::from_secs(60),
    memory: 4 << 30,
};

#[test]
fn every_corpus_case_is_clean() {
    let scratch = tempfile::Builder::new()
        .prefix("volcad-corpus-")
        .tempdir()
        .unwrap();
    let entries = corpus::load(&corpus::folder()).unwrap();
    assert!(!entries.is_empty(), "the corpus is empty");
    let mut failed = Vec::new();
    for (file, entry) in &entries {
        let case = entry.case().unwrap();
        // An open entry is only reported: a short cap keeps a known hang
        // from costing the suite a minute.
        let limits = if entry.open.is_some() {
            Limits {
                time: Duration::from_secs(10),
                ..LIMITS
            }
        } else {
            LIMITS
        };
        let r = run_case(&bin(), &case, limits, scratch.path()).unwrap();
        match (&entry.open, r.verdict == Verdict::Clean) {
            (_, true) => {}
            // A fault another part of issue 39 owns, not fixed on this
            // branch: reported, not failed.
            (Some(owner), false) => eprintln!("{file}: {:?}, open ({owner})", r.verdict),
            (None, false) => failed.push(format!(
                "{file}: {:?} (exit {:?})\n  {}",
                r.verdict, r.code, r.stderr_tail
            )),
        }
    }
    assert!(failed.is_empty(), "{}", failed.join("\n"));
}

#[test]
fn a_bounded_generated_run_is_clean() {
    let scratch = tempfile::Builder::new()
        .prefix("volcad-fuzz-")
        .tempdir()
        .unwrap();
    let stop = session::Stop {
        cases: Some(300),
        time: None,
        skip_open: true,
    };
    let t = session::run(&bin(), 7, stop, LIMITS, scratch.path(), |_, _, _| {}).unwrap();
    eprintln!("{}", t.summary());
    let faults: Vec<String> = t
        .faults
        .iter()
        .map(|(i, c, r)| {
            format!(
                "case {i} ({}) {:?}: {:?}\n  {}",
                c.name, c.args, r.verdict, r.stderr_tail
            )
        })
        .collect();
    assert!(faults.is_empty(), "{}\n{}", t.summary(), faults.join("\n"));
}
