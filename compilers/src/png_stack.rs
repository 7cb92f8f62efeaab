//! Inkjet slice stacks: one PNG per layer, each pixel one material.
//!
//! Pipeline, one slab of layers at a time (memory ∝ slab, never volume):
//! `Sampler::sample_layers` (distances + fractions, parallel) → material
//! codes per voxel ([`crate::dither`]: seeded random or 3D error diffusion)
//! → per layer, in parallel: RGBA rows → PNG bytes ([`crate::png_io`]) →
//! file. Output bytes depend only on the design and the parameters, never
//! on the thread count or the layer range.
//!
//! # Layout
//!
//! * `slice_00000.png` … one 8-bit RGBA PNG per layer, named by its *global*
//!   layer index (zero padded to at least 5 digits, more when the grid has
//!   ≥ 100 000 layers); layer 0 is the lowest Z. Parts of a job exported
//!   with different `layers` ranges (or `shard`s) hold the single export's
//!   files; [`crate::shard`] merges them, manifest included.
//! * Pixel = the material's colour from the material table; void is
//!   transparent `(0, 0, 0, 0)`. Each PNG's `pHYs` chunk holds the voxel's
//!   X and Y size, so image tools show the layer at its printed size.
//! * Orientation: image width is X, height is Y. **Column 0 = min X, row 0 =
//!   max Y**: an image viewer shows the layer as seen from above (+Z) with +X
//!   to the right and +Y up, not mirrored. (pyvcad puts min Y in row 0 and
//!   max X in column 0, i.e. the same view turned 180°.)
//! * With `per_material_bitmaps`: one folder per material (its name, made
//!   safe for file systems), holding 1-bit grayscale PNGs with the same
//!   names, white (1) where the voxel is that material.
//! * Grid: voxel centres `origin + (i + ½)·voxel`, `ceil(extent / voxel)`
//!   voxels per axis centred on the design's bounding box (the sampler's
//!   [`Grid::covering`]).
//!
//! # Differences from pyvcad's `DirectMaterialCompiler`
//!
//! Samples sit at voxel centres (pyvcad: corners `min + i·vs`); X is not
//! flipped; empty leading and trailing layers are kept, so file `k` is
//! always layer `k` and split jobs merge; names are zero padded; the choice
//! is seeded and repeatable (pyvcad's is not), with error diffusion as an
//! option; fractions are normalised by their sum.

use std::ops::Range;
use std::sync::atomic::{AtomicU64, Ordering};

use glam::DVec3;
use rayon::prelude::*;
use volcad_core::Model;
use volcad_core::sampler::{Consumer, Grid, Sampler, Slab};

use crate::bitmaps::{self, BitmapFolder, BitmapFormat, BitmapStyle};
use crate::color::{self, ColorPlan};
use crate::design::{grid_for, palette};
use crate::dither::{self, Diffuser};
use crate::estimate::{Look, coarse_estimate, sampled_layers};
use crate::job::{ExportError, JobContext, Summary};
use crate::keep_out;
use crate::lazy_random;
use crate::png_io::{self, PixelsPerMetre};
pub use crate::png_summary::grid_span_note;
pub(crate) use crate::png_summary::merged_notes;
use crate::png_summary::summary;
pub use crate::presets::{Preset, preset, presets};
use crate::resources::{check_disk, check_memory, run_with_threads};
use crate::slice_image::{ImageStyle, Orientation, bitmap_png, rgba_png};

pub use crate::png_params::{Dither, PngParams};

/// What a slice stack will take, known before it starts.
#[derive(Clone, Debug, PartialEq)]
pub struct Estimate {
    /// The voxel grid.
    pub grid: Grid,
    /// Layers that will be written (global indices).
    pub layers: Range<usize>,
    /// Voxels in those layers.
    pub voxels: u64,
    /// Layers sampled per slab.
    pub slab_layers: usize,
    /// Working memory (bytes).
    pub memory_bytes: u64,
    /// Rough size of the output (bytes).
    pub disk_bytes: u64,
    /// Files that will be written.
    pub files: u64,
}

/// Working memory aimed at for one slab.
const SLAB_BUDGET: usize = 256 << 20;
/// Most layers per slab.
const MAX_SLAB_LAYERS: usize = 16;

/// Grid, layer range, memory and output size of a stack; errors for a bad
/// voxel size, an unbounded or empty design, a material missing from the
/// table, a bad layer range, or buffers that do not fit in memory.
///
/// The output size comes from a rule of thumb and from a few layers coded
/// and encoded as the export does (`sampled_bytes`): what the CLI prints
/// and checks the disk with, and the studio shows. The export job itself
/// checks by the rule alone (coding the layers costs as much as a small
/// stack's own export).
pub fn estimate(model: &Model, p: &PngParams) -> Result<Estimate, ExportError> {
    estimate_with(model, p, Look::Layers)
}

pub(crate) fn estimate_with(
    model: &Model,
    p: &PngParams,
    look: Look,
) -> Result<Estimate, ExportError> {
    let pal = palette(model)?;
    keep_out::plan(model, p.liquid_keep_out)?;
    let grid = grid_for(model, p.voxel, 0.0)?;
    let inks = check_options(model, p, &grid)?;
    let [nx, ny, nz] = grid.dims;
    let layers = match (&p.layers, p.shard) {
        (Some(_), Some(s)) => {
            return Err(ExportError::param(
                "--shard",
                format!("{s} and --layers both choose layers; give one of them"),
            ));
        }
        (None, Some(s)) => s.layers(nz)?,
        (None, None) => 0..nz,
        (Some(r), None) if r.start < r.end && r.end <= nz => r.clone(),
        (Some(r), None) => {
            return Err(ExportError::param(
                "--layers",
                format!(
                    "{}..{} is not a non-empty range inside 0..{nz} (the grid has {nz} layers)",
                    r.start, r.end
                ),
            ));
        }
    };
    let k = model.materials().len();
    let layer = nx * ny;
    // Per layer held in a slab: distance (4) + fractions (4k) + code (1);
    // full colour adds the wanted colours.
    let per_layer = if p.full_color {
        layer * color::bytes_per_voxel(k)
    } else {
        layer * (5 + 4 * k)
    };
    let slab_layers = (SLAB_BUDGET / per_layer.max(1))
        .clamp(1, MAX_SLAB_LAYERS)
        .min(layers.len() + dither::BLOCK_LAYERS);
    let workers = p
        .threads
        .unwrap_or_else(rayon::current_num_threads)
        .max(1)
        .min(slab_layers);
    // Per encoding worker: RGBA (4), PNG output (≤ 4), one bitmap (⅛).
    let encode = layer * 9;
    let carry = if p.dither == Dither::Diffusion {
        layer * Diffuser::bytes_per_voxel(k)
    } else {
        0
    };
    let memory_bytes = (slab_layers * per_layer + workers * encode + carry) as u64;
    check_memory(
        memory_bytes,
        &format!("a slab of {slab_layers} layer(s) of {nx} × {ny} voxels"),
    )?;
    let voxels = (layer * layers.len()) as u64;
    // Rough output: pure material compresses to almost nothing, a two-way
    // mix to 0.7 (random) or 0.85 (diffusion) bytes per voxel (the files'
    // bytes over its voxels from `volcad export png
    // assets/examples/graded_bar.rhai --voxel 0.02`, with `--dither random`
    // and `--dither diffusion`), plus a row's worth and a header per file.
    let pr = coarse_estimate(model, p.voxel);
    let mixed_bytes = match p.dither {
        Dither::Random => 0.7,
        Dither::Diffusion => 0.85,
    };
    // A full-colour part is dithered everywhere.
    let per_voxel = match p.full_color {
        true => FULL_COLOR_BYTES * pr.inside,
        false => 0.02 * pr.inside + mixed_bytes * pr.mixed,
    };
    let mut files = layers.len() as u64;
    let mut disk = voxels as f64 * per_voxel + files as f64 * (200.0 + ny as f64);
    if p.per_material_bitmaps {
        let n = (layers.len() * inks) as u64;
        files += n;
        disk += match p.bitmap_format {
            BitmapFormat::Png => {
                voxels as f64 * (0.01 * pr.inside + 0.12 * pr.mixed)
                    + n as f64 * (100.0 + ny as f64 / 4.0)
            }
            // Uncompressed: exact.
            BitmapFormat::Bmp => {
                let w = p.bitmap_width.unwrap_or(nx);
                n as f64 * (bitmaps::BMP_HEADER + bitmaps::bmp_row_bytes(w) * ny) as f64
            }
        };
    }
    // The rule above is rough (0.7 to 2.2 bytes a mixed voxel across the
    // examples); a few layers coded and encoded as the export does see
    // what it cannot.
    let sampled = match look {
        Look::Layers if !p.full_color => sampled_bytes(model, p, grid, &layers, &pal),
        _ => None,
    };
    let disk = match sampled {
        Some(b) => disk.max(b as f64),
        None => disk,
    };
    Ok(Estimate {
        grid,
        layers,
        voxels,
        slab_layers,
        memory_bytes,
        disk_bytes: disk as u64,
        files,
    })
}

/// Bytes an inside voxel of a full-colour stack's PNGs take: every voxel
/// is dithered among six colours, which fdeflate's row filter barely
/// shrinks below one RGBA byte a voxel.
const FULL_COLOR_BYTES: f64 = 1.2;

/// Check the options that go together (full colour, bitmap format and
/// width) and the design's colours; returns how many inks (materials or
/// resins) the stack's voxels take.
fn check_options(model: &Model, p: &PngParams, grid: &Grid) -> Result<usize, ExportError> {
    if p.bitmap_width.is_some() && p.bitmap_format != BitmapFormat::Bmp {
        return Err(ExportError::param(
            "--bitmap-width",
            "sets the width of BMP bitmaps; add --bitmaps --bitmap-format bmp",
        ));
    }
    bitmaps::check_width(p.bitmap_width, grid.dims[0], grid.voxel)?;
    if !p.full_color {
        if p.color_profile.is_some() {
            return Err(ExportError::param(
                "--color-profile",
                "gives the resins' colours for --full-color; add --full-color",
            ));
        }
        return Ok(model.materials().len());
    }
    if p.liquid_keep_out.is_some() {
        return Err(ExportError::param(
            "--liquid-keep-out",
            "removes a material, and a full-colour stack is made of colour resins; leave it out",
        ));
    }
    Ok(color::check(model, p)?.resins.len())
}

/// Write the slice stack into `ctx.staging()`.
pub fn export_png_stack(
    model: &Model,
    p: &PngParams,
    ctx: &JobContext,
) -> Result<Summary, ExportError> {
    let est = estimate_with(model, p, Look::Coarse)?;
    check_disk(est.disk_bytes, ctx.folder(), "a larger voxel size")?;
    run_with_threads(p.threads, || write_stack(model, p, &est, ctx))
}

/// What the stack's voxels are made of: names (with their table ids, for
/// folder names) and palette by code (0 = void).
struct Inks {
    names: Vec<(String, u8)>,
    pal: Vec<[u8; 4]>,
    plan: Option<ColorPlan>,
}

fn inks(model: &Model, p: &PngParams) -> Result<Inks, ExportError> {
    if p.full_color {
        let plan = ColorPlan::new(model, p)?;
        let names = plan.resins.iter().map(|r| (r.name.clone(), 0)).collect();
        let pal = std::iter::once([0; 4])
            .chain(plan.resins.iter().map(|r| r.rgba))
            .collect();
        return Ok(Inks {
            names,
            pal,
            plan: Some(plan),
        });
    }
    let names = model
        .materials()
        .iter()
        .map(|id| (model.table().name(*id).to_owned(), *id))
        .collect();
    Ok(Inks {
        names,
        pal: palette(model)?,
        plan: None,
    })
}

/// What writing one layer (or a whole stack) produced.
pub(crate) struct LayerOut {
    /// Files written, relative to the output folder.
    pub files: Vec<String>,
    /// Voxels per count slot (material or vat).
    pub counts: Vec<u64>,
}

/// Run `write` on every layer of the stack (its global index and material
/// codes, see [`for_each_slab`], or the resin codes of a full-colour
/// `plan`, see [`color::for_each_slab`]), the layers of a slab in
/// parallel, and gather their files in layer order and their `slots`
/// counts.
pub(crate) fn write_layers(
    model: &Model,
    p: &PngParams,
    plan: Option<&ColorPlan>,
    est: &Estimate,
    ctx: &JobContext,
    slots: usize,
    write: impl Fn(usize, &[u8]) -> Result<LayerOut, ExportError> + Sync,
) -> Result<LayerOut, ExportError> {
    let [nx, ny, _] = est.grid.dims;
    let layer = nx * ny;
    let mut all = LayerOut {
        files: Vec::new(),
        counts: vec![0; slots],
    };
    let written = AtomicU64::new(0);
    let each = |zs: Range<usize>, codes: &[u8]| {
        let outs: Vec<LayerOut> = zs
            .clone()
            .into_par_iter()
            .map(|z| {
                let i = z - zs.start;
                let out = write(z, &codes[i * layer..(i + 1) * layer])?;
                // Per layer, in whatever order layers finish (reports are snapshots).
                let n = written.fetch_add(1, Ordering::Relaxed) + 1;
                let total = est.layers.len() as u64;
                ctx.progress("slicing", n, total, "layers", n as f64 / total as f64);
                Ok(out)
            })
            .collect::<Result<_, ExportError>>()?;
        for o in outs {
            all.files.extend(o.files);
            for (t, c) in all.counts.iter_mut().zip(o.counts) {
                *t += c;
            }
        }
        Ok(())
    };
    match plan {
        Some(plan) => color::for_each_slab(model, plan, est, ctx, each)?,
        None => for_each_slab(model, p, est, ctx, each)?,
    }
    Ok(all)
}

fn write_stack(
    model: &Model,
    p: &PngParams,
    est: &Estimate,
    ctx: &JobContext,
) -> Result<Summary, ExportError> {
    let [nx, ny, nz] = est.grid.dims;
    let inks = inks(model, p)?;
    let digits = png_io::name_digits(nz);
    let folders = if p.per_material_bitmaps {
        bitmaps::folders(&inks.names)
    } else {
        Vec::new()
    };
    for f in &folders {
        let dir = ctx.staging().join(&f.dir);
        std::fs::create_dir_all(&dir).map_err(|e| ExportError::io(&dir, e))?;
    }
    let style = top_view(est.grid.voxel);
    let bits = BitmapStyle {
        format: p.bitmap_format,
        width: p.bitmap_width,
        image: style,
    };
    let slots = inks.names.len();
    let out = write_layers(model, p, inks.plan.as_ref(), est, ctx, slots, |z, c| {
        write_layer(ctx, [nx, ny], z, digits, c, &inks.pal, &folders, bits)
    })?;
    let names = inks.names.into_iter().map(|(n, _)| n);
    Ok(summary(
        model,
        p,
        est,
        out.files,
        names.zip(out.counts).collect(),
        inks.plan.as_ref(),
    ))
}

/// The PNG stack's images: top view, with the voxel's size in `pHYs`.
fn top_view(voxel: DVec3) -> ImageStyle {
    ImageStyle {
        orientation: Orientation::TopView,
        pixel: Some(PixelsPerMetre::from_mm(voxel.x, voxel.y)),
    }
}

/// Sample and code the stack's layers one slab at a time and hand each
/// slab's layers to `f`: the global layer range and one material code per
/// voxel (x fastest, then y, then layer; 0 = void). Layers below
/// `est.layers` that error diffusion warms up on are not handed over.
pub(crate) fn for_each_slab(
    model: &Model,
    p: &PngParams,
    est: &Estimate,
    ctx: &JobContext,
    mut f: impl FnMut(Range<usize>, &[u8]) -> Result<(), ExportError>,
) -> Result<(), ExportError> {
    let grid = est.grid;
    let [nx, ny, _] = grid.dims;
    let layer = nx * ny;
    let k = model.materials().len();
    let keep = keep_out::plan(model, p.liquid_keep_out)?;
    // Keep-out needs every voxel's distance and fractions.
    let single = single_material_code(model).filter(|_| keep.is_none());
    let mut diffuser =
        (p.dither == Dither::Diffusion && single.is_none()).then(|| Diffuser::new(nx, ny, k));
    let sampler = match keep {
        Some(_) => Sampler::new(model, grid, Consumer::PngStackKeepOut),
        None => stack_sampler(model, grid, single, diffuser.is_some()),
    };
    let first = if diffuser.is_some() {
        Diffuser::warmup_start(est.layers.start)
    } else {
        est.layers.start
    };
    let mut codes = vec![0u8; est.slab_layers * layer];
    sample_slabs(
        &sampler,
        first..est.layers.end,
        est.slab_layers,
        ctx,
        |z0, z1, slab| {
            if let Some(keep) = &keep {
                keep_out::apply(keep, model, &grid, z0, &mut slab.dist, &mut slab.fracs);
            }
            let codes = &mut codes[..(z1 - z0) * layer];
            match diffuser.as_mut() {
                Some(d) => {
                    for (l, c) in codes.chunks_mut(layer).enumerate() {
                        let v = l * layer;
                        d.layer(
                            z0 + l,
                            &slab.dist[v..v + layer],
                            &slab.fracs[v * k..(v + layer) * k],
                            c,
                        );
                    }
                }
                None => pick_codes(model, grid, p.seed, single, z0, slab, codes),
            }
            ctx.check_cancel()?;
            let from = z0.max(est.layers.start);
            f(from..z1, &codes[(from - z0) * layer..])
        },
    )
}

/// Sample `layers` with `sampler`, `slab_layers` at a time, checking for
/// a cancel before each slab, and hand each slab (its first and end
/// layer) to `each`: the slab loop every stack shares.
pub(crate) fn sample_slabs(
    sampler: &Sampler<'_>,
    layers: Range<usize>,
    slab_layers: usize,
    ctx: &JobContext,
    mut each: impl FnMut(usize, usize, &mut Slab) -> Result<(), ExportError>,
) -> Result<(), ExportError> {
    let mut slab = Slab::default();
    let mut z0 = layers.start;
    while z0 < layers.end {
        ctx.check_cancel()?;
        let z1 = (z0 + slab_layers).min(layers.end);
        sampler
            .sample_layers(z0, z1, &mut slab, ctx.cancel_flag())
            .map_err(|_| ExportError::Cancelled)?;
        each(z0, z1, &mut slab)?;
        z0 = z1;
    }
    Ok(())
}

/// The code every inside voxel gets when the design has one material
/// everywhere (fixed fractions with one non-zero entry): random picks and
/// error diffusion both choose it whatever their numbers, so neither the
/// fractions nor the picks are needed, and the signs alone are sampled.
fn single_material_code(model: &Model) -> Option<u8> {
    let k = model.materials().len();
    let mut f = vec![0.0; k];
    if !model.fixed_fractions(&mut f) {
        return None;
    }
    let mut nonzero = f.iter().enumerate().filter(|(_, v)| **v > 0.0);
    match (nonzero.next(), nonzero.next()) {
        (Some((i, v)), None) if *v as f32 > crate::dither::MIN_TOTAL => u8::try_from(i + 1).ok(),
        _ => None,
    }
}

/// The sampler of a stack. Random picks need a voxel's fractions only
/// where bounds leave the pick open (see lazy_random.rs); diffusion needs
/// every one; a design of one material everywhere (`single`) needs none.
/// Pixels need the sign of the distance only.
fn stack_sampler(model: &Model, grid: Grid, single: Option<u8>, diffusion: bool) -> Sampler<'_> {
    let consumer = match (single, diffusion) {
        (Some(_), _) => Consumer::PngStackSingle,
        (None, true) => Consumer::PngStackDiffusion,
        (None, false) => Consumer::PngStackRandom,
    };
    Sampler::new(model, grid, consumer)
}

/// Material codes of the layers of `slab` (from layer `z0`) by `single`'s
/// code or seeded random picks (error diffusion is `Diffuser::layer`).
fn pick_codes(
    model: &Model,
    grid: Grid,
    seed: u64,
    single: Option<u8>,
    z0: usize,
    slab: &Slab,
    codes: &mut [u8],
) {
    let [nx, ny, _] = grid.dims;
    let k = model.materials().len();
    match single {
        Some(code) => codes
            .par_chunks_mut(nx)
            .zip(slab.dist.par_chunks(nx))
            .for_each(|(c, d)| {
                // Branch-free, so the loop vectorises (NaN counts as inside,
                // as `d > 0` false did).
                for (o, d) in c.iter_mut().zip(d) {
                    *o = code - code * u8::from(*d > 0.0);
                }
            }),
        None => {
            // The sampler's lazy rectangles, row by row, per layer.
            let lazy: Vec<_> = (0..slab.layers)
                .map(|l| slab.rect_rows(z0 + l, nx, ny))
                .collect();
            // Runs along x share their bounds from row to row where the
            // fractions do not vary along y or z.
            let shared = lazy_random::RunMemo::applies(model);
            codes.par_chunks_mut(nx).enumerate().for_each_init(
                lazy_random::RunMemo::default,
                |memo, (row, c)| {
                    let v = row * nx;
                    lazy_random::choose_random_row(
                        model,
                        &grid,
                        seed,
                        [row % ny, z0 + row / ny],
                        &slab.dist[v..v + nx],
                        &slab.fracs[v * k..(v + nx) * k],
                        k,
                        lazy[row / ny].row(row % ny),
                        c,
                        shared.then_some(memo),
                    );
                },
            )
        }
    }
}

/// Layers the size estimate samples, codes and encodes (see
/// [`sampled_bytes`]).
const SAMPLED_LAYERS: usize = 3;

/// Bytes of the stack's files from [`SAMPLED_LAYERS`] layers (the middles
/// of equal stretches of the range) coded and encoded as the export does,
/// scaled to every layer; `None` when a layer's buffers would not fit the
/// slab budget. Error diffusion is estimated from random picks scaled by
/// 0.85/0.7 (the rule of thumb's two ratios, see [`estimate_with`]), since
/// its codes depend on every layer below. How well a layer compresses
/// depends on its colours and its mix, which a rule of thumb cannot see:
/// compare the bytes per voxel of `volcad export png` on the graded bar at
/// 0.02 mm and on the seat (`assets/examples/bicycle_seat.rhai`) at 0.3 mm.
fn sampled_bytes(
    model: &Model,
    p: &PngParams,
    grid: Grid,
    layers: &Range<usize>,
    pal: &[[u8; 4]],
) -> Option<u64> {
    let [nx, ny, _] = grid.dims;
    let k = model.materials().len();
    if nx * ny * (4 + 4 * k + 1 + 8) > SLAB_BUDGET {
        return None;
    }
    let single = single_material_code(model);
    let sampler = stack_sampler(model, grid, single, false);
    let mut slab = Slab::default();
    let mut codes = vec![0u8; nx * ny];
    let mut bits = Vec::new();
    let style = top_view(grid.voxel);
    let (mut bytes, mut picks) = (0usize, 0usize);
    for z in sampled_layers(layers.clone(), SAMPLED_LAYERS) {
        picks += 1;
        sampler
            .sample_layers(
                z,
                z + 1,
                &mut slab,
                &std::sync::atomic::AtomicBool::new(false),
            )
            .ok()?;
        pick_codes(model, grid, p.seed, single, z, &slab, &mut codes);
        bytes += rgba_png(nx, ny, &codes, pal, style).ok()?.len();
        if p.per_material_bitmaps {
            for code in 1..=k as u8 {
                bytes += bitmap_png(nx, ny, &codes, code, &mut bits, style)
                    .ok()?
                    .len();
            }
        }
    }
    let scale = if p.dither == Dither::Diffusion && single.is_none() {
        0.85 / 0.7
    } else {
        1.0
    };
    Some((bytes as f64 * scale * layers.len() as f64 / picks.max(1) as f64) as u64)
}

/// Colour, encode and write layer `z` from its codes; count its materials.
#[allow(clippy::too_many_arguments)]
fn write_layer(
    ctx: &JobContext,
    [nx, ny]: [usize; 2],
    z: usize,
    digits: usize,
    codes: &[u8],
    pal: &[[u8; 4]],
    folders: &[BitmapFolder],
    bits: BitmapStyle,
) -> Result<LayerOut, ExportError> {
    let name = png_io::slice_name(z, digits);
    // A histogram of every code, without a branch or bounds check a voxel.
    let mut hist = [0u64; 256];
    for c in codes {
        hist[*c as usize] += 1;
    }
    let counts: Vec<u64> = hist[1..pal.len()].to_vec();
    let path = ctx.staging().join(&name);
    let bytes = rgba_png(nx, ny, codes, pal, bits.image)
        .map_err(|e| ExportError::Other(format!("{}: PNG encoding: {e}", path.display())))?;
    std::fs::write(&path, bytes).map_err(|e| ExportError::io(&path, e))?;
    let mut files = vec![name.clone()];
    files.extend(bitmaps::write_layer(
        ctx,
        [nx, ny],
        z,
        &name,
        codes,
        folders,
        bits,
    )?);
    Ok(LayerOut { files, counts })
}
