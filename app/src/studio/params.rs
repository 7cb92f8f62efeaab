//! Parameter sliders: one per `param(name, default, min, max)` the script
//! declared. Moving one re-runs the script with the value as an override
//! (`ScriptOptions.params`); the text is not edited. Named sets of values
//! live beside the design (`design.params.json`, OpenSCAD's customizer
//! layout): the panel switches between them and saves the sliders as one,
//! and reopening the design brings back the set chosen last.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use volcad_core::script::Param;
use volcad_core::script::param_sets::{self, ParamSets};

/// The user's slider values, by parameter name, and the design's sets.
#[derive(Default)]
pub struct ParamPanel {
    overrides: HashMap<String, f64>,
    sets: ParamSets,
    /// The sets file (`None`: the design is not saved yet).
    sets_path: Option<PathBuf>,
    /// The set the sliders came from.
    current: Option<String>,
    /// The name field for saving a set.
    new_name: String,
}

impl ParamPanel {
    /// The overrides to run the script with.
    pub fn overrides(&self) -> &HashMap<String, f64> {
        &self.overrides
    }

    /// Forget every override (a new document).
    pub fn clear(&mut self) {
        self.overrides.clear();
        self.sets = ParamSets::default();
        self.sets_path = None;
        self.current = None;
    }

    /// The design at `design` was opened: read its sets file if it has one
    /// and take the values of the set chosen last. An unreadable file is
    /// an error for the log (the sliders start from the defaults).
    pub fn open_sets(&mut self, design: Option<&Path>) -> Result<(), String> {
        self.clear();
        let Some(design) = design else {
            return Ok(());
        };
        let path = param_sets::path_beside(design);
        self.sets_path = Some(path.clone());
        if !path.exists() {
            return Ok(());
        }
        self.sets = ParamSets::load(&path).map_err(|e| e.to_string())?;
        if let Some(name) = self.sets.last_set.clone() {
            self.choose(&name)?;
        }
        Ok(())
    }

    /// Take the values of set `name`.
    pub fn choose(&mut self, name: &str) -> Result<(), String> {
        self.overrides = self.sets.values(name).map_err(|e| e.to_string())?;
        self.current = Some(name.to_owned());
        Ok(())
    }

    /// Save the sliders' values (of `params`) as set `name` beside the design.
    pub fn save_set(&mut self, name: &str, params: &[Param]) -> Result<PathBuf, String> {
        let path = self
            .sets_path
            .clone()
            .ok_or("save the design first: sets are kept beside its file")?;
        let name = name.trim();
        if name.is_empty() {
            return Err("give the set a name".into());
        }
        let values = params
            .iter()
            .map(|p| {
                (
                    p.name.clone(),
                    self.overrides.get(&p.name).copied().unwrap_or(p.value),
                )
            })
            .collect();
        self.sets.store(name, &values);
        self.sets.save(&path).map_err(|e| e.to_string())?;
        self.current = Some(name.to_owned());
        Ok(path)
    }

    /// The set names, in order.
    pub fn set_names(&self) -> Vec<String> {
        self.sets.sets.keys().cloned().collect()
    }

    /// The design was saved under a new name: keep its sets there.
    pub fn moved_to(&mut self, design: &Path) {
        self.sets_path = Some(param_sets::path_beside(design));
    }

    /// The set row: choose a set, or save the sliders as one. Returns a
    /// log line and whether the values changed.
    fn sets_ui(&mut self, ui: &mut egui::Ui, params: &[Param]) -> (Option<String>, bool) {
        let mut log = None;
        let mut changed = false;
        ui.horizontal(|ui| {
            let shown = self.current.clone().unwrap_or_else(|| "(sliders)".into());
            egui::ComboBox::from_label("Set")
                .selected_text(shown)
                .show_ui(ui, |ui| {
                    for name in self.set_names() {
                        if ui
                            .selectable_label(self.current.as_deref() == Some(&name), &name)
                            .clicked()
                        {
                            match self.choose(&name) {
                                Ok(()) => changed = true,
                                Err(e) => log = Some(e),
                            }
                        }
                    }
                });
        });
        ui.horizontal(|ui| {
            let l = ui.label("Set name").id;
            ui.add(egui::TextEdit::singleline(&mut self.new_name).desired_width(110.0))
                .labelled_by(l);
            let can = self.sets_path.is_some();
            let r = ui
                .add_enabled(can, egui::Button::new("Save set"))
                .on_hover_text("Save the sliders as a named set beside the design")
                .on_disabled_hover_text("Save the design first: sets are kept beside its file");
            if r.clicked() {
                let name = self.new_name.clone();
                log = Some(match self.save_set(&name, params) {
                    Ok(p) => format!("saved parameter set \"{}\" in {}", name.trim(), p.display()),
                    Err(e) => format!("parameter set not saved: {e}"),
                });
            }
        });
        (log, changed)
    }

    /// Set one (tests, and the slider).
    pub fn set(&mut self, name: &str, value: f64) {
        self.overrides.insert(name.to_owned(), value);
    }

    /// Show the sets and the sliders; a log line, and true when a value
    /// changed (re-run the script).
    pub fn ui(&mut self, ui: &mut egui::Ui, params: &[Param]) -> (Option<String>, bool) {
        if params.is_empty() {
            ui.weak("The script declares no parameters. Add one with\nparam(\"name\", default, min, max)");
            return (None, false);
        }
        let (log, mut changed) = self.sets_ui(ui, params);
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
                    self.current = None;
                    changed = true;
                }
                let is_default = (v - p.default).abs() <= f64::EPSILON * p.default.abs().max(1.0);
                if ui
                    .add_enabled(!is_default, egui::Button::new("Reset").small())
                    .on_hover_text("Reset to the default")
                    .clicked()
                {
                    self.overrides.remove(&p.name);
                    self.current = None;
                    changed = true;
                }
                ui.end_row();
            }
        });
        (log, changed)
    }
}
