//! Conservative bounds over boxes, for samplers that skip empty space and fill
//! homogeneous regions without touching every voxel.
//!
//! * `interval(b)`: an interval containing the node's value at every point of
//!   box `b`. Exact SDFs are 1-Lipschitz, so `d(centre) ± half diagonal`
//!   bounds them; composites combine their children's intervals; math strings
//!   use interval arithmetic (`Expr::eval_interval`).
//! * `constant_fractions(b)`: true when the fractions are the same at every
//!   point of `b` where the node is inside.

use glam::DVec3;

use super::pnode::{COORD_SLOTS, D_SLOT, DERIVED_MASK, NAry, PNode, tile_local};
use super::sdf;
use crate::aabb::Aabb;
use crate::interval::Interval;
use crate::trimesh::Probe;

/// `d(centre) ± half diagonal` for a 1-Lipschitz field.
#[inline]
/// Per axis, the least and the greatest `|pᵢ − cᵢ|` over the points `p` of
/// `b` (least 0 where `b` spans `cᵢ`), computed as the point distances are
/// (`fl(p − c)`, rounding is monotone), so they bound those too.
fn abs_offsets(b: &Aabb, c: DVec3) -> (DVec3, DVec3) {
    let (lo, hi) = (b.min - c, b.max - c);
    let spans = lo.cmple(DVec3::ZERO) & hi.cmpge(DVec3::ZERO);
    let near = DVec3::select(spans, DVec3::ZERO, lo.abs().min(hi.abs()));
    (near, lo.abs().max(hi.abs()))
}

/// Exact intervals of the primitives whose distance does not decrease as
/// each `|pᵢ − cᵢ|` grows (sphere, box, cylinder): the values at the least
/// and the greatest offsets. The Lipschitz bound `d(c) ± r` is looser by up
/// to the box's half diagonal: a 32 × 32 voxel tile of the graded bar
/// within a millimetre of its faces was never settled, and its voxels were
/// evaluated one by one.
fn primitive(node: &PNode, b: &Aabb) -> Option<Interval> {
    match node {
        PNode::Sphere { c, r, .. } => {
            let (near, far) = abs_offsets(b, *c);
            Some(Interval::new(near.length() - r, far.length() - r))
        }
        PNode::Box { c, h, .. } => {
            let (near, far) = abs_offsets(b, *c);
            Some(Interval::new(
                sdf::box_of_offsets(near - *h),
                sdf::box_of_offsets(far - *h),
            ))
        }
        PNode::Cylinder { c, r, hh, .. } => {
            let (near, far) = abs_offsets(b, *c);
            let rho = |v: DVec3| glam::DVec2::new(v.x, v.y).length();
            Some(Interval::new(
                sdf::cylinder_of(rho(near), near.z, *r, *hh),
                sdf::cylinder_of(rho(far), far.z, *r, *hh),
            ))
        }
        _ => None,
    }
}

fn lipschitz(node: &PNode, b: &Aabb) -> Interval {
    let d = node.dist(b.center());
    let r = b.half_diagonal();
    Interval::new(d - r, d + r)
}

/// A mesh's interval: `±(u + r)` when the first triangle of the centre's
/// candidate list lies within `r` of it at distance `u`; else from the
/// bounded distance query, exact (`d ± r`) when the surface is within `2r`
/// of the centre, else only the side that matters
/// (`[d − r, ∞)` outside, `(−∞, d + r]` inside) from the mesh's coarse grid,
/// without a closest-triangle search. Samplers ask this for every tile.
fn mesh_interval(mesh: &crate::trimesh::TriangleMesh, b: &Aabb) -> Interval {
    let r = b.half_diagonal();
    let reach = 2.0 * r + 1e-9;
    let floor = -mesh.bbox().half_diagonal();
    let c = b.center();
    // With a triangle within `r` of the centre, `|d| ≤ u ≤ r`: the exact
    // interval `d ± r` holds zero, so a sampler opens the box whatever `d`
    // is, and `±(u + r)`, which holds it too, comes without the search for
    // the nearest triangle and its side.
    let d = match mesh.signed_distance_unless_within(c, r) {
        Some(Probe::Within(u)) => return Interval::new((-(u + r)).max(floor), u + r),
        Some(Probe::Exact(d)) => d,
        None => mesh.signed_distance_bound(c, reach),
    };
    if d.abs() < reach {
        Interval::new((d - r).max(floor), d + r)
    } else if d > 0.0 {
        Interval::new(d - r, f64::INFINITY)
    } else {
        Interval::new(floor.min(d + r), d + r)
    }
}

/// The part of a Tile child's domain that box `b` maps to: the mapped box if
/// `b` lies in one cell, else the whole cell.
fn tile_box(b: &Aabb, cell: DVec3) -> Aabb {
    let lo = crate::fastmath::floor3(b.min / cell);
    let hi = crate::fastmath::floor3(b.max / cell);
    if lo == hi {
        let q = tile_local(b.min, cell);
        Aabb::new(q, q + b.size())
    } else {
        Aabb::from_center_size(DVec3::ZERO, cell)
    }
}

/// The reflection `I − 2nnᵀ` across a plane with unit normal `n`.
pub fn reflection(n: DVec3) -> glam::DMat3 {
    glam::DMat3::IDENTITY - 2.0 * glam::DMat3::from_cols(n * n.x, n * n.y, n * n.z)
}

/// The box of `m·p + t` over the points `p` of `b`.
fn affine_box(b: &Aabb, m: &glam::DMat3, t: DVec3) -> Aabb {
    let q = b.transformed(m, DVec3::ZERO);
    Aabb::new(q.min + t, q.max + t)
}

/// Intervals of the coordinate slots over `b` (x y z rho phic r theta phis d).
/// `used`: the slots the caller's expressions read (bit `i` for slot `i`);
/// the derived ones are bounded only when some is read (two interval
/// squares and roots a call, which a gradient along an axis never reads),
/// and are `EVERYTHING` otherwise.
pub fn coord_intervals(b: &Aabb, d: Interval, used: u64) -> [Interval; COORD_SLOTS] {
    let x = Interval::new(b.min.x, b.max.x);
    let y = Interval::new(b.min.y, b.max.y);
    let z = Interval::new(b.min.z, b.max.z);
    if used & DERIVED_MASK == 0 {
        let all = Interval::EVERYTHING;
        return [x, y, z, all, all, all, all, all, d];
    }
    let rho = (x.square() + y.square()).sqrt();
    let r = (x.square() + y.square() + z.square()).sqrt();
    let angle = Interval::new(-std::f64::consts::PI, std::f64::consts::PI);
    let polar = Interval::new(0.0, std::f64::consts::PI);
    [x, y, z, rho, angle, r, angle, polar, d]
}

impl PNode {
    /// True when the node's value is 1-Lipschitz (`|f(p) − f(q)| ≤ |p − q|`),
    /// so `f(c) ± r` bounds it over a ball of radius `r`: exact Euclidean
    /// distances, and what min, max, offsets, shells, rigid motions and the
    /// metric Scale make of them. Math-string functions, TPMS sheets (an
    /// approximation) and Tile (its repetition breaks continuity at cell
    /// borders when the child is larger than the cell) are not.
    pub fn is_lipschitz(&self) -> bool {
        match self {
            PNode::Sphere { .. }
            | PNode::Box { .. }
            | PNode::Cylinder { .. }
            | PNode::Strut { .. }
            | PNode::Prism { .. }
            | PNode::Lattice { .. }
            | PNode::Mesh { .. }
            | PNode::SimField(_)
            | PNode::Text { .. }
            | PNode::Shape { .. } => true,
            // A sum of n distances changes up to n times as fast.
            PNode::Sum { children, .. } => children.len() == 1 && children[0].is_lipschitz(),
            PNode::Function { .. } | PNode::Tpms { .. } => false,
            // A lattice folded into one octant (mirror symmetric in its mid
            // planes) and clipped to the tiled cell takes the same value on
            // both sides of every cell face, so the tiling is continuous
            // and, 1-Lipschitz within each cell, 1-Lipschitz everywhere.
            // Any other tiled child may jump at the faces.
            PNode::Tile { cell, child } => matches!(
                &**child,
                PNode::Lattice { fold: true, clip_h: Some(h), .. } if *h * 2.0 == *cell
            ),
            PNode::Translate { child, .. }
            | PNode::Rotate { child, .. }
            | PNode::Scale { child, .. }
            | PNode::Offset { child, .. }
            | PNode::Shell { child, .. }
            | PNode::Blend { child, .. }
            | PNode::Mirror { child, .. } => child.is_lipschitz(),
            PNode::FGrade(g) => g.child.is_lipschitz(),
            PNode::AttrGrade { child, .. } => child.is_lipschitz(),
            PNode::Affine(a) => a.child.is_lipschitz(),
            PNode::Union(n) | PNode::Intersection(n) => n.lipschitz,
            PNode::Difference { a, b, smooth } => {
                *smooth <= 0.0 && a.is_lipschitz() && b.is_lipschitz()
            }
        }
    }

    /// A conservative interval of the distance over `b`.
    pub fn interval(&self, b: &Aabb) -> Interval {
        match self {
            PNode::Sphere { .. } | PNode::Box { .. } | PNode::Cylinder { .. } => {
                primitive(self, b).unwrap_or_else(|| lipschitz(self, b))
            }
            PNode::Strut { .. }
            | PNode::Prism { .. }
            | PNode::Lattice { .. }
            | PNode::Shape { .. }
            | PNode::Text { .. } => lipschitz(self, b),
            PNode::Mirror {
                point,
                normal,
                child,
            } => child.interval(&b.transformed(&reflection(*normal), *point)),
            PNode::Sum { iso, children } => {
                let mut i = Interval::point(*iso);
                for c in children {
                    let ci = c.interval(b);
                    i = Interval::new(i.lo + ci.lo, i.hi + ci.hi);
                }
                i
            }
            PNode::Mesh { mesh, .. } => mesh_interval(mesh, b),
            PNode::SimField(g) => mesh_interval(g.field.boundary_mesh(), b),
            PNode::Function {
                expr,
                clip_c,
                clip_h,
                ..
            } => {
                let slots = coord_intervals(b, Interval::EVERYTHING, expr.used_vars());
                let f = expr.eval_interval(&slots);
                let clip = Aabb::from_center_size(*clip_c, *clip_h * 2.0);
                let dc = super::sdf::rect_prism(b.center(), clip.center(), *clip_h);
                let r = b.half_diagonal();
                f.max(Interval::new(dc - r, dc + r))
            }
            PNode::Tpms { t, .. } => t.interval(b),
            PNode::Translate { t, child } => child.interval(&Aabb::new(b.min - *t, b.max - *t)),
            PNode::Rotate {
                to_local,
                around,
                child,
            } => child.interval(&b.transformed(to_local, *around)),
            PNode::Scale { inv, k, child } => {
                let i = child.interval(&b.scaled(*inv));
                Interval::new(i.lo * *k, i.hi * *k)
            }
            PNode::Affine(a) => {
                let i = a.child.interval(&affine_box(b, &a.m, a.t));
                Interval::new(i.lo * a.k, i.hi * a.k)
            }
            // A sharp union of 1-Lipschitz children is 1-Lipschitz: one
            // indexed query at the centre gives the same interval as the
            // minimum over every child's `d(c) ± r`, without visiting them.
            PNode::Union(u) if u.lipschitz && b.is_finite() => lipschitz(self, b),
            PNode::Union(u) => u.union_interval(b),
            PNode::Intersection(n) => {
                let mut i = n.children[0].interval(b);
                for c in &n.children[1..] {
                    i = i.max(c.interval(b));
                }
                if n.smooth > 0.0 {
                    i.hi += n.smooth;
                }
                i
            }
            PNode::Difference {
                a,
                b: right,
                smooth,
            } => {
                let mut i = a.interval(b).max(-right.interval(b));
                if *smooth > 0.0 {
                    i.hi += *smooth;
                }
                i
            }
            PNode::Offset { o, child } => child.interval(b) - *o,
            PNode::Shell { t, child } => {
                let i = child.interval(b);
                i.max(Interval::point(-*t) - i)
            }
            PNode::Tile { cell, child } => child.interval(&tile_box(b, *cell)),
            PNode::FGrade(g) => g.child.interval(b),
            PNode::AttrGrade { child, .. } => child.interval(b),
            PNode::Blend { child, .. } => child.interval(b),
        }
    }

    /// True when the fractions are the same wherever the node is inside `b`.
    pub fn constant_fractions(&self, b: &Aabb) -> bool {
        if self.leaf_material().is_some() {
            return true;
        }
        if let PNode::Offset { o, .. } = self
            && *o > 0.0
        {
            // Points outside the child count too (see `frac_bounds`).
            return self.fixed_fractions().is_some();
        }
        if let Some((child, cb)) = self.fraction_child_box(b) {
            return child.constant_fractions(&cb);
        }
        match self {
            PNode::SimField(_) => false,
            PNode::Union(u) => u.union_constant(b),
            PNode::Intersection(n) => {
                if n.blend {
                    n.children.iter().all(|c| c.constant_fractions(b)) && n.children.len() == 1
                } else {
                    n.children[0].constant_fractions(b)
                }
            }
            PNode::Difference { a, .. } => a.constant_fractions(b),
            PNode::FGrade(g) => match g.slot_intervals(b) {
                None => true,
                Some(slots) => g.exprs.iter().all(|e| {
                    e.constant().is_some() || {
                        let i = e.eval_interval(&slots);
                        i.lo == i.hi
                    }
                }),
            },
            PNode::AttrGrade { child, src } => {
                super::fraction_bound::attr_grade_constant(child, src, b)
            }
            PNode::Blend { .. } | PNode::Sum { .. } => false,
            _ => true, // leaves: above
        }
    }

    /// The child whose fractions this node passes on
    /// ([`PNode::fraction_child`]), with `b` in the child's frame.
    pub(super) fn fraction_child_box(&self, b: &Aabb) -> Option<(&PNode, Aabb)> {
        let child = self.fraction_child()?;
        let cb = match self {
            PNode::Translate { t, .. } => Aabb::new(b.min - *t, b.max - *t),
            PNode::Rotate {
                to_local, around, ..
            } => b.transformed(to_local, *around),
            PNode::Scale { inv, .. } => b.scaled(*inv),
            PNode::Mirror { point, normal, .. } => b.transformed(&reflection(*normal), *point),
            PNode::Affine(a) => affine_box(b, &a.m, a.t),
            PNode::Tile { cell, .. } => tile_box(b, *cell),
            _ => *b, // offset, shell: the same points
        };
        Some((child, cb))
    }
}

impl super::pnode::Grade {
    /// Intervals of the coordinate slots over `b` (`d` from the child when
    /// an expression reads it); `None` when the child has no inside point
    /// in `b`.
    pub(super) fn slot_intervals(&self, b: &Aabb) -> Option<[Interval; COORD_SLOTS]> {
        let d = self.child.interval(b);
        if d.lo > 0.0 {
            return None;
        }
        let d = if self.used & (1 << D_SLOT) != 0 {
            d
        } else {
            Interval::EVERYTHING
        };
        Some(coord_intervals(b, d, self.used))
    }
}

impl NAry {
    fn union_interval(&self, b: &Aabb) -> Interval {
        let mut acc = Interval::new(f64::INFINITY, f64::INFINITY);
        let take = |acc: &mut Interval, i: Interval| {
            acc.lo = acc.lo.min(i.lo);
            acc.hi = acc.hi.min(i.hi);
        };
        match &self.index {
            Some(index) => {
                for &i in index.always() {
                    take(&mut acc, self.children[i as usize].interval(b));
                }
                // Children near `b` first; then every child whose box is
                // within the current upper bound of `b`. Farther children
                // cannot lower either end: their values exceed the distance
                // to their box, which exceeds `hi` everywhere in `b`.
                let near = b.expand(b.half_diagonal());
                index.bvh().overlapping(&near, |i| {
                    take(&mut acc, self.children[i as usize].interval(b))
                });
                let reach = if acc.hi.is_finite() {
                    b.expand(acc.hi.max(0.0) + b.half_diagonal())
                } else {
                    Aabb::EVERYTHING
                };
                // The second pass skips what the first already took.
                index.bvh().overlapping(&reach, |i| {
                    if !self.boxes[i as usize].overlaps(&near) {
                        take(&mut acc, self.children[i as usize].interval(b))
                    }
                });
            }
            None => {
                for c in &self.children {
                    take(&mut acc, c.interval(b));
                }
            }
        }
        if self.smooth > 0.0 {
            acc.lo -= self.smooth;
        }
        acc
    }

    /// Up to `N` children that may contain a point of `b` (interval
    /// `lo ≤ 0`), and how many; `None` when more than `N` may.
    pub(super) fn maybe_inside<const N: usize>(&self, b: &Aabb) -> Option<([usize; N], usize)> {
        let mut ids = [0usize; N];
        let mut n = 0;
        let mut many = false;
        let mut check = |i: usize| {
            if many || self.children[i].interval(b).lo > 0.0 {
                return;
            }
            if n == N {
                many = true;
            } else {
                ids[n] = i;
                n += 1;
            }
        };
        match &self.index {
            Some(index) => {
                for &i in index.always() {
                    check(i as usize);
                }
                index.bvh().overlapping(b, |i| check(i as usize));
            }
            None => (0..self.children.len()).for_each(&mut check),
        }
        (!many).then_some((ids, n))
    }

    /// Constant when exactly one child can be inside in `b` and it is constant.
    fn union_constant(&self, b: &Aabb) -> bool {
        match self.maybe_inside::<1>(b) {
            None => false,
            Some((_, 0)) => true,
            Some(_) if self.smooth > 0.0 => false,
            Some(([i], _)) => self.children[i].constant_fractions(b),
        }
    }
}
