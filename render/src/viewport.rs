//! The egui viewport: a paint callback that draws with the [`Renderer`]
//! kept in egui-wgpu's `callback_resources`.
//!
//! ```ignore
//! // once, in App::new(cc):
//! volcad_render::viewport::register(cc.wgpu_render_state.as_ref().unwrap());
//! // every frame, in the viewport panel:
//! let (rect, response) = ui.allocate_exact_size(ui.available_size(), egui::Sense::click_and_drag());
//! let size_px = [(rect.width() * ppp).round() as u32, (rect.height() * ppp).round() as u32];
//! let cb = ViewportCallback { settings: settings.clone(), bake: baker.try_recv(), size_px };
//! ui.painter().add(egui_wgpu::Callback::new_paint_callback(rect, cb));
//! ```
//!
//! The pipeline has no depth attachment and one sample: keep eframe's
//! `depth_buffer` at 0 and `multisampling` at 0 or 1 (the defaults). One
//! viewport per window (the uniforms are shared).

use std::sync::Arc;

use crate::bake::VolumeBake;
use crate::gpu::Renderer;
use crate::settings::ViewSettings;

/// One frame of the viewport.
#[derive(Clone)]
pub struct ViewportCallback {
    /// What to show.
    pub settings: ViewSettings,
    /// A bake to upload before drawing (pass each new bake once, then `None`).
    pub bake: Option<Arc<VolumeBake>>,
    /// The callback rect in physical pixels (`rect.size() · pixels_per_point`),
    /// for the aspect ratio and pixel-sized lines.
    pub size_px: [u32; 2],
}

impl egui_wgpu::CallbackTrait for ViewportCallback {
    fn prepare(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        _screen_descriptor: &egui_wgpu::ScreenDescriptor,
        egui_encoder: &mut wgpu::CommandEncoder,
        callback_resources: &mut egui_wgpu::CallbackResources,
    ) -> Vec<wgpu::CommandBuffer> {
        if let Some(r) = callback_resources.get_mut::<Renderer>() {
            if let Some(b) = &self.bake {
                r.upload(device, queue, b);
            }
            r.prepare_scaled(device, queue, egui_encoder, &self.settings, self.size_px);
        }
        Vec::new()
    }

    fn paint(
        &self,
        _info: egui::PaintCallbackInfo,
        render_pass: &mut wgpu::RenderPass<'static>,
        callback_resources: &egui_wgpu::CallbackResources,
    ) {
        if let Some(r) = callback_resources.get::<Renderer>() {
            r.paint(render_pass);
        }
    }
}

/// Create the [`Renderer`] for egui's device and target format and store it
/// in the callback resources (call once, at startup).
pub fn register(render_state: &egui_wgpu::RenderState) {
    let renderer = Renderer::new(&render_state.device, render_state.target_format);
    render_state
        .renderer
        .write()
        .callback_resources
        .insert(renderer);
}
