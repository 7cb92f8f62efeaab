//! The viewport's attribute mode: which field colours the surface and the
//! cut plane (the materials, or one of `Model::attributes()`), its range,
//! and the legend (colour bar, name, unit, range).

use volcad_core::Model;
use volcad_core::attribute::{AttributeKind, range};
use volcad_render::{AttributeShading, ColorMap, VolumeBake};

/// What colours the picture.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Shading {
    /// The attribute by name (`None`: the materials). A name, not an
    /// index, so the choice survives edits that add attributes.
    pub attribute: Option<String>,
    /// A fixed range for scalars (`None`: the baked values' own).
    pub fixed: Option<[f64; 2]>,
}

/// The label of the "colour by materials" entry.
pub const MATERIALS: &str = "Materials";

impl Shading {
    /// The bake's shading for `model`, or `None` for the materials (also
    /// when the design no longer has the attribute).
    pub fn for_model(&self, model: &Model) -> Option<AttributeShading> {
        let name = self.attribute.as_deref()?;
        let index = model.attribute_index(name)?;
        Some(AttributeShading {
            index,
            width: model.attributes()[index].kind.width(),
            range: self.fixed,
            map: ColorMap::Viridis,
        })
    }

    /// The combo box of what colours the picture; true when it changed.
    pub fn picker_ui(&mut self, ui: &mut egui::Ui, model: Option<&Model>) -> bool {
        let before = self.clone();
        let names: Vec<String> = model
            .map(|m| m.attributes().iter().map(|a| a.name.clone()).collect())
            .unwrap_or_default();
        ui.label("Colour");
        egui::ComboBox::from_id_salt("shade-by")
            .selected_text(self.attribute.as_deref().unwrap_or(MATERIALS))
            .show_ui(ui, |ui| {
                ui.selectable_value(&mut self.attribute, None, MATERIALS);
                for n in &names {
                    ui.selectable_value(&mut self.attribute, Some(n.clone()), n);
                }
            })
            .response
            .on_hover_text(
                "Shade the surface and the cut plane by the materials or by an attribute \
                 (scalars through the viridis colour map, vectors by magnitude, colours as they are)",
            );
        if self.attribute != before.attribute {
            self.fixed = None;
        }
        *self != before
    }
}

/// Unit of a common attribute name (`""` for others).
pub fn unit(name: &str) -> &'static str {
    range(name).map_or("", |(_, _, u)| u)
}

/// The legend of the attribute on screen: name, unit, colour bar and range
/// (automatic or fixed, editable). True when the range changed.
pub fn legend_ui(
    ui: &mut egui::Ui,
    model: &Model,
    shading: &mut Shading,
    bake: Option<&VolumeBake>,
) -> bool {
    let Some(s) = shading.for_model(model) else {
        return false;
    };
    let info = &model.attributes()[s.index];
    let unit = unit(&info.name);
    let title = if unit.is_empty() {
        info.name.clone()
    } else {
        format!("{} ({unit})", info.name)
    };
    ui.label(egui::RichText::new(title).strong());
    if info.kind == AttributeKind::Vec4 {
        ui.weak("shown as its own colour (RGBA)");
        return false;
    }
    if info.kind == AttributeKind::Vec3 {
        ui.weak("shaded by magnitude");
    }
    color_bar(ui, s.map);
    let shown = s.range.or_else(|| bake.and_then(|b| b.attribute_range));
    let mut changed = false;
    ui.horizontal(|ui| match shown {
        Some([lo, hi]) => {
            ui.monospace(format!("min {}", fmt(lo)));
            ui.monospace(format!("max {}", fmt(hi)));
        }
        None => {
            ui.weak("no values baked yet");
        }
    });
    let mut auto = shading.fixed.is_none();
    if ui
        .checkbox(&mut auto, "Automatic range")
        .on_hover_text("Automatic: the smallest and largest value of the baked preview")
        .changed()
    {
        shading.fixed = if auto {
            None
        } else {
            Some(shown.unwrap_or([0.0, 1.0]))
        };
        changed = true;
    }
    if let Some([lo, hi]) = &mut shading.fixed {
        ui.horizontal(|ui| {
            changed |= ui.add(egui::DragValue::new(lo).prefix("min ")).changed();
            changed |= ui.add(egui::DragValue::new(hi).prefix("max ")).changed();
        });
    }
    ui.weak("grey: inside, but no node sets it");
    changed
}

/// A number for the legend: 4 significant digits.
pub fn fmt(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        format!("{v:.3}")
    } else if v.abs() >= 1e5 || v.abs() < 1e-3 {
        format!("{v:.3e}")
    } else {
        let decimals = (3 - v.abs().log10().floor() as i32).clamp(0, 6) as usize;
        format!("{v:.decimals$}")
    }
}

/// The colour map as a horizontal bar, low values on the left.
fn color_bar(ui: &mut egui::Ui, map: ColorMap) {
    let width = ui.available_width().clamp(80.0, 240.0);
    let (rect, _) = ui.allocate_exact_size(egui::vec2(width, 14.0), egui::Sense::hover());
    let steps = 64;
    let painter = ui.painter();
    for i in 0..steps {
        let t = (i as f64 + 0.5) / steps as f64;
        let [r, g, b, _] = map.color(t);
        let x0 = rect.left() + rect.width() * i as f32 / steps as f32;
        let x1 = rect.left() + rect.width() * (i + 1) as f32 / steps as f32;
        painter.rect_filled(
            egui::Rect::from_x_y_ranges(x0..=x1, rect.y_range()),
            0.0,
            egui::Color32::from_rgb(r, g, b),
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn legend_numbers_keep_four_significant_digits() {
        assert_eq!(fmt(2850.0), "2850");
        assert_eq!(fmt(0.35), "0.3500");
        assert_eq!(fmt(12.25), "12.25");
        assert_eq!(fmt(0.0), "0.000");
        assert_eq!(fmt(2.5e6), "2.500e6");
    }
}
