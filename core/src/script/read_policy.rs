//! Which files a script may read: anything inside its project, and folders
//! the user allowed (`--allow-read DIR`, the studio's read folders).
//!
//! The project is the nearest folder at or above the script's folder that
//! holds `.git` or `volcad.toml`, else the script's own folder. The search
//! stops below the user's home folder: neither home itself nor anything
//! above it is ever a project (a home kept in git must not open `~/.ssh` to
//! a downloaded script), and a script saved directly in home reads nothing
//! but the allowed folders. Paths are relative to the script's folder;
//! absolute paths are refused, and every path is compared after resolving
//! symbolic links, so a link cannot lead out.

use std::path::{Path, PathBuf};

/// Files that mark a project's top folder.
pub const PROJECT_MARKERS: [&str; 2] = [".git", "volcad.toml"];

/// The user's home folder from the environment, if set.
pub fn home_dir() -> Option<PathBuf> {
    std::env::var_os("HOME")
        .or_else(|| std::env::var_os("USERPROFILE"))
        .filter(|h| !h.is_empty())
        .map(PathBuf::from)
}

/// Where a script's project is and how it was found.
#[derive(Clone, Debug, PartialEq)]
pub struct Project {
    /// The folder files may be read under; `None` when the script lies in
    /// the home folder itself (or above it).
    pub root: Option<PathBuf>,
    /// How `root` was chosen, for messages.
    pub why: String,
}

/// The project of a script in `script_dir` (canonical), given the user's
/// home (canonical, if known).
pub fn project_of(script_dir: &Path, home: Option<&Path>) -> Project {
    let is_home_or_above = |d: &Path| home.is_some_and(|h| h.starts_with(d));
    if is_home_or_above(script_dir) {
        return Project {
            root: None,
            why: format!(
                "the script is in the home folder {} itself, which is never a project; \
                 move it into a project folder",
                script_dir.display()
            ),
        };
    }
    for d in script_dir.ancestors() {
        if is_home_or_above(d) {
            break;
        }
        if let Some(m) = PROJECT_MARKERS.iter().find(|m| d.join(m).exists()) {
            return Project {
                root: Some(d.to_path_buf()),
                why: format!("the nearest folder above the script holding {m}"),
            };
        }
    }
    Project {
        root: Some(script_dir.to_path_buf()),
        why: "the script's own folder: no folder above it (below the home folder) holds \
              .git or volcad.toml"
            .into(),
    }
}

/// Resolve `name`, relative to the script's folder `base`, to a file the
/// script may read; the error says why not and what allows it.
pub fn resolve(
    name: &str,
    base: &Path,
    allowed: &[PathBuf],
    home: Option<&Path>,
) -> Result<PathBuf, String> {
    if Path::new(name).is_absolute() {
        return Err(format!(
            "cannot read \"{name}\": write the path relative to the script's folder {} \
             (absolute paths are not read, so a script reads the same files on every machine)",
            base.display()
        ));
    }
    let base = base
        .canonicalize()
        .map_err(|e| format!("script folder {}: {e}", base.display()))?;
    let joined = base.join(name);
    let full = joined
        .canonicalize()
        .map_err(|e| format!("cannot read \"{name}\" ({}): {e}", joined.display()))?;
    let home = home.and_then(|h| h.canonicalize().ok());
    let project = project_of(&base, home.as_deref());
    let inside = |d: &Path| full.starts_with(d);
    if project.root.as_deref().is_some_and(inside)
        || allowed
            .iter()
            .filter_map(|d| d.canonicalize().ok())
            .any(|d| inside(&d))
    {
        return Ok(full);
    }
    let folder = full.parent().unwrap_or(&full);
    let place = match &project.root {
        Some(r) => format!(
            "outside the project folder {} ({})",
            r.display(),
            project.why
        ),
        None => format!("not in an allowed folder: {}", project.why),
    };
    Err(format!(
        "cannot read \"{name}\" ({}): it is {place}; to allow it, run with `--allow-read {}` \
         (in the studio: File → Folders Scripts May Read)",
        full.display(),
        folder.display()
    ))
}

#[cfg(test)]
mod tests;
