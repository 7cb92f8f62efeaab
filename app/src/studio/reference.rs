//! Help → Language reference: every script function with its forms, a
//! description and an example, searchable, and the math strings'
//! names; the same entries give the editor's hover tooltips
//! (`volcad_core::script::reference`, checked against the engine).

use volcad_core::script::reference::{self, FnDoc, Group};

/// The reference window.
#[derive(Default)]
pub struct ReferenceWindow {
    /// Shown.
    pub open: bool,
    /// The search box's text.
    pub query: String,
}

const GROUPS: [Group; 8] = [
    Group::Geometry,
    Group::Lattice,
    Group::Boolean,
    Group::Transform,
    Group::Material,
    Group::Data,
    Group::Method,
    Group::Value,
];

/// One entry: name, forms, description and example.
pub fn entry_ui(ui: &mut egui::Ui, f: &FnDoc) {
    ui.label(egui::RichText::new(f.name).strong().monospace());
    for form in f.forms {
        ui.monospace(*form);
    }
    ui.label(f.summary);
    if !f.example.is_empty() {
        ui.weak(format!("e.g. {}", f.skeleton));
    }
}

impl ReferenceWindow {
    /// Draw the window when open.
    pub fn ui(&mut self, ctx: &egui::Context) {
        let mut open = self.open;
        egui::Window::new("Language reference")
            .open(&mut open)
            .default_size([460.0, 520.0])
            // Over the editor, where the script being written is, not
            // over the part.
            .default_pos([24.0, 90.0])
            .vscroll(false)
            .show(ctx, |ui| {
                ui.horizontal(|ui| {
                    ui.label("Search");
                    ui.add(
                        egui::TextEdit::singleline(&mut self.query)
                            .id_salt("reference-search")
                            .hint_text("name or words, e.g. lattice"),
                    );
                });
                ui.separator();
                egui::ScrollArea::vertical()
                    .id_salt("reference-scroll")
                    .show(ui, |ui| self.entries_ui(ui));
            });
        self.open = open;
    }

    fn entries_ui(&self, ui: &mut egui::Ui) {
        let found: Vec<&FnDoc> = reference::search(&self.query).collect();
        for g in GROUPS {
            let in_group: Vec<&&FnDoc> = found.iter().filter(|f| f.group == g).collect();
            if in_group.is_empty() {
                continue;
            }
            ui.heading(g.title());
            for f in in_group {
                entry_ui(ui, f);
                ui.add_space(6.0);
            }
        }
        let q = self.query.to_lowercase();
        let math: Vec<_> = reference::MATH
            .iter()
            .filter(|m| {
                q.is_empty()
                    || m.name.to_lowercase().contains(&q)
                    || m.summary.to_lowercase().contains(&q)
            })
            .collect();
        if !math.is_empty() {
            ui.heading("Math strings (FGrade, Function, SimulationField)");
            egui::Grid::new("math-reference")
                .striped(true)
                .show(ui, |ui| {
                    for m in math {
                        ui.monospace(m.name);
                        ui.label(m.summary);
                        ui.end_row();
                    }
                });
        }
        if found.is_empty() && self.query.len() > 1 {
            ui.weak(format!("Nothing matches \"{}\".", self.query));
        }
    }
}
