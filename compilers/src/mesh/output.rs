//! What a mesh export writes and reports: every segment's files (STL, OBJ,
//! one 3MF), the checks of every mesh (volume, watertightness, shape), and
//! the job's summary with its notes.

use std::fs::File;
use std::io::{BufWriter, Write};

use rayon::prelude::*;
use serde_json::json;
use volcad_core::Model;
use volcad_core::model::StatedGaps;

use super::{DEFAULT_INFILL, MeshParams, Plan, SegmentBy, SegmentMesh, bodies, obj, stl, threemf};
use crate::job::{ExportError, JobContext, Summary};
use crate::resources::human_bytes;

/// `fill_density` text: the percent rounded to 0.01, with `%`.
fn percent_text(v: f64) -> String {
    format!("{}%", (v * 100.0).round() / 100.0)
}

fn create(path: &std::path::Path) -> Result<BufWriter<File>, ExportError> {
    File::create(path)
        .map(|f| BufWriter::with_capacity(1 << 20, f))
        .map_err(|e| ExportError::io(path, e))
}

/// One output file.
#[derive(Clone, Copy)]
enum FileJob<'a> {
    Stl(&'a SegmentMesh),
    Obj(&'a SegmentMesh),
    ThreeMf,
}

/// Write every file, all in parallel (each file's bytes depend only on its
/// meshes); the list comes back in a fixed order.
pub(super) fn write_files(
    segs: &[SegmentMesh],
    p: &MeshParams,
    ctx: &JobContext,
) -> Result<Vec<String>, ExportError> {
    let present: Vec<&SegmentMesh> = segs.iter().filter(|s| !s.mesh.is_empty()).collect();
    if present.is_empty() {
        return Err(ExportError::Other("no segment has any voxel at this voxel size; the part is thinner than a voxel or empty".into()));
    }
    let mut jobs: Vec<FileJob> = Vec::new();
    if p.formats.threemf {
        jobs.push(FileJob::ThreeMf);
    }
    for s in &present {
        if p.formats.stl {
            jobs.push(FileJob::Stl(s));
        }
        if p.formats.obj {
            jobs.push(FileJob::Obj(s));
        }
    }
    jobs.par_iter()
        .map(|job| {
            ctx.check_cancel()?;
            let name = match job {
                FileJob::Stl(s) => format!("{}.stl", s.name),
                FileJob::Obj(s) => format!("{}.obj", s.name),
                FileJob::ThreeMf => "segments.3mf".to_owned(),
            };
            let path = ctx.staging().join(&name);
            let mut w = create(&path)?;
            let r = match job {
                FileJob::Stl(s) => stl::write_stl(&s.mesh, &s.name, &mut w),
                FileJob::Obj(s) => obj::write_obj(&s.mesh, &s.name, &mut w),
                FileJob::ThreeMf => {
                    let parts: Vec<threemf::Part> = present
                        .iter()
                        .map(|s| threemf::Part {
                            name: &s.name,
                            mesh: &s.mesh,
                            settings: vec![("fill_density", percent_text(s.infill_percent))],
                        })
                        .collect();
                    threemf::write_3mf(&parts, "part", &mut w)
                }
            };
            r.and_then(|_| w.flush())
                .map_err(|e| ExportError::io(&path, e))?;
            Ok(name)
        })
        .collect()
}

/// The body count, and a warning when the part fell into more bodies than
/// the design has parts (thin features broke apart), or into fewer (a gap
/// between parts closed), where the design states its parts
/// ([`volcad_core::Model::stated_gaps`]).
pub(super) fn body_notes(b: &bodies::Bodies, voxel: f64, design: &StatedGaps) -> Vec<String> {
    let total: f64 = b.volumes.iter().sum();
    let n = b.count;
    let mut out = vec![match design.parts {
        Some(parts) if parts > 1 => format!("bodies: {n} (the design has {parts} separate parts)"),
        _ => format!("bodies: {n}"),
    }];
    let parts = design.parts.unwrap_or(1);
    if n > parts {
        let design = if parts > 1 {
            format!("a design of {parts} parts")
        } else {
            "a design in one piece".into()
        };
        out.push(format!(
            "warning: the part is {n} separate bodies (the largest holds {:.1} % of the volume); {design} has features thinner than about two voxels of {voxel} mm that broke apart: use a smaller --voxel",
            100.0 * b.volumes[0] / total.max(f64::MIN_POSITIVE)
        ));
    } else if design.parts.is_some_and(|parts| n < parts) {
        let bodies = if n == 1 { "body" } else { "bodies" };
        out.push(match &design.narrowest {
            Some(g) => format!(
                "warning: {parts} parts of the design merged into {n} {bodies}: the gap between them, {} mm, is narrower than two voxels of {voxel} mm; --voxel {} keeps them apart",
                crate::thin::size_above(g.width),
                crate::thin::size_below(g.width / crate::thin::CELLS_ACROSS)
            ),
            None => format!(
                "warning: {parts} parts of the design merged into {n} {bodies}: a gap between them is too narrow for voxels of {voxel} mm: use a smaller --voxel"
            ),
        });
    }
    out
}

/// Volume, watertightness and shape (smallest angle, shortest edge) of
/// every segment. The contouring guarantees watertightness; checked anyway
/// (a linear pass over the edges), every segment on its own thread.
pub(super) fn checks(segs: &[SegmentMesh]) -> Vec<Check> {
    // Both at once, beside the writers and the body count, each split
    // over the cores (the volume in fixed chunks, so the same bits on any
    // thread count).
    segs.par_iter()
        .map(|s| {
            let (watertight, (volume, shape)) =
                rayon::join(|| s.mesh.is_watertight(), || s.mesh.volume_and_shape());
            Check {
                volume,
                watertight,
                shape,
            }
        })
        .collect()
}

/// What [`checks`] finds for one segment.
pub(super) struct Check {
    volume: f64,
    watertight: bool,
    /// Smallest triangle angle (degrees) and shortest edge (mm).
    shape: (f64, f64),
}

/// The job's summary: the grid, each segment's counts and checks, the
/// parameters as written in the manifest.
pub(super) fn summary(
    model: &Model,
    p: &MeshParams,
    pl: &Plan,
    segs: &[SegmentMesh],
    files: Vec<String>,
    checks: &[Check],
) -> Summary {
    let [nx, ny, nz] = pl.grid.dims;
    let mut notes = vec![format!(
        "grid {nx} × {ny} × {nz} (padded by one voxel), working memory about {}",
        human_bytes(pl.estimate.memory_bytes)
    )];
    if let SegmentBy::Material(id) = p.by
        && !model.materials().contains(&id)
    {
        notes.push(format!(
            "material {} is not in the design: its fraction is 0 everywhere",
            model.table().name(id)
        ));
    }
    let mut total_volume = 0.0;
    let (mut angle, mut edge) = (180.0f64, f64::INFINITY);
    for (s, c) in segs.iter().zip(checks) {
        let (v, watertight) = (c.volume, c.watertight);
        if s.mesh.is_empty() {
            notes.push(format!(
                "{}: empty (no voxel in this range), no file",
                s.name
            ));
            continue;
        }
        total_volume += v;
        angle = angle.min(c.shape.0);
        edge = edge.min(c.shape.1);
        let tight = if watertight {
            "watertight"
        } else {
            "NOT WATERTIGHT (please report)"
        };
        notes.push(format!(
            "{}: {} triangles, {} vertices, {v:.3} mm³, {tight}, fill_density {}",
            s.name,
            s.mesh.triangles.len(),
            s.mesh.vertices.len(),
            percent_text(s.infill_percent)
        ));
    }
    notes.push(format!("total volume {total_volume:.3} mm³"));
    if edge.is_finite() {
        notes.push(format!(
            "triangle shape: smallest angle {angle:.3}°, shortest edge {edge:.3e} mm"
        ));
    }
    let by = match p.by {
        SegmentBy::Material(id) => {
            json!({ "material": model.table().name(id), "id": id, "segments": p.segments })
        }
        SegmentBy::Dominant => json!("dominant"),
    };
    Summary {
        kind: "mesh".into(),
        files,
        counts: segs.iter().map(|s| (s.name.clone(), s.voxels)).collect(),
        units: pl.estimate.voxels,
        unit: "voxels".into(),
        parameters: json!({
            "voxel_mm": p.voxel.to_array(),
            "by": by,
            "formats": { "stl": p.formats.stl, "obj": p.formats.obj, "3mf": p.formats.threemf },
            "infill": p.infill_expr.as_deref().unwrap_or(DEFAULT_INFILL),
            "grid": { "dims": [nx, ny, nz], "origin_mm": pl.grid.origin.to_array() },
        }),
        notes,
        seconds: 0.0,
    }
}
