//! The viewport: the renderer's paint callback, camera input, view
//! settings, the material legend and the probe.
//!
//! ```text
//! Arc<Model> ──ProgressiveBaker (thread)──► try_recv each frame ──► Arc<VolumeBake> (generation n)
//! UploadOnce callback: uploads bake n once (tracks the last uploaded generation), then draws
//! hover/click ──ProbeWorker (thread, newest request wins)──► PickHit ──► read-out
//! ```

use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

use egui::{Key, Pos2, Rect, Sense};
use egui_wgpu::wgpu;
use volcad_core::Model;
use volcad_render::viewport::ViewportCallback;
use volcad_render::{
    Camera, CutPlane, ProgressiveBaker, StandardView, ViewMode, ViewSettings, VolumeBake,
};

use super::attribute_view::{self, Shading};
use super::legend;
use super::probe::{Probe, ProbeWorker};

/// Zoom per scroll point.
const ZOOM_PER_POINT: f32 = 0.0025;

/// A paint callback that uploads each bake exactly once, even when a frame
/// is laid out but never painted (tests step without rendering).
struct UploadOnce {
    settings: ViewSettings,
    bake: Option<(u64, Arc<VolumeBake>)>,
    uploaded: Arc<AtomicU64>,
    size_px: [u32; 2],
}

impl egui_wgpu::CallbackTrait for UploadOnce {
    fn prepare(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        screen: &egui_wgpu::ScreenDescriptor,
        encoder: &mut wgpu::CommandEncoder,
        resources: &mut egui_wgpu::CallbackResources,
    ) -> Vec<wgpu::CommandBuffer> {
        let bake = match &self.bake {
            Some((generation, b))
                if self.uploaded.swap(*generation, Ordering::AcqRel) != *generation =>
            {
                Some(b.clone())
            }
            _ => None,
        };
        let inner = ViewportCallback {
            settings: self.settings.clone(),
            bake,
            size_px: self.size_px,
        };
        inner.prepare(device, queue, screen, encoder, resources)
    }

    fn paint(
        &self,
        info: egui::PaintCallbackInfo,
        pass: &mut wgpu::RenderPass<'static>,
        resources: &egui_wgpu::CallbackResources,
    ) {
        let inner = ViewportCallback {
            settings: self.settings.clone(),
            bake: None,
            size_px: self.size_px,
        };
        inner.paint(info, pass, resources);
    }
}

/// The viewport's state.
pub struct Viewport {
    /// What to show (camera, mode, cut, opacity, overlays).
    pub settings: ViewSettings,
    /// What colours the surface and the cut plane (materials or an attribute).
    pub shading: Shading,
    model: Option<Arc<Model>>,
    baker: Option<ProgressiveBaker>,
    levels: Vec<u32>,
    bake: Option<(u64, Arc<VolumeBake>)>,
    bakes_received: u64,
    uploaded: Arc<AtomicU64>,
    /// The script has an error: the picture is of the last good design.
    pub stale: bool,
    /// Keep the part framed (after opening, and while panels settle)
    /// until the user moves the camera.
    auto_fit: bool,
    /// A new file or example was loaded: fit its first model, not the
    /// model still on screen from the previous file.
    fit_pending: bool,
    fitted_size: egui::Vec2,
    view: StandardView,
    has_gpu: bool,
    probe: ProbeWorker,
    /// A pinned probe read-out (click).
    pub pinned: Option<Probe>,
    /// The read-out under the cursor.
    pub hovered: Option<Probe>,
    last_hover: Option<Pos2>,
    bake_started: Option<Instant>,
    /// Width / height of the picture last frame (fitting uses it).
    aspect: f32,
}

impl Viewport {
    /// A viewport; `has_gpu` is false when eframe runs without wgpu.
    pub fn new(has_gpu: bool, levels: Vec<u32>) -> Self {
        Self {
            settings: ViewSettings::default(),
            shading: Shading::default(),
            model: None,
            baker: None,
            levels,
            bake: None,
            bakes_received: 0,
            uploaded: Arc::new(AtomicU64::new(0)),
            stale: false,
            auto_fit: true,
            fit_pending: false,
            fitted_size: egui::Vec2::ZERO,
            view: StandardView::Iso,
            has_gpu,
            probe: ProbeWorker::default(),
            pinned: None,
            hovered: None,
            last_hover: None,
            bake_started: None,
            aspect: 1.0,
        }
    }

    /// Show a new model: start baking it (the previous bake stays on screen
    /// until the first level arrives).
    pub fn set_model(&mut self, ctx: &egui::Context, model: Arc<Model>) {
        if std::mem::take(&mut self.fit_pending) {
            self.auto_fit = true;
            self.fitted_size = egui::Vec2::ZERO;
        }
        let n = model.materials().len();
        // Opacity is per position in `materials()`: keep it only while the
        // design uses the same materials.
        if self
            .model
            .as_ref()
            .is_none_or(|m| m.materials() != model.materials())
        {
            self.settings.material_opacity = vec![1.0; n];
        }
        if let ViewMode::Iso { material_index, .. } = &mut self.settings.mode {
            *material_index = (*material_index).min(n.saturating_sub(1));
        }
        self.model = Some(model.clone());
        self.rebake(ctx);
        self.stale = false;
        self.pinned = None;
        self.hovered = None;
    }

    /// Bake the model on screen again (a new model, or a new shading).
    fn rebake(&mut self, ctx: &egui::Context) {
        let Some(model) = self.model.clone() else {
            return;
        };
        let shading = self.shading.for_model(&model);
        let ctx = ctx.clone();
        match &mut self.baker {
            Some(b) => b.restart_shaded(model, shading),
            None => {
                let mut b =
                    ProgressiveBaker::start(model.clone(), self.levels.clone(), move || {
                        ctx.request_repaint()
                    });
                if shading.is_some() {
                    b.restart_shaded(model, shading);
                }
                self.baker = Some(b);
            }
        }
        self.bake_started = Some(Instant::now());
    }

    /// Fit the camera to the next model that arrives (after opening a
    /// file or an example). Until then the previous design stays on
    /// screen with its camera: fitting now would frame the old part.
    pub fn fit_next(&mut self) {
        if self.model.is_none() {
            self.auto_fit = true;
            self.fitted_size = egui::Vec2::ZERO;
        } else {
            self.fit_pending = true;
        }
    }

    /// The model on screen.
    pub fn model(&self) -> Option<&Arc<Model>> {
        self.model.as_ref()
    }

    /// The bake on screen.
    pub fn bake(&self) -> Option<&Arc<VolumeBake>> {
        self.bake.as_ref().map(|(_, b)| b)
    }

    /// Number of bakes received so far (tests, screenshots).
    pub fn bakes_received(&self) -> u64 {
        self.bakes_received
    }

    /// True while levels are still baking.
    pub fn is_baking(&self) -> bool {
        self.baker.as_ref().is_some_and(|b| !b.is_done())
    }

    /// Take finished bakes and probe results (call every frame).
    pub fn poll(&mut self) -> Option<String> {
        let mut note = None;
        if let Some(b) = self.baker.as_ref().and_then(ProgressiveBaker::try_recv) {
            self.bakes_received += 1;
            note = Some(format!(
                "baked {}×{}×{} voxels ({:.3} mm) in {:.2} s",
                b.dims[0], b.dims[1], b.dims[2], b.voxel_size_mm, b.bake_seconds
            ));
            self.bake = Some((self.bakes_received, b));
        }
        if let Some(e) = self
            .baker
            .as_ref()
            .filter(|b| b.is_done())
            .and_then(ProgressiveBaker::error)
        {
            note = Some(format!("bake stopped: {e}"));
            self.baker = None;
        }
        if let Some(r) = self.probe.poll() {
            self.hovered = r;
        }
        note
    }

    fn fit(&mut self) {
        if let Some(m) = &self.model {
            let ortho = self.settings.camera.orthographic;
            let mut cam = Camera::fit(&m.bbox(), self.view);
            // `fit` frames the bounding sphere vertically; a tall, narrow
            // picture needs the distance for its width.
            if self.aspect < 1.0 {
                cam.distance /= self.aspect.max(0.2);
            }
            cam.orthographic = ortho;
            self.settings.camera = cam;
        }
    }

    /// Toolbar above the picture: standard views, projection, mode, cut plane.
    pub fn toolbar_ui(&mut self, ui: &mut egui::Ui) {
        ui.horizontal_wrapped(|ui| {
            for (label, view) in [
                ("Iso", StandardView::Iso),
                ("Top", StandardView::Top),
                ("Front", StandardView::Front),
                ("Side", StandardView::Side),
            ] {
                if ui
                    .selectable_label(self.view == view, label)
                    .on_hover_text(format!("{label} view"))
                    .clicked()
                {
                    self.view = view;
                    self.fit();
                }
            }
            if ui
                .button("Fit")
                .on_hover_text("Fit the part (F, or double-click)")
                .clicked()
            {
                self.fit();
            }
            ui.checkbox(&mut self.settings.camera.orthographic, "Ortho");
            ui.checkbox(&mut self.settings.show_bbox, "Box");
            ui.checkbox(&mut self.settings.show_grid, "Grid");
        });
        ui.horizontal_wrapped(|ui| {
            let mode = &mut self.settings.mode;
            let is_iso = matches!(mode, ViewMode::Iso { .. });
            if ui
                .selectable_label(*mode == ViewMode::Solid, "Solid")
                .clicked()
            {
                *mode = ViewMode::Solid;
            }
            if ui
                .selectable_label(*mode == ViewMode::Volume, "Volume")
                .clicked()
            {
                *mode = ViewMode::Volume;
            }
            if ui
                .selectable_label(is_iso, "Fraction")
                .on_hover_text(
                    "Iso-fraction surface: where one material's fraction equals a level \
                     (not the Iso view above)",
                )
                .clicked()
                && !is_iso
            {
                *mode = ViewMode::Iso {
                    material_index: 0,
                    level: 0.5,
                };
            }
            if *mode == ViewMode::Volume {
                ui.add(
                    egui::Slider::new(
                        &mut self.settings.volume_density,
                        volcad_render::MIN_DENSITY..=volcad_render::MAX_DENSITY,
                    )
                    .logarithmic(true)
                    .text("density"),
                )
                .on_hover_text(
                    "How opaque the volume is: more shows the outer layers, less sees deeper",
                );
            }
            ui.separator();
            if self.shading.picker_ui(ui, self.model.as_deref()) {
                self.rebake(ui.ctx());
            }
            ui.separator();
            self.cut_ui(ui);
        });
        if let ViewMode::Iso {
            material_index,
            level,
        } = &mut self.settings.mode
            && let Some(m) = &self.model
        {
            ui.horizontal(|ui| {
                ui.label("Iso surface of");
                let names: Vec<String> = m
                    .materials()
                    .iter()
                    .map(|id| m.table().name(*id).to_owned())
                    .collect();
                egui::ComboBox::from_id_salt("iso-material")
                    .selected_text(names.get(*material_index).cloned().unwrap_or_default())
                    .show_ui(ui, |ui| {
                        for (i, n) in names.iter().enumerate() {
                            ui.selectable_value(material_index, i, n);
                        }
                    });
                ui.add(egui::Slider::new(level, 0.0..=1.0).text("fraction"));
            });
        }
    }

    /// The cut plane's switch, and its axis, offset and side when on.
    fn cut_ui(&mut self, ui: &mut egui::Ui) {
        let mut cut_on = self.settings.cut.is_some();
        if ui.checkbox(&mut cut_on, "Cut").changed() {
            let c = self
                .model
                .as_ref()
                .map_or(0.0, |m| m.bbox().center().z as f32);
            self.settings.cut = cut_on.then_some(CutPlane {
                axis: 2,
                offset: c,
                keep_below: true,
            });
        }
        if let Some(cut) = &mut self.settings.cut {
            for (i, a) in ["x", "y", "z"].iter().enumerate() {
                ui.selectable_value(&mut cut.axis, i, *a);
            }
            let (lo, hi) = self
                .model
                .as_ref()
                .map(|m| m.bbox())
                .filter(|b| b.is_finite() && !b.is_empty())
                .map_or((-10.0, 10.0), |b| {
                    (b.min[cut.axis] as f32, b.max[cut.axis] as f32)
                });
            ui.add(egui::Slider::new(&mut cut.offset, lo..=hi).text("mm"));
            ui.checkbox(&mut cut.keep_below, "keep below");
        }
    }

    /// The picture, with camera input, overlays and the probe.
    pub fn canvas_ui(&mut self, ui: &mut egui::Ui) {
        let (rect, response) = ui.allocate_exact_size(ui.available_size(), Sense::click_and_drag());
        self.aspect = rect.width() / rect.height().max(1.0);
        if self.auto_fit && self.model.is_some() && rect.size() != self.fitted_size {
            self.fitted_size = rect.size();
            self.fit();
        }
        self.handle_input(ui, rect, &response);
        let bg = ui.visuals().extreme_bg_color.to_normalized_gamma_f32();
        self.settings.background = bg;
        if !self.has_gpu {
            ui.painter().text(
                rect.center(),
                egui::Align2::CENTER_CENTER,
                "No GPU renderer (wgpu) available",
                egui::FontId::proportional(16.0),
                ui.visuals().error_fg_color,
            );
            return;
        }
        let ppp = ui.ctx().pixels_per_point();
        let size_px = [
            (rect.width() * ppp).round().max(1.0) as u32,
            (rect.height() * ppp).round().max(1.0) as u32,
        ];
        if self.bake.is_some() {
            let cb = UploadOnce {
                settings: self.settings.clone(),
                bake: self.bake.clone(),
                uploaded: self.uploaded.clone(),
                size_px,
            };
            ui.painter()
                .add(egui_wgpu::Callback::new_paint_callback(rect, cb));
        }
        self.overlays_ui(ui, rect);
        if let (Some(p), Some(m)) = (&self.hovered, &self.model) {
            response.on_hover_ui_at_pointer(|ui| {
                ui.monospace(format!(
                    "({:.2}, {:.2}, {:.2}) mm",
                    p.hit.point.x, p.hit.point.y, p.hit.point.z
                ));
                for (id, f) in &p.hit.fractions {
                    ui.monospace(format!("{} {:.3}", m.table().name(*id), f));
                }
            });
        }
    }

    fn handle_input(&mut self, ui: &egui::Ui, rect: Rect, response: &egui::Response) {
        let aspect = rect.width() / rect.height().max(1.0);
        let ndc = |p: Pos2| {
            volcad_render::Vec2::new(
                (p.x - rect.left()) / rect.width() * 2.0 - 1.0,
                1.0 - (p.y - rect.top()) / rect.height() * 2.0,
            )
        };
        let scroll = if response.hovered() {
            ui.input(|i| i.smooth_scroll_delta.y)
        } else {
            0.0
        };
        if response.dragged() || scroll != 0.0 {
            self.auto_fit = false;
        }
        let cam = &mut self.settings.camera;
        if response.dragged() {
            let d = response.drag_delta();
            let pan = response.dragged_by(egui::PointerButton::Secondary)
                || response.dragged_by(egui::PointerButton::Middle)
                || ui.input(|i| i.modifiers.shift);
            if pan {
                cam.pan(d.x, d.y, rect.height());
            } else {
                cam.orbit(d.x, d.y);
            }
        }
        if response.hovered() {
            if scroll != 0.0
                && let Some(p) = response.hover_pos()
            {
                cam.zoom_to((-scroll * ZOOM_PER_POINT).exp(), ndc(p), aspect);
            }
            if ui.input(|i| i.key_pressed(Key::F)) && !ui.ctx().egui_wants_keyboard_input() {
                self.fit();
            }
        }
        if response.double_clicked() {
            self.fit();
        }
        let Some(model) = self.model.clone() else {
            return;
        };
        let request = |p: Pos2| super::probe::ProbeRequest {
            model: model.clone(),
            view: self.settings.clone(),
            ndc: ndc(p),
            aspect,
            pos: p,
        };
        if response.clicked()
            && let Some(p) = response.interact_pointer_pos()
        {
            // Pinning is rare and the user waits for it: run it here would
            // block on a big design, so it goes through the worker too.
            self.pinned = None;
            self.probe.request(ui.ctx(), request(p), true);
        }
        match response.hover_pos() {
            Some(p) if !response.dragged() && self.last_hover != Some(p) => {
                self.last_hover = Some(p);
                self.probe.request(ui.ctx(), request(p), false);
            }
            None => {
                self.last_hover = None;
                self.hovered = None;
            }
            _ => {}
        }
        if let Some(pin) = self.probe.take_pinned() {
            self.pinned = pin;
        }
    }

    fn overlays_ui(&self, ui: &mut egui::Ui, rect: Rect) {
        // Labels (not painted text) so they are readable by accessibility
        // tools and the UI tests.
        let v = ui.visuals().clone();
        let mut notes: Vec<(String, egui::Color32)> = Vec::new();
        if self.stale {
            notes.push((
                "Stale: the script has an error; showing the last good design".into(),
                v.warn_fg_color,
            ));
        }
        if self.model.is_none() {
            notes.push(("no design yet".into(), v.weak_text_color()));
        } else if self.bake.is_none() {
            notes.push(("baking…".into(), v.text_color()));
        } else if self.is_baking() {
            notes.push(("refining…".into(), v.weak_text_color()));
        }
        if !notes.is_empty() {
            let mut child = ui.new_child(
                egui::UiBuilder::new()
                    .max_rect(rect.shrink(8.0))
                    .layout(egui::Layout::top_down(egui::Align::Min)),
            );
            for (text, color) in notes {
                egui::Frame::popup(child.style())
                    .show(&mut child, |ui| ui.colored_label(color, text));
            }
        }
        let painter = ui.painter_at(rect);
        for (probe, pinned) in [(&self.hovered, false), (&self.pinned, true)] {
            if let Some(p) = probe {
                let (radius, color) = if pinned {
                    (5.0, egui::Color32::YELLOW)
                } else {
                    (3.0, v.text_color())
                };
                painter.circle_stroke(p.pos, radius, egui::Stroke::new(2.0, color));
            }
        }
    }

    /// The status line: bounding box, voxel size and bake level.
    pub fn status_text(&self) -> String {
        let Some(m) = &self.model else {
            return "no design".into();
        };
        let b = m.bbox();
        let mut s = if b.is_finite() && !b.is_empty() {
            let d = b.size();
            format!("bbox {:.2} × {:.2} × {:.2} mm", d.x, d.y, d.z)
        } else {
            "bbox unbounded".into()
        };
        if let Some((_, bake)) = &self.bake {
            s += &format!(
                "  ·  preview voxel {:.3} mm ({}³ level)",
                bake.voxel_size_mm, bake.resolution
            );
        }
        if self.is_baking() {
            let secs = self.bake_started.map_or(0.0, |t| t.elapsed().as_secs_f32());
            s += &format!("  ·  baking ({secs:.1} s)");
        }
        s
    }

    /// The material legend (right panel), after the attribute legend in
    /// attribute mode.
    pub fn legend_ui(&mut self, ui: &mut egui::Ui) {
        match self.model.clone() {
            Some(m) => {
                let bake = self.bake.as_ref().map(|(_, b)| b.as_ref());
                if attribute_view::legend_ui(ui, &m, &mut self.shading, bake) {
                    self.rebake(ui.ctx());
                }
                legend::materials_ui(ui, &m, &mut self.settings)
            }
            None => {
                ui.weak("No design.");
            }
        }
    }

    /// The probe read-out (right panel).
    pub fn probe_ui(&self, ui: &mut egui::Ui) {
        if let Some(m) = &self.model {
            legend::probe_ui(ui, m, self.hovered.as_ref(), self.pinned.as_ref());
        }
    }
}
