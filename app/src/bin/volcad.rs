//! The `volcad` command line: `main → run(parse())`; errors print `{:#}`
//! on stderr and exit 1 (2 for usage errors, from clap).

use clap::Parser;

/// Live heap bytes are counted so that a runaway script stops with an error
/// instead of exhausting memory (`volcad_core::heap`).
#[global_allocator]
static HEAP: volcad_core::heap::CountingAllocator = volcad_core::heap::CountingAllocator;

fn main() {
    if let Err(e) = volcad_studio::cpu::check() {
        eprintln!("error: {e}");
        std::process::exit(1);
    }
    let cli = volcad_studio::cli::Cli::parse();
    if let Err(e) = volcad_studio::cli::run(cli) {
        eprintln!("error: {e:#}");
        std::process::exit(1);
    }
}
