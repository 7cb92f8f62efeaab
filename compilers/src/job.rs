//! The job runner: every export runs as a job on a background thread,
//! reports progress through a channel, stops promptly on cancel, and writes
//! into a temporary folder beside the destination that is renamed into place
//! only when the job completes. A cancelled, failed or crashed job therefore
//! never leaves something that looks finished.
//!
//! Pipeline: `spawn(name, dest, work)` → thread → `work(&JobContext)` writes
//! files under `ctx.staging()` and calls `ctx.progress(..)` /
//! `ctx.check_cancel()?` → on `Ok(summary)` the manifest is written and the
//! staging folder renamed to `dest` → the handle's `join()` returns the summary.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{Receiver, SyncSender, TrySendError, sync_channel};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use serde::{Deserialize, Serialize};

/// One progress report.
#[derive(Clone, Debug, PartialEq)]
pub struct Progress {
    /// Stage name ("sampling", "writing PNG", "marching cubes", ...).
    pub stage: String,
    /// Fraction of the whole job done, 0..=1.
    pub fraction: f64,
    /// Units done (voxels, layers or elements, see `unit`).
    pub done: u64,
    /// Units in total.
    pub total: u64,
    /// What `done` counts.
    pub unit: &'static str,
    /// Time since the job started.
    pub elapsed: Duration,
    /// Estimated time left (from the rate so far).
    pub eta: Option<Duration>,
}

/// Why a job did not complete.
#[derive(Debug, thiserror::Error)]
pub enum ExportError {
    /// The user cancelled; nothing was left at the destination.
    #[error("cancelled; no output was written")]
    Cancelled,
    /// A parameter is wrong: which one and why.
    #[error("{param}: {message}")]
    BadParameter {
        /// Parameter name as the CLI spells it (`--voxel`, `--segments`).
        param: String,
        /// What is wrong and what is allowed.
        message: String,
    },
    /// Writing failed. The OS error is part of the message, not a chained
    /// source: printed with its chain, it appeared twice.
    #[error("{}: {err}", .path.display())]
    Io {
        /// The file or folder.
        path: PathBuf,
        /// The OS error.
        err: std::io::Error,
    },
    /// The destination exists and is not a folder we may replace.
    #[error("{0}: the destination exists and is not an export folder; choose another or remove it")]
    DestinationExists(PathBuf),
    /// The job panicked (a bug); nothing was left at the destination.
    #[error("internal error: {0}")]
    Panicked(String),
    /// Anything else, with context.
    #[error("{0}")]
    Other(String),
}

impl ExportError {
    /// An I/O error at `path`.
    pub fn io(path: &Path, err: std::io::Error) -> Self {
        ExportError::Io {
            path: path.to_owned(),
            err,
        }
    }

    /// A bad parameter.
    pub fn param(param: &str, message: impl Into<String>) -> Self {
        ExportError::BadParameter {
            param: param.to_owned(),
            message: message.into(),
        }
    }
}

/// What a finished job reports, and what goes into `manifest.json` (read
/// back by [`crate::shard`]'s merge).
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct Summary {
    /// Export kind ("png", "mesh", "fea").
    pub kind: String,
    /// Files written, relative to the output folder.
    pub files: Vec<String>,
    /// Count per material name (voxels or elements).
    pub counts: Vec<(String, u64)>,
    /// Units processed (voxels or elements) and what they are.
    pub units: u64,
    /// What `units` counts.
    pub unit: String,
    /// Parameters as given (for the manifest).
    pub parameters: serde_json::Value,
    /// Free-form lines for the user (quality figures, warnings).
    pub notes: Vec<String>,
    /// Wall time in seconds. Not written to the manifest, which records
    /// only what defines the output: two runs of the same export write
    /// the same bytes, manifest included.
    #[serde(skip)]
    pub seconds: f64,
}

/// What a job's work function sees.
pub struct JobContext {
    staging: PathBuf,
    cancel: Arc<AtomicBool>,
    tx: SyncSender<Progress>,
    start: Instant,
    /// The design's hash, for the manifest.
    pub design_hash: String,
    /// The design's name (its script's file name), for the manifest.
    pub design: Option<String>,
}

impl JobContext {
    /// The folder to write into (renamed to the destination on success).
    pub fn staging(&self) -> &Path {
        &self.staging
    }

    /// The folder that will hold the destination (the staging folder's
    /// parent): what messages about its disk name, since the staging
    /// folder's name means nothing to the user.
    pub fn folder(&self) -> &Path {
        self.staging.parent().unwrap_or(&self.staging)
    }

    /// Err(Cancelled) once cancel was asked for.
    pub fn check_cancel(&self) -> Result<(), ExportError> {
        if self.cancel.load(Ordering::Relaxed) {
            Err(ExportError::Cancelled)
        } else {
            Ok(())
        }
    }

    /// The cancel flag, for samplers.
    pub fn cancel_flag(&self) -> &AtomicBool {
        &self.cancel
    }

    /// Report progress (dropped if the receiver is behind: reports are
    /// snapshots, the next one supersedes).
    pub fn progress(&self, stage: &str, done: u64, total: u64, unit: &'static str, fraction: f64) {
        let elapsed = self.start.elapsed();
        let fraction = fraction.clamp(0.0, 1.0);
        let eta = (fraction > 0.01).then(|| elapsed.mul_f64((1.0 - fraction) / fraction));
        let p = Progress {
            stage: stage.to_owned(),
            fraction,
            done,
            total,
            unit,
            elapsed,
            eta,
        };
        match self.tx.try_send(p) {
            Ok(()) | Err(TrySendError::Full(_)) | Err(TrySendError::Disconnected(_)) => {}
        }
    }
}

/// A running job.
pub struct JobHandle {
    /// Progress reports (bounded; drain it each frame).
    pub progress: Receiver<Progress>,
    cancel: Arc<AtomicBool>,
    thread: Option<JoinHandle<Result<Summary, ExportError>>>,
    /// Why the worker thread could not be started (then `thread` is `None`
    /// and `join` returns this as the job's error).
    spawn_error: Option<String>,
    dest: PathBuf,
}

impl JobHandle {
    /// Ask the job to stop; `join` then returns `Cancelled`.
    pub fn cancel(&self) {
        self.cancel.store(true, Ordering::Relaxed);
    }

    /// True once the worker has finished (successfully or not).
    pub fn is_finished(&self) -> bool {
        self.thread.as_ref().is_none_or(|t| t.is_finished())
    }

    /// Where the output goes.
    pub fn destination(&self) -> &Path {
        &self.dest
    }

    /// Wait for the result.
    pub fn join(mut self) -> Result<Summary, ExportError> {
        match self.thread.take().map(|t| t.join()) {
            Some(Ok(r)) => r,
            Some(Err(panic)) => Err(ExportError::Panicked(panic_message(&panic))),
            None => Err(ExportError::Other(format!(
                "the export's thread could not be started: {}",
                self.spawn_error.take().unwrap_or_default()
            ))),
        }
    }
}

impl Drop for JobHandle {
    /// Dropping a running job cancels it (its staging folder is removed by
    /// the worker).
    fn drop(&mut self) {
        if self.thread.is_some() {
            self.cancel();
        }
    }
}

fn panic_message(p: &Box<dyn std::any::Any + Send>) -> String {
    p.downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| p.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "panic".into())
}

/// The manifest written into every output folder.
#[derive(Serialize)]
struct Manifest<'a> {
    tool: &'static str,
    version: &'static str,
    design_hash: &'a str,
    #[serde(skip_serializing_if = "Option::is_none")]
    design: Option<&'a str>,
    #[serde(flatten)]
    summary: &'a Summary,
}

/// A stable 64-bit FNV-1a hash of the design text (and anything else that
/// defines the output), as 16 hex digits.
pub fn design_hash(parts: &[&[u8]]) -> String {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for part in parts {
        for b in *part {
            h ^= u64::from(*b);
            h = h.wrapping_mul(0x0100_0000_01b3);
        }
        h ^= 0xff;
        h = h.wrapping_mul(0x0100_0000_01b3);
    }
    format!("{h:016x}")
}

/// Start `work` on a new thread, writing into a staging folder beside `dest`.
pub fn spawn<F>(dest: PathBuf, design_hash: String, work: F) -> JobHandle
where
    F: FnOnce(&JobContext) -> Result<Summary, ExportError> + Send + 'static,
{
    spawn_design(dest, design_hash, None, work)
}

/// [`spawn`], with the design's name recorded in the manifest (what the
/// question before replacing a finished export names).
pub fn spawn_design<F>(
    dest: PathBuf,
    design_hash: String,
    design: Option<String>,
    work: F,
) -> JobHandle
where
    F: FnOnce(&JobContext) -> Result<Summary, ExportError> + Send + 'static,
{
    spawn_runner(dest, move |d, c, tx| {
        run_job(d, (design_hash, design), c, tx, work)
    })
}

/// [`spawn`] for an export that is one file (`part.gcvf`): `work` writes
/// `ctx.staging()/<dest's file name>`, which is moved to `dest` once the
/// job has succeeded (a regular file there is replaced; a folder or a
/// special file is refused before any work). The job's folder, manifest
/// included, is removed; a failed or cancelled job leaves nothing.
pub fn spawn_file<F>(dest: PathBuf, design_hash: String, work: F) -> JobHandle
where
    F: FnOnce(&JobContext) -> Result<Summary, ExportError> + Send + 'static,
{
    spawn_runner(dest, move |d, c, tx| {
        let name = d
            .file_name()
            .map(|n| n.to_string_lossy().to_string())
            .ok_or_else(|| ExportError::Other(format!("{}: not a file name", d.display())))?;
        if std::fs::symlink_metadata(&d).is_ok_and(|m| !m.is_file()) {
            return Err(ExportError::Other(format!(
                "{}: exists and is not a regular file; give a new file name",
                d.display()
            )));
        }
        let job_dir = d.with_file_name(format!(".{name}.job-{}", std::process::id()));
        let summary = run_job(job_dir.clone(), (design_hash, None), c, tx, work)?;
        let moved = std::fs::rename(job_dir.join(&name), &d);
        let _ = std::fs::remove_dir_all(&job_dir);
        moved.map_err(|e| ExportError::io(&d, e))?;
        Ok(summary)
    })
}

/// The thread, channel and cancel flag of a job that `runner` runs.
fn spawn_runner<R>(dest: PathBuf, runner: R) -> JobHandle
where
    R: FnOnce(PathBuf, Arc<AtomicBool>, SyncSender<Progress>) -> Result<Summary, ExportError>
        + Send
        + 'static,
{
    let (tx, rx) = sync_channel(64);
    let cancel = Arc::new(AtomicBool::new(false));
    let c2 = cancel.clone();
    let d2 = dest.clone();
    let spawned = std::thread::Builder::new()
        .name("volcad-export".into())
        .spawn(move || runner(d2, c2, tx));
    // A thread the system refuses (no memory, a process limit) becomes the
    // job's error, reported by `join` like any other failure.
    let (thread, spawn_error) = match spawned {
        Ok(t) => (Some(t), None),
        Err(e) => (None, Some(e.to_string())),
    };
    JobHandle {
        progress: rx,
        cancel,
        thread,
        spawn_error,
        dest,
    }
}

/// Staging folders left beside `parent/name` by earlier runs whose process
/// is gone (killed outright, or the machine went down) are removed, so
/// crashed exports do not pile up hidden gigabytes beside the destination.
/// A folder whose process still runs (another export to the same place)
/// is left alone, and so is every folder where that cannot be told.
fn remove_stale_staging(parent: &Path, name: &str) {
    let prefix = format!(".{name}.partial-");
    let Ok(entries) = std::fs::read_dir(parent) else {
        return;
    };
    for e in entries.flatten() {
        let pid = e
            .file_name()
            .to_str()
            .and_then(|n| n.strip_prefix(&prefix))
            .and_then(|p| p.parse::<u32>().ok());
        if let Some(pid) = pid
            && pid != std::process::id()
            && process_gone(pid)
        {
            let _ = std::fs::remove_dir_all(e.path());
        }
    }
}

/// True when no process `pid` exists: `kill(pid, 0)` fails with `ESRCH`.
#[cfg(unix)]
fn process_gone(pid: u32) -> bool {
    let pid = i32::try_from(pid)
        .ok()
        .and_then(rustix::process::Pid::from_raw);
    pid.is_some_and(|p| rustix::process::test_kill_process(p) == Err(rustix::io::Errno::SRCH))
}

/// Elsewhere the question is not asked: nothing is removed.
#[cfg(not(unix))]
fn process_gone(_pid: u32) -> bool {
    false
}

/// Run `work` on this thread with the design's hash and name (what [`spawn`]
/// and [`spawn_design`] run on their thread; tests may call it directly).
pub fn run_job<F>(
    dest: PathBuf,
    (design_hash, design): (String, Option<String>),
    cancel: Arc<AtomicBool>,
    tx: SyncSender<Progress>,
    work: F,
) -> Result<Summary, ExportError>
where
    F: FnOnce(&JobContext) -> Result<Summary, ExportError>,
{
    let dest = resolve_destination(dest)?;
    if dest.exists() && !(dest.is_dir() && dest.join("manifest.json").exists()) {
        // Never replace something that is not one of our exports.
        if !(dest.is_dir()
            && std::fs::read_dir(&dest)
                .map(|mut d| d.next().is_none())
                .unwrap_or(false))
        {
            return Err(ExportError::DestinationExists(dest));
        }
    }
    let parent = dest
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    // A file where a folder must be: "File exists" from the OS says neither
    // which path nor what is wrong with it.
    let existing = parent.ancestors().find(|a| a.exists());
    if let Some(file) = existing.filter(|a| !a.is_dir()) {
        return Err(ExportError::Other(format!(
            "{}: is a file, not a folder, so {} cannot be created in it",
            file.display(),
            dest.display()
        )));
    }
    std::fs::create_dir_all(parent).map_err(|e| ExportError::io(parent, e))?;
    // The folders made for this export go again if it fails: a refused
    // export leaves the tree as it found it.
    let made: Vec<PathBuf> = parent
        .ancestors()
        .take_while(|a| Some(*a) != existing)
        .map(Path::to_path_buf)
        .collect();
    let design = (design_hash, design);
    let out = stage_and_run(&dest, parent, cancel, tx, design, work);
    if out.is_err() {
        for folder in &made {
            if std::fs::remove_dir(folder).is_err() {
                break;
            }
        }
    }
    out
}

/// `dest` as the export will write it: a symlink to a folder is followed
/// (the folder it names is the destination, the link stays); a special
/// file, or a symlink to one or to nothing, is refused, never renamed over
/// (a rename would replace `/dev/stdout`'s link with a regular folder).
fn resolve_destination(dest: PathBuf) -> Result<PathBuf, ExportError> {
    let Ok(link) = std::fs::symlink_metadata(&dest) else {
        return Ok(dest);
    };
    let meta = if link.file_type().is_symlink() {
        std::fs::metadata(&dest).map_err(|e| {
            ExportError::Other(format!(
                "{}: a symlink whose target cannot be opened ({e}); remove it or choose another folder",
                dest.display()
            ))
        })?
    } else {
        link.clone()
    };
    if meta.is_dir() {
        return if link.file_type().is_symlink() {
            dest.canonicalize().map_err(|e| ExportError::io(&dest, e))
        } else {
            Ok(dest)
        };
    }
    if meta.is_file() {
        return Err(ExportError::DestinationExists(dest));
    }
    Err(ExportError::Other(format!(
        "{}: is a device, pipe or socket; an export writes a folder of files, so give a folder path",
        dest.display()
    )))
}

/// Make the staging folder beside `dest` in `parent`, run `work` in it and
/// rename it into place (see [`run_job`]).
fn stage_and_run<F>(
    dest: &Path,
    parent: &Path,
    cancel: Arc<AtomicBool>,
    tx: SyncSender<Progress>,
    (design_hash, design): (String, Option<String>),
    work: F,
) -> Result<Summary, ExportError>
where
    F: FnOnce(&JobContext) -> Result<Summary, ExportError>,
{
    let name = dest
        .file_name()
        .map(|n| n.to_string_lossy().to_string())
        .unwrap_or_else(|| "export".into());
    remove_stale_staging(parent, &name);
    let staging = parent.join(format!(".{name}.partial-{}", std::process::id()));
    if staging.exists() {
        let _ = std::fs::remove_dir_all(&staging);
    }
    // The staging folder's name means nothing to the user: say which
    // folder refused the export.
    std::fs::create_dir_all(&staging).map_err(|e| {
        ExportError::Other(format!(
            "{}: cannot write {} in this folder: {e}",
            parent.display(),
            dest.display()
        ))
    })?;
    let ctx = JobContext {
        staging: staging.clone(),
        cancel,
        tx,
        start: Instant::now(),
        design_hash,
        design,
    };
    let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| work(&ctx)));
    let result = match result {
        Ok(r) => r,
        Err(p) => Err(ExportError::Panicked(panic_message(&p))),
    };
    let finish = |mut summary: Summary| -> Result<Summary, ExportError> {
        ctx.check_cancel()?;
        summary.seconds = ctx.start.elapsed().as_secs_f64();
        let manifest = Manifest {
            tool: "volcad",
            version: env!("CARGO_PKG_VERSION"),
            design_hash: &ctx.design_hash,
            design: ctx.design.as_deref(),
            summary: &summary,
        };
        let path = staging.join("manifest.json");
        let text = serde_json::to_string_pretty(&manifest)
            .map_err(|e| ExportError::Other(e.to_string()))?;
        std::fs::write(&path, text).map_err(|e| ExportError::io(&path, e))?;
        if dest.exists() {
            std::fs::remove_dir_all(dest).map_err(|e| ExportError::io(dest, e))?;
        }
        std::fs::rename(&staging, dest).map_err(|e| ExportError::io(dest, e))?;
        Ok(summary)
    };
    let out = result.and_then(finish);
    if out.is_err() {
        let _ = std::fs::remove_dir_all(&staging);
    }
    // A file that failed in the staging folder is named as it would have
    // been in the destination.
    out.map_err(|e| match e {
        ExportError::Io { path, err } => ExportError::Io {
            path: path
                .strip_prefix(&staging)
                .map_or(path.clone(), |rel| dest.join(rel)),
            err,
        },
        e => e,
    })
}

#[cfg(test)]
mod tests;
