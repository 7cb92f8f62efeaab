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
//! it ([`crate::spatial::wide::WideBvh::overlapping_nodes`]), so the same
//! tetrahedra count, and a minimum or maximum does not depend on the order
//! or grouping it is taken in. The count decides the same "too many" as
//! before.
//!
//! Why: a segmented mesh export of a simulation field asks `SimField::bounds`
//! for every open tile, and each call meets tens of tetrahedra.

use crate::spatial::wide::WideChild;

use super::tet_bvh::TetLocator;

/// Most values in either half of a table (lows, highs): 4 M, 64 MB in
/// all, about 950 thousand tetrahedra with three columns (a tree has about
/// one node per two tetrahedra; the seat: 50,105 tetrahedra and 23,702
/// nodes, 0.22 M values). Larger tables are not built and bounds read
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
        let nodes = locator.tree_node_count();
        let rows = slots + nodes;
        if rows.saturating_mul(stride) > MAX_VALUES {
            return None;
        }
        let mut t = NodeRanges {
            stride,
            first_node: slots,
            lo: vec![f64::INFINITY; rows * stride],
            hi: vec![f64::NEG_INFINITY; rows * stride],
            count: vec![0; nodes],
        };
        for slot in 0..slots {
            let r = slot * stride..(slot + 1) * stride;
            let nodes = locator.slot_nodes(slot as u32);
            widen_by_tet(values, stride, nodes, &mut t.lo[r.clone()], &mut t.hi[r]);
        }
        // Children have larger indices than their parents: last to first.
        let (mut lo, mut hi) = (vec![0.0; stride], vec![0.0; stride]);
        for i in (0..nodes).rev() {
            lo.fill(f64::INFINITY);
            hi.fill(f64::NEG_INFINITY);
            let mut count = 0;
            for c in locator.tree_children(i) {
                count += t.count(c);
                t.merge(c, &mut lo, &mut hi);
            }
            let r = (slots + i) * stride..(slots + i + 1) * stride;
            t.lo[r.clone()].copy_from_slice(&lo);
            t.hi[r].copy_from_slice(&hi);
            t.count[i] = u32::try_from(count).unwrap_or(u32::MAX);
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

/// Widens `lo` and `hi` (`stride` columns) by the nodal rows of a
/// tetrahedron's four `nodes` in `values` (node-major): the table's rows,
/// and what a field without a table merges per tetrahedron.
#[inline]
pub(crate) fn widen_by_tet(
    values: &[f64],
    stride: usize,
    nodes: [u32; 4],
    lo: &mut [f64],
    hi: &mut [f64],
) {
    for m in nodes {
        let row = &values[m as usize * stride..(m as usize + 1) * stride];
        widen(lo, hi, row, row);
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
