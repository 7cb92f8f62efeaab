//! Memory and disk checks made before an export starts, so that a job that
//! cannot fit is refused with the numbers instead of failing half-way.
//!
//! Both probes are best effort: `None` means "unknown" and the check is then
//! skipped (a full disk is still caught when a write fails, and the job
//! runner removes the partial output).

use std::path::Path;

use crate::job::ExportError;

pub use volcad_core::heap::{available_memory, human_bytes};

/// Free bytes on the file system holding `dir` (or its nearest existing
/// ancestor, since an export's folder may not exist yet): the space an
/// unprivileged user may take, `f_bavail · f_frsize` from POSIX
/// `statvfs` (what `df -P` calls "Available"), or `None` when unknown.
///
/// A system call through rustix (already a dependency, safe code), not
/// `df`: spawning a process costs more than a small export, and a mesh
/// export asks twice.
#[cfg(unix)]
pub fn available_disk(dir: &Path) -> Option<u64> {
    // A relative path's last ancestor is "", the current folder.
    let existing = dir
        .ancestors()
        .map(|a| {
            if a.as_os_str().is_empty() {
                Path::new(".")
            } else {
                a
            }
        })
        .find(|a| a.exists())?;
    let s = rustix::fs::statvfs(existing).ok()?;
    s.f_bavail.checked_mul(s.f_frsize)
}

/// Unknown off Unix: the disk check is skipped, and a full disk is caught
/// when a write fails (see the module docs).
#[cfg(not(unix))]
pub fn available_disk(_dir: &Path) -> Option<u64> {
    None
}

/// Run `f` on a worker of a pool of `threads` workers (`None`: the current
/// pool, all cores by default). Output never depends on the count; only
/// speed does.
///
/// On a worker, not the calling thread: `f`'s own serial stretches then
/// leave the other workers the cores (called from outside, a third thread
/// ran beside two workers that were still spinning for work), and its
/// joins are a worker's, not injected into the pool and waited for each
/// time. (`rayon::scope` called from outside the pool runs its closure on
/// a worker and blocks until it returns; from a worker, in place.)
pub fn run_with_threads<T: Send>(
    threads: Option<usize>,
    f: impl FnOnce() -> Result<T, ExportError> + Send,
) -> Result<T, ExportError> {
    match threads {
        None => rayon::scope(|_| f()),
        Some(n) => {
            check_threads(n)?;
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(n)
                .build()
                .map_err(|e| ExportError::Other(format!("starting {n} worker threads: {e}")))?;
            pool.install(f)
        }
    }
}

/// A worker thread count an export may use: 1 to [`max_threads`].
pub fn check_threads(n: usize) -> Result<(), ExportError> {
    if n == 0 {
        return Err(ExportError::param("--threads", "must be at least 1"));
    }
    if n > max_threads() {
        return Err(ExportError::param(
            "--threads",
            format!(
                "{n} threads; at most {} here ({} cores: more threads than cores do not run faster, and each costs memory)",
                max_threads(),
                cores()
            ),
        ));
    }
    Ok(())
}

/// Cores of this machine (1 when unknown).
fn cores() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
}

/// Most worker threads an export may ask for: eight per core, and at least
/// 64 (tests ask for a few more threads than a small machine has cores).
pub fn max_threads() -> usize {
    (8 * cores()).max(64)
}

/// Refuse when `needed` bytes of working memory exceed what is available
/// (with 20% head room for the rest of the program). `what` says what the
/// memory is for; the error names `--voxel`, the parameter that fixes it.
pub fn check_memory(needed: u64, what: &str) -> Result<(), ExportError> {
    if let Some(avail) = available_memory() {
        let usable = avail / 5 * 4;
        if needed > usable {
            return Err(ExportError::param(
                "--voxel",
                format!(
                    "{what} needs {} of memory but only {} is available ({} free); use a larger voxel size",
                    human_bytes(needed),
                    human_bytes(usable),
                    human_bytes(avail)
                ),
            ));
        }
    }
    Ok(())
}

/// Stops an export whose memory outgrows what was available when it
/// started, with an error, before the kernel's out-of-memory killer stops
/// the whole process (which leaves the staging folder behind and, in the
/// studio, loses the session). The estimates behind [`check_memory`] can
/// miss: the size estimate does not see parts or interfaces much thinner than
/// its cells. Reads the heap that [`volcad_core::heap::CountingAllocator`]
/// counts; without it (a library user's program) there is no guard.
pub struct MemoryGuard {
    base: usize,
    limit: u64,
}

impl MemoryGuard {
    /// A guard allowing the heap to grow by four fifths of the memory
    /// available now, or `None` when either is unknown.
    pub fn for_export() -> Option<MemoryGuard> {
        MemoryGuard::with_limit(available_memory()? / 5 * 4)
    }

    /// A guard allowing the heap to grow by `limit` bytes from now, or
    /// `None` without a counting allocator.
    pub fn with_limit(limit: u64) -> Option<MemoryGuard> {
        Some(MemoryGuard {
            base: volcad_core::heap::live_bytes()?,
            limit,
        })
    }

    /// An error naming `--voxel` once the heap has grown past the limit;
    /// `what` says how far the export got (asked only then).
    pub fn check(&self, what: impl FnOnce() -> String) -> Result<(), ExportError> {
        let grown = volcad_core::heap::live_bytes().map_or(0, |l| l.saturating_sub(self.base));
        if grown as u64 > self.limit {
            return Err(ExportError::param(
                "--voxel",
                format!(
                    "stopped {}: the export holds {} of memory, more than the {} that was available when it started (the estimate was too low for this design); use a larger voxel size",
                    what(),
                    human_bytes(grown as u64),
                    human_bytes(self.limit)
                ),
            ));
        }
        Ok(())
    }
}

/// Refuse when about `needed` bytes of output will not fit on the disk that
/// holds `dir`. The error names `--out`, and `coarser` (what makes the
/// output smaller: "a larger voxel size").
pub fn check_disk(needed: u64, dir: &Path, coarser: &str) -> Result<(), ExportError> {
    if let Some(free) = available_disk(dir)
        && needed > free
    {
        return Err(ExportError::param(
            "--out",
            format!(
                "the output needs about {} but only {} is free on the disk of {}; free space, choose another folder or use {coarser}",
                human_bytes(needed),
                human_bytes(free),
                dir.display()
            ),
        ));
    }
    Ok(())
}

/// [`check_disk`] for an export into `dest` (which need not exist yet): the
/// disk of the folder it is made in. The CLI and the studio check with the
/// estimates they show (which sample layers at the voxel size) before they
/// start a job, whose own up-front check goes by coarser rules.
pub fn check_disk_for(needed: u64, dest: &Path, coarser: &str) -> Result<(), ExportError> {
    let folder = dest
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    check_disk(needed, folder, coarser)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn human_bytes_rounds() {
        assert_eq!(human_bytes(300), "300 B");
        assert_eq!(human_bytes(1536), "1.5 KiB");
        assert_eq!(human_bytes(50 << 20), "50 MiB");
    }

    /// `df -Pk`'s "Available" column for `dir`, in bytes.
    fn df_available(dir: &Path) -> Option<u64> {
        let out = std::process::Command::new("df")
            .arg("-Pk")
            .arg(dir)
            .output()
            .ok()?;
        let text = String::from_utf8(out.stdout).ok()?;
        let kib: u64 = text
            .lines()
            .nth(1)?
            .split_whitespace()
            .nth(3)?
            .parse()
            .ok()?;
        Some(kib * 1024)
    }

    #[test]
    fn free_disk_agrees_with_df_and_looks_past_missing_folders() {
        if !cfg!(unix) {
            return;
        }
        let dir = std::env::temp_dir();
        let ours = available_disk(&dir).expect("statvfs of the temporary folder");
        // Other processes write meanwhile: agree within 64 MiB.
        if let Some(df) = df_available(&dir) {
            assert!(ours.abs_diff(df) < 64 << 20, "statvfs {ours}, df {df}");
        }
        let missing = dir.join("volcad-no-such-folder/a/b");
        assert!(!missing.exists());
        let below = available_disk(&missing).expect("the nearest existing folder's disk");
        assert!(below.abs_diff(ours) < 64 << 20, "{below} against {ours}");
        // A relative folder that does not exist: the current folder's disk.
        let here = available_disk(Path::new(".")).expect("the current folder's disk");
        let relative = available_disk(Path::new("volcad-no-such-folder/a"))
            .expect("a missing relative folder falls back to the current one");
        assert!(
            relative.abs_diff(here) < 64 << 20,
            "{relative} against {here}"
        );
    }

    #[test]
    fn probes_answer_on_linux() {
        if cfg!(target_os = "linux") {
            assert!(available_memory().is_some_and(|m| m > 0));
            assert!(available_disk(&std::env::temp_dir()).is_some_and(|d| d > 0));
        }
    }

    #[test]
    fn thread_counts_are_bounded() {
        let e = run_with_threads(Some(100_000), || Ok(()))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("--threads") && e.contains("100000 threads; at most"),
            "{e}"
        );
        assert!(run_with_threads(Some(max_threads()), || Ok(())).is_ok());
        assert!(run_with_threads(Some(0), || Ok(())).is_err());
    }

    #[test]
    fn huge_needs_are_refused_with_numbers() {
        let e = check_memory(u64::MAX / 2, "one layer")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("--voxel: one layer needs"), "{e}");
        let e = check_disk(u64::MAX / 2, &std::env::temp_dir(), "a larger voxel size")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("--out: the output needs about"), "{e}");
        // A destination not made yet is checked on its folder's disk.
        let tmp = std::env::temp_dir();
        let e = check_disk_for(u64::MAX / 2, &tmp.join("not-yet"), "a larger voxel size")
            .unwrap_err()
            .to_string();
        assert!(e.contains(&format!("disk of {}", tmp.display())), "{e}");
        assert!(check_disk_for(1, &tmp.join("not-yet"), "x").is_ok());
    }
}
