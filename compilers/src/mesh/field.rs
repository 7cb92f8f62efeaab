//! Contouring a plain scalar field (no segments): the region `{v ≤ 0}`.

use volcad_core::sampler::Grid;

use super::contour::{Contourer, Plane};
use super::indexed::IndexedMesh;
use super::interface::Interface;

/// Mesh the region `{v ≤ 0}` of a field sampled at the centres of `grid`
/// (`values` x fastest, then y, then z): marching cubes (one label, see
/// `super::cube_loops`), with flat regions merged (see `super::flat`). Samples on the grid's outer layer count as
/// outside, so the mesh is always closed.
///
/// # Panics
/// If `values` does not have one value per voxel.
pub fn marching_cubes(grid: &Grid, values: &[f32]) -> IndexedMesh {
    contour_field(Contourer::new(*grid, 1, Interface::Midpoint), grid, values)
}

/// [`marching_cubes`] through a configured one-label contourer.
pub(super) fn contour_field(mut c: Contourer, grid: &Grid, values: &[f32]) -> IndexedMesh {
    let [nx, ny, nz] = grid.dims;
    assert_eq!(values.len(), nx * ny * nz, "one value per voxel");
    for z in 0..nz {
        let dist = values[z * nx * ny..(z + 1) * nx * ny].to_vec();
        let label = border_void(&dist, [nx, ny, nz], z, |d| u16::from(d <= 0.0));
        // (Every sample is given: none is left to evaluate.)
        c.push_plane(
            z,
            Plane {
                label,
                dist: dist.into(),
                value: Vec::new(),
                bits: Vec::new(),
            },
            &|[i, j, k]| values[(k * ny + j) * nx + i],
        );
    }
    c.finish(&|[i, j, k], _| values[(k * ny + j) * nx + i])
        .pop()
        .unwrap_or_default()
}

/// Labels of plane `z` from `f`, with the grid's outer layer void.
pub fn border_void(
    dist: &[f32],
    [nx, ny, nz]: [usize; 3],
    z: usize,
    f: impl Fn(f32) -> u16,
) -> Vec<u16> {
    let edge_plane = z == 0 || z + 1 == nz;
    dist.iter()
        .enumerate()
        .map(|(v, d)| {
            let (x, y) = (v % nx, v / nx);
            if edge_plane || x == 0 || y == 0 || x + 1 == nx || y + 1 == ny {
                0
            } else {
                f(*d)
            }
        })
        .collect()
}
