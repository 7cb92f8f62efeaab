//! A slice stack's summary: its manifest's counts, parameters and notes,
//! and the notes of a stack merged from shards (see [`crate::shard`]).

use std::ops::Range;

use glam::DVec3;
use serde_json::json;
use volcad_core::Model;
use volcad_core::sampler::Grid;

use crate::color::{self, ColorPlan};
use crate::job::Summary;
use crate::png_stack::{Estimate, PngParams};
use crate::shard::Part;

/// The summary of a finished stack: `counts` per ink (material or resin).
pub(crate) fn summary(
    model: &Model,
    p: &PngParams,
    est: &Estimate,
    files: Vec<String>,
    counts: Vec<(String, u64)>,
    plan: Option<&ColorPlan>,
) -> Summary {
    let [nx, ny, nz] = est.grid.dims;
    // What the design and grid alone decide (the same in every shard):
    // the slices' span against the part's, then thin features.
    let mut design_notes = vec![grid_span_note(&est.grid, &model.bbox())];
    design_notes.extend(crate::thin::thin_feature_notes(
        model,
        est.grid.voxel.max_element(),
        "--voxel",
    ));
    let g = est.grid;
    let notes = stack_notes(g.dims, g.voxel, &est.layers, &counts, design_notes);
    let o = est.grid.origin;
    let mut parameters = json!({
        "voxel_mm": est.grid.voxel.to_array(),
        "seed": p.seed,
        "dither": p.dither.name(),
        "layers": [est.layers.start, est.layers.end],
        "grid": { "dims": [nx, ny, nz], "origin_mm": o.to_array() },
        "per_material_bitmaps": p.per_material_bitmaps,
        "liquid_keep_out_mm": p.liquid_keep_out,
        "orientation": "column 0 = min X, row 0 = max Y, layer 0 = lowest Z",
    });
    if let Some(s) = p.shard {
        parameters["shard"] = s.to_json();
    }
    if let Some(plan) = plan {
        parameters["full_color"] = json!({ "space": "OKLab", "resins": color::resins_json(plan) });
    }
    if p.per_material_bitmaps {
        parameters["bitmap_format"] = json!(p.bitmap_format.name());
        parameters["bitmap_width"] = json!(p.bitmap_width);
    }
    Summary {
        kind: "png".into(),
        files,
        counts,
        units: est.voxels,
        unit: "voxels".into(),
        parameters,
        notes,
        seconds: 0.0,
    }
}

/// The notes of a stack's manifest: its layer range, orientation and
/// volume per material, then `design_notes` (what the design alone
/// decides: thin features), then a warning when every slice is blank.
/// [`crate::shard`] rebuilds the whole stack's notes from its shards'
/// with it, so a merged manifest reads as the single export's.
fn stack_notes(
    [nx, ny, nz]: [usize; 3],
    voxel: DVec3,
    layers: &Range<usize>,
    counts: &[(String, u64)],
    design_notes: Vec<String>,
) -> Vec<String> {
    let voxel_mm3 = voxel.x * voxel.y * voxel.z;
    let mut notes = vec![
        format!(
            "{} layer(s) {}..{} of {nz}, {nx} × {ny} px each",
            layers.len(),
            layers.start,
            layers.end
        ),
        "orientation: column 0 = min X, row 0 = max Y (top view), layer 0 = lowest Z".to_owned(),
        // No working-memory figure: it grows with the thread count, and
        // the notes go into the manifest, which must not (the command line
        // prints the estimate before it starts).
    ];
    for (name, c) in counts {
        notes.push(format!(
            "{name}: {c} voxels = {:.3} mm³",
            *c as f64 * voxel_mm3
        ));
    }
    notes.extend(design_notes);
    if counts.iter().all(|(_, c)| *c == 0) {
        notes.push(
            "warning: no voxel centre is inside the design, so every slice is blank (the part is empty, or thinner than a voxel)"
                .to_owned(),
        );
    }
    notes
}

/// The notes of `layers` holding `counts`, with the design notes of `part`
/// (a shard of the same stack); `None` when `part`'s notes are not the ones
/// this version writes (then its design notes cannot be told apart).
pub(crate) fn merged_notes(
    part: &Part,
    layers: &Range<usize>,
    counts: &[(String, u64)],
) -> Option<Vec<String>> {
    let own = stack_notes(
        part.dims,
        part.voxel,
        &part.layers,
        &part.summary.counts,
        Vec::new(),
    );
    let notes = &part.summary.notes;
    let head = 2 + part.summary.counts.len();
    let tail = own.len().checked_sub(head)?;
    let design_end = notes.len().checked_sub(tail)?;
    if design_end < head || notes[..head] != own[..head] || notes[design_end..] != own[head..] {
        return None;
    }
    let design = notes[head..design_end].to_vec();
    Some(stack_notes(part.dims, part.voxel, layers, counts, design))
}

/// How the slices' extent relates to the part's: each count is
/// `ceil(extent / voxel)`, as pyvcad 2.3.4's (its J750 stack of a
/// 15 × 10 × 5 mm bar is 355 × 119 px and 186 layers), centred on the
/// part, so the stack is up to one voxel larger than the part per axis.
pub fn grid_span_note(grid: &Grid, part: &volcad_core::Aabb) -> String {
    let span = DVec3::new(
        grid.dims[0] as f64,
        grid.dims[1] as f64,
        grid.dims[2] as f64,
    ) * grid.voxel;
    let size = part.size();
    format!(
        "slices span {:.4} × {:.4} × {:.4} mm for a part of {:.4} × {:.4} × {:.4} mm: each count is ceil(extent / voxel), as in pyvcad, centred on the part (up to one voxel more per axis)",
        span.x, span.y, span.z, size.x, size.y, size.z
    )
}
