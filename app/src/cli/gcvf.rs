//! `volcad export gcvf DESIGN --out part.gcvf`: a GrabCAD Voxel Print
//! package for PolyJet printers, and the J750 material table that
//! `--preset j750` brings to PNG stacks (`--map red=VeroMgnt`). The checks
//! and the job are the export plan's (`plan::ExportParams::Gcvf`).

use std::path::{Path, PathBuf};
use std::sync::Arc;

use anyhow::{Context, bail};
use glam::DVec3;
use volcad_compilers::gcvf::GcvfParams;
use volcad_compilers::png_stack;
use volcad_compilers::printer_table::{is_j750_preset, j750_model, parse_map};
use volcad_core::Model;

use super::export::{ExportArgs, parse_dither};
use super::output::{Target, target};

/// The design as a PNG stack writes it: with `--preset j750`, relabelled
/// with J750 resins (refused when a material is not one and `--map` does
/// not make it one); otherwise unchanged.
pub(super) fn printer_model(a: &ExportArgs, model: Arc<Model>) -> anyhow::Result<Arc<Model>> {
    if !a.preset.as_deref().is_some_and(is_j750_preset) {
        if let Some(m) = &a.map {
            bail!(
                "--map {m}: maps onto a printer's resins, so it needs --preset j750 (or `volcad export gcvf`)"
            );
        }
        return Ok(model);
    }
    let map = parse_map(a.map.as_deref().unwrap_or(""))?;
    Ok(j750_model(&model, &map)?)
}

/// The package's path: `--out` as a file (a symlink to one resolved);
/// folders and special files are refused.
pub(super) fn package_path(out: &Path) -> anyhow::Result<PathBuf> {
    match target(out, "--out")? {
        Target::Staged(p) => Ok(p),
        _ => bail!(
            "--out {}: a .gcvf is a zip archive written beside its destination and renamed; give a file name",
            out.display()
        ),
    }
}

/// The package's parameters from the options (`voxel` as parsed; the J750
/// grid when none was given), written to `dest`.
pub(super) fn gcvf_params(
    a: &ExportArgs,
    voxel: Option<DVec3>,
    dest: &Path,
) -> anyhow::Result<GcvfParams> {
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
    Ok(GcvfParams {
        voxel,
        seed: a.seed,
        dither: parse_dither(a.dither.as_deref())?,
        map: parse_map(a.map.as_deref().unwrap_or(""))?,
        threads: a.threads,
        file_name,
        liquid_keep_out: a.liquid_keep_out,
    })
}
