//! A coarse look at a design before an export, for size estimates: how much
//! of the box is inside, how much of that is a mix of materials, and about
//! how much surface there is.
//!
//! The design is sampled on at most [`COARSE_CELLS`]³ voxels (through the one
//! sampler). The surface area is estimated from sign changes between
//! neighbouring samples: each change along axis `a` stands for one voxel face
//! of area `Π_{b≠a} h_b`; summed, that is the area of the blocky (cuberille)
//! surface, about 3/2 of the true area for a surface with random
//! orientation, so the sum is scaled by 2/3.

use std::ops::Range;
use std::sync::atomic::AtomicBool;

use glam::DVec3;
use volcad_core::Model;
use volcad_core::sampler::{Consumer, Grid, Sampler, Slab};

/// Samples per axis of the coarse grid (at most).
pub const COARSE_CELLS: usize = 40;

/// How closely an export's estimate looks at the design.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Look {
    /// The coarse grid and rules of thumb only (about a millisecond): what
    /// an export job checks up front.
    Coarse,
    /// Also a few layers sampled at the export's own voxel size and run
    /// through its next steps (meshes contour them, slice stacks encode
    /// them): what the estimates shown before an export use, and the CLI
    /// checks with. Parts thinner than the coarse grid's cells, and layers that
    /// compress worse than the rule says, show there.
    Layers,
}

/// Layers an estimate samples: the middles of `picks` equal stretches of
/// `layers` (fewer when the range is shorter).
pub fn sampled_layers(layers: Range<usize>, picks: usize) -> impl Iterator<Item = usize> {
    let picks = picks.min(layers.len());
    (0..picks).map(move |i| layers.start + (2 * i + 1) * layers.len() / (2 * picks))
}

/// What the coarse grid saw.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CoarseEstimate {
    /// Share of the box inside the part, 0..=1.
    pub inside: f64,
    /// Share of the box inside with no material at 99% or more, 0..=1.
    pub mixed: f64,
    /// Estimated surface area (mm²) inside the box.
    pub surface_mm2: f64,
    /// Area of the part's faces on its bounding box (mm²): planar, so a
    /// mesh export merges them into few triangles.
    pub flat_mm2: f64,
    /// The coarse grid's voxel (mm): parts thinner than this may be missed.
    pub cell: DVec3,
}

/// Sample `model` coarsely over its bounding box with voxels no finer than
/// `voxel`; the default (all zero) for an unbounded or empty box. Kept
/// with the model ([`Model::derived`]): an export's estimate and its job
/// both ask.
pub fn coarse_estimate(model: &Model, voxel: DVec3) -> CoarseEstimate {
    let key = voxel.to_array().map(f64::to_bits);
    model.derived(key, || sampled_coarse(model, voxel))
}

fn sampled_coarse(model: &Model, voxel: DVec3) -> CoarseEstimate {
    let bbox = model.bbox();
    let coarse = (bbox.size() / COARSE_CELLS as f64).max(voxel);
    let Ok(grid) = Grid::covering(&bbox, coarse, (COARSE_CELLS as u128 + 1).pow(3)) else {
        return CoarseEstimate::default();
    };
    let [nx, ny, nz] = grid.dims;
    // Counts read signs only.
    let sampler = Sampler::new(model, grid, Consumer::Estimate);
    let mut slab = Slab::default();
    if sampler
        .sample_layers(0, nz, &mut slab, &AtomicBool::new(false))
        .is_err()
    {
        return CoarseEstimate::default();
    }
    let k = slab.k;
    let inside = |v: usize| slab.dist[v] <= 0.0;
    let (mut n_in, mut n_mixed) = (0usize, 0usize);
    let mut crossings = [0usize; 3];
    let mut on_box = [0usize; 3];
    for z in 0..nz {
        for y in 0..ny {
            for x in 0..nx {
                let v = (z * ny + y) * nx + x;
                if inside(v) {
                    n_in += 1;
                    let f = slab.fracs_of(v);
                    let total: f32 = f.iter().sum();
                    if k > 1 && f.iter().all(|fi| *fi < 0.99 * total) {
                        n_mixed += 1;
                    }
                }
                let dims = [nx, ny, nz];
                for (a, (c, step)) in [(x, 1), (y, nx), (z, nx * ny)].into_iter().enumerate() {
                    if c > 0 && inside(v) != inside(v - step) {
                        crossings[a] += 1;
                    }
                    // Beyond the box there is no part: an inside sample on
                    // the grid's edge has a face there (a box-shaped part
                    // fills its box and has no other crossings at all).
                    if inside(v) && (c == 0 || c + 1 == dims[a]) {
                        on_box[a] += 1 + usize::from(dims[a] == 1);
                    }
                }
            }
        }
    }
    let total = (nx * ny * nz) as f64;
    let h = grid.voxel;
    let faces = [h.y * h.z, h.x * h.z, h.x * h.y];
    let area =
        |counts: [usize; 3]| -> f64 { counts.iter().zip(faces).map(|(c, a)| *c as f64 * a).sum() };
    CoarseEstimate {
        inside: n_in as f64 / total,
        mixed: n_mixed as f64 / total,
        surface_mm2: area(crossings) * 2.0 / 3.0,
        // Axis-aligned: the cuberille area is the true area.
        flat_mm2: area(on_box),
        cell: h,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sampled_layers_are_middles_of_equal_stretches() {
        assert_eq!(sampled_layers(0..99, 3).collect::<Vec<_>>(), [16, 49, 82]);
        assert_eq!(sampled_layers(10..12, 3).collect::<Vec<_>>(), [10, 11]);
        assert_eq!(sampled_layers(5..6, 3).collect::<Vec<_>>(), [5]);
        assert_eq!(sampled_layers(4..4, 3).count(), 0);
    }

    #[test]
    fn sphere_coarse_estimate_is_about_right() {
        let src = "let m = default_materials(); Sphere(Vec3(0,0,0), 10, m.id(\"red\"))";
        let d = volcad_core::script::run_script(src, "t.rhai", &Default::default()).unwrap();
        let model = Model::prepare(&d.root, d.materials.clone()).unwrap();
        let p = coarse_estimate(&model, DVec3::splat(0.1));
        // Sphere in its box: π/6 ≈ 0.524 inside; area 4π·100 ≈ 1257 mm².
        assert!((p.inside - 0.524).abs() < 0.05, "{p:?}");
        assert_eq!(p.mixed, 0.0);
        assert!((p.surface_mm2 / 1257.0 - 1.0).abs() < 0.25, "{p:?}");
        // It touches its box only at six points (a little more at the
        // coarse grid's resolution).
        assert!(p.flat_mm2 < 0.1 * 1257.0, "{p:?}");
    }

    #[test]
    fn a_part_that_fills_its_box_has_surface() {
        let src =
            "let m = default_materials(); RectPrism(Vec3(0,0,0), Vec3(10,10,10), m.id(\"red\"))";
        let d = volcad_core::script::run_script(src, "t.rhai", &Default::default()).unwrap();
        let model = Model::prepare(&d.root, d.materials.clone()).unwrap();
        let p = coarse_estimate(&model, DVec3::splat(0.1));
        // Its 600 mm² all lie on its box.
        assert!(p.inside > 0.9, "{p:?}");
        assert!((p.flat_mm2 / 600.0 - 1.0).abs() < 0.05, "{p:?}");
        assert_eq!(p.surface_mm2, 0.0);
    }
}
