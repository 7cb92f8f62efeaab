//! `volcad export png|mesh|fea|gcvf|vat`: run an export job
//! with a progress bar; Ctrl-C cancels cleanly (nothing is left behind).

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::RecvTimeoutError;
use std::time::Duration;

use anyhow::{Context, bail};
use glam::DVec3;
use volcad_compilers::bitmaps::BitmapFormat;
use volcad_compilers::fea::{Element, EndSets, FeaParams, Sizing, StepParams};
use volcad_compilers::job::{self, design_hash};
use volcad_compilers::mesh::{MeshFormats, MeshParams, SegmentBy};
use volcad_compilers::plan::{ExportParams, Severity, Verdict, blocking};
use volcad_compilers::png_stack::{self, Dither, PngParams};
use volcad_compilers::printer_table::{check_j750_tray, is_j750_preset};
use volcad_compilers::shard;

use super::DesignArgs;
use super::design::load_design;

/// What to export.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// Inkjet slice stack: one PNG per layer.
    Png,
    /// Segmented meshes: STL + OBJ per segment and one 3MF.
    Mesh,
    /// FEA mesh for Abaqus/CalculiX (.inp).
    Fea,
    /// GrabCAD Voxel Print package for PolyJet (J750) printers (.gcvf).
    Gcvf,
    /// Grayscale slice stack for vat photopolymer (MSLA) printers.
    Vat,
}

/// `volcad export` options (spelled as scripts rely on them).
#[derive(clap::Args, Debug)]
pub struct ExportArgs {
    /// png, mesh, fea, gcvf or vat.
    #[arg(value_enum)]
    pub kind: Kind,
    /// The design.
    #[command(flatten)]
    pub design: DesignArgs,
    /// Output folder (written to a staging folder and renamed when complete).
    #[arg(long)]
    pub out: PathBuf,
    /// Voxel size in mm (each within 1e-6..=1e6): one value, or X,Y,Z.
    ///
    /// The grid has ceil(extent / voxel) voxels per axis, as pyvcad's,
    /// centred on the part: a slice stack reaches up to one voxel past the
    /// part per axis (its summary and manifest give both sizes).
    #[arg(long, allow_hyphen_values = true)]
    pub voxel: Option<String>,
    /// Printer preset: the voxel size for png (j750, j750-hq, cube-0.1), the screen for vat (saturn-4-ultra, photon-mono-m7-pro).
    #[arg(long)]
    pub preset: Option<String>,
    /// Worker threads (default: all cores).
    #[arg(long, allow_negative_numbers = true)]
    pub threads: Option<usize>,
    /// Seed of the material draw (same seed, same bytes).
    #[arg(long, default_value_t = 0, allow_negative_numbers = true)]
    pub seed: u64,
    /// png, vat: only layers A..B (A to B-1, B excluded) or A..=B (A to B
    /// included); file names keep the global layer indices.
    #[arg(long)]
    pub layers: Option<String>,
    /// png, vat: only the K-th of N equal layer ranges (K counts from 1: 1/4 is
    /// the lowest quarter, 4/4 the top); file names keep the global layer
    /// indices, and `volcad merge` joins the N folders into the single export.
    #[arg(long, value_name = "K/N")]
    pub shard: Option<String>,
    /// png, gcvf, vat: random (default) or diffusion.
    #[arg(long)]
    pub dither: Option<String>,
    /// png: also write 1-bit stacks, one folder per material.
    #[arg(long)]
    pub bitmaps: bool,
    /// png with --bitmaps: png (default) or bmp (pyvcad's MyersonCompiler layout: material black on white).
    #[arg(long)]
    pub bitmap_format: Option<String>,
    /// png with --bitmap-format bmp: fixed image width in pixels, the layer at the left (Myerson: 880).
    #[arg(long)]
    pub bitmap_width: Option<usize>,
    /// png: each voxel one J750 colour resin (cyan, magenta, yellow, black, white, clear) reproducing the design's `color` attribute (else its materials' colours) by error diffusion in OKLab.
    #[arg(long)]
    pub full_color: bool,
    /// png with --full-color: measured resin colours, a CSV `name,L,a,b` (CIELAB D50) or `name,r,g,b` (sRGB 0-255).
    #[arg(long)]
    pub color_profile: Option<PathBuf>,
    /// gcvf, and png with --preset j750: design material = J750 resin, e.g. red=VeroMgnt,blue=VeroCyan.
    #[arg(long)]
    pub map: Option<String>,
    /// png, gcvf: remove the material named liquid (J750: M.Cleanser) within this many mm of the surface.
    #[arg(long, allow_negative_numbers = true)]
    pub liquid_keep_out: Option<f64>,
    /// mesh: number of fraction ranges with `--by MATERIAL` (default 4).
    #[arg(long, allow_negative_numbers = true)]
    pub segments: Option<usize>,
    /// mesh: material whose fraction splits the part, or `dominant`.
    #[arg(long)]
    pub by: Option<String>,
    /// mesh: 3MF infill percent as a math string of f (the segment's mid fraction).
    #[arg(long)]
    pub infill: Option<String>,
    /// mesh: files to write, a comma list of stl, obj, 3mf (default: all three).
    #[arg(long)]
    pub formats: Option<String>,
    /// fea: c3d8r (bricks, the default) or c3d4 (adaptive tets).
    #[arg(long)]
    pub element: Option<String>,
    /// fea with c3d4: smallest tet cell (mm).
    #[arg(long, allow_negative_numbers = true)]
    pub min_cell: Option<f64>,
    /// fea with c3d4: largest tet cell (mm).
    #[arg(long, allow_negative_numbers = true)]
    pub max_cell: Option<f64>,
    /// fea with c3d4: cell size as a math string of h (heterogeneity) instead of the linear rule.
    #[arg(long, allow_hyphen_values = true)]
    pub sizing: Option<String>,
    /// fea: append a static step: bottom fixed, top displaced by this many mm in z.
    #[arg(long, allow_negative_numbers = true)]
    pub step: Option<f64>,
    /// fea: end sets, pieces and property bins.
    #[command(flatten)]
    pub fea_checks: Box<FeaChecks>,
    /// vat: intensity, vats and printer screen.
    #[command(flatten)]
    pub vat: Box<super::vat::VatArgs>,
    /// Override the refusals that protect your work and machine: replace a
    /// finished export in --out (a folder holding our manifest.json), and
    /// (fea) write a deck even when CalculiX would need more memory than
    /// this machine has. A folder of other files is never replaced.
    #[arg(long)]
    pub force: bool,
}

/// `volcad export fea` options that choose the end node sets, let a deck
/// in pieces through, and bin property fields (boxed: they would make every command's
/// arguments larger).
#[derive(clap::Args, Debug)]
pub struct FeaChecks {
    /// fea: NBOTTOM/NTOP are the nodes closer than this many mm to the lowest/highest z (default: one element size).
    #[arg(long, allow_negative_numbers = true)]
    pub fix_band: Option<f64>,
    /// fea: NBOTTOM (clamped) is the nodes where this condition on x, y, z holds, e.g. "z<0.5".
    #[arg(long, allow_hyphen_values = true)]
    pub fix: Option<String>,
    /// fea: NTOP (moved by --step) is the nodes where this condition holds, e.g. "z>29.5".
    #[arg(long, allow_hyphen_values = true)]
    pub load: Option<String>,
    /// fea: write a deck whose elements fall into several pieces (refused otherwise).
    #[arg(long)]
    pub allow_pieces: bool,
    /// fea: with a `modulus` attribute, elastic sets per property (default 16).
    #[arg(long, allow_negative_numbers = true)]
    pub property_bins: Option<usize>,
}

/// The voxel sizes accepted, in mm: a nanometre to a kilometre.
const VOXEL_RANGE: (f64, f64) = (1e-6, 1e6);

fn parse_voxel(s: &str) -> anyhow::Result<DVec3> {
    let parts: Vec<f64> = s
        .split(',')
        .map(|p| {
            p.trim()
                .parse::<f64>()
                .with_context(|| format!("--voxel {s}: {p:?} is not a number"))
        })
        .collect::<anyhow::Result<_>>()?;
    let v = match parts.as_slice() {
        [a] => DVec3::splat(*a),
        [a, b, c] => DVec3::new(*a, *b, *c),
        _ => bail!("--voxel {s}: give one size or three (X,Y,Z) in mm"),
    };
    if !(v.cmpgt(DVec3::ZERO).all() && v.is_finite()) {
        bail!("--voxel {s}: voxel sizes must be > 0");
    }
    // A voxel's volume is their product: outside this range it overflows
    // or vanishes in f64 (1e300 mm gives an infinite volume, NaN figures).
    if !(v.cmpge(DVec3::splat(VOXEL_RANGE.0)).all() && v.cmple(DVec3::splat(VOXEL_RANGE.1)).all()) {
        bail!(
            "--voxel {s}: each voxel size must be within {:e}..={:e} mm",
            VOXEL_RANGE.0,
            VOXEL_RANGE.1
        );
    }
    Ok(v)
}

pub(super) fn parse_layers(s: &str) -> anyhow::Result<std::ops::Range<usize>> {
    Ok(volcad_compilers::plan::text::parse_layers("--layers", s)?)
}

/// `--formats stl,obj,3mf` (any subset, any order).
fn parse_formats(s: &str) -> anyhow::Result<MeshFormats> {
    let mut f = MeshFormats {
        stl: false,
        obj: false,
        threemf: false,
    };
    for part in s.split(',').map(str::trim).filter(|p| !p.is_empty()) {
        match part.to_ascii_lowercase().as_str() {
            "stl" => f.stl = true,
            "obj" => f.obj = true,
            "3mf" => f.threemf = true,
            other => bail!("--formats {s}: unknown format `{other}`; use stl, obj and 3mf"),
        }
    }
    if !(f.stl || f.obj || f.threemf) {
        bail!("--formats {s}: name at least one of stl, obj, 3mf");
    }
    Ok(f)
}

/// The options given that belong to another kind of export than `a.kind`.
fn foreign_options(a: &ExportArgs) -> Vec<&'static str> {
    let given = [
        (
            "--layers",
            a.layers.is_some() && a.kind != Kind::Vat,
            Kind::Png,
        ),
        (
            "--dither",
            a.dither.is_some() && !matches!(a.kind, Kind::Gcvf | Kind::Vat),
            Kind::Png,
        ),
        ("--bitmaps", a.bitmaps, Kind::Png),
        ("--bitmap-format", a.bitmap_format.is_some(), Kind::Png),
        ("--bitmap-width", a.bitmap_width.is_some(), Kind::Png),
        ("--full-color", a.full_color, Kind::Png),
        ("--color-profile", a.color_profile.is_some(), Kind::Png),
        ("--map", a.map.is_some() && a.kind != Kind::Gcvf, Kind::Png),
        (
            "--liquid-keep-out",
            a.liquid_keep_out.is_some() && a.kind != Kind::Gcvf,
            Kind::Png,
        ),
        ("--segments", a.segments.is_some(), Kind::Mesh),
        ("--by", a.by.is_some(), Kind::Mesh),
        ("--infill", a.infill.is_some(), Kind::Mesh),
        ("--formats", a.formats.is_some(), Kind::Mesh),
        ("--element", a.element.is_some(), Kind::Fea),
        ("--min-cell", a.min_cell.is_some(), Kind::Fea),
        ("--max-cell", a.max_cell.is_some(), Kind::Fea),
        ("--sizing", a.sizing.is_some(), Kind::Fea),
        ("--step", a.step.is_some(), Kind::Fea),
        (
            "--property-bins",
            a.fea_checks.property_bins.is_some(),
            Kind::Fea,
        ),
        ("--fix-band", a.fea_checks.fix_band.is_some(), Kind::Fea),
        ("--fix", a.fea_checks.fix.is_some(), Kind::Fea),
        ("--load", a.fea_checks.load.is_some(), Kind::Fea),
        ("--allow-pieces", a.fea_checks.allow_pieces, Kind::Fea),
    ];
    let vat = a.vat.given().into_iter().map(|n| (n, true, Kind::Vat));
    given
        .into_iter()
        .chain(vat)
        .filter(|(_, on, kind)| *on && *kind != a.kind)
        .map(|(name, ..)| name)
        .collect()
}

/// `--dither` (default random).
pub(super) fn parse_dither(d: Option<&str>) -> anyhow::Result<Dither> {
    Ok(match d.unwrap_or("random") {
        "random" => Dither::Random,
        "diffusion" => Dither::Diffusion,
        d => bail!("--dither {d}: expected random or diffusion"),
    })
}

/// `--element` (default c3d8r).
fn parse_element(e: Option<&str>) -> anyhow::Result<Element> {
    Ok(match e.unwrap_or("c3d8r") {
        "c3d8r" | "C3D8R" => Element::C3D8R,
        "c3d4" | "C3D4" => Element::C3D4,
        e => bail!("--element {e}: expected c3d8r or c3d4"),
    })
}

/// Bricks are sized by `--voxel` alone: the tetrahedra's sizing options
/// would be ignored, and the deck would not be what was asked for.
fn refuse_tet_options(a: &ExportArgs, element: Element) -> anyhow::Result<()> {
    if element != Element::C3D8R {
        return Ok(());
    }
    refuse_given(
        &given_names(&[
            ("--min-cell", a.min_cell.is_some()),
            ("--max-cell", a.max_cell.is_some()),
            ("--sizing", a.sizing.is_some()),
        ]),
        "bricks (c3d8r, the default element), which --voxel sizes",
        "add --element c3d4 for adaptive tetrahedra, or give --voxel MM for bricks",
    )
}

/// The names of the options given, from `(name, given)` pairs.
pub(super) fn given_names(options: &[(&'static str, bool)]) -> Vec<&'static str> {
    options
        .iter()
        .filter(|(_, on)| *on)
        .map(|(name, _)| *name)
        .collect()
}

/// Refuses the options `given` (when there are any), which do not apply to
/// `what`, saying what to write `instead`.
fn refuse_given(given: &[&str], what: &str, instead: &str) -> anyhow::Result<()> {
    if given.is_empty() {
        return Ok(());
    }
    bail!(
        "{} {} not apply to {what}; {instead}",
        given.join(", "),
        if given.len() == 1 { "does" } else { "do" }
    )
}

/// Run `volcad export`.
pub fn export(a: &ExportArgs) -> anyhow::Result<()> {
    // Options of another export kind would be ignored, and the files would
    // not be what the command line asked for: refuse them before any work.
    let kind = format!("{:?}", a.kind).to_lowercase();
    refuse_given(
        &foreign_options(a),
        &format!("`volcad export {kind}`"),
        "see `volcad export --help` for which export each option belongs to",
    )?;
    if a.shard.is_some() && !matches!(a.kind, Kind::Png | Kind::Vat) {
        bail!(shard::not_shardable(&kind));
    }
    if a.kind == Kind::Fea {
        refuse_tet_options(a, parse_element(a.element.as_deref())?)?;
    }
    let l = load_design(&a.design)?;
    let model = l.model.clone();
    let voxel = match (&a.voxel, &a.preset) {
        // A vat printer's pixel and layer are its voxel (`vat.rs`).
        _ if a.kind == Kind::Vat => None,
        (Some(v), _) => Some(parse_voxel(v)?),
        (None, Some(p)) => Some(
            png_stack::presets()
                .iter()
                .find(|q| q.name == p.as_str())
                .map(|q| q.voxel)
                .with_context(|| {
                    let names: Vec<&str> = png_stack::presets().iter().map(|q| q.name).collect();
                    format!("--preset {p}: unknown; known presets: {}", names.join(", "))
                })?,
        ),
        (None, None) => None,
    };
    // The values the script ran with (from --param and --params/--set
    // alike, in declaration order): two runs with the same values share a
    // hash, which `volcad merge` relies on to join their shards.
    let values: Vec<String> = l
        .design
        .params
        .iter()
        .map(|p| format!("{}={:?}", p.name, p.value))
        .collect();
    let hash = design_hash(&[l.source.as_bytes(), values.join("\n").as_bytes()]);
    if let Some(t) = a.threads {
        volcad_compilers::resources::check_threads(t)?;
    }
    // A GrabCAD package is one file, not a folder of ours.
    let dest = match a.kind {
        Kind::Gcvf => super::gcvf::package_path(&a.out)?,
        _ => a.out.clone(),
    };
    let params = match a.kind {
        Kind::Gcvf => ExportParams::Gcvf(super::gcvf::gcvf_params(a, voxel, &dest)?),
        Kind::Png => ExportParams::Png(png_params(a, voxel)?),
        Kind::Mesh => ExportParams::Mesh(mesh_params(a, voxel, &model)?),
        Kind::Fea => ExportParams::Fea(fea_params(a, voxel, &model)?),
        Kind::Vat => ExportParams::Vat(super::vat::vat_params(a, &model)?),
    };
    // `--preset j750` relabels the design with the printer's resins (a
    // full-colour stack is made of them whatever the design's materials).
    let model = match params {
        ExportParams::Png(_) if !a.full_color => super::gcvf::printer_model(a, model)?,
        ExportParams::Png(_) if a.preset.as_deref().is_some_and(is_j750_preset) => {
            check_j750_tray(&model)?;
            model
        }
        _ => model,
    };
    let verdicts = preflight(&params, &model, &dest)?;
    for v in verdicts.iter().filter(|v| v.severity == Severity::Warn) {
        eprintln!("{}", v.message);
    }
    if let Some(v) = blocking(&verdicts, a.force) {
        bail!("{}", v.message);
    }
    let mut params = params;
    params.set_force(a.force);
    // Before the job starts: a signal that came between the job creating
    // its staging folder and the handler being installed ended the process
    // with the folder left behind (seen once in CI).
    let interrupted = interrupt_flag();
    let design = a
        .design
        .design
        .file_name()
        .map(|n| n.to_string_lossy().into_owned());
    let handle = params.run(model, dest, hash, design);
    follow(handle, &interrupted)
}

/// The plan's estimate (printed) and every pre-flight verdict for an
/// export into `dest`. Adaptive tetrahedra skip the estimate: it grades a
/// coarse lattice, as long as meshing itself.
fn preflight(
    params: &ExportParams,
    model: &volcad_core::Model,
    dest: &Path,
) -> anyhow::Result<Vec<Verdict>> {
    let (mut verdicts, disk) = if params.estimate_is_slow() {
        (params.design_verdicts(model), None)
    } else {
        let a = params.assess(model)?;
        note!("estimate: {}", a.text);
        (a.verdicts, a.disk_bytes)
    };
    verdicts.extend(params.preflight(disk, dest));
    Ok(verdicts)
}

/// The slice stack's parameters from the options (`voxel` as parsed).
pub(crate) fn png_params(a: &ExportArgs, voxel: Option<DVec3>) -> anyhow::Result<PngParams> {
    let dither = match a.dither.as_deref().unwrap_or("random") {
        "random" => Dither::Random,
        "diffusion" => Dither::Diffusion,
        d => bail!("--dither {d}: expected random or diffusion"),
    };
    check_color_options(a)?;
    let bitmap_format = match &a.bitmap_format {
        Some(f) => BitmapFormat::parse(f)?,
        None => BitmapFormat::Png,
    };
    Ok(PngParams {
        voxel: voxel.context(
            "--voxel or --preset is required for png (e.g. --voxel 0.1 or --preset j750)",
        )?,
        seed: a.seed,
        dither,
        layers: a.layers.as_deref().map(parse_layers).transpose()?,
        shard: a.shard.as_deref().map(str::parse).transpose()?,
        per_material_bitmaps: a.bitmaps,
        threads: a.threads,
        liquid_keep_out: a.liquid_keep_out,
        full_color: a.full_color,
        color_profile: a.color_profile.clone(),
        bitmap_format,
        bitmap_width: a.bitmap_width,
    })
}

/// Options that would do nothing with the full-colour and bitmap options
/// given (the plan refuses the rest: a profile without --full-color, a
/// width without BMP, keep-out in colour).
fn check_color_options(a: &ExportArgs) -> anyhow::Result<()> {
    if a.bitmap_format.is_some() && !a.bitmaps {
        bail!("--bitmap-format: chooses the format of the 1-bit bitmaps; add --bitmaps");
    }
    if a.full_color {
        if let Some(d) = &a.dither {
            bail!(
                "--dither {d}: a full-colour stack always diffuses colour error in OKLab; leave --dither out with --full-color"
            );
        }
        if let Some(m) = &a.map {
            bail!(
                "--map {m}: a full-colour stack is made of the J750 colour resins whatever the design's materials; leave --map out with --full-color"
            );
        }
    }
    Ok(())
}

/// The mesh export's parameters from the options (`voxel` as parsed).
fn mesh_params(
    a: &ExportArgs,
    voxel: Option<DVec3>,
    model: &volcad_core::Model,
) -> anyhow::Result<MeshParams> {
    let by = match a.by.as_deref() {
        None | Some("dominant") => SegmentBy::Dominant,
        Some(name) => SegmentBy::Material(model.table().id(name).context("--by")?),
    };
    // Dominant segments are one per material: a range count would
    // be silently ignored, and the files would not be what was asked.
    if let (SegmentBy::Dominant, Some(n)) = (by, a.segments) {
        bail!(
            "--segments {n}: ranges split one material's fraction; add --by MATERIAL \
             (for example --by {}), or leave --segments out for one segment per \
             dominant material",
            model
                .materials()
                .first()
                .map(|&id| model.table().name(id).to_string())
                .unwrap_or_else(|| "red".into())
        );
    }
    Ok(MeshParams {
        voxel: voxel.context("--voxel is required for mesh (e.g. --voxel 0.25)")?,
        segments: a.segments.unwrap_or(MeshParams::default().segments),
        by,
        formats: parse_formats(a.formats.as_deref().unwrap_or("stl,obj,3mf"))?,
        infill_expr: a.infill.clone(),
        threads: a.threads,
    })
}

/// The FEA export's parameters from the options (`voxel` as parsed).
fn fea_params(
    a: &ExportArgs,
    voxel: Option<DVec3>,
    model: &volcad_core::Model,
) -> anyhow::Result<FeaParams> {
    let element = parse_element(a.element.as_deref())?;
    let voxel = voxel.map(|v| v.min_element());
    // The default element size comes from the box: an unbounded
    // design is refused first, as every export words it.
    let size = volcad_compilers::design::bounded_box(model)?
        .size()
        .min_element();
    let min_cell = a.min_cell.or(voxel).unwrap_or(size / 10.0);
    Ok(FeaParams {
        element,
        voxel: voxel.unwrap_or(min_cell),
        min_cell,
        max_cell: a.max_cell.unwrap_or(min_cell * 4.0),
        sizing: a.sizing.clone().map_or(Sizing::Heterogeneity, Sizing::Expr),
        seed: a.seed,
        property_bins: a.fea_checks.property_bins,
        step: a.step.map(|d| StepParams {
            top_displacement: d,
        }),
        ends: EndSets {
            band: a.fea_checks.fix_band,
            fix: a.fea_checks.fix.clone(),
            load: a.fea_checks.load.clone(),
        },
        allow_pieces: a.fea_checks.allow_pieces,
        // Set by the plan once the user agreed (`--force`).
        force: false,
        solver_memory: None,
        threads: a.threads,
    })
}

/// A flag that Ctrl-C, SIGTERM and SIGHUP set, for [`follow`] to cancel the
/// export with.
pub(super) fn interrupt_flag() -> Arc<AtomicBool> {
    let interrupted = Arc::new(AtomicBool::new(false));
    let flag = interrupted.clone();
    // A second handler cannot be installed (e.g. in tests running several
    // exports in one process); the job then simply runs to its end.
    // The first signal cancels (the job removes its staging folder); a
    // second one exits at once, for a job that does not stop promptly (the
    // next export to the same place removes what it left).
    let _ = ctrlc::set_handler(move || {
        if flag.swap(true, Ordering::Relaxed) {
            note!("interrupted again: exiting without waiting for the export to stop");
            std::process::exit(130);
        }
    });
    interrupted
}

/// Show progress until the job ends; a signal (`interrupted`) cancels it.
pub(super) fn follow(handle: job::JobHandle, interrupted: &AtomicBool) -> anyhow::Result<()> {
    let bar = indicatif::ProgressBar::new(1000);
    bar.set_style(
        indicatif::ProgressStyle::with_template(
            "{spinner} {msg:<24} [{bar:30}] {percent:>3}% eta {eta}",
        )
        .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    let dest = handle.destination().to_path_buf();
    // Waits on the progress channel, which closes when the job ends: the
    // command returns as soon as the export is done (sleeping between
    // polls would add half a sleep on average to every export), and Ctrl-C
    // is still seen within 50 ms.
    while !handle.is_finished() {
        if interrupted.load(Ordering::Relaxed) {
            handle.cancel();
        }
        match handle.progress.recv_timeout(Duration::from_millis(50)) {
            Ok(p) => {
                bar.set_message(p.stage.clone());
                bar.set_position((p.fraction * 1000.0) as u64);
            }
            Err(RecvTimeoutError::Timeout) => {}
            Err(RecvTimeoutError::Disconnected) => break,
        }
    }
    bar.finish_and_clear();
    let summary = handle.join()?;
    outln!(
        "{}: {} files in {}",
        summary.kind,
        summary.files.len(),
        dest.display()
    );
    for (name, count) in &summary.counts {
        outln!("  {name:<16} {count}");
    }
    if summary.seconds > 0.0 && summary.units > 0 {
        outln!(
            "  {} {} in {:.2} s ({:.3e} {}/s)",
            summary.units,
            summary.unit,
            summary.seconds,
            summary.units as f64 / summary.seconds,
            summary.unit
        );
    }
    for n in &summary.notes {
        outln!("  {n}");
    }
    Ok(())
}
