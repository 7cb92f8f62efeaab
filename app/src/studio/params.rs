//! Parameter sliders: one per `param(name, default, min, max)` the script
//! declared. Moving one re-runs the script with the value as an override
//! (`ScriptOptions.params`); the text is not edited.

use std::collections::HashMap;

use volcad_core::script::Param;

/// The user's slider values, by parameter name.
#[derive(Default)]
pub struct ParamPanel {
    overrides: HashMap<String, f64>,
}

impl ParamPanel {
    /// The overrides to run the script with.
    pub fn overrides(&self) -> &HashMap<String, f64> {
        &self.overrides
    }

    /// Forget every override (a new document).
    pub fn clear(&mut self) {
        self.overrides.clear();
    }

    /// Set one (tests, and the slider).
    pub fn set(&mut self, name: &str, value: f64) {
        self.overrides.insert(name.to_owned(), value);
    }

    /// Show the sliders; true when a value changed (re-run the script).
    pub fn ui(&mut self, ui: &mut egui::Ui, params: &[Param]) -> bool {
        if params.is_empty() {
            ui.weak("The script declares no parameters. Add one with\nparam(\"name\", default, min, max)");
            return false;
        }
        let mut changed = false;
        egui::Grid::new("params").num_columns(2).show(ui, |ui| {
            for p in params {
                let mut v = self
                    .overrides
                    .get(&p.name)
                    .copied()
                    .unwrap_or(p.value)
                    .clamp(p.min, p.max);
                let slider = egui::Slider::new(&mut v, p.min..=p.max)
                    .text(p.name.as_str())
                    .clamping(egui::SliderClamping::Always);
                let resp = ui.add(slider).on_hover_text(format!(
                    "default {}, range {} to {}",
                    p.default, p.min, p.max
                ));
                if resp.changed() {
                    self.overrides.insert(p.name.clone(), v);
                    changed = true;
                }
                let is_default = (v - p.default).abs() <= f64::EPSILON * p.default.abs().max(1.0);
                if ui
                    .add_enabled(!is_default, egui::Button::new("Reset").small())
                    .on_hover_text("Reset to the default")
                    .clicked()
                {
                    self.overrides.remove(&p.name);
                    changed = true;
                }
                ui.end_row();
            }
        });
        changed
    }
}
