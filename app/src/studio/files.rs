//! Files: the open document and the recovery file that autosaves unsaved
//! text (file dialogs are in `dialogs.rs`).
//!
//! Recovery: every few seconds while the text differs from the saved file,
//! `recovery.rhai` (the text) and `recovery.json` (which file it belongs to)
//! are written in the data folder, on a worker thread, atomically
//! (write + rename). Saving or discarding removes them; on start-up the
//! studio offers to restore them.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant, SystemTime};

use serde::{Deserialize, Serialize};

/// The document in the editor.
#[derive(Clone, Debug, Default)]
pub struct Document {
    /// Where it is saved (`None`: untitled).
    pub path: Option<PathBuf>,
    /// The text as last saved or opened (dirty = editor text differs).
    pub saved_text: String,
    /// Folder relative file names resolve in (the file's folder, or the
    /// examples folder for an example).
    pub base_dir: Option<PathBuf>,
    /// What the title bar and errors call it when untitled.
    pub untitled_name: String,
}

impl Document {
    /// An untitled document.
    pub fn untitled(name: &str, text: &str, base_dir: Option<PathBuf>) -> Self {
        Self {
            path: None,
            saved_text: text.to_owned(),
            base_dir,
            untitled_name: name.to_owned(),
        }
    }

    /// A document read from `path`.
    pub fn from_file(path: &Path, text: &str) -> Self {
        Self {
            path: Some(path.to_owned()),
            saved_text: text.to_owned(),
            base_dir: volcad_core::script::ScriptOptions::for_file(path).base_dir,
            untitled_name: String::new(),
        }
    }

    /// The name errors and the title use.
    pub fn name(&self) -> String {
        match &self.path {
            Some(p) => p.file_name().map_or_else(
                || p.display().to_string(),
                |n| n.to_string_lossy().into_owned(),
            ),
            None => self.untitled_name.clone(),
        }
    }

    /// True when `text` differs from what is saved.
    pub fn is_dirty(&self, text: &str) -> bool {
        text != self.saved_text
    }

    /// Write `text` to `path` and make it this document's file.
    pub fn save_as(&mut self, path: &Path, text: &str) -> Result<(), String> {
        write_atomically(path, text.as_bytes())
            .map_err(|e| format!("could not save {}: {e}", path.display()))?;
        *self = Document::from_file(path, text);
        Ok(())
    }
}

/// Write via a temporary file and a rename, so a crash never leaves half a file.
pub fn write_atomically(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let tmp = path.with_file_name(format!(".{name}.tmp-{}", std::process::id()));
    std::fs::write(&tmp, bytes)?;
    std::fs::rename(&tmp, path).inspect_err(|_| {
        let _ = std::fs::remove_file(&tmp);
    })
}

/// Read a script file.
pub fn read_script(path: &Path) -> Result<String, String> {
    std::fs::read_to_string(path).map_err(|e| format!("could not open {}: {e}", path.display()))
}

/// What `recovery.json` records.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct RecoveryMeta {
    /// The file the text belongs to (`None`: untitled).
    pub path: Option<PathBuf>,
    /// Seconds since the Unix epoch when it was written.
    pub saved_at: u64,
}

/// Text found in the recovery file at start-up.
#[derive(Clone, Debug, PartialEq)]
pub struct Recovered {
    /// The unsaved text.
    pub text: String,
    /// Which file it belongs to, and when it was written.
    pub meta: RecoveryMeta,
}

/// The autosave of unsaved text.
///
/// One write at a time: the next write, [`Recovery::clear`] and dropping
/// wait for the one in flight (a few milliseconds; writes start at most
/// once per interval). Otherwise an older text could land after a newer
/// one, or a write still in flight when the file was saved could bring
/// back a recovery file for text that is already saved.
pub struct Recovery {
    dir: Option<PathBuf>,
    interval: Duration,
    last_write: Option<Instant>,
    last_text: Option<String>,
    writing: Option<std::thread::JoinHandle<()>>,
}

impl Recovery {
    /// Autosave into `dir` every `interval` (`None`: disabled).
    pub fn new(dir: Option<PathBuf>, interval: Duration) -> Self {
        Self {
            dir,
            interval,
            last_write: None,
            last_text: None,
            writing: None,
        }
    }

    /// Wait for the write in flight, if any.
    fn wait(&mut self) {
        if let Some(w) = self.writing.take() {
            let _ = w.join();
        }
    }

    /// The recovery file's path.
    pub fn text_path(&self) -> Option<PathBuf> {
        self.dir.as_ref().map(|d| d.join("recovery.rhai"))
    }

    fn meta_path(&self) -> Option<PathBuf> {
        self.dir.as_ref().map(|d| d.join("recovery.json"))
    }

    /// What an earlier session left behind.
    pub fn load(&self) -> Option<Recovered> {
        let text = std::fs::read_to_string(self.text_path()?).ok()?;
        let meta = self
            .meta_path()
            .and_then(|p| std::fs::read_to_string(p).ok())
            .and_then(|s| serde_json::from_str(&s).ok())
            .unwrap_or_default();
        Some(Recovered { text, meta })
    }

    /// Called each frame: write the text when dirty, changed, and the
    /// interval has passed. Returns true when a write was started.
    pub fn tick(
        &mut self,
        ctx: &egui::Context,
        text: &str,
        dirty: bool,
        path: Option<&Path>,
    ) -> bool {
        let (Some(tp), Some(mp)) = (self.text_path(), self.meta_path()) else {
            return false;
        };
        if !dirty {
            // Back to the saved text (undo, or a save elsewhere): the
            // recovery file this run wrote no longer holds unsaved work. A
            // file left by an earlier run stays until the user answers.
            if self.last_text.is_some() {
                self.clear();
            }
            return false;
        }
        if self.last_text.as_deref() == Some(text) {
            return false;
        }
        if let Some(t) = self.last_write {
            let left = self.interval.saturating_sub(t.elapsed());
            if !left.is_zero() {
                ctx.request_repaint_after(left);
                return false;
            }
        }
        self.last_write = Some(Instant::now());
        self.last_text = Some(text.to_owned());
        let saved_at = SystemTime::now()
            .duration_since(SystemTime::UNIX_EPOCH)
            .map_or(0, |d| d.as_secs());
        let meta = RecoveryMeta {
            path: path.map(Path::to_owned),
            saved_at,
        };
        let text = text.to_owned();
        let dir = self.dir.clone();
        self.wait();
        self.writing = std::thread::Builder::new()
            .name("volcad-autosave".into())
            .spawn(move || {
                let result = dir
                    .as_deref()
                    .map_or(Ok(()), std::fs::create_dir_all)
                    .and_then(|_| write_atomically(&tp, text.as_bytes()))
                    .and_then(|_| {
                        write_atomically(
                            &mp,
                            serde_json::to_string(&meta).unwrap_or_default().as_bytes(),
                        )
                    });
                if let Err(e) = result {
                    eprintln!("volcad-studio: autosave to {} failed: {e}", tp.display());
                }
            })
            .ok();
        true
    }

    /// Remove the recovery files (after save, or when the user discards).
    pub fn clear(&mut self) {
        self.wait();
        self.last_text = None;
        for p in [self.text_path(), self.meta_path()].into_iter().flatten() {
            let _ = std::fs::remove_file(p);
        }
    }
}

impl Drop for Recovery {
    fn drop(&mut self) {
        self.wait();
    }
}

/// The default data folder: `$XDG_DATA_HOME/volcad` (or `~/.local/share/volcad`).
pub fn default_data_dir() -> Option<PathBuf> {
    std::env::var_os("XDG_DATA_HOME")
        .filter(|v| !v.is_empty())
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".local/share")))
        .map(|d| d.join("volcad"))
}

/// The user's documents folder (`$HOME/Documents` when it exists, else
/// `$HOME`), where an untitled design's exports go by default.
pub fn documents_dir() -> Option<PathBuf> {
    let home = PathBuf::from(std::env::var_os("HOME").filter(|h| !h.is_empty())?);
    let docs = home.join("Documents");
    Some(if docs.is_dir() { docs } else { home })
}

/// Open a folder in the desktop's file manager (`xdg-open`), without waiting.
pub fn open_folder(path: &Path) -> Result<(), String> {
    let program = if cfg!(target_os = "macos") {
        "open"
    } else if cfg!(windows) {
        "explorer"
    } else {
        "xdg-open"
    };
    let mut child = std::process::Command::new(program)
        .arg(path)
        .stdin(std::process::Stdio::null())
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .map_err(|e| format!("could not run {program}: {e}"))?;
    // Reap it off the UI thread so it leaves no zombie.
    std::thread::spawn(move || child.wait());
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recovery_round_trip() {
        let scratch = tempfile::tempdir().unwrap();
        let dir = scratch.path().join("recovery");
        let ctx = egui::Context::default();
        let mut r = Recovery::new(Some(dir.clone()), Duration::ZERO);
        assert!(r.load().is_none());
        assert!(!r.tick(&ctx, "x", false, None), "clean text is not saved");
        assert!(r.tick(&ctx, "unsaved", true, Some(Path::new("/a/b.rhai"))));
        assert!(
            !r.tick(&ctx, "unsaved", true, None),
            "same text is not saved twice"
        );
        let t = Instant::now();
        let got = loop {
            if let Some(g) = r.load().filter(|g| g.meta.path.is_some()) {
                break g;
            }
            assert!(t.elapsed() < Duration::from_secs(5));
            std::thread::sleep(Duration::from_millis(10));
        };
        assert_eq!(got.text, "unsaved");
        assert_eq!(got.meta.path.as_deref(), Some(Path::new("/a/b.rhai")));
        r.clear();
        assert!(r.load().is_none());
    }

    #[test]
    fn clear_waits_for_the_write_in_flight() {
        // Saving right after an autosave started: the write must not bring
        // the recovery file back once it is cleared (without the wait this
        // fails in the first rounds).
        let scratch = tempfile::tempdir().unwrap();
        let ctx = egui::Context::default();
        for i in 0..20 {
            let mut r = Recovery::new(Some(scratch.path().join(format!("r{i}"))), Duration::ZERO);
            assert!(r.tick(&ctx, "unsaved", true, None));
            r.clear();
            std::thread::sleep(Duration::from_millis(5));
            assert!(r.load().is_none(), "round {i}");
        }
    }

    #[test]
    fn save_as_makes_a_clean_document() {
        let scratch = tempfile::tempdir().unwrap();
        let dir = scratch.path();
        let mut d = Document::untitled("untitled.rhai", "", None);
        assert!(d.is_dirty("abc"));
        let p = dir.join("part.rhai");
        d.save_as(&p, "abc").unwrap();
        assert!(!d.is_dirty("abc"));
        assert_eq!(d.name(), "part.rhai");
        assert_eq!(read_script(&p).unwrap(), "abc");
        assert_eq!(d.base_dir.as_deref(), Some(dir));
    }
}
