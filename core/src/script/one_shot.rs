//! A design file or text to a prepared model in one call, for tests,
//! benchmarks, one-shot tools and embedders.

use std::path::{Path, PathBuf};

use super::{ScriptError, ScriptOptions};
use crate::model::{Model, PrepareError};

/// Why [`model_of`] or [`model_of_file`] gave no model. Its message is the
/// script's or the preparation's own.
#[derive(Debug, thiserror::Error)]
pub enum DesignError {
    /// The design file could not be read.
    #[error("{}: {source}", path.display())]
    Read {
        /// The file.
        path: PathBuf,
        /// What the system said.
        source: std::io::Error,
    },
    /// The script (or legacy design) failed.
    #[error(transparent)]
    Script(#[from] ScriptError),
    /// The node tree could not be prepared.
    #[error(transparent)]
    Prepare(#[from] PrepareError),
}

/// Run a design script (or a legacy `.vcad` text) and prepare its model.
pub fn model_of(source: &str, name: &str, opts: &ScriptOptions) -> Result<Model, DesignError> {
    let d = crate::vcad::run_design(source, name, opts)?;
    Ok(Model::prepare(&d.root, d.materials.clone())?)
}

/// [`model_of`] for a script file: its text, named by its file name, with
/// relative data paths resolved beside it.
pub fn model_of_file(path: &Path) -> Result<Model, DesignError> {
    let src = std::fs::read_to_string(path).map_err(|source| DesignError::Read {
        path: path.to_owned(),
        source,
    })?;
    let name = path.file_name().map_or_else(
        || path.display().to_string(),
        |n| n.to_string_lossy().into(),
    );
    model_of(&src, &name, &ScriptOptions::for_file(path))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each failure is its own variant, and says what the string error
    /// said before it was typed.
    #[test]
    fn each_failure_has_its_variant_and_message() {
        let dir = tempfile::tempdir().expect("temp dir");
        let missing = dir.path().join("missing.rhai");
        let e = model_of_file(&missing).expect_err("no file");
        assert!(matches!(e, DesignError::Read { .. }), "{e:?}");
        assert!(
            e.to_string()
                .starts_with(&format!("{}: ", missing.display())),
            "{e}"
        );
        let opts = ScriptOptions::default();
        let e = model_of("Sphere(Vec3(0, 0, 0), -1, 1)", "s.rhai", &opts).expect_err("radius");
        assert!(matches!(e, DesignError::Script(_)), "{e:?}");
        assert!(
            e.to_string().starts_with("s.rhai:1:") && e.to_string().contains("radius must be > 0"),
            "{e}"
        );
        let e = model_of("Union(false, [])", "u.rhai", &opts).expect_err("empty union");
        assert!(matches!(e, DesignError::Prepare(_)), "{e:?}");
        let good = model_of("Sphere(Vec3(0, 0, 0), 2, 1)", "g.rhai", &opts).expect("sphere");
        assert!((good.distance(glam::DVec3::ZERO) + 2.0).abs() < 1e-12);
    }
}
