//! # volcad-render
//!
//! The Volcad viewport: a prepared [`Model`] is **baked** on worker threads
//! into 3D textures and **ray-marched** by a WGSL fragment shader, inside the
//! egui viewport (an egui-wgpu paint callback) or offscreen into an image.
//!
//! Data flow:
//!
//! ```text
//! Arc<Model> ──ProgressiveBaker (thread; core sampler, rayon)──► Arc<VolumeBake> 64³, 128³, 256³
//!            ──Renderer::upload (write_texture, once per bake)──► distance R16Float,
//!                                                                colour + fractions Rgba8Unorm
//! ViewSettings ──Renderer::prepare (one uniform write per frame)──► Renderer::paint
//!              (one fullscreen triangle: sphere tracing, shading, cut plane, overlays)
//! ```
//!
//! The frame cost depends on the image size and the bake resolution, never
//! on the design's node count: the shader only samples textures.
//!
//! - [`Camera`], [`StandardView`]: orbit camera, standard views, rays.
//! - [`ViewSettings`], [`ViewMode`], [`CutPlane`]: what to show.
//! - [`bake`], [`VolumeBake`], [`ProgressiveBaker`]: model → voxels.
//! - [`Renderer`]: pipelines and textures, created once per device.
//! - [`viewport`]: the egui-wgpu paint callback.
//! - [`render_offscreen`], [`Offscreen`]: own device, image out (tests, CLI).
//! - [`pick`]: exact CPU ray cast for the cursor read-out.
//!
//! **Modes.** Solid: opaque lit surface, colour = fraction-weighted mix of
//! the material colours (materials with very low alpha, like `clear`, keep
//! their light colour). Volume: front-to-back accumulation, density scaled by
//! each material's alpha (at least 0.08) and opacity. Iso: the surface where
//! one material's fraction equals a level. A cut plane removes one side; the
//! cut face shows the colours inside. Fractions of the first four materials
//! are kept per voxel (hiding and iso work for those); colours use all.
//!
//! **Thin features.** Sampling a distance field at voxel centres loses
//! features thinner than a voxel. The shader draws the surface at
//! `d = THIN_BIAS_VOXELS · voxel` instead of 0 (a dilation by a quarter of a
//! voxel: 0.08 mm at 64³ of a 20 mm part, 0.02 mm at 256³), and the bake
//! dilates the colour and fraction volumes two voxels outwards so the dilated
//! surface is coloured like the part. Measured in `benches/render.rs` and
//! checked by `tests/render.rs::bcc_sphere_shows_struts`.
//!
//! **Software renderers.** Mesa's lavapipe executes both sides of every
//! branch, so the shader keeps loop bodies to one or two texture lookups and
//! uses one pipeline per path (solid, region, volume; WGSL `override`
//! constants). On a software rasteriser (lavapipe) a full-size frame is
//! slow; set [`ViewSettings::render_scale`] to 0.5 there (a quarter of the
//! pixels).
#![warn(missing_docs)]

pub mod attribute_bake;
mod bake;
mod camera;
pub mod colormap;
mod gpu;
mod offscreen;
mod pick;
mod progressive;
mod redistance;
mod settings;
mod upscale;
pub mod viewport;
mod wgpu_parts;

pub use attribute_bake::AttributeShading;
pub use bake::{BakeError, MAX_CHANNELS, VolumeBake, bake, bake_shaded};
pub use camera::{Camera, StandardView};
pub use colormap::ColorMap;
pub use gpu::{MAX_DENSITY, MIN_DENSITY, RENDER_SHADER, Renderer, THIN_BIAS_VOXELS};
pub use offscreen::{Offscreen, render_offscreen};
pub use pick::{HitSurface, PickHit, pick, pick_drawn};
pub use progressive::{DEFAULT_LEVELS, ProgressiveBaker};
pub use settings::{CutPlane, ViewMode, ViewSettings};
pub use upscale::BLIT_SHADER;

pub use glam::{Vec2, Vec3};
use volcad_core::Model;
pub use volcad_core::sampler::Cancelled;

/// Why an offscreen render failed.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// No GPU adapter (not even a software one) was found.
    #[error(
        "no GPU adapter found (backends tried: {backends}); install Mesa's software Vulkan (mesa-vulkan-drivers) or set WGPU_BACKEND"
    )]
    NoAdapter {
        /// The backends that were asked for.
        backends: String,
    },
    /// The adapter refused to create a device.
    #[error("could not create a GPU device: {0}")]
    Device(#[from] wgpu::RequestDeviceError),
    /// The design could not be baked.
    #[error("could not bake the design: {0}")]
    Bake(#[from] BakeError),
    /// Reading the image back from the GPU failed.
    #[error("could not read the image back from the GPU: {0}")]
    Readback(String),
    /// The image size is zero or larger than the device allows.
    #[error("image size {width}x{height} is not supported (max {max} per side)")]
    BadSize {
        /// Requested width.
        width: u32,
        /// Requested height.
        height: u32,
        /// The device's limit.
        max: u32,
    },
}

/// Convenience for the CLI: bake `model` at `resolution` (no cancel).
pub fn bake_blocking(model: &Model, resolution: u32) -> Result<VolumeBake, BakeError> {
    bake(
        model,
        resolution,
        &std::sync::atomic::AtomicBool::new(false),
    )
}
