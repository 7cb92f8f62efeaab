//! The caller-owned [`Slab`] of samples, and how a slab is cut into the
//! sampler's tasks: rows of tiles, layer by layer, merged back in task
//! order so the result is the same on any thread count.

use super::TILE;

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
    /// (empty when fractions were not asked for). Zero outside, except for
    /// [`super::Consumer::MeshContour`] (left as they were). `NaN` in a
    /// voxel of a solid tile a surface crosses whose fractions vary, for
    /// [`super::Consumer::PngStackRandom`]: the consumer evaluates them.
    pub fracs: Vec<f32>,
    /// Fractions per voxel (`Model::materials().len()`).
    pub k: usize,
    /// Rectangles of solid voxels, by layer then row block: for
    /// [`super::Consumer::MeshContour`], those that share one fraction
    /// vector, `rect_fracs[at..at + k]`; for
    /// [`super::Consumer::PngStackRandom`], solid tiles whose fractions the
    /// consumer evaluates (`rect_fracs` all `NaN`). Their voxels' entries
    /// in `fracs` are not written (they hold whatever the buffer held).
    /// [`Slab::rect_rows`] lists them row by row.
    pub rects: Vec<SolidRect>,
    /// Fraction vectors of `rects`, `k` values each.
    pub rect_fracs: Vec<f32>,
}

/// Voxels `[x0, x0 + w) × [y0, y0 + h)` of layer `z`, all inside the part
/// and all with the fractions at `Slab::rect_fracs[at..at + k]`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SolidRect {
    /// Global layer.
    pub z: usize,
    /// First column.
    pub x0: usize,
    /// First row.
    pub y0: usize,
    /// Columns.
    pub w: usize,
    /// Rows.
    pub h: usize,
    /// Offset of its fractions in `Slab::rect_fracs`.
    pub at: usize,
}

impl Slab {
    /// Fractions of voxel `v` (index within the slab).
    #[inline]
    pub fn fracs_of(&self, v: usize) -> &[f32] {
        &self.fracs[v * self.k..(v + 1) * self.k]
    }

    /// The rectangles of layer `z` (`nx × ny` voxels), as runs row by row:
    /// `rects` is their range in [`Slab::rects`].
    pub fn rect_rows(&self, z: usize, nx: usize, ny: usize) -> RectRows {
        // The sampler lists rectangles by layer.
        let lo = self.rects.partition_point(|r| r.z < z);
        let hi = self.rects.partition_point(|r| r.z <= z);
        let rects = &self.rects[lo..hi];
        // Counting sort by row. Within a row the sampler's order (tiles left
        // to right, quadrants left before right) is already by column; the
        // check below keeps that an optimisation, not an assumption.
        let rows = |r: &SolidRect| r.y0.min(ny)..(r.y0 + r.h).min(ny);
        let mut first = vec![0usize; ny + 1];
        for r in rects {
            for y in rows(r) {
                first[y + 1] += 1;
            }
        }
        for y in 0..ny {
            first[y + 1] += first[y];
        }
        let mut fill = first.clone();
        let mut spans = vec![RowSpan::default(); first[ny]];
        for (i, r) in rects.iter().enumerate() {
            for y in rows(r) {
                spans[fill[y]] = RowSpan {
                    x0: r.x0,
                    x1: (r.x0 + r.w).min(nx),
                    rect: i,
                };
                fill[y] += 1;
            }
        }
        for y in 0..ny {
            let row = &mut spans[first[y]..first[y + 1]];
            if !row.is_sorted_by_key(|s| s.x0) {
                row.sort_unstable_by_key(|s| s.x0);
            }
        }
        RectRows {
            rects: lo..hi,
            first,
            spans,
        }
    }
}

/// One layer's [`SolidRect`]s as runs, row by row ([`Slab::rect_rows`]).
#[derive(Clone, Debug, Default)]
pub struct RectRows {
    /// The layer's rectangles: their range in [`Slab::rects`].
    pub rects: std::ops::Range<usize>,
    /// Row `y`'s runs are `spans[first[y]..first[y + 1]]`.
    first: Vec<usize>,
    spans: Vec<RowSpan>,
}

impl RectRows {
    /// Row `y`'s runs, by column (none when the layer has no rectangle).
    #[inline]
    pub fn row(&self, y: usize) -> &[RowSpan] {
        match self.first.get(y + 1) {
            Some(&end) => &self.spans[self.first[y]..end],
            None => &[],
        }
    }
}

/// Columns `x0..x1` of one row inside rectangle `rect` (counted from the
/// layer's first, see [`RectRows::rects`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RowSpan {
    /// First column.
    pub x0: usize,
    /// Past the last column.
    pub x1: usize,
    /// The rectangle, among the layer's.
    pub rect: usize,
}

/// Repeat `one` (a voxel's fractions, or a mesh label's interface values)
/// over `run`. The usual few materials get a fixed-size copy the compiler
/// turns into plain stores; a copy of run-time length was a library call
/// per voxel (a tenth of a graded mesh export). An empty `one` writes
/// nothing.
pub fn fill_pattern(run: &mut [f32], one: &[f32]) {
    fn fixed<const K: usize>(run: &mut [f32], one: &[f32]) {
        let mut p = [0.0; K];
        p.copy_from_slice(one);
        for v in run.chunks_exact_mut(K) {
            v.copy_from_slice(&p);
        }
    }
    match one.len() {
        0 => {}
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

/// `run.fill(v)` as plain stores: for zeros `fill` calls the library's
/// `memset`, which costs more than the stores themselves on the few voxels
/// of a leaf's row or a small settled tile's (millions of calls on a
/// lattice).
#[inline]
pub(super) fn fill_short(run: &mut [f32], v: f32) {
    // (Hidden from the optimiser, the value cannot be seen to be zero and
    // the loop is not turned back into that call.)
    let v = std::hint::black_box(v);
    for x in run {
        *x = v;
    }
}

/// `run.fill(v)` for a row of a settled tile: the widths tiles have (4,
/// 8, 16, 32) as whole-array stores, where the general loop spent more on
/// its setup and remainder than on the stores (millions of rows).
#[inline]
pub(super) fn fill_run(run: &mut [f32], v: f32) {
    fn fixed<const N: usize>(run: &mut [f32], v: f32) {
        if let Ok(a) = <&mut [f32; N]>::try_from(run) {
            *a = [v; N];
        }
    }
    match run.len() {
        4 => fixed::<4>(run, v),
        8 => fixed::<8>(run, v),
        16 => fixed::<16>(run, v),
        32 => fixed::<32>(run, v),
        _ => run.fill(v),
    }
}

/// Voxels `[x0, x0 + w) × [y0, y0 + h)` of layer `z`.
///
/// Packed into two integers (a grid has at most `u32::MAX` voxels along
/// an axis, a tile at most `TILE` along a side): a pair of scalars is
/// passed in registers, where five fields went through memory, written by
/// the caller and read back at the top of every call of the quadtree.
#[derive(Clone, Copy)]
pub(super) struct Rect {
    /// `z` in the high half, `x0` in the low.
    zx: u64,
    /// `y0` in the high half, then `w` and `h` (16 bits each).
    ywh: u64,
}

impl Rect {
    /// The rectangle `[x0, x0 + w) × [y0, y0 + h)` of layer `z`.
    #[inline(always)]
    pub fn new(z: usize, x0: usize, y0: usize, w: usize, h: usize) -> Self {
        debug_assert!(w <= TILE && h <= TILE && x0.max(y0).max(z) <= u32::MAX as usize);
        Self {
            zx: (z as u64) << 32 | x0 as u64,
            ywh: (y0 as u64) << 32 | (w as u64) << 16 | h as u64,
        }
    }

    /// `(z, x0, y0, w, h)`.
    #[inline(always)]
    pub fn parts(self) -> (usize, usize, usize, usize, usize) {
        (
            (self.zx >> 32) as usize,
            (self.zx & 0xffff_ffff) as usize,
            (self.ywh >> 32) as usize,
            ((self.ywh >> 16) & 0xffff) as usize,
            (self.ywh & 0xffff) as usize,
        )
    }
}

/// Column ranges `(x0, w)` of the tiles across a row of `nx` voxels.
pub(super) fn x_tiles(nx: usize) -> impl Iterator<Item = (usize, usize)> {
    (0..nx).step_by(TILE).map(move |x0| (x0, TILE.min(nx - x0)))
}

/// Each layer's rows of `dist` and `fracs` (`nx × ny` a layer, `k`
/// fractions a voxel) cut into blocks of TILE rows, layer by layer: the
/// sampler's tasks, with the layer's index in the slab.
pub(super) fn row_blocks<'b>(
    dist: &'b mut [f32],
    fracs: &'b mut [f32],
    nx: usize,
    ny: usize,
    k: usize,
) -> Vec<(usize, Rows<'b>)> {
    let (layer, block) = (nx * ny, nx * TILE);
    let mut out = Vec::new();
    // No fractions (k = 0): every task gets an empty slice.
    let next = |it: &mut std::slice::ChunksMut<'b, f32>| it.next().filter(|_| k > 0);
    let mut frac_layers = fracs.chunks_mut((layer * k).max(1));
    for (l, dl) in dist.chunks_mut(layer).enumerate() {
        let fl = next(&mut frac_layers).unwrap_or_default();
        let mut frac_blocks = fl.chunks_mut((block * k).max(1));
        for (bi, d) in dl.chunks_mut(block).enumerate() {
            let f = next(&mut frac_blocks).unwrap_or_default();
            let rows = Rows {
                row0: bi * TILE,
                dist: d,
                fracs: f,
                k,
                rects: Vec::new(),
                rect_fracs: Vec::new(),
                counts: Counts::default(),
            };
            out.push((l, rows));
        }
    }
    out
}

/// The tasks' rectangles into `rects` and `fracs`, in task order (layer, then row
/// block: the same on any thread count), with offsets into one array.
pub(super) fn merge_rects(done: Vec<Rows>, rects: &mut Vec<SolidRect>, fracs: &mut Vec<f32>) {
    rects.clear();
    fracs.clear();
    for out in done {
        let base = fracs.len();
        rects.extend(out.rects.into_iter().map(|r| SolidRect {
            at: r.at + base,
            ..r
        }));
        fracs.extend_from_slice(&out.rect_fracs);
    }
}

/// A task's buffers: rows from `row0` of one layer, `k` fractions a voxel.
pub(super) struct Rows<'b> {
    pub row0: usize,
    pub dist: &'b mut [f32],
    pub fracs: &'b mut [f32],
    pub k: usize,
    /// Solid rectangles found (for [`super::Consumer::MeshContour`]), with
    /// their fractions `k` apiece (`at` counts from this task's first).
    pub rects: Vec<SolidRect>,
    pub rect_fracs: Vec<f32>,
    /// What this task did, added to the sampler's statistics once the
    /// slab is done.
    pub counts: Counts,
}

/// A task's share of [`super::SampleStats`], counted without atomics: the
/// counters are shared by every thread, and adding to them per tile (a
/// few dozen voxels) kept their cache line moving between the cores,
/// next to fields every voxel reads. Counted per task, they cost about
/// what no statistics at all would.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Counts {
    pub evaluated: u64,
    pub skipped: u64,
    pub solid_blocks: u64,
    pub shared: u64,
}
