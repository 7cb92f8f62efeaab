//! Model → voxels for the GPU.
//!
//! `bake(model, resolution)` samples the model with the core grid sampler
//! (rayon-parallel, interval-culled) on a cubic-voxel grid covering the
//! bounding box plus two voxels of padding, then converts each slab to:
//!
//! - distance (mm) as f16 bits (uploaded as `R16Float`, filterable
//!   everywhere);
//! - colour: `Σ fᵢ·rgbᵢ / Σ fᵢ` and alpha `Σ fᵢ·aᵢ / Σ fᵢ` (`Rgba8Unorm`);
//! - fractions of up to [`MAX_CHANNELS`] materials (the first four of
//!   `Model::materials()`), for visibility and iso surfaces (`Rgba8Unorm`).
//!
//! A model whose value is not a distance bound (a math-string `Function`,
//! see `Model::distance_is_bound`) has its distance volume replaced by
//! signed distances from its zero crossings (`redistance`) first.
//!
//! Finally the colour and fraction volumes are dilated two voxels outwards
//! (26-neighbour average of inside voxels): trilinear lookups at the
//! surface, and on the slightly dilated surface the shader draws to keep thin
//! features, then read the part's own colour instead of a blend with "empty".

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use glam::{DVec3, Vec3};
use rayon::prelude::*;
use volcad_core::sampler::{Cancelled, Consumer, Grid, GridError, Sampler, Slab};
use volcad_core::{Aabb, MaterialId, Model};

use crate::attribute_bake::{AttributeEval, AttributeShading, shade};

/// Material fractions stored per voxel (one `Rgba8Unorm` texel).
pub const MAX_CHANNELS: usize = 4;

/// Voxels of padding around the bounding box on every side.
const PAD_VOXELS: f64 = 2.0;

/// Largest grid a bake may make (a 1024³ bake is 7 GiB of CPU memory).
const MAX_BAKE_VOXELS: u128 = 1 << 30;

/// Distance stored for an empty design (mm).
const FAR: f32 = 1.0e4;

/// Why a bake did not finish.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum BakeError {
    /// The cancel flag was set (a newer edit replaced the model).
    #[error("bake cancelled")]
    Cancelled,
    /// The design cannot be put on a grid (unbounded, or too large).
    #[error(transparent)]
    Grid(#[from] GridError),
    /// The shading attribute has a value outside its range.
    #[error("attribute: {0}")]
    Attribute(String),
}

impl From<Cancelled> for BakeError {
    fn from(_: Cancelled) -> Self {
        BakeError::Cancelled
    }
}

/// A model sampled on a regular grid, ready for upload.
///
/// Voxel `(i, j, k)` is at index `i + nx·(j + ny·k)`; its centre is
/// `origin + (i + ½, j + ½, k + ½)·voxel`.
#[derive(Clone, Debug)]
pub struct VolumeBake {
    /// Voxels per axis.
    pub dims: [u32; 3],
    /// Lowest corner of voxel (0, 0, 0) (mm).
    pub origin: Vec3,
    /// Voxel size per axis (mm; the bake uses cubes).
    pub voxel: Vec3,
    /// Signed distance per voxel (mm, negative inside) as IEEE f16 bits.
    pub distance: Vec<u16>,
    /// Mixed material colour per voxel (RGB 0-255) and mixed alpha; outside
    /// voxels near the surface carry the colour of the part next to them.
    pub color: Vec<[u8; 4]>,
    /// Fractions (0-255) of the materials listed in `channels`.
    pub fractions: Vec<[u8; 4]>,
    /// Model material index (into `materials`) of each fraction channel.
    pub channels: Vec<usize>,
    /// The model's materials (ids, ascending, `Model::materials()`).
    pub materials: Vec<MaterialId>,
    /// Colour (RGBA 0-255) of each model material.
    pub palette: Vec<[u8; 4]>,
    /// The model's bounding box (for overlays), empty for an empty design.
    pub bbox: Aabb,
    /// Edge of one voxel (mm).
    pub voxel_size_mm: f32,
    /// The requested resolution (voxels along the longest side).
    pub resolution: u32,
    /// Wall time of the bake (s).
    pub bake_seconds: f32,
    /// True when the model's value was not a distance and the distance
    /// volume holds distances rebuilt from its sign (`redistance`).
    pub redistanced: bool,
    /// In attribute mode, the range the scalar values were mapped over
    /// (the fixed range, or the baked values' smallest and largest).
    pub attribute_range: Option<[f64; 2]>,
    /// True when the colour volume was filled from an attribute.
    pub attribute_shaded: bool,
}

impl VolumeBake {
    /// Index of voxel (i, j, k).
    pub fn index(&self, i: u32, j: u32, k: u32) -> usize {
        (i + self.dims[0] * (j + self.dims[1] * k)) as usize
    }

    /// Distance at voxel (i, j, k) (mm).
    pub fn distance_at(&self, i: u32, j: u32, k: u32) -> f32 {
        half::f16::from_bits(self.distance[self.index(i, j, k)]).to_f32()
    }

    /// Total voxels.
    pub fn voxel_count(&self) -> usize {
        self.dims.iter().map(|d| *d as usize).product()
    }

    /// True when the design has no volume (nothing to draw).
    pub fn is_empty(&self) -> bool {
        self.bbox.is_empty()
    }

    /// The fraction channel holding model material `material_index`, if any.
    pub fn channel_of(&self, material_index: usize) -> Option<usize> {
        self.channels.iter().position(|c| *c == material_index)
    }

    /// World-space box of the grid (mm).
    pub fn grid_box(&self) -> (Vec3, Vec3) {
        let d = Vec3::new(
            self.dims[0] as f32,
            self.dims[1] as f32,
            self.dims[2] as f32,
        );
        (self.origin, self.origin + d * self.voxel)
    }

    fn empty(model: &Model, seconds: f32) -> VolumeBake {
        let n = 2usize * 2 * 2;
        VolumeBake {
            dims: [2, 2, 2],
            origin: Vec3::splat(-1.0),
            voxel: Vec3::ONE,
            distance: vec![half::f16::from_f32(FAR).to_bits(); n],
            color: vec![[0; 4]; n],
            fractions: vec![[0; 4]; n],
            channels: Vec::new(),
            materials: model.materials().to_vec(),
            palette: palette(model),
            bbox: Aabb::new(DVec3::ZERO, DVec3::ZERO),
            voxel_size_mm: 1.0,
            resolution: 0,
            bake_seconds: seconds,
            redistanced: false,
            attribute_range: None,
            attribute_shaded: false,
        }
    }
}

fn palette(model: &Model) -> Vec<[u8; 4]> {
    model
        .materials()
        .iter()
        .map(|id| {
            model
                .table()
                .get(*id)
                .map(|m| m.rgba())
                .unwrap_or([255, 0, 255, 255])
        })
        .collect()
}

/// Bake `model` with `resolution` voxels along the longest side of its
/// bounding box (cubic voxels, plus two voxels of padding per side).
///
/// Runs on the current rayon pool; checks `cancel` between rows of tiles.
/// An empty design gives an empty bake (nothing drawn), an unbounded one an
/// error.
pub fn bake(model: &Model, resolution: u32, cancel: &AtomicBool) -> Result<VolumeBake, BakeError> {
    bake_shaded(model, resolution, None, cancel)
}

/// [`bake`], with the colour volume from an attribute (see
/// [`crate::attribute_bake`]) when `shading` is given.
pub fn bake_shaded(
    model: &Model,
    resolution: u32,
    shading: Option<(&AttributeShading, &AttributeEval<'_>)>,
    cancel: &AtomicBool,
) -> Result<VolumeBake, BakeError> {
    let start = Instant::now();
    let bbox = model.bbox();
    if bbox.is_empty() {
        return Ok(VolumeBake::empty(model, start.elapsed().as_secs_f32()));
    }
    if !bbox.is_finite() {
        // Let the grid produce its "unbounded" message.
        Grid::covering(&bbox, DVec3::ONE, MAX_BAKE_VOXELS)?;
    }
    let resolution = resolution.max(2);
    let voxel = (bbox.size().max_element() / resolution as f64).max(1e-9);
    let grid = Grid::covering(
        &bbox.expand(PAD_VOXELS * voxel),
        DVec3::splat(voxel),
        MAX_BAKE_VOXELS,
    )?;
    let [nx, ny, nz] = grid.dims;
    let layer = nx * ny;
    let n = layer * nz;

    let k = model.materials().len();
    let pal = palette(model);
    let channels: Vec<usize> = (0..k.min(MAX_CHANNELS)).collect();
    let mut distance = vec![0u16; n];
    let mut color = vec![[0u8; 4]; n];
    let mut fractions = vec![[0u8; 4]; n];

    let sampler = Sampler::new(model, grid, Consumer::ViewportBake);
    let mut slab = Slab::default();
    let layers_per_slab = (1usize << 18).div_ceil(layer).clamp(1, nz);
    let mut z0 = 0;
    while z0 < nz {
        if cancel.load(Ordering::Relaxed) {
            return Err(BakeError::Cancelled);
        }
        let z1 = (z0 + layers_per_slab).min(nz);
        sampler.sample_layers(z0, z1, &mut slab, cancel)?;
        let range = z0 * layer..z1 * layer;
        let slab = &slab;
        distance[range.clone()]
            .par_chunks_mut(nx)
            .zip(color[range.clone()].par_chunks_mut(nx))
            .zip(fractions[range].par_chunks_mut(nx))
            .enumerate()
            .for_each(|(row, ((d, c), f))| {
                let v0 = row * nx;
                for x in 0..nx {
                    let v = v0 + x;
                    d[x] = half::f16::from_f32(slab.dist[v].clamp(-60000.0, 60000.0)).to_bits();
                    if k > 0 {
                        (c[x], f[x]) = mix(slab.fracs_of(v), &pal, &channels);
                    }
                }
            });
        z0 = z1;
    }
    let attribute_range = match shading {
        Some((shading, eval)) => {
            let inside = |v: usize| half::f16::from_bits(distance[v]).to_f32() <= 0.0;
            shade(&grid, &inside, shading, eval, &mut color, cancel)?
        }
        None => None,
    };
    let redistanced = !model.distance_is_bound()
        && redistance_if_needed(&mut distance, grid.dims, voxel as f32, cancel)?;
    dilate(
        &mut color,
        &mut fractions,
        &distance,
        grid.dims,
        voxel as f32,
        cancel,
    )?;

    Ok(VolumeBake {
        dims: [nx as u32, ny as u32, nz as u32],
        origin: grid.origin.as_vec3(),
        voxel: grid.voxel.as_vec3(),
        distance,
        color,
        fractions,
        channels,
        materials: model.materials().to_vec(),
        palette: pal,
        bbox,
        voxel_size_mm: voxel as f32,
        resolution,
        bake_seconds: start.elapsed().as_secs_f32(),
        redistanced,
        attribute_range,
        attribute_shaded: shading.is_some(),
    })
}

/// Redistance the f16 distance volume of a model that is not a distance
/// bound when its slope says the tracer cannot use it as it is; true when
/// it did.
fn redistance_if_needed(
    distance: &mut [u16],
    dims: [usize; 3],
    voxel: f32,
    cancel: &AtomicBool,
) -> Result<bool, BakeError> {
    let mut field: Vec<f32> = distance
        .par_iter()
        .map(|b| half::f16::from_bits(*b).to_f32())
        .collect();
    if !crate::redistance::needs_redistance(&field, dims[0], voxel) {
        return Ok(false);
    }
    crate::redistance::redistance(&mut field, dims, voxel, cancel)?;
    distance
        .par_iter_mut()
        .zip(field.par_iter())
        .for_each(|(d, f)| *d = half::f16::from_f32(f.clamp(-60000.0, 60000.0)).to_bits());
    Ok(true)
}

/// Mixed colour and channel fractions of one voxel.
fn mix(fr: &[f32], pal: &[[u8; 4]], channels: &[usize]) -> ([u8; 4], [u8; 4]) {
    let sum: f32 = fr.iter().map(|f| f.max(0.0)).sum();
    if sum <= 1e-6 {
        return ([0; 4], [0; 4]);
    }
    let mut acc = [0.0f32; 4];
    for (f, p) in fr.iter().zip(pal) {
        let w = f.max(0.0);
        if w > 0.0 {
            for c in 0..4 {
                acc[c] += w * p[c] as f32;
            }
        }
    }
    let norm = 1.0 / sum;
    let color = acc.map(|a| (a * norm).round().clamp(0.0, 255.0) as u8);
    let scale = 255.0 / sum.max(1.0);
    let mut fo = [0u8; 4];
    for (o, ch) in fo.iter_mut().zip(channels) {
        *o = (fr[*ch].max(0.0) * scale).round().clamp(0.0, 255.0) as u8;
    }
    (color, fo)
}

/// Two passes of 26-neighbour dilation of the colour and fraction volumes
/// into outside voxels within three voxels of the surface.
fn dilate(
    color: &mut [[u8; 4]],
    fractions: &mut [[u8; 4]],
    distance: &[u16],
    dims: [usize; 3],
    voxel: f32,
    cancel: &AtomicBool,
) -> Result<(), BakeError> {
    let [nx, ny, nz] = dims;
    let near = 3.0 * voxel;
    let mut filled: Vec<bool> = color
        .par_iter()
        .zip(fractions.par_iter())
        .map(|(c, f)| c[3] > 0 || f.iter().any(|v| *v > 0))
        .collect();
    for _pass in 0..2 {
        if cancel.load(Ordering::Relaxed) {
            return Err(BakeError::Cancelled);
        }
        let updates: Vec<(usize, [u8; 4], [u8; 4])> = (0..nz)
            .into_par_iter()
            .flat_map_iter(|z| {
                let (color, fractions, filled) = (&*color, &*fractions, &filled);
                let mut out = Vec::new();
                for y in 0..ny {
                    for x in 0..nx {
                        let v = x + nx * (y + ny * z);
                        if filled[v] || half::f16::from_bits(distance[v]).to_f32() > near {
                            continue;
                        }
                        let (mut c, mut f, mut count) = ([0u32; 4], [0u32; 4], 0u32);
                        for dz in z.saturating_sub(1)..(z + 2).min(nz) {
                            for dy in y.saturating_sub(1)..(y + 2).min(ny) {
                                for dx in x.saturating_sub(1)..(x + 2).min(nx) {
                                    let u = dx + nx * (dy + ny * dz);
                                    if filled[u] {
                                        count += 1;
                                        for i in 0..4 {
                                            c[i] += color[u][i] as u32;
                                            f[i] += fractions[u][i] as u32;
                                        }
                                    }
                                }
                            }
                        }
                        if count > 0 {
                            let avg = |a: [u32; 4]| a.map(|s| ((s + count / 2) / count) as u8);
                            out.push((v, avg(c), avg(f)));
                        }
                    }
                }
                out
            })
            .collect();
        for (v, c, f) in updates {
            color[v] = c;
            fractions[v] = f;
            filled[v] = true;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mix_normalises_and_keeps_channels() {
        let pal = [[255, 0, 0, 255], [0, 0, 255, 255]];
        let (c, f) = mix(&[0.25, 0.75], &pal, &[0, 1]);
        assert_eq!(c, [64, 0, 191, 255]);
        assert_eq!(f, [64, 191, 0, 0]);
        assert_eq!(mix(&[0.0, 0.0], &pal, &[0, 1]), ([0; 4], [0; 4]));
    }
}
