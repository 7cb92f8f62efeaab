//! The regression corpus: every case that ever failed, one JSON file each
//! in `tests/fuzz-corpus/`, replayed by `cargo test` (tests/tests/fuzz.rs).
//! Files are stored as text where they are UTF-8 (readable in a review),
//! else as hex.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::{Case, Expect, Verdict};

/// One input file as stored.
#[derive(Debug, Serialize, Deserialize)]
struct StoredFile {
    name: String,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    text: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    hex: Option<String>,
}

/// A corpus entry: the case, what it did when found, and, while the fault
/// is not fixed, which issue owns it.
#[derive(Debug, Serialize, Deserialize)]
pub struct Entry {
    /// Generator and number it was found as.
    pub name: String,
    /// The command line after `volcad`.
    pub args: Vec<String>,
    files: Vec<StoredFile>,
    /// What a clean run does.
    pub expect: Expect,
    /// What it did when found.
    pub found: Verdict,
    /// The issue that owns a fault not fixed yet; the replay reports it
    /// instead of failing.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub open: Option<String>,
}

/// The corpus folder of this repository.
pub fn folder() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz-corpus")
}

impl Entry {
    /// The entry of `case`, found as `found`.
    pub fn new(case: &Case, found: Verdict) -> Self {
        let files = case
            .files
            .iter()
            .map(|(name, bytes)| match std::str::from_utf8(bytes) {
                Ok(t) => StoredFile {
                    name: name.clone(),
                    text: Some(t.to_owned()),
                    hex: None,
                },
                Err(_) => StoredFile {
                    name: name.clone(),
                    text: None,
                    hex: Some(bytes.iter().map(|b| format!("{b:02x}")).collect()),
                },
            })
            .collect();
        Entry {
            name: case.name.clone(),
            args: case.args.clone(),
            files,
            expect: case.expect,
            found,
            open: case.open.clone(),
        }
    }

    /// The case to run.
    pub fn case(&self) -> Result<Case, String> {
        let mut files = Vec::new();
        for f in &self.files {
            let bytes = match (&f.text, &f.hex) {
                (Some(t), _) => t.as_bytes().to_vec(),
                (None, Some(h)) => unhex(h).ok_or_else(|| format!("{}: bad hex", f.name))?,
                (None, None) => Vec::new(),
            };
            files.push((f.name.clone(), bytes));
        }
        Ok(Case {
            name: self.name.clone(),
            args: self.args.clone(),
            files,
            expect: self.expect,
            open: self.open.clone(),
        })
    }
}

fn unhex(h: &str) -> Option<Vec<u8>> {
    (0..h.len())
        .step_by(2)
        .map(|i| h.get(i..i + 2).and_then(|b| u8::from_str_radix(b, 16).ok()))
        .collect()
}

/// Every entry of `dir`, by file name.
pub fn load(dir: &Path) -> Result<Vec<(String, Entry)>, String> {
    let mut out = Vec::new();
    let rd = std::fs::read_dir(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    for e in rd.flatten() {
        let p = e.path();
        if p.extension().is_some_and(|x| x == "json") {
            let text = std::fs::read_to_string(&p).map_err(|e| format!("{}: {e}", p.display()))?;
            let entry: Entry =
                serde_json::from_str(&text).map_err(|e| format!("{}: {e}", p.display()))?;
            out.push((e.file_name().to_string_lossy().to_string(), entry));
        }
    }
    out.sort_by(|a, b| a.0.cmp(&b.0));
    Ok(out)
}

/// Save `entry` in `dir` as `<name>.json` (an existing one is kept).
pub fn save(dir: &Path, entry: &Entry) -> std::io::Result<PathBuf> {
    std::fs::create_dir_all(dir)?;
    let p = dir.join(format!("{}.json", entry.name));
    if !p.exists() {
        let text = serde_json::to_string_pretty(entry).map_err(std::io::Error::other)?;
        std::fs::write(&p, text + "\n")?;
    }
    Ok(p)
}
