//! Progressive baking on a background thread.
//!
//! One thread per model: it bakes each level (coarse first) and sends each
//! finished [`VolumeBake`] through a bounded channel, then calls `wake` (the
//! UI's `ctx.request_repaint`). Dropping the baker, or `restart`, sets the
//! cancel flag; the sampler stops at its next row of tiles and the thread's
//! results are never seen (the channel belongs to the old baker).

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{Receiver, TryRecvError, sync_channel};
use std::sync::{Arc, Mutex};

use volcad_core::Model;

use crate::attribute_bake::AttributeShading;
use crate::bake::{BakeError, VolumeBake, bake_shaded};

/// Bakes a model at increasing resolutions in the background.
pub struct ProgressiveBaker {
    cancel: Arc<AtomicBool>,
    done: Arc<AtomicBool>,
    error: Arc<Mutex<Option<BakeError>>>,
    rx: Receiver<Arc<VolumeBake>>,
    levels: Vec<u32>,
    wake: Arc<dyn Fn() + Send + Sync>,
    shading: Option<AttributeShading>,
}

/// The default levels: a coarse image fast, then detail.
pub const DEFAULT_LEVELS: [u32; 3] = [64, 128, 256];

impl ProgressiveBaker {
    /// Start baking `model` at each of `levels` (voxels along the longest
    /// side; use [`DEFAULT_LEVELS`] unless the user picked a quality), calling
    /// `wake` after each level and when finished or failed.
    pub fn start(
        model: Arc<Model>,
        levels: Vec<u32>,
        wake: impl Fn() + Send + Sync + 'static,
    ) -> Self {
        Self::spawn(model, levels, Arc::new(wake), None)
    }

    fn spawn(
        model: Arc<Model>,
        levels: Vec<u32>,
        wake: Arc<dyn Fn() + Send + Sync>,
        shading: Option<AttributeShading>,
    ) -> Self {
        let cancel = Arc::new(AtomicBool::new(false));
        let done = Arc::new(AtomicBool::new(false));
        let error = Arc::new(Mutex::new(None));
        let (tx, rx) = sync_channel(levels.len().max(1));
        let (c, d, e, w, lv, sh) = (
            cancel.clone(),
            done.clone(),
            error.clone(),
            wake.clone(),
            levels.clone(),
            shading.clone(),
        );
        let spawned = std::thread::Builder::new()
            .name("volcad-bake".into())
            .spawn(move || {
                let eval = |pts: volcad_core::Points<'_>, out: &mut [f64]| {
                    let index = sh.as_ref().map_or(0, |s| s.index);
                    model
                        .attribute_batch(index, pts, out)
                        .map_err(|e| e.to_string())
                };
                for level in lv {
                    match bake_shaded(&model, level, sh.as_ref().map(|s| (s, &eval as _)), &c) {
                        Ok(b) => {
                            if c.load(Ordering::Relaxed) || tx.send(Arc::new(b)).is_err() {
                                break;
                            }
                            w();
                        }
                        Err(BakeError::Cancelled) => break,
                        Err(err) => {
                            *e.lock().unwrap_or_else(|p| p.into_inner()) = Some(err);
                            break;
                        }
                    }
                }
                d.store(true, Ordering::Release);
                w();
            });
        if let Err(err) = spawned {
            // No thread: report it as done, with nothing baked.
            *error.lock().unwrap_or_else(|p| p.into_inner()) =
                Some(BakeError::Grid(volcad_core::sampler::GridError::Unbounded(
                    format!("could not start the bake thread: {err}"),
                )));
            done.store(true, Ordering::Release);
        }
        ProgressiveBaker {
            cancel,
            done,
            error,
            rx,
            levels,
            wake,
            shading,
        }
    }

    /// Cancel the bake in flight and start baking `model` (same levels,
    /// wake function and shading).
    pub fn restart(&mut self, model: Arc<Model>) {
        let shading = self.shading.clone();
        self.restart_shaded(model, shading);
    }

    /// Cancel the bake in flight and bake `model` with its colour volume
    /// from an attribute (`Some`) or the materials (`None`).
    pub fn restart_shaded(&mut self, model: Arc<Model>, shading: Option<AttributeShading>) {
        let next = Self::spawn(model, self.levels.clone(), self.wake.clone(), shading);
        *self = next; // drops the old baker, which cancels it
    }

    /// The shading of the bakes.
    pub fn shading(&self) -> Option<&AttributeShading> {
        self.shading.as_ref()
    }

    /// The next finished level, if one arrived (call every frame; upload it).
    /// Returns the finest waiting level and skips coarser ones.
    pub fn try_recv(&self) -> Option<Arc<VolumeBake>> {
        let mut last = None;
        loop {
            match self.rx.try_recv() {
                Ok(b) => last = Some(b),
                Err(TryRecvError::Empty | TryRecvError::Disconnected) => return last,
            }
        }
    }

    /// True when every level was baked (and received or waiting), or the
    /// bake failed or was cancelled.
    pub fn is_done(&self) -> bool {
        self.done.load(Ordering::Acquire)
    }

    /// Why the bake stopped early (unbounded design, ...), if it did.
    pub fn error(&self) -> Option<BakeError> {
        self.error.lock().unwrap_or_else(|p| p.into_inner()).clone()
    }

    /// The levels this baker bakes.
    pub fn levels(&self) -> &[u32] {
        &self.levels
    }
}

impl Drop for ProgressiveBaker {
    fn drop(&mut self) {
        self.cancel.store(true, Ordering::Relaxed);
    }
}
