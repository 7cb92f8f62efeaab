//! What a slice stack is asked for: the voxel, the material choice, the
//! layers and the extra outputs ([`PngParams`]), shared by the PNG stack,
//! the full-colour stack and the studio's panel.

use std::ops::Range;
use std::path::PathBuf;

use glam::DVec3;

use crate::bitmaps::BitmapFormat;
use crate::presets::presets;
use crate::shard::Shard;

/// How each voxel's material is chosen from its fractions.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Dither {
    /// Seeded random choice, keyed by the voxel's global index.
    #[default]
    Random,
    /// 3D vector error diffusion (smoother gradients).
    Diffusion,
}

impl Dither {
    /// The CLI spelling.
    pub fn name(self) -> &'static str {
        match self {
            Dither::Random => "random",
            Dither::Diffusion => "diffusion",
        }
    }
}

/// Parameters of a slice stack.
#[derive(Clone, Debug, PartialEq)]
pub struct PngParams {
    /// Voxel size (mm) per axis.
    pub voxel: DVec3,
    /// Seed of the random choice.
    pub seed: u64,
    /// Material choice.
    pub dither: Dither,
    /// Global layers to write (`None`: all).
    pub layers: Option<Range<usize>>,
    /// Write only this shard's layers (K-th of N equal ranges, see
    /// [`crate::shard`]); exclusive with `layers`.
    pub shard: Option<Shard>,
    /// Also write one folder of 1-bit PNGs per material.
    pub per_material_bitmaps: bool,
    /// Worker threads (`None`: all cores).
    pub threads: Option<usize>,
    /// Remove the liquid material within this distance (mm) of the
    /// surface (see [`crate::keep_out`]).
    pub liquid_keep_out: Option<f64>,
    /// One colour resin per voxel reproducing the design's `color` (see
    /// [`crate::color`]) instead of its materials.
    pub full_color: bool,
    /// Measured resin colours for `full_color` (see [`crate::color::profile`]).
    pub color_profile: Option<PathBuf>,
    /// File format of the per-material bitmaps.
    pub bitmap_format: BitmapFormat,
    /// Fixed width (px) of BMP bitmaps, the layer at the left.
    pub bitmap_width: Option<usize>,
}

impl Default for PngParams {
    /// The J750 preset, seed 0, random choice, all layers, RGBA only.
    fn default() -> Self {
        Self {
            voxel: presets()[0].voxel,
            seed: 0,
            dither: Dither::Random,
            layers: None,
            shard: None,
            per_material_bitmaps: false,
            threads: None,
            liquid_keep_out: None,
            full_color: false,
            color_profile: None,
            bitmap_format: BitmapFormat::Png,
            bitmap_width: None,
        }
    }
}
