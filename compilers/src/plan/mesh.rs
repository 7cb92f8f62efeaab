//! The segmented meshes' plan: their estimate line and the size that must
//! resolve thin features.

use volcad_core::Model;

use super::Assessment;
use crate::job::{ExportError, JobContext, Summary};
use crate::mesh::{self, MeshParams};

pub(super) fn estimate(model: &Model, p: &MeshParams) -> Result<Assessment, ExportError> {
    let est = mesh::estimate_mesh(model, p)?;
    let counts = format!(
        "{} segments, about {} triangles, ",
        est.segments, est.triangles
    );
    Ok(Assessment::voxel_grid(&est, &counts))
}

pub(super) fn run(model: &Model, p: &MeshParams, ctx: &JobContext) -> Result<Summary, ExportError> {
    mesh::export_meshes(model, p, ctx)
}
