//! A coarse grid of exact signed distances for cheap bounds far from the
//! surface.
//!
//! The exact SDF is 1-Lipschitz, so knowing `d(c)` at a cell centre `c`
//! bounds every point `p` of the cell: `|d(c)| − |p − c| ≤ |d(p)| ≤ |d(c)| +
//! |p − c|`, and when the lower bound is positive `p` lies on the same side
//! as `c`. This answers [`super::TriangleMesh::signed_distance_bound`] in O(1)
//! for points deep inside or far outside (the sampler's "skip this region"
//! question), and the upper bound starts the exact nearest-triangle search
//! with a finite radius so far points prune as well as near ones.

use glam::DVec3;
use rayon::prelude::*;

use crate::aabb::Aabb;

/// Most cells along the longest side of the mesh box.
const MAX_CELLS: f64 = 32.0;

/// Distances at cell centres.
#[derive(Clone, Debug)]
pub(crate) struct CoarseGrid {
    /// Centre of cell (0, 0, 0).
    pub(super) origin: DVec3,
    /// Cell side.
    pub(super) cell: f64,
    /// `1 / cell`.
    pub(super) inv_cell: f64,
    /// Cells per axis.
    pub(super) dims: [usize; 3],
    /// Signed distance at each centre, x fastest.
    pub(super) d: Vec<f64>,
}

impl CoarseGrid {
    /// Samples `sdf` at the centres of a grid covering `bbox` plus one cell,
    /// with about `2·∛triangles` (4 to 32) cells along the longest side: a
    /// few exact queries per triangle, so building stays a small part of
    /// loading.
    pub fn new(
        bbox: &Aabb,
        triangles: usize,
        sdf: impl Fn(DVec3) -> f64 + Sync,
    ) -> Option<CoarseGrid> {
        let extent = bbox.size().max_element();
        if !(extent > 0.0 && extent.is_finite()) {
            return None;
        }
        let cells = (2.0 * (triangles as f64).cbrt())
            .clamp(4.0, MAX_CELLS)
            .round();
        let cell = extent / cells;
        let lo = bbox.min - DVec3::splat(cell);
        let n = ((bbox.max + DVec3::splat(cell) - lo) / cell).ceil();
        let dims = [n.x as usize, n.y as usize, n.z as usize];
        let origin = lo + DVec3::splat(cell * 0.5);
        let count = dims[0] * dims[1] * dims[2];
        let d = (0..count)
            .into_par_iter()
            .map(|i| {
                let (x, y, z) = (i % dims[0], i / dims[0] % dims[1], i / (dims[0] * dims[1]));
                sdf(origin + DVec3::new(x as f64, y as f64, z as f64) * cell)
            })
            .collect();
        Some(CoarseGrid {
            origin,
            cell,
            inv_cell: 1.0 / cell,
            dims,
            d,
        })
    }

    /// The distance at the centre of `p`'s cell and `|p − centre|`, or
    /// `None` when `p` is outside the grid.
    #[inline]
    pub fn lookup(&self, p: DVec3) -> Option<(f64, f64)> {
        let g = (p - self.origin) * self.inv_cell + DVec3::splat(0.5);
        if !(g.x >= 0.0 && g.y >= 0.0 && g.z >= 0.0) {
            return None;
        }
        let (x, y, z) = (g.x as usize, g.y as usize, g.z as usize);
        if x >= self.dims[0] || y >= self.dims[1] || z >= self.dims[2] {
            return None;
        }
        let c = self.origin + DVec3::new(x as f64, y as f64, z as f64) * self.cell;
        Some((
            self.d[x + self.dims[0] * (y + self.dims[1] * z)],
            p.distance(c),
        ))
    }
}
