//! Volcad Studio: the desktop IDE.
//!
//! `volcad-studio [--script FILE | --example NAME] [--then-example NAME] [--screenshot PATH] [--quit-after-frames N]`
//!
//! `--screenshot` is for the smoke test: the studio opens, runs the script,
//! waits for the preview to finish baking, saves a screenshot and quits
//! (exit status 0 when the PNG was written).

use std::path::PathBuf;
use std::sync::atomic::Ordering;

use clap::Parser;
use volcad_studio::studio::{StudioApp, StudioOptions};

/// Live heap bytes are counted so that a runaway script stops with an error
/// instead of exhausting memory (`volcad_core::heap`).
#[global_allocator]
static HEAP: volcad_core::heap::CountingAllocator = volcad_core::heap::CountingAllocator;

/// Volcad Studio: write a design script, see it live, export it.
#[derive(Parser, Debug)]
#[command(name = "volcad-studio", version)]
struct Args {
    /// Open this design script.
    #[arg(long, value_name = "FILE")]
    script: Option<PathBuf>,
    /// Open a bundled example by name (e.g. graded_bar, bunny_lattice).
    #[arg(long, value_name = "NAME", conflicts_with = "script")]
    example: Option<String>,
    /// With `--screenshot`: once the first design is baked, open this bundled
    /// example the way the Examples menu does, and take the screenshot of it
    /// (the smoke test checks that the second design is framed).
    #[arg(long, value_name = "NAME", requires = "screenshot")]
    then_example: Option<String>,
    /// Save a screenshot of the window here once the preview is baked, then quit.
    #[arg(long, value_name = "PATH")]
    screenshot: Option<PathBuf>,
    /// Quit after this many frames (a safety net for automated runs).
    #[arg(long, value_name = "N")]
    quit_after_frames: Option<u64>,
    /// Do not read or write saved settings (window layout, recent files).
    #[arg(long)]
    no_persistence: bool,
}

fn main() -> anyhow::Result<()> {
    volcad_studio::cpu::check().map_err(anyhow::Error::msg)?;
    let args = Args::parse();
    let automated = args.screenshot.is_some() || args.quit_after_frames.is_some();
    let opts = StudioOptions {
        script: args.script,
        example: args.example,
        then_example: args.then_example,
        screenshot: args.screenshot,
        quit_after_frames: args.quit_after_frames,
        // Automated runs leave the user's settings alone.
        persistence: !(args.no_persistence || automated),
        ..StudioOptions::default()
    };
    let status = opts.exit_status.clone();
    let native = eframe::NativeOptions {
        viewport: egui::ViewportBuilder::default()
            .with_title("Volcad Studio")
            .with_app_id("volcad-studio")
            .with_inner_size([1280.0, 800.0])
            .with_min_inner_size([640.0, 400.0]),
        renderer: eframe::Renderer::Wgpu,
        persist_window: opts.persistence,
        ..Default::default()
    };
    eframe::run_native(
        "Volcad Studio",
        native,
        Box::new(move |cc| Ok(Box::new(StudioApp::new(cc, opts)))),
    )
    .map_err(|e| anyhow::anyhow!("could not start the studio: {e}"))?;
    let code = status.load(Ordering::Relaxed);
    if code != 0 {
        std::process::exit(code);
    }
    Ok(())
}
