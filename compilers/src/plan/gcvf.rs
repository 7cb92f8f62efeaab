//! The GrabCAD package's plan: its estimate line (with the J750 table's
//! refusals), the size that must resolve thin features, and the checks on
//! its destination, which is one file rather than a folder.

use std::path::Path;

use volcad_core::Model;

use super::{Assessment, Opt, Severity, Verdict};
use crate::gcvf::{self, GcvfParams};
use crate::job::{ExportError, JobContext, Summary};

pub(super) fn estimate(model: &Model, p: &GcvfParams) -> Result<Assessment, ExportError> {
    let (est, mats) = gcvf::estimate(model, p)?;
    let names: Vec<&str> = mats.iter().map(|m| m.name.as_str()).collect();
    let counts = format!("resins {}, about ", names.join(", "));
    Ok(Assessment::voxel_grid(&est, &counts))
}

/// The verdict on writing the package to `dest`: none when nothing is
/// there, a question before replacing a regular file, a refusal for a
/// folder or anything else that is not a regular file.
pub(super) fn file_verdict(dest: &Path) -> Option<Verdict> {
    let meta = std::fs::symlink_metadata(dest).ok()?;
    let d = dest.display();
    let (severity, message) = if meta.is_file() {
        (
            Severity::Ask,
            format!(
                "--out {d}: a file of {:.1} MB is already there; add --force to replace it, or give another name",
                meta.len() as f64 / 1e6
            ),
        )
    } else {
        (
            Severity::Refuse,
            format!(
                "--out {d}: a .gcvf is a zip archive written beside its destination and renamed; give a file name"
            ),
        )
    };
    Some(Verdict {
        severity,
        option: Opt::Out,
        message,
    })
}

pub(super) fn run(model: &Model, p: &GcvfParams, ctx: &JobContext) -> Result<Summary, ExportError> {
    gcvf::export_gcvf(model, p, ctx)
}
