//! The one grid sampler every consumer uses (preview bakes, slice stacks,
//! meshes, FEA meshes).
//!
//! A [`Grid`] of voxels covers a box; samples are taken at voxel centres
//! `origin + (i + ½)·voxel`. [`Sampler::sample_layers`] fills a caller-owned
//! [`Slab`] (a few z layers) in parallel: each layer is cut into rows of
//! tiles, and each tile is refined quadtree-style with the model's interval
//! bound. A tile whose interval is beyond ± one voxel diagonal (beyond 0
//! for a [`Consumer`] that reads signs only) is filled without evaluating
//! its voxels (empty space, or solid interior); a solid tile with constant
//! fractions gets one fraction evaluation, and so do the inside voxels of
//! an open tile where the fractions are fixed or proved constant (see
//! `Shared`). Two consumers use fraction bounds (`Model::fraction_bounds`)
//! on solid tiles: [`Consumer::MeshContour`] (one evaluation where the
//! segment label is proved constant) and [`Consumer::PngStackRandom`]
//! (`NaN` fractions that the consumer evaluates only where its bounds leave
//! a pick open; for blended designs also in tiles a surface crosses).
//! Memory is proportional to the slab, never to the volume.
//!
//! Skipped voxels store the interval end (`lo` outside, `hi` inside), or in
//! an open leaf a neighbour's value less their distance (see `leaf`): the
//! sign is exact and the magnitude is a valid bound. For consumers that
//! read distances, a skipped voxel is farther than one voxel diagonal from
//! the surface, so no surface crossing lies on a grid edge that touches it,
//! and meshers never interpolate it. A mesh export's contouring settles
//! tiles as signs-only consumers do and gets `±∞` where a skipped voxel may
//! lie within that diagonal: it evaluates those it reads (see
//! [`Consumer::MeshContour`]).

use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};

use rayon::prelude::*;

use crate::aabb::Aabb;
use crate::interval::Interval;
use crate::model::{MAX_MATERIALS, Model};

mod consumer;
mod grid;
mod leaf;
mod slab;
pub use consumer::{Consumer, UniformTest};
pub use grid::{Grid, GridError};
use slab::{Counts, Rect, Rows, fill_run, fill_short, merge_rects, row_blocks, x_tiles};
pub use slab::{RectRows, RowSpan, Slab, SolidRect, fill_pattern};

/// Counts of how voxels were obtained (for reports and benchmarks).
#[derive(Debug, Default)]
pub struct SampleStats {
    /// Voxels whose distance was evaluated.
    pub evaluated: AtomicU64,
    /// Voxels filled from an interval bound without evaluation.
    pub skipped: AtomicU64,
    /// Of those, solid voxels filled by a block through several layers
    /// ([`Consumer::MeshContour`]).
    pub solid_blocks: AtomicU64,
    /// Evaluated inside voxels whose fractions were not evaluated: shared
    /// over a tile where they are fixed or proved constant.
    pub shared: AtomicU64,
}

impl SampleStats {
    /// Adds the tasks' counts of one slab.
    fn add<'r, 'b: 'r>(&self, tasks: impl IntoIterator<Item = &'r Rows<'b>>) {
        let mut sum = Counts::default();
        for c in tasks.into_iter().map(|t| t.counts) {
            sum.evaluated += c.evaluated;
            sum.skipped += c.skipped;
            sum.solid_blocks += c.solid_blocks;
            sum.shared += c.shared;
        }
        self.evaluated.fetch_add(sum.evaluated, Ordering::Relaxed);
        self.skipped.fetch_add(sum.skipped, Ordering::Relaxed);
        self.solid_blocks
            .fetch_add(sum.solid_blocks, Ordering::Relaxed);
        self.shared.fetch_add(sum.shared, Ordering::Relaxed);
    }
}

/// What bounds settle about a box of voxel centres ([`Sampler::settle`]).
enum Settled {
    /// The surface may be near: evaluate (or split).
    Open,
    /// Every voxel is outside; the value to store.
    Outside(f32),
    /// The surface may be near, but the bound is one number over a tile of
    /// more than one voxel: every voxel's distance is that number (see
    /// `settle`).
    Exact(f64),
    /// Every voxel is inside; the value to store, whether they may all
    /// take the centre's fractions (fixed, or uniform for the consumer),
    /// and whether the consumer's test found them mixed (smaller boxes may
    /// settle).
    Solid {
        value: f32,
        constant: bool,
        mixed: bool,
    },
}

/// How a tile whose distances are not evaluated gets its fractions.
#[derive(Clone, Copy)]
enum Fill<'f> {
    /// Outside: all zero.
    Outside,
    /// Inside, one vector for every voxel.
    Constant(&'f [f32]),
    /// Inside, listed in `Slab::rects` with `NaN` fractions for a lazy
    /// consumer, which evaluates them.
    Lazy,
    /// Inside, evaluated voxel by voxel.
    Evaluate,
}

/// Fractions shared by the inside voxels of an open tile, when
/// `Model::constant_fractions` proved them equal over it: the first inside
/// voxel's are evaluated (as stored, `f32`), and the others need only their
/// distance. Outside voxels get zeros, as an evaluation gives them. On a
/// lattice graded per cell, the fraction expression was a tenth of a slice
/// stack's time.
// One lives on the stack per top-level tile; boxing it would allocate.
#[allow(clippy::large_enum_variant)]
enum Shared {
    /// Not proved constant here.
    Unknown,
    /// Proved constant; the fractions once an inside voxel has been seen.
    Constant(Option<[f32; MAX_MATERIALS]>),
}

/// What fraction bounds say about a solid tile and its neighbours.
enum Uniformity {
    /// The consumer's answer is the same throughout.
    Same,
    /// It may change inside: smaller tiles may still be uniform.
    Mixed,
    /// No bound (or no test): sample every voxel.
    Unknown,
}

/// Samples a model on a grid.
pub struct Sampler<'a> {
    model: &'a Model,
    grid: Grid,
    with_fracs: bool,
    uniform: Option<UniformTest<'a>>,
    lazy: bool,
    solid_rects: bool,
    blocks: bool,
    signs_only: bool,
    /// Lazy fractions in tiles a surface crosses too (see `tile`).
    lazy_open: bool,
    /// The design's fractions when they are fixed (see [`Shared`]).
    fixed: Option<[f32; MAX_MATERIALS]>,
    /// Evaluated voxels of a leaf bound the leaf's later ones (see `leaf`).
    lipschitz_skip: bool,
    /// Outside voxels get zero fractions (see `Needs::outside_fracs`).
    outside_fracs: bool,
    /// For [`Consumer::MeshContour`]: one voxel diagonal, within which a
    /// value not evaluated is written as `±∞` (see [`Self::written`]).
    unevaluated_near: Option<f64>,
    leaf_gaps: leaf::LeafGaps,
    /// Open tiles asked whether their fractions are constant, and how many
    /// were (see `try_constant`).
    constant_asked: AtomicU64,
    constant_yes: AtomicU64,
    /// Statistics since creation.
    pub stats: SampleStats,
}

/// The sampler stopped because its cancel flag was set.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("cancelled")]
pub struct Cancelled;

const TILE: usize = 32;
/// Widest fraction bounds (summed over materials) of a tile left to a lazy
/// consumer: beyond it most of its voxels would be evaluated anyway.
const LAZY_WIDTH: f64 = 0.5;
const LEAF: usize = 4;
/// Open tiles counted by `try_constant` before its answer is kept.
const LEARN: u64 = 4096;

impl<'a> Sampler<'a> {
    /// A sampler of `model` on `grid` for `consumer` (which decides what
    /// is written: see [`Consumer`]).
    pub fn new(model: &'a Model, grid: Grid, consumer: Consumer<'a>) -> Self {
        let needs = consumer.needs();
        let with_fracs = needs.fracs;
        let mut f = [0.0f64; MAX_MATERIALS];
        let k = model.materials().len();
        let fixed = (with_fracs && k > 0 && model.fixed_fractions(&mut f[..k])).then(|| {
            let mut one = [0.0f32; MAX_MATERIALS];
            for (o, v) in one.iter_mut().zip(&f[..k]) {
                *o = *v as f32;
            }
            one
        });
        // Piecewise-constant designs have nothing to leave lazy.
        let lazy = needs.lazy && model.varying_fractions();
        Self {
            fixed,
            constant_asked: AtomicU64::new(0),
            constant_yes: AtomicU64::new(0),
            model,
            grid,
            with_fracs,
            uniform: needs.uniform,
            lazy,
            solid_rects: needs.solid_rects,
            blocks: needs.blocks,
            signs_only: needs.signs_only,
            lazy_open: lazy && model.averages_fractions(),
            lipschitz_skip: needs.lipschitz_skip && model.distance_is_bound(),
            unevaluated_near: needs.unevaluated_near.then(|| grid.voxel.length()),
            outside_fracs: needs.outside_fracs,
            leaf_gaps: leaf::leaf_gaps(grid.voxel.x, grid.voxel.y),
            stats: SampleStats::default(),
        }
    }

    /// The grid.
    pub fn grid(&self) -> &Grid {
        &self.grid
    }

    /// The distance at voxel `[x, y, z]`, as an evaluating tile stores it:
    /// what a consumer evaluates where this sampler left a voxel
    /// unevaluated (see [`Consumer::MeshContour`]).
    pub fn evaluate(&self, [x, y, z]: [usize; 3]) -> f32 {
        self.model.distance(self.grid.center(x, y, z)) as f32
    }

    /// Fill `slab` with layers `z0..z1` (in parallel on the current rayon
    /// pool). Checks `cancel` between rows of tiles.
    pub fn sample_layers(
        &self,
        z0: usize,
        z1: usize,
        slab: &mut Slab,
        cancel: &AtomicBool,
    ) -> Result<(), Cancelled> {
        let [nx, ny, _] = self.grid.dims;
        let k = if self.with_fracs {
            self.model.materials().len()
        } else {
            0
        };
        let layers = z1 - z0;
        slab.z0 = z0;
        slab.layers = layers;
        slab.k = k;
        slab.dist.resize(nx * ny * layers, 0.0);
        slab.fracs.resize(nx * ny * layers * k, 0.0);
        if self.blocks && layers > 1 {
            return self.sample_blocks(z0, slab, cancel);
        }
        // Tasks: one per block of TILE rows of one layer, so no task
        // straddles a layer.
        let done: Vec<Rows> = row_blocks(&mut slab.dist, &mut slab.fracs, nx, ny, k)
            .into_par_iter()
            .map(|(l, mut out)| {
                if cancel.load(Ordering::Relaxed) {
                    return Err(Cancelled);
                }
                self.fill_rows(z0 + l, &mut out);
                Ok(out)
            })
            .collect::<Result<_, _>>()?;
        self.stats.add(&done);
        merge_rects(done, &mut slab.rects, &mut slab.rect_fracs);
        Ok(())
    }

    /// [`Self::sample_layers`] with tasks of TILE rows through every layer
    /// (see [`Consumer::MeshContour`]); `slab` is sized.
    fn sample_blocks(
        &self,
        z0: usize,
        slab: &mut Slab,
        cancel: &AtomicBool,
    ) -> Result<(), Cancelled> {
        let [nx, ny, _] = self.grid.dims;
        let mut tasks: Vec<Vec<Rows>> = (0..ny.div_ceil(TILE)).map(|_| Vec::new()).collect();
        for (_, out) in row_blocks(&mut slab.dist, &mut slab.fracs, nx, ny, slab.k) {
            tasks[out.row0 / TILE].push(out);
        }
        let done: Vec<Vec<Rows>> = tasks
            .into_par_iter()
            .map(|mut outs| {
                if cancel.load(Ordering::Relaxed) {
                    return Err(Cancelled);
                }
                let (y0, h) = (outs[0].row0, outs[0].dist.len() / nx);
                for (x0, w) in x_tiles(nx) {
                    if !self.block(z0, x0, y0, w, h, &mut outs) {
                        for (z, out) in (z0..).zip(outs.iter_mut()) {
                            self.tile(Rect::new(z, x0, y0, w, h), out, &mut self.shared());
                        }
                    }
                }
                Ok(outs)
            })
            .collect::<Result<_, _>>()?;
        // Back to layer-major order, the order `sample_layers` gives.
        let mut done: Vec<_> = done.into_iter().map(|d| d.into_iter()).collect();
        let by_layer: Vec<Rows> = (0..slab.layers)
            .flat_map(|_| done.iter_mut().filter_map(|t| t.next()).collect::<Vec<_>>())
            .collect();
        self.stats.add(&by_layer);
        merge_rects(by_layer, &mut slab.rects, &mut slab.rect_fracs);
        Ok(())
    }

    /// Columns `x0..x0 + w` of rows `y0..y0 + h` through every layer of
    /// `outs` (from `z0`) at once, when one bound settles all of them:
    /// empty, or solid with one fraction vector. False when it does not.
    fn block(
        &self,
        z0: usize,
        x0: usize,
        y0: usize,
        w: usize,
        h: usize,
        outs: &mut [Rows],
    ) -> bool {
        let z1 = z0 + outs.len() - 1;
        let k = outs[0].k;
        let b = Aabb::new(
            self.grid.center(x0, y0, z0),
            self.grid.center(x0 + w - 1, y0 + h - 1, z1),
        );
        // Only what one vector settles for every layer: no lazy or
        // per-voxel fractions, no quadtree split across layers.
        let (value, one) = match self.settle(&b, k) {
            Settled::Outside(value) => (value, None),
            Settled::Solid {
                value, constant, ..
            } if constant || k == 0 => (value, Some(self.centre_fractions(&b, k))),
            _ => return false,
        };
        if one.is_some() {
            outs[0].counts.solid_blocks += (w * h * outs.len()) as u64;
        }
        for (z, out) in (z0..).zip(outs.iter_mut()) {
            let how = match &one {
                None => Fill::Outside,
                Some(one) => Fill::Constant(&one[..k]),
            };
            self.fill(Rect::new(z, x0, y0, w, h), out, value, how);
        }
        true
    }

    /// Fill `out`'s rows of layer `z`, tile by tile.
    fn fill_rows(&self, z: usize, out: &mut Rows) {
        let nx = self.grid.dims[0];
        let (y0, h) = (out.row0, out.dist.len() / nx);
        for (x0, w) in x_tiles(nx) {
            self.tile(Rect::new(z, x0, y0, w, h), out, &mut self.shared());
        }
    }

    /// Refine tile `r` into `out`.
    fn tile(&self, r: Rect, out: &mut Rows, shared: &mut Shared) {
        let (z, x0, y0, w, h) = r.parts();
        let k = out.k;
        let b = self.grid.centres_box(x0, x0 + w - 1, y0, y0 + h - 1, z);
        match self.settle(&b, k) {
            Settled::Open => {}
            Settled::Outside(value) => return self.fill(r, out, value, Fill::Outside),
            // Where the voxels' fractions need no evaluation either (none
            // asked, or the design's fixed mix), the tile is written as
            // evaluating it would: zeros outside, the mix inside.
            Settled::Exact(d) if k == 0 || matches!(shared, Shared::Constant(Some(_))) => {
                let how = match shared {
                    Shared::Constant(Some(one)) if d <= 0.0 => Fill::Constant(&one[..k]),
                    _ if d <= 0.0 => Fill::Constant(&[]),
                    _ => Fill::Outside,
                };
                return self.fill(r, out, d as f32, how);
            }
            Settled::Exact(_) => {}
            Settled::Solid { mixed: true, .. } if w > LEAF || h > LEAF => {
                return self.split(r, out, shared);
            }
            Settled::Solid {
                value, constant, ..
            } => {
                let one = if constant {
                    self.centre_fractions(&b, k)
                } else {
                    [0.0; MAX_MATERIALS]
                };
                let how = if constant {
                    Fill::Constant(&one[..k])
                } else if self.lazy && self.bounded(&b, k) {
                    // Lazy only where the consumer will be able to bound them.
                    Fill::Lazy
                } else {
                    Fill::Evaluate
                };
                return self.fill(r, out, value, how);
            }
        }
        if w > LEAF || h > LEAF {
            // Asked of 32² and 16² tiles only: a smaller open tile has too
            // few inside voxels to pay for the bound.
            let large = w * h > 4 * LEAF * LEAF;
            if large && matches!(shared, Shared::Unknown) && self.try_constant(&b, k) {
                return self.split(r, out, &mut Shared::Constant(None));
            }
            return self.split(r, out, shared);
        }
        self.leaf(r, out, shared, &b);
    }

    /// What the bounds say about the voxel centres in `b` (`k` fractions).
    /// Beyond one voxel diagonal from the surface no grid edge that touches
    /// a voxel is crossed, so its distance need not be evaluated.
    fn settle(&self, b: &Aabb, k: usize) -> Settled {
        let margin = self.margin();
        let iv = self.model.interval(b);
        let one_number = iv.lo == iv.hi && iv.lo.is_finite() && b.min != b.max;
        if iv.lo > margin {
            return Settled::Outside(self.written(iv.lo, one_number));
        }
        // Inside, a mesh export of varying fractions keeps the margin of
        // one voxel diagonal: inside voxels settled nearer would take their
        // tile's fractions where the labels allow (`uniformity`), and the
        // segments' mean fractions in the summary would move.
        let inside_margin = match self.unevaluated_near {
            Some(diagonal) if k > 0 && self.fixed.is_none() => diagonal,
            _ => margin,
        };
        if iv.hi.is_nan() || iv.hi >= -inside_margin {
            // A bound that is one number over a box of voxel centres is
            // every voxel's distance: the exact intervals (a box's, a
            // cylinder's, and their translates and unions) evaluate the
            // point function at the box's nearest and farthest offsets
            // (`model::bound`), with float
            // operations that are monotone, so each voxel's value lies
            // between the two ends as computed, bit for bit. Bounds that
            // are not exact (Lipschitz, expressions) are never one number
            // over a box that is not a point. A layer through a face
            // parallel to it (the cube's top and bottom) is such a tile
            // away from the other faces: without this, a cube's layers
            // within a voxel diagonal of them are evaluated voxel by voxel.
            if one_number {
                return Settled::Exact(iv.lo);
            }
            return Settled::Open;
        }
        let mut mixed = false;
        let constant = k > 0
            && (self.model.constant_fractions(b)
                || match self.uniformity(b, k) {
                    Uniformity::Same => true,
                    Uniformity::Mixed => {
                        mixed = true;
                        false
                    }
                    Uniformity::Unknown => false,
                });
        Settled::Solid {
            value: self.written(iv.hi, one_number),
            constant,
            mixed,
        }
    }

    /// What a voxel whose distance was not evaluated stores, given a bound
    /// `v` (exact when `exact`): `v`, except for [`Consumer::MeshContour`]
    /// where a bound within one voxel diagonal of zero is written `±∞`
    /// with its sign, for the contourer to evaluate where it reads it.
    fn written(&self, v: f64, exact: bool) -> f32 {
        match self.unevaluated_near {
            Some(diagonal) if !exact && v.abs() <= diagonal => f32::INFINITY.copysign(v as f32),
            _ => v as f32,
        }
    }

    /// How far from the surface a voxel's value may be a bound: one voxel
    /// diagonal for consumers that read distances, 0 for those that read
    /// signs only.
    fn margin(&self) -> f64 {
        if self.signs_only {
            0.0
        } else {
            self.grid.voxel.length()
        }
    }

    /// How a top-level tile starts: every inside voxel shares the design's
    /// fractions when they are fixed (one material: nothing to evaluate
    /// but distances).
    fn shared(&self) -> Shared {
        match self.fixed {
            Some(one) if !self.lazy_open => Shared::Constant(Some(one)),
            _ => Shared::Unknown,
        }
    }

    /// Whether an open tile's inside voxels have proved-constant fractions
    /// (`b` its voxel centres). The test costs an interval evaluation of
    /// the grading, which pays only where it sometimes succeeds (a lattice
    /// graded per cell); on a smooth grading (a gyroid graded by radius) it
    /// never does, and asking every open tile is wasted work. So it stops
    /// being asked once fewer than one in
    /// eight of its first 64 answers were yes.
    /// Which tiles ask it can depend on the threads' timing; what is
    /// written cannot (the shared fractions are the evaluated ones).
    fn try_constant(&self, b: &Aabb, k: usize) -> bool {
        // Without grading, a union's fractions come with its distance walk
        // (the first child holding the point): nothing to spare.
        if k == 0 || self.lazy_open || !self.model.varying_fractions() {
            return false;
        }
        let asked = self.constant_asked.load(Ordering::Relaxed);
        let yes = self.constant_yes.load(Ordering::Relaxed);
        if asked >= 64 && yes * 8 < asked {
            return false;
        }
        // Counted for the first `LEARN` asks only: the answer is settled by
        // then, and both threads writing these counters for every open
        // tile kept their cache line moving between the cores.
        let learning = asked < LEARN;
        if learning {
            self.constant_asked.fetch_add(1, Ordering::Relaxed);
        }
        let constant = self.model.constant_fractions(b);
        if constant && learning {
            self.constant_yes.fetch_add(1, Ordering::Relaxed);
        }
        constant
    }

    /// Fractions at the centre of `b`, as stored.
    /// Nothing is evaluated for `k = 0`.
    fn centre_fractions(&self, b: &Aabb, k: usize) -> [f32; MAX_MATERIALS] {
        let mut f = [0.0f64; MAX_MATERIALS];
        if k > 0 {
            self.model.eval_into(b.center(), &mut f[..k]);
        }
        let mut one = [0.0f32; MAX_MATERIALS];
        for (o, v) in one.iter_mut().zip(&f[..k]) {
            *o = *v as f32;
        }
        one
    }

    /// Write tile `r` without evaluating distances: `value` everywhere,
    /// fractions as `how` says.
    fn fill(&self, r: Rect, out: &mut Rows, value: f32, how: Fill<'_>) {
        let (z, x0, y0, w, h) = r.parts();
        let (k, row0, nx) = (out.k, out.row0, self.grid.dims[0]);
        // A lazy tile is always listed (its fractions are the consumer's).
        let as_rect = k > 0
            && match how {
                Fill::Constant(_) => self.solid_rects,
                Fill::Lazy => true,
                _ => false,
            };
        if as_rect {
            out.rects.push(SolidRect {
                z,
                x0,
                y0,
                w,
                h,
                at: out.rect_fracs.len(),
            });
            match how {
                Fill::Constant(one) => out.rect_fracs.extend_from_slice(one),
                _ => out.rect_fracs.resize(out.rect_fracs.len() + k, f32::NAN),
            }
        }
        out.counts.skipped += (w * h) as u64;
        if w == 0 || h == 0 {
            return;
        }
        let first = (y0 - row0) * nx + x0;
        // Distances row by row, with no other test a row: most fills
        // write nothing else (a mesh's outside tiles, listed rectangles).
        for row in out.dist[first..first + (h - 1) * nx + w].chunks_mut(nx) {
            fill_run(&mut row[..w], value);
        }
        if k == 0 || as_rect || (matches!(how, Fill::Outside) && !self.outside_fracs) {
            return;
        }
        // (Zeroed only when voxels are evaluated: most fills are small.)
        let mut f = None;
        for y in y0..y0 + h {
            let row = (y - row0) * nx;
            // Whole runs at once where every voxel gets the same
            // fractions (a per-voxel `fill` was a library call each).
            let run = &mut out.fracs[(row + x0) * k..(row + x0 + w) * k];
            match how {
                Fill::Outside => fill_short(run, 0.0),
                // (Listed as a rectangle above.)
                Fill::Lazy => {}
                Fill::Constant(one) => fill_pattern(run, one),
                Fill::Evaluate => {
                    // (Lazily: the array's zeroing stays out of the loop.)
                    #[allow(clippy::unnecessary_lazy_evaluations)]
                    let f = f.get_or_insert_with(|| [0.0f64; MAX_MATERIALS]);
                    for (x, voxel) in (x0..).zip(run.chunks_exact_mut(k)) {
                        let p = self.grid.center(x, y, z);
                        self.model.fractions_inside(p, &mut f[..k]);
                        for (o, v) in voxel.iter_mut().zip(&f[..k]) {
                            *o = *v as f32;
                        }
                    }
                }
            }
        }
    }

    /// Refine a tile as four quarters.
    fn split(&self, r: Rect, out: &mut Rows, shared: &mut Shared) {
        let (z, rx, ry, rw, rh) = r.parts();
        let (hw, hh) = (rw.div_ceil(2), rh.div_ceil(2));
        for (x0, w) in [(rx, hw), (rx + hw, rw - hw)] {
            for (y0, h) in [(ry, hh), (ry + hh, rh - hh)] {
                if w > 0 && h > 0 {
                    self.tile(Rect::new(z, x0, y0, w, h), out, shared);
                }
            }
        }
    }

    /// Whether the model bounds the fractions over `b` narrowly enough for
    /// bounds to settle most random picks (a gentle grading, not a tile
    /// where several parts with different materials meet): the widths sum
    /// to at most [`LAZY_WIDTH`].
    fn bounded(&self, b: &Aabb, k: usize) -> bool {
        let mut iv = [Interval::point(0.0); MAX_MATERIALS];
        self.model.fraction_bounds(b, &mut iv[..k])
            && iv[..k].iter().map(|i| i.hi - i.lo).sum::<f64>() <= LAZY_WIDTH
    }

    /// Whether the consumer's test holds over the solid tile of voxel
    /// centres `b` grown by one voxel (neighbours in x, y and z included;
    /// they must be inside too).
    fn uniformity(&self, b: &Aabb, k: usize) -> Uniformity {
        let Some(test) = self.uniform else {
            return Uniformity::Unknown;
        };
        let grown = Aabb::new(b.min - self.grid.voxel, b.max + self.grid.voxel);
        let mut iv = [Interval::point(0.0); MAX_MATERIALS];
        if !self.model.fraction_bounds(&grown, &mut iv[..k]) {
            return Uniformity::Unknown;
        }
        if self.model.interval(&grown).hi < 0.0 && test(&iv[..k]) {
            Uniformity::Same
        } else {
            Uniformity::Mixed
        }
    }
}

#[cfg(test)]
mod tests;
