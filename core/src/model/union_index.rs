//! Spatial index over the children of a large union (the 3,286 struts of the
//! bunny lattice, the 144 swatches of the calibration sheet).
//!
//! Two structures over the children's bounding boxes:
//!
//! * a **uniform grid**: each cell lists (in child order) the children whose
//!   interval over the cell has a lower end below `margin` (two cell sizes).
//!   For a point in a cell, an unlisted child's value exceeds `margin`, so it
//!   cannot be the minimum when a listed child is below `margin`, and it
//!   cannot contain the point: "first child containing p" is found among the
//!   listed ones. Using the child's own interval (not its box) keeps long
//!   diagonal struts out of the cells they only pass near.
//! * a **BVH** for the rest: points outside the grid or with no listed child
//!   closer than `margin` get the exact minimum by nearest-first traversal
//!   that prunes subtrees whose box is farther than the best value so far.
//!
//! Both are built once at prepare time; queries allocate nothing.

use glam::DVec3;

use crate::aabb::Aabb;
use crate::spatial::cells::CellLattice;
use crate::spatial::round::f32_down;

/// Cell-list entries per child (on average) that the grid may hold before
/// its cells are made coarser, within [`MIN_ENTRIES`, `MAX_ENTRIES`]
/// (8 bytes each, twice while building). A child is listed in at least the
/// 5³ cells around it; struts of the bunny lattice in a few hundred.
const ENTRIES_PER_CHILD: usize = 1024;
const MIN_ENTRIES: usize = 1 << 24;
const MAX_ENTRIES: usize = 1 << 27;

/// Cells per axis for cubic cells of side `cell` over a box of `size`.
fn grid_dims(size: DVec3, cell: f64) -> [usize; 3] {
    [
        ((size.x / cell).ceil() as usize).clamp(1, 1024),
        ((size.y / cell).ceil() as usize).clamp(1, 1024),
        ((size.z / cell).ceil() as usize).clamp(1, 1024),
    ]
}

/// How many (child, cell) pairs the grid of `dims` over `grid_box` may
/// list: the cells of each finite child's box grown by the two-cell
/// margin (an upper bound of the lists' length; saturating).
fn covered_cells(
    boxes: &[Aabb],
    finite: &[u32],
    grid_box: Aabb,
    size: DVec3,
    dims: [usize; 3],
) -> usize {
    let d = DVec3::new(dims[0] as f64, dims[1] as f64, dims[2] as f64);
    let cell_size = size / d;
    let margin = 2.0 * cell_size.max_element();
    finite.iter().fold(0usize, |acc, &i| {
        let b = boxes[i as usize].expand(margin);
        let lo = ((b.min - grid_box.min) / cell_size)
            .floor()
            .max(DVec3::ZERO)
            .min(d - 1.0);
        let hi = ((b.max - grid_box.min) / cell_size)
            .floor()
            .max(DVec3::ZERO)
            .min(d - 1.0);
        let n = (hi - lo + 1.0).element_product();
        acc.saturating_add(n as usize)
    })
}

/// Grid + BVH over child boxes. Children with infinite boxes are kept in
/// `always` and visited for every query.
#[derive(Debug)]
pub struct UnionIndex {
    cells: CellLattice,
    /// Half the cells' diagonal, for [`UnionIndex::slack`].
    half_diagonal: f64,
    /// CSR: children of cell c are `entries[offsets[c]..offsets[c+1]]`,
    /// sorted by lower bound over the cell, so a query can stop once the
    /// next bound is above what it already found. Bound and index sit side
    /// by side: a query touches one cache line, not two arrays.
    offsets: Vec<u32>,
    entries: Vec<Entry>,
    margin: f64,
    always: Vec<u32>,
    bvh: Bvh,
}

/// One listed child of a cell.
#[derive(Debug, Clone, Copy)]
pub struct Entry {
    /// Lower bound of the child's value over the cell (rounded down to f32).
    pub lo: f32,
    /// The child's index in the union.
    pub child: u32,
}

/// What a query may visit: the listed children of the point's cell, or
/// `None` when the caller must fall back to the BVH.
pub enum Candidates<'a> {
    /// Children to test, ascending; `margin` bounds the unlisted ones.
    Cell {
        /// Listed children, by ascending lower bound.
        entries: &'a [Entry],
        /// Children with infinite boxes (ascending index).
        always: &'a [u32],
        /// Every unlisted finite child's value exceeds this.
        margin: f64,
        /// The cell's centre, for [`UnionIndex::slack`].
        centre: DVec3,
    },
    /// The point is outside the grid.
    Outside,
}

/// The per-child cell lists (`lists[k]`: child `finite[k]`'s cells and
/// lower bounds) as one list per cell in CSR form (cell `c`'s entries are
/// `entries[offsets[c]..offsets[c + 1]]`), each sorted by lower bound.
fn cell_lists(finite: &[u32], lists: &[Vec<(u32, f32)>], ncells: usize) -> (Vec<u32>, Vec<Entry>) {
    let mut offsets = vec![0u32; ncells + 1];
    for l in lists {
        for &(c, _) in l {
            offsets[c as usize + 1] += 1;
        }
    }
    for c in 0..ncells {
        offsets[c + 1] += offsets[c];
    }
    let mut fill = offsets.clone();
    let mut entries = vec![Entry { lo: 0.0, child: 0 }; offsets[ncells] as usize];
    for (&i, l) in finite.iter().zip(lists) {
        for &(c, lo) in l {
            entries[fill[c as usize] as usize] = Entry { lo, child: i };
            fill[c as usize] += 1;
        }
    }
    for c in 0..ncells {
        entries[offsets[c] as usize..offsets[c + 1] as usize]
            .sort_unstable_by_key(|e| crate::spatial::order::f32_then_index(e.lo, e.child));
    }
    (offsets, entries)
}

impl UnionIndex {
    /// Build over `boxes` (one per child, in child order). `lower_bound(i,
    /// cell)` must return a lower bound of child `i`'s value over `cell` (its
    /// interval's `lo`); a child is listed in a cell when that bound is below
    /// the margin, so an unlisted child's value exceeds the margin anywhere in
    /// the cell (this needs only sound intervals, no Lipschitz assumption).
    /// Callers that pass `d(centre) − half diagonal` of 1-Lipschitz children
    /// may also use [`UnionIndex::slack`].
    pub fn build(boxes: &[Aabb], lower_bound: impl Fn(usize, &Aabb) -> f64 + Sync) -> Self {
        let mut always = Vec::new();
        let mut finite: Vec<u32> = Vec::new();
        let mut grid_box = Aabb::EMPTY;
        for (i, b) in boxes.iter().enumerate() {
            if b.is_finite() {
                finite.push(i as u32);
                grid_box = grid_box.union(b);
            } else if !b.is_empty() {
                always.push(i as u32);
            }
        }
        // About 32 cubic cells per finite child, at most 2 million cells.
        // Finer grids list fewer candidates per cell (a point visits the
        // children within `|p − centre|` of its cell's centre) but outgrow
        // the caches and shrink the two-cell margin, beyond which points
        // take the BVH. Why 32 and not 16 or 44: docs/PERFORMANCE.md,
        // "Large unions".
        let n = finite.len().max(1) as f64;
        let size = grid_box.size().max(DVec3::splat(1e-9));
        let volume = size.x * size.y * size.z;
        let mut cell = (volume / (32.0 * n)).cbrt().max((volume / 2.0e6).cbrt());
        let mut dims = grid_dims(size, cell);
        // Children that overlap (a thousand coincident spheres) are each
        // listed in every cell: the lists grow as children × cells, so
        // quadratically in the children. Coarser cells until the lists'
        // upper bound (every cell of each child's box grown by the margin)
        // fits the budget; each coarsening costs the queries there
        // candidates, not correctness.
        let budget = (ENTRIES_PER_CHILD * finite.len()).clamp(MIN_ENTRIES, MAX_ENTRIES);
        for _ in 0..32 {
            let listed = covered_cells(boxes, &finite, grid_box, size, dims);
            if listed <= budget {
                break;
            }
            cell *= (listed as f64 / budget as f64).cbrt().max(1.25);
            dims = grid_dims(size, cell);
        }
        let cell_size = size / DVec3::new(dims[0] as f64, dims[1] as f64, dims[2] as f64);
        // Two cells: points within two cells of a child never need the BVH;
        // lists are sorted by lower bound, so long lists cost little.
        let margin = 2.0 * cell_size.max_element();
        let inv_cell = DVec3::ONE / cell_size;
        let lattice = CellLattice::new(grid_box.min, cell_size, dims);
        let ncells = lattice.slots();
        let cell_range = |b: &Aabb| {
            let lo = ((b.min - grid_box.min) * inv_cell).floor();
            let hi = ((b.max - grid_box.min) * inv_cell).floor();
            let clamp = |v: f64, d: usize| (v.max(0.0) as usize).min(d - 1);
            (
                [
                    clamp(lo.x, dims[0]),
                    clamp(lo.y, dims[1]),
                    clamp(lo.z, dims[2]),
                ],
                [
                    clamp(hi.x, dims[0]),
                    clamp(hi.y, dims[1]),
                    clamp(hi.z, dims[2]),
                ],
            )
        };
        let cell_box = |x: usize, y: usize, z: usize| {
            let lo = grid_box.min + DVec3::new(x as f64, y as f64, z as f64) * cell_size;
            Aabb::new(lo, lo + cell_size)
        };
        // Per child (in parallel), the cells it is listed in; then CSR in
        // child order per cell.
        use rayon::prelude::*;
        let lists: Vec<Vec<(u32, f32)>> = finite
            .par_iter()
            .map(|&i| {
                let (lo, hi) = cell_range(&boxes[i as usize].expand(margin));
                let mut cells = Vec::new();
                // Blocks of 4³ cells first: a block whose bound is already
                // above the margin is skipped whole (long diagonal struts
                // touch few of the cells in their box).
                const B: usize = 4;
                for bz in (lo[2]..=hi[2]).step_by(B) {
                    for by in (lo[1]..=hi[1]).step_by(B) {
                        for bx in (lo[0]..=hi[0]).step_by(B) {
                            let ex = (bx + B - 1).min(hi[0]);
                            let ey = (by + B - 1).min(hi[1]);
                            let ez = (bz + B - 1).min(hi[2]);
                            let block = cell_box(bx, by, bz).union(&cell_box(ex, ey, ez));
                            if lower_bound(i as usize, &block) >= margin {
                                continue;
                            }
                            for z in bz..=ez {
                                for y in by..=ey {
                                    for x in bx..=ex {
                                        let lo = lower_bound(i as usize, &cell_box(x, y, z));
                                        if lo < margin {
                                            cells.push((
                                                lattice.index([x, y, z]) as u32,
                                                f32_down(lo),
                                            ));
                                        }
                                    }
                                }
                            }
                        }
                    }
                }
                cells
            })
            .collect();
        let (offsets, entries) = cell_lists(&finite, &lists, ncells);
        let bvh = Bvh::build(boxes, &finite);
        Self {
            cells: lattice,
            half_diagonal: 0.5 * cell_size.length(),
            offsets,
            entries,
            margin,
            always,
            bvh,
        }
    }

    /// The candidates for point `p`.
    #[inline]
    pub fn candidates(&self, p: DVec3) -> Candidates<'_> {
        // Points on the grid box's upper faces belong to no cell: the BVH
        // answers them, exactly as well.
        let Some((c, xyz)) = self.cells.locate(p) else {
            return Candidates::Outside;
        };
        let (a, b) = (self.offsets[c] as usize, self.offsets[c + 1] as usize);
        Candidates::Cell {
            entries: &self.entries[a..b],
            always: &self.always,
            margin: self.margin,
            centre: self.cells.centre(xyz),
        }
    }

    /// `r − |p − c|` (rounded down) for the cell centre `c` of `p` and the
    /// cells' half diagonal `r`. When the bounds were built as `d(c) − r`
    /// of 1-Lipschitz children, a child's value at `p` is at least
    /// `lo + slack` (`d(p) ≥ d(c) − |p − c|`): a tighter stop for a query.
    #[inline]
    pub fn slack(&self, p: DVec3, centre: DVec3) -> f64 {
        let r = self.half_diagonal;
        (r - p.distance(centre)).max(0.0) - 1e-12 * r
    }

    /// Children with infinite boxes.
    pub fn always(&self) -> &[u32] {
        &self.always
    }

    /// The BVH over finite children.
    pub fn bvh(&self) -> &Bvh {
        &self.bvh
    }
}

/// A flattened binary BVH over child boxes (median split on the longest axis).
#[derive(Debug, Default)]
pub struct Bvh {
    nodes: Vec<BvhNode>,
    /// Child indices, leaves point into ranges of this.
    order: Vec<u32>,
}

#[derive(Debug, Clone, Copy)]
struct BvhNode {
    bbox: Aabb,
    /// Leaf: first index into `order`; inner: index of the right child (left is next).
    first_or_right: u32,
    /// Leaf: count (> 0); inner: 0.
    count: u32,
}

const LEAF_SIZE: usize = 4;

impl Bvh {
    /// Build over the children `ids` with boxes `boxes[id]`.
    pub fn build(boxes: &[Aabb], ids: &[u32]) -> Self {
        let mut order = ids.to_vec();
        let mut nodes = Vec::with_capacity(2 * ids.len() / LEAF_SIZE + 1);
        if !order.is_empty() {
            let n = order.len();
            build_rec(boxes, &mut order, 0, n, &mut nodes);
        }
        Self { nodes, order }
    }

    /// Visit children in near-to-far-ish order, pruning subtrees whose box is
    /// farther than the bound `visit` returns (it is called with a child
    /// index and returns the new pruning distance).
    pub fn nearest(&self, p: DVec3, bound: f64, mut visit: impl FnMut(u32) -> f64) {
        let mut bound = bound;
        self.walk(
            &mut bound,
            |bound, bbox| bbox.distance(p) > *bound,
            |bound, c| *bound = bound.min(visit(c)),
            |nodes, left, right| {
                let dl = nodes[left as usize].bbox.distance_squared(p);
                let dr = nodes[right as usize].bbox.distance_squared(p);
                // Push the farther first so the nearer is visited first.
                if dl < dr {
                    (right, left)
                } else {
                    (left, right)
                }
            },
        );
    }

    /// Visit every child whose box overlaps `b`.
    pub fn overlapping(&self, b: &Aabb, mut visit: impl FnMut(u32)) {
        self.walk(
            &mut (),
            |(), bbox| !bbox.overlaps(b),
            |(), c| visit(c),
            |_, left, right| (left, right),
        );
    }

    /// The depth-first walk of both queries: a node is skipped when
    /// `prune(state, its box)`, a leaf's children go to `leaf` in order, and
    /// an inner node's two halves are pushed in the order `push` gives (the
    /// second is visited first). The stack's 64 entries outnumber the
    /// depth of any tree `build` makes: its median splits halve `u32` ids.
    #[inline(always)]
    fn walk<S>(
        &self,
        state: &mut S,
        prune: impl Fn(&S, &Aabb) -> bool,
        mut leaf: impl FnMut(&mut S, u32),
        push: impl Fn(&[BvhNode], u32, u32) -> (u32, u32),
    ) {
        if self.nodes.is_empty() {
            return;
        }
        let mut stack: [u32; 64] = [0; 64];
        let mut sp = 1usize;
        while sp > 0 {
            sp -= 1;
            let idx = stack[sp];
            let node = &self.nodes[idx as usize];
            if prune(state, &node.bbox) {
                continue;
            }
            if node.count > 0 {
                let a = node.first_or_right as usize;
                for &c in &self.order[a..a + node.count as usize] {
                    leaf(state, c);
                }
            } else if sp + 2 <= stack.len() {
                (stack[sp], stack[sp + 1]) = push(&self.nodes, idx + 1, node.first_or_right);
                sp += 2;
            }
        }
    }
}

fn build_rec(
    boxes: &[Aabb],
    order: &mut [u32],
    start: usize,
    end: usize,
    nodes: &mut Vec<BvhNode>,
) {
    let mut bbox = Aabb::EMPTY;
    for &i in &order[start..end] {
        bbox = bbox.union(&boxes[i as usize]);
    }
    let me = nodes.len();
    nodes.push(BvhNode {
        bbox,
        first_or_right: start as u32,
        count: (end - start) as u32,
    });
    if end - start <= LEAF_SIZE {
        return;
    }
    let size = bbox.size();
    let axis = if size.x >= size.y && size.x >= size.z {
        0
    } else if size.y >= size.z {
        1
    } else {
        2
    };
    let mid = (start + end) / 2;
    order[start..end].select_nth_unstable_by(mid - start, |a, b| {
        let ca = boxes[*a as usize].center()[axis];
        let cb = boxes[*b as usize].center()[axis];
        ca.total_cmp(&cb)
    });
    build_rec(boxes, order, start, mid, nodes);
    let right = nodes.len() as u32;
    build_rec(boxes, order, mid, end, nodes);
    nodes[me].first_or_right = right;
    nodes[me].count = 0;
}
