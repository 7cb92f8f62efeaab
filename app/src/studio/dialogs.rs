//! File dialogs: the desktop's own (`rfd` through xdg-desktop-portal), or a
//! built-in file browser (`browser.rs`) where the desktop has none.
//!
//! A native dialog runs its blocking call on a short-lived thread and
//! answers through a channel that the UI drains every frame. Without a
//! portal (minimal Linux, WSL, containers) `rfd` answers "cancelled" at
//! once, so a dialog that comes back empty in less time than a person
//! needs to close one is taken as "no desktop dialog here": the log says so
//! once, and this and every later dialog use the built-in browser, drawn
//! inside the studio's window (`browser.rs`). The egui file-browser crates
//! were tried: `egui-file-dialog` does not follow egui 0.37, and
//! `egui_file` draws emoji that egui's bundled fonts do not have.

use std::path::{Path, PathBuf};
use std::sync::mpsc::{Receiver, Sender, channel};
use std::time::{Duration, Instant};

use super::browser::{Browser, BrowserKind, BrowserState};

/// A native dialog answering "cancelled" sooner than this was never shown.
const NOT_SHOWN: Duration = Duration::from_millis(300);

/// What a dialog was opened for.
#[derive(Clone, Debug, PartialEq)]
pub enum DialogPurpose {
    /// File → Open.
    Open,
    /// File → Save As (then maybe continue with a pending action).
    SaveAs,
    /// An export panel's output folder (panel index).
    ExportFolder(usize),
    /// A folder scripts may read besides their project.
    ReadFolder,
}

/// A dialog's answer.
#[derive(Debug)]
pub struct DialogAnswer {
    /// What it was for.
    pub purpose: DialogPurpose,
    /// The chosen path (`None`: cancelled).
    pub path: Option<PathBuf>,
}

/// Whether the desktop shows file dialogs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Native {
    /// Not known yet: the first dialog tries.
    Untried,
    /// A native dialog was shown.
    Works,
    /// None could be shown: the built-in browser serves.
    Missing,
}

/// A native dialog's answer, with whether it can have been shown.
struct NativeAnswer {
    purpose: DialogPurpose,
    path: Option<PathBuf>,
    start: Option<PathBuf>,
    file_name: Option<String>,
    shown: bool,
}

/// The studio's file dialogs.
pub struct Dialogs {
    tx: Sender<NativeAnswer>,
    rx: Receiver<NativeAnswer>,
    open: usize,
    native: Native,
    builtin: Option<(DialogPurpose, Browser)>,
    notice: Option<String>,
    told: bool,
}

impl Default for Dialogs {
    fn default() -> Self {
        let (tx, rx) = channel();
        // Without a session bus there is no portal to ask.
        let native = if std::env::var_os("DBUS_SESSION_BUS_ADDRESS").is_some() {
            Native::Untried
        } else {
            Native::Missing
        };
        Self {
            tx,
            rx,
            open: 0,
            native,
            builtin: None,
            notice: None,
            told: false,
        }
    }
}

impl Dialogs {
    /// True while a dialog is showing.
    pub fn is_open(&self) -> bool {
        self.open > 0 || self.builtin.is_some()
    }

    /// A line for the log, once: why the built-in browser is used.
    pub fn take_notice(&mut self) -> Option<String> {
        self.notice.take()
    }

    fn tell(&mut self, why: &str) {
        if !self.told {
            self.told = true;
            self.notice = Some(format!(
                "no desktop file dialog here ({why}): using the built-in file browser"
            ));
        }
    }

    /// Show a dialog for `purpose`, starting in `dir`.
    pub fn show(
        &mut self,
        ctx: &egui::Context,
        purpose: DialogPurpose,
        dir: Option<PathBuf>,
        file_name: Option<String>,
    ) {
        if self.native == Native::Missing {
            self.tell("there is no session bus");
            self.open_builtin(purpose, dir, file_name);
            return;
        }
        let tx = self.tx.clone();
        let ctx = ctx.clone();
        self.open += 1;
        let p = purpose.clone();
        let spawned = std::thread::Builder::new()
            .name("volcad-dialog".into())
            .spawn(move || {
                let t = Instant::now();
                let path = native_dialog(&p, dir.as_deref(), file_name.clone());
                let shown = path.is_some() || t.elapsed() >= NOT_SHOWN;
                let _ = tx.send(NativeAnswer {
                    purpose: p,
                    path,
                    start: dir,
                    file_name,
                    shown,
                });
                ctx.request_repaint();
            });
        if spawned.is_err() {
            self.open -= 1;
            self.open_builtin(purpose, None, None);
        }
    }

    fn open_builtin(&mut self, purpose: DialogPurpose, dir: Option<PathBuf>, name: Option<String>) {
        let (kind, title) = match &purpose {
            DialogPurpose::Open => (BrowserKind::OpenFile, "Open design"),
            DialogPurpose::SaveAs => (BrowserKind::SaveFile, "Save design as"),
            DialogPurpose::ExportFolder(_) => (BrowserKind::Folder, "Output folder"),
            DialogPurpose::ReadFolder => (BrowserKind::Folder, "A folder scripts may read"),
        };
        let dir = dir
            .or_else(|| std::env::current_dir().ok())
            .unwrap_or_else(|| PathBuf::from("/"));
        self.builtin = Some((purpose, Browser::new(kind, title, dir, name)));
    }

    /// The next answer, if any; draws the built-in browser while it is
    /// open (call every frame).
    pub fn poll(&mut self, ctx: &egui::Context) -> Option<DialogAnswer> {
        if let Ok(a) = self.rx.try_recv() {
            self.open = self.open.saturating_sub(1);
            if a.shown {
                self.native = Native::Works;
            } else if self.native == Native::Untried {
                self.native = Native::Missing;
                self.tell("xdg-desktop-portal did not show one");
                self.open_builtin(a.purpose, a.start, a.file_name);
                return None;
            }
            return Some(DialogAnswer {
                purpose: a.purpose,
                path: a.path,
            });
        }
        let (purpose, d) = self.builtin.as_mut()?;
        let path = match d.ui(ctx) {
            BrowserState::Open => return None,
            BrowserState::Chosen(p) => Some(p),
            BrowserState::Cancelled => None,
        };
        let purpose = purpose.clone();
        self.builtin = None;
        let path = path.map(|p| with_rhai_extension(&purpose, p));
        Some(DialogAnswer { purpose, path })
    }
}

/// A saved design without an extension gets `.rhai`.
fn with_rhai_extension(purpose: &DialogPurpose, p: PathBuf) -> PathBuf {
    if *purpose == DialogPurpose::SaveAs && p.extension().is_none() {
        p.with_extension("rhai")
    } else {
        p
    }
}

/// The desktop's dialog (blocking; on a worker thread).
fn native_dialog(
    p: &DialogPurpose,
    dir: Option<&Path>,
    file_name: Option<String>,
) -> Option<PathBuf> {
    let mut d = rfd::FileDialog::new();
    if let Some(dir) = dir {
        d = d.set_directory(dir);
    }
    match p {
        DialogPurpose::Open => d
            .add_filter("Design (Rhai script or legacy .vcad)", &["rhai", "vcad"])
            .pick_file(),
        DialogPurpose::SaveAs => {
            let d = d.add_filter("Rhai design script", &["rhai"]);
            let d = match file_name {
                Some(n) => d.set_file_name(n),
                None => d,
            };
            d.save_file()
                .map(|p| with_rhai_extension(&DialogPurpose::SaveAs, p))
        }
        DialogPurpose::ExportFolder(_) | DialogPurpose::ReadFolder => d.pick_folder(),
    }
}
