//! Offscreen rendering with its own device: tests, benchmarks and
//! `volcad render`.
//!
//! `Instance` without a display → adapter → `Rgba8Unorm` target (not sRGB:
//! the egui surface is not sRGB either, so images match the app) → the same
//! [`Renderer`] → `copy_texture_to_buffer` (rows padded to 256 bytes) →
//! `map_async` + `poll(wait)` → [`image::RgbaImage`].

use std::sync::mpsc;
use std::time::Instant;

use volcad_core::Model;

use crate::RenderError;
use crate::bake::{VolumeBake, bake};
use crate::gpu::Renderer;
use crate::settings::ViewSettings;

const FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;

/// A device, a [`Renderer`] and a target image of fixed size.
pub struct Offscreen {
    device: wgpu::Device,
    queue: wgpu::Queue,
    renderer: Renderer,
    target: wgpu::Texture,
    readback: wgpu::Buffer,
    size: [u32; 2],
    padded_row: u32,
    adapter: String,
}

impl Offscreen {
    /// Open a device (backends from `WGPU_BACKEND`, else the platform's
    /// defaults) and make a `size` target.
    ///
    /// # Errors
    /// [`RenderError::NoAdapter`] when no adapter exists (tests must fail
    /// then, not skip), [`RenderError::Device`], [`RenderError::BadSize`].
    pub fn new(size: [u32; 2]) -> Result<Self, RenderError> {
        let desc = wgpu::InstanceDescriptor::new_without_display_handle_from_env();
        let backends = desc.backends;
        let instance = wgpu::Instance::new(desc);
        let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            force_fallback_adapter: false,
            compatible_surface: None,
            ..Default::default()
        }))
        .map_err(|_| RenderError::NoAdapter {
            backends: format!("{backends:?}"),
        })?;
        let info = adapter.get_info();
        let (device, queue) =
            pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
                label: Some("volcad offscreen"),
                required_limits:
                    wgpu::Limits::downlevel_defaults().using_resolution(adapter.limits()),
                ..Default::default()
            }))?;
        let max = device.limits().max_texture_dimension_2d;
        if size[0] == 0 || size[1] == 0 || size[0] > max || size[1] > max {
            return Err(RenderError::BadSize {
                width: size[0],
                height: size[1],
                max,
            });
        }
        let target = crate::wgpu_parts::target_texture(
            &device,
            "volcad offscreen target",
            size,
            FORMAT,
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
        );
        let padded_row = (size[0] * 4).div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT)
            * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
        let readback = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("volcad readback"),
            size: padded_row as u64 * size[1] as u64,
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        });
        let renderer = Renderer::new(&device, FORMAT);
        let adapter = format!("{} ({:?}, {:?})", info.name, info.backend, info.device_type);
        Ok(Offscreen {
            device,
            queue,
            renderer,
            target,
            readback,
            size,
            padded_row,
            adapter,
        })
    }

    /// The adapter's name, backend and type (for reports).
    pub fn adapter(&self) -> &str {
        &self.adapter
    }

    /// The image size.
    pub fn size(&self) -> [u32; 2] {
        self.size
    }

    /// The renderer (to change its thin-feature bias, for example).
    pub fn renderer_mut(&mut self) -> &mut Renderer {
        &mut self.renderer
    }

    /// Upload a bake (replaces the previous one).
    pub fn upload(&mut self, bake: &VolumeBake) {
        self.renderer.upload(&self.device, &self.queue, bake);
    }

    /// Draw one frame and wait for it on the GPU, without reading it back;
    /// returns the wall time (s). For frame-time benchmarks.
    pub fn draw_timed(&mut self, settings: &ViewSettings) -> Result<f64, RenderError> {
        let start = Instant::now();
        let cmd = self.encode(settings, false);
        let idx = self.queue.submit([cmd]);
        self.device
            .poll(wgpu::PollType::Wait {
                submission_index: Some(idx),
                timeout: None,
            })
            .map_err(|e| RenderError::Readback(e.to_string()))?;
        Ok(start.elapsed().as_secs_f64())
    }

    /// Draw one frame and read it back.
    pub fn render(&mut self, settings: &ViewSettings) -> Result<image::RgbaImage, RenderError> {
        let cmd = self.encode(settings, true);
        let idx = self.queue.submit([cmd]);
        let slice = self.readback.slice(..);
        let (tx, rx) = mpsc::channel();
        slice.map_async(wgpu::MapMode::Read, move |r| {
            let _ = tx.send(r);
        });
        self.device
            .poll(wgpu::PollType::Wait {
                submission_index: Some(idx),
                timeout: None,
            })
            .map_err(|e| RenderError::Readback(e.to_string()))?;
        rx.recv()
            .map_err(|e| RenderError::Readback(e.to_string()))?
            .map_err(|e| RenderError::Readback(e.to_string()))?;
        let [w, h] = self.size;
        let mut pixels = Vec::with_capacity((w * h * 4) as usize);
        {
            let view = slice
                .get_mapped_range()
                .map_err(|e| RenderError::Readback(e.to_string()))?;
            for row in view.chunks(self.padded_row as usize).take(h as usize) {
                pixels.extend_from_slice(&row[..(w * 4) as usize]);
            }
        }
        self.readback.unmap();
        image::RgbaImage::from_raw(w, h, pixels)
            .ok_or_else(|| RenderError::Readback("short image buffer".into()))
    }

    fn encode(&mut self, settings: &ViewSettings, copy: bool) -> wgpu::CommandBuffer {
        let view = self
            .target
            .create_view(&wgpu::TextureViewDescriptor::default());
        let mut enc = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("volcad offscreen"),
            });
        self.renderer
            .prepare_scaled(&self.device, &self.queue, &mut enc, settings, self.size);
        {
            let [r, g, b, a] = settings.background.map(|c| c as f64);
            let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("volcad offscreen"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color { r, g, b, a }),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: None,
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            self.renderer.paint(&mut pass);
        }
        if copy {
            let [w, h] = self.size;
            enc.copy_texture_to_buffer(
                wgpu::TexelCopyTextureInfo {
                    texture: &self.target,
                    mip_level: 0,
                    origin: wgpu::Origin3d::ZERO,
                    aspect: wgpu::TextureAspect::All,
                },
                wgpu::TexelCopyBufferInfo {
                    buffer: &self.readback,
                    layout: wgpu::TexelCopyBufferLayout {
                        offset: 0,
                        bytes_per_row: Some(self.padded_row),
                        rows_per_image: Some(h),
                    },
                },
                wgpu::Extent3d {
                    width: w,
                    height: h,
                    depth_or_array_layers: 1,
                },
            );
        }
        enc.finish()
    }
}

/// Bake `model` at `bake_resolution` and render one `size` image of it.
pub fn render_offscreen(
    model: &Model,
    settings: &ViewSettings,
    size: [u32; 2],
    bake_resolution: u32,
) -> Result<image::RgbaImage, RenderError> {
    let mut off = Offscreen::new(size)?;
    let b = bake(
        model,
        bake_resolution,
        &std::sync::atomic::AtomicBool::new(false),
    )?;
    off.upload(&b);
    off.render(settings)
}
