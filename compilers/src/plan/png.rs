//! The slice stack's plan: its estimate line and the size that must
//! resolve thin features.

use volcad_core::Model;

use super::Assessment;
use crate::job::{ExportError, JobContext, Summary};
use crate::png_stack::{self, PngParams};
use crate::resources::human_bytes;

pub(super) fn estimate(model: &Model, p: &PngParams) -> Result<Assessment, ExportError> {
    let est = png_stack::estimate(model, p)?;
    let [nx, ny, nz] = est.grid.dims;
    Ok(Assessment {
        text: format!(
            "{nx} × {ny} × {nz} voxels ({:.3e}), layers {} to {} included ({} of {nz}; {} files), about {} on disk, {} memory",
            est.voxels as f64,
            est.layers.start,
            est.layers.end.saturating_sub(1),
            est.layers.len(),
            est.files,
            human_bytes(est.disk_bytes),
            human_bytes(est.memory_bytes)
        ),
        disk_bytes: Some(est.disk_bytes),
        verdicts: Vec::new(),
    })
}

pub(super) fn run(model: &Model, p: &PngParams, ctx: &JobContext) -> Result<Summary, ExportError> {
    png_stack::export_png_stack(model, p, ctx)
}
