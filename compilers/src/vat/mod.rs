//! Vat photopolymer slice stacks: one 8-bit grayscale image of the whole
//! screen per layer (and per vat on multi-vat printers), for masked-LCD
//! (MSLA) printers and grayscale-exposure research printers.
//!
//! Pipeline: the PNG stack's slab loop (`png_stack::for_each_slab`:
//! sampling, the seeded material draw or error diffusion, layer range and
//! shard) gives each voxel a material; each material belongs to one vat;
//! per layer, in parallel, each vat's image is the screen, black, with the
//! part's voxels of that vat at their intensity → PNG (with `pHYs`) or BMP.
//! Bytes depend only on the design and the parameters, never on the thread
//! count or the layer range.
//!
//! # Layout
//!
//! * One vat: `slice_00000.png` … (names as the PNG stack's), one per
//!   layer, layer 0 the lowest. Several vats: `vat1/slice_00000.png`,
//!   `vat2/…`, the same layer indices in every folder.
//! * Image = the printer's whole screen (`W × H` pixels), background 0
//!   (black, no light); the part's grid is centred on the screen, or moved
//!   by `offset` (mm). Column 0 = min X, row 0 = max Y (the PNG stack's
//!   top view).
//! * Pixel value: 255 where the voxel is solid, or its intensity: a scalar
//!   attribute mapped linearly from `[lo, hi]` onto 0..=255 (clamped), or
//!   one material's fraction (fractions normalised by their sum) × 255.
//!
//! Printers' own binaries (`.ctb`, `.goo`, `.pwmx`) are not written: their
//! slicers (and UVtools) import PNG stacks.

pub mod printers;
mod write;

pub(crate) use write::merged_notes;

use std::ops::Range;

use glam::DVec3;
use volcad_core::Model;
use volcad_core::attribute::AttributeKind;
use volcad_core::sampler::Grid;

use crate::job::{ExportError, JobContext, Summary};
use crate::png_stack::{self, Dither, PngParams};
use crate::resources::{check_disk, check_memory, run_with_threads};
use crate::shard::Shard;
pub use printers::{VatPrinter, vat_preset, vat_presets};

/// Where each pixel's gray value comes from.
#[derive(Clone, Debug, PartialEq)]
pub enum Intensity {
    /// Every solid voxel at full exposure (255).
    Solid,
    /// A scalar attribute mapped over `range` (`None`: the attribute's
    /// interval bound over the design) onto 0..=255.
    Attribute {
        /// The attribute's name.
        name: String,
        /// The values shown as 0 and 255.
        range: Option<(f64, f64)>,
    },
    /// The fraction of one material, × 255.
    Fraction(String),
}

/// Parameters of a vat stack.
#[derive(Clone, Debug, PartialEq)]
pub struct VatParams {
    /// The printer's screen and build height.
    pub printer: VatPrinter,
    /// Gray value source.
    pub intensity: Intensity,
    /// Materials of each vat (one entry per vat; 1, 2 or 4 vats). Empty:
    /// one vat holding every material.
    pub vats: Vec<Vec<String>>,
    /// The part's centre moved from the screen's centre by this (mm).
    pub offset: [f64; 2],
    /// Write 8-bit BMP rather than PNG.
    pub bmp: bool,
    /// Seed of the material draw.
    pub seed: u64,
    /// Material choice.
    pub dither: Dither,
    /// Global layers to write (`None`: all).
    pub layers: Option<Range<usize>>,
    /// Write only this shard's layers.
    pub shard: Option<Shard>,
    /// Worker threads (`None`: all cores).
    pub threads: Option<usize>,
}

impl VatParams {
    /// The PNG stack's parameters for the same grid, draw and layers.
    pub(crate) fn stack(&self) -> PngParams {
        PngParams {
            voxel: self.printer.voxel(),
            seed: self.seed,
            dither: self.dither,
            layers: self.layers.clone(),
            shard: self.shard,
            per_material_bitmaps: false,
            threads: self.threads,
            liquid_keep_out: None,
            full_color: false,
            color_profile: None,
            bitmap_format: Default::default(),
            bitmap_width: None,
        }
    }
}

/// The resolved gray source.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Gray {
    /// 255 inside.
    Solid,
    /// Attribute `index` over `lo..hi`.
    Attribute { index: usize, lo: f64, hi: f64 },
    /// The fraction of material slot `slot`.
    Fraction { slot: usize },
}

/// What a vat stack will take, known before it starts.
#[derive(Clone, Debug, PartialEq)]
pub struct VatEstimate {
    /// The stack's estimate (grid, layers, slab, its memory).
    pub stack: png_stack::Estimate,
    /// Vat (0-based) of each material slot.
    pub vat_of: Vec<u8>,
    /// Number of vats.
    pub vats: usize,
    /// The part's grid's first column and row on the screen.
    pub place: [usize; 2],
    /// Gray source.
    pub(crate) gray: Gray,
    /// Working memory (bytes), slab and screen images.
    pub memory_bytes: u64,
    /// Rough size of the output (bytes).
    pub disk_bytes: u64,
    /// Files that will be written.
    pub files: u64,
}

/// Check everything and size the stack: the vats and their materials,
/// the intensity source, the part against the build area and height, the
/// layer range and memory; every error names its option.
pub fn estimate(model: &Model, p: &VatParams) -> Result<VatEstimate, ExportError> {
    let vat_of = vat_of(model, &p.vats)?;
    let vats = p.vats.len().max(1);
    let gray = resolve_gray(model, &p.intensity)?;
    let grid = crate::design::grid_for(model, p.printer.voxel(), 0.0)?;
    let place = place(&grid, &p.printer, p.offset)?;
    let stack = png_stack::estimate(model, &p.stack())?;
    let [w, h] = p.printer.screen;
    let screen = (w * h) as u64;
    let workers = p
        .threads
        .unwrap_or_else(rayon::current_num_threads)
        .max(1)
        .min(stack.slab_layers) as u64;
    // Per worker: each vat's screen image and its encoded bytes (≤ the
    // image), plus the part's gray values.
    let image_bytes = workers * (vats as u64 * screen * 2 + stack.grid.dims[0] as u64 * 9);
    let memory_bytes = stack.memory_bytes + image_bytes;
    check_memory(
        memory_bytes,
        &format!("{vats} screen image(s) of {w} × {h} px per worker"),
    )?;
    let layers = stack.layers.len() as u64;
    let files = layers * vats as u64;
    // BMP: the raw screen plus header and palette. PNG: the black screen
    // deflates to about a byte per 250 pixels (fdeflate's fastest level,
    // "Up" filter: a few bytes per all-black row); the part's pixels to
    // about half a byte (a solid part) to one byte (graded grays, mixed
    // vats).
    let part = stack.voxels as f64;
    let disk_bytes = if p.bmp {
        files * (screen + 1078)
    } else {
        (part * if gray == Gray::Solid { 0.5 } else { 1.0 }) as u64 + files * (screen / 250 + 200)
    };
    Ok(VatEstimate {
        stack,
        vat_of,
        vats,
        place,
        gray,
        memory_bytes,
        disk_bytes,
        files,
    })
}

/// Write the stack into `ctx.staging()`.
pub fn export_vat(model: &Model, p: &VatParams, ctx: &JobContext) -> Result<Summary, ExportError> {
    let est = estimate(model, p)?;
    check_disk(est.disk_bytes, ctx.folder(), "a smaller --layers range")?;
    run_with_threads(p.threads, || write::write_stack(model, p, &est, ctx))
}

/// Vat (0-based) of each material slot of `model` from `vats` (the
/// materials of each vat); every material must be in exactly one.
fn vat_of(model: &Model, vats: &[Vec<String>]) -> Result<Vec<u8>, ExportError> {
    let table = model.table();
    let names: Vec<&str> = model.materials().iter().map(|id| table.name(*id)).collect();
    if vats.is_empty() {
        return Ok(vec![0; names.len()]);
    }
    if ![1, 2, 4].contains(&vats.len()) {
        return Err(ExportError::param(
            "--vats",
            format!("{} vats: vat printers have 1, 2 or 4", vats.len()),
        ));
    }
    let mut out: Vec<Option<u8>> = vec![None; names.len()];
    for (v, mats) in vats.iter().enumerate() {
        for m in mats {
            let Some(slot) = names.iter().position(|n| n == m) else {
                return Err(ExportError::param(
                    "--vat-materials",
                    format!(
                        "the design has no material {m:?}; it uses {}",
                        names.join(", ")
                    ),
                ));
            };
            if out[slot].is_some() {
                return Err(ExportError::param(
                    "--vat-materials",
                    format!("{m} is named for two vats; each material goes to one vat"),
                ));
            }
            out[slot] = u8::try_from(v).ok();
        }
    }
    let missing: Vec<&str> = names
        .iter()
        .zip(&out)
        .filter(|(_, v)| v.is_none())
        .map(|(n, _)| *n)
        .collect();
    if !missing.is_empty() {
        return Err(ExportError::param(
            "--vat-materials",
            format!(
                "{} in no vat; list every material of the design (it uses {}), e.g. --vat-materials {}",
                missing.join(", "),
                names.join(", "),
                names.join(",")
            ),
        ));
    }
    Ok(out.into_iter().map(|v| v.unwrap_or(0)).collect())
}

/// The intensity source checked against the design.
fn resolve_gray(model: &Model, i: &Intensity) -> Result<Gray, ExportError> {
    match i {
        Intensity::Solid => Ok(Gray::Solid),
        Intensity::Fraction(name) => {
            let table = model.table();
            let names: Vec<&str> = model.materials().iter().map(|id| table.name(*id)).collect();
            names
                .iter()
                .position(|n| n == name)
                .map(|slot| Gray::Fraction { slot })
                .ok_or_else(|| {
                    ExportError::param(
                        "--intensity",
                        format!(
                            "fraction:{name}: the design has no material {name:?}; it uses {}",
                            names.join(", ")
                        ),
                    )
                })
        }
        Intensity::Attribute { name, range } => {
            let index = model
                .require_attribute(name)
                .map_err(|e| ExportError::param("--intensity", e.to_string()))?;
            if model.attributes()[index].kind != AttributeKind::Scalar {
                return Err(ExportError::param(
                    "--intensity",
                    format!(
                        "attribute {name:?} is not a scalar; give a scalar attribute or fraction:MATERIAL"
                    ),
                ));
            }
            let (lo, hi) = match range {
                Some(r) => *r,
                None => {
                    let b = model
                        .attribute_interval(index, &model.bbox())
                        .filter(|b| b.lo.is_finite() && b.hi.is_finite() && b.lo < b.hi)
                        .ok_or_else(|| {
                            ExportError::param(
                                "--range",
                                format!("the design gives no finite, non-empty bound of {name:?}; give --range LO,HI"),
                            )
                        })?;
                    (b.lo, b.hi)
                }
            };
            if !(lo.is_finite() && hi.is_finite() && lo < hi) {
                return Err(ExportError::param(
                    "--range",
                    format!("{lo},{hi}: give LO,HI with LO < HI, both finite"),
                ));
            }
            Ok(Gray::Attribute { index, lo, hi })
        }
    }
}

/// The part grid's first screen column and row: centred, moved by
/// `offset` mm (+X right, +Y up); refused when the part, or the part
/// moved, does not fit the build area or height (both sizes named).
fn place(grid: &Grid, printer: &VatPrinter, offset: [f64; 2]) -> Result<[usize; 2], ExportError> {
    let [nx, ny, nz] = grid.dims;
    let [w, h] = printer.screen;
    let [aw, ah] = printer.area();
    let v = grid.voxel;
    let size = DVec3::new(nx as f64, ny as f64, nz as f64) * v;
    let who = if printer.name == "custom" {
        "the screen".to_owned()
    } else {
        format!("the {} build area", printer.name)
    };
    if nx > w || ny > h {
        return Err(ExportError::param(
            "design",
            format!(
                "the part needs {nx} × {ny} px ({:.2} × {:.2} mm); {who} is {w} × {h} px ({aw:.2} × {ah:.2} mm): scale the part down or pick a larger printer",
                size.x, size.y
            ),
        ));
    }
    if let Some(height) = printer.height
        && size.z > height + 1e-9
    {
        return Err(ExportError::param(
            "design",
            format!(
                "the part is {:.2} mm high ({nz} layers); the {} builds at most {height:.2} mm",
                size.z, printer.name
            ),
        ));
    }
    if !(offset[0].is_finite() && offset[1].is_finite()) {
        return Err(ExportError::param(
            "--offset",
            "give X,Y in mm, e.g. --offset 10,-5",
        ));
    }
    // Column and row of the part's first column and top row: centred, then
    // the offset in whole pixels (rows grow downwards, +Y up).
    let col = (w - nx) as f64 / 2.0 + offset[0] / v.x;
    let row = (h - ny) as f64 / 2.0 - offset[1] / v.y;
    let (col, row) = (col.floor(), row.floor());
    if col < 0.0 || row < 0.0 || col + nx as f64 > w as f64 || row + ny as f64 > h as f64 {
        return Err(ExportError::param(
            "--offset",
            format!(
                "{},{} mm moves the part ({:.2} × {:.2} mm) off {who} ({aw:.2} × {ah:.2} mm); the centre may move at most {:.2} mm in X and {:.2} mm in Y",
                offset[0],
                offset[1],
                size.x,
                size.y,
                (w - nx) as f64 / 2.0 * v.x,
                (h - ny) as f64 / 2.0 * v.y
            ),
        ));
    }
    Ok([col as usize, row as usize])
}
