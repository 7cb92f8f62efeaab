//! A flattened binary bounding-volume hierarchy over boxes.
//!
//! Shared by the triangle mesh (closest-point and winding-number queries) and
//! by [`crate::simfield`] (point location in tetrahedra). The tree is built
//! top-down with binned SAH (surface-area heuristic, Wald 2007 "On fast
//! construction of SAH-based bounding volume hierarchies"): a split of `n`
//! primitives into `L` and `R` costs `area(L)·|L| + area(R)·|R|`, which
//! estimates how many primitives a random query touches.
//!
//! Layout: nodes sit in one `Vec` (56 bytes each); the two children of an
//! inner node are adjacent (`first`, `first + 1`) so one cache line fetch
//! usually brings both boxes. A leaf covers the primitive slots
//! `first .. first + count` of the permutation returned by [`build`]; callers
//! reorder their primitive data by that permutation so leaves read memory
//! contiguously.

use glam::DVec3;

use crate::aabb::Aabb;

/// Depth after which the builder stops using SAH and splits at the median,
/// which halves the primitive count per level. SAH alone can peel one
/// primitive per level on adversarial input; with this cap the depth stays
/// below `MEDIAN_DEPTH + log2(n) < MAX_DEPTH`, so fixed traversal stacks
/// can't overflow.
const MEDIAN_DEPTH: usize = 32;

/// Upper bound of the tree depth (see [`MEDIAN_DEPTH`]): 32 + log2(2^32).
pub(crate) const MAX_DEPTH: usize = 64;

/// Number of SAH bins per axis.
const BINS: usize = 16;

/// One node of the flattened tree.
#[derive(Clone, Copy, Debug)]
pub(crate) struct BvhNode {
    /// Lowest corner of the node's box.
    pub min: DVec3,
    /// Highest corner of the node's box.
    pub max: DVec3,
    /// Leaf: first primitive slot. Inner node: index of the left child (the
    /// right child is `first + 1`).
    pub first: u32,
    /// Leaf: number of primitives (> 0). Inner node: 0.
    pub count: u32,
}

impl BvhNode {
    /// True for a leaf.
    #[inline(always)]
    pub fn is_leaf(&self) -> bool {
        self.count > 0
    }

    /// True when `p` lies in the closed box.
    #[cfg(test)]
    pub fn contains(&self, p: DVec3) -> bool {
        p.x >= self.min.x
            && p.x <= self.max.x
            && p.y >= self.min.y
            && p.y <= self.max.y
            && p.z >= self.min.z
            && p.z <= self.max.z
    }
}

/// The flattened tree. Node 0 is the root.
#[derive(Clone, Debug)]
pub(crate) struct Bvh {
    /// All nodes, root first.
    pub nodes: Vec<BvhNode>,
    /// For every node, the half-open range of primitive slots it covers
    /// (children cover adjacent sub-ranges). Used to precompute per-node data.
    pub ranges: Vec<[u32; 2]>,
}

/// Surface area of a box (half of it, the factor 2 does not change SAH).
fn half_area(min: DVec3, max: DVec3) -> f64 {
    let e = (max - min).max(DVec3::ZERO);
    e.x * e.y + e.y * e.z + e.z * e.x
}

/// Builds the tree over `boxes` (one per primitive; must be non-empty and
/// finite) with at most `leaf_size` primitives per leaf. Returns the tree and
/// the permutation `slot -> primitive index`.
pub(crate) fn build(boxes: &[Aabb], leaf_size: usize) -> (Bvh, Vec<u32>) {
    let leaf_size = leaf_size.max(1);
    let n = boxes.len();
    let centroids: Vec<DVec3> = boxes.iter().map(|b| b.center()).collect();
    let mut perm: Vec<u32> = (0..n as u32).collect();
    let empty = BvhNode {
        min: DVec3::ZERO,
        max: DVec3::ZERO,
        first: 0,
        count: 0,
    };
    let mut nodes = vec![empty];
    let mut ranges = vec![[0u32, n as u32]];
    // (node index, lo, hi, depth)
    let mut work = vec![(0usize, 0usize, n, 0usize)];
    while let Some((ni, lo, hi, depth)) = work.pop() {
        let mut bmin = DVec3::splat(f64::INFINITY);
        let mut bmax = DVec3::splat(f64::NEG_INFINITY);
        let mut cmin = bmin;
        let mut cmax = bmax;
        for &i in &perm[lo..hi] {
            let b = &boxes[i as usize];
            bmin = bmin.min(b.min);
            bmax = bmax.max(b.max);
            cmin = cmin.min(centroids[i as usize]);
            cmax = cmax.max(centroids[i as usize]);
        }
        nodes[ni].min = bmin;
        nodes[ni].max = bmax;
        ranges[ni] = [lo as u32, hi as u32];
        let count = hi - lo;
        if count <= leaf_size {
            nodes[ni].first = lo as u32;
            nodes[ni].count = count as u32;
            continue;
        }
        let extent = cmax - cmin;
        let mid = if depth < MEDIAN_DEPTH && extent.max_element() > 0.0 {
            sah_split(boxes, &centroids, &mut perm[lo..hi], cmin, extent)
                .map(|m| lo + m)
                .unwrap_or_else(|| median_split(&centroids, &mut perm[lo..hi], extent) + lo)
        } else {
            median_split(&centroids, &mut perm[lo..hi], extent) + lo
        };
        let left = nodes.len();
        nodes.push(empty);
        nodes.push(empty);
        ranges.push([0, 0]);
        ranges.push([0, 0]);
        nodes[ni].first = left as u32;
        nodes[ni].count = 0;
        work.push((left + 1, mid, hi, depth + 1));
        work.push((left, lo, mid, depth + 1));
    }
    (Bvh { nodes, ranges }, perm)
}

/// Splits `perm` at the median centroid along the widest centroid axis;
/// returns the split position (always strictly inside).
fn median_split(centroids: &[DVec3], perm: &mut [u32], extent: DVec3) -> usize {
    let axis = if extent.x >= extent.y && extent.x >= extent.z {
        0
    } else if extent.y >= extent.z {
        1
    } else {
        2
    };
    let mid = perm.len() / 2;
    perm.select_nth_unstable_by(mid, |&a, &b| {
        centroids[a as usize][axis].total_cmp(&centroids[b as usize][axis])
    });
    mid
}

/// Binned SAH over all three axes. Partitions `perm` and returns the split
/// position, or `None` when no split separates the centroids.
fn sah_split(
    boxes: &[Aabb],
    centroids: &[DVec3],
    perm: &mut [u32],
    cmin: DVec3,
    extent: DVec3,
) -> Option<usize> {
    let mut best: Option<(f64, usize, usize)> = None; // (cost, axis, bins left of the split)
    for axis in 0..3 {
        if extent[axis] <= 0.0 {
            continue;
        }
        let scale = BINS as f64 / extent[axis];
        let mut cnt = [0usize; BINS];
        let mut bmin = [DVec3::splat(f64::INFINITY); BINS];
        let mut bmax = [DVec3::splat(f64::NEG_INFINITY); BINS];
        for &i in perm.iter() {
            let b = bin_of(centroids[i as usize][axis], cmin[axis], scale);
            cnt[b] += 1;
            bmin[b] = bmin[b].min(boxes[i as usize].min);
            bmax[b] = bmax[b].max(boxes[i as usize].max);
        }
        // Sweep from the right to get the right-hand areas.
        let mut right_cost = [0.0f64; BINS];
        let (mut rmin, mut rmax, mut rc) = (
            DVec3::splat(f64::INFINITY),
            DVec3::splat(f64::NEG_INFINITY),
            0usize,
        );
        for s in (1..BINS).rev() {
            rmin = rmin.min(bmin[s]);
            rmax = rmax.max(bmax[s]);
            rc += cnt[s];
            right_cost[s] = if rc > 0 {
                half_area(rmin, rmax) * rc as f64
            } else {
                0.0
            };
        }
        let (mut lmin, mut lmax, mut lc) = (
            DVec3::splat(f64::INFINITY),
            DVec3::splat(f64::NEG_INFINITY),
            0usize,
        );
        for s in 1..BINS {
            lmin = lmin.min(bmin[s - 1]);
            lmax = lmax.max(bmax[s - 1]);
            lc += cnt[s - 1];
            if lc == 0 || lc == perm.len() {
                continue;
            }
            let cost = half_area(lmin, lmax) * lc as f64 + right_cost[s];
            if best.is_none_or(|(c, _, _)| cost < c) {
                best = Some((cost, axis, s));
            }
        }
    }
    let (_, axis, split) = best?;
    let scale = BINS as f64 / extent[axis];
    // Partition: primitives in bins < split go left.
    let mut i = 0;
    let mut j = perm.len();
    while i < j {
        if bin_of(centroids[perm[i] as usize][axis], cmin[axis], scale) < split {
            i += 1;
        } else {
            j -= 1;
            perm.swap(i, j);
        }
    }
    (i > 0 && i < perm.len()).then_some(i)
}

#[inline]
fn bin_of(c: f64, cmin: f64, scale: f64) -> usize {
    (((c - cmin) * scale) as usize).min(BINS - 1)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn leaves_partition_all_primitives() {
        let boxes: Vec<Aabb> = (0..1000)
            .map(|i| {
                let c = DVec3::new((i * 7 % 13) as f64, (i * 11 % 17) as f64, (i % 5) as f64);
                Aabb::new(c - DVec3::splat(0.3), c + DVec3::splat(0.3))
            })
            .collect();
        let (bvh, perm) = build(&boxes, 4);
        let mut seen = vec![false; boxes.len()];
        for (ni, n) in bvh.nodes.iter().enumerate() {
            let [lo, hi] = bvh.ranges[ni];
            for s in lo..hi {
                let b = &boxes[perm[s as usize] as usize];
                assert!(n.contains(b.min) && n.contains(b.max));
            }
            if n.is_leaf() {
                assert!(n.count <= 4);
                for s in n.first..n.first + n.count {
                    assert!(!seen[perm[s as usize] as usize]);
                    seen[perm[s as usize] as usize] = true;
                }
            }
        }
        assert!(seen.iter().all(|&s| s));
    }

    #[test]
    fn identical_boxes_terminate() {
        let boxes = vec![Aabb::new(DVec3::ZERO, DVec3::ONE); 100];
        let (bvh, _) = build(&boxes, 4);
        assert!(bvh.nodes.iter().filter(|n| n.is_leaf()).count() >= 25);
    }
}
