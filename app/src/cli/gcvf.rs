//! `volcad export gcvf DESIGN --out part.gcvf`: a GrabCAD Voxel Print
//! package for PolyJet printers, and the J750 material table that
//! `--preset j750` brings to PNG stacks (`--map red=VeroMgnt`).

use std::path::PathBuf;
use std::sync::Arc;

use anyhow::{Context, bail};
use glam::DVec3;
use volcad_compilers::gcvf::{self, GcvfParams};
use volcad_compilers::job::{self, JobHandle};
use volcad_compilers::png_stack;
use volcad_compilers::printer_table::{parse_map, relabel, resolve};
use volcad_compilers::resources::check_disk_for;
use volcad_core::{MaterialTable, Model};

use super::export::{ExportArgs, parse_dither, warn_thin};
use super::output::{Target, target};

/// True for the presets that are J750 grids.
fn is_j750(preset: Option<&str>) -> bool {
    preset.is_some_and(|p| p.eq_ignore_ascii_case("j750") || p.eq_ignore_ascii_case("j750-hq"))
}

/// The design as a PNG stack writes it: with `--preset j750`, relabelled
/// with J750 resins (refused when a material is not one and `--map` does
/// not make it one); otherwise unchanged.
pub(super) fn printer_model(a: &ExportArgs, model: Arc<Model>) -> anyhow::Result<Arc<Model>> {
    if !is_j750(a.preset.as_deref()) {
        if let Some(m) = &a.map {
            bail!(
                "--map {m}: maps onto a printer's resins, so it needs --preset j750 (or `volcad export gcvf`)"
            );
        }
        return Ok(model);
    }
    let map = parse_map(a.map.as_deref().unwrap_or(""))?;
    let table = MaterialTable::j750();
    let mats = resolve(&model, &table, &map, "J750")?;
    Ok(Arc::new(relabel(&model, &mats, &table, "J750")))
}

/// Check everything and start the package's job (see [`gcvf`]).
pub(super) fn start(
    a: &ExportArgs,
    model: Arc<Model>,
    voxel: Option<DVec3>,
    hash: String,
    dest: PathBuf,
) -> anyhow::Result<JobHandle> {
    let dest = match target(&dest, "--out")? {
        Target::Staged(p) => p,
        _ => bail!(
            "--out {}: a .gcvf is a zip archive written beside its destination and renamed; give a file name",
            dest.display()
        ),
    };
    // As for export folders: a finished package is replaced only with
    // --force (the job itself refuses anything that is not a regular file).
    if !a.force
        && let Ok(m) = std::fs::metadata(&dest)
        && m.is_file()
    {
        bail!(
            "--out {}: a file of {:.1} MB is already there; add --force to replace it, or give another name",
            dest.display(),
            m.len() as f64 / 1e6
        );
    }
    let file_name = dest
        .file_name()
        .map(|n| n.to_string_lossy().to_string())
        .context("--out: give a file name, e.g. part.gcvf")?;
    let voxel = match voxel {
        Some(v) => v,
        None => png_stack::preset("j750")
            .map(|p| p.voxel)
            .context("the j750 preset")?,
    };
    let p = GcvfParams {
        voxel,
        seed: a.seed,
        dither: parse_dither(a.dither.as_deref())?,
        map: parse_map(a.map.as_deref().unwrap_or(""))?,
        threads: a.threads,
        file_name,
        liquid_keep_out: a.liquid_keep_out,
    };
    let (est, _) = gcvf::estimate(&model, &p)?;
    let [nx, ny, nz] = est.grid.dims;
    note!(
        "grid {nx} x {ny} x {nz} ({} voxels); about {:.1} MB, {:.1} MB working memory",
        est.voxels,
        est.disk_bytes as f64 / 1e6,
        est.memory_bytes as f64 / 1e6
    );
    check_disk_for(est.disk_bytes, &dest, "a larger voxel size")?;
    warn_thin(&model, voxel.max_element(), "--voxel");
    Ok(job::spawn_file(dest, hash, move |ctx| {
        gcvf::export_gcvf(&model, &p, ctx)
    }))
}
