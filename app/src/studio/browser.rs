//! The built-in file browser, for desktops without a file dialog: a path
//! field, the folder's entries (folders first, then the files the dialog
//! is for), Up, and OK/Cancel. Enter confirms and Escape cancels.

use std::path::{Path, PathBuf};

/// What the browser picks.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BrowserKind {
    /// An existing design file.
    OpenFile,
    /// A file name to write (existing or new).
    SaveFile,
    /// A folder.
    Folder,
}

/// Where the browser stands after a frame.
#[derive(Clone, Debug, PartialEq)]
pub enum BrowserState {
    /// Still choosing.
    Open,
    /// This path was chosen.
    Chosen(PathBuf),
    /// Closed without a choice.
    Cancelled,
}

/// One built-in file browser window.
pub struct Browser {
    kind: BrowserKind,
    title: &'static str,
    dir: PathBuf,
    /// The path field: a full path, or a name in `dir`.
    field: String,
    entries: Vec<(String, bool)>,
    error: Option<String>,
}

/// Design files the Open browser lists.
const DESIGN_EXTENSIONS: [&str; 2] = ["rhai", "vcad"];

impl Browser {
    /// A browser of `kind` starting in `dir`, the field holding `name`.
    pub fn new(kind: BrowserKind, title: &'static str, dir: PathBuf, name: Option<String>) -> Self {
        let mut b = Browser {
            kind,
            title,
            dir,
            field: name.unwrap_or_default(),
            entries: Vec::new(),
            error: None,
        };
        b.list();
        b
    }

    fn list(&mut self) {
        self.entries.clear();
        match std::fs::read_dir(&self.dir) {
            Ok(rd) => {
                for e in rd.flatten() {
                    let name = e.file_name().to_string_lossy().into_owned();
                    if name.starts_with('.') {
                        continue;
                    }
                    let is_dir = e.path().is_dir();
                    let shown = is_dir
                        || (self.kind != BrowserKind::Folder
                            && Path::new(&name)
                                .extension()
                                .is_some_and(|x| DESIGN_EXTENSIONS.iter().any(|d| x == *d)));
                    if shown {
                        self.entries.push((name, is_dir));
                    }
                }
                self.entries
                    .sort_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(&b.0)));
                self.error = None;
            }
            Err(e) => self.error = Some(format!("{}: {e}", self.dir.display())),
        }
    }

    fn enter(&mut self, dir: PathBuf) {
        self.dir = dir;
        if self.kind != BrowserKind::SaveFile {
            self.field.clear();
        }
        self.list();
    }

    /// The path the field names (relative names are in the folder shown).
    fn target(&self) -> PathBuf {
        let f = self.field.trim();
        if f.is_empty() {
            self.dir.clone()
        } else {
            self.dir.join(f)
        }
    }

    /// The choice, if the field names something this browser may pick;
    /// a folder named by an Open or Save field is entered instead.
    fn confirm(&mut self) -> BrowserState {
        let t = self.target();
        match self.kind {
            BrowserKind::Folder if t.is_dir() => BrowserState::Chosen(t),
            BrowserKind::Folder => {
                self.error = Some(format!("not a folder: {}", t.display()));
                BrowserState::Open
            }
            _ if t.is_dir() => {
                self.enter(t);
                BrowserState::Open
            }
            BrowserKind::OpenFile if !t.is_file() => {
                self.error = Some(format!("no such file: {}", t.display()));
                BrowserState::Open
            }
            BrowserKind::SaveFile if !t.parent().is_some_and(Path::is_dir) => {
                self.error = Some(format!("no such folder: {}", t.display()));
                BrowserState::Open
            }
            _ => BrowserState::Chosen(t),
        }
    }

    /// Draw the window; its state after this frame.
    pub fn ui(&mut self, ctx: &egui::Context) -> BrowserState {
        let mut state = BrowserState::Open;
        let mut open = true;
        egui::Window::new(self.title)
            .open(&mut open)
            .collapsible(false)
            .default_size([520.0, 420.0])
            .show(ctx, |ui| state = self.body_ui(ui));
        if !open {
            return BrowserState::Cancelled;
        }
        state
    }

    fn body_ui(&mut self, ui: &mut egui::Ui) -> BrowserState {
        ui.horizontal(|ui| {
            if ui.button("Up").on_hover_text("The parent folder").clicked()
                && let Some(p) = self.dir.parent().map(Path::to_path_buf)
            {
                self.enter(p);
            }
            ui.monospace(self.dir.display().to_string());
        });
        let mut chosen = None;
        egui::ScrollArea::vertical()
            .id_salt("browser-entries")
            .max_height(260.0)
            .show(ui, |ui| {
                let mut go = None;
                for (name, is_dir) in &self.entries {
                    let label = if *is_dir {
                        format!("{name}/")
                    } else {
                        name.clone()
                    };
                    let r = ui.selectable_label(self.field == *name, label);
                    if r.double_clicked() {
                        go = Some((name.clone(), *is_dir, true));
                    } else if r.clicked() {
                        go = Some((name.clone(), *is_dir, false));
                    }
                }
                if let Some((name, is_dir, twice)) = go {
                    if is_dir && (twice || self.kind == BrowserKind::Folder) {
                        self.enter(self.dir.join(&name));
                    } else if !is_dir && twice {
                        self.field = name;
                        chosen = Some(self.confirm());
                    } else {
                        self.field = name;
                    }
                }
            });
        let label = match self.kind {
            BrowserKind::Folder => "Folder",
            _ => "File name",
        };
        ui.horizontal(|ui| {
            let l = ui.label(label).id;
            ui.add(egui::TextEdit::singleline(&mut self.field).id_salt("browser-field"))
                .labelled_by(l);
        });
        if let Some(e) = &self.error {
            ui.colored_label(ui.visuals().error_fg_color, e);
        }
        let ok = match self.kind {
            BrowserKind::OpenFile => "Open",
            BrowserKind::SaveFile => "Save",
            BrowserKind::Folder => "Choose",
        };
        let mut state = chosen.unwrap_or(BrowserState::Open);
        ui.horizontal(|ui| {
            let enter = ui.input(|i| i.key_pressed(egui::Key::Enter));
            if ui.button(ok).clicked() || enter {
                state = self.confirm();
            }
            if ui.button("Cancel").clicked() || ui.input(|i| i.key_pressed(egui::Key::Escape)) {
                state = BrowserState::Cancelled;
            }
        });
        state
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lists_folders_and_designs_and_confirms_by_kind() {
        let dir = tempfile::tempdir().expect("temp dir");
        std::fs::create_dir(dir.path().join("sub")).expect("mkdir");
        std::fs::write(dir.path().join("a.rhai"), "1").expect("write");
        std::fs::write(dir.path().join("notes.txt"), "x").expect("write");
        let mut b = Browser::new(BrowserKind::OpenFile, "Open", dir.path().into(), None);
        assert_eq!(
            b.entries,
            vec![("sub".to_string(), true), ("a.rhai".to_string(), false)]
        );
        b.field = "missing.rhai".into();
        assert_eq!(b.confirm(), BrowserState::Open);
        assert!(
            b.error
                .as_deref()
                .is_some_and(|e| e.contains("no such file"))
        );
        b.field = "a.rhai".into();
        assert_eq!(b.confirm(), BrowserState::Chosen(dir.path().join("a.rhai")));
        let mut s = Browser::new(
            BrowserKind::SaveFile,
            "Save",
            dir.path().into(),
            Some("new.rhai".into()),
        );
        assert_eq!(
            s.confirm(),
            BrowserState::Chosen(dir.path().join("new.rhai"))
        );
        let mut f = Browser::new(BrowserKind::Folder, "Folder", dir.path().into(), None);
        f.field = "sub".into();
        assert_eq!(f.confirm(), BrowserState::Chosen(dir.path().join("sub")));
    }
}
