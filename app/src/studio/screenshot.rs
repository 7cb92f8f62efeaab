//! `--screenshot PATH`: the smoke test's mode. The studio runs normally,
//! waits until the script ran and the preview finished baking (every level),
//! paints two more frames so the picture is on screen, asks eframe for a
//! screenshot (`ViewportCommand::Screenshot`), writes the PNG and closes.
//! With `--then-example NAME` it then opens that example as the Examples
//! menu does and waits for its bake before the picture (the smoke test's
//! check that a newly opened design is framed).
//! `--quit-after-frames N` closes after N frames whatever happened (exit
//! status 2 when no screenshot was written by then).

use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::Ordering;
use std::sync::mpsc::{Receiver, channel};

use super::StudioApp;

/// Frames to paint after the bake before taking the picture.
const SETTLE_FRAMES: u32 = 2;

enum State {
    /// Waiting for the design and its bake (a bake numbered above
    /// `after`: bakes of a design opened earlier do not count).
    Waiting { settled: u32, after: u64 },
    /// Asked eframe; the image comes through the channel.
    Requested(Receiver<Arc<egui::ColorImage>>),
    /// Written (or failed); closing.
    Done,
}

/// The screenshot mode's state.
pub struct Screenshot {
    path: Option<PathBuf>,
    state: State,
}

impl Screenshot {
    /// Take a screenshot into `path` (or nothing when `None`).
    pub fn new(path: Option<PathBuf>) -> Self {
        Self {
            path,
            state: State::Waiting {
                settled: 0,
                after: 0,
            },
        }
    }
}

/// Write `image` as a PNG.
pub fn save_png(image: &egui::ColorImage, path: &std::path::Path) -> Result<(), String> {
    let [w, h] = image.size;
    let bytes: Vec<u8> = image.pixels.iter().flat_map(|c| c.to_array()).collect();
    let img = image::RgbaImage::from_raw(w as u32, h as u32, bytes).ok_or("bad screenshot size")?;
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    }
    img.save(path)
        .map_err(|e| format!("{}: {e}", path.display()))
}

impl StudioApp {
    pub(super) fn screenshot_step(&mut self, ctx: &egui::Context) {
        if let Some(n) = self.opts.quit_after_frames
            && self.frames >= n
            && !matches!(self.shot.state, State::Done)
        {
            if self.shot.path.is_some() {
                eprintln!("volcad-studio: no screenshot after {n} frames; quitting");
                self.opts.exit_status.store(2, Ordering::Relaxed);
            }
            self.shot.state = State::Done;
            self.allow_close = true;
            ctx.send_viewport_cmd(egui::ViewportCommand::Close);
            return;
        }
        let Some(path) = self.shot.path.clone() else {
            return;
        };
        self.allow_close = true;
        match &mut self.shot.state {
            State::Waiting { settled, after } => {
                ctx.request_repaint();
                let ready = !self.live.is_busy()
                    && (self.error.is_some()
                        || (self.viewport.bakes_received() > *after && !self.viewport.is_baking()));
                if ready {
                    *settled += 1;
                }
                if *settled > SETTLE_FRAMES
                    && let Some(next) = self.opts.then_example.take()
                {
                    // `--then-example`: open it as the Examples menu does
                    // and wait for its own bake.
                    *after = self.viewport.bakes_received();
                    *settled = 0;
                    match super::examples::find(&next) {
                        Some(e) => self.request(ctx, super::commands::Pending::Example(e.file)),
                        None => {
                            eprintln!("volcad-studio: no example called {next}");
                            self.opts.exit_status.store(1, Ordering::Relaxed);
                            self.shot.state = State::Done;
                            ctx.send_viewport_cmd(egui::ViewportCommand::Close);
                        }
                    }
                } else if *settled > SETTLE_FRAMES {
                    let (tx, rx) = channel();
                    let c = ctx.clone();
                    ctx.request_screenshot(move |img| {
                        let _ = tx.send(img);
                        c.request_repaint();
                    });
                    self.shot.state = State::Requested(rx);
                }
            }
            State::Requested(rx) => {
                ctx.request_repaint();
                if let Ok(img) = rx.try_recv() {
                    match save_png(&img, &path) {
                        Ok(()) => {
                            let (mean, max) = self.stats.mean_max();
                            let (imean, imax) = self.stats.interval_mean_max();
                            println!(
                                "volcad-studio: screenshot {}x{} saved to {} ({} frames; last {} frames: App::ui mean {mean:.1} ms, max {max:.1} ms; frame interval mean {imean:.1} ms, max {imax:.1} ms)",
                                img.size[0],
                                img.size[1],
                                path.display(),
                                self.frames,
                                self.stats.ui_ms.len()
                            );
                        }
                        Err(e) => {
                            eprintln!("volcad-studio: could not save the screenshot: {e}");
                            self.opts.exit_status.store(1, Ordering::Relaxed);
                        }
                    }
                    if let Some(e) = &self.error {
                        eprintln!("volcad-studio: the script failed: {}", e.error);
                        self.opts.exit_status.store(3, Ordering::Relaxed);
                    }
                    self.shot.state = State::Done;
                    ctx.send_viewport_cmd(egui::ViewportCommand::Close);
                }
            }
            State::Done => {}
        }
    }
}
