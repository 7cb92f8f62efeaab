//! The printer exports' fields: the GrabCAD package (J750 grid, resin
//! map, seed, keep-out) and the vat stack (printer, intensity and its
//! range, vats, offset, layers or shard).
//! Text fields are parsed as the command line parses its options, so a
//! field that does not parse names itself and what to write.

use std::sync::Arc;

use volcad_compilers::gcvf::GcvfParams;
use volcad_compilers::plan::VatText;
use volcad_compilers::png_stack::{self, Dither};
use volcad_compilers::printer_table::parse_map;
use volcad_compilers::vat::{Intensity, VatParams, VatPrinter, vat_presets};
use volcad_core::Model;
use volcad_core::attribute::AttributeKind;

use super::fields::text_row;
use crate::studio::jobs::in_panel_words;

/// The fields of the GCVF and vat panels.
pub(super) struct PrinterFields {
    /// J750 high quality (14 µm layers) rather than high speed (27 µm).
    hq: bool,
    /// Material choice and seed, shared by both panels.
    dither: Dither,
    seed: u64,
    /// `red=VeroMgnt,blue=VeroCyan`.
    map: String,
    /// Liquid keep-out (mm), when on.
    keep_out: Option<f64>,
    /// Index into `vat_presets()`, or `None` for a custom screen.
    vat_preset: Option<usize>,
    /// Custom screen: pitch (µm), pixels, layer (µm).
    pixel_um: [f64; 2],
    screen: [usize; 2],
    layer_um: f64,
    intensity: Intensity,
    /// `a,b` or `a+c,b`: the materials of each vat (empty: one vat).
    vats: String,
    bmp: bool,
    /// The vat options the command line takes as text, as it writes them
    /// (`LO,HI`, `X,Y`, `A..B`, `K/N`; blank: not given).
    range: String,
    offset: String,
    layers: String,
    shard: String,
}

impl Default for PrinterFields {
    fn default() -> Self {
        Self {
            hq: false,
            dither: Dither::Random,
            seed: 0,
            map: String::new(),
            keep_out: None,
            vat_preset: Some(0),
            pixel_um: [50.0, 50.0],
            screen: [1920, 1080],
            layer_um: 50.0,
            intensity: Intensity::Solid,
            vats: String::new(),
            bmp: false,
            range: String::new(),
            offset: String::new(),
            layers: String::new(),
            shard: String::new(),
        }
    }
}

impl PrinterFields {
    /// The GCVF parameters (the job names the file after its destination).
    pub(super) fn gcvf(&self) -> Result<GcvfParams, String> {
        let name = if self.hq { "j750-hq" } else { "j750" };
        let voxel = png_stack::preset(name)
            .map(|p| p.voxel)
            .ok_or_else(|| format!("the {name} preset is missing"))?;
        Ok(GcvfParams {
            voxel,
            seed: self.seed,
            dither: self.dither,
            map: parse_map(&self.map).map_err(|e| in_panel_words(&e.to_string()))?,
            threads: None,
            file_name: "part.gcvf".into(),
            liquid_keep_out: self.keep_out,
        })
    }

    /// The vat stack's parameters.
    pub(super) fn vat(&self) -> Result<VatParams, String> {
        let printer = match self.vat_preset.and_then(|i| vat_presets().get(i).cloned()) {
            Some(p) => p,
            None => VatPrinter::custom(self.pixel_um, self.screen, self.layer_um)
                .map_err(|e| in_panel_words(&e.to_string()))?,
        };
        let vats = self
            .vats
            .split(',')
            .map(|g| {
                g.split('+')
                    .map(str::trim)
                    .filter(|m| !m.is_empty())
                    .map(str::to_owned)
                    .collect::<Vec<_>>()
            })
            .collect::<Vec<_>>();
        let vats = if self.vats.trim().is_empty() {
            Vec::new()
        } else {
            vats
        };
        let mut intensity = self.intensity.clone();
        let chosen = VatText {
            layers: Some(&self.layers),
            shard: Some(&self.shard),
            offset: Some(&self.offset),
            range: Some(&self.range),
        }
        .apply(&mut intensity)
        .map_err(|e| in_panel_words(&e.to_string()))?;
        Ok(VatParams {
            printer,
            intensity,
            vats,
            offset: chosen.offset,
            bmp: self.bmp,
            seed: self.seed,
            dither: self.dither,
            layers: chosen.layers,
            shard: chosen.shard,
            threads: None,
        })
    }

    /// The resin map's text (`red=VeroMgnt,blue=VeroCyan`).
    pub(super) fn map_text(&self) -> &str {
        &self.map
    }

    /// The resin map row (GCVF, and PNG stacks for a J750).
    pub(super) fn map_row(&mut self, ui: &mut egui::Ui) {
        let hint = "red=VeroMgnt,blue=VeroCyan";
        text_row(ui, "Resin map", &mut self.map, hint, 220.0)
            .on_hover_text("Design material = J750 resin, for names the J750 table lacks");
        ui.end_row();
    }

    /// Material choice and seed rows.
    fn draw_rows(&mut self, ui: &mut egui::Ui) {
        ui.label("Material choice");
        ui.horizontal(|ui| {
            ui.selectable_value(&mut self.dither, Dither::Random, "random");
            ui.selectable_value(&mut self.dither, Dither::Diffusion, "error diffusion");
        });
        ui.end_row();
        let label = ui.label("Seed").id;
        ui.add(egui::DragValue::new(&mut self.seed))
            .labelled_by(label);
        ui.end_row();
    }

    pub(super) fn gcvf_ui(&mut self, ui: &mut egui::Ui) {
        egui::Grid::new("gcvf-params")
            .num_columns(2)
            .show(ui, |ui| {
                ui.label("J750 mode");
                ui.horizontal(|ui| {
                    ui.selectable_value(&mut self.hq, false, "high speed (27 µm)");
                    ui.selectable_value(&mut self.hq, true, "high quality (14 µm)");
                });
                ui.end_row();
                self.map_row(ui);
                self.draw_rows(ui);
                ui.label("Liquid keep-out");
                ui.horizontal(|ui| {
                    let mut on = self.keep_out.is_some();
                    ui.checkbox(&mut on, "remove M.Cleanser within");
                    if on {
                        let d = self.keep_out.get_or_insert(0.5);
                        ui.add(
                            egui::DragValue::new(d)
                                .speed(0.01)
                                .range(0.0..=100.0)
                                .suffix(" mm"),
                        );
                    } else {
                        self.keep_out = None;
                    }
                });
                ui.end_row();
            });
    }

    pub(super) fn vat_ui(&mut self, ui: &mut egui::Ui, model: Option<&Arc<Model>>) {
        let presets = vat_presets();
        egui::Grid::new("vat-params").num_columns(2).show(ui, |ui| {
            let label = ui.label("Vat printer").id;
            let current = self
                .vat_preset
                .and_then(|i| presets.get(i))
                .map_or("Custom screen", |p| p.name.as_str());
            egui::ComboBox::from_id_salt("vat-printer")
                .selected_text(current)
                .show_ui(ui, |ui| {
                    for (i, p) in presets.iter().enumerate() {
                        ui.selectable_value(&mut self.vat_preset, Some(i), p.name.as_str())
                            .on_hover_text(p.description.as_str());
                    }
                    ui.selectable_value(&mut self.vat_preset, None, "Custom screen");
                })
                .response
                .labelled_by(label);
            ui.end_row();
            if self.vat_preset.is_none() {
                self.custom_rows(ui);
            }
            self.intensity_row(ui, model);
            let hint = "one vat; or a,b (a+c,b)";
            text_row(ui, "Vat materials", &mut self.vats, hint, 220.0);
            ui.end_row();
            self.draw_rows(ui);
            ui.label("");
            ui.checkbox(&mut self.bmp, "8-bit BMP instead of PNG");
            ui.end_row();
            self.vat_text_rows(ui);
        });
    }

    /// Offset, layers and shard: text as the command line takes it.
    fn vat_text_rows(&mut self, ui: &mut egui::Ui) {
        let rows = [
            (
                "Offset (mm)",
                "centred; or X,Y",
                &mut self.offset,
                "The part's centre moved from the screen's, X,Y mm",
            ),
            (
                "Layers",
                "all; or A..B, A..=B",
                &mut self.layers,
                "Only these layers (file names keep the global layer indices)",
            ),
            (
                "Shard",
                "all; or K/N",
                &mut self.shard,
                "Only the K-th of N equal layer ranges, for volcad merge",
            ),
        ];
        for (name, hint, text, tip) in rows {
            text_row(ui, name, text, hint, 220.0).on_hover_text(tip);
            ui.end_row();
        }
    }

    /// A custom screen's pitch, size and layer.
    fn custom_rows(&mut self, ui: &mut egui::Ui) {
        let label = ui.label("Pixel (µm)").id;
        ui.horizontal(|ui| {
            for v in &mut self.pixel_um {
                ui.add(egui::DragValue::new(v).speed(0.1).range(1.0..=10_000.0))
                    .labelled_by(label);
            }
        });
        ui.end_row();
        let label = ui.label("Screen (px)").id;
        ui.horizontal(|ui| {
            for v in &mut self.screen {
                ui.add(egui::DragValue::new(v).range(1..=65_535))
                    .labelled_by(label);
            }
        });
        ui.end_row();
        let label = ui.label("Layer (µm)").id;
        ui.add(
            egui::DragValue::new(&mut self.layer_um)
                .speed(0.5)
                .range(1.0..=10_000.0),
        )
        .labelled_by(label);
        ui.end_row();
    }

    /// Where the gray comes from: solid, a scalar attribute of the design
    /// (over its bound), or a material's fraction.
    fn intensity_row(&mut self, ui: &mut egui::Ui, model: Option<&Arc<Model>>) {
        let text = |i: &Intensity| match i {
            Intensity::Solid => "solid (255)".to_owned(),
            Intensity::Attribute { name, .. } => format!("attribute {name}"),
            Intensity::Fraction(m) => format!("fraction of {m}"),
        };
        let mut choices = vec![Intensity::Solid];
        if let Some(m) = model {
            choices.extend(
                m.attributes()
                    .iter()
                    .filter(|a| a.kind == AttributeKind::Scalar)
                    .map(|a| Intensity::Attribute {
                        name: a.name.clone(),
                        range: None,
                    }),
            );
            choices.extend(
                m.materials()
                    .iter()
                    .map(|id| Intensity::Fraction(m.table().name(*id).to_owned())),
            );
        }
        let label = ui.label("Intensity").id;
        egui::ComboBox::from_id_salt("vat-intensity")
            .selected_text(text(&self.intensity))
            .show_ui(ui, |ui| {
                for c in choices {
                    let t = text(&c);
                    ui.selectable_value(&mut self.intensity, c, t);
                }
            })
            .response
            .labelled_by(label);
        ui.end_row();
        if matches!(self.intensity, Intensity::Attribute { .. }) {
            let hint = "the attribute's bound; or LO,HI";
            text_row(ui, "Range", &mut self.range, hint, 220.0)
                .on_hover_text("The attribute values shown as black and white");
            ui.end_row();
        } else {
            self.range.clear();
        }
    }
}
