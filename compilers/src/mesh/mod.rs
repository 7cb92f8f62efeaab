//! Segmented meshes for slicers: the part split by fraction ranges of one
//! material (or by dominant material), each segment a closed triangle mesh.
//!
//! Pipeline, a slab of layers at a time: `Sampler::sample_layers` (grid
//! padded by one voxel so its outer layer is outside) → [`segment`] labels
//! per voxel → [`contour`] (marching tetrahedra inside each cube, multi-label,
//! shared vertices; marching cubes with one label, see `cube_loops`) → per
//! segment an [`IndexedMesh`] → STL ([`stl`]), OBJ ([`obj`]) per segment
//! and one `segments.3mf` ([`threemf`]) with every segment as a named part
//! carrying its `fill_density`.
//!
//! Guarantees: each segment's mesh is watertight (every edge in exactly two
//! triangles, opposite directions) and outward oriented; neighbouring
//! segments share their interface triangles exactly (same positions,
//! opposite orientation), so the segments cover the part once. The outer
//! surface is placed from the true distances.
//!
//! Infill: `fill_density = clamp(expr(f), 0, 100)%`, `expr` a math string of
//! `f` (default [`DEFAULT_INFILL`]), where `f` is the middle of the
//! segment's range `(s + ½)/n` when splitting by a material, and the mean
//! dominant fraction over the segment's voxels when splitting by dominant
//! material.
//!
//! # Differences from pyvcad's `MeshCompiler`
//!
//! Any material (pyvcad always splits by material id 1) or the dominant
//! one; binary STL (pyvcad: ASCII through VTK) plus OBJ and 3MF; segments
//! share their interfaces exactly instead of being contoured one by one
//! (which leaves gaps and overlaps); fractions are normalised by their sum.

mod band_scratch;
pub mod bodies;
pub mod contour;
mod cube_loops;
pub mod field;
mod flat;
pub mod indexed;
mod interface;
pub(crate) mod kuhn;
mod layer_dist;
mod loop_cdt;
mod mixed;
pub mod obj;
mod one_label;
mod outline;
mod output;
pub mod segment;
mod sign_row;
pub mod stl;
mod text_blocks;
pub mod threemf;
mod unevaluated;
mod vertex_keys;

use std::sync::atomic::AtomicBool;

use glam::DVec3;
use rayon::prelude::*;
use volcad_core::expr::Expr;
use volcad_core::sampler::{Consumer, Grid, Sampler, Slab, UniformTest};
use volcad_core::{MaterialId, Model};

pub use field::marching_cubes;
pub use indexed::{EdgeReport, IndexedMesh};

use crate::design::{grid_for, palette};
use crate::estimate::{Look, coarse_estimate, sampled_layers};
use crate::job::{ExportError, JobContext, Summary};
use crate::png_io::folder_name;
use crate::resources::{MemoryGuard, check_disk, check_memory, run_with_threads};
use contour::{Contourer, Plane};
use layer_dist::{DistPool, LayerDist};
use output::{body_notes, checks, summary, write_files};
use segment::{Classifier, Tally};

/// Infill percent from `f` when no expression is given.
pub const DEFAULT_INFILL: &str = "10 + 80*f";
/// Most segments by fraction ranges.
pub const MAX_SEGMENTS: usize = 1000;
/// Working memory aimed at for one slab of samples.
const SLAB_BUDGET: usize = 256 << 20;
/// Most layers sampled per slab. Two slabs' planes are in flight (one
/// contoured while the next is sampled), so thin slabs keep the working
/// set small: fewer fresh pages to fault in, and planes still in cache
/// when contoured. Compare values by alternating runs of two builds on the
/// graded bar by dominant material and the cube (`volcad export mesh
/// assets/examples/graded_bar.rhai --by dominant --voxel 0.0422`, and
/// `hello_cube.rhai --voxel 0.05`): fewer layers were faster on both, down
/// to four; the seat, gyroid, bunny lattice and tiled FCC did not move.
const SLAB_LAYERS: usize = 4;
/// Triangles per voxel face of surface (measured on spheres and lattices),
/// by marching tetrahedra (two or more segments) and by marching cubes (one
/// segment: no face diagonals, see `cube_loops`).
const TRIANGLES_PER_FACE: [f64; 2] = [9.0, 3.5];
/// Cube layers the triangle estimate samples at the export's voxel size
/// (see `sampled_triangles`), when the coarse grid's cells are more than
/// [`SAMPLE_BEYOND`] voxels across.
const SAMPLED_LAYERS: usize = 3;
/// Coarse cells at most this many voxels across see what the export sees.
const SAMPLE_BEYOND: f64 = 2.0;
/// Triangles of merged flat faces per voxel of `sqrt(flat area)`, with two
/// or more segments and with one: a 10 mm cube makes about 12 thousand
/// with two segments at 0.1 mm and 24 thousand at 0.05 mm, where
/// `sqrt(600 mm²)` is 245 and 490 voxels; its outlines have no face
/// diagonals' points with one segment.
const FLAT_TRIANGLES_PER_EDGE: [f64; 2] = [50.0, 20.0];
/// Bytes held until the end of the export per flat cube (a voxel of a
/// planar face): its region's union-find entry, its interned key, its
/// kept place and labels (8 bytes) and growth slack (its samples are not
/// kept, and regions list their cubes only to fall back; see `flat.rs`).
/// The merged faces' triangles are few, but the bookkeeping grows with
/// their area in voxels: the 10 mm cube (600 mm² of faces) peaks at 77 MB
/// resident at 0.02 mm and 269 MB at 0.01 mm, about 33 to 41 bytes for
/// each flat cube added besides the slabs and planes (`/usr/bin/time -v
/// volcad export mesh assets/examples/hello_cube.rhai --voxel 0.01`; 670
/// MB when cubes kept their samples and 16-byte keys). Counted as 50 to
/// err on the safe side (growth slack depends on where the arrays stand
/// when they grow).
const FLAT_CUBE_BYTES: f64 = 50.0;

/// How the part is split.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SegmentBy {
    /// `segments` equal ranges of this material's fraction.
    Material(MaterialId),
    /// One segment per material of the design, where it has the largest
    /// fraction (`segments` is ignored).
    Dominant,
}

/// Which files to write.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MeshFormats {
    /// Binary STL per segment.
    pub stl: bool,
    /// OBJ per segment.
    pub obj: bool,
    /// One `segments.3mf` with every segment as a part.
    pub threemf: bool,
}

impl Default for MeshFormats {
    /// All three.
    fn default() -> Self {
        Self {
            stl: true,
            obj: true,
            threemf: true,
        }
    }
}

/// Parameters of a segmented mesh export.
#[derive(Clone, Debug, PartialEq)]
pub struct MeshParams {
    /// Voxel size (mm) per axis of the sampling grid.
    pub voxel: DVec3,
    /// Number of fraction ranges (with [`SegmentBy::Material`]).
    pub segments: usize,
    /// How to split.
    pub by: SegmentBy,
    /// Files to write.
    pub formats: MeshFormats,
    /// Infill percent as a math string of `f` (`None`: [`DEFAULT_INFILL`]).
    pub infill_expr: Option<String>,
    /// Worker threads (`None`: all cores).
    pub threads: Option<usize>,
}

impl Default for MeshParams {
    /// 0.1 mm voxels, by dominant material, every format.
    fn default() -> Self {
        Self {
            voxel: DVec3::splat(0.1),
            segments: 4,
            by: SegmentBy::Dominant,
            formats: MeshFormats::default(),
            infill_expr: None,
            threads: None,
        }
    }
}

/// What a mesh export will take, known before it starts.
#[derive(Clone, Debug, PartialEq)]
pub struct MeshEstimate {
    /// The (padded) sampling grid.
    pub grid: Grid,
    /// Voxels sampled.
    pub voxels: u64,
    /// Segments.
    pub segments: usize,
    /// Layers sampled per slab.
    pub slab_layers: usize,
    /// Rough triangle count over all segments, from the coarsely estimated surface area
    /// as marching tetrahedra would cut it: flat faces merge into far fewer
    /// (the memory and disk checks err on the safe side there).
    pub triangles: u64,
    /// Working memory, meshes included (bytes, rough).
    pub memory_bytes: u64,
    /// Rough size of the output (bytes).
    pub disk_bytes: u64,
}

/// One segment's result.
#[derive(Clone, Debug, PartialEq)]
pub struct SegmentMesh {
    /// File and part name.
    pub name: String,
    /// Its closed mesh (may be empty when no voxel fell in the segment).
    pub mesh: IndexedMesh,
    /// Voxels in the segment.
    pub voxels: u64,
    /// The `f` its infill is computed from (see the module docs).
    pub f: f64,
    /// Infill percent.
    pub infill_percent: f64,
}

struct Plan {
    grid: Grid,
    classifier: Classifier,
    infill: Expr,
    slab_layers: usize,
    estimate: MeshEstimate,
    /// Let the sampler fill label-uniform solid tiles with one evaluation
    /// (off only in tests, to show it changes nothing).
    uniform_tiles: bool,
    /// How flat regions are contoured: merged, except in tests.
    flat: Flat,
    /// Every inside voxel's label and fraction, when the design's fixed
    /// mix decides them (see [`segment::fixed_class`]).
    fixed: Option<(u16, f32)>,
}

/// How flat regions are contoured ([`Flat::Merge`], except in tests that
/// compare the ways).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Flat {
    /// Merged (see `flat.rs`).
    Merge,
    /// Not merged: plain marching tetrahedra.
    #[cfg_attr(not(test), allow(dead_code))]
    Off,
    /// Merged, and every region contoured by its fallback.
    #[cfg_attr(not(test), allow(dead_code))]
    FallbackOnly,
}

fn plan(model: &Model, p: &MeshParams, look: Look) -> Result<Plan, ExportError> {
    let k = model.materials().len();
    let classifier = match p.by {
        SegmentBy::Dominant => Classifier::Dominant { k },
        SegmentBy::Material(id) => {
            if id == 0 || model.table().get(id).is_none() {
                return Err(ExportError::param(
                    "--material",
                    format!(
                        "material id {id} is not in the material table ({}); it has ids 1..={}",
                        model.table().origin(),
                        model.table().len() - 1
                    ),
                ));
            }
            if !(1..=MAX_SEGMENTS).contains(&p.segments) {
                return Err(ExportError::param(
                    "--segments",
                    format!("{} segments; use 1..={MAX_SEGMENTS}", p.segments),
                ));
            }
            Classifier::Ranges {
                slot: model.materials().iter().position(|m| *m == id),
                n: p.segments,
            }
        }
    };
    if !(p.formats.stl || p.formats.obj || p.formats.threemf) {
        return Err(ExportError::param(
            "--format",
            "no output format chosen; pick stl, obj and/or 3mf",
        ));
    }
    let src = p.infill_expr.as_deref().unwrap_or(DEFAULT_INFILL);
    let infill =
        Expr::compile(src, &["f"]).map_err(|e| ExportError::param("--infill", e.to_string()))?;
    palette(model)?;
    let grid = grid_for(model, p.voxel, p.voxel.max_element())?;
    let [nx, ny, nz] = grid.dims;
    let layer = nx * ny;
    let stride = classifier.interface().stride();
    let per_layer = layer * (4 + 4 * k);
    let slab_layers = (SLAB_BUDGET / per_layer.max(1))
        .clamp(1, SLAB_LAYERS)
        .min(nz);
    let pr = coarse_estimate(model, p.voxel);
    let fixed = segment::fixed_class(&classifier, model);
    let face = (p.voxel.x * p.voxel.y * p.voxel.z).powf(2.0 / 3.0);
    let segments = classifier.segments();
    // Interfaces add surface; assume about half the outer area per extra segment.
    let more = 1.0 + 0.5 * (segments as f64 - 1.0).min(4.0);
    // Faces on the bounding box are planar and merge: their triangles go
    // with their outlines, about their length in voxels (each segment has
    // its own).
    let cut = usize::from(segments == 1);
    let flat_triangles = FLAT_TRIANGLES_PER_EDGE[cut] * (pr.flat_mm2 / face).sqrt() * more;
    let coarse = pr.surface_mm2 * more / face * TRIANGLES_PER_FACE[cut];
    // Sampled layers see what the coarse grid's cells are too coarse for. Two
    // layers and their planes must fit the slab budget: a grid whose layer
    // alone outgrows memory is refused below, not sampled first.
    let pair_bytes = 2 * layer * (4 + 4 * k + 2 + 4 + 4 * stride);
    let sampled = if look == Look::Layers
        && pr.cell.max_element() > SAMPLE_BEYOND * p.voxel.min_element()
        && pair_bytes <= SLAB_BUDGET
    {
        sampled_triangles(model, grid, &classifier, fixed) as f64
    } else {
        0.0
    };
    let triangles = (coarse.max(sampled) + flat_triangles) as u64;
    // Meshes: 12 B per triangle, ~½ vertex per triangle at 12 B + map entry.
    let mesh_bytes = triangles * 12 + triangles / 2 * 40;
    // Flat cubes are kept to the end: the box's faces, planar interfaces
    // (guessed like the triangles) and, to err on the safe side, every
    // other face of the surface, which may be planar too.
    let flat_cubes = (pr.flat_mm2 + pr.surface_mm2) * more / face;
    let flat_bytes = (flat_cubes * FLAT_CUBE_BYTES) as u64;
    // Planes: one slab being contoured, the next being labelled, and the
    // contourer's previous plane; their distances are the slabs' buffers
    // (three circulate: the one sampled into is in `per_layer`).
    // With one segment the contourer also keeps its vertices by grid edge
    // (`one_label::LayerEdges`, 8 bytes a slot): two planes' x and y edges
    // (two slots a sample) and the layer's z edges (one).
    let plane_edges = if segments == 1 {
        (2 * 2 + 1) * layer * 8
    } else {
        0
    };
    let planes = ((2 * slab_layers + 1) * layer * (2 + 4 * stride)
        + 2 * slab_layers * layer * 4
        + plane_edges) as u64;
    let memory_bytes = (slab_layers * per_layer) as u64 + planes + mesh_bytes + flat_bytes;
    check_memory(
        memory_bytes,
        &format!("meshing {nx} × {ny} × {nz} voxels (about {triangles} triangles)"),
    )?;
    let estimate = MeshEstimate {
        grid,
        voxels: grid.count(),
        segments,
        slab_layers,
        triangles,
        memory_bytes,
        disk_bytes: output_bytes(p.formats, triangles, segments),
    };
    Ok(Plan {
        grid,
        classifier,
        infill,
        slab_layers,
        estimate,
        uniform_tiles: true,
        flat: Flat::Merge,
        fixed,
    })
}

/// About how many bytes `triangles` triangles in `segments` segments take
/// in `formats` (binary STL 50 per triangle; OBJ about 40, with half a
/// vertex per triangle; the 3MF, compressed, about 20), plus headers.
fn output_bytes(formats: MeshFormats, triangles: u64, segments: usize) -> u64 {
    let per_triangle =
        50 * u64::from(formats.stl) + 40 * u64::from(formats.obj) + 20 * u64::from(formats.threemf);
    triangles * per_triangle + 4096 * segments as u64
}

/// Grid, memory, rough triangle count and output size; errors for bad
/// parameters (voxel, segments, material, infill expression, formats), an
/// unbounded design, or meshes that would not fit in memory.
pub fn estimate_mesh(model: &Model, p: &MeshParams) -> Result<MeshEstimate, ExportError> {
    plan(model, p, Look::Layers).map(|pl| pl.estimate)
}

fn segment_names(model: &Model, p: &MeshParams, c: &Classifier) -> Vec<String> {
    let n = c.segments();
    let digits = n.saturating_sub(1).to_string().len().max(2);
    let mat = |id: MaterialId| folder_name(model.table().name(id), id);
    (0..n)
        .map(|s| match p.by {
            SegmentBy::Material(id) => {
                let (lo, hi) = (s as f64 / n as f64, (s + 1) as f64 / n as f64);
                format!("seg{s:0digits$}_{}_{lo:.3}-{hi:.3}", mat(id))
            }
            SegmentBy::Dominant => format!("seg{s:0digits$}_{}", mat(model.materials()[s])),
        })
        .collect()
}

/// Compute every segment's mesh in memory (`progress(layers_done, layers)`
/// after each slab). The export writes these; tests and previews use them
/// directly.
pub fn segment_meshes(
    model: &Model,
    p: &MeshParams,
    cancel: &AtomicBool,
    progress: impl Fn(usize, usize) + Sync,
) -> Result<Vec<SegmentMesh>, ExportError> {
    let pl = plan(model, p, Look::Coarse)?;
    run_with_threads(p.threads, || build(model, p, &pl, cancel, &progress))
}

/// The sampler of a mesh export: fractions, and (unless `uniform` is
/// `None`, in tests) label-uniform solid tiles filled with one evaluation;
/// where the labels come from signs alone (a `fixed` class), distances
/// only.
fn sampler_for<'a>(
    model: &'a Model,
    grid: Grid,
    uniform: Option<UniformTest<'a>>,
    fixed: Option<(u16, f32)>,
) -> Sampler<'a> {
    let consumer = match (uniform, fixed) {
        // Labels from signs alone (`label_plane`): no fractions to write.
        (Some(_), Some(_)) => Consumer::MeshContourSigns,
        (Some(u), None) => Consumer::MeshContour(u),
        // The reference the tests compare with: every voxel sampled.
        (None, _) => Consumer::ViewportBake,
    };
    Sampler::new(model, grid, consumer)
}

/// Triangles of the curved (not flat-merged) surface, from a few cube
/// layers sampled and contoured at the export's own voxel size and scaled
/// to all layers. The coarse grid cannot see parts thinner than its cells:
/// on the bunny lattice at 0.26 mm (struts 1 mm across, coarse cells 1.6 mm)
/// it saw the bunny and not the struts, and estimated 2.1 million
/// triangles for 9.9 million.
fn sampled_triangles(
    model: &Model,
    grid: Grid,
    classifier: &Classifier,
    fixed: Option<(u16, f32)>,
) -> u64 {
    let dims = grid.dims;
    let layers = dims[2].saturating_sub(1);
    if layers == 0 {
        return 0;
    }
    let uniform = |b: &[volcad_core::interval::Interval]| classifier.uniform(b);
    let sampler = sampler_for(model, grid, Some(&uniform), fixed);
    let mut slab = Slab::default();
    let (mut made, mut picks) = (0, 0);
    for z in sampled_layers(0..layers, SAMPLED_LAYERS) {
        picks += 1;
        if sampler
            .sample_layers(z, z + 2, &mut slab, &AtomicBool::new(false))
            .is_err()
        {
            return 0;
        }
        let mut contourer =
            Contourer::new(grid, classifier.segments(), classifier.interface()).counting_only();
        // Both planes share the slab's distances, as in the export. The
        // contourer numbers them 0 and 1: its plane `k` is layer `z + k`.
        let dist = std::sync::Arc::new(std::mem::take(&mut slab.dist));
        let exact = |[i, j, k]: [usize; 3]| sampler.evaluate([i, j, z + k]);
        for l in 0..2 {
            let plane = label_plane(
                classifier,
                fixed,
                &slab,
                &dist,
                [l, z + l],
                dims,
                Plane::default(),
            );
            contourer.push_plane(l, plane.0, &exact);
        }
        made += contourer.triangles();
    }
    (made as f64 * layers as f64 / picks.max(1) as f64) as u64
}

/// Layer `l` (global layer `z`) of `slab` labelled: from the signs alone
/// where the design's `fixed` mix decides every inside voxel, else voxel
/// by voxel.
fn label_plane(
    classifier: &Classifier,
    fixed: Option<(u16, f32)>,
    slab: &Slab,
    dist: &std::sync::Arc<Vec<f32>>,
    [l, z]: [usize; 2],
    dims: [usize; 3],
    reuse: Plane,
) -> (Plane, Tally) {
    match fixed {
        Some(class) => segment::fixed_plane_into(dist, l, dims, z, reuse, class),
        None => classifier.plane_into(slab, dist, l, dims, z, reuse),
    }
}

fn build(
    model: &Model,
    p: &MeshParams,
    pl: &Plan,
    cancel: &AtomicBool,
    progress: &(impl Fn(usize, usize) + Sync),
) -> Result<Vec<SegmentMesh>, ExportError> {
    let dims = pl.grid.dims;
    let nz = dims[2];
    let uniform = |b: &[volcad_core::interval::Interval]| pl.classifier.uniform(b);
    let sampler = sampler_for(
        model,
        pl.grid,
        pl.uniform_tiles.then_some(&uniform),
        pl.fixed,
    );
    let mut contourer =
        Contourer::new(pl.grid, pl.classifier.segments(), pl.classifier.interface());
    contourer = match pl.flat {
        Flat::Merge => contourer,
        Flat::Off => contourer.with_flat_merge(false),
        Flat::FallbackOnly => contourer.with_fallback_only(),
    };
    let exact = |at: [usize; 3]| sampler.evaluate(at);
    let mut tally = Tally::new(pl.classifier.segments());
    let mut slab = Slab::default();
    let mut pool = DistPool::default();
    // Sample and label one slab of planes, into retired planes' buffers;
    // the planes share the slab's distances (see `layer_dist`).
    let mut labelled = |slab: &mut Slab, z0: usize, z1: usize, mut spare: Vec<Plane>| {
        slab.dist = pool.take();
        sampler
            .sample_layers(z0, z1, slab, cancel)
            .map_err(|_| ExportError::Cancelled)?;
        let dist = pool.share(std::mem::take(&mut slab.dist));
        // Planes are labelled in parallel: on one thread this was a third
        // of a slab's time on the graded bar, with the other core idle
        // once it had contoured the previous slab.
        let jobs: Vec<(usize, Plane)> = (z0..z1)
            .map(|z| (z, spare.pop().unwrap_or_default()))
            .collect();
        let slab = &*slab;
        Ok::<_, ExportError>(
            jobs.into_par_iter()
                .map(|(z, reuse)| {
                    label_plane(
                        &pl.classifier,
                        pl.fixed,
                        slab,
                        &dist,
                        [z - z0, z],
                        dims,
                        reuse,
                    )
                })
                .collect::<Vec<_>>(),
        )
    };
    let guard = MemoryGuard::for_export();
    let mut z0 = 0;
    let mut z1 = pl.slab_layers.min(nz);
    let mut ready = labelled(&mut slab, z0, z1, Vec::new())?;
    let mut spare = Vec::new();
    while z0 < nz {
        let next = (z1 < nz).then(|| (z1, (z1 + pl.slab_layers).min(nz)));
        let planes = std::mem::take(&mut ready);
        let reuse = std::mem::take(&mut spare);
        // Contour this slab while the next one is sampled: contouring has
        // sequential parts (stitching rows, joining flat regions) that
        // would otherwise leave a core idle. Planes still enter the
        // contourer in order, so the output does not change.
        let (sampled, retired) = rayon::join(
            || {
                next.map(|(a, b)| labelled(&mut slab, a, b, reuse))
                    .transpose()
            },
            || {
                let mut retired = Vec::new();
                for (z, (plane, t)) in (z0..).zip(planes) {
                    tally.add(&t);
                    // A retired plane lets go of its slab's distances at
                    // once (it is kept for its other buffers), so the
                    // buffer can come back to the sampler (kept until
                    // reuse, a fourth buffer was needed).
                    retired.extend(contourer.push_plane(z, plane, &exact).map(|mut p| {
                        p.dist = LayerDist::default();
                        p
                    }));
                }
                retired
            },
        );
        progress(z1, nz);
        if let Some(g) = &guard {
            g.check(|| format!("meshing after layer {z1} of {nz}"))?;
        }
        ready = sampled?.unwrap_or_default();
        spare = retired;
        z0 = z1;
        z1 = next.map_or(nz, |n| n.1);
    }
    // The slab sampled into, the one contoured and the one whose last
    // plane the contourer held: more means retired planes kept buffers.
    debug_assert!(pool.fresh() <= 3, "{} distance buffers", pool.fresh());
    named_segments(model, p, pl, contourer, &tally)
}

/// The contourer's meshes as named segments with their infill (flat regions
/// triangulated now, see [`Contourer::finish`]).
fn named_segments(
    model: &Model,
    p: &MeshParams,
    pl: &Plan,
    contourer: Contourer,
    tally: &Tally,
) -> Result<Vec<SegmentMesh>, ExportError> {
    let names = segment_names(model, p, &pl.classifier);
    let n = pl.classifier.segments();
    contourer
        .finish(&|[i, j, k], value| pl.classifier.sample(model, pl.grid.center(i, j, k), value))
        .into_iter()
        .enumerate()
        .map(|(s, mesh)| {
            let voxels = tally.voxels[s];
            let f = match pl.classifier {
                Classifier::Ranges { .. } => (s as f64 + 0.5) / n as f64,
                Classifier::Dominant { .. } => {
                    if voxels > 0 {
                        tally.sum_f[s] / voxels as f64
                    } else {
                        1.0
                    }
                }
            };
            let v = pl.infill.eval(&[f]);
            if !v.is_finite() {
                return Err(ExportError::param(
                    "--infill",
                    format!("\"{}\" gives {v} at f = {f}", pl.infill.source()),
                ));
            }
            Ok(SegmentMesh {
                name: names[s].clone(),
                mesh,
                voxels,
                f,
                infill_percent: v.clamp(0.0, 100.0),
            })
        })
        .collect()
}

/// Write the segments' files into `ctx.staging()`.
pub fn export_meshes(
    model: &Model,
    p: &MeshParams,
    ctx: &JobContext,
) -> Result<Summary, ExportError> {
    let pl = plan(model, p, Look::Coarse)?;
    check_disk(pl.estimate.disk_bytes, ctx.folder(), "a larger voxel size")?;
    let thin = crate::thin::thin_feature_notes(model, p.voxel.max_element(), "--voxel");
    run_with_threads(p.threads, || {
        let nz = pl.grid.dims[2];
        let segs = build(model, p, &pl, ctx.cancel_flag(), &|done, total| {
            ctx.progress(
                "meshing",
                done as u64,
                total as u64,
                "layers",
                0.9 * done as f64 / total.max(1) as f64,
            );
        })?;
        debug_assert!(nz > 0);
        ctx.check_cancel()?;
        // The up-front check went by the coarse grid, which misses parts
        // thinner than its cells; the triangles are known now, and nothing
        // is written yet.
        let made: usize = segs.iter().map(|s| s.mesh.triangles.len()).sum();
        check_disk(
            output_bytes(p.formats, made as u64, segs.len()),
            ctx.folder(),
            "a larger voxel size",
        )?;
        ctx.progress("writing", 0, 1, "files", 0.9);
        // The checks read the meshes as the writers do: both at once, so a
        // core left idle by the last (longest) file checks the meshes.
        let (files, (checks, bodies)) = rayon::join(
            || write_files(&segs, p, ctx),
            || rayon::join(|| checks(&segs), || bodies::bodies(&segs)),
        );
        let mut s = summary(model, p, &pl, &segs, files?, &checks);
        s.notes.extend(thin);
        let design = model.stated_gaps(crate::thin::CELLS_ACROSS * p.voxel.max_element());
        s.notes
            .extend(body_notes(&bodies, p.voxel.max_element(), &design));
        Ok(s)
    })
}

#[cfg(test)]
pub(crate) mod tests;
