//! One export plan, two front ends: what the command line (`volcad export`)
//! and the studio's export panel both do before and when they start an
//! export.
//!
//! ```text
//! ExportParams ─► assess(model) ─► Assessment { estimate line, sizes,
//!                                               design verdicts }
//!              ─► preflight(dest) ─► + disk and output-folder verdicts
//!              ─► run(model, dest) ─► job::JobHandle
//! ```
//!
//! A [`Verdict`] is one pre-flight finding: [`Severity::Refuse`] stops the
//! export, [`Severity::Ask`] stops it unless the user agrees (`--force` on
//! the command line, a question in the studio), [`Severity::Warn`] is shown
//! and the export goes on. Each names the [`Opt`] it concerns, a stable key
//! that the command line spells as its flag and the studio as its field.
//! Messages are written with the flags (`--voxel 0.35 resolves it`); the
//! studio rewrites them into its field names through [`Opt::ALL`].
//!
//! Adding an export kind: write `plan/KIND.rs` with `estimate` (the
//! [`Assessment`] line and sizes), `cell` (the size that must resolve the
//! design's thinnest feature, and its option), optionally `checks` (verdicts
//! only this kind makes), and `run` (the job's work); add a variant to
//! [`ExportParams`] and its arm in each `match` below (the compiler lists
//! them). Both front ends then show its estimate and every check, and only
//! their parameter fields are new.

mod fea;
pub mod folder;
mod gcvf;
mod mesh;
mod png;
pub mod text;
mod vat;

pub use vat::{VatChoices, VatText};

use std::path::{Path, PathBuf};
use std::sync::Arc;

use volcad_core::Model;

use crate::fea::FeaParams;
use crate::gcvf::GcvfParams;
use crate::job::{self, ExportError, JobHandle};
use crate::mesh::MeshParams;
use crate::png_stack::PngParams;
use crate::resources::{check_disk_for, human_bytes};
use crate::thin::thin_feature_notes;
use crate::vat::VatParams;

/// The options a verdict can concern: a stable key for each, spelled as a
/// flag by the command line ([`Opt::flag`]) and as a field by the studio.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Opt {
    /// Voxel or brick size.
    Voxel,
    /// Smallest tetrahedron cell.
    MinCell,
    /// Largest tetrahedron cell.
    MaxCell,
    /// Cell size as a math string of h.
    Sizing,
    /// The output folder.
    Out,
    /// Worker threads.
    Threads,
    /// Layer range of a slice stack.
    Layers,
    /// Fraction ranges of a mesh export.
    Segments,
    /// Material a mesh export splits by.
    By,
    /// 3MF infill expression.
    Infill,
    /// Mesh file formats.
    Formats,
    /// Static step of an FEA deck.
    Step,
    /// Elastic sets per property of an FEA deck.
    PropertyBins,
    /// The share of a slice stack's layers one machine writes.
    Shard,
    /// Override the refusals that protect the user.
    Force,
    /// One colour resin per voxel from the design's colours.
    FullColor,
    /// Measured resin colours of a full-colour stack.
    ColorProfile,
    /// File format of per-material bitmaps.
    BitmapFormat,
    /// Fixed width of BMP bitmaps.
    BitmapWidth,
    /// The printer preset (voxel size, screen, material table).
    Preset,
    /// Design material = printer resin pairs.
    Map,
    /// A vat stack's gray source.
    Intensity,
    /// The attribute values a vat stack maps onto 0..=255.
    Range,
    /// How many vats a vat stack feeds.
    Vats,
    /// Which materials each vat holds.
    VatMaterials,
    /// Where the part sits on a vat printer's screen.
    Offset,
    /// The design itself.
    Design,
}

impl Opt {
    /// Every key. No flag starts another, so a message can be rewritten
    /// flag by flag.
    pub const ALL: [Opt; 27] = [
        Opt::MinCell,
        Opt::MaxCell,
        Opt::Sizing,
        Opt::Voxel,
        Opt::Out,
        Opt::Threads,
        Opt::Layers,
        Opt::Segments,
        Opt::By,
        Opt::Infill,
        Opt::Formats,
        Opt::Step,
        Opt::PropertyBins,
        Opt::Shard,
        Opt::Force,
        Opt::FullColor,
        Opt::ColorProfile,
        Opt::BitmapFormat,
        Opt::BitmapWidth,
        Opt::Preset,
        Opt::Map,
        Opt::Intensity,
        Opt::Range,
        Opt::Vats,
        Opt::VatMaterials,
        Opt::Offset,
        Opt::Design,
    ];

    /// The command line's flag (`Design` has none: it is the design file).
    pub fn flag(self) -> &'static str {
        match self {
            Opt::Voxel => "--voxel",
            Opt::MinCell => "--min-cell",
            Opt::MaxCell => "--max-cell",
            Opt::Sizing => "--sizing",
            Opt::Out => "--out",
            Opt::Threads => "--threads",
            Opt::Layers => "--layers",
            Opt::Segments => "--segments",
            Opt::By => "--by",
            Opt::Infill => "--infill",
            Opt::Formats => "--formats",
            Opt::Step => "--step",
            Opt::PropertyBins => "--property-bins",
            Opt::Shard => "--shard",
            Opt::Force => "--force",
            Opt::FullColor => "--full-color",
            Opt::ColorProfile => "--color-profile",
            Opt::BitmapFormat => "--bitmap-format",
            Opt::BitmapWidth => "--bitmap-width",
            Opt::Preset => "--preset",
            Opt::Map => "--map",
            Opt::Intensity => "--intensity",
            Opt::Range => "--range",
            Opt::Vats => "--vats",
            Opt::VatMaterials => "--vat-materials",
            Opt::Offset => "--offset",
            Opt::Design => "design",
        }
    }

    /// The key whose flag is `flag` (an [`ExportError::BadParameter`]'s
    /// parameter); unknown flags concern the design.
    pub fn from_flag(flag: &str) -> Opt {
        Opt::ALL
            .into_iter()
            .find(|o| o.flag() == flag)
            .unwrap_or(Opt::Design)
    }
}

/// How a verdict bears on the export.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Severity {
    /// The export does not start.
    Refuse,
    /// The export starts only when the user agrees (`--force`, or the
    /// studio's question): it would replace work or outgrow the machine.
    Ask,
    /// Said before the export starts; it goes on.
    Warn,
}

/// One pre-flight finding.
#[derive(Clone, Debug, PartialEq)]
pub struct Verdict {
    /// What it means for the export.
    pub severity: Severity,
    /// The option that fixes it.
    pub option: Opt,
    /// What is wrong and what to write instead, with command-line flags.
    pub message: String,
}

impl Verdict {
    /// A refusal from an export error (its parameter names the option).
    pub fn refuse(e: &ExportError) -> Verdict {
        Verdict::from_error(Severity::Refuse, e)
    }

    fn from_error(severity: Severity, e: &ExportError) -> Verdict {
        let option = match e {
            ExportError::BadParameter { param, .. } => Opt::from_flag(param),
            _ => Opt::Design,
        };
        Verdict {
            severity,
            option,
            message: e.to_string(),
        }
    }
}

/// The parameters of one export, of any kind.
#[derive(Clone, Debug, PartialEq)]
pub enum ExportParams {
    /// Inkjet slice stack.
    Png(PngParams),
    /// Segmented meshes and 3MF.
    Mesh(MeshParams),
    /// FEA deck.
    Fea(FeaParams),
    /// GrabCAD Voxel Print package (one file).
    Gcvf(GcvfParams),
    /// Vat photopolymer slice stack.
    Vat(VatParams),
}

/// What an export will produce, and what the design alone says about it.
#[derive(Clone, Debug, PartialEq)]
pub struct Assessment {
    /// One line for the user: grid, counts, sizes.
    pub text: String,
    /// Output size to check the disk with (`None`: checked by the job).
    pub disk_bytes: Option<u64>,
    /// Warnings and questions that follow from the design and the
    /// parameters (thin features, solver memory).
    pub verdicts: Vec<Verdict>,
}

/// What a voxel-grid export's estimate line shows of its estimate: the
/// grid's size, its voxels, and the bytes on disk and in memory.
trait GridEstimate {
    /// `(dims, voxels, disk bytes, memory bytes)`.
    fn sizes(&self) -> ([usize; 3], u64, u64, u64);
}

impl GridEstimate for crate::png_stack::Estimate {
    fn sizes(&self) -> ([usize; 3], u64, u64, u64) {
        (
            self.grid.dims,
            self.voxels,
            self.disk_bytes,
            self.memory_bytes,
        )
    }
}

impl GridEstimate for crate::mesh::MeshEstimate {
    fn sizes(&self) -> ([usize; 3], u64, u64, u64) {
        (
            self.grid.dims,
            self.voxels,
            self.disk_bytes,
            self.memory_bytes,
        )
    }
}

impl Assessment {
    /// A voxel-grid export's estimate, checked against its disk size:
    /// "NX × NY × NZ voxels (N), {counts}{disk} on disk, {memory} memory"
    /// (`counts` ends with its separator, and "about " where it applies).
    fn voxel_grid(est: &impl GridEstimate, counts: &str) -> Self {
        let ([nx, ny, nz], voxels, disk, memory) = est.sizes();
        Assessment {
            text: format!(
                "{nx} × {ny} × {nz} voxels ({:.3e}), {counts}{} on disk, {} memory",
                voxels as f64,
                human_bytes(disk),
                human_bytes(memory)
            ),
            disk_bytes: Some(disk),
            verdicts: Vec::new(),
        }
    }
}

impl ExportParams {
    /// The kind as the manifest and the command line name it.
    pub fn kind(&self) -> &'static str {
        match self {
            ExportParams::Png(_) => "png",
            ExportParams::Mesh(_) => "mesh",
            ExportParams::Fea(_) => "fea",
            ExportParams::Gcvf(_) => "gcvf",
            ExportParams::Vat(_) => "vat",
        }
    }

    /// True when [`assess`](Self::assess) costs about as much as the
    /// export (adaptive tetrahedra grade a lattice to estimate): the
    /// command line then checks the design alone ([`Self::design_verdicts`]).
    pub fn estimate_is_slow(&self) -> bool {
        matches!(self, ExportParams::Fea(p) if p.element == crate::fea::Element::C3D4)
    }

    /// Estimate the export and check the design against its parameters.
    pub fn assess(&self, model: &Model) -> Result<Assessment, ExportError> {
        let mut a = match self {
            ExportParams::Png(p) => png::estimate(model, p)?,
            ExportParams::Mesh(p) => mesh::estimate(model, p)?,
            ExportParams::Fea(p) => fea::estimate(model, p)?,
            ExportParams::Gcvf(p) => gcvf::estimate(model, p)?,
            ExportParams::Vat(p) => vat::estimate(model, p)?,
        };
        let mut verdicts = self.design_verdicts(model);
        verdicts.append(&mut a.verdicts);
        a.verdicts = verdicts;
        Ok(a)
    }

    /// The checks that need no estimate: features thinner than the cells
    /// resolve.
    pub fn design_verdicts(&self, model: &Model) -> Vec<Verdict> {
        // A voxel's largest side decides what it resolves.
        let (size, option) = match self {
            ExportParams::Png(p) => (p.voxel.max_element(), Opt::Voxel),
            ExportParams::Mesh(p) => (p.voxel.max_element(), Opt::Voxel),
            ExportParams::Fea(p) => fea::cell(p),
            ExportParams::Gcvf(p) => (p.voxel.max_element(), Opt::Voxel),
            ExportParams::Vat(p) => vat::cell(p),
        };
        thin_feature_notes(model, size, option.flag())
            .into_iter()
            .filter(|n| n.starts_with("warning"))
            .map(|message| Verdict {
                severity: Severity::Warn,
                option,
                message,
            })
            .collect()
    }

    /// Let the export through the refusals the user agreed to override
    /// (an FEA deck's solver memory; the job replaces a finished export
    /// anyway once asked to run).
    pub fn set_force(&mut self, force: bool) {
        if let ExportParams::Fea(p) = self {
            p.force = force;
        }
    }

    /// Start the export into `dest`; `design_hash` and `design` (the
    /// script's name) go into its manifest.
    pub fn run(
        self,
        model: Arc<Model>,
        dest: PathBuf,
        design_hash: String,
        design: Option<String>,
    ) -> JobHandle {
        match self {
            ExportParams::Png(p) => job::spawn_design(dest, design_hash, design, move |ctx| {
                png::run(&model, &p, ctx)
            }),
            ExportParams::Mesh(p) => job::spawn_design(dest, design_hash, design, move |ctx| {
                mesh::run(&model, &p, ctx)
            }),
            ExportParams::Fea(p) => job::spawn_design(dest, design_hash, design, move |ctx| {
                fea::run(&model, &p, ctx)
            }),
            ExportParams::Gcvf(mut p) => {
                // The job writes the archive under its own file name.
                if let Some(n) = dest.file_name() {
                    p.file_name = n.to_string_lossy().into_owned();
                }
                job::spawn_file(dest, design_hash, move |ctx| gcvf::run(&model, &p, ctx))
            }
            ExportParams::Vat(p) => job::spawn_design(dest, design_hash, design, move |ctx| {
                vat::run(&model, &p, ctx)
            }),
        }
    }

    /// True when the export is one file (a `.gcvf`) rather than a folder.
    pub fn is_file(&self) -> bool {
        matches!(self, ExportParams::Gcvf(_))
    }

    /// [`preflight`] for this kind: a one-file export checks its file
    /// rather than a folder.
    pub fn preflight(&self, disk_bytes: Option<u64>, dest: &Path) -> Vec<Verdict> {
        if !self.is_file() {
            return preflight(disk_bytes, dest);
        }
        let mut out = Vec::new();
        if let Some(Err(e)) = disk_bytes.map(|b| check_disk_for(b, dest, "a larger voxel size")) {
            out.push(Verdict::refuse(&e));
        }
        out.extend(gcvf::file_verdict(dest));
        out
    }
}

/// The checks made just before an export starts into `dest`: room on its
/// disk for `disk_bytes`, and what `dest` holds now (see [`folder`]).
pub fn preflight(disk_bytes: Option<u64>, dest: &Path) -> Vec<Verdict> {
    let mut out = Vec::new();
    // The job's own up-front check goes by coarser rules; the estimate
    // sampled layers at the export's voxel size.
    if let Some(Err(e)) = disk_bytes.map(|b| check_disk_for(b, dest, "a larger voxel size")) {
        out.push(Verdict::refuse(&e));
    }
    out.extend(folder::verdict(dest));
    out
}

/// The first verdict that stops the export: a refusal, or a question when
/// the user has not agreed (`force`).
pub fn blocking(verdicts: &[Verdict], force: bool) -> Option<&Verdict> {
    verdicts
        .iter()
        .find(|v| v.severity == Severity::Refuse)
        .or_else(|| {
            verdicts
                .iter()
                .find(|v| v.severity == Severity::Ask && !force)
        })
}
