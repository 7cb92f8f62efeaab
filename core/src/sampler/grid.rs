//! The voxel grid a sampler covers: voxel centres `origin + (i + ½)·voxel`
//! over a design's bounding box, and why a grid cannot be made.

use glam::DVec3;

use crate::bounds::Aabb;

/// A regular voxel grid.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Grid {
    /// Lowest corner of voxel (0, 0, 0).
    pub origin: DVec3,
    /// Voxel size per axis (mm).
    pub voxel: DVec3,
    /// Voxels per axis.
    pub dims: [usize; 3],
}

/// Why a grid cannot be made.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum GridError {
    /// A voxel size is zero, negative or not a number.
    #[error("voxel size must be > 0 on every axis, got ({}, {}, {}) mm", .0.x, .0.y, .0.z)]
    BadVoxel(DVec3),
    /// The design has no finite extent.
    #[error(
        "the design is unbounded (bounding box {0}); clip Tile or TPMS with Intersection and a bounded shape"
    )]
    Unbounded(String),
    /// The design is empty.
    #[error("the design is empty (its bounding box has no volume)")]
    Empty,
    /// The grid would have more voxels than the limit.
    #[error(
        "{voxels} voxels ({nx} × {ny} × {nz}) is more than the limit of {limit}; use a larger voxel size"
    )]
    TooLarge {
        /// Total voxels.
        voxels: u128,
        /// X count.
        nx: u128,
        /// Y count.
        ny: u128,
        /// Z count.
        nz: u128,
        /// The limit.
        limit: u128,
    },
}

impl GridError {
    /// `Empty` or `Unbounded` for a box no grid can cover, so every export
    /// (grids, and the FEA tetrahedra, which need no grid) words them alike.
    pub fn check_box(bbox: &Aabb) -> Result<(), GridError> {
        if bbox.is_empty() {
            return Err(GridError::Empty);
        }
        if !bbox.is_finite() {
            return Err(GridError::Unbounded(format!(
                "{:?} .. {:?}",
                bbox.min.to_array(),
                bbox.max.to_array()
            )));
        }
        Ok(())
    }
}

impl Grid {
    /// The grid of `voxel`-sized cells covering `bbox` (count = ceil(extent /
    /// voxel), at least 1, centred on the box).
    pub fn covering(bbox: &Aabb, voxel: DVec3, max_voxels: u128) -> Result<Grid, GridError> {
        if !(voxel.cmpgt(DVec3::ZERO).all() && voxel.is_finite()) {
            return Err(GridError::BadVoxel(voxel));
        }
        GridError::check_box(bbox)?;
        let n = (bbox.size() / voxel).ceil().max(DVec3::ONE);
        let (nx, ny, nz) = (n.x as u128, n.y as u128, n.z as u128);
        let voxels = nx * ny * nz;
        if voxels > max_voxels || n.max_element() > u32::MAX as f64 {
            return Err(GridError::TooLarge {
                voxels,
                nx,
                ny,
                nz,
                limit: max_voxels,
            });
        }
        let span = n * voxel;
        let origin = bbox.center() - span * 0.5;
        Ok(Grid {
            origin,
            voxel,
            dims: [nx as usize, ny as usize, nz as usize],
        })
    }

    /// Centre of voxel (i, j, k).
    #[inline(always)]
    pub fn center(&self, i: usize, j: usize, k: usize) -> DVec3 {
        self.origin + (DVec3::new(i as f64, j as f64, k as f64) + 0.5) * self.voxel
    }

    /// Total voxels.
    pub fn count(&self) -> u64 {
        self.dims.iter().map(|d| *d as u64).product()
    }

    /// Voxels in one layer.
    pub fn layer_len(&self) -> usize {
        self.dims[0] * self.dims[1]
    }

    /// The box of voxel centres of the index ranges (inclusive ends).
    #[inline]
    pub(super) fn centres_box(&self, i0: usize, i1: usize, j0: usize, j1: usize, k: usize) -> Aabb {
        Aabb::new(self.center(i0, j0, k), self.center(i1, j1, k))
    }
}
