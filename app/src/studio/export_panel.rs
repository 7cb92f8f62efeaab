//! Export panels: PNG slice stack (inkjet), segmented meshes (STL/OBJ/3MF)
//! and FEA meshes (.inp). Each has its parameters with defaults (printer
//! presets for slice stacks), an output folder (typed, or picked with a
//! dialog), an estimate of size and voxel count computed on a worker, and a
//! Start button that spawns a `volcad_compilers::job`.
//!
//! Destination: the folder as typed when it does not exist yet, is empty or
//! holds an earlier export (`manifest.json`); otherwise a fresh subfolder
//! `<design>-<kind>` inside it, so an export never mixes with other files.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::mpsc::{Receiver, Sender, channel};

use glam::DVec3;
use volcad_compilers::fea::solver::solver_bytes;
use volcad_compilers::fea::{Element, FeaParams, Sizing, StepParams, property_bins};
use volcad_compilers::job::{self, design_hash};
use volcad_compilers::mesh::{MeshFormats, MeshParams, SegmentBy};
use volcad_compilers::png_stack::{self, Dither, PngParams};
use volcad_compilers::resources::{check_disk_for, human_bytes};
use volcad_compilers::thin::thin_feature_notes;
use volcad_core::Model;

use super::jobs::{Jobs, fresh_destination, in_panel_words};

/// What the panel asks the app to do.
pub enum Action {
    /// Nothing.
    None,
    /// Show a folder dialog for the output folder.
    PickFolder(usize),
    /// Log a line.
    Log(String),
}

/// Which export.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// Inkjet slice stack.
    Png,
    /// Segmented meshes and 3MF.
    Mesh,
    /// FEA mesh.
    Fea,
}

impl Kind {
    fn title(self) -> &'static str {
        match self {
            Kind::Png => "PNG stack",
            Kind::Mesh => "Meshes / 3MF",
            Kind::Fea => "FEA (.inp)",
        }
    }

    fn suffix(self) -> &'static str {
        match self {
            Kind::Png => "png",
            Kind::Mesh => "mesh",
            Kind::Fea => "fea",
        }
    }
}

/// One set of parameters, ready for a job.
#[derive(Clone, Debug, PartialEq)]
enum Params {
    Png(PngParams),
    Mesh(MeshParams),
    Fea(FeaParams),
}

/// Estimates run on one worker thread, newest request first: a mesh
/// estimate samples a few layers at the export's voxel size (tens of
/// milliseconds, more on large designs), and dragging a value asks for one
/// per frame. Requests that a newer one overtook while the worker was busy
/// are dropped unanswered, so at most one estimate runs at a time.
#[derive(Default)]
struct EstimateWorker {
    key: Option<(usize, Params)>,
    /// Number of the newest request; only its answer is shown.
    seq: u64,
    text: Option<Result<Estimated, String>>,
    link: Option<WorkerLink>,
}

/// One request to the worker.
struct EstimateRequest {
    seq: u64,
    model: Arc<Model>,
    params: Params,
    ctx: egui::Context,
}

/// The worker's two channels (the worker ends when `jobs` is dropped).
struct WorkerLink {
    jobs: Sender<EstimateRequest>,
    answers: Receiver<(u64, Result<Estimated, String>)>,
    /// Estimates computed (read by tests).
    #[cfg_attr(not(test), allow(dead_code))]
    computed: Arc<AtomicUsize>,
}

impl WorkerLink {
    fn start() -> Option<WorkerLink> {
        let (jobs, inbox) = channel::<EstimateRequest>();
        let (outbox, answers) = channel();
        let computed = Arc::new(AtomicUsize::new(0));
        let count = computed.clone();
        std::thread::Builder::new()
            .name("volcad-estimate".into())
            .spawn(move || {
                while let Ok(mut req) = inbox.recv() {
                    // Skip to the newest request waiting.
                    while let Ok(newer) = inbox.try_recv() {
                        req = newer;
                    }
                    let answer = estimate(&req.model, &req.params);
                    count.fetch_add(1, Ordering::Relaxed);
                    if outbox.send((req.seq, answer)).is_err() {
                        break;
                    }
                    req.ctx.request_repaint();
                }
            })
            .ok()?;
        Some(WorkerLink {
            jobs,
            answers,
            computed,
        })
    }
}

impl EstimateWorker {
    fn update(&mut self, ctx: &egui::Context, model: &Arc<Model>, params: &Params) {
        let key = (Arc::as_ptr(model) as usize, params.clone());
        if self.key.as_ref() != Some(&key) {
            self.key = Some(key);
            self.text = None;
            self.seq += 1;
            if self.link.is_none() {
                self.link = WorkerLink::start();
            }
            let sent = self.link.as_ref().is_some_and(|l| {
                l.jobs
                    .send(EstimateRequest {
                        seq: self.seq,
                        model: model.clone(),
                        params: params.clone(),
                        ctx: ctx.clone(),
                    })
                    .is_ok()
            });
            if !sent {
                self.link = None;
                self.text = Some(Err("the estimate could not be started".into()));
            }
        }
        if let Some(link) = &self.link {
            for (seq, answer) in link.answers.try_iter() {
                if seq == self.seq {
                    self.text = Some(answer);
                }
            }
        }
    }
}

/// An estimate as the panel shows it, and the output size to check the
/// disk with before a job starts (slice stacks and meshes; an FEA export
/// checks its deck's size once its mesh is built).
#[derive(Clone, Debug, PartialEq)]
struct Estimated {
    text: String,
    disk_bytes: Option<u64>,
    /// `warning: …` lines (features thinner than the cells resolve).
    warnings: Vec<String>,
}

fn estimate(model: &Model, p: &Params) -> Result<Estimated, String> {
    let e = |e: volcad_compilers::ExportError| in_panel_words(&e.to_string());
    let (size, option) = match p {
        Params::Png(p) => (p.voxel.max_element(), "--voxel"),
        Params::Mesh(p) => (p.voxel.max_element(), "--voxel"),
        Params::Fea(p) => p.cell(),
    };
    let warnings: Vec<String> = thin_feature_notes(model, size, option)
        .into_iter()
        .filter(|n| n.starts_with("warning"))
        .map(|n| in_panel_words(&n))
        .collect();
    Ok(match p {
        Params::Png(p) => {
            let est = png_stack::estimate(model, p).map_err(e)?;
            let [nx, ny, nz] = est.grid.dims;
            Estimated {
                text: format!(
                    "{nx} × {ny} × {nz} voxels ({:.3e}), {} files, about {} on disk, {} memory",
                    est.voxels as f64,
                    est.files,
                    human_bytes(est.disk_bytes),
                    human_bytes(est.memory_bytes)
                ),
                disk_bytes: Some(est.disk_bytes),
                warnings,
            }
        }
        Params::Mesh(p) => {
            let est = volcad_compilers::mesh::estimate_mesh(model, p).map_err(e)?;
            let [nx, ny, nz] = est.grid.dims;
            Estimated {
                text: format!(
                    "{nx} × {ny} × {nz} voxels ({:.3e}), {} segments, about {} triangles, {} on disk",
                    est.voxels as f64,
                    est.segments,
                    est.triangles,
                    human_bytes(est.disk_bytes)
                ),
                disk_bytes: Some(est.disk_bytes),
                warnings,
            }
        }
        Params::Fea(p) => {
            let est = volcad_compilers::fea::estimate_fea(model, p).map_err(e)?;
            Estimated {
                text: format!(
                    "about {} elements, {} nodes, {} .inp, {} for CalculiX's solver",
                    est.elements,
                    est.nodes,
                    human_bytes(est.file_bytes),
                    human_bytes(solver_bytes(est.nodes))
                ),
                disk_bytes: None,
                warnings,
            }
        }
    })
}

/// The export panels' state.
pub struct ExportPanels {
    dir: String,
    kind: Kind,
    png: PngParams,
    /// Index into `png_stack::presets()`, or `None` for a custom voxel.
    preset: Option<usize>,
    mesh: MeshParams,
    fea: FeaParams,
    fea_expr: String,
    fea_step: Option<f64>,
    estimate: EstimateWorker,
}

impl ExportPanels {
    /// Panels exporting into `dir` by default.
    pub fn new(dir: Option<PathBuf>) -> Self {
        Self {
            dir: dir.map(|d| d.display().to_string()).unwrap_or_default(),
            kind: Kind::Png,
            png: PngParams::default(),
            preset: Some(0),
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
            estimate: EstimateWorker::default(),
        }
    }

    /// The output folder typed or picked.
    pub fn dir(&self) -> Option<PathBuf> {
        (!self.dir.trim().is_empty()).then(|| PathBuf::from(self.dir.trim()))
    }

    /// Set the output folder.
    pub fn set_dir(&mut self, dir: PathBuf) {
        self.dir = dir.display().to_string();
    }

    fn params(&self) -> Params {
        match self.kind {
            Kind::Png => Params::Png(self.png.clone()),
            Kind::Mesh => Params::Mesh(self.mesh.clone()),
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
                Params::Fea(p)
            }
        }
    }

    /// Show the panels; `design` is the model on screen and its script text.
    pub fn ui(
        &mut self,
        ui: &mut egui::Ui,
        design: Option<(&Arc<Model>, &str)>,
        jobs: &mut Jobs,
    ) -> Action {
        let mut action = Action::None;
        ui.horizontal(|ui| {
            for k in [Kind::Png, Kind::Mesh, Kind::Fea] {
                ui.selectable_value(&mut self.kind, k, k.title());
            }
        });
        ui.add_space(4.0);
        match self.kind {
            Kind::Png => self.png_ui(ui),
            Kind::Mesh => self.mesh_ui(ui, design.map(|(m, _)| m)),
            Kind::Fea => self.fea_ui(ui),
        }
        ui.horizontal(|ui| {
            let label = ui.label("Output folder").id;
            ui.with_layout(egui::Layout::right_to_left(egui::Align::Center), |ui| {
                if ui.button("Browse…").clicked() {
                    action = Action::PickFolder(0);
                }
                ui.add(
                    egui::TextEdit::singleline(&mut self.dir)
                        .desired_width(f32::INFINITY)
                        .hint_text("folder to write into"),
                )
                .labelled_by(label);
            });
        });
        let Some((model, source)) = design else {
            ui.weak("No design to export yet.");
            return action;
        };
        self.estimate.update(ui.ctx(), model, &self.params());
        match &self.estimate.text {
            None => {
                ui.horizontal(|ui| {
                    ui.spinner();
                    ui.weak("estimating…");
                });
            }
            Some(Ok(t)) => {
                ui.label(egui::RichText::new(format!("Estimate: {}", t.text)).small());
                for w in &t.warnings {
                    ui.colored_label(ui.visuals().warn_fg_color, w);
                }
            }
            Some(Err(e)) => {
                ui.colored_label(ui.visuals().error_fg_color, e);
            }
        }
        let stem = design_stem(source);
        let dest = self.dir().map(|d| destination(&d, &stem, self.kind));
        if let Some(d) = &dest {
            ui.weak(format!("Writes {}", d.display()));
        }
        let ok = dest.is_some() && matches!(self.estimate.text, Some(Ok(_)));
        let start = ui.add_enabled(
            ok,
            egui::Button::new(format!("Export {}", self.kind.title())),
        );
        let disk_bytes = match &self.estimate.text {
            Some(Ok(t)) => t.disk_bytes,
            _ => None,
        };
        // The job's own up-front check goes by coarser rules (see
        // `check_disk_for`); this estimate sampled layers at the voxel size.
        let room = |dest: &Path| {
            disk_bytes.map_or(Ok(()), |b| {
                check_disk_for(b, dest, "a larger voxel size")
                    .map_err(|e| in_panel_words(&e.to_string()))
            })
        };
        if start.clicked()
            && let Some(dest) = dest
        {
            if let Err(e) = room(&dest) {
                return Action::Log(format!("{} export not started: {e}", self.kind.title()));
            }
            let hash = design_hash(&[source.as_bytes()]);
            let model = model.clone();
            let handle = match self.params() {
                Params::Png(p) => job::spawn(dest.clone(), hash, move |ctx| {
                    png_stack::export_png_stack(&model, &p, ctx)
                }),
                Params::Mesh(p) => job::spawn(dest.clone(), hash, move |ctx| {
                    volcad_compilers::mesh::export_meshes(&model, &p, ctx)
                }),
                Params::Fea(p) => job::spawn(dest.clone(), hash, move |ctx| {
                    volcad_compilers::fea::export_fea(&model, &p, ctx)
                }),
            };
            jobs.push(self.kind.title(), handle);
            action = Action::Log(format!(
                "{} export started into {}",
                self.kind.title(),
                dest.display()
            ));
        }
        action
    }

    fn png_ui(&mut self, ui: &mut egui::Ui) {
        let presets = png_stack::presets();
        egui::Grid::new("png-params").num_columns(2).show(ui, |ui| {
            let label = ui.label("Printer").id;
            let current = self.preset.map_or("Custom voxel", |i| presets[i].name);
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
                        .selectable_label(self.preset.is_none(), "Custom voxel")
                        .clicked()
                    {
                        self.preset = None;
                    }
                })
                .response
                .labelled_by(label);
            ui.end_row();
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
            ui.label("");
            ui.checkbox(
                &mut self.png.per_material_bitmaps,
                "1-bit bitmaps per material",
            );
            ui.end_row();
        });
    }

    fn mesh_ui(&mut self, ui: &mut egui::Ui, model: Option<&Arc<Model>>) {
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
                let label = ui.label("3MF infill % of f").id;
                let mut expr = self.mesh.infill_expr.clone().unwrap_or_default();
                let hint = volcad_compilers::mesh::DEFAULT_INFILL;
                if ui
                    .add(
                        egui::TextEdit::singleline(&mut expr)
                            .hint_text(hint)
                            .desired_width(140.0),
                    )
                    .labelled_by(label)
                    .changed()
                {
                    self.mesh.infill_expr =
                        (!expr.trim().is_empty()).then(|| expr.trim().to_owned());
                }
                ui.end_row();
            });
    }

    fn fea_ui(&mut self, ui: &mut egui::Ui) {
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
                    ui.add(
                        egui::DragValue::new(&mut self.fea.voxel)
                            .speed(0.01)
                            .range(0.01..=100.0),
                    )
                    .labelled_by(label);
                    ui.end_row();
                }
                Element::C3D4 => {
                    let label = ui.label("Cell min / max (mm)").id;
                    ui.horizontal(|ui| {
                        ui.add(
                            egui::DragValue::new(&mut self.fea.min_cell)
                                .speed(0.01)
                                .range(0.01..=100.0),
                        )
                        .labelled_by(label);
                        ui.add(
                            egui::DragValue::new(&mut self.fea.max_cell)
                                .speed(0.01)
                                .range(0.01..=100.0),
                        )
                        .labelled_by(label);
                    });
                    ui.end_row();
                    let label = ui.label("Size of h (mm)").id;
                    ui.add(
                        egui::TextEdit::singleline(&mut self.fea_expr)
                            .hint_text("linear in h")
                            .desired_width(140.0),
                    )
                    .labelled_by(label);
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

/// The design's name for output folders: the first word-ish of its first
/// comment, else "design".
fn design_stem(source: &str) -> String {
    let Some(first) = source
        .lines()
        .next()
        .and_then(|l| l.trim().strip_prefix("//"))
    else {
        return "design".into();
    };
    let first = first.trim_start_matches('/').trim();
    let stem: String = first
        .chars()
        .take_while(|c| *c != ':' && *c != '.')
        .map(|c| {
            if c.is_ascii_alphanumeric() {
                c.to_ascii_lowercase()
            } else {
                '_'
            }
        })
        .collect();
    let stem = stem.trim_matches('_').to_owned();
    if stem.is_empty() || stem.len() > 40 {
        "design".into()
    } else {
        stem
    }
}

/// Where an export into `dir` goes (see the module docs).
pub fn destination(dir: &Path, stem: &str, kind: Kind) -> PathBuf {
    let usable = !dir.exists()
        || dir.join("manifest.json").exists()
        || std::fs::read_dir(dir)
            .map(|mut d| d.next().is_none())
            .unwrap_or(false);
    if usable {
        dir.to_owned()
    } else {
        fresh_destination(dir, &format!("{stem}-{}", kind.suffix()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_burst_of_requests_gets_the_newest_answer_from_few_estimates() {
        let d = volcad_core::script::run_script(
            "let m = default_materials(); Sphere(Vec3(0,0,0), 10, m.id(\"red\"))",
            "t.rhai",
            &Default::default(),
        )
        .unwrap();
        let model = Arc::new(Model::prepare(&d.root, d.materials).unwrap());
        let ctx = egui::Context::default();
        let mut w = EstimateWorker::default();
        let mesh = |voxel: f64| {
            Params::Mesh(MeshParams {
                voxel: DVec3::splat(voxel),
                ..MeshParams::default()
            })
        };
        // Twenty values in a row, as a drag gives them, the last 0.2 mm.
        for i in 0..20 {
            w.update(&ctx, &model, &mesh(0.2 + 0.01 * f64::from(19 - i)));
        }
        let deadline = std::time::Instant::now() + std::time::Duration::from_secs(60);
        while w.text.is_none() && std::time::Instant::now() < deadline {
            std::thread::sleep(std::time::Duration::from_millis(5));
            w.update(&ctx, &model, &mesh(0.2));
        }
        let text = w
            .text
            .clone()
            .expect("an answer")
            .expect("an estimate")
            .text;
        // 20 mm at 0.2 mm, padded by a voxel on every side.
        assert!(text.starts_with("102 × 102 × 102 voxels"), "{text}");
        let computed = w.link.as_ref().unwrap().computed.load(Ordering::Relaxed);
        assert!(
            (1..=3).contains(&computed),
            "{computed} estimates for 20 requests"
        );
    }

    #[test]
    fn destinations_never_mix_with_other_files() {
        let scratch = tempfile::tempdir().unwrap();
        let base = scratch.path().join("dest");
        assert_eq!(
            destination(&base, "bar", Kind::Png),
            base,
            "a new folder is used as is"
        );
        std::fs::create_dir_all(&base).unwrap();
        assert_eq!(
            destination(&base, "bar", Kind::Png),
            base,
            "an empty folder too"
        );
        std::fs::write(base.join("notes.txt"), "x").unwrap();
        assert_eq!(destination(&base, "bar", Kind::Png), base.join("bar-png"));
        std::fs::create_dir_all(base.join("bar-png")).unwrap();
        assert_eq!(destination(&base, "bar", Kind::Mesh), base.join("bar-mesh"));
        assert_eq!(destination(&base, "bar", Kind::Png), base.join("bar-png-2"));
    }

    #[test]
    fn stems_come_from_the_first_comment() {
        assert_eq!(
            design_stem("// Graded bar: red to blue\nlet m"),
            "graded_bar"
        );
        assert_eq!(design_stem("let m = 1;"), "design");
        assert_eq!(design_stem(""), "design");
    }
}
