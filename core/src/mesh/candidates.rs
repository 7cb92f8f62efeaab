//! A grid of per-cell candidate lists: for every cell near the surface, the
//! few triangles that can be nearest to some point of the cell. An exact
//! distance query in such a cell tests those triangles and no tree.
//!
//! Why it is exact: let `c` be the cell's centre, `r` its half diagonal and
//! `u = d(c)` the exact unsigned distance there. For `p` in the cell, the
//! nearest triangle `t*` satisfies `d(p, t*) ≤ d(p) ≤ u + r`, hence
//! `d(c, t*) ≤ d(p, t*) + r ≤ u + 2r`. So the triangles with
//! `d(c, t) ≤ u + 2r` include `t*` for every point of the cell. Kept sorted
//! by `d(c, t)`, a query stops at the first `t` with
//! `d(c, t) − |p − c| ≥ best` (a lower bound of `d(p, t)` and of every
//! later one).
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
use crate::bounds::Aabb;

/// Cells along the longest side of the (padded) mesh box.
const CELLS: f64 = 64.0;
/// Cells farther than this many cell sizes from the surface keep no list.
const FAR: f64 = 4.0;
/// Longest list kept; cells that need more fall back to the BVH.
const MAX_LIST: usize = 40;

/// One candidate: the triangle slot and `d(c, t)` rounded down to `f32`.
#[derive(Clone, Copy, Debug)]
struct Candidate {
    dc: f32,
    slot: u32,
}

/// The grid. Cell `i` lists `items[offsets[i]..offsets[i + 1]]`; an empty
/// range means "no list, ask the BVH".
#[derive(Clone, Debug)]
pub(crate) struct CandidateGrid {
    min: DVec3,
    cell: f64,
    inv_cell: f64,
    dims: [usize; 3],
    offsets: Vec<u32>,
    /// Per cell: +1 or −1 when the whole cell is on that side, 0 when the
    /// surface may cross it.
    side: Vec<i8>,
    items: Vec<Candidate>,
}

impl CandidateGrid {
    /// Builds the grid over the mesh box padded by two cells. `mesh` must
    /// answer exact queries through its BVH (this grid is not yet attached).
    pub fn new(mesh: &TriangleMesh) -> Option<CandidateGrid> {
        let b = mesh.bbox;
        let extent = b.size().max_element();
        if !(extent > 0.0 && extent.is_finite()) {
            return None;
        }
        let cell = extent / CELLS;
        let min = b.min - DVec3::splat(2.0 * cell);
        let n = ((b.max + DVec3::splat(2.0 * cell) - min) / cell).ceil();
        let dims = [n.x as usize, n.y as usize, n.z as usize];
        let r = 0.5 * cell * 3f64.sqrt();
        let count = dims[0] * dims[1] * dims[2];
        let lists: Vec<(i8, Vec<Candidate>)> = (0..count)
            .into_par_iter()
            .map(|i| {
                let (x, y, z) = (i % dims[0], i / dims[0] % dims[1], i / (dims[0] * dims[1]));
                let c = min + (DVec3::new(x as f64, y as f64, z as f64) + 0.5) * cell;
                // Cells the coarse grid proves far from the surface keep no
                // list (their points are rarely asked; the BVH answers them).
                if let Some((dc, rr)) = mesh.coarse.as_ref().and_then(|g| g.lookup(c))
                    && dc.abs() - rr - r > FAR * cell
                {
                    return (if dc < 0.0 { -1 } else { 1 }, Vec::new());
                }
                let d = mesh.signed_distance(c);
                let u = d.abs();
                // The inequality with a relative slack for rounding.
                let side = if u > r * (1.0 + 1e-9) {
                    if d < 0.0 { -1 } else { 1 }
                } else {
                    0
                };
                let reach = (u + 2.0 * r) * (1.0 + 1e-9) + 1e-12 * extent;
                (side, mesh.within(c, reach, MAX_LIST).unwrap_or_default())
            })
            .collect();
        let mut offsets = Vec::with_capacity(count + 1);
        let mut items = Vec::new();
        let mut side = Vec::with_capacity(count);
        offsets.push(0u32);
        for (s, mut l) in lists {
            l.sort_by(|a, b| a.dc.total_cmp(&b.dc).then(a.slot.cmp(&b.slot)));
            items.extend_from_slice(&l);
            offsets.push(items.len() as u32);
            side.push(s);
        }
        Some(CandidateGrid {
            min,
            cell,
            inv_cell: 1.0 / cell,
            dims,
            offsets,
            side,
            items,
        })
    }

    /// The nearest triangle slot and squared distance for `p`, and the
    /// cell's side (0 when unknown); `None` when `p`'s cell keeps no list.
    #[inline]
    pub fn nearest(&self, mesh: &TriangleMesh, p: DVec3) -> Option<(usize, f64, i8)> {
        let g = (p - self.min) * self.inv_cell;
        if !(g.x >= 0.0 && g.y >= 0.0 && g.z >= 0.0) {
            return None;
        }
        let (x, y, z) = (g.x as usize, g.y as usize, g.z as usize);
        if x >= self.dims[0] || y >= self.dims[1] || z >= self.dims[2] {
            return None;
        }
        let i = x + self.dims[0] * (y + self.dims[1] * z);
        let list = &self.items[self.offsets[i] as usize..self.offsets[i + 1] as usize];
        let first = list.first()?;
        let c = self.min + (DVec3::new(x as f64, y as f64, z as f64) + 0.5) * self.cell;
        // |p − c| rounded up a little, so `dc − pc` stays a lower bound.
        let pc = p.distance(c) * (1.0 + 1e-12) + 1e-12 * self.cell;
        let mut best = mesh.tris[first.slot as usize].distance_squared(p);
        let mut slot = first.slot;
        for e in &list[1..] {
            let lb = f64::from(e.dc) - pc;
            if lb > 0.0 && lb * lb >= best {
                break;
            }
            let t = &mesh.tris[e.slot as usize];
            // The distance to the triangle's plane is a cheap lower bound.
            let h = t.n.dot(p - t.a);
            if h * h >= best {
                continue;
            }
            let d2 = t.distance_squared(p);
            if d2 < best {
                best = d2;
                slot = e.slot;
            }
        }
        Some((slot as usize, best, self.side[i]))
    }
}

impl TriangleMesh {
    /// Every triangle slot within `reach` of `c`, with its distance to `c`
    /// (rounded down to `f32`), or `None` when there are more than `max`.
    fn within(&self, c: DVec3, reach: f64, max: usize) -> Option<Vec<Candidate>> {
        let mut out = Vec::new();
        let reach2 = reach * reach;
        let mut stack = [0u32; super::bvh::MAX_DEPTH + 2];
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
                        let d = d2.sqrt();
                        let f = d as f32;
                        let dc = if f as f64 > d { f.next_down() } else { f };
                        out.push(Candidate { dc, slot: s });
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
