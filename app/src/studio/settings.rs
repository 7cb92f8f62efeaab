//! What the studio remembers between runs: recent files, the last file, the
//! theme and the editor font size (panel sizes persist through egui's own
//! memory). Stored as one JSON value in eframe's storage.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

/// Storage key for [`Settings`].
pub const STORAGE_KEY: &str = "volcad-studio-settings";

/// How many recent files the File menu lists.
pub const MAX_RECENT: usize = 10;

/// The theme the user picked.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum Theme {
    /// Follow the system.
    #[default]
    System,
    /// Always dark.
    Dark,
    /// Always light.
    Light,
}

/// Persisted studio state.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Settings {
    /// Most recent first.
    pub recent_files: Vec<PathBuf>,
    /// The file open when the studio last closed.
    pub last_file: Option<PathBuf>,
    /// Colour theme.
    pub theme: Theme,
    /// Editor font size in points.
    pub editor_font_size: f32,
    /// Panels shown.
    pub show_editor: bool,
    /// Right panel (export, legend) shown.
    pub show_side: bool,
    /// Bottom panel (problems, log) shown.
    pub show_bottom: bool,
    /// Export folders typed or picked, per design and kind (see
    /// `export_panel::Place`).
    pub export_dirs: BTreeMap<String, PathBuf>,
    /// Folders scripts may read besides their project (the command line's
    /// `--allow-read DIR`).
    pub read_folders: Vec<PathBuf>,
}

impl Default for Settings {
    fn default() -> Self {
        Self {
            recent_files: Vec::new(),
            last_file: None,
            theme: Theme::System,
            editor_font_size: 14.0,
            show_editor: true,
            show_side: true,
            show_bottom: true,
            export_dirs: BTreeMap::new(),
            read_folders: Vec::new(),
        }
    }
}

impl Settings {
    /// Read from eframe's storage (defaults when absent or unreadable).
    pub fn load(storage: Option<&dyn eframe::Storage>) -> Self {
        storage
            .and_then(|s| eframe::get_value::<Settings>(s, STORAGE_KEY))
            .unwrap_or_default()
    }

    /// Write into eframe's storage.
    pub fn store(&self, storage: &mut dyn eframe::Storage) {
        eframe::set_value(storage, STORAGE_KEY, self);
    }

    /// Put `path` first in the recent list.
    pub fn add_recent(&mut self, path: &Path) {
        self.recent_files.retain(|p| p != path);
        self.recent_files.insert(0, path.to_owned());
        self.recent_files.truncate(MAX_RECENT);
    }

    /// Clamp the font size into a readable range.
    pub fn zoom(&mut self, delta: f32) {
        self.editor_font_size = (self.editor_font_size + delta).clamp(8.0, 40.0);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recent_files_are_unique_and_bounded() {
        let mut s = Settings::default();
        for i in 0..15 {
            s.add_recent(Path::new(&format!("/tmp/{i}.rhai")));
        }
        s.add_recent(Path::new("/tmp/3.rhai"));
        assert_eq!(s.recent_files.len(), MAX_RECENT);
        assert_eq!(s.recent_files[0], Path::new("/tmp/3.rhai"));
        assert_eq!(
            s.recent_files
                .iter()
                .filter(|p| p.ends_with("3.rhai"))
                .count(),
            1
        );
    }

    #[test]
    fn round_trips_through_json() {
        let mut s = Settings {
            theme: Theme::Light,
            editor_font_size: 18.0,
            ..Settings::default()
        };
        s.add_recent(Path::new("/a/b.rhai"));
        let text = serde_json::to_string(&s).unwrap();
        assert_eq!(serde_json::from_str::<Settings>(&text).unwrap(), s);
        // Older or partial values fill in defaults.
        let partial: Settings = serde_json::from_str(r#"{"theme":"Dark"}"#).unwrap();
        assert_eq!(partial.theme, Theme::Dark);
        assert_eq!(partial.editor_font_size, 14.0);
    }
}
