//! Menus, keyboard shortcuts, file commands and modals (unsaved changes,
//! restore after a crash, quit with running jobs), and window close.

use std::path::PathBuf;

use egui::{Key, KeyboardShortcut, Modifiers, ViewportCommand};

use super::dialogs::{DialogAnswer, DialogPurpose};
use super::export_panel::Question;
use super::files::{self, Document, Recovered};
use super::settings::Theme;
use super::{StudioApp, examples};

const SAVE: KeyboardShortcut = KeyboardShortcut::new(Modifiers::COMMAND, Key::S);
const SAVE_AS: KeyboardShortcut =
    KeyboardShortcut::new(Modifiers::COMMAND.plus(Modifiers::SHIFT), Key::S);
const OPEN: KeyboardShortcut = KeyboardShortcut::new(Modifiers::COMMAND, Key::O);
const NEW: KeyboardShortcut = KeyboardShortcut::new(Modifiers::COMMAND, Key::N);
const QUIT: KeyboardShortcut = KeyboardShortcut::new(Modifiers::COMMAND, Key::Q);
const ZOOM_IN: KeyboardShortcut = KeyboardShortcut::new(Modifiers::COMMAND, Key::Plus);
const ZOOM_IN_EQUALS: KeyboardShortcut = KeyboardShortcut::new(Modifiers::COMMAND, Key::Equals);
const ZOOM_OUT: KeyboardShortcut = KeyboardShortcut::new(Modifiers::COMMAND, Key::Minus);
const ZOOM_RESET: KeyboardShortcut = KeyboardShortcut::new(Modifiers::COMMAND, Key::Num0);
const RUN: KeyboardShortcut = KeyboardShortcut::new(Modifiers::NONE, Key::F5);

/// The text of File → New.
const NEW_SCRIPT: &str = r#"// A new design. Edit and watch the preview.
let m = default_materials();
Sphere(Vec3(0, 0, 0), 10, m.id("red"))
"#;

/// Something that replaces the editor's text (or ends the session), done
/// after the unsaved-changes question.
#[derive(Clone, Debug, PartialEq)]
pub enum Pending {
    /// File → New.
    New,
    /// File → Open… (the dialog comes after the question).
    Open,
    /// Open this file (recent files).
    OpenPath(PathBuf),
    /// Open a bundled example by file name.
    Example(&'static str),
    /// Close the window.
    Quit,
}

/// A modal dialog.
#[derive(Clone, Debug, PartialEq)]
pub enum Modal {
    /// "Save changes to X?" before `Pending`.
    Unsaved(Pending),
    /// Unsaved text from a previous session was found.
    Restore(Recovered),
    /// Exports are running and the window is closing.
    QuitWithJobs,
    /// A message to acknowledge (an error saving, for example).
    Message(String),
    /// An export waits: it would replace a finished export or outgrow the
    /// solving machine.
    ConfirmExport(Question),
}

/// Apply the theme preference.
pub fn apply_theme(ctx: &egui::Context, theme: Theme) {
    ctx.set_theme(match theme {
        Theme::System => egui::ThemePreference::System,
        Theme::Dark => egui::ThemePreference::Dark,
        Theme::Light => egui::ThemePreference::Light,
    });
}

impl StudioApp {
    /// Do `p`, asking first when it would lose unsaved text.
    pub fn request(&mut self, ctx: &egui::Context, p: Pending) {
        if self.is_dirty() {
            self.modal = Some(Modal::Unsaved(p));
        } else {
            self.perform(ctx, p);
        }
    }

    fn perform(&mut self, ctx: &egui::Context, p: Pending) {
        match p {
            Pending::New => self.load(
                ctx,
                Document::untitled("untitled.rhai", NEW_SCRIPT, None),
                NEW_SCRIPT.to_owned(),
            ),
            Pending::Open => {
                let dir = self
                    .doc
                    .path
                    .as_ref()
                    .and_then(|p| p.parent().map(PathBuf::from));
                self.dialogs.show(ctx, DialogPurpose::Open, dir, None);
            }
            Pending::OpenPath(path) => self.open_path(ctx, path),
            Pending::Example(file) => {
                if let Some(e) = examples::find(file) {
                    self.load(
                        ctx,
                        Document::untitled(e.file, e.source, examples::base_dir()),
                        e.source.to_owned(),
                    );
                }
            }
            Pending::Quit => {
                if self.jobs.any_running() {
                    self.modal = Some(Modal::QuitWithJobs);
                } else {
                    self.quit(ctx);
                }
            }
        }
    }

    fn quit(&mut self, ctx: &egui::Context) {
        // A clean document leaves no recovery file behind: the next start
        // must not offer work that was never lost.
        if !self.is_dirty() {
            self.recovery.clear();
        }
        self.allow_close = true;
        ctx.send_viewport_cmd(ViewportCommand::Close);
    }

    /// Open a script file (no unsaved-changes question; see `request`).
    pub fn open_path(&mut self, ctx: &egui::Context, path: PathBuf) {
        match files::read_script(&path) {
            Ok(text) => {
                self.settings.add_recent(&path);
                self.load(ctx, Document::from_file(&path, &text), text);
            }
            Err(e) => {
                self.bottom.log(&e);
                self.modal = Some(Modal::Message(e));
            }
        }
    }

    fn load(&mut self, ctx: &egui::Context, doc: Document, text: String) {
        self.bottom.log(format!(
            "opened {}",
            doc.path
                .as_ref()
                .map_or_else(|| doc.name(), |p| p.display().to_string())
        ));
        self.doc = doc;
        self.editor.set_text(ctx, text);
        if let Err(e) = self.params.open_sets(self.doc.path.as_deref()) {
            self.bottom.log(format!("parameter sets not read: {e}"));
        }
        self.recovery.clear();
        self.error = None;
        self.viewport.fit_next();
        self.run_now();
    }

    /// File → Save (Save As when untitled). Returns true when saved.
    pub fn save(&mut self, ctx: &egui::Context) -> bool {
        match self.doc.path.clone() {
            Some(p) => self.save_to(p),
            None => {
                self.save_as_dialog(ctx);
                false
            }
        }
    }

    fn save_as_dialog(&mut self, ctx: &egui::Context) {
        let name = self.doc.name();
        let dir = self
            .doc
            .path
            .as_ref()
            .and_then(|p| p.parent().map(PathBuf::from));
        self.dialogs
            .show(ctx, DialogPurpose::SaveAs, dir, Some(name));
    }

    /// Save the text to `path` and make it the document's file.
    pub fn save_to(&mut self, path: PathBuf) -> bool {
        let text = self.editor.text.clone();
        match self.doc.save_as(&path, &text) {
            Ok(()) => {
                self.settings.add_recent(&path);
                self.params.moved_to(&path);
                self.recovery.clear();
                self.bottom.log(format!("saved {}", path.display()));
                true
            }
            Err(e) => {
                self.bottom.log(&e);
                self.modal = Some(Modal::Message(e));
                false
            }
        }
    }

    pub(super) fn on_dialog(&mut self, ctx: &egui::Context, a: DialogAnswer) {
        let Some(path) = a.path else {
            self.after_save = None;
            return;
        };
        match a.purpose {
            DialogPurpose::Open => self.open_path(ctx, path),
            DialogPurpose::SaveAs => {
                if self.save_to(path)
                    && let Some(p) = self.after_save.take()
                {
                    self.perform(ctx, p);
                }
            }
            DialogPurpose::ExportFolder(_) => self.exports.set_dir(path),
            DialogPurpose::ReadFolder => {
                if !self.settings.read_folders.contains(&path) {
                    self.settings.read_folders.push(path);
                }
                self.run_now();
            }
        }
    }

    pub(super) fn handle_close(&mut self, ctx: &egui::Context) {
        if ctx.input(|i| i.viewport().close_requested()) && !self.allow_close {
            ctx.send_viewport_cmd(ViewportCommand::CancelClose);
            if self.modal.is_none() {
                self.request(ctx, Pending::Quit);
            }
        }
    }

    pub(super) fn shortcuts(&mut self, ctx: &egui::Context) {
        if self.modal.is_some() {
            return;
        }
        let pressed = |s: &KeyboardShortcut| ctx.input_mut(|i| i.consume_shortcut(s));
        if pressed(&SAVE_AS) {
            self.save_as_dialog(ctx);
        } else if pressed(&SAVE) {
            self.save(ctx);
        }
        if pressed(&OPEN) {
            self.request(ctx, Pending::Open);
        }
        if pressed(&NEW) {
            self.request(ctx, Pending::New);
        }
        if ctx.input_mut(|i| i.consume_key(Modifiers::NONE, Key::F1)) {
            self.reference.open = !self.reference.open;
        }
        if pressed(&QUIT) {
            self.request(ctx, Pending::Quit);
        }
        if pressed(&ZOOM_IN) || pressed(&ZOOM_IN_EQUALS) {
            self.settings.zoom(1.0);
        }
        if pressed(&ZOOM_OUT) {
            self.settings.zoom(-1.0);
        }
        if pressed(&ZOOM_RESET) {
            self.settings.editor_font_size = super::settings::Settings::default().editor_font_size;
        }
        if pressed(&RUN) {
            self.run_now();
        }
    }

    pub(super) fn update_title(&mut self, ctx: &egui::Context) {
        let title = format!(
            "{}{} — Volcad Studio",
            self.doc.name(),
            if self.is_dirty() { " •" } else { "" }
        );
        if title != self.title {
            ctx.send_viewport_cmd(ViewportCommand::Title(title.clone()));
            self.title = title;
        }
    }

    pub(super) fn menu_bar(&mut self, ui: &mut egui::Ui) {
        let ctx = ui.ctx().clone();
        let sc = |s: &KeyboardShortcut| ctx.format_shortcut(s);
        egui::MenuBar::new().ui(ui, |ui| {
            ui.menu_button("File", |ui| {
                if ui.add(egui::Button::new("New").shortcut_text(sc(&NEW))).clicked() {
                    self.request(&ctx, Pending::New);
                }
                if ui.add(egui::Button::new("Open…").shortcut_text(sc(&OPEN))).clicked() {
                    self.request(&ctx, Pending::Open);
                }
                ui.menu_button("Open Recent", |ui| {
                    if self.settings.recent_files.is_empty() {
                        ui.weak("No recent files");
                    }
                    for p in self.settings.recent_files.clone() {
                        if ui.button(p.display().to_string()).clicked() {
                            self.request(&ctx, Pending::OpenPath(p));
                        }
                    }
                });
                ui.separator();
                if ui.add(egui::Button::new("Save").shortcut_text(sc(&SAVE))).clicked() {
                    self.save(&ctx);
                }
                if ui.add(egui::Button::new("Save As…").shortcut_text(sc(&SAVE_AS))).clicked() {
                    self.save_as_dialog(&ctx);
                }
                ui.menu_button("Folders Scripts May Read", |ui| {
                    ui.weak("Besides the script's project (the folder above it with .git or volcad.toml)");
                    for p in self.settings.read_folders.clone() {
                        if ui.button(format!("✕ {}", p.display())).on_hover_text("Remove").clicked() {
                            self.settings.read_folders.retain(|q| q != &p);
                            self.run_now();
                        }
                    }
                    if ui.button("Add Folder…").clicked() {
                        self.dialogs.show(&ctx, DialogPurpose::ReadFolder, None, None);
                    }
                });
                ui.separator();
                if ui.button("Quit").clicked() {
                    self.request(&ctx, Pending::Quit);
                }
            });
            ui.menu_button("Edit", |ui| {
                if ui.add(egui::Button::new("Undo").shortcut_text("Ctrl+Z")).clicked() && self.editor.undo(&ctx) {
                    self.schedule_after_edit();
                }
                if ui.add(egui::Button::new("Redo").shortcut_text("Ctrl+Shift+Z")).clicked() && self.editor.redo(&ctx) {
                    self.schedule_after_edit();
                }
                ui.separator();
                if ui.add(egui::Button::new("Find…").shortcut_text(sc(&super::editor::FIND))).clicked() {
                    self.editor.open_find();
                }
                if ui.add(egui::Button::new("Run now").shortcut_text(sc(&RUN))).clicked() {
                    self.run_now();
                }
            });
            ui.menu_button("View", |ui| {
                ui.checkbox(&mut self.settings.show_editor, "Editor");
                ui.checkbox(&mut self.settings.show_side, "Side panel");
                ui.checkbox(&mut self.settings.show_bottom, "Problems and log");
                ui.separator();
                for (label, t) in [("System theme", Theme::System), ("Dark", Theme::Dark), ("Light", Theme::Light)] {
                    if ui.radio_value(&mut self.settings.theme, t, label).clicked() {
                        apply_theme(&ctx, t);
                    }
                }
                ui.separator();
                if ui.add(egui::Button::new("Larger editor font").shortcut_text(sc(&ZOOM_IN))).clicked() {
                    self.settings.zoom(1.0);
                }
                if ui.add(egui::Button::new("Smaller editor font").shortcut_text(sc(&ZOOM_OUT))).clicked() {
                    self.settings.zoom(-1.0);
                }
            });
            ui.menu_button("Examples", |ui| {
                for e in examples::all() {
                    if ui
                        .add(egui::Button::new(&e.title).shortcut_text(e.file))
                        .clicked()
                    {
                        self.request(&ctx, Pending::Example(e.file));
                    }
                }
            });
            ui.menu_button("Help", |ui| {
                if ui
                    .add(egui::Button::new("Language reference").shortcut_text("F1"))
                    .clicked()
                {
                    self.reference.open = true;
                }
                ui.weak("In the editor: Ctrl+Space completes; hover a name for its forms.");
                ui.separator();
                ui.label(format!("Volcad Studio {}", env!("CARGO_PKG_VERSION")));
                ui.weak("Volumetric multi-material design: edit the Rhai script,\nthe preview follows; export from the right panel.");
                ui.weak("Viewport: drag to orbit, right/middle/Shift-drag to pan,\nscroll to zoom, double-click or F to fit, click to pin the probe.");
            });
        });
    }

    fn schedule_after_edit(&mut self) {
        let req = self.run_request();
        self.live.schedule(req);
    }

    pub(super) fn modal_ui(&mut self, ctx: &egui::Context) {
        let Some(modal) = self.modal.clone() else {
            return;
        };
        let mut close = false;
        // Enter takes the highlighted (first, safe) choice; Escape cancels,
        // keeping everything as it was.
        let enter = ctx.input_mut(|i| i.consume_key(Modifiers::NONE, Key::Enter));
        let esc = ctx.input_mut(|i| i.consume_key(Modifiers::NONE, Key::Escape));
        egui::Modal::new(egui::Id::unique("studio-modal")).show(ctx, |ui| {
            ui.set_max_width(440.0);
            match &modal {
                Modal::Unsaved(p) => {
                    ui.heading("Unsaved changes");
                    ui.label(format!("Save the changes to {} first?", self.doc.name()));
                    ui.horizontal(|ui| {
                        if ui.button("Save").clicked() || enter {
                            close = true;
                            if self.doc.path.is_some() {
                                if self.save(ctx) {
                                    self.perform(ctx, p.clone());
                                }
                            } else {
                                self.after_save = Some(p.clone());
                                self.save_as_dialog(ctx);
                            }
                        }
                        if ui.button("Don't save").clicked() {
                            close = true;
                            self.recovery.clear();
                            self.doc.saved_text = self.editor.text.clone();
                            self.perform(ctx, p.clone());
                        }
                        if ui.button("Cancel").clicked() || esc {
                            close = true;
                        }
                    });
                }
                Modal::Restore(r) => {
                    ui.heading("Restore unsaved work?");
                    let of = r.meta.path.as_ref().map_or_else(
                        || "an untitled script".to_owned(),
                        |p| p.display().to_string(),
                    );
                    ui.label(format!(
                        "The studio closed with unsaved changes to {of} ({} lines).",
                        r.text.lines().count()
                    ));
                    ui.horizontal(|ui| {
                        if ui.button("Restore").clicked() || enter {
                            close = true;
                            self.restore(ctx, r.clone());
                        }
                        if ui.button("Discard").clicked() {
                            close = true;
                            self.recovery.clear();
                        }
                        // Escape decides nothing: the file is offered again
                        // next time.
                        if ui.button("Later").clicked() || esc {
                            close = true;
                        }
                    });
                }
                Modal::QuitWithJobs => {
                    ui.heading("Exports are running");
                    ui.label("Quitting cancels them; their output folders will not be written.");
                    ui.horizontal(|ui| {
                        if ui.button("Cancel exports and quit").clicked() {
                            close = true;
                            self.jobs.cancel_all();
                            self.quit(ctx);
                        }
                        if ui.button("Keep working").clicked() || enter || esc {
                            close = true;
                        }
                    });
                }
                Modal::Message(m) => {
                    ui.label(m);
                    if ui.button("OK").clicked() || enter || esc {
                        close = true;
                    }
                }
                Modal::ConfirmExport(q) => {
                    ui.heading(&q.heading);
                    ui.label(&q.text);
                    ui.horizontal(|ui| {
                        if ui.button(&q.confirm).clicked() {
                            close = true;
                            if let Some(line) = self.exports.confirm(&mut self.jobs) {
                                self.bottom.log(line);
                            }
                        }
                        // Enter, like Escape, keeps the folder: replacing
                        // work takes a click.
                        if ui.button("Cancel").clicked() || enter || esc {
                            close = true;
                            if let Some(line) = self.exports.cancel_pending() {
                                self.bottom.log(line);
                            }
                        }
                    });
                }
            }
        });
        if close && self.modal.as_ref() == Some(&modal) {
            self.modal = None;
        }
    }

    fn restore(&mut self, ctx: &egui::Context, r: Recovered) {
        let doc = match &r.meta.path {
            Some(p) => {
                let saved = files::read_script(p).unwrap_or_default();
                Document::from_file(p, &saved)
            }
            None => Document::untitled("recovered.rhai", "", None),
        };
        self.bottom
            .log("restored unsaved work from the recovery file");
        self.doc = doc;
        self.editor.set_text(ctx, r.text);
        if let Err(e) = self.params.open_sets(self.doc.path.as_deref()) {
            self.bottom.log(format!("parameter sets not read: {e}"));
        }
        self.viewport.fit_next();
        self.run_now();
    }
}
