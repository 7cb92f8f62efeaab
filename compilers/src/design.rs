//! Checks on a design that every export makes first: the voxel grid over
//! its bounding box, and its materials' colours from the material table.
//! Errors name the parameter to change (`--voxel`, `design`, `materials`).

use glam::DVec3;
use volcad_core::sampler::{Grid, GridError};
use volcad_core::{Aabb, Model};

use crate::job::ExportError;

/// Most voxels a grid may have (a sanity bound; memory and disk are checked
/// separately).
pub const MAX_VOXELS: u128 = 1 << 44;

/// The grid of `voxel` over `model`'s box, grown by `pad` on every side,
/// with grid errors named by the parameter that fixes them.
pub fn grid_for(model: &Model, voxel: DVec3, pad: f64) -> Result<Grid, ExportError> {
    let bbox = model.bbox();
    let bbox = if bbox.is_finite() && pad > 0.0 {
        bbox.expand(pad)
    } else {
        bbox
    };
    Grid::covering(&bbox, voxel, MAX_VOXELS).map_err(grid_error)
}

/// The design's bounding box, or the error every export gives for an
/// empty or unbounded design (the FEA exports, which size elements
/// rather than voxels, check it before anything else).
pub fn bounded_box(model: &Model) -> Result<Aabb, ExportError> {
    let b = model.bbox();
    GridError::check_box(&b).map_err(grid_error)?;
    Ok(b)
}

/// A grid error named by what fixes it: the voxel size, or the design
/// (unbounded or empty).
pub fn grid_error(e: GridError) -> ExportError {
    match e {
        GridError::BadVoxel(_) | GridError::TooLarge { .. } => {
            ExportError::param("--voxel", e.to_string())
        }
        GridError::Unbounded(_) | GridError::Empty => ExportError::param("design", e.to_string()),
    }
}

/// Check that every material of the design is in its table. Returns the
/// palette by code: index 0 is void `(0, 0, 0, 0)`, then one RGBA colour per
/// material slot (`Model::materials()` order).
pub fn palette(model: &Model) -> Result<Vec<[u8; 4]>, ExportError> {
    let mut pal = vec![[0u8; 4]];
    for id in model.materials() {
        let m = model.table().get(*id).ok_or_else(|| {
            ExportError::param(
                "materials",
                format!(
                    "the design uses material id {id}, which the material table ({}) does not have",
                    model.table().origin()
                ),
            )
        })?;
        pal.push(m.rgba());
    }
    Ok(pal)
}
