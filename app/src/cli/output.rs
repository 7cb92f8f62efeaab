//! Where the single-file commands (`sample`, `render`, `fea-result`) write,
//! and how they read their input files.
//!
//! A regular file is written to a hidden staging file beside it and renamed
//! into place only when complete, so a failed or interrupted command never
//! leaves a file that looks finished. Character devices (`/dev/null`, a
//! terminal) and pipes cannot be replaced by a rename, and must not be: the
//! output is written to them directly. `-` is standard output. A symlink is
//! judged by what it points to (a symlink to a regular file has its target
//! replaced, the link stays). Anything else (a folder, a socket, a block
//! device) is refused before any work.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
pub use volcad_core::script::clip;

/// How one output path is written.
#[derive(Debug, PartialEq, Eq)]
pub enum Target {
    /// Standard output (`--out -`).
    Stdout,
    /// A character device or a pipe: opened and written in place.
    Direct(PathBuf),
    /// A regular file (or none yet): staged beside it, then renamed.
    Staged(PathBuf),
}

/// The kind of a special file, in words.
#[cfg(unix)]
fn special_kind(t: std::fs::FileType) -> Option<&'static str> {
    use std::os::unix::fs::FileTypeExt;
    if t.is_socket() {
        Some("a socket")
    } else if t.is_block_device() {
        Some("a block device")
    } else {
        None
    }
}

#[cfg(not(unix))]
fn special_kind(_t: std::fs::FileType) -> Option<&'static str> {
    None
}

/// True for a character device or a FIFO: written in place, never renamed over.
#[cfg(unix)]
fn is_stream(t: std::fs::FileType) -> bool {
    use std::os::unix::fs::FileTypeExt;
    t.is_char_device() || t.is_fifo()
}

#[cfg(not(unix))]
fn is_stream(_t: std::fs::FileType) -> bool {
    false
}

/// Decide how `out` (the value of `option`) is written; refuses folders
/// and special files before any work is done.
pub fn target(out: &Path, option: &str) -> anyhow::Result<Target> {
    if out.as_os_str() == "-" {
        return Ok(Target::Stdout);
    }
    let shown = out.display();
    let link = match std::fs::symlink_metadata(out) {
        Ok(m) => m,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            return Ok(Target::Staged(out.to_owned()));
        }
        Err(e) => bail!("{option} {shown}: {e}"),
    };
    let is_link = link.file_type().is_symlink();
    let meta = if is_link {
        std::fs::metadata(out).with_context(|| {
            format!(
                "{option} {shown}: a symlink whose target cannot be opened; remove it or give another name"
            )
        })?
    } else {
        link
    };
    let t = meta.file_type();
    if is_stream(t) {
        return Ok(Target::Direct(out.to_owned()));
    }
    if t.is_dir() {
        bail!(
            "{option} {shown}: is a folder; give a file name in it (for example {shown}/out.csv)"
        );
    }
    if let Some(kind) = special_kind(t) {
        bail!(
            "{option} {shown}: is {kind}; volcad writes regular files, character devices \
             (such as /dev/null), pipes, or standard output (`-`)"
        );
    }
    // A symlink to a regular file: replace the target, keep the link.
    let dest = if is_link {
        out.canonicalize()
            .with_context(|| format!("{option} {shown}: cannot resolve the symlink"))?
    } else {
        out.to_owned()
    };
    Ok(Target::Staged(dest))
}

/// The hidden staging file beside `dest`.
fn staging_path(dest: &Path) -> PathBuf {
    let name = dest
        .file_name()
        .map_or_else(|| "out".into(), |n| n.to_string_lossy().to_string());
    dest.with_file_name(format!(".{name}.partial-{}", std::process::id()))
}

/// Write `out` through `write` (see the module doc for where it goes). On
/// failure nothing is left that looks finished, and the message names
/// `out`, never the staging file.
pub fn write_output(
    out: &Path,
    option: &str,
    write: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> anyhow::Result<()> {
    let cannot = || format!("cannot write {}", out.display());
    match target(out, option)? {
        Target::Stdout => {
            let mut w = BufWriter::new(std::io::stdout().lock());
            write(&mut w)
                .and_then(|()| w.flush())
                .context("cannot write to standard output")
        }
        Target::Direct(path) => {
            let mut w = BufWriter::new(
                std::fs::OpenOptions::new()
                    .write(true)
                    .open(&path)
                    .with_context(cannot)?,
            );
            write(&mut w).and_then(|()| w.flush()).with_context(cannot)
        }
        Target::Staged(dest) => {
            let staging = staging_path(&dest);
            let staged = || -> std::io::Result<()> {
                let mut w = BufWriter::new(File::create(&staging)?);
                write(&mut w)?;
                w.into_inner().map_err(|e| e.into_error())?.sync_all()?;
                std::fs::rename(&staging, &dest)
            };
            let r = staged();
            if r.is_err() {
                let _ = std::fs::remove_file(&staging);
            }
            r.with_context(cannot)
        }
    }
}

/// The byte-order mark some editors put at the start of UTF-8 files.
const BOM: char = '\u{feff}';

/// Read a text input file: it must be a regular file (a FIFO would block
/// for ever, a device never ends); a UTF-8 byte-order mark is dropped.
pub fn read_input(path: &Path, what: &str) -> anyhow::Result<String> {
    check_regular(path, what)?;
    let text =
        std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))?;
    Ok(match text.strip_prefix(BOM) {
        Some(rest) => rest.to_owned(),
        None => text,
    })
}

/// Refuse an input that is not a regular file, naming what it is.
pub fn check_regular(path: &Path, what: &str) -> anyhow::Result<()> {
    let meta =
        std::fs::metadata(path).with_context(|| format!("cannot read {}", path.display()))?;
    if meta.is_file() {
        return Ok(());
    }
    let kind = if meta.is_dir() {
        "a folder"
    } else if is_stream(meta.file_type()) {
        "a pipe or device"
    } else {
        special_kind(meta.file_type()).unwrap_or("not a regular file")
    };
    bail!(
        "{}: is {kind}; give the {what} as a regular file",
        path.display()
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_failed_write_leaves_no_staging_file_and_names_the_destination() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("out.csv");
        let e = write_output(&out, "--out", |w| {
            w.write_all(b"x,y,z\n")?;
            Err(std::io::Error::other("disk full"))
        })
        .unwrap_err();
        let msg = format!("{e:#}");
        assert!(msg.contains("out.csv: disk full"), "{msg}");
        assert!(!msg.contains("partial"), "{msg}");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
    }

    #[cfg(unix)]
    #[test]
    fn devices_and_fifos_are_written_in_place_and_symlinks_kept() {
        let dir = tempfile::tempdir().unwrap();
        let null = dir.path().join("null");
        std::os::unix::fs::symlink("/dev/null", &null).unwrap();
        assert_eq!(
            target(&null, "--out").unwrap(),
            Target::Direct(null.clone())
        );
        write_output(&null, "--out", |w| w.write_all(b"abc")).unwrap();
        assert!(
            std::fs::symlink_metadata(&null)
                .unwrap()
                .file_type()
                .is_symlink()
        );
        // A symlink to a regular file: the target gets the text, the link stays.
        let real = dir.path().join("real.csv");
        std::fs::write(&real, "old").unwrap();
        let link = dir.path().join("link.csv");
        std::os::unix::fs::symlink(&real, &link).unwrap();
        write_output(&link, "--out", |w| w.write_all(b"new")).unwrap();
        assert!(
            std::fs::symlink_metadata(&link)
                .unwrap()
                .file_type()
                .is_symlink()
        );
        assert_eq!(std::fs::read_to_string(&real).unwrap(), "new");
        assert_eq!(target(Path::new("-"), "--out").unwrap(), Target::Stdout);
        let e = target(dir.path(), "--out").unwrap_err().to_string();
        assert!(e.contains("is a folder"), "{e}");
    }

    #[test]
    fn clip_keeps_short_text_and_counts_what_it_drops() {
        assert_eq!(clip("abc", 5), "abc");
        assert_eq!(clip("abcdef", 3), "abc… (3 more characters)");
        assert_eq!(clip("ééé", 1), "é… (2 more characters)");
    }

    #[test]
    fn inputs_drop_a_bom_and_refuse_folders() {
        let dir = tempfile::tempdir().unwrap();
        let f = dir.path().join("a.csv");
        std::fs::write(&f, "\u{feff}x,y,z\n").unwrap();
        assert_eq!(read_input(&f, "points").unwrap(), "x,y,z\n");
        let e = read_input(dir.path(), "points").unwrap_err().to_string();
        assert!(
            e.contains("is a folder; give the points as a regular file"),
            "{e}"
        );
    }
}
