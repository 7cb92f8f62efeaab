//! The segmented meshes' plan: their estimate line and the size that must
//! resolve thin features.

use volcad_core::Model;

use super::Assessment;
use crate::job::{ExportError, JobContext, Summary};
use crate::mesh::{self, MeshParams};
use crate::resources::human_bytes;

pub(super) fn estimate(model: &Model, p: &MeshParams) -> Result<Assessment, ExportError> {
    let est = mesh::estimate_mesh(model, p)?;
    let [nx, ny, nz] = est.grid.dims;
    Ok(Assessment {
        text: format!(
            "{nx} × {ny} × {nz} voxels ({:.3e}), {} segments, about {} triangles, {} on disk, {} memory",
            est.voxels as f64,
            est.segments,
            est.triangles,
            human_bytes(est.disk_bytes),
            human_bytes(est.memory_bytes)
        ),
        disk_bytes: Some(est.disk_bytes),
        verdicts: Vec::new(),
    })
}

pub(super) fn run(model: &Model, p: &MeshParams, ctx: &JobContext) -> Result<Summary, ExportError> {
    mesh::export_meshes(model, p, ctx)
}
