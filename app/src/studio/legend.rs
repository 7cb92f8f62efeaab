//! The right panel's read-outs of the viewport: the material legend
//! (swatch, name, visibility, opacity) and the probe.

use egui::Sense;
use volcad_core::Model;
use volcad_render::{ViewMode, ViewSettings};

use super::probe::Probe;

/// One row per material of the design: swatch, visibility, opacity.
pub fn materials_ui(ui: &mut egui::Ui, m: &Model, settings: &mut ViewSettings) {
    let volume = settings.mode == ViewMode::Volume;
    settings.material_opacity.resize(m.materials().len(), 1.0);
    egui::Grid::new("legend")
        .num_columns(3)
        .striped(true)
        .show(ui, |ui| {
            for (id, op) in m
                .materials()
                .iter()
                .zip(settings.material_opacity.iter_mut())
            {
                let Some(mat) = m.table().get(*id) else {
                    continue;
                };
                let [r, g, b, _] = mat.rgba();
                let (swatch, _) = ui.allocate_exact_size(egui::vec2(14.0, 14.0), Sense::hover());
                ui.painter()
                    .rect_filled(swatch, 2.0, egui::Color32::from_rgb(r, g, b));
                ui.painter().rect_stroke(
                    swatch,
                    2.0,
                    ui.visuals().widgets.noninteractive.bg_stroke,
                    egui::StrokeKind::Inside,
                );
                let mut visible = *op > 0.0;
                if ui
                    .checkbox(&mut visible, mat.name.as_str())
                    .on_hover_text(format!("material id {id}"))
                    .changed()
                {
                    *op = if visible { 1.0 } else { 0.0 };
                }
                ui.add_enabled(
                    volume || *op > 0.0,
                    egui::Slider::new(op, 0.0..=1.0).show_value(false),
                )
                .on_hover_text("Opacity (volume mode); 0 hides it");
                ui.end_row();
            }
        });
}

/// The probe read-outs: under the cursor, and pinned by a click.
pub fn probe_ui(ui: &mut egui::Ui, m: &Model, hovered: Option<&Probe>, pinned: Option<&Probe>) {
    for (title, probe) in [("Under the cursor", hovered), ("Pinned (click)", pinned)] {
        ui.label(egui::RichText::new(title).strong());
        let Some(p) = probe else {
            ui.weak("—");
            continue;
        };
        let q = p.hit.point;
        ui.weak(p.hit.surface.describe());
        ui.monospace(format!("x {:.3}  y {:.3}  z {:.3} mm", q.x, q.y, q.z));
        ui.monospace(format!(
            "distance {:.4} mm (depth {:.2} mm)",
            p.surface_distance, p.hit.distance
        ));
        for (id, f) in &p.hit.fractions {
            ui.monospace(format!("{:>10}  {:.3}", m.table().name(*id), f));
        }
        for a in &p.attributes {
            ui.monospace(a.text());
        }
    }
}
