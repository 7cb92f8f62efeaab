//! The voxel grid a sampler covers: voxel centres `origin + (i + ½)·voxel`
//! over a design's bounding box, and why a grid cannot be made.

use glam::DVec3;

use crate::aabb::Aabb;

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
        "{} voxels ({} × {} × {}) is more than the limit of {limit}; use a larger voxel size",
        count_text(*.voxels), count_text(*.nx), count_text(*.ny), count_text(*.nz)
    )]
    TooLarge {
        /// Total voxels (a float: a huge box's counts overflow integers).
        voxels: f64,
        /// X count.
        nx: f64,
        /// Y count.
        ny: f64,
        /// Z count.
        nz: f64,
        /// The limit.
        limit: u128,
    },
}

/// A voxel count as an integer, or in scientific notation past 10¹⁵
/// (where a float no longer holds every integer, and digits stop helping).
fn count_text(v: f64) -> String {
    if v.is_infinite() {
        "more than 1e308".into()
    } else if v < 1e15 {
        format!("{v:.0}")
    } else {
        format!("{v:.3e}")
    }
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
        let too_large = || GridError::TooLarge {
            voxels: n.x * n.y * n.z,
            nx: n.x,
            ny: n.y,
            nz: n.z,
            limit: max_voxels,
        };
        // Each count below 2³², so the product is exact in u128.
        if n.max_element() > u32::MAX as f64 {
            return Err(too_large());
        }
        let (nx, ny, nz) = (n.x as u128, n.y as u128, n.z as u128);
        if nx * ny * nz > max_voxels {
            return Err(too_large());
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn too_large_grids_say_how_large_without_overflowing() {
        let b = Aabb::new(DVec3::ZERO, DVec3::splat(200.0));
        let e = Grid::covering(&b, DVec3::splat(0.1), 1_000_000_000).unwrap_err();
        assert_eq!(
            e.to_string(),
            "8000000000 voxels (2000 × 2000 × 2000) is more than the limit of 1000000000; use a larger voxel size"
        );
        // A box of 10³⁰⁰ mm: counts past any integer type (this multiplied
        // saturated u128s, which overflows in a debug build).
        let huge = Aabb::new(DVec3::splat(-1e300), DVec3::splat(1e300));
        let e = Grid::covering(&huge, DVec3::splat(0.5), 1 << 40)
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("more than 1e308 voxels"), "{e}");
        assert!(e.contains("(4.000e300 × 4.000e300 × 4.000e300)"), "{e}");
        assert!(Grid::covering(&b, DVec3::splat(1.0), 1 << 40).is_ok());
    }
}
