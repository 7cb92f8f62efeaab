//! A 4-wide BVH with single-precision boxes for fast queries.
//!
//! The binary SAH tree of [`super::bvh`] (built with one primitive per leaf)
//! is collapsed into nodes of up to four children (Wald, Benthin & Boulos,
//! "Getting rid of packets", 2008; Dammertz et al., "Shallow bounding volume
//! hierarchies", 2008): a node repeatedly opens its largest inner child until
//! it holds four. The four child boxes are stored as structure-of-arrays
//! `f32` lanes (one 128-byte, cache-aligned node), so one SSE sequence gives
//! all four box distances or containment tests and the tree is half as deep.
//! A child is either another node or one primitive (triangle or tetrahedron
//! slot); queries test primitives in `f64`.
//!
//! Boxes are rounded outwards to `f32` and grown by a margin of
//! `16·ε_f32·max|coordinate|`, which covers rounding the query point and the
//! single-precision arithmetic: a box is only skipped when its true distance
//! exceeds the best one found, so results equal a pure `f64` traversal.

use glam::{BVec4A, DVec3, Vec4};

use crate::aabb::Aabb;

use super::bvh::Bvh;
use super::round::{f32_down, f32_up};

/// Marks a child slot that holds a primitive (its slot number in the low bits).
const PRIM: u32 = 1 << 31;
/// An unused child slot (its box is empty, so no query ever reaches it).
const EMPTY: u32 = u32::MAX;

/// Four child boxes as lanes, plus the children.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
struct Node4 {
    /// Lowest x, y, z of the four child boxes.
    lo: [Vec4; 3],
    /// Highest x, y, z of the four child boxes.
    hi: [Vec4; 3],
    /// `PRIM | slot`, a node index, or `EMPTY`.
    child: [u32; 4],
}

/// One child of a node, as [`WideBvh::children`] lists them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum WideChild {
    /// A primitive's slot.
    Prim(u32),
    /// Another node's index.
    Node(u32),
}

/// The collapsed tree. Node 0 is the root.
#[derive(Clone, Debug)]
pub(crate) struct WideBvh {
    nodes: Vec<Node4>,
}

/// Squared `f32` bound that is at least `d2` (so pruning stays conservative).
#[inline(always)]
fn bound(d2: f64) -> f32 {
    f32_up(d2 * (1.0 + 1e-5))
}

impl WideBvh {
    /// Collapses `bvh`, whose leaves must hold one primitive each.
    pub fn new(bvh: &Bvh) -> WideBvh {
        let root = &bvh.nodes[0];
        let scale = root.min.abs().max(root.max.abs()).max_element();
        let margin = 16.0 * f32::EPSILON as f64 * scale;
        let mut nodes: Vec<Node4> = Vec::with_capacity(bvh.nodes.len() / 2 + 1);
        // (binary node to collapse, wide node to fill)
        let mut work = vec![(0usize, 0usize)];
        nodes.push(Node4 {
            lo: [Vec4::INFINITY; 3],
            hi: [Vec4::NEG_INFINITY; 3],
            child: [EMPTY; 4],
        });
        while let Some((bi, wi)) = work.pop() {
            let b = &bvh.nodes[bi];
            let mut items: Vec<usize> = if b.is_leaf() {
                vec![bi]
            } else {
                vec![b.first as usize, b.first as usize + 1]
            };
            while items.len() < 4 {
                // Open the inner child with the largest surface area.
                let area = |i: usize| {
                    let e = bvh.nodes[i].max - bvh.nodes[i].min;
                    e.x * e.y + e.y * e.z + e.z * e.x
                };
                let Some(k) = (0..items.len())
                    .filter(|&k| !bvh.nodes[items[k]].is_leaf())
                    .max_by(|&x, &y| area(items[x]).total_cmp(&area(items[y])))
                else {
                    break;
                };
                let c = bvh.nodes[items[k]].first as usize;
                items[k] = c;
                items.push(c + 1);
            }
            for (lane, &it) in items.iter().enumerate() {
                let n = &bvh.nodes[it];
                for a in 0..3 {
                    nodes[wi].lo[a][lane] = f32_down(n.min[a] - margin);
                    nodes[wi].hi[a][lane] = f32_up(n.max[a] + margin);
                }
                nodes[wi].child[lane] = if n.is_leaf() {
                    PRIM | n.first
                } else {
                    nodes.push(Node4 {
                        lo: [Vec4::INFINITY; 3],
                        hi: [Vec4::NEG_INFINITY; 3],
                        child: [EMPTY; 4],
                    });
                    work.push((it, nodes.len() - 1));
                    (nodes.len() - 1) as u32
                };
            }
        }
        WideBvh { nodes }
    }

    /// Nearest primitive to `p` closer than `sqrt(max_d2)`: `test(slot, best)`
    /// returns the squared distance of a primitive (or anything `>= best`
    /// when a cheap bound already rules it out). Returns the slot and its
    /// squared distance. Children are visited nearest first; the stack holds
    /// at most three entries per level.
    #[inline(always)]
    pub fn nearest<F: FnMut(u32, f64) -> f64>(
        &self,
        p: DVec3,
        max_d2: f64,
        mut test: F,
    ) -> Option<(u32, f64)> {
        let px = Vec4::splat(p.x as f32);
        let py = Vec4::splat(p.y as f32);
        let pz = Vec4::splat(p.z as f32);
        let mut best = max_d2;
        let mut best_f = bound(best);
        let mut best_slot = EMPTY;
        let mut stack = Stack::<(u32, f32)>::new();
        let mut ni = 0usize;
        'visit: loop {
            let n = &self.nodes[ni];
            let dx = (n.lo[0] - px).max(px - n.hi[0]).max(Vec4::ZERO);
            let dy = (n.lo[1] - py).max(py - n.hi[1]).max(Vec4::ZERO);
            let dz = (n.lo[2] - pz).max(pz - n.hi[2]).max(Vec4::ZERO);
            let d2 = dx * dx + dy * dy + dz * dz;
            let mut mask = d2.cmplt(Vec4::splat(best_f)).bitmask();
            let d2 = d2.to_array();
            let mut inner = [(0u32, 0.0f32); 4];
            let mut ni_count = 0;
            while mask != 0 {
                let lane = mask.trailing_zeros() as usize;
                mask &= mask - 1;
                let c = n.child[lane];
                if c & PRIM != 0 {
                    let s = c & !PRIM;
                    let d = test(s, best);
                    if d < best {
                        best = d;
                        best_f = bound(d);
                        best_slot = s;
                    }
                } else {
                    inner[ni_count] = (c, d2[lane]);
                    ni_count += 1;
                }
            }
            // Keep the inner children still in reach, sorted by distance.
            let mut k = 0;
            for i in 0..ni_count {
                let e = inner[i];
                if e.1 < best_f {
                    let mut j = k;
                    while j > 0 && inner[j - 1].1 > e.1 {
                        inner[j] = inner[j - 1];
                        j -= 1;
                    }
                    inner[j] = e;
                    k += 1;
                }
            }
            if k > 0 {
                // Farthest first, so the nearest remaining pops first.
                for e in inner[1..k].iter().rev() {
                    stack.push(*e);
                }
                ni = inner[0].0 as usize;
                continue 'visit;
            }
            while let Some((node, d)) = stack.pop() {
                if d < best_f {
                    ni = node as usize;
                    continue 'visit;
                }
            }
            break;
        }
        (best_slot != EMPTY).then_some((best_slot, best))
    }

    /// Calls `f` with every primitive whose box may meet `b` (boxes and `b`
    /// rounded outwards); stops and returns false as soon as `f` does.
    pub fn overlapping<F: FnMut(u32) -> bool>(&self, b: &Aabb, mut f: F) -> bool {
        let q = RoundedBox::new(b);
        self.walk(
            |n| (q.meets(n), 0),
            |c| match c {
                WideChild::Prim(slot) => f(slot),
                WideChild::Node(_) => true, // (no lane is whole)
            },
        )
    }

    /// Nodes in the tree (node 0 is the root), for tables kept per node.
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// The children of node `i`: a primitive's slot or another node. A
    /// node's children have larger indices than the node (the build pushes
    /// a node before its children), so a pass over the nodes from the last
    /// to the first sees every child before its parent.
    pub fn children(&self, i: usize) -> impl Iterator<Item = WideChild> + '_ {
        self.nodes[i]
            .child
            .iter()
            .filter(|&&c| c != EMPTY)
            .map(|&c| {
                if c & PRIM != 0 {
                    WideChild::Prim(c & !PRIM)
                } else {
                    WideChild::Node(c)
                }
            })
    }

    /// As [`WideBvh::overlapping`], calling `visit` with each primitive
    /// reached, but a node whose (rounded) box lies within `b`'s is handed
    /// whole to `visit` as [`WideChild::Node`] instead of being opened.
    /// Every primitive below such a node meets `b`: a primitive's box lies
    /// within each box above it (node boxes are unions of their children's,
    /// and rounding outwards keeps the order), so a caller that keeps a
    /// summary per node sees the same primitives. Stops and returns false
    /// as soon as `visit` does.
    pub fn overlapping_nodes(&self, b: &Aabb, visit: impl FnMut(WideChild) -> bool) -> bool {
        let q = RoundedBox::new(b);
        self.walk(|n| (q.meets(n), q.holds(n)), visit)
    }

    /// First primitive whose box contains `p` and for which `test(slot)` is
    /// true.
    #[inline(always)]
    pub fn find<F: FnMut(u32) -> bool>(&self, p: DVec3, mut test: F) -> Option<u32> {
        let q = [p.x, p.y, p.z].map(|v| Vec4::splat(v as f32));
        let mut found = None;
        self.walk(
            |n| (every_axis(|a| q[a].cmpge(n.lo[a]) & q[a].cmple(n.hi[a])), 0),
            |c| {
                let WideChild::Prim(slot) = c else {
                    return true; // (no lane is whole)
                };
                let hit = test(slot);
                if hit {
                    found = Some(slot);
                }
                !hit
            },
        );
        found
    }

    /// Depth-first walk into the children that `lanes` selects (bit masks
    /// of a node's four lanes: the lanes to enter, and among them the inner
    /// ones to hand to `visit` whole instead of opening), calling `visit`
    /// with each primitive reached and each whole node; stops and returns
    /// false as soon as `visit` does.
    #[inline(always)]
    fn walk(
        &self,
        lanes: impl Fn(&Node4) -> (u32, u32),
        mut visit: impl FnMut(WideChild) -> bool,
    ) -> bool {
        let mut stack = Stack::<u32>::new();
        let mut ni = 0usize;
        loop {
            let n = &self.nodes[ni];
            let (mut mask, whole) = lanes(n);
            while mask != 0 {
                let lane = mask.trailing_zeros() as usize;
                mask &= mask - 1;
                let c = n.child[lane];
                let reached = if c & PRIM != 0 {
                    Some(WideChild::Prim(c & !PRIM))
                } else if whole & (1 << lane) != 0 {
                    Some(WideChild::Node(c))
                } else {
                    None
                };
                match reached {
                    Some(r) => {
                        if !visit(r) {
                            return false;
                        }
                    }
                    None => stack.push(c),
                }
            }
            match stack.pop() {
                Some(next) => ni = next as usize,
                None => return true,
            }
        }
    }
}

/// A query box rounded outwards to `f32`, splat across the four lanes.
struct RoundedBox {
    lo: [Vec4; 3],
    hi: [Vec4; 3],
}

impl RoundedBox {
    fn new(b: &Aabb) -> RoundedBox {
        RoundedBox {
            lo: [b.min.x, b.min.y, b.min.z].map(|v| Vec4::splat(f32_down(v))),
            hi: [b.max.x, b.max.y, b.max.z].map(|v| Vec4::splat(f32_up(v))),
        }
    }

    /// Lanes of `n` whose boxes meet this one.
    #[inline(always)]
    fn meets(&self, n: &Node4) -> u32 {
        every_axis(|a| n.lo[a].cmple(self.hi[a]) & n.hi[a].cmpge(self.lo[a]))
    }

    /// Lanes of `n` whose boxes lie within this one.
    #[inline(always)]
    fn holds(&self, n: &Node4) -> u32 {
        every_axis(|a| n.lo[a].cmpge(self.lo[a]) & n.hi[a].cmple(self.hi[a]))
    }
}

/// The lanes for which `test(axis)` holds on all three axes.
#[inline(always)]
fn every_axis(test: impl Fn(usize) -> BVec4A) -> u32 {
    (test(0) & test(1) & test(2)).bitmask()
}

/// Traversal stack: a small inline array (enough for any realistic tree:
/// three entries per level) that spills to the heap instead of overflowing.
struct Stack<T: Copy + Default> {
    inline: [T; 32],
    len: usize,
    spill: Vec<T>,
}

impl<T: Copy + Default> Stack<T> {
    #[inline(always)]
    fn new() -> Self {
        Stack {
            inline: [T::default(); 32],
            len: 0,
            spill: Vec::new(),
        }
    }

    #[inline(always)]
    fn push(&mut self, v: T) {
        if self.len < self.inline.len() {
            self.inline[self.len] = v;
            self.len += 1;
        } else {
            self.spill.push(v);
        }
    }

    #[inline(always)]
    fn pop(&mut self) -> Option<T> {
        if let Some(v) = self.spill.pop() {
            return Some(v);
        }
        if self.len == 0 {
            return None;
        }
        self.len -= 1;
        Some(self.inline[self.len])
    }
}
