//! The one grid sampler every consumer uses (preview bakes, slice stacks,
//! meshes, FEA meshes).
//!
//! A [`Grid`] of voxels covers a box; samples are taken at voxel centres
//! `origin + (i + ½)·voxel`. [`Sampler::sample_layers`] fills a caller-owned
//! [`Slab`] (a few z layers) in parallel: each layer is cut into rows of
//! tiles, and each tile is refined quadtree-style with the model's interval
//! bound. A tile whose interval is beyond ± one voxel diagonal is filled
//! without evaluating its voxels (empty space, or solid interior); a solid
//! tile with constant fractions gets one fraction evaluation. Two consumer
//! options use fraction bounds (`Model::fraction_bounds`) on solid tiles:
//! [`Sampler::with_uniform`] (meshes: one evaluation where the segment label
//! is proved constant) and [`Sampler::with_lazy_fractions`] (random
//! dithering: `NaN` fractions that the consumer evaluates only where its
//! bounds leave a pick open). Memory is proportional to the slab, never to
//! the volume.
//!
//! Skipped voxels store the interval end (`lo` outside, `hi` inside): the
//! sign is exact and the magnitude is a valid bound. Because a skipped voxel
//! is farther than one voxel diagonal from the surface, no surface crossing
//! lies on a grid edge that touches it, so meshers never interpolate it.

use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};

use glam::DVec3;
use rayon::prelude::*;

use crate::bounds::Aabb;
use crate::interval::Interval;
use crate::model::{MAX_MATERIALS, Model};

/// A regular voxel grid.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Grid {
    /// Lowest corner of voxel (0, 0, 0).
    pub origin: DVec3,
    /// Voxel size per axis (mm).
    pub voxel: DVec3,
    /// Voxels per axis.
    pub dims: [usize; 3],
}

/// Why a grid cannot be made.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum GridError {
    /// A voxel size is zero, negative or not a number.
    #[error("voxel size must be > 0 on every axis, got ({}, {}, {}) mm", .0.x, .0.y, .0.z)]
    BadVoxel(DVec3),
    /// The design has no finite extent.
    #[error(
        "the design is unbounded (bounding box {0}); clip Tile or TPMS with Intersection and a bounded shape"
    )]
    Unbounded(String),
    /// The design is empty.
    #[error("the design is empty (its bounding box has no volume)")]
    Empty,
    /// The grid would have more voxels than the limit.
    #[error(
        "{voxels} voxels ({nx} × {ny} × {nz}) is more than the limit of {limit}; use a larger voxel size"
    )]
    TooLarge {
        /// Total voxels.
        voxels: u128,
        /// X count.
        nx: u128,
        /// Y count.
        ny: u128,
        /// Z count.
        nz: u128,
        /// The limit.
        limit: u128,
    },
}

impl Grid {
    /// The grid of `voxel`-sized cells covering `bbox` (count = ceil(extent /
    /// voxel), at least 1, centred on the box).
    pub fn covering(bbox: &Aabb, voxel: DVec3, max_voxels: u128) -> Result<Grid, GridError> {
        if !(voxel.cmpgt(DVec3::ZERO).all() && voxel.is_finite()) {
            return Err(GridError::BadVoxel(voxel));
        }
        if bbox.is_empty() {
            return Err(GridError::Empty);
        }
        if !bbox.is_finite() {
            return Err(GridError::Unbounded(format!(
                "{:?} .. {:?}",
                bbox.min.to_array(),
                bbox.max.to_array()
            )));
        }
        let n = (bbox.size() / voxel).ceil().max(DVec3::ONE);
        let (nx, ny, nz) = (n.x as u128, n.y as u128, n.z as u128);
        let voxels = nx * ny * nz;
        if voxels > max_voxels || n.max_element() > u32::MAX as f64 {
            return Err(GridError::TooLarge {
                voxels,
                nx,
                ny,
                nz,
                limit: max_voxels,
            });
        }
        let span = n * voxel;
        let origin = bbox.center() - span * 0.5;
        Ok(Grid {
            origin,
            voxel,
            dims: [nx as usize, ny as usize, nz as usize],
        })
    }

    /// Centre of voxel (i, j, k).
    #[inline]
    pub fn center(&self, i: usize, j: usize, k: usize) -> DVec3 {
        self.origin + (DVec3::new(i as f64, j as f64, k as f64) + 0.5) * self.voxel
    }

    /// Total voxels.
    pub fn count(&self) -> u64 {
        self.dims.iter().map(|d| *d as u64).product()
    }

    /// Voxels in one layer.
    pub fn layer_len(&self) -> usize {
        self.dims[0] * self.dims[1]
    }

    /// The box of voxel centres of the index ranges (inclusive ends).
    fn centres_box(&self, i0: usize, i1: usize, j0: usize, j1: usize, k: usize) -> Aabb {
        Aabb::new(self.center(i0, j0, k), self.center(i1, j1, k))
    }
}

/// A few z layers of samples, owned by the caller and reused between calls.
#[derive(Clone, Debug, Default)]
pub struct Slab {
    /// First layer held.
    pub z0: usize,
    /// Layers held.
    pub layers: usize,
    /// Signed distance per voxel, index `(z − z0)·nx·ny + y·nx + x`.
    pub dist: Vec<f32>,
    /// Fractions per voxel, `k` consecutive values in model material order
    /// (empty when fractions were not asked for). Zero outside. `NaN` in a
    /// solid tile whose fractions vary, when the sampler was made
    /// [`Sampler::with_lazy_fractions`]: the consumer evaluates them.
    pub fracs: Vec<f32>,
    /// Fractions per voxel (`Model::materials().len()`).
    pub k: usize,
}

impl Slab {
    /// Fractions of voxel `v` (index within the slab).
    #[inline]
    pub fn fracs_of(&self, v: usize) -> &[f32] {
        &self.fracs[v * self.k..(v + 1) * self.k]
    }
}

/// Counts of how voxels were obtained (for reports and benchmarks).
#[derive(Debug, Default)]
pub struct SampleStats {
    /// Voxels whose distance was evaluated.
    pub evaluated: AtomicU64,
    /// Voxels filled from an interval bound without evaluation.
    pub skipped: AtomicU64,
}

/// Repeat `one` (a voxel's fractions) over `run`. The usual few materials
/// get a fixed-size copy the compiler turns into plain stores; a copy of
/// run-time length was a library call per voxel (a tenth of a graded mesh
/// export).
fn fill_pattern(run: &mut [f32], one: &[f32]) {
    fn fixed<const K: usize>(run: &mut [f32], one: &[f32]) {
        let mut p = [0.0; K];
        p.copy_from_slice(one);
        for v in run.chunks_exact_mut(K) {
            v.copy_from_slice(&p);
        }
    }
    match one.len() {
        1 => run.fill(one[0]),
        2 => fixed::<2>(run, one),
        3 => fixed::<3>(run, one),
        4 => fixed::<4>(run, one),
        k => {
            for v in run.chunks_exact_mut(k) {
                v.copy_from_slice(one);
            }
        }
    }
}

/// Voxels `[x0, x0 + w) × [y0, y0 + h)` of layer `z`.
#[derive(Clone, Copy)]
struct Rect {
    z: usize,
    x0: usize,
    y0: usize,
    w: usize,
    h: usize,
}

/// A task's buffers: rows from `row0` of one layer, `k` fractions a voxel.
struct Rows<'b> {
    row0: usize,
    dist: &'b mut [f32],
    fracs: &'b mut [f32],
    k: usize,
}

/// A consumer's test on fraction bounds: true when every fraction vector
/// within them means the same to it (a mesh export's segment label).
pub type UniformTest<'a> = &'a (dyn Fn(&[Interval]) -> bool + Sync);

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

impl<'a> Sampler<'a> {
    /// A sampler of `model` on `grid`; `with_fracs` also fills fractions.
    pub fn new(model: &'a Model, grid: Grid, with_fracs: bool) -> Self {
        Self {
            model,
            grid,
            with_fracs,
            uniform: None,
            lazy: false,
            stats: SampleStats::default(),
        }
    }

    /// For consumers that read only a function of the fractions (`test`
    /// says where it is constant): a solid tile whose fraction bounds, over
    /// the tile grown by one voxel on every side, pass `test` gets its
    /// centre's fractions in every voxel (one evaluation instead of one per
    /// voxel). Growing the box makes every neighbour of such a voxel agree
    /// too, so a mesher never interpolates across it: the mesh is the same
    /// as with every voxel sampled. Not for slice stacks, which dither the
    /// fractions themselves.
    pub fn with_uniform(mut self, test: UniformTest<'a>) -> Self {
        self.uniform = Some(test);
        self
    }

    /// The grid.
    pub fn grid(&self) -> &Grid {
        &self.grid
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
        // Tasks: one per block of TILE rows of one layer, so no task
        // straddles a layer.
        let layer = nx * ny;
        let block = nx * TILE;
        let mut tasks: Vec<(usize, usize, &mut [f32], &mut [f32])> = Vec::new();
        let mut frac_layers = slab.fracs.chunks_mut((layer * k).max(1));
        for (l, dl) in slab.dist.chunks_mut(layer).enumerate() {
            let fl: &mut [f32] = if k > 0 {
                frac_layers.next().unwrap_or_default()
            } else {
                &mut []
            };
            let mut frac_blocks = fl.chunks_mut((block * k).max(1));
            for (bi, d) in dl.chunks_mut(block).enumerate() {
                let f: &mut [f32] = if k > 0 {
                    frac_blocks.next().unwrap_or_default()
                } else {
                    &mut []
                };
                tasks.push((z0 + l, bi * TILE, d, f));
            }
        }
        tasks.into_par_iter().try_for_each(|(z, y0, dist, fr)| {
            if cancel.load(Ordering::Relaxed) {
                return Err(Cancelled);
            }
            let rows = dist.len() / nx;
            self.fill_rows(z, y0, rows, dist, fr, k);
            Ok(())
        })
    }

    /// Fill rows `y0..y0+rows` of layer `z`.
    fn fill_rows(
        &self,
        z: usize,
        y0: usize,
        rows: usize,
        dist: &mut [f32],
        fracs: &mut [f32],
        k: usize,
    ) {
        let nx = self.grid.dims[0];
        let mut out = Rows {
            row0: y0,
            dist,
            fracs,
            k,
        };
        let mut x0 = 0;
        while x0 < nx {
            let w = TILE.min(nx - x0);
            let r = Rect {
                z,
                x0,
                y0,
                w,
                h: rows,
            };
            self.tile(r, &mut out);
            x0 += w;
        }
    }

    /// For consumers that bound the fractions and evaluate them only where
    /// the bounds do not settle what they need (random dithering): a solid
    /// tile whose fractions vary, and which `Model::fraction_bounds` can
    /// bound, gets `NaN` fractions instead of one evaluation per voxel (see
    /// `Slab::fracs`). Nothing changes for a design whose fractions never
    /// vary (`Model::varying_fractions`).
    pub fn with_lazy_fractions(mut self) -> Self {
        // Piecewise-constant designs have nothing to leave lazy.
        self.lazy = self.model.varying_fractions();
        self
    }

    /// Refine tile `r` into `out`.
    fn tile(&self, r: Rect, out: &mut Rows) {
        let Rect { z, x0, y0, w, h } = r;
        let k = out.k;
        let row0 = out.row0;
        let nx = self.grid.dims[0];
        let b = self.grid.centres_box(x0, x0 + w - 1, y0, y0 + h - 1, z);
        let margin = self.grid.voxel.length();
        let iv = self.model.interval(&b);
        let filled = if iv.lo > margin {
            Some((iv.lo as f32, false))
        } else if iv.hi < -margin {
            Some((iv.hi as f32, true))
        } else {
            None
        };
        if let Some((value, inside)) = filled {
            let mut f = [0.0f64; MAX_MATERIALS];
            let mut constant = inside && k > 0 && self.model.constant_fractions(&b);
            if inside && k > 0 && !constant {
                match self.uniformity(&b, k) {
                    Uniformity::Same => constant = true,
                    Uniformity::Mixed if w > LEAF || h > LEAF => {
                        return self.split(r, out);
                    }
                    _ => {}
                }
            }
            let mut one = [0.0f32; MAX_MATERIALS];
            if constant {
                self.model.eval_into(b.center(), &mut f[..k]);
                for (o, v) in one.iter_mut().zip(&f[..k]) {
                    *o = *v as f32;
                }
            }
            // Lazy only where the consumer will be able to bound them.
            let lazy = inside && !constant && self.lazy && self.bounded(&b, k);
            for y in y0..y0 + h {
                let row = (y - row0) * nx;
                out.dist[row + x0..row + x0 + w].fill(value);
                if k == 0 {
                    continue;
                }
                // Whole runs at once where every voxel gets the same
                // fractions (a per-voxel `fill` was a library call each).
                let run = &mut out.fracs[(row + x0) * k..(row + x0 + w) * k];
                if !inside {
                    run.fill(0.0);
                } else if lazy {
                    run.fill(f32::NAN);
                } else if constant {
                    fill_pattern(run, &one[..k]);
                } else {
                    for (x, voxel) in (x0..).zip(run.chunks_exact_mut(k)) {
                        let p = self.grid.center(x, y, z);
                        self.model.fractions_inside(p, &mut f[..k]);
                        for (o, v) in voxel.iter_mut().zip(&f[..k]) {
                            *o = *v as f32;
                        }
                    }
                }
            }
            self.stats
                .skipped
                .fetch_add((w * h) as u64, Ordering::Relaxed);
            return;
        }
        if w > LEAF || h > LEAF {
            return self.split(r, out);
        }
        let mut f = [0.0f64; MAX_MATERIALS];
        for y in y0..y0 + h {
            let row = (y - row0) * nx;
            for x in x0..x0 + w {
                let p = self.grid.center(x, y, z);
                let v = row + x;
                if k > 0 {
                    out.dist[v] = self.model.eval_into(p, &mut f[..k]) as f32;
                    for (o, val) in out.fracs[v * k..(v + 1) * k].iter_mut().zip(&f[..k]) {
                        *o = *val as f32;
                    }
                } else {
                    out.dist[v] = self.model.distance(p) as f32;
                }
            }
        }
        self.stats
            .evaluated
            .fetch_add((w * h) as u64, Ordering::Relaxed);
    }
    /// Refine a tile as four quarters.
    fn split(&self, r: Rect, out: &mut Rows) {
        let (hw, hh) = (r.w.div_ceil(2), r.h.div_ceil(2));
        for (x0, w) in [(r.x0, hw), (r.x0 + hw, r.w - hw)] {
            for (y0, h) in [(r.y0, hh), (r.y0 + hh, r.h - hh)] {
                if w > 0 && h > 0 {
                    self.tile(Rect { x0, y0, w, h, ..r }, out);
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
