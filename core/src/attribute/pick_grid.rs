//! Which children of a union with attributes may contain a point: a
//! uniform grid over the children's boxes, each cell listing (in child
//! order, so the first child containing a point still wins) the children
//! whose box meets it and whose distance interval over the cell does not
//! rule out an inside point (a long diagonal strut's box meets many cells
//! it does not pass through).
//!
//! Why: a union's attribute goes to the first child containing the point,
//! and testing every child is a distance evaluation per child: a lattice
//! whose 3,286 struts each carry an attribute tested them all at every
//! inside point. The grid leaves the few struts near the point. The
//! distance tree's union index cannot serve: it indexes the flattened
//! union, whose children are not these (only the children that carry an
//! attribute are here).

use std::sync::Arc;

use glam::DVec3;

use super::prepared::ANode;
use crate::aabb::Aabb;
use crate::spatial::cells::CellLattice;

/// Unions with fewer children test them all.
const MIN_CHILDREN: usize = 16;
/// Most cells along one axis.
const MAX_DIM: usize = 128;
/// Most list entries (child in a cell) before the grid is not worth it.
const MAX_ENTRIES: usize = 1 << 24;

/// Child lists by cell.
pub(super) struct PickGrid {
    cells: CellLattice,
    /// `items[starts[s]..starts[s + 1]]` are slot `s`'s children.
    starts: Vec<u32>,
    items: Vec<u32>,
}

impl PickGrid {
    /// The grid of `children`, or `None` when they are few, one has an
    /// unbounded box, or the boxes overlap so much a grid would not help.
    pub(super) fn build(children: &[Arc<ANode>]) -> Option<PickGrid> {
        if children.len() < MIN_CHILDREN {
            return None;
        }
        let boxes: Vec<Aabb> = children.iter().map(|c| c.dist.bbox).collect();
        if boxes.iter().any(|b| b.is_empty() || !b.is_finite()) {
            return None;
        }
        let all = boxes.iter().fold(Aabb::EMPTY, |a, b| a.union(b));
        let size = all.size().max(DVec3::splat(1e-9));
        // About one cell per child, near-cubic.
        let h = (size.x * size.y * size.z / children.len() as f64).cbrt();
        let dim = |s: f64| ((s / h).ceil() as usize).clamp(1, MAX_DIM);
        let dims = [dim(size.x), dim(size.y), dim(size.z)];
        let cell = size / DVec3::new(dims[0] as f64, dims[1] as f64, dims[2] as f64);
        let cells = CellLattice::new(all.min, cell, dims);
        // Each box's cell range, by `locate`'s arithmetic (`(p − min)·(1 /
        // cell)`, truncated): it is monotonic in p, so a point of the box
        // lies in a cell of the range.
        let inv = DVec3::ONE / cell;
        let range = |b: &Aabb| {
            let lo = ((b.min - all.min) * inv).floor();
            let hi = ((b.max - all.min) * inv).floor();
            let clampi = |v: f64, d: usize| (v.max(0.0) as usize).min(d - 1);
            let r = |a: usize| {
                let (l, h) = ([lo.x, lo.y, lo.z][a], [hi.x, hi.y, hi.z][a]);
                (clampi(l, dims[a]), clampi(h, dims[a]))
            };
            [r(0), r(1), r(2)]
        };
        let mut entries = 0usize;
        for b in &boxes {
            let [rx, ry, rz] = range(b);
            entries += (rx.1 - rx.0 + 1) * (ry.1 - ry.0 + 1) * (rz.1 - rz.0 + 1);
            if entries > MAX_ENTRIES {
                return None;
            }
        }
        // A cell a child's box meets, kept where the child's distance over
        // the cell (grown by a rounding margin: `locate` may put a point a
        // few ulps outside its cell's box) may be ≤ 0.
        let slack = 1e-9 * cell.length();
        let listed: Vec<Vec<usize>> = children
            .iter()
            .zip(&boxes)
            .map(|(c, b)| {
                let mut keep = Vec::new();
                for_cells(range(b), |k| {
                    let lo = all.min + DVec3::new(k[0] as f64, k[1] as f64, k[2] as f64) * cell;
                    let cb = Aabb::new(lo, lo + cell).expand(slack);
                    if c.dist.interval(&cb).lo <= slack {
                        keep.push(cells.index(k));
                    }
                });
                keep
            })
            .collect();
        let mut counts = vec![0u32; cells.slots() + 1];
        for s in listed.iter().flatten() {
            counts[s + 1] += 1;
        }
        for s in 1..counts.len() {
            counts[s] += counts[s - 1];
        }
        let starts = counts;
        let mut fill = starts.clone();
        let mut items = vec![0u32; listed.iter().map(Vec::len).sum()];
        // Children in order: each cell's list ascends.
        for (i, slots) in listed.iter().enumerate() {
            for &s in slots {
                items[fill[s] as usize] = i as u32;
                fill[s] += 1;
            }
        }
        Some(PickGrid {
            cells,
            starts,
            items,
        })
    }

    /// The children whose box may hold `q`, ascending; none outside the
    /// grid.
    #[inline]
    pub(super) fn candidates(&self, q: DVec3) -> &[u32] {
        match self.cells.locate(q) {
            Some((s, _)) => &self.items[self.starts[s] as usize..self.starts[s + 1] as usize],
            None => &[],
        }
    }
}

/// Calls `f` with every cell of the inclusive ranges.
fn for_cells(r: [(usize, usize); 3], mut f: impl FnMut([usize; 3])) {
    for z in r[2].0..=r[2].1 {
        for y in r[1].0..=r[1].1 {
            for x in r[0].0..=r[0].1 {
                f([x, y, z]);
            }
        }
    }
}
