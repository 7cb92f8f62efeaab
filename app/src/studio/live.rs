//! Live preview: the script runs on a worker thread a short while after the
//! last edit, and a newer edit cancels the older run.
//!
//! ```text
//! edit ──schedule()──► debounce deadline ──poll() on the UI thread──► spawn worker(gen, cancel)
//! worker: run_script → Model::prepare ──channel (gen-tagged)──► poll(): results of old gens dropped
//! ```
//!
//! The UI thread never waits: `poll` drains the channel with `try_recv`, and
//! workers call `ctx.request_repaint()` when they finish.

use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{Receiver, Sender, channel};
use std::time::{Duration, Instant};

use volcad_core::Model;
use volcad_core::script::{Design, Param, ScriptError, ScriptOptions};
use volcad_core::vcad::run_design;

/// One script run to do.
#[derive(Clone, Debug)]
pub struct RunRequest {
    /// The script text.
    pub source: String,
    /// Name shown in errors (file name or `<editor>`).
    pub name: String,
    /// Folder that relative file names resolve in.
    pub base_dir: Option<PathBuf>,
    /// Parameter overrides (sliders).
    pub params: HashMap<String, f64>,
    /// Folders the script may read besides its project (settings).
    pub allow_read: Vec<PathBuf>,
}

/// A successful run: the design's side data and its prepared model.
pub struct LiveDesign {
    /// The prepared model, shared with the baker, probe and exports.
    pub model: Arc<Model>,
    /// Parameters the script declared (with the values it ran with).
    pub params: Vec<Param>,
    /// Lines the script printed.
    pub log: Vec<String>,
    /// Warnings from the run.
    pub warnings: Vec<String>,
    /// Script run time.
    pub script_time: Duration,
    /// Prepare time.
    pub prepare_time: Duration,
    /// The text that produced it (exports hash it).
    pub source: String,
}

/// Why a run failed.
#[derive(Clone, Debug, PartialEq)]
pub struct LiveError {
    /// The script error (prepare errors carry no line).
    pub error: ScriptError,
    /// Which step failed: "script", "prepare" or "start".
    pub stage: &'static str,
}

/// What a worker sends back.
pub enum LiveResult {
    /// The script ran and the model is prepared.
    Ok(Box<LiveDesign>),
    /// The script or preparation failed.
    Err(LiveError),
}

struct Message {
    generation: u64,
    result: LiveResult,
}

/// Debounces edits and runs scripts on workers, newest wins.
pub struct LiveRunner {
    debounce: Duration,
    pending: Option<(Instant, RunRequest)>,
    generation: u64,
    cancel: Option<Arc<AtomicBool>>,
    running: bool,
    tx: Sender<Message>,
    rx: Receiver<Message>,
}

impl LiveRunner {
    /// A runner that waits `debounce` after the last edit.
    pub fn new(debounce: Duration) -> Self {
        let (tx, rx) = channel();
        Self {
            debounce,
            pending: None,
            generation: 0,
            cancel: None,
            running: false,
            tx,
            rx,
        }
    }

    /// Run `req` once no newer request arrives within the debounce time.
    pub fn schedule(&mut self, req: RunRequest) {
        self.pending = Some((Instant::now() + self.debounce, req));
    }

    /// Run `req` on the next `poll`, skipping the debounce (open, params).
    pub fn schedule_now(&mut self, req: RunRequest) {
        self.pending = Some((Instant::now(), req));
    }

    /// True while a run is waiting or working.
    pub fn is_busy(&self) -> bool {
        self.pending.is_some() || self.running
    }

    /// The generation of the newest run started.
    pub fn generation(&self) -> u64 {
        self.generation
    }

    /// Start a due run, and return the newest finished result (older ones
    /// are dropped). Call once per frame.
    pub fn poll(&mut self, ctx: &egui::Context) -> Option<LiveResult> {
        if let Some((due, _)) = &self.pending {
            let now = Instant::now();
            if *due <= now {
                if let Some((_, req)) = self.pending.take() {
                    self.start(ctx, req);
                }
            } else {
                ctx.request_repaint_after(*due - now);
            }
        }
        let mut newest = None;
        while let Ok(msg) = self.rx.try_recv() {
            if msg.generation == self.generation {
                self.running = false;
                newest = Some(msg.result);
            }
        }
        newest
    }

    fn start(&mut self, ctx: &egui::Context, req: RunRequest) {
        if let Some(old) = self.cancel.take() {
            old.store(true, Ordering::Relaxed);
        }
        self.generation += 1;
        self.running = true;
        let cancel = Arc::new(AtomicBool::new(false));
        self.cancel = Some(cancel.clone());
        let generation = self.generation;
        let tx = self.tx.clone();
        let ctx = ctx.clone();
        let spawned = std::thread::Builder::new()
            .name("volcad-script".into())
            .spawn(move || {
                let result = run(req, cancel);
                // The receiver lives as long as the app; a send error means it closed.
                let _ = tx.send(Message { generation, result });
                ctx.request_repaint();
            });
        if let Err(e) = spawned {
            self.running = false;
            let error = ScriptError {
                file: String::new(),
                line: None,
                column: None,
                message: format!("could not start a worker thread: {e}"),
            };
            let _ = self.tx.send(Message {
                generation,
                result: LiveResult::Err(LiveError {
                    error,
                    stage: "start",
                }),
            });
        }
    }
}

impl Drop for LiveRunner {
    fn drop(&mut self) {
        if let Some(c) = &self.cancel {
            c.store(true, Ordering::Relaxed);
        }
    }
}

/// The worker's job: run the script, then prepare the model.
pub fn run(req: RunRequest, cancel: Arc<AtomicBool>) -> LiveResult {
    let opts = ScriptOptions {
        base_dir: req.base_dir,
        allow_read: req.allow_read,
        params: req.params,
        cancel: Some(cancel),
        ..ScriptOptions::default()
    };
    let t0 = Instant::now();
    // A `.vcad` name runs the legacy OpenVCAD text reader, anything else Rhai.
    let design: Design = match run_design(&req.source, &req.name, &opts) {
        Ok(d) => d,
        Err(error) => {
            return LiveResult::Err(LiveError {
                error,
                stage: "script",
            });
        }
    };
    let script_time = t0.elapsed();
    let t1 = Instant::now();
    match Model::prepare(&design.root, design.materials.clone()) {
        Ok(model) => LiveResult::Ok(Box::new(LiveDesign {
            model: Arc::new(model),
            params: design.params,
            log: design.log,
            warnings: design.warnings,
            script_time,
            prepare_time: t1.elapsed(),
            source: req.source,
        })),
        Err(e) => {
            // The node description carries the script line ("Sphere (line 3)");
            // pull it out so the problems list can jump there.
            let line = line_in(&e.node);
            let error = ScriptError {
                file: req.name,
                line,
                column: None,
                message: e.to_string(),
            };
            LiveResult::Err(LiveError {
                error,
                stage: "prepare",
            })
        }
    }
}

/// The first "line N" in a node description.
fn line_in(s: &str) -> Option<usize> {
    let i = s.find("line ")?;
    let digits: String = s[i + 5..]
        .chars()
        .take_while(char::is_ascii_digit)
        .collect();
    digits.parse().ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    const BAR: &str = r#"let m = default_materials();
RectPrism(Vec3(0, 0, 0), Vec3(15, 10, 5), m.id("gray"))"#;

    fn req(source: &str) -> RunRequest {
        RunRequest {
            source: source.into(),
            name: "<editor>".into(),
            base_dir: None,
            params: HashMap::new(),
            allow_read: Vec::new(),
        }
    }

    fn wait(runner: &mut LiveRunner, ctx: &egui::Context) -> LiveResult {
        let t = Instant::now();
        loop {
            if let Some(r) = runner.poll(ctx) {
                return r;
            }
            assert!(t.elapsed() < Duration::from_secs(20), "no result");
            std::thread::sleep(Duration::from_millis(5));
        }
    }

    #[test]
    fn runs_and_prepares() {
        let ctx = egui::Context::default();
        let mut r = LiveRunner::new(Duration::ZERO);
        r.schedule(req(BAR));
        match wait(&mut r, &ctx) {
            LiveResult::Ok(d) => assert!((d.model.bbox().size().x - 15.0).abs() < 1e-9),
            LiveResult::Err(e) => panic!("{e:?}"),
        }
        assert!(!r.is_busy());
    }

    #[test]
    fn newer_edit_wins_and_stale_results_are_dropped() {
        let ctx = egui::Context::default();
        let mut r = LiveRunner::new(Duration::ZERO);
        // A slow run, then a fast one: only the fast one's result arrives.
        r.schedule(req("let s = 0; for i in 0..2000000 { s += i; } let m = default_materials(); Sphere(Vec3(0,0,0), 1, m.id(\"red\"))"));
        assert!(r.poll(&ctx).is_none());
        r.schedule(req(BAR));
        match wait(&mut r, &ctx) {
            LiveResult::Ok(d) => assert!(d.source.contains("RectPrism")),
            LiveResult::Err(e) => panic!("{e:?}"),
        }
        std::thread::sleep(Duration::from_millis(200));
        assert!(
            r.poll(&ctx).is_none(),
            "the cancelled run's result is dropped"
        );
    }

    #[test]
    fn a_scheduled_run_waits_for_the_debounce_deadline() {
        let ctx = egui::Context::default();
        let mut r = LiveRunner::new(Duration::from_secs(3600));
        r.schedule(req(BAR));
        assert!(r.poll(&ctx).is_none());
        assert_eq!(r.generation(), 0, "nothing started before the deadline");
        r.schedule_now(req(BAR));
        let _ = wait(&mut r, &ctx);
        assert_eq!(r.generation(), 1);
    }

    #[test]
    fn errors_carry_the_line() {
        let ctx = egui::Context::default();
        let mut r = LiveRunner::new(Duration::ZERO);
        r.schedule(req("let m = default_materials();\nlet x = ;\n"));
        match wait(&mut r, &ctx) {
            LiveResult::Err(e) => assert_eq!(e.error.line, Some(2), "{e:?}"),
            LiveResult::Ok(_) => panic!("expected an error"),
        }
        assert_eq!(line_in("Sphere (line 12, col 3)"), Some(12));
    }
}
