//! The `volcad` command line: `main → run(parse())`; errors print `{:#}`
//! on stderr and exit 1 (2 for usage errors, from clap); a closed standard
//! output (`volcad info x | head -1`) ends it quietly with 0.

use std::io::Write;

use clap::Parser;

/// Live heap bytes are counted so that a runaway script stops with an error
/// instead of exhausting memory (`volcad_core::heap`).
#[global_allocator]
static HEAP: volcad_core::heap::CountingAllocator = volcad_core::heap::CountingAllocator;

/// The longest error message printed whole: messages quote user input (a
/// CSV cell, a script token) that can be megabytes long.
const MAX_MESSAGE: usize = 4000;

fn main() {
    if let Err(e) = volcad_studio::cpu::check() {
        let _ = writeln!(std::io::stderr(), "error: {e}");
        std::process::exit(1);
    }
    let cli = volcad_studio::cli::Cli::parse();
    if let Err(e) = volcad_studio::cli::run(cli) {
        if volcad_studio::cli::is_broken_pipe(&e) {
            std::process::exit(0);
        }
        let message = volcad_studio::cli::clip(&format!("{e:#}"), MAX_MESSAGE);
        let _ = writeln!(std::io::stderr(), "error: {message}");
        std::process::exit(1);
    }
}
