//! Liquid keep-out (pyvcad 2.3.4's `liquid_keep_out`): the liquid material
//! (named `liquid`, or the J750's cleaning fluid `M.Cleanser`) is removed
//! within a distance of the part's surface, so no liquid pocket opens onto
//! the outside; a voxel where nothing else remains is void, elsewhere the
//! remaining fractions are drawn from.
//!
//! As pyvcad measures it, the liquid stays only where the distance is
//! strictly below −keep-out (a voxel exactly at −keep-out loses it).

use rayon::prelude::*;
use volcad_core::Model;
use volcad_core::sampler::{Consumer, Grid, Sampler, Slab};

use crate::design::grid_for;
use crate::dither::MIN_TOTAL;
use crate::job::ExportError;

/// Names that mark the liquid material (compared ignoring case).
pub const LIQUID_NAMES: [&str; 2] = ["liquid", "M.Cleanser"];
/// Cells of the grid the up-front check samples.
const CHECK_CELLS: f64 = 262_144.0;

/// The keep-out of one export.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KeepOut {
    /// The liquid's slot in `Model::materials()`.
    pub slot: usize,
    /// Distance from the surface (mm).
    pub distance: f32,
}

/// The keep-out `distance` asks for on `model`, checked: a positive finite
/// distance, a liquid material in the design, and something left of the
/// part once the liquid near its surface is gone (sampled on a coarse
/// grid, before any work).
pub fn plan(model: &Model, distance: Option<f64>) -> Result<Option<KeepOut>, ExportError> {
    let Some(d) = distance else { return Ok(None) };
    let opt = "--liquid-keep-out";
    if !(d.is_finite() && d > 0.0 && d < 1e6) {
        return Err(ExportError::param(
            opt,
            format!("{d}: give a distance in mm, > 0"),
        ));
    }
    let table = model.table();
    let slot = model
        .materials()
        .iter()
        .position(|id| LIQUID_NAMES.iter().any(|n| table.name(*id).eq_ignore_ascii_case(n)))
        .ok_or_else(|| {
            let names: Vec<&str> = model.materials().iter().map(|id| table.name(*id)).collect();
            ExportError::param(
                opt,
                format!(
                    "the design has no liquid material (named liquid or M.Cleanser; it uses {}); leave the option out",
                    names.join(", ")
                ),
            )
        })?;
    let k = KeepOut {
        slot,
        distance: d as f32,
    };
    check_not_emptied(model, &k)?;
    Ok(Some(k))
}

/// Refuses a keep-out that leaves no voxel of the part: every point of it
/// within the distance of the surface holds liquid alone.
fn check_not_emptied(model: &Model, k: &KeepOut) -> Result<(), ExportError> {
    let size = crate::design::bounded_box(model)?.size();
    let cell = (size.x * size.y * size.z / CHECK_CELLS).cbrt();
    let grid: Grid = grid_for(model, glam::DVec3::splat(cell), 0.0)?;
    let mut slab = Slab::default();
    Sampler::new(model, grid, Consumer::PngStackKeepOut)
        .sample_layers(
            0,
            grid.dims[2],
            &mut slab,
            &std::sync::atomic::AtomicBool::new(false),
        )
        .map_err(|_| ExportError::Cancelled)?;
    let n = model.materials().len();
    let [nx, ny, _] = grid.dims;
    // Deep inside, the sampler stores a bound: the truth is evaluated.
    let depth =
        |v: usize| -model.distance(grid.center(v % nx, (v / nx) % ny, v / (nx * ny))) as f32;
    let mut deepest = 0.0f32;
    let kept = slab.dist.iter().enumerate().any(|(v, d)| {
        if *d > 0.0 {
            return false;
        }
        let f = &slab.fracs[v * n..(v + 1) * n];
        let other: f32 = f
            .iter()
            .enumerate()
            .filter(|(i, _)| *i != k.slot)
            .map(|(_, x)| x)
            .sum();
        let deep = depth(v);
        deepest = deepest.max(deep);
        other > MIN_TOTAL || deep > k.distance
    });
    if kept {
        Ok(())
    } else {
        Err(ExportError::param(
            "--liquid-keep-out",
            format!(
                "{} mm removes the whole part: it is liquid only and at most {:.3} mm deep; use a distance below that",
                k.distance, deepest
            ),
        ))
    }
}

/// Applies the keep-out to the voxels of a slab of `grid` from layer `z0`
/// (`dist` one per voxel, `fracs` `n` per voxel): the liquid's fraction
/// goes where the distance is at least −distance; a voxel left with
/// nothing becomes void (distance +1). The sampler stores a bound (nearer
/// zero than the truth) deep inside the part, so a voxel the bound puts
/// within reach is evaluated before its liquid goes.
pub fn apply(
    k: &KeepOut,
    model: &Model,
    grid: &Grid,
    z0: usize,
    dist: &mut [f32],
    fracs: &mut [f32],
) {
    let n = model.materials().len();
    let [nx, ny, _] = grid.dims;
    dist.par_chunks_mut(nx)
        .zip(fracs.par_chunks_mut(nx * n))
        .enumerate()
        .for_each(|(row, (d, f))| {
            let (y, z) = (row % ny, z0 + row / ny);
            for (x, (d, f)) in d.iter_mut().zip(f.chunks_exact_mut(n)).enumerate() {
                if *d > 0.0 || *d < -k.distance || f[k.slot] <= 0.0 {
                    continue;
                }
                if (model.distance(grid.center(x, y, z)) as f32) < -k.distance {
                    continue;
                }
                f[k.slot] = 0.0;
                if f.iter().sum::<f32>() <= MIN_TOTAL {
                    *d = 1.0;
                }
            }
        });
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn liquid_goes_near_the_surface_only() {
        // A liquid sphere of radius 2 (the VeroCyan one under it never
        // shows: the first child wins), sampled along x through the centre:
        // liquid stays where it is deeper than 1 mm, goes (void) elsewhere.
        let m = volcad_core::script::model_of(
            r#"let m = j750_materials(); Union(false, [Sphere(Vec3(0,0,0), 2, m.id("M.Cleanser")), Sphere(Vec3(0,0,0), 2, m.id("VeroCyan"))])"#,
            "t.rhai",
            &volcad_core::script::ScriptOptions::default(),
        )
        .unwrap();
        let grid = Grid {
            origin: glam::DVec3::new(-2.0, -0.5, -0.5),
            voxel: glam::DVec3::ONE,
            dims: [4, 1, 1],
        };
        let k = plan(&m, Some(1.0)).unwrap().unwrap();
        // Sampled bounds nearer zero than the truth (−0.5 for all).
        let mut dist = [-0.5f32; 4];
        let mut fracs = vec![0.0f32; 8];
        for v in 0..4 {
            fracs[v * 2 + k.slot] = 1.0;
        }
        apply(&k, &m, &grid, 0, &mut dist, &mut fracs);
        // Centres at x = −1.5, −0.5, 0.5, 1.5: depths 0.5, 1.5, 1.5, 0.5.
        assert_eq!(dist, [1.0, -0.5, -0.5, 1.0]);
    }
}
