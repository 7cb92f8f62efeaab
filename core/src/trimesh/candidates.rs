//! A grid of per-cell candidate lists: for every cell near the surface, the
//! few triangles that can be nearest to some point of the cell. An exact
//! distance query in such a cell tests those triangles and no tree.
//!
//! Why it is exact: let `c` be the cell's centre, `r` its half diagonal and
//! `u = d(c)` the exact unsigned distance there. For `p` in the cell, the
//! nearest triangle `t*` satisfies `d(p, t*) ≤ d(p) ≤ u + r`, hence
//! `d(c, t*) ≤ d(p, t*) + r ≤ u + 2r`. So the triangles with
//! `d(c, t) ≤ u + 2r` include `t*` for every point of the cell. Kept sorted
//! by `d(c, t)` (stored rounded down), a query stops at the first `t` with
//! `d(c, t) − |p − c|` above the best distance so far (a lower bound of
//! `d(p, t)` and of every later one).
//!
//! Most of a walk proves that a neighbour of the first candidate `t₁` is
//! not nearer. Each entry carries bits, set at build time, that say where
//! it lies relative to `t₁` (its plane and its edges); a query that stands
//! over `t₁`'s face, an edge or a vertex skips the entries those bits prove
//! no nearer, without reading their triangles (see [`super::certificate`]).
//!
//! The sign: when `u > r` no point of the cell is on the surface (the SDF
//! is 1-Lipschitz), so the whole cell has the sign of `d(c)` and the query
//! skips the pseudo-normal test.
//!
//! Cells whose list would be long (deep inside, far outside) keep no list;
//! those points use the BVH as before. Built once per mesh, in parallel.

use glam::DVec3;
use rayon::prelude::*;

use super::TriangleMesh;
use super::certificate::{self, Skips};
use super::triangle::Feature;
use crate::aabb::Aabb;
use crate::spatial::cells::CellLattice;
use crate::spatial::round::f32_down;

/// Fewest cells along the longest side of the mesh box. Finer cells mean
/// shorter lists (fewer exact triangle tests per query) for more build
/// time; see docs/PERFORMANCE.md, "Mesh distance", for how the choice is
/// measured.
const CELLS: f64 = 128.0;
/// Fewest triangles for which a grid is built (see [`CandidateGrid::new`]).
const MIN_TRIANGLES: usize = 64;
/// Most cells in one grid (5 bytes each plus the lists).
const MAX_TOTAL: f64 = 4.0e6;
/// Cells farther than this many cell sizes from the surface keep no list.
/// With `PAD`, it keeps the reach of the lists (about 2.5 mm on the bunny)
/// when the cells got finer: points a few voxels from the surface, inside
/// or outside the mesh box, still skip the BVH.
const FAR: f64 = 3.5;
/// Cells of padding around the mesh box.
const PAD: f64 = 4.0;
/// Longest block list (2×2×2 cells) gathered; beyond it the cells keep none.
const MAX_BLOCK: usize = 160;
/// Longest list kept; cells that need more fall back to the BVH.
const MAX_LIST: usize = 40;

/// What [`CandidateGrid::nearest_unless_within`] finds.
#[derive(Clone, Copy, Debug)]
pub enum Near {
    /// The first triangle's squared distance, within the asked radius.
    Within(f64),
    /// The nearest triangle's slot and squared distance, and the side
    /// (as [`CandidateGrid::nearest`]).
    Nearest(usize, f64, i8),
}

/// One candidate: the triangle slot and `d(c, t)` rounded down to `f32`.
#[derive(Clone, Copy, Debug)]
struct Candidate {
    dc: f32,
    slot: u32,
}

/// The grid, packed: a packed list is half the size of one of
/// `Candidate`s, and the walk stops on an integer compare.
///
/// `records[i]`: the start of cell `i`'s list in `items` (low 30 bits) and
/// its side plus one (high 2 bits: 0 inside, 1 unknown, 2 outside; also
/// kept for a cell whose list was too long to keep); the list ends where
/// cell `i + 1`'s starts. An empty list means "no list, ask the BVH".
///
/// `items`: one `u32` per candidate, the triangle slot in the low
/// `slot_bits` bits, then its certificate bits (when there is room, see
/// [`super::certificate`]), and `q = ⌊d(c, t) / unit⌋` above them, so
/// `q · unit ≤ d(c, t)` stays a lower bound (a coarser one than the exact
/// distance, which only means the query may test a triangle more; the
/// answer is the same).
#[derive(Clone, Debug)]
pub(crate) struct CandidateGrid {
    pub(super) cells: CellLattice,
    pub(super) records: Vec<u32>,
    pub(super) items: Vec<u32>,
    pub(super) slot_bits: u32,
    /// Bit position of `q` in an item.
    pub(super) q_shift: u32,
    /// The certificate bits a query point needs of an entry to skip it.
    pub(super) skips: Skips,
    /// One over the length of one step of the packed distance (mm⁻¹),
    /// times `1 + 10⁻⁹`.
    pub(super) inv_unit: f64,
    /// `1e-12` cell sizes: absolute slack on `|p − c|`.
    pub(super) tiny: f64,
}

/// Fewest bits of `q` for which an item also keeps certificate bits:
/// meshes of up to 65,536 triangles keep them (larger ones keep the
/// layout without, and walk more). On the bunny, whose 3,674 triangles
/// leave 12 bits, 8 bits (steps of 1/256 of the longest reach, 11 µm)
/// changed the bench by less than its noise.
const MIN_Q_BITS: u32 = 8;

/// Whether items with `slot_bits` of slot keep certificate bits.
pub(super) fn certified(slot_bits: u32) -> bool {
    slot_bits + certificate::BITS + MIN_Q_BITS <= 32
}

/// The constants that shape a built grid: a cached grid built with other
/// values is not this build's grid (`super::grid_cache` keys on them).
pub(super) const SHAPE: [f64; 8] = [
    CELLS,
    MAX_TOTAL,
    FAR,
    PAD,
    MAX_BLOCK as f64,
    MAX_LIST as f64,
    MIN_Q_BITS as f64,
    certificate::BITS as f64,
];

/// Bits of a cell record that hold the list's start.
const START_BITS: u32 = 30;
const START_MASK: u32 = (1 << START_BITS) - 1;

/// The side stored in a cell record: −1, 0 (unknown) or +1.
#[inline(always)]
fn side_of(record: u32) -> i8 {
    (record >> START_BITS) as i8 - 1
}

/// `v` grown by a relative and an absolute margin, so list reaches stay
/// conservative under rounding.
#[inline]
fn slack(v: f64, extent: f64) -> f64 {
    v * (1.0 + 1e-9) + 1e-12 * extent
}

/// The cell size: about a typical triangle across (sqrt(area / count)), and
/// at least `CELLS` along the longest side, so lists stay short for coarse
/// meshes (few big faces) and fine ones; finer than a triangle costs more
/// to build than it saves. At most `MAX_TOTAL` cells.
fn cell_size(mesh: &TriangleMesh, extent: f64) -> f64 {
    let area: f64 = mesh
        .tris
        .iter()
        .map(|t| 0.5 * t.ab.cross(t.ac).length())
        .sum();
    let typical = (area / mesh.tris.len() as f64).sqrt();
    let size = mesh.bbox.size();
    let mut cell = (extent / CELLS).min(typical).max(extent * 1e-6);
    let cells_for = |c: f64| {
        let n = (size + DVec3::splat(2.0 * PAD * c)) / c;
        n.x.ceil() * n.y.ceil() * n.z.ceil()
    };
    while cells_for(cell) > MAX_TOTAL {
        cell *= 1.25;
    }
    cell
}

/// Every cell's side and candidate list, by 2×2×2 blocks in parallel.
///
/// Per block: one BVH range query for all eight cells. A cell's list
/// needs d(c_i, t) ≤ u_i + 2r; with |c_i − c_B| = r and u_i ≤ U + r, those
/// t have d(c_B, t) ≤ U + 4r, so the block's list holds every cell's list
/// and every cell's nearest triangle.
fn gather_lists(
    mesh: &TriangleMesh,
    lattice: &CellLattice,
    min: DVec3,
    cell: f64,
    extent: f64,
) -> Vec<(i8, Vec<Candidate>)> {
    let dims = lattice.dims();
    let bdims = [dims[0] / 2, dims[1] / 2, dims[2] / 2];
    let block_of = |bi: usize| {
        (
            bi % bdims[0],
            bi / bdims[0] % bdims[1],
            bi / (bdims[0] * bdims[1]),
        )
    };
    let blocks: Vec<[(i8, Vec<Candidate>); 8]> = (0..bdims[0] * bdims[1] * bdims[2])
        .into_par_iter()
        .map(|bi| {
            let (bx, by, bz) = block_of(bi);
            block_lists(mesh, block_corner(min, cell, [bx, by, bz]), cell, extent)
        })
        .collect();
    let mut lists: Vec<(i8, Vec<Candidate>)> = vec![(0, Vec::new()); lattice.slots()];
    for (bi, block) in blocks.into_iter().enumerate() {
        let (bx, by, bz) = block_of(bi);
        for (k, l) in block.into_iter().enumerate() {
            let (x, y, z) = (2 * bx + (k & 1), 2 * by + (k >> 1 & 1), 2 * bz + (k >> 2));
            lists[lattice.index([x, y, z])] = l;
        }
    }
    lists
}

/// The eight cells' sides and lists of the block whose lowest corner is
/// `corner` (see [`gather_lists`]).
fn block_lists(
    mesh: &TriangleMesh,
    corner: DVec3,
    cell: f64,
    extent: f64,
) -> [(i8, Vec<Candidate>); 8] {
    let r = half_diagonal(cell);
    let cb = corner + DVec3::splat(cell);
    let mut out: [(i8, Vec<Candidate>); 8] = Default::default();
    // Blocks the coarse grid proves far from the surface keep no
    // lists (their points are rarely asked; the BVH answers them).
    if let Some((dc, rr)) = mesh.coarse.as_ref().and_then(|g| g.lookup(cb))
        && dc.abs() - rr - 2.0 * r > FAR * cell
    {
        return out;
    }
    let u_block = mesh.distance(cb);
    if u_block - 2.0 * r > FAR * cell {
        return out; // far from the surface too
    }
    let Some(block) = mesh.within(cb, slack(u_block + 4.0 * r, extent), MAX_BLOCK) else {
        return out;
    };
    let mut d2s = vec![0.0; block.len()];
    for (k, o) in out.iter_mut().enumerate() {
        let c = build_centre(corner, cell, k);
        let mut best = (f64::INFINITY, 0usize);
        for (d2, e) in d2s.iter_mut().zip(&block) {
            *d2 = mesh.tris[e.slot as usize].distance_squared(c);
            if *d2 < best.0 {
                best = (*d2, e.slot as usize);
            }
        }
        let u = best.0.sqrt();
        // No point of the cell is on the surface when u > r
        // (1-Lipschitz), so the cell has the centre's side.
        let side = if u > r * (1.0 + 1e-9) {
            if mesh.sign_at(c, best.1) < 0.0 { -1 } else { 1 }
        } else {
            0
        };
        let reach2 = slack(u + 2.0 * r, extent).powi(2);
        // Counted first, so a list is one allocation of its
        // size (collected through the filter, the lists grew
        // by doubling, reallocating again and again),
        // and a list too long to keep none.
        let kept = |d2: &f64| *d2 <= reach2;
        let n = d2s.iter().filter(|d2| kept(d2)).count();
        let mut list = Vec::new();
        if n <= MAX_LIST {
            list.reserve_exact(n);
            list.extend(
                d2s.iter()
                    .zip(&block)
                    .filter(|(d2, _)| kept(d2))
                    .map(|(d2, e)| Candidate {
                        dc: f32_down(d2.sqrt()),
                        slot: e.slot,
                    }),
            );
        }
        *o = (side, list);
    }
    out
}

/// How lists are packed into `u32` items: quantised distance above the
/// certificate bits above the triangle slot.
struct Packing {
    slot_bits: u32,
    q_shift: u32,
    certified: bool,
    unit: f64,
    /// `1 / unit`.
    inv: f64,
    steps: u64,
    tol: f64,
}

impl Packing {
    /// One packed item: `⌊dc / unit⌋` or one less, never more (stepped down
    /// where rounding went one too far; `i64`, whose conversions are single
    /// instructions), then `bits`, then the slot.
    fn item(&self, c: &Candidate, bits: u32) -> u32 {
        let dc = f64::from(c.dc);
        let mut q = ((dc * self.inv) as i64).clamp(0, self.steps as i64);
        while q > 0 && q as f64 * self.unit > dc {
            q -= 1;
        }
        ((q as u32) << self.q_shift) | (bits << self.slot_bits) | c.slot
    }

    /// The cell records and the packed items of `lists` (`total` entries),
    /// which are sorted and freed. Sorted, packed and freed in parallel, by
    /// runs of cells whose packed items are one contiguous slice.
    fn pack(
        &self,
        mesh: &TriangleMesh,
        lists: &mut [(i8, Vec<Candidate>)],
        total: usize,
    ) -> (Vec<u32>, Vec<u32>) {
        let mut records = Vec::with_capacity(lists.len() + 1);
        let mut start = 0u32;
        for (s, l) in lists.iter() {
            records.push(start | (((s + 1) as u32) << START_BITS));
            start += l.len() as u32;
        }
        records.push(start);
        let mut items = vec![0u32; total];
        let mut tasks = Vec::new();
        let mut rest: &mut [u32] = &mut items;
        for cells in lists.chunks_mut(1 << 12) {
            let n = cells.iter().map(|l| l.1.len()).sum();
            let (head, tail) = std::mem::take(&mut rest).split_at_mut(n);
            tasks.push((cells, head));
            rest = tail;
        }
        tasks.into_par_iter().for_each(|(cells, out)| {
            let mut k = 0;
            for (_, l) in cells {
                l.sort_unstable_by_key(|c| crate::spatial::order::f32_then_index(c.dc, c.slot));
                let frame = l
                    .first()
                    .filter(|_| self.certified)
                    .and_then(|c| certificate::Frame::new(&mesh.tris[c.slot as usize], self.tol));
                for c in l.iter() {
                    let bits = frame
                        .as_ref()
                        .map_or(0, |f| f.bits(&mesh.tris[c.slot as usize]));
                    out[k] = self.item(c, bits);
                    k += 1;
                }
                *l = Vec::new();
            }
        });
        (records, items)
    }
}

impl CandidateGrid {
    /// Builds the grid over the mesh box padded by two cells. `mesh` must
    /// answer exact queries through its BVH (this grid is not yet attached).
    pub fn new(mesh: &TriangleMesh) -> Option<CandidateGrid> {
        // A handful of triangles: the BVH answers as fast as a list would,
        // while the grid's build grows with its cells (up to `MAX_TOTAL`),
        // not with the triangles.
        if mesh.triangles.len() < MIN_TRIANGLES {
            return None;
        }
        let b = mesh.bbox;
        let extent = b.size().max_element();
        if !(extent > 0.0 && extent.is_finite()) {
            return None;
        }
        let cell = cell_size(mesh, extent);
        let min = b.min - DVec3::splat(PAD * cell);
        // Dimensions rounded up to even: cells are built in 2×2×2 blocks.
        let n = ((b.max + DVec3::splat(PAD * cell) - min) / cell / 2.0).ceil() * 2.0;
        let dims = [n.x as usize, n.y as usize, n.z as usize];
        let lattice = CellLattice::new(min, DVec3::splat(cell), dims);
        let mut lists = gather_lists(mesh, &lattice, min, cell, extent);
        let total: usize = lists.iter().map(|l| l.1.len()).sum();
        if total > START_MASK as usize {
            return None; // (cannot happen below MAX_TOTAL · MAX_LIST)
        }
        let slot_bits = (usize::BITS - (mesh.tris.len().max(2) - 1).leading_zeros()).min(31);
        let certified = certified(slot_bits);
        let q_shift = if certified {
            slot_bits + certificate::BITS
        } else {
            slot_bits
        };
        let steps = (1u64 << (32 - q_shift)) - 1;
        let far = lists
            .par_iter()
            .map(|l| l.1.iter().map(|c| c.dc).fold(0.0, f32::max))
            .reduce(|| 0.0, f32::max);
        let unit = if far > 0.0 {
            f64::from(far) / steps as f64
        } else {
            1.0
        };
        let packing = Packing {
            slot_bits,
            q_shift,
            certified,
            unit,
            inv: 1.0 / unit,
            steps,
            // Certificates relative to each list's first triangle, with a
            // tolerance of 10⁻¹² of the mesh box.
            tol: 1e-12 * extent,
        };
        let (records, items) = packing.pack(mesh, &mut lists, total);
        Some(CandidateGrid {
            cells: lattice,
            records,
            items,
            slot_bits,
            q_shift,
            skips: Skips::new(slot_bits, certified),
            inv_unit: (1.0 + 1e-9) / unit,
            tiny: 1e-12 * cell,
        })
    }

    /// The nearest triangle slot and squared distance for `p`, and `p`'s
    /// side when the cell or the nearest face settles it (0 when unknown);
    /// `None` when `p`'s cell keeps no list.
    #[inline]
    pub fn nearest(&self, mesh: &TriangleMesh, p: DVec3) -> Option<(usize, f64, i8)> {
        match self.walk::<false>(mesh, p, 0.0)? {
            Near::Nearest(slot, d2, side) => Some((slot, d2, side)),
            // (Never: a walk that may not stop early does not.)
            Near::Within(_) => None,
        }
    }

    /// As [`Self::nearest`], unless the list's first triangle lies within
    /// `sqrt(within2)` of `p`: then its squared distance (an upper bound of
    /// the nearest's), without the walk and the side.
    #[inline]
    pub fn nearest_unless_within(
        &self,
        mesh: &TriangleMesh,
        p: DVec3,
        within2: f64,
    ) -> Option<Near> {
        self.walk::<true>(mesh, p, within2)
    }

    /// [`Self::nearest`], stopping after the first triangle when `EARLY`
    /// and it lies within `sqrt(within2)`.
    #[inline(always)]
    fn walk<const EARLY: bool>(&self, mesh: &TriangleMesh, p: DVec3, within2: f64) -> Option<Near> {
        let (i, xyz) = self.cells.locate(p)?;
        let record = self.records[i];
        let list = &self.items
            [(record & START_MASK) as usize..(self.records[i + 1] & START_MASK) as usize];
        let (&first, rest) = list.split_first()?;
        let slot_mask = (1u32 << self.slot_bits) - 1;
        let c = self.cells.centre(xyz);
        // |p − c| rounded up a little, so `dc − pc` stays a lower bound.
        let pc = p.distance(c) * (1.0 + 1e-12) + self.tiny;
        let mut slot = first & slot_mask;
        let t1 = &mesh.tris[slot as usize];
        let (mut best, feature) = t1.distance_squared_feature_face_first(p);
        if EARLY && best <= within2 {
            return Some(Near::Within(best));
        }
        let above = t1.n.dot(p - t1.a) > 0.0;
        // The entries that p's place relative to t₁ proves no nearer are
        // skipped unread.
        let need = self.skips.need(feature, above);
        // Entries are sorted by `q`, so the walk stops at the first one
        // whose lower bound `q · unit − |p − c|` reaches `sqrt(best)`: one
        // integer compare per entry against the packed form of the least
        // such `q` (at most one too high, which only tests an entry more;
        // `inv_unit` is widened by 10⁻⁹, far above these few roundings).
        let stop = |best: f64| {
            let q = ((pc + best.sqrt()) * self.inv_unit) as u32;
            (u64::from(q) + 1) << self.q_shift
        };
        let mut stop_at = stop(best);
        for &e in rest {
            // Skipped entries first, even past the stop (skipping is always
            // sound): that test waits only for t₁'s region, while the stop
            // waits for its distance and a square root, and a mispredicted
            // branch costs the whole wait.
            if need != 0 && e & need == need {
                continue;
            }
            if u64::from(e) >= stop_at {
                break;
            }
            let s = e & slot_mask;
            let t = &mesh.tris[s as usize];
            // The distance to the triangle's plane is a cheap lower bound.
            let h = t.n.dot(p - t.a);
            if h * h >= best {
                continue;
            }
            let d2 = t.distance_squared(p);
            if d2 < best {
                best = d2;
                slot = s;
                stop_at = stop(best);
            }
        }
        // A cell the surface may cross has no side of its own; but when the
        // answer is t₁'s face, the side is the face's (its pseudo-normal is
        // its normal).
        let side = match side_of(record) {
            0 if slot == first & slot_mask && feature == Feature::Face => {
                if above {
                    1
                } else {
                    -1
                }
            }
            s => s,
        };
        Some(Near::Nearest(slot as usize, best, side))
    }

    /// `+1` or `−1` when every point of `p`'s cell is on that side of the
    /// surface (set at build time from the exact distance at the centre,
    /// larger than the half diagonal); `None` when the surface may cross
    /// the cell or `p` is outside the grid.
    #[inline]
    pub fn side(&self, p: DVec3) -> Option<i8> {
        let (i, _) = self.cells.locate(p)?;
        let s = side_of(self.records[i]);
        (s != 0).then_some(s)
    }
}

impl TriangleMesh {
    /// Every triangle slot within `reach` of `c`, with its distance to `c`
    /// (rounded down to `f32`), or `None` when there are more than `max`.
    fn within(&self, c: DVec3, reach: f64, max: usize) -> Option<Vec<Candidate>> {
        // Room for the most it returns: one allocation, no regrowth.
        let mut out = Vec::with_capacity(max);
        let reach2 = reach * reach;
        let mut stack = [0u32; crate::spatial::bvh::MAX_DEPTH + 2];
        let mut sp = 1usize;
        while sp > 0 {
            sp -= 1;
            let n = &self.nodes[stack[sp] as usize];
            if Aabb::new(n.min, n.max).distance_squared(c) > reach2 {
                continue;
            }
            if n.is_leaf() {
                for s in n.first..n.first + n.count {
                    let d2 = self.tris[s as usize].distance_squared(c);
                    if d2 <= reach2 {
                        if out.len() == max {
                            return None;
                        }
                        out.push(Candidate {
                            dc: f32_down(d2.sqrt()),
                            slot: s,
                        });
                    }
                }
            } else {
                stack[sp] = n.first;
                stack[sp + 1] = n.first + 1;
                sp += 2;
            }
        }
        Some(out)
    }
}

/// Half the diagonal of a cubic cell of side `cell`: no point of the cell
/// is farther from its centre.
fn half_diagonal(cell: f64) -> f64 {
    0.5 * cell * 3f64.sqrt()
}

/// The lower corner of block `b` (2×2×2 cells of size `cell` from `min`).
fn block_corner(min: DVec3, cell: f64, b: [usize; 3]) -> DVec3 {
    min + DVec3::new(b[0] as f64, b[1] as f64, b[2] as f64) * 2.0 * cell
}

/// The centre of cell `k` (x fastest) of the block at `corner`, as the
/// build computes it (its lists are exact for this point).
fn build_centre(corner: DVec3, cell: f64, k: usize) -> DVec3 {
    let off = DVec3::new((k & 1) as f64, (k >> 1 & 1) as f64, (k >> 2) as f64);
    corner + (off + 0.5) * cell
}

#[cfg(test)]
impl CandidateGrid {
    /// Cell `xyz`'s list as triangle slots in stored order, its side, and
    /// the centre and half diagonal the build used: for tests that check
    /// the lists against their definition.
    pub(crate) fn cell_list(&self, xyz: [usize; 3]) -> (Vec<u32>, i8, DVec3, f64) {
        let i = self.cells.index(xyz);
        let (a, b) = (
            self.records[i] & START_MASK,
            self.records[i + 1] & START_MASK,
        );
        let mask = (1u32 << self.slot_bits) - 1;
        let slots = self.items[a as usize..b as usize]
            .iter()
            .map(|e| e & mask)
            .collect();
        let cell = self.cells.cell().x;
        let b = [xyz[0] / 2, xyz[1] / 2, xyz[2] / 2];
        let k = (xyz[0] & 1) | (xyz[1] & 1) << 1 | (xyz[2] & 1) << 2;
        let c = build_centre(block_corner(self.cells.origin(), cell, b), cell, k);
        (slots, side_of(self.records[i]), c, half_diagonal(cell))
    }

    /// Cells along each axis.
    pub(crate) fn dims(&self) -> [usize; 3] {
        self.cells.dims()
    }
}
