//! GrabCAD Voxel Print packages (`.gcvf`) for Stratasys PolyJet printers:
//! the zip pyvcad 2.3.4's `GCVFExporter` writes, streamed one slab of
//! layers at a time as the PNG stack is. Memory: the stack's slab plus one
//! 16-bit height per column, less than the PNG stack itself holds, since a
//! layer's PNG is encoded a row at a time ([`crate::row_png`]) where the
//! stack holds the layer's whole RGBA image (4 bytes a voxel, twice the
//! z-buffer's 2).
//!
//! # Entries
//!
//! * `gcvf_export_<k>.png`: layer k (0 = lowest Z, no zero padding), 8-bit
//!   RGBA, each voxel its resin's colour, void `(0, 0, 0, 0)`; stored, not
//!   deflated (PNG data is compressed already).
//! * `Zbuffer.png`: 16-bit grayscale, per column the index of its highest
//!   solid layer (0 where the column is empty), as pyvcad writes it.
//! * `Mesh.stl`: binary STL of the part's surface (mm), moved so the voxel
//!   block spans x ∈ [0, W], y ∈ [−H, 0], z ∈ [0, N] voxel sizes.
//! * `MeshBbx.ktn`: six little-endian `f32`: `0 0 0 W H N` (voxels).
//! * `ConfigFile.xml`: pyvcad's fields, comments and order (version,
//!   resolution, slice size and range, bit depth, resin count, semantics,
//!   creation mode, prefix, background and one entry per resin with its
//!   name, RGBA and voxel count); written last, once the counts are known.
//!
//! # Orientation
//!
//! As pyvcad's images: column 0 = max X, row 0 = min Y (our PNG stack's
//! top view turned 180°), while the mesh keeps +X and +Y. The slices and
//! `Mesh.stl` must agree with each other in GrabCAD, and pyvcad's pair is
//! the one PolyJet users have printed from; turning only our images would
//! turn the voxels against the mesh.
//!
//! # Differences from pyvcad 2.3.4
//!
//! The `<Resolution>` block holds the grid's true values (dpi = 25.4 / voxel,
//! rounded; layer thickness in nm), where pyvcad always writes 600, 300 and
//! 27000; samples sit at voxel centres; the draw is seeded; the mesh is
//! contoured at a capped resolution (at most [`MESH_CELLS`] cells) rather
//! than at the voxel size, so the seat at J750 resolution needs no
//! billion-triangle preview; its y range is [−H, 0] for every design
//! (pyvcad's is shifted by the box's centre when that is not at y = 0).

use std::io::{BufWriter, Write};

use glam::DVec3;
use rayon::prelude::*;
use serde_json::json;
use volcad_core::sampler::{Consumer, Sampler, Slab};
use volcad_core::{MaterialTable, Model};

use crate::design::grid_for;
use crate::estimate::Look;
use crate::job::{ExportError, JobContext, Summary};
use crate::mesh::field::marching_cubes;
use crate::mesh::stl::write_stl;
use crate::png_io::PixelsPerMetre;
use crate::png_stack::{self, Dither, Estimate, PngParams};
use crate::printer_table::{PrinterMaterial, palette_of, resolve};
use crate::resources::{check_disk, run_with_threads};
use crate::row_png::rgba_png;
use crate::slice_image::{ImageStyle, Orientation};

/// The slice images' name prefix (pyvcad's).
pub const PREFIX: &str = "gcvf_export_";
/// Most resins a J750 tray holds at once (pyvcad's `MaxNumberOfColors`).
pub const MAX_RESINS: usize = 6;
/// Most cells of the preview mesh's grid.
pub const MESH_CELLS: f64 = 2_097_152.0;

/// Parameters of a GCVF package.
#[derive(Clone, Debug, PartialEq)]
pub struct GcvfParams {
    /// Voxel size (mm); the J750 is 600 × 300 dpi, 27 µm (or 14 µm).
    pub voxel: DVec3,
    /// Seed of the material draw.
    pub seed: u64,
    /// Material choice.
    pub dither: Dither,
    /// Design material → J750 resin, for names the table lacks.
    pub map: Vec<(String, String)>,
    /// Worker threads (`None`: all cores).
    pub threads: Option<usize>,
    /// The archive's file name inside the job's folder.
    pub file_name: String,
    /// Remove the liquid (`M.Cleanser`) within this distance (mm) of the
    /// surface (see [`crate::keep_out`]).
    pub liquid_keep_out: Option<f64>,
}

impl GcvfParams {
    fn stack(&self) -> PngParams {
        PngParams {
            voxel: self.voxel,
            seed: self.seed,
            dither: self.dither,
            layers: None,
            shard: None,
            per_material_bitmaps: false,
            threads: self.threads,
            liquid_keep_out: self.liquid_keep_out,
            ..PngParams::default()
        }
    }
}

/// The package's grid and size, and its resins; refuses what GrabCAD
/// cannot take: a part larger than the tray, a material the J750 table
/// lacks (unless mapped), more
/// than [`MAX_RESINS`] resins, more layers than a 16-bit z-buffer holds.
pub fn estimate(
    model: &Model,
    p: &GcvfParams,
) -> Result<(Estimate, Vec<PrinterMaterial>), ExportError> {
    estimate_with(model, p, Look::Layers)
}

/// [`estimate`] with the stack's estimate looking as `look` says (layers
/// sampled for front ends, the coarse look in the job).
fn estimate_with(
    model: &Model,
    p: &GcvfParams,
    look: Look,
) -> Result<(Estimate, Vec<PrinterMaterial>), ExportError> {
    crate::printer_table::check_j750_tray(model)?;
    let mats = resolve(model, &MaterialTable::j750(), &p.map, "J750")?;
    if mats.len() > MAX_RESINS {
        let names: Vec<&str> = mats.iter().map(|m| m.name.as_str()).collect();
        return Err(ExportError::param(
            "materials",
            format!(
                "{} resins ({}); a J750 holds at most {MAX_RESINS}: map some onto others with --map",
                mats.len(),
                names.join(", ")
            ),
        ));
    }
    let est = png_stack::estimate_with(model, &p.stack(), look)?;
    let nz = est.grid.dims[2];
    if nz > usize::from(u16::MAX) + 1 {
        return Err(ExportError::param(
            "--voxel",
            format!("{nz} layers; the z-buffer holds at most 65536: use a thicker layer"),
        ));
    }
    Ok((est, mats))
}

/// Write the package into `ctx.staging()` as `p.file_name`.
pub fn export_gcvf(
    model: &Model,
    p: &GcvfParams,
    ctx: &JobContext,
) -> Result<Summary, ExportError> {
    // The front end showed the sampled estimate; the job checks by the
    // coarse one, as the PNG stack's does (no layers sampled twice).
    let (est, mats) = estimate_with(model, p, Look::Coarse)?;
    check_disk(est.disk_bytes, ctx.folder(), "a larger voxel size")?;
    run_with_threads(p.threads, || write_package(model, p, &est, &mats, ctx))
}

fn write_package(
    model: &Model,
    p: &GcvfParams,
    est: &Estimate,
    mats: &[PrinterMaterial],
    ctx: &JobContext,
) -> Result<Summary, ExportError> {
    let path = ctx.staging().join(&p.file_name);
    let io = |e: std::io::Error| ExportError::io(&path, e);
    let file = std::fs::File::create(&path).map_err(io)?;
    let mut zip = crate::zip_writer::ZipOut::new(BufWriter::new(file));
    let [nx, ny, nz] = est.grid.dims;
    let layer = nx * ny;
    let pal = palette_of(mats);
    let style = ImageStyle {
        orientation: Orientation::Pyvcad,
        pixel: Some(PixelsPerMetre::from_mm(est.grid.voxel.x, est.grid.voxel.y)),
    };
    let mut counts = vec![0u64; mats.len()];
    // The z-buffer, kept as `Zbuffer.png`'s pixels (big-endian, pyvcad's
    // orientation: image row j is voxel row j, column nx - 1 - i is voxel
    // column i), so it is encoded without a second copy.
    let mut top = vec![0u8; layer * 2];
    let batch = rayon::current_num_threads().max(1);
    png_stack::for_each_slab(model, &p.stack(), est, ctx, |zs, codes| {
        // Layers come in rising order, so the last solid one wins.
        top.par_chunks_mut(nx * 2).enumerate().for_each(|(j, t)| {
            for l in 0..zs.len() {
                let row = &codes[l * layer + j * nx..l * layer + (j + 1) * nx];
                let z = ((zs.start + l) as u16).to_be_bytes();
                for (t, c) in t.chunks_exact_mut(2).rev().zip(row) {
                    if *c != 0 {
                        t.copy_from_slice(&z);
                    }
                }
            }
        });
        // Encode `batch` layers at once, then store them in order: one
        // layer's PNG per worker in memory, as the PNG stack holds.
        for group in zs.clone().collect::<Vec<_>>().chunks(batch) {
            let pngs: Vec<(Vec<u8>, Vec<u64>)> = group
                .par_iter()
                .map(|z| {
                    let c = &codes[(z - zs.start) * layer..(z - zs.start + 1) * layer];
                    let png = rgba_png(nx, ny, c, &pal, style).map_err(|e| {
                        ExportError::Other(format!("{}: PNG encoding: {e}", path.display()))
                    })?;
                    let mut n = vec![0u64; pal.len() - 1];
                    for c in c.iter().filter(|c| **c > 0) {
                        n[*c as usize - 1] += 1;
                    }
                    Ok((png, n))
                })
                .collect::<Result<_, ExportError>>()?;
            for (z, (png, n)) in group.iter().zip(pngs) {
                zip.stored(&format!("{PREFIX}{z}.png"), &png).map_err(io)?;
                for (t, c) in counts.iter_mut().zip(n) {
                    *t += c;
                }
                ctx.progress(
                    "slicing",
                    *z as u64 + 1,
                    nz as u64,
                    "layers",
                    (*z + 1) as f64 / nz as f64 * 0.95,
                );
            }
        }
        Ok(())
    })?;
    ctx.check_cancel()?;
    let zbuf = crate::png_io::encode_gray16_be(nx, ny, &top)
        .map_err(|e| ExportError::Other(format!("Zbuffer.png: {e}")))?;
    drop(top);
    zip.stored("Zbuffer.png", &zbuf).map_err(io)?;
    drop(zbuf);
    ctx.progress("mesh", 0, 1, "meshes", 0.96);
    let mesh = preview_mesh(model, est, ctx)?;
    zip.entry("Mesh.stl", false, |w| {
        write_stl(&mesh, "GCVF part surface", w)
    })
    .map_err(io)?;
    let bbx: Vec<u8> = [0.0, 0.0, 0.0, nx as f32, ny as f32, nz as f32]
        .iter()
        .flat_map(|v: &f32| v.to_le_bytes())
        .collect();
    zip.entry("MeshBbx.ktn", false, |w| w.write_all(&bbx))
        .map_err(io)?;
    let xml = config_xml(est, mats, &counts);
    zip.entry("ConfigFile.xml", false, |w| w.write_all(xml.as_bytes()))
        .map_err(io)?;
    let w = zip.finish().map_err(io)?;
    w.into_inner()
        .map_err(|e| io(e.into_error()))?
        .sync_all()
        .map_err(io)?;
    Ok(summary(p, est, mats, counts))
}

/// The part's surface on a grid of at most [`MESH_CELLS`] cubic cells (the
/// voxel's largest side, or coarser), moved into the package's frame.
fn preview_mesh(
    model: &Model,
    est: &Estimate,
    ctx: &JobContext,
) -> Result<crate::mesh::indexed::IndexedMesh, ExportError> {
    let g = est.grid;
    let span = g.voxel * DVec3::new(g.dims[0] as f64, g.dims[1] as f64, g.dims[2] as f64);
    let cell = g
        .voxel
        .max_element()
        .max((span.x * span.y * span.z / MESH_CELLS).cbrt());
    let grid = grid_for(model, DVec3::splat(cell), cell)?;
    let mut slab = Slab::default();
    Sampler::new(model, grid, Consumer::SurfaceContour)
        .sample_layers(0, grid.dims[2], &mut slab, ctx.cancel_flag())
        .map_err(|_| ExportError::Cancelled)?;
    let mut mesh = marching_cubes(&grid, &slab.dist);
    let shift = DVec3::new(g.origin.x, g.origin.y + span.y, g.origin.z);
    for v in &mut mesh.vertices {
        for (a, s) in v.iter_mut().zip(shift.to_array()) {
            *a = (f64::from(*a) - s) as f32;
        }
    }
    Ok(mesh)
}

/// `ConfigFile.xml` as pyvcad 2.3.4 lays it out, with the grid's true
/// resolution.
fn config_xml(est: &Estimate, mats: &[PrinterMaterial], counts: &[u64]) -> String {
    let [nx, ny, nz] = est.grid.dims;
    let v = est.grid.voxel;
    let dpi = |mm: f64| (25.4 / mm).round() as u64;
    let nm = (v.z * 1e6).round() as u64;
    let mut s = format!(
        r#"<?xml version="1.0" encoding="UTF-8"?>
<!--  GCVF - GrabCad Voxel Print File  -  -->
<GCVF>
    <!--  Version numbers are updated periodically  -->
    <Version>2</Version>
    <Resolution>
        <!--  Note that the X/Y are in dots per inch, Z is in nano-meters. All are integers.  -->
        <XDpi>{}</XDpi>
        <YDpi>{}</YDpi>
        <SliceThicknessNanoMeter>{nm}</SliceThicknessNanoMeter>
    </Resolution>
    <SliceDimensions>
        <!--  The dimensions (width/height in pixels) of each of the images  -->
        <SliceWidth>{nx}</SliceWidth>
        <SliceHeight>{ny}</SliceHeight>
    </SliceDimensions>
    <SliceRange>
        <!--  indices of first slice and number of slices.
    It is assumed all intermediate images are present.  -->
        <StartIndex>0</StartIndex>
        <NumberOfSlices>{nz}</NumberOfSlices>
    </SliceRange>
    <!--  number of bytes per pixel  -->
    <BitDepth>4</BitDepth>
    <!--  maximal number of resins to expect  -->
    <MaxNumberOfColors>{MAX_RESINS}</MaxNumberOfColors>
    <!--  Current only 'Materials' is supported  -->
    <DataSemantics>Materials</DataSemantics>
    <!--  may be 'MODEL_ONLY' or 'WITH_SUPPORT_ETC'  -->
    <CreationMode>MODEL_ONLY</CreationMode>
    <!-- When defined by user, prefix must include full path.
       In the archived cgvf file no full path is used.  -->
    <ImageFilePrefix>{PREFIX}</ImageFilePrefix>
    <MaterialList>
        <!-- air color in Red/Green/Blue/Alpha order -->
        <BackGroundMaterialRGBA>0 0 0 0</BackGroundMaterialRGBA>
        <!-- Each resin is coded as name, color in Red/Green/Blue/Alpha order, and voxel count. -->
"#,
        dpi(v.x),
        dpi(v.y)
    );
    for (m, c) in mats.iter().zip(counts) {
        let [r, g, b, a] = m.rgba;
        s.push_str(&format!(
            "        <Material>\n            <Name>{}</Name>\n            <RGBA>{r} {g} {b} {a}</RGBA>\n            <VoxelCount>{c}</VoxelCount>\n        </Material>\n",
            xml_escape(&m.name)
        ));
    }
    s.push_str("    </MaterialList>\n</GCVF>\n");
    s
}

fn xml_escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

fn summary(p: &GcvfParams, est: &Estimate, mats: &[PrinterMaterial], counts: Vec<u64>) -> Summary {
    let [nx, ny, nz] = est.grid.dims;
    let v = est.grid.voxel;
    let mut notes = vec![
        format!("{nz} layer(s) of {nx} × {ny} px, 600 × 300 dpi is the J750's grid"),
        "orientation: column 0 = max X, row 0 = min Y (pyvcad's), layer 0 = lowest Z".to_owned(),
    ];
    let j750 = png_stack::preset("j750").map(|q| q.voxel);
    if j750.is_some_and(|j| (j.x - v.x).abs() > 1e-9 || (j.y - v.y).abs() > 1e-9) {
        notes.push(format!(
            "warning: voxel {:.4} × {:.4} mm is not the J750's 600 × 300 dpi; GrabCAD prints each pixel at the printer's size (use --preset j750)",
            v.x, v.y
        ));
    }
    for (m, c) in mats.iter().zip(&counts) {
        if m.name != m.design_name {
            notes.push(format!("{} printed as {}", m.design_name, m.name));
        }
        notes.push(format!(
            "{}: {c} voxels = {:.3} mm³",
            m.name,
            *c as f64 * v.x * v.y * v.z
        ));
    }
    Summary {
        kind: "gcvf".into(),
        files: vec![p.file_name.clone()],
        counts: mats.iter().map(|m| m.name.clone()).zip(counts).collect(),
        units: est.voxels,
        unit: "voxels".into(),
        parameters: json!({
            "voxel_mm": v.to_array(),
            "seed": p.seed,
            "dither": p.dither.name(),
            "map": p.map,
            "liquid_keep_out_mm": p.liquid_keep_out,
            "grid": { "dims": [nx, ny, nz], "origin_mm": est.grid.origin.to_array() },
            "orientation": "column 0 = max X, row 0 = min Y, layer 0 = lowest Z",
        }),
        notes,
        seconds: 0.0,
    }
}
