//! GPU side: the ray-march pipeline, the three 3D textures and the uniform
//! buffer.
//!
//! Lifecycle (as in egui's custom3d example): [`Renderer::new`] once per
//! device; [`Renderer::upload`] once per finished bake (`write_texture`; new
//! textures only when the grid size changes); [`Renderer::prepare`] once per
//! frame (one uniform write); [`Renderer::paint`] draws one fullscreen
//! triangle into the current pass (no depth attachment, one sample).

use bytemuck::{Pod, Zeroable};
use glam::Vec3;

use crate::bake::{MAX_CHANNELS, VolumeBake};
use crate::settings::{ViewMode, ViewSettings};
use crate::upscale::Upscaler;
use crate::wgpu_parts::{sampler_entry, texture_entry};

/// The ray-march shader (WGSL), after the full-screen triangle it shares
/// with the upscale pass.
pub const RENDER_SHADER: &str = concat!(
    include_str!("shaders/fullscreen.wgsl"),
    include_str!("shaders/raymarch.wgsl")
);

/// The surface is drawn at `d = THIN_BIAS_VOXELS · voxel` (mm) instead of 0,
/// so features thinner than a voxel still cross the level in the
/// trilinearly interpolated distance field. On struts about a voxel
/// across (the BCC sphere at a coarse bake) the struts break into beads
/// without the bias; with 0.25 they are continuous and a little thick, and
/// at fine bakes the bias is a small fraction of a voxel.
pub const THIN_BIAS_VOXELS: f32 = 0.25;

/// Volume mode: optical depth, at opacity 1, of the mean chord of the
/// part's bounding box (`4V/S`, Cauchy): an average ray through a solid part
/// keeps `e^-VOLUME_DEPTH` of the light behind it, for plates and bars alike.
const VOLUME_DEPTH: f32 = 1.5;

/// The range of `ViewSettings::volume_density`: beyond it the picture is
/// either the surface only or nothing at all.
pub const MIN_DENSITY: f32 = 0.05;
/// See [`MIN_DENSITY`].
pub const MAX_DENSITY: f32 = 20.0;

/// Materials below this alpha (0..1) are "clear": drawn in Solid mode with
/// their (light) colour, and at this alpha in Volume mode.
const MIN_VOLUME_ALPHA: f32 = 0.08;

/// The uniform block, laid out as `struct Uniforms` in the shader.
#[repr(C, align(16))]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub(crate) struct Uniforms {
    /// xyz eye, w 1 for orthographic.
    eye: [f32; 4],
    /// xyz right, w half-extent factor in x (tan·aspect or mm).
    right: [f32; 4],
    /// xyz up, w half-extent factor in y.
    up: [f32; 4],
    /// xyz forward, w unused.
    forward: [f32; 4],
    /// xyz grid min corner (mm), w voxel edge (mm).
    grid_min: [f32; 4],
    /// xyz grid size (mm), w surface bias (mm).
    grid_size: [f32; 4],
    /// xyz model bbox min, w 1 when a volume is loaded.
    bbox_min: [f32; 4],
    /// xyz model bbox max, w volume optical depth per mm.
    bbox_max: [f32; 4],
    /// Background colour.
    background: [f32; 4],
    /// Cut plane: kept where dot(xyz, p) + w ≤ 0.
    cut: [f32; 4],
    /// x iso level, y iso channel, z channel count, w colour from fractions (1/0).
    iso: [f32; 4],
    /// Opacity per fraction channel.
    opacity: [f32; 4],
    /// RGB 0..1 and alpha of each fraction channel's material.
    palette: [[f32; 4]; MAX_CHANNELS],
    /// x mode (0 solid, 1 volume, 2 iso), y overlays (1 bbox, 2 grid, 4 axes,
    /// 8 cut), z 1 when a material is hidden, w unused.
    flags: [u32; 4],
    /// x, y viewport size (px), z grid spacing (mm), w unused.
    viewport: [f32; 4],
}

/// Which pipeline draws (index into `Renderer::pipelines`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Path {
    Solid = 0,
    Region = 1,
    Volume = 2,
}

/// Pipelines, textures and uniforms for one device and target format.
pub struct Renderer {
    /// Solid, region (iso or hidden materials), volume: see `Path`.
    pipelines: [wgpu::RenderPipeline; 3],
    path: Path,
    layout: wgpu::BindGroupLayout,
    sampler: wgpu::Sampler,
    uniform_buffer: wgpu::Buffer,
    textures: Option<Volume>,
    bind_group: wgpu::BindGroup,
    meta: Option<VolumeMeta>,
    thin_bias_voxels: f32,
    upscaler: Upscaler,
    /// The last prepare rendered at reduced resolution: paint upscales.
    reduced: bool,
}

struct Volume {
    dims: [u32; 3],
    distance: wgpu::Texture,
    color: wgpu::Texture,
    fractions: wgpu::Texture,
}

/// What the uniforms need to know about the uploaded bake.
#[derive(Clone, Debug)]
struct VolumeMeta {
    grid_min: Vec3,
    grid_size: Vec3,
    voxel: f32,
    bbox_min: Vec3,
    bbox_max: Vec3,
    empty: bool,
    channels: Vec<usize>,
    palette: Vec<[u8; 4]>,
    material_count: usize,
    /// The colour volume holds an attribute's colours: the shader must not
    /// remix the materials' palette over it.
    attribute: bool,
}

impl Volume {
    fn new(device: &wgpu::Device, dims: [u32; 3]) -> Self {
        let make = |label, format| {
            device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size: wgpu::Extent3d {
                    width: dims[0],
                    height: dims[1],
                    depth_or_array_layers: dims[2],
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D3,
                format,
                usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
                view_formats: &[],
            })
        };
        Volume {
            dims,
            distance: make("volcad distance", wgpu::TextureFormat::R16Float),
            color: make("volcad colour", wgpu::TextureFormat::Rgba8Unorm),
            fractions: make("volcad fractions", wgpu::TextureFormat::Rgba8Unorm),
        }
    }
}

impl Renderer {
    /// Build the pipeline for `target_format` (the egui target, or
    /// `Rgba8Unorm` offscreen), with an empty 2³ volume bound.
    pub fn new(device: &wgpu::Device, target_format: wgpu::TextureFormat) -> Self {
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("volcad raymarch"),
            source: wgpu::ShaderSource::Wgsl(RENDER_SHADER.into()),
        });
        let tex_entry = |binding| texture_entry(binding, wgpu::TextureViewDimension::D3);
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("volcad raymarch"),
            entries: &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: false,
                        min_binding_size: wgpu::BufferSize::new(
                            std::mem::size_of::<Uniforms>() as u64
                        ),
                    },
                    count: None,
                },
                tex_entry(1),
                tex_entry(2),
                tex_entry(3),
                sampler_entry(4),
            ],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("volcad raymarch"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let make = |label: &str, constants: &[(&str, f64)]| {
            let options = wgpu::PipelineCompilationOptions {
                constants,
                ..Default::default()
            };
            crate::wgpu_parts::fullscreen_pipeline(
                device,
                label,
                &pipeline_layout,
                &module,
                options,
                target_format,
            )
        };
        let pipelines = [
            make("volcad raymarch solid", &[]),
            make("volcad raymarch region", &[("REGION", 1.0)]),
            make("volcad raymarch volume", &[("VOLUME", 1.0)]),
        ];
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("volcad trilinear"),
            address_mode_u: wgpu::AddressMode::ClampToEdge,
            address_mode_v: wgpu::AddressMode::ClampToEdge,
            address_mode_w: wgpu::AddressMode::ClampToEdge,
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            ..Default::default()
        });
        let uniform_buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("volcad uniforms"),
            size: std::mem::size_of::<Uniforms>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let placeholder = Volume::new(device, [2, 2, 2]);
        let bind_group = Self::bind(device, &layout, &uniform_buffer, &placeholder, &sampler);
        Renderer {
            pipelines,
            path: Path::Solid,
            layout,
            sampler,
            uniform_buffer,
            textures: None,
            bind_group,
            meta: None,
            thin_bias_voxels: THIN_BIAS_VOXELS,
            upscaler: Upscaler::new(device, target_format),
            reduced: false,
        }
    }

    fn bind(
        device: &wgpu::Device,
        layout: &wgpu::BindGroupLayout,
        uniforms: &wgpu::Buffer,
        v: &Volume,
        sampler: &wgpu::Sampler,
    ) -> wgpu::BindGroup {
        let view = |t: &wgpu::Texture| t.create_view(&wgpu::TextureViewDescriptor::default());
        let (d, c, f) = (view(&v.distance), view(&v.color), view(&v.fractions));
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("volcad raymarch"),
            layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: uniforms.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::TextureView(&d),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: wgpu::BindingResource::TextureView(&c),
                },
                wgpu::BindGroupEntry {
                    binding: 3,
                    resource: wgpu::BindingResource::TextureView(&f),
                },
                wgpu::BindGroupEntry {
                    binding: 4,
                    resource: wgpu::BindingResource::Sampler(sampler),
                },
            ],
        })
    }

    /// Copy a finished bake into the 3D textures (new textures only when the
    /// grid size changed). Call once per bake, not per frame.
    pub fn upload(&mut self, device: &wgpu::Device, queue: &wgpu::Queue, bake: &VolumeBake) {
        let dims = bake.dims;
        if self.textures.as_ref().is_none_or(|t| t.dims != dims) {
            let v = Volume::new(device, dims);
            self.bind_group = Self::bind(
                device,
                &self.layout,
                &self.uniform_buffer,
                &v,
                &self.sampler,
            );
            self.textures = Some(v);
        }
        let Some(v) = &self.textures else { return };
        let size = wgpu::Extent3d {
            width: dims[0],
            height: dims[1],
            depth_or_array_layers: dims[2],
        };
        let write = |tex: &wgpu::Texture, bytes: &[u8], texel: u32| {
            queue.write_texture(
                wgpu::TexelCopyTextureInfo {
                    texture: tex,
                    mip_level: 0,
                    origin: wgpu::Origin3d::ZERO,
                    aspect: wgpu::TextureAspect::All,
                },
                bytes,
                wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(dims[0] * texel),
                    rows_per_image: Some(dims[1]),
                },
                size,
            );
        };
        write(&v.distance, bytemuck::cast_slice(&bake.distance), 2);
        write(&v.color, bytemuck::cast_slice(&bake.color), 4);
        write(&v.fractions, bytemuck::cast_slice(&bake.fractions), 4);
        let (gmin, gmax) = bake.grid_box();
        self.meta = Some(VolumeMeta {
            grid_min: gmin,
            grid_size: gmax - gmin,
            voxel: bake.voxel_size_mm,
            bbox_min: bake.bbox.min.as_vec3(),
            bbox_max: bake.bbox.max.as_vec3(),
            empty: bake.is_empty(),
            channels: bake.channels.clone(),
            palette: bake.palette.clone(),
            material_count: bake.materials.len(),
            attribute: bake.attribute_shaded,
        });
    }

    /// Override the thin-feature bias (voxels; default [`THIN_BIAS_VOXELS`],
    /// 0 draws the plain zero level). For measurements.
    pub fn set_thin_bias_voxels(&mut self, voxels: f32) {
        self.thin_bias_voxels = voxels.max(0.0);
    }

    /// True once a bake was uploaded.
    pub fn has_volume(&self) -> bool {
        self.meta.is_some()
    }

    /// Write this frame's uniforms for `settings` and a viewport of
    /// `size` pixels; [`Renderer::paint`] then ray-marches at full
    /// resolution (`settings.render_scale` is ignored).
    pub fn prepare(&mut self, queue: &wgpu::Queue, settings: &ViewSettings, size: [u32; 2]) {
        let u = self.uniforms(settings, size);
        queue.write_buffer(&self.uniform_buffer, 0, bytemuck::bytes_of(&u));
        self.path = match u.flags[0] {
            1 => Path::Volume,
            2 => Path::Region,
            _ if u.flags[2] != 0 => Path::Region,
            _ => Path::Solid,
        };
        self.reduced = false;
    }

    /// Like [`Renderer::prepare`], honouring `settings.render_scale`: below
    /// 1 the ray march is recorded now into `encoder` at the reduced size,
    /// and [`Renderer::paint`] upscales it (what the viewport callback does).
    pub fn prepare_scaled(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        settings: &ViewSettings,
        size: [u32; 2],
    ) {
        let scale = settings.render_scale.clamp(0.05, 1.0);
        if scale >= 0.999 {
            self.prepare(queue, settings, size);
            return;
        }
        let low = size.map(|v| ((v as f32 * scale).round() as u32).max(1));
        self.prepare(queue, settings, low);
        let view = self.upscaler.target(device, low);
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("volcad reduced resolution"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: None,
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&self.pipelines[self.path as usize]);
        pass.set_bind_group(0, &self.bind_group, &[]);
        pass.draw(0..3, 0..1);
        drop(pass);
        self.reduced = true;
    }

    /// Draw into `pass` (its viewport set to the image or the egui rect).
    pub fn paint(&self, pass: &mut wgpu::RenderPass<'_>) {
        if self.reduced {
            self.upscaler.paint(pass);
            return;
        }
        pass.set_pipeline(&self.pipelines[self.path as usize]);
        pass.set_bind_group(0, &self.bind_group, &[]);
        pass.draw(0..3, 0..1);
    }

    pub(crate) fn uniforms(&self, s: &ViewSettings, size: [u32; 2]) -> Uniforms {
        let w = size[0].max(1) as f32;
        let h = size[1].max(1) as f32;
        let aspect = w / h;
        let cam = &s.camera;
        let (right, up, forward) = cam.basis();
        let (hx, hy) = if cam.orthographic {
            let hh = cam.half_height_at_target();
            (hh * aspect, hh)
        } else {
            let t = (cam.fov_y * 0.5).tan();
            (t * aspect, t)
        };
        let v4 = |v: Vec3, w: f32| [v.x, v.y, v.z, w];
        let mut u = Uniforms::zeroed();
        u.eye = v4(cam.eye(), if cam.orthographic { 1.0 } else { 0.0 });
        u.right = v4(right, hx);
        u.up = v4(up, hy);
        u.forward = v4(forward, 0.0);
        u.background = s.background;
        u.viewport = [w, h, 0.0, 0.0];
        let mut overlays = 0u32;
        if s.show_bbox {
            overlays |= 1;
        }
        if s.show_grid {
            overlays |= 2;
        }
        if s.show_axes {
            overlays |= 4;
        }
        if let Some(c) = &s.cut {
            overlays |= 8;
            let axis = c.axis.min(2);
            let mut n = [0.0f32; 3];
            n[axis] = if c.keep_below { 1.0 } else { -1.0 };
            u.cut = [n[0], n[1], n[2], -n[axis] * c.offset];
        }
        let mode = match s.mode {
            ViewMode::Solid => 0,
            ViewMode::Volume => 1,
            ViewMode::Iso { .. } => 2,
        };
        u.flags = [mode, overlays, 0, 0];
        let Some(m) = &self.meta else {
            return u;
        };
        u.grid_min = v4(m.grid_min, m.voxel);
        u.grid_size = v4(m.grid_size, self.thin_bias_voxels * m.voxel);
        let extent = (m.bbox_max - m.bbox_min).max_element().max(1e-6);
        u.bbox_min = v4(m.bbox_min, if m.empty { 0.0 } else { 1.0 });
        let e = (m.bbox_max - m.bbox_min).max(Vec3::splat(1e-6));
        let mean_chord = 2.0 * e.x * e.y * e.z / (e.x * e.y + e.y * e.z + e.z * e.x);
        let density = s.volume_density.clamp(MIN_DENSITY, MAX_DENSITY);
        u.bbox_max = v4(m.bbox_max, VOLUME_DEPTH * density / mean_chord);
        // Ground grid spacing: a power of ten giving 5..50 lines across.
        u.viewport[2] = 10f32.powf((extent / 5.0).log10().floor());
        if m.empty {
            u.bbox_min = [0.0; 4];
            u.bbox_max = [0.0; 4];
            u.viewport[2] = 10.0;
        }
        let mut hidden = false;
        for (c, mi) in m.channels.iter().enumerate() {
            let rgba = m.palette.get(*mi).copied().unwrap_or([255; 4]);
            let alpha = (rgba[3] as f32 / 255.0).max(MIN_VOLUME_ALPHA);
            u.palette[c] = [
                rgba[0] as f32 / 255.0,
                rgba[1] as f32 / 255.0,
                rgba[2] as f32 / 255.0,
                alpha,
            ];
            u.opacity[c] = s.opacity(*mi);
            hidden |= u.opacity[c] <= 0.0;
        }
        u.flags[2] = hidden as u32;
        let all_in_channels = m.material_count <= MAX_CHANNELS && !m.attribute;
        let iso_channel = match s.mode {
            ViewMode::Iso { material_index, .. } => m
                .channels
                .iter()
                .position(|c| *c == material_index)
                .map_or(-1.0, |c| c as f32),
            _ => -1.0,
        };
        let level = match s.mode {
            ViewMode::Iso { level, .. } => level.clamp(0.0, 1.0),
            _ => 0.5,
        };
        u.iso = [
            level,
            iso_channel,
            m.channels.len() as f32,
            if all_in_channels { 1.0 } else { 0.0 },
        ];
        u
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uniform_layout_matches_the_shader() {
        assert_eq!(std::mem::size_of::<Uniforms>(), 16 * 18);
        let module = wgpu::naga::front::wgsl::parse_str(RENDER_SHADER).expect("shader parses");
        let (_, ty) = module
            .types
            .iter()
            .find(|(_, t)| t.name.as_deref() == Some("Uniforms"))
            .expect("struct Uniforms");
        let wgpu::naga::TypeInner::Struct { span, .. } = ty.inner else {
            panic!("Uniforms is not a struct")
        };
        assert_eq!(
            span as usize,
            std::mem::size_of::<Uniforms>(),
            "Rust and WGSL Uniforms differ in size"
        );
    }
}
