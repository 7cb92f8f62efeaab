//! C3D8R bricks on the shared voxel grid.
//!
//! Every voxel whose centre is inside (`d ≤ 0`, pyvcad's rule) and whose drawn
//! material is not void becomes one brick spanning the voxel. Corner nodes
//! are shared: a grid corner is a node when any of its eight voxels is a
//! brick. The grid is streamed a few layers at a time through the core's
//! sampler, so memory holds the mesh, never the grid:
//!
//! * voxel layer `k` is sampled → its brick mask;
//! * corner layer `k` (below it) is numbered from the masks of voxel layers
//!   `k − 1` and `k`, in `(j, i)` order, so node ids grow with z, then y, then
//!   x;
//! * the bricks of voxel layer `k − 1` are emitted (their corners are layers
//!   `k − 1` and `k`), in `(j, i)` order.
//!
//! The boundary faces and connected pieces are found on the way, from the
//! masks of the layers beside each brick (`GridFaces`).
//!
//! Node order per brick is CalculiX's: bottom face counter-clockwise seen
//! from +z, then the top face in the same order.

use std::sync::atomic::AtomicBool;

use glam::DVec3;
use volcad_core::Model;
use volcad_core::material::VOID;
use volcad_core::sampler::{Consumer, Grid, Sampler, Slab};

use super::topology::GridFaces;
use super::{FeaMesh, draw};
use crate::job::ExportError;

/// Largest grid the brick export samples.
const MAX_VOXELS: u128 = 4_000_000_000;
/// Layers sampled per slab.
const SLAB: usize = 8;

/// The brick grid for `voxel`.
pub fn grid(model: &Model, voxel: f64) -> Result<Grid, ExportError> {
    if !(voxel.is_finite() && voxel > 0.0) {
        return Err(ExportError::param(
            "--voxel",
            format!("the brick size must be > 0 mm, got {voxel}"),
        ));
    }
    Grid::covering(&model.bbox(), DVec3::splat(voxel), MAX_VOXELS)
        .map_err(crate::design::grid_error)
}

/// Mesh `model` into bricks of size `voxel`; materials drawn with `seed`,
/// keyed by the voxel's grid index.
pub fn brick_mesh(
    model: &Model,
    voxel: f64,
    seed: u64,
    max_elements: u64,
    cancel: &AtomicBool,
    progress: &(dyn Fn(&str, u64, u64, f64) + Sync),
) -> Result<FeaMesh, ExportError> {
    let grid = grid(model, voxel)?;
    let [nx, ny, nz] = grid.dims;
    // A brick is kept by the sign at its centre only.
    let sampler = Sampler::new(model, grid, Consumer::FeaBricks);
    let slots = model.materials();
    let mut mesh = FeaMesh::new(super::Element::C3D8R);
    let mut slab = Slab::default();
    // Brick mask and material slot of the previous and current voxel layer.
    let mut prev: Vec<u16> = vec![u16::MAX; nx * ny];
    let mut cur: Vec<u16> = vec![u16::MAX; nx * ny];
    // Node ids of corner layers k − 1 and k.
    let cw = nx + 1;
    let mut ids_lo: Vec<u32> = vec![u32::MAX; cw * (ny + 1)];
    let mut ids_hi: Vec<u32> = vec![u32::MAX; cw * (ny + 1)];
    let mut f = vec![0.0f64; slots.len()];
    let mut faces = GridFaces::new(nx, ny);
    for k in 0..=nz {
        if k < nz {
            if k.is_multiple_of(SLAB) {
                let z1 = (k + SLAB).min(nz);
                sampler
                    .sample_layers(k, z1, &mut slab, cancel)
                    .map_err(|_| ExportError::Cancelled)?;
                progress("sampling bricks", k as u64, nz as u64, k as f64 / nz as f64);
            }
            let base = (k - slab.z0) * nx * ny;
            for (v, c) in cur.iter_mut().enumerate() {
                *c = u16::MAX;
                if slab.dist[base + v] <= 0.0 {
                    for (o, s) in f.iter_mut().zip(slab.fracs_of(base + v)) {
                        *o = f64::from(*s);
                    }
                    let key = (k * nx * ny + v) as u64;
                    if let Some(s) = draw(&f, seed, key)
                        && slots[s] != VOID
                    {
                        *c = s as u16;
                    }
                }
            }
        } else {
            cur.fill(u16::MAX);
        }
        // Number corner layer k.
        let brick = |m: &[u16], i: usize, j: usize| i < nx && j < ny && m[j * nx + i] != u16::MAX;
        for j in 0..=ny {
            for i in 0..=nx {
                let mut used = false;
                for (di, dj) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                    if i >= di && j >= dj {
                        used |= brick(&prev, i - di, j - dj) || brick(&cur, i - di, j - dj);
                    }
                }
                ids_hi[j * cw + i] = if used {
                    mesh.nodes
                        .push(grid.origin + DVec3::new(i as f64, j as f64, k as f64) * grid.voxel);
                    (mesh.nodes.len() - 1) as u32
                } else {
                    u32::MAX
                };
            }
        }
        // Emit the bricks of voxel layer k − 1.
        if k > 0 {
            let first = mesh.len();
            for j in 0..ny {
                for i in 0..nx {
                    let s = prev[j * nx + i];
                    if s == u16::MAX {
                        continue;
                    }
                    let c = |lay: &[u32], di: usize, dj: usize| lay[(j + dj) * cw + i + di];
                    mesh.conn.extend([
                        c(&ids_lo, 0, 0),
                        c(&ids_lo, 1, 0),
                        c(&ids_lo, 1, 1),
                        c(&ids_lo, 0, 1),
                        c(&ids_hi, 0, 0),
                        c(&ids_hi, 1, 0),
                        c(&ids_hi, 1, 1),
                        c(&ids_hi, 0, 1),
                    ]);
                    mesh.mat.push(s);
                }
            }
            faces.layer(&mesh, first, &prev, &cur);
            if mesh.mat.len() as u64 > max_elements {
                return Err(ExportError::param(
                    "--voxel",
                    format!("more than {max_elements} bricks; use a larger brick size"),
                ));
            }
        }
        std::mem::swap(&mut prev, &mut cur);
        std::mem::swap(&mut ids_lo, &mut ids_hi);
    }
    mesh.topology = Some(faces.finish());
    let v = grid.voxel.x * grid.voxel.y * grid.voxel.z;
    mesh.notes.push(format!(
        "bricks: {} of {} × {} × {} voxels ({} mm); mesh volume {:.4} mm³",
        mesh.len(),
        nx,
        ny,
        nz,
        voxel,
        mesh.len() as f64 * v
    ));
    Ok(mesh)
}
