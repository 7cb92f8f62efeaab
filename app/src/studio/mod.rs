//! # The studio
//!
//! One window: the code editor (left), the viewport (centre), parameters,
//! legend, probe and export panels (right), problems and log (bottom).
//!
//! Threads and channels (the UI thread never waits; each is drained with
//! `try_recv` once per frame, and every worker wakes the UI when it sends):
//!
//! ```text
//! editor edit ─debounce─► LiveRunner worker: run_script → Model::prepare ─► Arc<Model>
//! Arc<Model> ─► ProgressiveBaker worker ─► VolumeBake 64³ → 128³ → 256³ ─► paint callback
//! hover/click ─► ProbeWorker ─► read-out
//! export panel ─► volcad_compilers::job thread ─► Progress … Summary
//! File dialogs ─► rfd on a thread ─► path;  autosave ─► writer thread ─► recovery.rhai
//! ```
//!
//! Files: `live` (script worker), `viewport` (+ `probe`, `legend`), `editor`
//! (+ `textops`, `highlight`), `params`, `export_panel` (+ `jobs`),
//! `problems`, `files`, `settings`, `examples`, `commands` (menus, shortcuts,
//! modals), `screenshot` (the `--screenshot` smoke test).
#![warn(missing_docs)]

pub mod attribute_view;
mod browser;
mod commands;
pub mod completion;
pub mod dialogs;
pub mod editor;
pub mod examples;
mod export_panel;
pub mod files;
pub mod highlight;
pub mod jobs;
mod legend;
pub mod live;
pub mod params;
pub mod probe;
pub mod problems;
pub mod reference;
mod screenshot;
pub mod settings;
pub mod textops;
pub mod viewport;

use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::AtomicI32;
use std::time::{Duration, Instant};

use egui_extras::syntax_highlighting::SyntectSettings;

use dialogs::Dialogs;
use editor::{Editor, LineMark};
use export_panel::ExportPanels;
use files::{Document, Recovery};
use jobs::Jobs;
use live::{LiveDesign, LiveError, LiveResult, LiveRunner, RunRequest};
use params::ParamPanel;
use problems::{BottomPanel, Problem, Severity};
use settings::Settings;
use viewport::Viewport;

pub use commands::Modal;
/// The egui the studio is built with (UI tests drive it with its types).
pub use egui;

/// How to start the studio (the binary fills it from its flags; tests
/// point the data folder at a temp dir and shorten the debounce).
#[derive(Clone, Debug)]
pub struct StudioOptions {
    /// Open this script (`--script`).
    pub script: Option<PathBuf>,
    /// Open this bundled example, by file name (`--example graded_bar`).
    pub example: Option<String>,
    /// Screenshot mode: open this example once the first design is baked,
    /// and screenshot that one instead.
    pub then_example: Option<String>,
    /// Start with this text, untitled (tests).
    pub initial_text: Option<String>,
    /// Save a screenshot here once the first design is baked, then quit.
    pub screenshot: Option<PathBuf>,
    /// Quit after this many frames (a safety net for the smoke test).
    pub quit_after_frames: Option<u64>,
    /// Read and write settings and egui memory in eframe's storage.
    pub persistence: bool,
    /// Folder for the recovery file (`None`: no autosave).
    pub data_dir: Option<PathBuf>,
    /// Where an untitled design's export folders go by default.
    pub documents_dir: Option<PathBuf>,
    /// Wait this long after the last edit before running the script.
    pub debounce: Duration,
    /// Autosave unsaved text this often.
    pub autosave_interval: Duration,
    /// Preview bake levels (voxels along the longest side).
    pub bake_levels: Vec<u32>,
    /// Exit status for the binary (screenshot mode sets it).
    pub exit_status: Arc<AtomicI32>,
}

impl Default for StudioOptions {
    fn default() -> Self {
        Self {
            script: None,
            example: None,
            then_example: None,
            initial_text: None,
            screenshot: None,
            quit_after_frames: None,
            persistence: true,
            data_dir: files::default_data_dir(),
            documents_dir: files::documents_dir(),
            debounce: Duration::from_millis(300),
            autosave_interval: Duration::from_secs(5),
            bake_levels: volcad_render_levels(),
            exit_status: Arc::new(AtomicI32::new(0)),
        }
    }
}

fn volcad_render_levels() -> Vec<u32> {
    vec![64, 128, 256]
}

impl StudioOptions {
    /// Options for UI tests: no persistence, recovery in `data_dir`, no
    /// debounce, small bakes.
    pub fn for_tests(data_dir: PathBuf, initial_text: &str) -> Self {
        Self {
            initial_text: Some(initial_text.to_owned()),
            persistence: false,
            documents_dir: Some(data_dir.join("documents")),
            data_dir: Some(data_dir),
            debounce: Duration::ZERO,
            autosave_interval: Duration::from_millis(200),
            bake_levels: vec![48],
            ..Self::default()
        }
    }
}

/// What the last successful run left on screen (besides the model, which
/// the viewport holds).
struct GoodDesign {
    params: Vec<volcad_core::script::Param>,
    warnings: Vec<String>,
    source: String,
    model: Arc<volcad_core::Model>,
}

/// Frame timing (the status line and the measurements).
#[derive(Clone, Debug, Default)]
pub struct FrameStats {
    /// CPU time of each of the last frames' `ui` (ms), oldest first.
    pub ui_ms: Vec<f32>,
    /// Time from one frame's start to the next (ms): `ui`, painting and
    /// waiting; a frame rate only while frames are requested back to back.
    pub interval_ms: Vec<f32>,
    last_start: Option<Instant>,
}

/// Frames the statistics cover.
const STATS_FRAMES: usize = 240;

impl FrameStats {
    fn push(&mut self, start: Instant, ms: f32) {
        for (v, x) in [
            (&mut self.ui_ms, Some(ms)),
            (
                &mut self.interval_ms,
                self.last_start.map(|l| (start - l).as_secs_f32() * 1e3),
            ),
        ] {
            if let Some(x) = x {
                v.push(x);
                if v.len() > STATS_FRAMES {
                    v.remove(0);
                }
            }
        }
        self.last_start = Some(start);
    }

    /// (mean, max) of `ui` over the recorded frames (ms).
    pub fn mean_max(&self) -> (f32, f32) {
        mean_max(&self.ui_ms)
    }

    /// (mean, max) of the frame intervals (ms).
    pub fn interval_mean_max(&self) -> (f32, f32) {
        mean_max(&self.interval_ms)
    }
}

fn mean_max(v: &[f32]) -> (f32, f32) {
    let n = v.len().max(1) as f32;
    (
        v.iter().sum::<f32>() / n,
        v.iter().copied().fold(0.0, f32::max),
    )
}

/// The studio application.
pub struct StudioApp {
    opts: StudioOptions,
    settings: Settings,
    syntect: Arc<SyntectSettings>,
    editor: Editor,
    doc: Document,
    live: LiveRunner,
    good: Option<GoodDesign>,
    error: Option<LiveError>,
    /// Help → Language reference.
    pub reference: reference::ReferenceWindow,
    params: ParamPanel,
    viewport: Viewport,
    bottom: BottomPanel,
    jobs: Jobs,
    exports: ExportPanels,
    dialogs: Dialogs,
    recovery: Recovery,
    modal: Option<Modal>,
    after_save: Option<commands::Pending>,
    allow_close: bool,
    frames: u64,
    stats: FrameStats,
    shot: screenshot::Screenshot,
    title: String,
}

impl StudioApp {
    /// Build the studio (registers the renderer with eframe's wgpu state).
    pub fn new(cc: &eframe::CreationContext<'_>, opts: StudioOptions) -> Self {
        let settings = if opts.persistence {
            Settings::load(cc.storage)
        } else {
            Settings::default()
        };
        let has_gpu = cc
            .wgpu_render_state
            .as_ref()
            .inspect(|rs| volcad_render::viewport::register(rs))
            .is_some();
        // On a software adapter (lavapipe, llvmpipe) a full-resolution
        // ray-marched frame costs most of a second; half resolution,
        // upscaled, keeps orbiting usable (about 4x fewer pixels).
        let software = cc.wgpu_render_state.as_ref().is_some_and(|rs| {
            rs.adapter.get_info().device_type == egui_wgpu::wgpu::DeviceType::Cpu
        });
        cc.egui_ctx.options_mut(|o| o.zoom_with_keyboard = false);
        commands::apply_theme(&cc.egui_ctx, settings.theme);
        let mut bottom = BottomPanel::default();
        let (doc, text) = initial_document(&opts, &settings, &mut bottom);
        let recovery = Recovery::new(opts.data_dir.clone(), opts.autosave_interval);
        let modal = match recovery.load() {
            Some(r) if opts.screenshot.is_none() && r.text != text => Some(Modal::Restore(r)),
            _ => None,
        };
        let mut app = Self {
            shot: screenshot::Screenshot::new(opts.screenshot.clone()),
            live: LiveRunner::new(opts.debounce),
            viewport: Viewport::new(has_gpu, opts.bake_levels.clone()),
            exports: ExportPanels::new(settings.export_dirs.clone()),
            opts,
            settings,
            syntect: highlight::settings(),
            editor: Editor::new(text),
            doc,
            good: None,
            error: None,
            reference: reference::ReferenceWindow::default(),
            params: ParamPanel::default(),
            bottom,
            jobs: Jobs::default(),
            dialogs: Dialogs::default(),
            recovery,
            modal,
            after_save: None,
            allow_close: false,
            frames: 0,
            stats: FrameStats::default(),
            title: String::new(),
        };
        if !has_gpu {
            app.bottom
                .log("no wgpu render state: the viewport cannot draw");
        }
        if software {
            app.viewport.settings.render_scale = 0.5;
        }
        app.run_now();
        app
    }

    fn run_request(&self) -> RunRequest {
        RunRequest {
            source: self.editor.text.clone(),
            name: self.doc.name(),
            base_dir: self.doc.base_dir.clone(),
            params: self.params.overrides().clone(),
            allow_read: self.settings.read_folders.clone(),
        }
    }

    /// Run the script on the next frame (no debounce).
    pub fn run_now(&mut self) {
        let req = self.run_request();
        self.live.schedule_now(req);
    }

    fn apply_result(&mut self, ctx: &egui::Context, result: LiveResult) {
        match result {
            LiveResult::Ok(d) => {
                let LiveDesign {
                    model,
                    params,
                    log,
                    warnings,
                    script_time,
                    prepare_time,
                    source,
                } = *d;
                for l in &log {
                    self.bottom.log(format!("print: {l}"));
                }
                self.bottom.log(format!(
                    "ran {} in {:.0} ms, prepared {} nodes in {:.0} ms",
                    self.doc.name(),
                    script_time.as_secs_f64() * 1e3,
                    model.node_count(),
                    prepare_time.as_secs_f64() * 1e3
                ));
                self.viewport.set_model(ctx, model.clone());
                self.editor.vocabulary = completion::Vocabulary {
                    materials: model
                        .table()
                        .materials()
                        .iter()
                        .skip(1)
                        .map(|m| m.name.clone())
                        .collect(),
                    params: params.iter().map(|p| p.name.clone()).collect(),
                };
                self.editor.marks.clear();
                self.error = None;
                self.good = Some(GoodDesign {
                    params,
                    warnings,
                    source,
                    model,
                });
            }
            LiveResult::Err(e) => {
                self.bottom.log(format!("{} error: {}", e.stage, e.error));
                self.editor.marks = e
                    .error
                    .line
                    .map(|line| LineMark {
                        line,
                        column: e.error.column,
                        message: e.error.message.clone(),
                    })
                    .into_iter()
                    .collect();
                self.viewport.stale = self.good.is_some();
                self.bottom.show_problems();
                self.error = Some(e);
            }
        }
    }

    /// The problems list: the current error, then the last design's warnings.
    pub fn problems(&self) -> Vec<Problem> {
        let mut v = Vec::new();
        if let Some(e) = &self.error {
            v.push(Problem {
                severity: Severity::Error,
                line: e.error.line,
                column: e.error.column,
                message: e.error.message.clone(),
            });
        }
        if let Some(g) = &self.good {
            v.extend(g.warnings.iter().map(|w| Problem {
                severity: Severity::Warning,
                line: None,
                column: None,
                message: w.clone(),
            }));
        }
        v
    }

    /// True when the editor text differs from the saved file.
    pub fn is_dirty(&self) -> bool {
        self.doc.is_dirty(&self.editor.text)
    }

    /// True when nothing is pending: no script run, no bake level left.
    pub fn is_idle(&self) -> bool {
        !self.live.is_busy() && !self.viewport.is_baking()
    }

    /// The completion list showing in the editor (tests).
    pub fn editor_completion(&self) -> &[completion::Item] {
        self.editor.completion.items()
    }

    /// The editor text (tests).
    pub fn text(&self) -> &str {
        &self.editor.text
    }

    /// The model on screen (tests).
    pub fn model(&self) -> Option<&Arc<volcad_core::Model>> {
        self.viewport.model()
    }

    /// The viewport (tests, measurements).
    pub fn viewport(&self) -> &Viewport {
        &self.viewport
    }

    /// The export jobs (tests).
    pub fn jobs(&self) -> &Jobs {
        &self.jobs
    }

    /// The modal showing, if any (tests).
    pub fn modal(&self) -> Option<&Modal> {
        self.modal.as_ref()
    }

    /// Frame timing so far.
    pub fn frame_stats(&self) -> &FrameStats {
        &self.stats
    }

    /// The log lines (tests).
    pub fn log_lines(&self) -> &[String] {
        self.bottom.log_lines()
    }

    /// Set the export panels' output folder (tests; the same as typing it).
    pub fn set_export_dir(&mut self, dir: PathBuf) {
        self.exports.set_dir(dir);
    }

    /// The export panels' output folder shown (tests).
    pub fn export_dir(&self) -> Option<PathBuf> {
        self.exports.dir()
    }

    fn poll_workers(&mut self, ctx: &egui::Context) {
        if let Some(r) = self.live.poll(ctx) {
            self.apply_result(ctx, r);
        }
        if let Some(note) = self.viewport.poll() {
            self.bottom.log(note);
        }
        for line in self.jobs.poll(ctx) {
            self.bottom.log(line);
        }
        while let Some(a) = self.dialogs.poll(ctx) {
            self.on_dialog(ctx, a);
        }
        if let Some(note) = self.dialogs.take_notice() {
            self.bottom.log(note);
        }
    }

    fn panels(&mut self, ui: &mut egui::Ui) {
        let ctx = ui.ctx().clone();
        egui::Panel::top("menu").show(ui, |ui| self.menu_bar(ui));
        egui::Panel::bottom("status").show(ui, |ui| {
            ui.horizontal(|ui| {
                ui.label(self.viewport.status_text());
                let (mean, max) = self.stats.mean_max();
                ui.with_layout(egui::Layout::right_to_left(egui::Align::Center), |ui| {
                    ui.weak(format!("ui {mean:.1} ms (max {max:.1})"));
                    if self.live.is_busy() {
                        ui.spinner();
                        ui.weak("running script");
                    }
                    ui.weak(format!("line {}", self.editor.cursor_line(&ctx)));
                });
            });
        });
        if self.settings.show_bottom {
            egui::Panel::bottom("problems")
                .resizable(true)
                .default_size(150.0)
                .show(ui, |ui| {
                    let problems = self.problems();
                    if let Some((line, col)) = self.bottom.ui(ui, &problems) {
                        self.editor.goto(line, col);
                    }
                });
        }
        if self.settings.show_editor {
            egui::Panel::left("editor")
                .resizable(true)
                .default_size(430.0)
                .min_size(200.0)
                .show(ui, |ui| {
                    let label = ui
                        .horizontal(|ui| {
                            let dirty = if self.is_dirty() { " •" } else { "" };
                            let label = ui.strong(format!("{}{dirty}", self.doc.name())).id;
                            if let Some(p) = &self.doc.path {
                                ui.weak(
                                    p.parent()
                                        .map(|d| d.display().to_string())
                                        .unwrap_or_default(),
                                );
                            }
                            label
                        })
                        .inner;
                    let out =
                        self.editor
                            .ui(ui, &self.syntect, self.settings.editor_font_size, label);
                    if out.changed {
                        let req = self.run_request();
                        self.live.schedule(req);
                    }
                });
        }
        if self.settings.show_side {
            egui::Panel::right("side")
                .resizable(true)
                .default_size(300.0)
                .min_size(220.0)
                .show(ui, |ui| {
                    egui::ScrollArea::vertical()
                        .id_salt("side-scroll")
                        .show(ui, |ui| self.side_ui(ui));
                });
        }
        egui::CentralPanel::default().show(ui, |ui| {
            self.viewport.toolbar_ui(ui);
            self.viewport.canvas_ui(ui);
        });
    }

    fn side_ui(&mut self, ui: &mut egui::Ui) {
        egui::CollapsingHeader::new("Parameters")
            .default_open(true)
            .show(ui, |ui| {
                let params = self
                    .good
                    .as_ref()
                    .map(|g| g.params.clone())
                    .unwrap_or_default();
                let (log, changed) = self.params.ui(ui, &params);
                if let Some(line) = log {
                    self.bottom.log(line);
                }
                if changed {
                    self.run_now();
                }
            });
        egui::CollapsingHeader::new("Materials")
            .default_open(true)
            .show(ui, |ui| self.viewport.legend_ui(ui));
        egui::CollapsingHeader::new("Probe")
            .default_open(true)
            .show(ui, |ui| {
                // A fixed height, so the panels below do not jump as the
                // read-out under the cursor changes length.
                let lines = 8 + self.model().map_or(0, |m| m.attributes().len());
                let h = ui.text_style_height(&egui::TextStyle::Monospace) * lines as f32;
                egui::ScrollArea::vertical()
                    .id_salt("probe-scroll")
                    .max_height(h)
                    .show(ui, |ui| {
                        ui.set_min_height(h);
                        self.viewport.probe_ui(ui);
                    });
            });
        egui::CollapsingHeader::new("Export")
            .default_open(true)
            .show(ui, |ui| {
                let model = self
                    .good
                    .as_ref()
                    .map(|g| (g.model.clone(), g.source.clone()));
                let ctx = ui.ctx().clone();
                let place = export_panel::Place::of(&self.doc, self.opts.documents_dir.as_deref());
                let action = self.exports.ui(
                    ui,
                    &place,
                    model.as_ref().map(|(m, s)| (m, s.as_str())),
                    &mut self.jobs,
                );
                match action {
                    export_panel::Action::None => {}
                    export_panel::Action::PickFolder(i) => {
                        let dir = self.exports.dir();
                        self.dialogs
                            .show(&ctx, dialogs::DialogPurpose::ExportFolder(i), dir, None);
                    }
                    export_panel::Action::Log(l) => self.bottom.log(l),
                    export_panel::Action::Ask(q) => self.modal = Some(Modal::ConfirmExport(q)),
                }
                for note in self.jobs.ui(ui) {
                    self.bottom.log(note);
                }
            });
    }
}

/// The document to start with: `--script`, the test text, the last file,
/// or the default example.
fn initial_document(
    opts: &StudioOptions,
    settings: &Settings,
    log: &mut BottomPanel,
) -> (Document, String) {
    if let Some(p) = &opts.script {
        match files::read_script(p) {
            Ok(t) => return (Document::from_file(p, &t), t),
            Err(e) => log.log(e),
        }
    }
    if let Some(name) = &opts.example {
        match examples::find(name) {
            Some(e) => {
                return (
                    Document::untitled(e.file, e.source, examples::base_dir()),
                    e.source.to_owned(),
                );
            }
            None => {
                let names: Vec<&str> = examples::all().iter().map(|e| e.file).collect();
                log.log(format!(
                    "no example called {name}; bundled: {}",
                    names.join(", ")
                ));
            }
        }
    }
    if let Some(t) = &opts.initial_text {
        return (Document::untitled("untitled.rhai", t, None), t.clone());
    }
    if opts.persistence
        && let Some(p) = &settings.last_file
        && let Ok(t) = files::read_script(p)
    {
        return (Document::from_file(p, &t), t);
    }
    let ex = examples::default_example();
    (
        Document::untitled(ex.file, ex.source, examples::base_dir()),
        ex.source.to_owned(),
    )
}

impl eframe::App for StudioApp {
    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        let t0 = Instant::now();
        let ctx = ui.ctx().clone();
        self.frames += 1;
        self.handle_close(&ctx);
        self.poll_workers(&ctx);
        self.shortcuts(&ctx);
        self.panels(ui);
        self.modal_ui(&ctx);
        self.reference.ui(&ctx);
        let dirty = self.is_dirty();
        self.recovery
            .tick(&ctx, &self.editor.text, dirty, self.doc.path.as_deref());
        self.update_title(&ctx);
        self.screenshot_step(&ctx);
        self.stats.push(t0, t0.elapsed().as_secs_f32() * 1e3);
    }

    fn save(&mut self, storage: &mut dyn eframe::Storage) {
        if self.opts.persistence {
            self.settings.last_file = self.doc.path.clone();
            self.settings.export_dirs = self.exports.dirs().clone();
            self.settings.store(storage);
        }
    }

    fn persist_egui_memory(&self) -> bool {
        self.opts.persistence
    }
}
