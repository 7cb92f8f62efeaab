//! Reduced-resolution rendering: the ray march is recorded into a smaller
//! texture (in the frame's command encoder, before egui's pass) and
//! [`Upscaler::paint`] draws it into the viewport with bilinear filtering.
//! The texture is made again only when its size changes.

/// The upscale pass's shader (WGSL), after the full-screen triangle it
/// shares with the ray march.
pub const BLIT_SHADER: &str = concat!(
    include_str!("shaders/fullscreen.wgsl"),
    include_str!("shaders/blit.wgsl")
);

pub(crate) struct Upscaler {
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    sampler: wgpu::Sampler,
    format: wgpu::TextureFormat,
    target: Option<Target>,
}

struct Target {
    size: [u32; 2],
    view: wgpu::TextureView,
    bind_group: wgpu::BindGroup,
}

impl Upscaler {
    pub(crate) fn new(device: &wgpu::Device, format: wgpu::TextureFormat) -> Self {
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("volcad upscale"),
            source: wgpu::ShaderSource::Wgsl(BLIT_SHADER.into()),
        });
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("volcad upscale"),
            entries: &[
                crate::wgpu_parts::texture_entry(0, wgpu::TextureViewDimension::D2),
                crate::wgpu_parts::sampler_entry(1),
            ],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("volcad upscale"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = crate::wgpu_parts::fullscreen_pipeline(
            device,
            "volcad upscale",
            &pipeline_layout,
            &module,
            wgpu::PipelineCompilationOptions::default(),
            format,
        );
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("volcad upscale"),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            ..Default::default()
        });
        Upscaler {
            pipeline,
            layout,
            sampler,
            format,
            target: None,
        }
    }

    /// The render target of `size` (made again only when the size changes).
    pub(crate) fn target(&mut self, device: &wgpu::Device, size: [u32; 2]) -> &wgpu::TextureView {
        let target = match self.target.take() {
            Some(t) if t.size == size => t,
            _ => self.make_target(device, size),
        };
        &self.target.insert(target).view
    }

    /// A render target of `size` and the bind group that samples it.
    fn make_target(&self, device: &wgpu::Device, size: [u32; 2]) -> Target {
        let texture = crate::wgpu_parts::target_texture(
            device,
            "volcad reduced resolution",
            size,
            self.format,
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
        );
        let view = texture.create_view(&wgpu::TextureViewDescriptor::default());
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("volcad upscale"),
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::TextureView(&view),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::Sampler(&self.sampler),
                },
            ],
        });
        Target {
            size,
            view,
            bind_group,
        }
    }

    /// Draw the reduced image over the whole viewport of `pass`.
    pub(crate) fn paint(&self, pass: &mut wgpu::RenderPass<'_>) {
        if let Some(t) = &self.target {
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &t.bind_group, &[]);
            pass.draw(0..3, 0..1);
        }
    }
}
