//! The export panels' parameter fields, one function per kind (the
//! output folder, estimate and Start button are shared, in `mod.rs`).

use std::path::PathBuf;
use std::sync::Arc;

use glam::DVec3;
use volcad_compilers::bitmaps::{BitmapFormat, MYERSON_WIDTH};
use volcad_compilers::fea::{Element, property_bins};
use volcad_compilers::mesh::{MeshFormats, SegmentBy};
use volcad_compilers::png_stack::{self, Dither};
use volcad_core::Model;

use super::ExportPanels;

/// The PNG printer choice without a preset: any voxel, the design's own
/// material table.
const GENERIC: &str = "Generic (custom voxel)";

/// One grid row of the export panels: `label`, then a one-line text field
/// `width` points wide that shows `hint` while empty, labelled by the label
/// (for screen readers). The caller adds hover text and ends the row.
pub(super) fn text_row(
    ui: &mut egui::Ui,
    label: &str,
    text: &mut String,
    hint: &str,
    width: f32,
) -> egui::Response {
    let label = ui.label(label).id;
    ui.add(
        egui::TextEdit::singleline(text)
            .hint_text(hint)
            .desired_width(width),
    )
    .labelled_by(label)
}

/// A length in mm for the FEA fields: 0.01 to 100 mm, dragged in 0.01 mm steps.
fn fea_mm(v: &mut f64) -> egui::DragValue<'_> {
    egui::DragValue::new(v).speed(0.01).range(0.01..=100.0)
}

impl ExportPanels {
    pub(super) fn png_ui(&mut self, ui: &mut egui::Ui) {
        let presets = png_stack::presets();
        egui::Grid::new("png-params").num_columns(2).show(ui, |ui| {
            let label = ui.label("Printer").id;
            let current = self.preset.map_or(GENERIC, |i| presets[i].name);
            egui::ComboBox::from_id_salt("png-preset")
                .selected_text(current)
                .show_ui(ui, |ui| {
                    for (i, p) in presets.iter().enumerate() {
                        if ui
                            .selectable_label(self.preset == Some(i), p.name)
                            .on_hover_text(p.description)
                            .clicked()
                        {
                            self.preset = Some(i);
                            self.png.voxel = p.voxel;
                        }
                    }
                    if ui
                        .selectable_label(self.preset.is_none(), GENERIC)
                        .on_hover_text("Any voxel, the design's own materials and colours")
                        .clicked()
                    {
                        self.preset = None;
                    }
                })
                .response
                .labelled_by(label);
            ui.end_row();
            if self.png_j750() {
                self.printers.map_row(ui);
            }
            let label = ui.label("Voxel (mm)").id;
            ui.horizontal(|ui| {
                let mut changed = false;
                for v in [
                    &mut self.png.voxel.x,
                    &mut self.png.voxel.y,
                    &mut self.png.voxel.z,
                ] {
                    changed |= ui
                        .add(
                            egui::DragValue::new(v)
                                .speed(0.001)
                                .range(0.001..=10.0)
                                .max_decimals(4),
                        )
                        .labelled_by(label)
                        .changed();
                }
                if changed {
                    self.preset = None;
                }
            });
            ui.end_row();
            ui.label("Material choice");
            ui.horizontal(|ui| {
                ui.selectable_value(&mut self.png.dither, Dither::Random, "random");
                ui.selectable_value(&mut self.png.dither, Dither::Diffusion, "error diffusion");
            });
            ui.end_row();
            let label = ui.label("Seed").id;
            ui.add(egui::DragValue::new(&mut self.png.seed))
                .labelled_by(label);
            ui.end_row();
            // One row for both switches: a taller panel would push a
            // running job's Cancel out of view.
            ui.label("");
            ui.horizontal(|ui| {
                ui.checkbox(&mut self.png.per_material_bitmaps, "1-bit bitmaps")
                    .on_hover_text("Also one 1-bit image per material per layer");
                ui.checkbox(&mut self.png.full_color, "Full colour")
                    .on_hover_text(
                        "Each voxel a J750 colour resin reproducing the design's colour",
                    );
            });
            ui.end_row();
            if self.png.per_material_bitmaps {
                self.bitmap_ui(ui);
            }
            self.full_color_ui(ui);
        });
    }

    /// Bitmap format and BMP width (`--bitmap-format`, `--bitmap-width`).
    fn bitmap_ui(&mut self, ui: &mut egui::Ui) {
        ui.label("Bitmap format");
        ui.horizontal(|ui| {
            ui.selectable_value(&mut self.png.bitmap_format, BitmapFormat::Png, "PNG");
            ui.selectable_value(
                &mut self.png.bitmap_format,
                BitmapFormat::Bmp,
                "BMP (Myerson)",
            )
            .on_hover_text("1-bit BMPs, material black on white, <100000+layer>_100000_<name>.bmp");
        });
        ui.end_row();
        if self.png.bitmap_format != BitmapFormat::Bmp {
            self.png.bitmap_width = None;
            return;
        }
        let label = ui.label("Bitmap width").id;
        ui.horizontal(|ui| {
            let mut fixed = self.png.bitmap_width.is_some();
            ui.checkbox(&mut fixed, "fixed");
            if fixed {
                let w = self.png.bitmap_width.get_or_insert(MYERSON_WIDTH);
                ui.add(egui::DragValue::new(w).range(1..=100_000).suffix(" px"))
                    .labelled_by(label);
            } else {
                self.png.bitmap_width = None;
            }
        });
        ui.end_row();
    }

    /// The profile of a full-colour stack (`--color-profile`).
    fn full_color_ui(&mut self, ui: &mut egui::Ui) {
        if !self.png.full_color {
            self.png.color_profile = None;
            return;
        }
        let mut text = self
            .png
            .color_profile
            .as_ref()
            .map(|p| p.display().to_string())
            .unwrap_or_default();
        let hint = "CSV of measured resins (optional)";
        if text_row(ui, "Colour profile", &mut text, hint, 180.0).changed() {
            self.png.color_profile = (!text.is_empty()).then(|| PathBuf::from(text));
        }
        ui.end_row();
    }

    pub(super) fn mesh_ui(&mut self, ui: &mut egui::Ui, model: Option<&Arc<Model>>) {
        egui::Grid::new("mesh-params")
            .num_columns(2)
            .show(ui, |ui| {
                let label = ui.label("Mesh voxel (mm)").id;
                let mut v = self.mesh.voxel.x;
                if ui
                    .add(
                        egui::DragValue::new(&mut v)
                            .speed(0.005)
                            .range(0.005..=10.0)
                            .max_decimals(3),
                    )
                    .labelled_by(label)
                    .changed()
                {
                    self.mesh.voxel = DVec3::splat(v);
                }
                ui.end_row();
                let label = ui.label("Split by").id;
                let name = |id| {
                    model.map_or_else(
                        || format!("material {id}"),
                        |m| m.table().name(id).to_owned(),
                    )
                };
                let current = match self.mesh.by {
                    SegmentBy::Dominant => "dominant material".to_owned(),
                    SegmentBy::Material(id) => format!("fraction of {}", name(id)),
                };
                egui::ComboBox::from_id_salt("mesh-by")
                    .selected_text(current)
                    .show_ui(ui, |ui| {
                        ui.selectable_value(
                            &mut self.mesh.by,
                            SegmentBy::Dominant,
                            "dominant material",
                        );
                        for id in model.map(|m| m.materials().to_vec()).unwrap_or_default() {
                            ui.selectable_value(
                                &mut self.mesh.by,
                                SegmentBy::Material(id),
                                format!("fraction of {}", name(id)),
                            );
                        }
                    })
                    .response
                    .labelled_by(label);
                ui.end_row();
                if matches!(self.mesh.by, SegmentBy::Material(_)) {
                    let label = ui.label("Segments").id;
                    ui.add(egui::DragValue::new(&mut self.mesh.segments).range(1..=64))
                        .labelled_by(label);
                    ui.end_row();
                }
                ui.label("Formats");
                ui.horizontal(|ui| {
                    let MeshFormats { stl, obj, threemf } = &mut self.mesh.formats;
                    ui.checkbox(stl, "STL");
                    ui.checkbox(obj, "OBJ");
                    ui.checkbox(threemf, "3MF");
                });
                ui.end_row();
                let mut expr = self.mesh.infill_expr.clone().unwrap_or_default();
                let hint = volcad_compilers::mesh::DEFAULT_INFILL;
                if text_row(ui, "3MF infill % of f", &mut expr, hint, 140.0).changed() {
                    self.mesh.infill_expr =
                        (!expr.trim().is_empty()).then(|| expr.trim().to_owned());
                }
                ui.end_row();
            });
    }

    pub(super) fn fea_ui(&mut self, ui: &mut egui::Ui) {
        egui::Grid::new("fea-params").num_columns(2).show(ui, |ui| {
            ui.label("Elements");
            ui.horizontal(|ui| {
                ui.selectable_value(&mut self.fea.element, Element::C3D8R, "C3D8R bricks");
                ui.selectable_value(&mut self.fea.element, Element::C3D4, "C3D4 tets");
            });
            ui.end_row();
            match self.fea.element {
                Element::C3D8R => {
                    let label = ui.label("Brick (mm)").id;
                    ui.add(fea_mm(&mut self.fea.voxel)).labelled_by(label);
                    ui.end_row();
                }
                Element::C3D4 => {
                    let label = ui.label("Cell min / max (mm)").id;
                    ui.horizontal(|ui| {
                        ui.add(fea_mm(&mut self.fea.min_cell)).labelled_by(label);
                        ui.add(fea_mm(&mut self.fea.max_cell)).labelled_by(label);
                    });
                    ui.end_row();
                    text_row(
                        ui,
                        "Size of h (mm)",
                        &mut self.fea_expr,
                        "linear in h",
                        140.0,
                    );
                    ui.end_row();
                }
            }
            let label = ui.label("FEA seed").id;
            ui.add(egui::DragValue::new(&mut self.fea.seed))
                .labelled_by(label);
            ui.end_row();
            let label = ui.label("Property bins").id;
            let mut bins = self
                .fea
                .property_bins
                .unwrap_or(property_bins::DEFAULT_BINS);
            let changed = ui
                .add(egui::DragValue::new(&mut bins).range(1..=property_bins::MAX_BINS))
                .labelled_by(label)
                .on_hover_text("Elastic sets per property when the design has a modulus attribute")
                .changed();
            if changed || self.fea.property_bins.is_some() {
                self.fea.property_bins = Some(bins);
            }
            ui.end_row();
            ui.label("Static step");
            ui.horizontal(|ui| {
                let mut on = self.fea_step.is_some();
                ui.checkbox(&mut on, "top z displacement");
                if on {
                    let d = self.fea_step.get_or_insert(-0.5);
                    ui.add(egui::DragValue::new(d).speed(0.01).suffix(" mm"))
                        .on_hover_text("Top z displacement");
                } else {
                    self.fea_step = None;
                }
            });
            ui.end_row();
        });
    }
}
