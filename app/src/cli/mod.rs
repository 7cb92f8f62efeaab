//! The headless `volcad` command line (ripgrep's shape: `main → run(parse())`
//! → one function per subcommand). Every failure is a message on stderr and
//! a non-zero exit, never a panic.

/// `println!` that returns the error instead of panicking: a closed pipe
/// (`volcad info x | head -1`) ends the command quietly ([`is_broken_pipe`]).
macro_rules! outln {
    ($($t:tt)*) => {{
        use std::io::Write as _;
        writeln!(std::io::stdout().lock(), $($t)*).map_err(crate::cli::stdout_error)?;
    }};
}

/// `eprintln!` that never panics (a closed standard error is not worth
/// failing a command for).
macro_rules! note {
    ($($t:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stderr().lock(), $($t)*);
    }};
}

mod bench;
mod design;
mod eval;
pub(crate) mod export;
mod fea_result;
mod gcvf;
mod info;
mod merge;
mod output;
mod render;
mod sample;
mod vat;

use std::path::PathBuf;

use clap::{Parser, Subcommand};

pub use design::load_design;

/// `volcad`: evaluate, render and export Volcad designs without a window.
#[derive(Parser, Debug)]
#[command(
    name = "volcad",
    version,
    about,
    long_about = None,
    after_help = EXIT_STATUS
)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// The exit statuses, as `--help` states them.
const EXIT_STATUS: &str = "Exit status: 0 on success (also when the reader of standard output \
closes it early), 1 when a command fails (bad design, bad option value, write error), \
2 for usage errors (unknown option, missing argument).";

/// Options shared by every command that loads a design.
#[derive(clap::Args, Debug, Clone)]
pub struct DesignArgs {
    /// The design: a Rhai script (.rhai) or a legacy OpenVCAD text design (.vcad).
    pub design: PathBuf,
    /// Override a `param(...)` of the script: `--param name=value` (repeatable).
    #[arg(long = "param", value_name = "NAME=VALUE")]
    pub params: Vec<String>,
    /// A folder the script may also read, besides its project (the
    /// nearest folder above it holding .git or volcad.toml, else its own
    /// folder): `--allow-read DIR` (repeatable).
    #[arg(long = "allow-read", value_name = "DIR")]
    pub allow_read: Vec<PathBuf>,
    /// A parameter-set file (`design.params.json`, as the studio saves
    /// it); with `--set NAME` its set NAME is applied (`--param` wins).
    #[arg(long = "params", value_name = "FILE", requires = "set")]
    pub params_file: Option<PathBuf>,
    /// The set of `--params FILE` to apply.
    #[arg(long = "set", value_name = "NAME", requires = "params_file")]
    pub set: Option<String>,
}

/// The subcommands.
#[derive(Subcommand, Debug)]
pub enum Command {
    /// Bounding box, node count, materials used, timings.
    Info(DesignArgs),
    /// Distance and fractions (by material name) at one point.
    Eval {
        /// The design.
        #[command(flatten)]
        design: DesignArgs,
        /// X (mm).
        #[arg(allow_negative_numbers = true)]
        x: f64,
        /// Y (mm).
        #[arg(allow_negative_numbers = true)]
        y: f64,
        /// Z (mm).
        #[arg(allow_negative_numbers = true)]
        z: f64,
    },
    /// Batch evaluation: CSV `x,y,z` in, `x,y,z,distance,<material>...` out.
    Sample {
        /// The design.
        #[command(flatten)]
        design: DesignArgs,
        /// Input CSV with header `x,y,z`.
        #[arg(long)]
        points: PathBuf,
        /// Output CSV (`-` for standard output).
        #[arg(long)]
        out: PathBuf,
        /// Attribute columns to add, comma-separated (`modulus,color`; a
        /// Vec3 gives `name.x name.y name.z`, a Vec4 `name.r` .. `name.a`).
        #[arg(long, value_delimiter = ',')]
        attributes: Vec<String>,
    },
    /// Render a view to a PNG (offscreen GPU, lavapipe where there is no GPU).
    Render(render::RenderArgs),
    /// Export for printers, slicers and solvers (boxed: its options
    /// outweigh every other command's).
    Export(Box<export::ExportArgs>),
    /// Join the folders of `volcad export png --shard K/N` into the single export.
    Merge(merge::MergeArgs),
    /// Convert a CalculiX .frd result to CSV (`node_id,x,y,z,dx,dy,dz`).
    FeaResult {
        /// The .frd file.
        frd: PathBuf,
        /// The .inp the job ran (for node coordinates).
        #[arg(long)]
        inp: PathBuf,
        /// Output CSV (`-` for standard output).
        #[arg(long)]
        out: PathBuf,
    },
    /// Measure evaluation and export throughput on designs (points/s, voxels/s).
    Bench(bench::BenchArgs),
}

/// Run a parsed command line.
pub fn run(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Command::Info(d) => info::info(&d),
        Command::Eval { design, x, y, z } => eval::eval(&design, x, y, z),
        Command::Sample {
            design,
            points,
            out,
            attributes,
        } => sample::sample(&design, &points, &out, &attributes),
        Command::Render(a) => render::render(&a),
        Command::Export(a) => export::export(&a),
        Command::Merge(a) => merge::merge(&a),
        Command::FeaResult { frd, inp, out } => fea_result::fea_result(&frd, &inp, &out),
        Command::Bench(a) => bench::bench(&a),
    }
}

/// The error of a failed write to standard output.
pub(crate) fn stdout_error(e: std::io::Error) -> anyhow::Error {
    anyhow::Error::new(e).context("cannot write to standard output")
}

/// True when `e` comes from writing to a pipe whose reader has gone
/// (`volcad info x | head -1`): the command then ends quietly with status
/// 0: the reader wanted no more, which is not a failure.
pub fn is_broken_pipe(e: &anyhow::Error) -> bool {
    e.chain().any(|c| {
        c.downcast_ref::<std::io::Error>()
            .is_some_and(|io| io.kind() == std::io::ErrorKind::BrokenPipe)
    })
}

pub use output::clip;
