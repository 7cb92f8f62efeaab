//! Full-colour inkjet stacks (`volcad export png --full-color`): each
//! voxel one of the printer's colour resins (J750: cyan, magenta, yellow,
//! black, white, clear) so that the part's `color` reproduces by error
//! diffusion in OKLab (see [`diffuse`]).
//!
//! The wanted colour of a voxel is the design's `color` attribute (RGBA,
//! 0-1, sRGB) there; where no node sets it, the colours of its materials
//! mixed by their fractions (in OKLab, so a 50/50 mix of two resin-coloured
//! materials comes out as half of each). An opaque colour outside what the
//! resins can average to is clipped toward the grey of its lightness (see
//! [`oklab::Gamut`]); alpha below 1 blends toward the clear resin:
//! `α·(colour, 1) + (1 − α)·(clear, its opacity)` in `[L, a, b, opacity]`.
//! The stack's files are those of a material stack (one PNG per layer,
//! pixels in the resins' table colours; bitmaps per resin), and its
//! manifest counts voxels per resin.

pub mod diffuse;
pub mod oklab;
pub mod profile;

use std::ops::Range;

use rayon::prelude::*;
use volcad_core::sampler::{Consumer, Grid, Sampler};
use volcad_core::{Model, Points};

use crate::design::palette;
use crate::dither::MIN_TOTAL;
use crate::job::{ExportError, JobContext};
use crate::png_stack::{self, Estimate, PngParams};
pub use diffuse::{CHANNELS, Ink};
pub use profile::{J750_COLOR_RESINS, Resin, resins};

/// The attribute a full-colour stack reproduces.
pub const COLOR: &str = "color";

/// Everything the per-voxel choice needs, built once per export.
pub struct ColorPlan {
    /// The resins, in code order (code `i + 1` is `resins[i]`).
    pub resins: Vec<Resin>,
    inks: Vec<Ink>,
    gamut: Option<oklab::Gamut>,
    clear: Option<Ink>,
    attr: Option<usize>,
    /// Wanted colour of each material slot (its table colour).
    materials: Vec<Ink>,
    /// Seed of the diffusion's offsets (see [`diffuse`]).
    seed: u64,
}

impl ColorPlan {
    /// The plan for `model` with the resins of `p` (its profile, if any).
    pub fn new(model: &Model, p: &PngParams) -> Result<ColorPlan, ExportError> {
        let resins = resins(p.color_profile.as_deref())?;
        let ink =
            |r: &Resin| -> Ink { [r.lab[0], r.lab[1], r.lab[2], r.opacity].map(|v| v as f32) };
        let opaque: Vec<oklab::Lab> = resins
            .iter()
            .filter(|r| r.opacity >= 0.5)
            .map(|r| r.lab)
            .collect();
        // The most transparent resin, if it is transparent at all.
        let clear = resins
            .iter()
            .filter(|r| r.opacity < 0.5)
            .min_by(|a, b| a.opacity.total_cmp(&b.opacity))
            .map(ink);
        let attr = model.attribute_index(COLOR);
        let mut plan = ColorPlan {
            inks: resins.iter().map(ink).collect(),
            resins,
            gamut: oklab::Gamut::new(&opaque),
            clear,
            attr,
            materials: Vec::new(),
            seed: p.seed,
        };
        plan.materials = palette(model)?
            .iter()
            .skip(1)
            .map(|c| plan.wanted(c.map(|v| f64::from(v) / 255.0)))
            .collect();
        Ok(plan)
    }

    /// The point `[L, a, b, opacity]` that sRGB `rgba` (0-1) asks for.
    pub fn wanted(&self, rgba: [f64; 4]) -> Ink {
        let lab = oklab::from_srgb([rgba[0], rgba[1], rgba[2]]);
        let lab = self.gamut.as_ref().map_or(lab, |g| g.map(lab));
        let opaque = [lab[0], lab[1], lab[2], 1.0].map(|v| v as f32);
        match self.clear {
            Some(c) if rgba[3] < 1.0 => {
                let a = rgba[3] as f32;
                [0, 1, 2, 3].map(|i| a * opaque[i] + (1.0 - a) * c[i])
            }
            _ => opaque,
        }
    }

    /// The resins as points, in code order.
    pub fn inks(&self) -> &[Ink] {
        &self.inks
    }

    /// Wanted colours and inside flags of layer `z` from its distances and
    /// fractions (`k` a voxel); the first attribute error in row order.
    fn wanted_layer(
        &self,
        model: &Model,
        grid: &Grid,
        z: usize,
        (dist, fracs): (&[f32], &[f32]),
        wanted: &mut [Ink],
        inside: &mut [bool],
    ) -> Result<(), ExportError> {
        let [nx, ny, _] = grid.dims;
        let k = model.materials().len();
        let mut xs = Vec::with_capacity(nx);
        let mut rgba = Vec::with_capacity(nx * 4);
        for y in 0..ny {
            let row = y * nx..(y + 1) * nx;
            xs.clear();
            xs.extend(row.clone().filter(|v| dist[*v] <= 0.0));
            rgba.clear();
            rgba.resize(xs.len() * 4, f64::NAN);
            if let Some(a) = self.attr {
                let c = grid.center(0, y, z);
                let px: Vec<f64> = xs.iter().map(|v| grid.center(v - y * nx, y, z).x).collect();
                let (py, pz) = (vec![c.y; xs.len()], vec![c.z; xs.len()]);
                let pts = Points {
                    x: &px,
                    y: &py,
                    z: &pz,
                };
                model
                    .attribute_batch(a, pts, &mut rgba)
                    .map_err(|e| ExportError::param("design", e.to_string()))?;
            }
            inside[row.clone()].fill(false);
            for (v, c) in xs.iter().zip(rgba.chunks_exact(4)) {
                let nan = c.iter().filter(|x| x.is_nan()).count();
                if nan == 0 {
                    wanted[*v] = self.wanted([c[0], c[1], c[2], c[3]]);
                    inside[*v] = true;
                    continue;
                }
                if nan < 4 {
                    let p = grid.center(v - y * nx, y, z);
                    return Err(ExportError::param(
                        "design",
                        format!(
                            "\"color\" is {c:?} at ({:.4}, {:.4}, {:.4}) mm: a component is not a number; give four numbers in 0-1",
                            p.x, p.y, p.z
                        ),
                    ));
                }
                // No node sets `color` here: the materials' mix.
                let f = &fracs[v * k..(v + 1) * k];
                let total: f32 = f.iter().sum();
                if total > MIN_TOTAL {
                    let mut w = [0.0f32; CHANNELS];
                    for (fi, m) in f.iter().zip(&self.materials) {
                        for c in 0..CHANNELS {
                            w[c] += fi / total * m[c];
                        }
                    }
                    wanted[*v] = w;
                    inside[*v] = true;
                }
            }
        }
        Ok(())
    }
}

/// Bytes held per voxel of a slab: distance, fractions, wanted colour,
/// inside flag and code.
pub fn bytes_per_voxel(k: usize) -> usize {
    4 + 4 * k + 4 * CHANNELS + 2
}

/// Check the design's colours before any work: the profile, and `color`
/// at the centres of a coarse grid (a value outside 0-1 is refused there,
/// naming the node, point and value).
pub fn check(model: &Model, p: &PngParams) -> Result<ColorPlan, ExportError> {
    let plan = ColorPlan::new(model, p)?;
    if let Some(a) = plan.attr {
        let b = model.bbox();
        let n = crate::estimate::COARSE_CELLS;
        let step = b.size() / n as f64;
        let mut out = [0.0; 4];
        for i in 0..n * n * n {
            let q = glam::DVec3::new((i % n) as f64, (i / n % n) as f64, (i / n / n) as f64);
            model
                .attribute_at(a, b.min + (q + 0.5) * step, &mut out)
                .map_err(|e| ExportError::param("design", e.to_string()))?;
        }
    }
    Ok(plan)
}

/// Sample and diffuse the stack's layers one slab at a time and hand each
/// slab's layers to `f`: the global layer range and one code per voxel (x
/// fastest, then y, then layer; 0 = void, `i + 1` = `plan.resins[i]`).
/// Layers are diffused in parallel, each on its own.
pub(crate) fn for_each_slab(
    model: &Model,
    plan: &ColorPlan,
    est: &Estimate,
    ctx: &JobContext,
    mut f: impl FnMut(Range<usize>, &[u8]) -> Result<(), ExportError>,
) -> Result<(), ExportError> {
    let grid = est.grid;
    let layer = grid.layer_len();
    let k = model.materials().len();
    // Fractions only where `color` is not set everywhere they are needed.
    let sampler = Sampler::new(model, grid, Consumer::PngStackFullColor);
    let mut codes = vec![0u8; est.slab_layers * layer];
    let mut wanted = vec![[0.0f32; CHANNELS]; est.slab_layers * layer];
    let mut inside = vec![false; est.slab_layers * layer];
    let layers = est.layers.clone();
    png_stack::sample_slabs(&sampler, layers, est.slab_layers, ctx, |z0, z1, slab| {
        let n = (z1 - z0) * layer;
        let results: Vec<Result<(), ExportError>> = codes[..n]
            .par_chunks_mut(layer)
            .zip(wanted[..n].par_chunks_mut(layer))
            .zip(inside[..n].par_chunks_mut(layer))
            .enumerate()
            .map(|(l, ((c, w), ins))| {
                let v = l * layer;
                let df = (
                    &slab.dist[v..v + layer],
                    &slab.fracs[v * k..(v + layer) * k],
                );
                plan.wanted_layer(model, &grid, z0 + l, df, w, ins)?;
                let first = ((z0 + l) * layer) as u64;
                let jitter = Some((plan.seed, first));
                diffuse::diffuse_layer(grid.dims[0], w, ins, &plan.inks, jitter, c);
                Ok(())
            })
            .collect();
        // The lowest layer's error, whatever the thread count.
        results.into_iter().collect::<Result<Vec<()>, _>>()?;
        ctx.check_cancel()?;
        f(z0..z1, &codes[..n])
    })
}

/// The manifest's record of the resins: names and the OKLab colours the
/// choice used (so a profile's effect is on record).
pub fn resins_json(plan: &ColorPlan) -> serde_json::Value {
    plan.resins
        .iter()
        .map(|r| {
            let lab = r.lab.map(|v| (v * 1e5).round() / 1e5);
            serde_json::json!({ "name": r.name, "oklab": lab, "opacity": r.opacity })
        })
        .collect()
}
