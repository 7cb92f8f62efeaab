//! Point location in a tetrahedral mesh.
//!
//! Barycentric test: for a tetrahedron `v0..v3` with edge matrix
//! `E = [v1−v0, v2−v0, v3−v0]`, `(λ1, λ2, λ3) = E⁻¹ (p − v0)` and
//! `λ0 = 1 − λ1 − λ2 − λ3`; the rows of `E⁻¹` are `(e2×e3, e3×e1, e1×e2)/det E`
//! and are precomputed, so a test is three dot products. `p` is inside when
//! every `λi ≥ −1e−12` (the tolerance keeps points on shared faces and at
//! nodes from falling between two tetrahedra through rounding). The formula
//! also holds for inverted tetrahedra (`det E < 0`).
//!
//! Finding the tetrahedron, fastest first:
//!
//! 1. the tetrahedron this thread found last (samplers visit neighbouring
//!    points, which usually share a tetrahedron), when `p` is well inside
//!    it (see [`NEAR`]);
//! 2. a **visibility walk** (Devillers, Pion & Teillaud, "Walking in a
//!    triangulation", 2002) from the tetrahedron that contains the centre of
//!    `p`'s cell in a coarse grid: while some `λk < 0`, step to the neighbour
//!    across the face opposite the most negative `λk`. A few steps reach `p`.
//!    Cells that lie wholly outside the mesh (boundary distance at the centre
//!    larger than the half diagonal) answer "outside" at once; a cell the
//!    boundary crosses with its centre outside starts from a tetrahedron
//!    near its centre;
//! 3. when the walk leaves the mesh (a non-convex boundary between start and
//!    `p`, or `p` outside) or exceeds its step limit: the BVH over the
//!    tetrahedra's boxes (4-wide, [`crate::spatial::wide`]), which tests every
//!    tetrahedron whose box contains `p`.
//!
//! A point on (or within the tolerance of) a face, edge or node is inside
//! every tetrahedron that shares it, and their interpolated values agree
//! only up to rounding. Steps 2 and 3 depend on `p` alone, but step 1
//! depends on the thread's previous point; so step 1 answers only points
//! farther than [`NEAR`] (in barycentric terms) from every face of the last
//! tetrahedron, which no other tetrahedron contains. The answer is then a
//! function of `p`, and exports are the same bytes on any number of
//! threads even where a voxel centre falls on a shared face.

use glam::DVec3;

use crate::aabb::Aabb;
use crate::spatial::bvh;
use crate::spatial::recent::RecentSlots;
use crate::spatial::wide::{WideBvh, WideChild};
use crate::trimesh::TriangleMesh;

/// Barycentric tolerance (dimensionless).
const TOLERANCE: f64 = -1e-12;
/// Least barycentric coordinate for the last tetrahedron to answer (step 1
/// of the module docs). Across a shared face the two tetrahedra's
/// coordinates of their opposite nodes are `h/H` and `−h/H′` (`h` the
/// distance to the face, `H`, `H′` the heights), so above this no
/// neighbour passes [`TOLERANCE`] unless its height is a million times
/// the last one's. About one point in a million of a sampler's is this
/// close to a face; they take the walk.
const NEAR: f64 = 1e-6;
/// No neighbour / no start tetrahedron.
const NONE: u32 = u32::MAX;
/// Grid cell wholly outside the mesh.
const OUTSIDE: u32 = u32::MAX - 1;
/// Most walk steps before falling back to the BVH.
const MAX_STEPS: usize = 48;

/// One tetrahedron prepared for the barycentric test (128 bytes).
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
struct TetData {
    /// Corner 0.
    v0: DVec3,
    /// Rows of `E⁻¹`.
    inv: [DVec3; 3],
    /// Node indices (as given, not reoriented).
    nodes: [u32; 4],
    /// Slot of the neighbour across the face opposite node k, or `NONE`.
    across: [u32; 4],
}

impl TetData {
    /// Barycentric coordinates of `p`.
    #[inline(always)]
    fn weights(&self, p: DVec3) -> [f64; 4] {
        let d = p - self.v0;
        let l1 = self.inv[0].dot(d);
        let l2 = self.inv[1].dot(d);
        let l3 = self.inv[2].dot(d);
        [1.0 - l1 - l2 - l3, l1, l2, l3]
    }
}

/// The least of the four weights (`minsd`: the weights of a finite point
/// are not NaN).
#[inline(always)]
fn least(w: &[f64; 4]) -> f64 {
    use crate::fastmath::min_plain;
    min_plain(min_plain(w[0], w[1]), min_plain(w[2], w[3]))
}

#[inline(always)]
fn inside(w: &[f64; 4]) -> bool {
    w[0] >= TOLERANCE && w[1] >= TOLERANCE && w[2] >= TOLERANCE && w[3] >= TOLERANCE
}

/// Coarse grid of walk starts.
#[derive(Clone, Debug)]
struct StartGrid {
    origin: DVec3,
    cell: f64,
    inv_cell: f64,
    dims: [usize; 3],
    /// Per cell: slot containing the centre, `OUTSIDE`, or `NONE`.
    start: Vec<u32>,
}

impl StartGrid {
    /// Cell `i`'s box and centre (cells x fastest).
    fn cell(&self, i: usize) -> (Aabb, DVec3) {
        let [nx, ny, _] = self.dims;
        let xyz = DVec3::new(
            (i % nx) as f64,
            (i / nx % ny) as f64,
            (i / (nx * ny)) as f64,
        );
        let lo = self.origin + xyz * self.cell;
        (
            Aabb::new(lo, lo + DVec3::splat(self.cell)),
            self.origin + (xyz + 0.5) * self.cell,
        )
    }
}

/// The locator.
#[derive(Clone, Debug)]
pub(crate) struct TetLocator {
    wide: WideBvh,
    /// Tetrahedra in BVH slot order.
    data: Vec<TetData>,
    /// Slot → index into the mesh's tetrahedra.
    order: Vec<u32>,
    grid: StartGrid,
}

/// `det E / 6` for a tetrahedron: its signed volume.
pub(crate) fn signed_volume(p: [DVec3; 4]) -> f64 {
    (p[1] - p[0]).dot((p[2] - p[0]).cross(p[3] - p[0])) / 6.0
}

impl TetLocator {
    /// Builds the locator's tree and neighbour links, without the start
    /// grid ([`TetLocator::start_walks`] adds it): they do not need the
    /// boundary surface, so the field's build makes both at once.
    /// Tetrahedra must be non-degenerate and indices valid (checked by the
    /// caller).
    pub fn unstarted(nodes: &[DVec3], tets: &[[u32; 4]]) -> TetLocator {
        let boxes: Vec<Aabb> = tets
            .iter()
            .map(|t| {
                let p = t.map(|i| nodes[i as usize]);
                Aabb::new(
                    p[0].min(p[1]).min(p[2]).min(p[3]),
                    p[0].max(p[1]).max(p[2]).max(p[3]),
                )
            })
            .collect();
        let (tree, order) = bvh::build(&boxes, 1);
        let wide = WideBvh::new(&tree);
        let mut data: Vec<TetData> = order
            .iter()
            .map(|&ti| {
                let t = tets[ti as usize];
                let p = t.map(|i| nodes[i as usize]);
                let (e1, e2, e3) = (p[1] - p[0], p[2] - p[0], p[3] - p[0]);
                let inv_det = 1.0 / e1.dot(e2.cross(e3));
                TetData {
                    v0: p[0],
                    inv: [
                        e2.cross(e3) * inv_det,
                        e3.cross(e1) * inv_det,
                        e1.cross(e2) * inv_det,
                    ],
                    nodes: t,
                    across: [NONE; 4],
                }
            })
            .collect();
        link_neighbours(&mut data);
        TetLocator {
            wide,
            data,
            order,
            grid: StartGrid {
                origin: DVec3::ZERO,
                cell: 0.0,
                inv_cell: 0.0,
                dims: [0; 3],
                start: Vec::new(),
            },
        }
    }

    /// Adds the start grid over `boundary` (the mesh's surface); until
    /// then every point searches the tree.
    pub fn start_walks(&mut self, boundary: &TriangleMesh) {
        self.grid = self.start_grid(boundary);
    }

    /// Calls `f` with the nodes of every tetrahedron whose box meets `b`,
    /// one by one; stops and returns false as soon as `f` does.
    pub fn overlapping(&self, b: &Aabb, mut f: impl FnMut([u32; 4]) -> bool) -> bool {
        self.wide
            .overlapping(b, |slot| f(self.data[slot as usize].nodes))
    }

    /// Nodes of the tetrahedra's tree, for a table kept per node.
    pub fn tree_node_count(&self) -> usize {
        self.wide.node_count()
    }

    /// The children of tree node `i` (tetrahedra by slot); see
    /// [`WideBvh::children`] for their order.
    pub fn tree_children(&self, i: usize) -> impl Iterator<Item = WideChild> + '_ {
        self.wide.children(i)
    }

    /// Tetrahedra, one per slot (the tree's order).
    pub fn slot_count(&self) -> usize {
        self.data.len()
    }

    /// The four nodes of the tetrahedron in `slot`.
    #[inline]
    pub fn slot_nodes(&self, slot: u32) -> [u32; 4] {
        self.data[slot as usize].nodes
    }

    /// Calls `f` with the slot of every tetrahedron whose box meets `b`,
    /// except that a tree node whose box lies within `b` goes whole to `f`
    /// (see [`WideBvh::overlapping_nodes`]); stops and returns false as soon
    /// as `f` does.
    pub fn overlapping_nodes(&self, b: &Aabb, f: impl FnMut(WideChild) -> bool) -> bool {
        self.wide.overlapping_nodes(b, f)
    }

    /// About one cell per tetrahedron over the mesh box; each cell remembers
    /// the tetrahedron at its centre, or that it is wholly outside.
    fn start_grid(&self, boundary: &TriangleMesh) -> StartGrid {
        let bbox = boundary.bbox();
        let size = bbox.size().max(DVec3::splat(1e-300));
        let cells = (self.data.len() as f64).clamp(1.0, 4e6);
        let cell = (size.x * size.y * size.z / cells)
            .cbrt()
            .max(size.max_element() / 1024.0);
        let n = (size / cell).ceil().max(DVec3::ONE);
        let dims = [n.x as usize, n.y as usize, n.z as usize];
        let half_diag = 0.5 * 3f64.sqrt() * cell;
        let mut grid = StartGrid {
            origin: bbox.min,
            cell,
            inv_cell: 1.0 / cell,
            dims,
            start: Vec::new(),
        };
        use rayon::prelude::*;
        grid.start = (0..dims[0] * dims[1] * dims[2])
            .into_par_iter()
            .map(|i| {
                let (b, c) = grid.cell(i);
                if let Some(s) = self.find_bvh(c).map(|(s, _)| s) {
                    s
                } else if boundary.signed_distance_bound(c, half_diag) > half_diag * (1.0 + 1e-9) {
                    OUTSIDE
                } else {
                    self.nearest_overlapping(&b, c)
                }
            })
            .collect();
        grid
    }

    /// For a cell `b` the boundary crosses whose centre `c` is outside: a
    /// tetrahedron near `c` among those whose boxes meet `b`, or
    /// `NONE`. Points of such a cell inside the mesh then
    /// walk a step or two from there instead of searching the BVH
    /// (measured with `volcad bench` on the bicycle seat).
    fn nearest_overlapping(&self, b: &Aabb, c: DVec3) -> u32 {
        let mut best = (f64::INFINITY, NONE);
        self.wide.overlapping(b, |slot| {
            let t = &self.data[slot as usize];
            // Ranked by how far `c`'s weights are from the centroid's (¼
            // each): a heuristic, since any start is correct (the walk
            // checks containment, and the BVH answers when it fails).
            let w = t.weights(c);
            let d = w.iter().map(|x| (x - 0.25).abs()).sum::<f64>();
            if d < best.0 || (d == best.0 && slot < best.1) {
                best = (d, slot);
            }
            true
        });
        best.1
    }

    /// Cells that keep no start though the boxes of some tetrahedra meet
    /// them (their points would search the BVH).
    #[cfg(test)]
    pub(super) fn unstarted_cells(&self) -> usize {
        let g = &self.grid;
        (0..g.start.len())
            .filter(|&i| g.start[i] == NONE && !self.wide.overlapping(&g.cell(i).0, |_| false))
            .count()
    }

    /// Exhaustive search through the BVH.
    fn find_bvh(&self, p: DVec3) -> Option<(u32, [f64; 4])> {
        let mut w = [0.0; 4];
        let slot = self.wide.find(p, |s| {
            w = self.data[s as usize].weights(p);
            inside(&w)
        })?;
        Some((slot, w))
    }

    /// Visibility walk from `slot` towards `p`; `None` when it leaves the
    /// mesh or runs out of steps.
    #[inline]
    fn walk(&self, mut slot: u32, p: DVec3) -> Option<(u32, [f64; 4])> {
        for _ in 0..MAX_STEPS {
            let t = &self.data[slot as usize];
            let w = t.weights(p);
            let mut k = 0;
            for i in 1..4 {
                if w[i] < w[k] {
                    k = i;
                }
            }
            if w[k] >= TOLERANCE {
                return Some((slot, w));
            }
            slot = t.across[k];
            if slot == NONE {
                return None;
            }
        }
        None
    }

    /// The tetrahedron containing `p` (mesh index), its node indices and the
    /// barycentric weights of those nodes.
    #[inline]
    pub fn locate(&self, p: DVec3) -> Option<(u32, [u32; 4], [f64; 4])> {
        if !p.is_finite() {
            return None;
        }
        let key = self.data.as_ptr() as usize;
        let found = self.locate_slot(p, key)?;
        LAST.with(|r| r.set(key, found.0));
        let t = &self.data[found.0 as usize];
        Some((self.order[found.0 as usize], t.nodes, found.1))
    }

    #[inline]
    fn locate_slot(&self, p: DVec3, key: usize) -> Option<(u32, [f64; 4])> {
        if let Some(s) = LAST
            .with(|r| r.get(key))
            .filter(|&s| (s as usize) < self.data.len())
        {
            let w = self.data[s as usize].weights(p);
            if least(&w) > NEAR {
                return Some((s, w));
            }
        }
        let g = &self.grid;
        let c = crate::fastmath::floor3((p - g.origin) * g.inv_cell);
        if c.x < 0.0 || c.y < 0.0 || c.z < 0.0 {
            return None;
        }
        // A point on the far face of the mesh box (index == dims) belongs to
        // the last cell; beyond it there is no tetrahedron.
        let cell = |v: f64, n: usize| {
            let i = v as usize;
            if i < n {
                Some(i)
            } else if i == n {
                Some(n - 1)
            } else {
                None
            }
        };
        let (x, y, z) = (
            cell(c.x, g.dims[0])?,
            cell(c.y, g.dims[1])?,
            cell(c.z, g.dims[2])?,
        );
        match g.start[x + g.dims[0] * (y + g.dims[1] * z)] {
            OUTSIDE => None,
            NONE => self.find_bvh(p),
            s => self.walk(s, p).or_else(|| self.find_bvh(p)),
        }
    }
}

/// Fills `across` by matching faces: the face opposite node k of one
/// tetrahedron equals a face of at most one other in a conforming mesh.
fn link_neighbours(data: &mut [TetData]) {
    let mut faces: Vec<([u32; 3], u32, u8)> = Vec::with_capacity(data.len() * 4);
    for (s, t) in data.iter().enumerate() {
        for k in 0..4 {
            let mut key = [0u32; 3];
            let mut j = 0;
            for (i, &n) in t.nodes.iter().enumerate() {
                if i != k {
                    key[j] = n;
                    j += 1;
                }
            }
            key.sort_unstable();
            faces.push((key, s as u32, k as u8));
        }
    }
    faces.sort_unstable_by_key(|f| f.0);
    for pair in faces.windows(2) {
        // Faces shared by more than two tetrahedra get arbitrary links; the
        // walk stays correct because it checks containment at every step.
        if pair[0].0 == pair[1].0 {
            data[pair[0].1 as usize].across[pair[0].2 as usize] = pair[1].1;
            data[pair[1].1 as usize].across[pair[1].2 as usize] = pair[0].1;
        }
    }
}

thread_local! {
    /// The last tetrahedron found by the few most recently used locators
    /// (keyed by address; a stale key only costs one failed test).
    static LAST: RecentSlots = const { RecentSlots::new() };
}
