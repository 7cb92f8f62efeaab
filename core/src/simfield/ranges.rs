//! The least and greatest value of every stored column over the four nodes
//! of each tetrahedron, and over the tetrahedra below each node of their
//! tree (with how many those are). [`super::SimField::bounds`] merges one
//! row of this table per tetrahedron its box meets, and one per tree node
//! whose box lies within its box, instead of reading four nodal rows per
//! tetrahedron.
//!
//! Why the bounds are the same: they are the least and greatest nodal
//! values over the tetrahedra whose boxes meet the query box. Every
//! tetrahedron below a tree node whose box lies within the query box meets
//! it ([`crate::mesh::wide::WideBvh::overlapping_nodes`]), so the same
//! tetrahedra count, and a minimum or maximum does not depend on the order
//! or grouping it is taken in. The count decides the same "too many" as
//! before.
//!
//! On the bicycle seat's 4-segment mesh at 0.5 mm, `SimField::bounds` was
//! 11 % of the export's instructions: 302 thousand calls meeting 26
//! tetrahedra each, at about 330 instructions per tetrahedron for its four
//! nodal rows (callgrind).

use crate::mesh::wide::WideChild;

use super::tet_bvh::TetLocator;

/// Most values in either half of a table (lows, highs): 4 M, 64 MB in
/// all, a million tetrahedra with three columns (the seat: 50 thousand
/// tetrahedra, 0.2 M values). Larger tables are not built and bounds read
/// each tetrahedron's nodal rows, as before the table.
pub(crate) const MAX_VALUES: usize = 1 << 22;

/// Rows of `stride` ranges: tetrahedra by slot, then tree nodes.
#[derive(Clone, Debug)]
pub(crate) struct NodeRanges {
    stride: usize,
    /// Row of tree node 0 (the rows before are the slots').
    first_node: usize,
    lo: Vec<f64>,
    hi: Vec<f64>,
    /// Tetrahedra below each tree node.
    count: Vec<u32>,
}

impl NodeRanges {
    /// The table of `locator`'s tetrahedra and tree over `values`
    /// (node-major, `stride` columns per mesh node), or `None` when it
    /// would hold more than [`MAX_VALUES`] values a side.
    pub fn new(locator: &TetLocator, values: &[f64], stride: usize) -> Option<NodeRanges> {
        let slots = locator.slot_count();
        let rows = slots + locator.tree_nodes().len();
        if rows.saturating_mul(stride) > MAX_VALUES {
            return None;
        }
        let children: Vec<Vec<WideChild>> = locator.tree_nodes().map(|c| c.collect()).collect();
        let mut t = NodeRanges {
            stride,
            first_node: slots,
            lo: vec![f64::INFINITY; rows * stride],
            hi: vec![f64::NEG_INFINITY; rows * stride],
            count: vec![0; children.len()],
        };
        for slot in 0..slots {
            let r = slot * stride..(slot + 1) * stride;
            for m in locator.slot_nodes(slot as u32) {
                let row = &values[m as usize * stride..(m as usize + 1) * stride];
                widen(&mut t.lo[r.clone()], &mut t.hi[r.clone()], row, row);
            }
        }
        // Children have larger indices than their parents: last to first.
        let (mut lo, mut hi) = (vec![0.0; stride], vec![0.0; stride]);
        for (i, list) in children.iter().enumerate().rev() {
            lo.fill(f64::INFINITY);
            hi.fill(f64::NEG_INFINITY);
            let mut count = 0u32;
            for &c in list {
                if let WideChild::Node(j) = c {
                    count = count.saturating_add(t.count[j as usize]);
                } else {
                    count += 1;
                }
                t.merge(c, &mut lo, &mut hi);
            }
            let r = (slots + i) * stride..(slots + i + 1) * stride;
            t.lo[r.clone()].copy_from_slice(&lo);
            t.hi[r].copy_from_slice(&hi);
            t.count[i] = count;
        }
        Some(t)
    }

    /// Tetrahedra that `c` stands for: one, or those below a tree node.
    #[inline]
    pub fn count(&self, c: WideChild) -> usize {
        match c {
            WideChild::Prim(_) => 1,
            WideChild::Node(n) => self.count[n as usize] as usize,
        }
    }

    /// Widens `lo` and `hi` (the first `stride` columns) by the ranges of
    /// `c`.
    #[inline]
    pub fn merge(&self, c: WideChild, lo: &mut [f64], hi: &mut [f64]) {
        let row = match c {
            WideChild::Prim(slot) => slot as usize,
            WideChild::Node(n) => self.first_node + n as usize,
        };
        let r = row * self.stride..(row + 1) * self.stride;
        widen(lo, hi, &self.lo[r.clone()], &self.hi[r]);
    }
}

/// `lo = min(lo, a)`, `hi = max(hi, b)` column by column.
#[inline]
fn widen(lo: &mut [f64], hi: &mut [f64], a: &[f64], b: &[f64]) {
    for (l, v) in lo.iter_mut().zip(a) {
        *l = l.min(*v);
    }
    for (h, v) in hi.iter_mut().zip(b) {
        *h = h.max(*v);
    }
}
