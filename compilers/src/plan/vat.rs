//! The vat stack's plan: its estimate line and the size that must resolve
//! thin features (the printer's pixel or layer, set by `--preset`).

use volcad_core::Model;

use super::{Assessment, Opt};
use crate::job::{ExportError, JobContext, Summary};
use crate::resources::human_bytes;
use crate::vat::{self, VatParams};

pub(super) fn estimate(model: &Model, p: &VatParams) -> Result<Assessment, ExportError> {
    let est = vat::estimate(model, p)?;
    let [nx, ny, nz] = est.stack.grid.dims;
    let [w, h] = p.printer.screen;
    let layers = &est.stack.layers;
    Ok(Assessment {
        text: format!(
            "part {nx} × {ny} px of a {w} × {h} px screen, layers {} to {} included ({} of {nz}), {} vat(s), {} files, about {} on disk, {} memory",
            layers.start,
            layers.end.saturating_sub(1),
            layers.len(),
            est.vats,
            est.files,
            human_bytes(est.disk_bytes),
            human_bytes(est.memory_bytes)
        ),
        disk_bytes: Some(est.disk_bytes),
        verdicts: Vec::new(),
    })
}

/// The voxel's largest side (pixel pitch or layer) decides what it
/// resolves; the printer sets it.
pub(super) fn cell(p: &VatParams) -> (f64, Opt) {
    (p.printer.voxel().max_element(), Opt::Preset)
}

pub(super) fn run(model: &Model, p: &VatParams, ctx: &JobContext) -> Result<Summary, ExportError> {
    vat::export_vat(model, p, ctx)
}
