//! Export panels: PNG slice stack (inkjet), segmented meshes (STL/OBJ/3MF),
//! FEA meshes (.inp), GrabCAD packages (.gcvf, one file) and vat printer
//! stacks (printer fields in `printer_fields.rs`). Each has its parameters with defaults (printer
//! presets for slice stacks, fields in `fields.rs`), an output folder, an
//! estimate computed on a worker (`worker.rs`), and a Start button. What
//! happens before and at the start is `volcad_compilers::plan`, the same
//! plan the command line runs: its refusals are logged, its questions asked
//! in a modal, its warnings shown under the estimate, in the panel's words.
//!
//! Output folder: one per design and kind, `<design>_<kind>` beside the
//! script (an untitled design's in the documents folder), remembered in
//! the settings once typed or picked. A folder that holds a finished export
//! is replaced only after the user agrees; one holding other files is
//! never used.

mod fields;
mod printer_fields;
mod worker;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use glam::DVec3;
use volcad_compilers::fea::{Element, FeaParams, Sizing, StepParams};
use volcad_compilers::job::design_hash;
use volcad_compilers::mesh::MeshParams;
use volcad_compilers::plan::folder::{self, Folder};
use volcad_compilers::plan::{ExportParams, Opt, Severity, Verdict};
use volcad_compilers::png_stack::{self, PngParams};
use volcad_compilers::printer_table::{check_j750_tray, is_j750_preset, j750_model, parse_map};
use volcad_core::Model;

use super::files::Document;
use super::jobs::{Jobs, in_panel_words};
use worker::EstimateWorker;

/// What the panel asks the app to do.
pub enum Action {
    /// Nothing.
    None,
    /// Show a folder dialog for the output folder.
    PickFolder(usize),
    /// Log a line.
    Log(String),
    /// Ask before the waiting export starts ([`ExportPanels::confirm`] or
    /// [`ExportPanels::cancel_pending`] answers).
    Ask(Question),
}

/// A question before an export starts.
#[derive(Clone, Debug, PartialEq)]
pub struct Question {
    /// The modal's heading.
    pub heading: String,
    /// What would be replaced or outgrown.
    pub text: String,
    /// The button that goes ahead.
    pub confirm: String,
}

/// Which export: the command line's kinds (`volcad export KIND`).
pub use crate::cli::export::Kind;

impl Kind {
    fn title(self) -> &'static str {
        match self {
            Kind::Png => "PNG stack",
            Kind::Mesh => "Meshes / 3MF",
            Kind::Fea => "FEA (.inp)",
            Kind::Gcvf => "GCVF (.gcvf)",
            Kind::Vat => "Vat stack",
        }
    }

    /// The tab's label: short, so the five tabs keep one row in the side
    /// panel's default width (a second row pushes a running job's Cancel
    /// out of view); the hover gives [`Kind::title`].
    fn tab(self) -> &'static str {
        match self {
            Kind::Png => "PNG",
            Kind::Mesh => "Mesh",
            Kind::Fea => "FEA",
            Kind::Gcvf => "GCVF",
            Kind::Vat => "Vat",
        }
    }

    fn suffix(self) -> &'static str {
        match self {
            Kind::Png => "png",
            Kind::Mesh => "mesh",
            Kind::Fea => "fea",
            Kind::Gcvf => "gcvf",
            Kind::Vat => "vat",
        }
    }

    /// The output field's label: a GCVF package is one file.
    fn out_label(self) -> &'static str {
        match self {
            Kind::Gcvf => "Output file",
            _ => "Output folder",
        }
    }
}

/// The design the panels export, as far as output folders go.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Place {
    /// What its folders are remembered by: the script's path, or
    /// `untitled:NAME`.
    pub key: String,
    /// Its file name ("bar.rhai"), for folder names and manifests.
    pub name: String,
    /// Where its folders go by default: beside the script.
    pub folder: PathBuf,
}

impl Place {
    /// Where `doc`'s export folders go: beside its script, or in
    /// `documents` (else the current folder) when it has none.
    pub fn of(doc: &Document, documents: Option<&Path>) -> Place {
        let name = doc.name();
        match &doc.path {
            Some(p) => Place {
                key: p.display().to_string(),
                folder: p.parent().map_or_else(PathBuf::new, Path::to_path_buf),
                name,
            },
            None => Place {
                key: format!("untitled:{name}"),
                folder: documents.map_or_else(|| PathBuf::from("."), Path::to_path_buf),
                name,
            },
        }
    }

    /// `<folder>/<design>_<kind>`, or `<folder>/<design>.gcvf` for a
    /// GrabCAD package.
    fn default_dir(&self, kind: Kind) -> PathBuf {
        match kind {
            Kind::Gcvf => self.folder.join(self.file_name(kind)),
            _ => self
                .folder
                .join(format!("{}_{}", self.stem(), kind.suffix())),
        }
    }

    /// The design's name without its extension.
    fn stem(&self) -> String {
        Path::new(&self.name)
            .file_stem()
            .map_or_else(|| "design".into(), |s| s.to_string_lossy().into_owned())
    }

    /// `<design>.<kind>`: the file a one-file export writes in a folder.
    fn file_name(&self, kind: Kind) -> String {
        format!("{}.{}", self.stem(), kind.suffix())
    }

    /// The settings key of its folder for `kind`.
    fn dir_key(&self, kind: Kind) -> String {
        format!("{}|{}", kind.suffix(), self.key)
    }
}

/// An export waiting for the user's answer.
struct Pending {
    params: ExportParams,
    model: Arc<Model>,
    dest: PathBuf,
    hash: String,
    design: String,
    title: &'static str,
}

/// The export panels' state.
pub struct ExportPanels {
    /// Folders typed or picked, by [`Place::dir_key`].
    dirs: BTreeMap<String, PathBuf>,
    /// The folder field's text, and the key it belongs to.
    dir: String,
    shown: Option<String>,
    kind: Kind,
    png: PngParams,
    /// Index into `png_stack::presets()`, or `None` for a custom voxel.
    preset: Option<usize>,
    mesh: MeshParams,
    fea: FeaParams,
    fea_expr: String,
    fea_step: Option<f64>,
    /// GrabCAD package and vat stack fields (`printer_fields.rs`).
    printers: printer_fields::PrinterFields,
    /// The file a one-file export gets in a picked folder.
    file_name: String,
    /// The design as the PNG printer choice prints it (a J750 relabels it
    /// with resins), by model and resin map.
    printed: Option<(usize, String, Result<Arc<Model>, String>)>,
    estimate: EstimateWorker,
    pending: Option<Pending>,
    /// Why the last Start did not start, shown until the next.
    refusal: Option<String>,
}

impl ExportPanels {
    /// Panels remembering the folders in `dirs` (from the settings).
    pub fn new(dirs: BTreeMap<String, PathBuf>) -> Self {
        Self {
            dirs,
            dir: String::new(),
            shown: None,
            kind: Kind::Png,
            png: PngParams::default(),
            preset: None,
            mesh: MeshParams {
                voxel: DVec3::splat(0.25),
                ..MeshParams::default()
            },
            fea: FeaParams {
                element: Element::C3D8R,
                ..FeaParams::default()
            },
            fea_expr: String::new(),
            fea_step: None,
            printers: printer_fields::PrinterFields::default(),
            file_name: String::new(),
            printed: None,
            estimate: EstimateWorker::default(),
            pending: None,
            refusal: None,
        }
    }

    /// The folders typed or picked (for the settings).
    pub fn dirs(&self) -> &BTreeMap<String, PathBuf> {
        &self.dirs
    }

    /// The output folder shown.
    pub fn dir(&self) -> Option<PathBuf> {
        (!self.dir.trim().is_empty()).then(|| PathBuf::from(self.dir.trim()))
    }

    /// Set the output folder of the design and kind shown (the same as
    /// typing it); a folder picked for a one-file export gets the
    /// design's file name in it.
    pub fn set_dir(&mut self, dir: PathBuf) {
        let dir = if self.kind == Kind::Gcvf && dir.is_dir() && !self.file_name.is_empty() {
            dir.join(&self.file_name)
        } else {
            dir
        };
        self.dir = dir.display().to_string();
        self.remember();
    }

    fn remember(&mut self) {
        if let Some(key) = &self.shown {
            match self.dir() {
                Some(d) => self.dirs.insert(key.clone(), d),
                None => self.dirs.remove(key),
            };
        }
    }

    /// Show the remembered or default folder of `place` and the kind.
    fn follow(&mut self, place: &Place) {
        self.file_name = place.file_name(self.kind);
        let key = place.dir_key(self.kind);
        if self.shown.as_ref() != Some(&key) {
            let dir = self
                .dirs
                .get(&key)
                .cloned()
                .unwrap_or_else(|| place.default_dir(self.kind));
            self.dir = dir.display().to_string();
            self.shown = Some(key);
            self.refusal = None;
        }
    }

    /// True when the PNG printer choice is a J750 (its material table).
    fn png_j750(&self) -> bool {
        self.preset
            .and_then(|i| png_stack::presets().get(i))
            .is_some_and(|p| is_j750_preset(p.name))
    }

    /// The design as the export writes it: for a PNG stack on a J750, its
    /// materials as J750 resins through the resin map (refused, naming
    /// the nearest resins, when one is not); otherwise `model`. A
    /// full-colour stack is made of the colour resins whatever the
    /// design's materials, so only the tray is checked, as the CLI does.
    fn printed_model(&mut self, model: &Arc<Model>) -> Result<Arc<Model>, String> {
        if !(self.kind == Kind::Png && self.png_j750()) {
            return Ok(model.clone());
        }
        if self.png.full_color {
            return check_j750_tray(model)
                .map(|()| model.clone())
                .map_err(|e| in_panel_words(&e.to_string()));
        }
        let key = (
            Arc::as_ptr(model) as usize,
            self.printers.map_text().to_owned(),
        );
        match &self.printed {
            Some((ptr, map, m)) if (*ptr, map) == (key.0, &key.1) => m.clone(),
            _ => {
                let m = parse_map(&key.1)
                    .and_then(|map| j750_model(model, &map))
                    .map_err(|e| in_panel_words(&e.to_string()));
                self.printed = Some((key.0, key.1, m.clone()));
                m
            }
        }
    }

    /// The parameters of the kind shown; an error (in the panel's words)
    /// for a field that does not parse.
    fn params(&self) -> Result<ExportParams, String> {
        Ok(match self.kind {
            Kind::Png => ExportParams::Png(self.png.clone()),
            Kind::Mesh => ExportParams::Mesh(self.mesh.clone()),
            Kind::Gcvf => ExportParams::Gcvf(self.printers.gcvf()?),
            Kind::Vat => ExportParams::Vat(self.printers.vat()?),
            Kind::Fea => {
                let mut p = self.fea.clone();
                p.sizing = if self.fea_expr.trim().is_empty() {
                    Sizing::Heterogeneity
                } else {
                    Sizing::Expr(self.fea_expr.trim().to_owned())
                };
                p.step = self.fea_step.map(|d| StepParams {
                    top_displacement: d,
                });
                ExportParams::Fea(p)
            }
        })
    }

    /// Show the panels; `place` says where the design's folders go,
    /// `design` is the model on screen and its script text.
    pub fn ui(
        &mut self,
        ui: &mut egui::Ui,
        place: &Place,
        design: Option<(&Arc<Model>, &str)>,
        jobs: &mut Jobs,
    ) -> Action {
        let mut action = Action::None;
        ui.horizontal_wrapped(|ui| {
            for k in [Kind::Png, Kind::Mesh, Kind::Fea, Kind::Gcvf, Kind::Vat] {
                ui.selectable_value(&mut self.kind, k, k.tab())
                    .on_hover_text(k.title());
            }
        });
        ui.add_space(4.0);
        self.follow(place);
        match self.kind {
            Kind::Png => self.png_ui(ui),
            Kind::Mesh => self.mesh_ui(ui, design.map(|(m, _)| m)),
            Kind::Fea => self.fea_ui(ui),
            Kind::Gcvf => self.printers.gcvf_ui(ui),
            Kind::Vat => self.printers.vat_ui(ui, design.map(|(m, _)| m)),
        }
        ui.horizontal(|ui| {
            let label = ui.label(self.kind.out_label()).id;
            ui.with_layout(egui::Layout::right_to_left(egui::Align::Center), |ui| {
                if ui.button("Browse…").clicked() {
                    action = Action::PickFolder(0);
                }
                let edit = ui
                    .add(
                        egui::TextEdit::singleline(&mut self.dir)
                            .desired_width(f32::INFINITY)
                            .hint_text("folder to write into"),
                    )
                    .labelled_by(label);
                if edit.changed() {
                    self.remember();
                }
            });
        });
        let Some((model, source)) = design else {
            ui.weak("No design to export yet.");
            return action;
        };
        let printed = self.printed_model(model);
        let params = printed.and_then(|m| self.params().map(|p| (m, p)));
        match &params {
            Ok((model, p)) => {
                self.estimate.update(ui.ctx(), model, p);
                self.estimate_ui(ui);
            }
            Err(e) => {
                ui.colored_label(ui.visuals().error_fg_color, e);
            }
        }
        let dest = self.dir();
        if let Some(d) = &dest {
            ui.weak(format!("Writes {}", d.display()));
        }
        if let Some(r) = &self.refusal {
            ui.colored_label(ui.visuals().error_fg_color, r);
        }
        let ok = dest.is_some() && params.is_ok() && matches!(self.estimate.answer, Some(Ok(_)));
        let start = ui.add_enabled(
            ok,
            egui::Button::new(format!("Export {}", self.kind.title())),
        );
        if start.clicked()
            && let Some(dest) = dest
            && let Ok((model, params)) = params
        {
            let hash = design_hash(&[source.as_bytes()]);
            action = self.start(params, &model, dest, hash, &place.name, jobs);
        }
        action
    }

    fn estimate_ui(&self, ui: &mut egui::Ui) {
        match &self.estimate.answer {
            None => {
                ui.horizontal(|ui| {
                    ui.spinner();
                    ui.weak("estimating…");
                });
            }
            Some(Ok(a)) => {
                ui.label(egui::RichText::new(format!("Estimate: {}", a.text)).small());
                for v in &a.verdicts {
                    ui.colored_label(ui.visuals().warn_fg_color, in_panel_words(&v.message));
                }
            }
            Some(Err(e)) => {
                ui.colored_label(ui.visuals().error_fg_color, e);
            }
        }
    }

    /// Start clicked: the plan's verdicts decide whether the export starts
    /// now, after a question, or not at all.
    fn start(
        &mut self,
        params: ExportParams,
        model: &Arc<Model>,
        dest: PathBuf,
        hash: String,
        design: &str,
        jobs: &mut Jobs,
    ) -> Action {
        let Some(Ok(a)) = &self.estimate.answer else {
            return Action::None;
        };
        let title = self.kind.title();
        let mut verdicts = a.verdicts.clone();
        verdicts.extend(params.preflight(a.disk_bytes, &dest));
        if let Some(v) = verdicts.iter().find(|v| v.severity == Severity::Refuse) {
            let line = format!("{title} export not started: {}", in_panel_words(&v.message));
            self.refusal = Some(line.clone());
            return Action::Log(line);
        }
        self.refusal = None;
        let questions: Vec<String> = verdicts
            .iter()
            .filter(|v| v.severity == Severity::Ask)
            .map(|v| question_text(v, &dest))
            .collect();
        let pending = Pending {
            params,
            model: model.clone(),
            dest,
            hash,
            design: design.to_owned(),
            title,
        };
        if questions.is_empty() {
            return launch(pending, jobs);
        }
        let replaces = verdicts
            .iter()
            .any(|v| v.severity == Severity::Ask && v.option == Opt::Out);
        self.pending = Some(pending);
        Action::Ask(Question {
            heading: if replaces {
                "Replace a finished export?".into()
            } else {
                format!("Export {title} anyway?")
            },
            text: questions.join("\n\n"),
            confirm: if replaces { "Replace" } else { "Export anyway" }.into(),
        })
    }

    /// The user agreed: start the waiting export (overriding the refusals
    /// asked about). Returns the log line.
    pub fn confirm(&mut self, jobs: &mut Jobs) -> Option<String> {
        let mut p = self.pending.take()?;
        p.params.set_force(true);
        match launch(p, jobs) {
            Action::Log(line) => Some(line),
            _ => None,
        }
    }

    /// The user declined: forget the waiting export. Returns the log line.
    pub fn cancel_pending(&mut self) -> Option<String> {
        let p = self.pending.take()?;
        Some(format!(
            "{} export not started; {} is as it was",
            p.title,
            p.dest.display()
        ))
    }
}

/// Start `p` and track it.
fn launch(p: Pending, jobs: &mut Jobs) -> Action {
    let line = format!("{} export started into {}", p.title, p.dest.display());
    let handle = p.params.run(p.model, p.dest, p.hash, Some(p.design));
    jobs.push(p.title, handle);
    Action::Log(line)
}

/// A question in the panel's words: a finished export in the folder is
/// named from its manifest.
fn question_text(v: &Verdict, dest: &Path) -> String {
    match (v.option, folder::inspect(dest)) {
        (Opt::Out, Folder::Export(e)) => format!(
            "{} holds a finished export: {}. Exporting replaces all of it.",
            dest.display(),
            e.describe()
        ),
        (Opt::Out, Folder::NotAFolder) if dest.is_file() => format!(
            "{} is already there ({:.1} MB). Exporting replaces it.",
            dest.display(),
            std::fs::metadata(dest).map_or(0.0, |m| m.len() as f64 / 1e6)
        ),
        _ => in_panel_words(&v.message),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The PNG panel's full-colour and bitmap fields make the parameters
    /// the command line makes from the same choices.
    #[test]
    fn png_fields_build_the_command_lines_plan() {
        use clap::Parser;
        use volcad_compilers::bitmaps::BitmapFormat;
        let args = [
            "volcad",
            "export",
            "png",
            "d.rhai",
            "--out",
            "o",
            "--preset",
            "j750",
            "--full-color",
            "--color-profile",
            "resins.csv",
            "--bitmaps",
            "--bitmap-format",
            "bmp",
            "--bitmap-width",
            "880",
        ];
        let cli = crate::cli::Cli::try_parse_from(args).unwrap();
        let crate::cli::Command::Export(a) = cli.command else {
            panic!("an export command");
        };
        let voxel = volcad_compilers::png_stack::preset("j750").map(|p| p.voxel);
        let want = crate::cli::export::png_params(&a, voxel).unwrap();
        let mut panels = ExportPanels::new(BTreeMap::new());
        panels.png.full_color = true;
        panels.png.color_profile = Some(PathBuf::from("resins.csv"));
        panels.png.per_material_bitmaps = true;
        panels.png.bitmap_format = BitmapFormat::Bmp;
        panels.png.bitmap_width = Some(volcad_compilers::bitmaps::MYERSON_WIDTH);
        assert_eq!(panels.params(), Ok(ExportParams::Png(want)));
    }

    #[test]
    fn default_folders_are_named_by_design_and_kind() {
        let place = Place {
            key: "/work/bar.rhai".into(),
            name: "bar.rhai".into(),
            folder: PathBuf::from("/work"),
        };
        assert_eq!(place.default_dir(Kind::Png), Path::new("/work/bar_png"));
        assert_eq!(place.default_dir(Kind::Mesh), Path::new("/work/bar_mesh"));
        assert_eq!(place.default_dir(Kind::Fea), Path::new("/work/bar_fea"));
        let mut panels = ExportPanels::new(BTreeMap::new());
        panels.follow(&place);
        assert_eq!(panels.dir(), Some(PathBuf::from("/work/bar_png")));
        panels.set_dir(PathBuf::from("/elsewhere"));
        let sphere = Place {
            key: "/work/sphere.rhai".into(),
            name: "sphere.rhai".into(),
            folder: PathBuf::from("/work"),
        };
        panels.follow(&sphere);
        assert_eq!(panels.dir(), Some(PathBuf::from("/work/sphere_png")));
        panels.follow(&place);
        assert_eq!(
            panels.dir(),
            Some(PathBuf::from("/elsewhere")),
            "remembered"
        );
        assert_eq!(panels.dirs().len(), 1);
    }
}
