//! The slice stack's plan: its estimate line and the size that must
//! resolve thin features.

use volcad_core::Model;

use super::Assessment;
use crate::job::{ExportError, JobContext, Summary};
use crate::png_stack::{self, PngParams};

pub(super) fn estimate(model: &Model, p: &PngParams) -> Result<Assessment, ExportError> {
    let est = png_stack::estimate(model, p)?;
    let counts = format!(
        "layers {} to {} included ({} of {}; {} files), about ",
        est.layers.start,
        est.layers.end.saturating_sub(1),
        est.layers.len(),
        est.grid.dims[2],
        est.files
    );
    Ok(Assessment::voxel_grid(&est, &counts))
}

pub(super) fn run(model: &Model, p: &PngParams, ctx: &JobContext) -> Result<Summary, ExportError> {
    png_stack::export_png_stack(model, p, ctx)
}
