//! The headless `volcad` command line (ripgrep's shape: `main → run(parse())`
//! → one function per subcommand). Every failure is a message on stderr and
//! a non-zero exit, never a panic.

mod design;
mod export;
mod info;
mod render;
mod sample;

use std::path::PathBuf;

use clap::{Parser, Subcommand};

pub use design::load_design;

/// `volcad`: evaluate, render and export Volcad designs without a window.
#[derive(Parser, Debug)]
#[command(name = "volcad", version, about, long_about = None)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

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
        /// Output CSV.
        #[arg(long)]
        out: PathBuf,
    },
    /// Render a view to a PNG (offscreen GPU, lavapipe where there is no GPU).
    Render(render::RenderArgs),
    /// Export for printers, slicers and solvers.
    Export(export::ExportArgs),
    /// Convert a CalculiX .frd result to CSV (`node_id,x,y,z,dx,dy,dz`).
    FeaResult {
        /// The .frd file.
        frd: PathBuf,
        /// The .inp the job ran (for node coordinates).
        #[arg(long)]
        inp: PathBuf,
        /// Output CSV.
        #[arg(long)]
        out: PathBuf,
    },
    /// Measure evaluation and export throughput on designs (points/s, voxels/s).
    Bench(info::BenchArgs),
}

/// Run a parsed command line.
pub fn run(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Command::Info(d) => info::info(&d),
        Command::Eval { design, x, y, z } => info::eval(&design, x, y, z),
        Command::Sample {
            design,
            points,
            out,
        } => sample::sample(&design, &points, &out),
        Command::Render(a) => render::render(&a),
        Command::Export(a) => export::export(&a),
        Command::FeaResult { frd, inp, out } => export::fea_result(&frd, &inp, &out),
        Command::Bench(a) => info::bench(&a),
    }
}
