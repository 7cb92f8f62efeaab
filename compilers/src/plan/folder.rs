//! What an output folder holds before an export replaces it: nothing, a
//! finished export of ours (it has our `manifest.json`), or other files.
//! A finished export is replaced only when the user agrees; a folder of
//! other files never is (the job refuses it too, see [`crate::job`]).

use std::path::Path;
use std::time::SystemTime;

use super::{Opt, Severity, Verdict};
use crate::job::ExportError;
use crate::resources::human_bytes;

/// A finished export found in a folder, from its manifest.
#[derive(Clone, Debug, PartialEq)]
pub struct FinishedExport {
    /// Export kind ("png", "mesh", "fea").
    pub kind: String,
    /// The design's name, when the manifest records it.
    pub design: Option<String>,
    /// When the manifest was written.
    pub written: Option<SystemTime>,
    /// Files in the folder (all levels).
    pub files: usize,
    /// Their total size in bytes.
    pub bytes: u64,
}

impl FinishedExport {
    /// "a png export of bar.rhai (20 files, 1.2 MiB, written 2026-12-05
    /// 18:40 UTC)".
    pub fn describe(&self) -> String {
        let of = self
            .design
            .as_ref()
            .map_or_else(String::new, |d| format!(" of {d}"));
        let when = self
            .written
            .map_or_else(String::new, |t| format!(", written {}", utc_text(t)));
        format!(
            "a {} export{of} ({} file{}, {}{when})",
            self.kind,
            self.files,
            if self.files == 1 { "" } else { "s" },
            human_bytes(self.bytes)
        )
    }
}

/// What a destination holds.
#[derive(Clone, Debug, PartialEq)]
pub enum Folder {
    /// Nothing there yet, or an empty folder.
    Free,
    /// A finished export of ours.
    Export(FinishedExport),
    /// A folder of other files: a few of their names (sorted) and how
    /// many entries there are in all.
    Other(Vec<String>, usize),
    /// A file or something else that is not a folder.
    NotAFolder,
}

/// How many names a refusal lists.
const NAMES_SHOWN: usize = 3;

/// Look at `dest` (a symlink to a folder counts as that folder).
pub fn inspect(dest: &Path) -> Folder {
    let Ok(meta) = std::fs::metadata(dest) else {
        // Nothing there, or a dangling link: the job says which.
        return if std::fs::symlink_metadata(dest).is_ok() {
            Folder::NotAFolder
        } else {
            Folder::Free
        };
    };
    if !meta.is_dir() {
        return Folder::NotAFolder;
    }
    let manifest = dest.join("manifest.json");
    if manifest.is_file() {
        let json: serde_json::Value = std::fs::read_to_string(&manifest)
            .ok()
            .and_then(|t| serde_json::from_str(&t).ok())
            .unwrap_or_default();
        let text = |k: &str| json.get(k).and_then(|v| v.as_str()).map(str::to_owned);
        let (files, bytes) = tally(dest);
        return Folder::Export(FinishedExport {
            kind: text("kind").unwrap_or_else(|| "unknown".into()),
            design: text("design"),
            written: std::fs::metadata(&manifest).and_then(|m| m.modified()).ok(),
            files,
            bytes,
        });
    }
    let mut names: Vec<String> = std::fs::read_dir(dest)
        .map(|d| {
            d.flatten()
                .map(|e| e.file_name().to_string_lossy().into_owned())
                .collect()
        })
        .unwrap_or_default();
    if names.is_empty() {
        return Folder::Free;
    }
    names.sort();
    let total = names.len();
    names.truncate(NAMES_SHOWN);
    Folder::Other(names, total)
}

/// Files under `dir` (all levels, links not followed) and their bytes.
fn tally(dir: &Path) -> (usize, u64) {
    let mut files = 0;
    let mut bytes = 0;
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).into_iter().flatten().flatten() {
            match e.file_type() {
                Ok(t) if t.is_dir() => stack.push(e.path()),
                Ok(_) => {
                    files += 1;
                    bytes += e.metadata().map_or(0, |m| m.len());
                }
                Err(_) => {}
            }
        }
    }
    (files, bytes)
}

/// The verdict on exporting into `dest`: none when it is free, a question
/// before replacing a finished export, a refusal for anything else.
pub fn verdict(dest: &Path) -> Option<Verdict> {
    let d = dest.display();
    let (severity, message) = match inspect(dest) {
        Folder::Free => return None,
        Folder::Export(e) => (
            Severity::Ask,
            format!(
                "--out {d}: holds a finished export, {}; add --force to replace it, or choose another folder",
                e.describe()
            ),
        ),
        Folder::Other(names, total) => {
            let more = total - names.len();
            let more = if more > 0 {
                format!(" and {more} more")
            } else {
                String::new()
            };
            (
                Severity::Refuse,
                format!(
                    "--out {d}: holds other files ({}{more}) and no export manifest; an export replaces its whole folder, so choose a new or empty folder",
                    names.join(", ")
                ),
            )
        }
        // A device, pipe or dangling link: the job refuses it, in its own
        // words, before it writes anything.
        Folder::NotAFolder if !dest.is_file() => return None,
        Folder::NotAFolder => {
            return Some(Verdict::refuse(&ExportError::DestinationExists(
                dest.to_owned(),
            )));
        }
    };
    Some(Verdict {
        severity,
        option: Opt::Out,
        message,
    })
}

/// `t` as "YYYY-MM-DD HH:MM UTC" (days to civil date after Howard
/// Hinnant's `civil_from_days`, valid for the proleptic Gregorian
/// calendar).
fn utc_text(t: SystemTime) -> String {
    let secs = t
        .duration_since(SystemTime::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs()) as i64;
    let (days, rem) = (secs.div_euclid(86_400), secs.rem_euclid(86_400));
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = doy - (153 * mp + 2) / 5 + 1;
    let month = if mp < 10 { mp + 3 } else { mp - 9 };
    let year = yoe + era * 400 + i64::from(month <= 2);
    format!(
        "{year:04}-{month:02}-{day:02} {:02}:{:02} UTC",
        rem / 3600,
        rem % 3600 / 60
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Duration;

    #[test]
    fn dates_are_civil_utc() {
        let at = |s: u64| utc_text(SystemTime::UNIX_EPOCH + Duration::from_secs(s));
        assert_eq!(at(0), "1970-01-01 00:00 UTC");
        // 2000-02-29 12:34 UTC (a leap day in a century leap year).
        assert_eq!(at(951_827_640), "2000-02-29 12:34 UTC");
        assert_eq!(at(1_796_470_800), "2026-12-05 11:40 UTC");
    }

    #[test]
    fn folders_are_told_apart_and_named() {
        let scratch = tempfile::tempdir().unwrap();
        let dir = scratch.path();
        let dest = dir.join("bar_png");
        assert_eq!(inspect(&dest), Folder::Free);
        assert!(verdict(&dest).is_none());
        std::fs::create_dir(&dest).unwrap();
        assert_eq!(inspect(&dest), Folder::Free, "an empty folder");
        for n in ["d.txt", "a.txt", "c.png", "b.stl"] {
            std::fs::write(dest.join(n), "x").unwrap();
        }
        let v = verdict(&dest).unwrap();
        assert_eq!((v.severity, v.option), (Severity::Refuse, Opt::Out));
        assert!(
            v.message
                .contains("holds other files (a.txt, b.stl, c.png and 1 more)"),
            "{}",
            v.message
        );
        std::fs::write(
            dest.join("manifest.json"),
            r#"{"tool": "volcad", "kind": "png", "design": "bar.rhai"}"#,
        )
        .unwrap();
        let Folder::Export(e) = inspect(&dest) else {
            panic!("an export")
        };
        assert_eq!((e.files, e.kind.as_str()), (5, "png"));
        let text = e.describe();
        assert!(
            text.starts_with("a png export of bar.rhai (5 files, ") && text.contains("written 20"),
            "{text}"
        );
        let v = verdict(&dest).unwrap();
        assert_eq!(v.severity, Severity::Ask);
        assert!(
            v.message.contains("add --force to replace it"),
            "{}",
            v.message
        );
        let file = dir.join("plain.txt");
        std::fs::write(&file, "x").unwrap();
        assert_eq!(verdict(&file).unwrap().severity, Severity::Refuse);
    }
}
