//! `fuzz`: generated cases against the real `volcad` binary (issue 39 item 10).
//!
//! `cargo run -p volcad-tests --release --bin fuzz -- --minutes 30`
//! (or `--seconds S`, `--cases N`; `--seed S` picks the cases, `--save`
//! adds every faulty case to tests/fuzz-corpus/). The binary is `$VOLCAD_BIN`
//! or `volcad` beside this one in the target folder: build it first with
//! `cargo build -p volcad-studio --release --bin volcad`.
//! Exit status 1 when any case was faulty.

use std::path::PathBuf;
use std::time::Duration;

use clap::Parser;
use volcad_tests::fuzz::{Limits, Verdict, corpus, find_binary, session};

/// Fuzz the `volcad` command line.
#[derive(Parser, Debug)]
#[command(name = "fuzz")]
struct Args {
    /// Run for this many minutes.
    #[arg(long)]
    minutes: Option<f64>,
    /// Run for this many seconds.
    #[arg(long)]
    seconds: Option<f64>,
    /// Run at most this many cases.
    #[arg(long)]
    cases: Option<u64>,
    /// The seed that names the cases.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Seconds one case may run.
    #[arg(long, default_value_t = 30.0)]
    case_seconds: f64,
    /// Address space one case may use (MiB).
    #[arg(long, default_value_t = 4096)]
    memory_mb: u64,
    /// The volcad binary (default: $VOLCAD_BIN, else beside this one).
    #[arg(long)]
    bin: Option<PathBuf>,
    /// Save every faulty case into the corpus folder.
    #[arg(long)]
    save: bool,
    /// The corpus folder `--save` writes to (default: tests/fuzz-corpus).
    #[arg(long)]
    corpus: Option<PathBuf>,
    /// Show case N of the seed (its command line and files) and run only it.
    #[arg(long)]
    only: Option<u64>,
}

fn main() {
    let a = Args::parse();
    let Some(bin) = a.bin.clone().or_else(find_binary) else {
        eprintln!(
            "error: no volcad binary: build it (cargo build -p volcad-studio --release --bin volcad) or set VOLCAD_BIN"
        );
        std::process::exit(2);
    };
    let time = a
        .minutes
        .map(|m| m * 60.0)
        .or(a.seconds)
        .filter(|s| s.is_finite() && *s > 0.0)
        .map(Duration::from_secs_f64);
    let stop = session::Stop {
        skip_open: false,
        cases: a.cases,
        time: time.or(if a.cases.is_none() {
            Some(Duration::from_secs(60))
        } else {
            None
        }),
    };
    let limits = Limits {
        time: Duration::from_secs_f64(a.case_seconds.max(1.0)),
        memory: a.memory_mb.saturating_mul(1 << 20),
    };
    let scratch = match tempfile::Builder::new().prefix("volcad-fuzz-").tempdir() {
        Ok(d) => d,
        Err(e) => {
            eprintln!("error: cannot make a scratch folder: {e}");
            std::process::exit(2);
        }
    };
    if let Some(n) = a.only {
        let case = volcad_tests::fuzz::generate::case(a.seed, n);
        for (name, bytes) in &case.files {
            let text = String::from_utf8_lossy(bytes);
            eprintln!(
                "--- {name} ({} bytes)\n{}",
                bytes.len(),
                volcad_core::script::clip(&text, 600)
            );
        }
        eprintln!("--- volcad {}", shown_args(&case.args));
        match volcad_tests::fuzz::run_case(&bin, &case, limits, scratch.path()) {
            Ok(r) => {
                println!(
                    "{:?} exit {:?} in {:.1} s\n{}",
                    r.verdict, r.code, r.seconds, r.stderr_tail
                );
                if a.save && r.verdict != Verdict::Clean {
                    let dir = a.corpus.clone().unwrap_or_else(corpus::folder);
                    match corpus::save(&dir, &corpus::Entry::new(&case, r.verdict)) {
                        Ok(p) => eprintln!("saved {}", p.display()),
                        Err(e) => eprintln!("error: cannot save {}: {e}", case.name),
                    }
                }
            }
            Err(e) => eprintln!("error: {e}"),
        }
        return;
    }
    eprintln!("fuzzing {} (seed {}, {:?})", bin.display(), a.seed, stop);
    let result = session::run(&bin, a.seed, stop, limits, scratch.path(), |i, case, r| {
        if r.verdict != Verdict::Clean {
            eprintln!(
                "{:?}: case {i} ({}) volcad {} -> exit {:?} in {:.1} s{}\n  {}",
                r.verdict,
                case.name,
                shown_args(&case.args),
                r.code,
                r.seconds,
                if r.leftovers.is_empty() {
                    String::new()
                } else {
                    format!(", left {:?}", r.leftovers)
                },
                r.stderr_tail.replace('\n', "\n  ")
            );
        }
    });
    let tally = match result {
        Ok(t) => t,
        Err(e) => {
            eprintln!("error: {e}");
            std::process::exit(2);
        }
    };
    if a.save {
        for (_, case, r) in tally.faults.iter().chain(&tally.open) {
            match corpus::save(
                &corpus::folder(),
                &corpus::Entry::new(case, r.verdict.clone()),
            ) {
                Ok(p) => eprintln!("saved {}", p.display()),
                Err(e) => eprintln!("error: cannot save {}: {e}", case.name),
            }
        }
    }
    println!("{}", tally.summary());
    if !tally.faults.is_empty() {
        std::process::exit(1);
    }
}

/// The command line for the report, long arguments cut.
fn shown_args(args: &[String]) -> String {
    args.iter()
        .map(|a| {
            if a.chars().count() > 40 {
                format!("{}…", a.chars().take(40).collect::<String>())
            } else {
                a.clone()
            }
        })
        .collect::<Vec<_>>()
        .join(" ")
}
