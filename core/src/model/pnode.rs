//! The prepared tree: every node resolved to the data its evaluation needs
//! (dense material indices, compiled expressions, matrices, spatial indices),
//! and its signed distance.
//!
//! Evaluation is a recursive `match` over this enum: static dispatch, no
//! allocation, no parsing. Shared subtrees of the script's tree stay shared
//! (`Arc`), so a unit cell under `Tile` is prepared once.

use std::sync::Arc;

use glam::{DMat3, DVec2, DVec3};

use super::sdf;
use super::shapes::Capsule;
use super::strut_grid::StrutGrid;
use super::tpms::Tpms;
use super::union_index::{Candidates, UnionIndex};
use crate::aabb::Aabb;
use crate::expr::Expr;

/// Dense material index within one model (position in `Model::materials`).
pub type Slot = u16;

/// Fractions that are the same at every point of a node (a primitive, a
/// moved primitive, an FGrade of constants: every strut of the bunny
/// lattice). A union keeps one per child so the winning child's material
/// is one table read, not a walk down the child's tree and its expression
/// tapes (those pointer chases dominated random-order profiles).
#[derive(Clone, Copy, Debug)]
pub struct FixedFractions {
    pub(super) len: u8,
    pub(super) slots: [Slot; 4],
    pub(super) values: [f64; 4],
}

impl FixedFractions {
    pub(super) fn one(m: Slot) -> Self {
        Self {
            len: 1,
            slots: [m, 0, 0, 0],
            values: [1.0, 0.0, 0.0, 0.0],
        }
    }

    /// Add the fractions into `out` (zero on entry), as `frac` would.
    #[inline]
    pub fn write(&self, out: &mut [f64]) {
        for i in 0..self.len as usize {
            out[self.slots[i] as usize] += self.values[i];
        }
    }
}

/// A capsule alone on a 64-byte cache line (a union's candidate loop reads
/// one per visited child, in random order; `Option<Capsule>` took 72 bytes,
/// so most straddled two lines). `r` is NaN for a child that is not a
/// capsule.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub struct LineCapsule(pub Capsule);

impl LineCapsule {
    /// The capsule of a child, or the NaN marker.
    pub fn of(c: Option<Capsule>) -> Self {
        LineCapsule(c.unwrap_or(Capsule {
            a: DVec3::ZERO,
            ab: DVec3::ZERO,
            inv_ab2: 0.0,
            r: f64::NAN,
        }))
    }
}

/// A planar polygon extruded along its normal, in its own frame.
#[derive(Clone, Debug)]
pub struct Prism {
    /// World -> frame rotation (rows: u, v, n).
    pub to_frame: DMat3,
    pub origin: DVec3,
    pub poly: Vec<DVec2>,
    /// Extent along the normal in frame coordinates.
    pub w_mid: f64,
    pub w_half: f64,
}

impl Prism {
    #[inline]
    pub fn dist(&self, p: DVec3) -> f64 {
        let q = self.to_frame * (p - self.origin);
        let d2 = sdf::polygon_2d(DVec2::new(q.x, q.y), &self.poly);
        sdf::extrude(d2, (q.z - self.w_mid).abs() - self.w_half)
    }
}

/// One prepared node. Field names follow [`crate::node::NodeKind`].
#[derive(Debug)]
pub enum PNode {
    Sphere {
        c: DVec3,
        r: f64,
        m: Slot,
    },
    Box {
        c: DVec3,
        h: DVec3,
        m: Slot,
    },
    Cylinder {
        c: DVec3,
        r: f64,
        hh: f64,
        m: Slot,
    },
    Strut {
        s: Capsule,
        m: Slot,
    },
    Prism {
        p: Box<Prism>,
        m: Slot,
    },
    /// Raw expression value, clipped to `clip` by `max(f, box sdf)`.
    Function {
        expr: Arc<Expr>,
        clip_c: DVec3,
        clip_h: DVec3,
        m: Slot,
    },
    Tpms {
        t: Tpms,
        m: Slot,
    },
    /// Struts of one radius `r`, optionally clipped to a centred box of
    /// half size `clip_h`.
    Lattice {
        struts: Vec<Capsule>,
        /// The cell is symmetric in the three axis planes: `struts` are
        /// those of the positive octant, taken at `|p|`.
        fold: bool,
        r: f64,
        /// Short strut lists per sub-cell of the clip box (see `strut_grid`).
        grid: Option<Box<StrutGrid>>,
        clip_h: Option<DVec3>,
        m: Slot,
    },
    Translate {
        t: DVec3,
        child: Arc<PNode>,
    },
    /// `child(to_local · (p − around) + around)`.
    Rotate {
        to_local: DMat3,
        around: DVec3,
        child: Arc<PNode>,
    },
    /// `child(p · inv) · k`, k = min |s| keeps the value a distance bound.
    Scale {
        inv: DVec3,
        k: f64,
        child: Arc<PNode>,
    },
    /// `child(m·p + t)·k`: a long chain of moves composed at prepare
    /// (`flatten`); `k` is the product of the Scales' `min |s|`.
    Affine(Box<Affine>),
    Union(Box<NAry>),
    Intersection(Box<NAry>),
    Difference {
        a: Arc<PNode>,
        b: Arc<PNode>,
        smooth: f64,
    },
    Offset {
        o: f64,
        child: Arc<PNode>,
    },
    /// Inner band of thickness `t` (> 0): `max(d, −t − d)`.
    Shell {
        t: f64,
        child: Arc<PNode>,
    },
    Tile {
        cell: DVec3,
        child: Arc<PNode>,
    },
    FGrade(Box<Grade>),
    /// Fractions from a scalar attribute of the child through a mix table
    /// (`Convert(child, from, fractions([a, b]), table)`); the child's
    /// distance.
    AttrGrade {
        child: Arc<PNode>,
        src: Arc<crate::attribute::FractionSource>,
    },
    Blend {
        r: f64,
        child: Arc<PNode>,
    },
    Mesh {
        mesh: Arc<crate::trimesh::TriangleMesh>,
        m: Slot,
    },
    SimField(Box<SimGrade>),
    /// Cone, torus, revolve or tapered strut (see `shapes`).
    Shape {
        s: Box<super::shapes::Shape>,
        m: Slot,
    },
    /// `child(p − 2n·(n·(p − point)))`: reflection across a plane.
    Mirror {
        point: DVec3,
        normal: DVec3,
        child: Arc<PNode>,
    },
    /// `Σ dᵢ + iso` (pyvcad's Sum).
    Sum {
        iso: f64,
        children: Vec<Arc<PNode>>,
    },
    /// Text outlines extruded between z = ±hz.
    Text {
        shape: Arc<super::polygon2d::Polygon2d>,
        hz: f64,
        m: Slot,
    },
}

/// `child(m·p + t)·k` (boxed: the other variants are smaller).
#[derive(Debug)]
pub struct Affine {
    pub m: DMat3,
    pub t: DVec3,
    pub k: f64,
    pub child: Arc<PNode>,
}

/// Union or intersection over many children.
#[derive(Debug)]
pub struct NAry {
    pub children: Vec<Arc<PNode>>,
    pub boxes: Vec<Aabb>,
    pub smooth: f64,
    pub blend: bool,
    /// Present for large, sharp unions.
    pub index: Option<UnionIndex>,
    /// Per child, its capsule when its distance is one (a strut, or a
    /// graded strut), evaluated inline in the candidate loop without pointer
    /// chasing; empty when no child is a capsule.
    pub capsules: Vec<LineCapsule>,
    /// Sharp, and every child 1-Lipschitz (see `PNode::is_lipschitz`).
    pub lipschitz: bool,
    /// Children whose fractions do not depend on the point.
    pub fixed: Vec<Option<FixedFractions>>,
}

/// FGrade: fractions from expressions over the child.
#[derive(Debug)]
pub struct Grade {
    pub exprs: Vec<Arc<Expr>>,
    /// The same expressions, evaluated together (shared work fused).
    pub set: crate::expr::ExprSet,
    pub mats: Vec<Slot>,
    /// Union of the expressions' used-variable masks.
    pub used: u64,
    pub child: Arc<PNode>,
}

/// SimulationField: fractions from expressions over an FEA result.
#[derive(Debug)]
pub struct SimGrade {
    pub field: Arc<crate::simfield::SimField>,
    pub exprs: Vec<Arc<Expr>>,
    /// The same expressions, evaluated together (shared work fused).
    pub set: crate::expr::ExprSet,
    pub mats: Vec<Slot>,
    pub used: u64,
}

/// Number of standard coordinate slots (x y z rho phic r theta phis d).
pub const COORD_SLOTS: usize = 9;
/// Slot of `d`, the child's signed distance.
pub const D_SLOT: usize = 8;
/// Mask of the derived coordinate slots (rho .. phis).
pub const DERIVED_MASK: u64 = 0b0_1111_1000;

impl PNode {
    /// True when `p` is inside (distance ≤ 0). Meshes answer from their
    /// coarse grid where they can (deep inside or far outside) instead of an
    /// exact closest-triangle search: fraction lookups in a solid region ask
    /// this for every voxel.
    #[inline]
    pub fn contains(&self, p: DVec3) -> bool {
        match self {
            PNode::Mesh { mesh, .. } => mesh.contains(p),
            PNode::SimField(g) => g.field.boundary_mesh().contains(p),
            _ => self.dist(p) <= 0.0,
        }
    }

    /// Signed distance at `p` (negative inside; a conservative bound where
    /// no closed form exists).
    pub fn dist(&self, p: DVec3) -> f64 {
        match self {
            PNode::Sphere { c, r, .. } => sdf::sphere(p, *c, *r),
            PNode::Box { c, h, .. } => sdf::rect_prism(p, *c, *h),
            PNode::Cylinder { c, r, hh, .. } => sdf::cylinder(p, *c, *r, *hh),
            PNode::Strut { s, .. } => s.dist(p),
            PNode::Prism { p: prism, .. } => prism.dist(p),
            PNode::Function {
                expr,
                clip_c,
                clip_h,
                ..
            } => {
                let mut slots = [0.0; COORD_SLOTS];
                coord_slots(p, expr.used_vars(), &mut slots);
                expr.eval(&slots).max(sdf::rect_prism(p, *clip_c, *clip_h))
            }
            PNode::Tpms { t, .. } => t.dist(p),
            PNode::Lattice { .. } => self.lattice_dist(p),
            PNode::Translate { t, child } => child.dist(p - *t),
            PNode::Rotate {
                to_local,
                around,
                child,
            } => child.dist(*to_local * (p - *around) + *around),
            PNode::Scale { inv, k, child } => child.dist(p * *inv) * *k,
            PNode::Affine(a) => a.child.dist(a.m * p + a.t) * a.k,
            PNode::Union(u) => u.union_dist(p),
            PNode::Intersection(n) => n.fold_dist(p, f64::max, sdf::smooth_max),
            PNode::Difference { a, b, smooth } => {
                let (da, db) = (a.dist(p), -b.dist(p));
                if *smooth > 0.0 {
                    sdf::smooth_max(da, db, *smooth)
                } else {
                    da.max(db)
                }
            }
            PNode::Offset { o, child } => child.dist(p) - *o,
            PNode::Shell { t, child } => {
                let d = child.dist(p);
                d.max(-*t - d)
            }
            // A tiled unit cell, the common case, without a second call.
            PNode::Tile { cell, child } => match &**child {
                lattice @ PNode::Lattice { .. } => lattice.lattice_dist(tile_local(p, *cell)),
                child => child.dist(tile_local(p, *cell)),
            },
            PNode::FGrade(g) => g.child.dist(p),
            PNode::AttrGrade { child, .. } => child.dist(p),
            PNode::Blend { child, .. } => child.dist(p),
            PNode::Mesh { mesh, .. } => mesh.signed_distance(p),
            PNode::SimField(s) => s.field.signed_distance(p),
            PNode::Shape { s, .. } => s.dist(p),
            PNode::Mirror {
                point,
                normal,
                child,
            } => child.dist(reflect(p, *point, *normal)),
            PNode::Sum { iso, children } => children.iter().map(|c| c.dist(p)).sum::<f64>() + *iso,
            PNode::Text { shape, hz, .. } => {
                sdf::extrude(shape.signed_distance(DVec2::new(p.x, p.y)), p.z.abs() - *hz)
            }
        }
    }
}

impl PNode {
    /// [`Self::dist`], with a sphere's, box's or cylinder's written in place:
    /// the bounding shape of an intersection costs no second call.
    #[inline(always)]
    fn leaf_or_dist(&self, p: DVec3) -> f64 {
        match self {
            PNode::Sphere { c, r, .. } => sdf::sphere(p, *c, *r),
            PNode::Box { c, h, .. } => sdf::rect_prism(p, *c, *h),
            PNode::Cylinder { c, r, hh, .. } => sdf::cylinder(p, *c, *r, *hh),
            _ => self.dist(p),
        }
    }

    /// A [`PNode::Lattice`]'s distance (`NaN` for any other node).
    #[inline(always)]
    fn lattice_dist(&self, p: DVec3) -> f64 {
        let PNode::Lattice {
            struts,
            clip_h,
            r,
            grid,
            fold,
            ..
        } = self
        else {
            return f64::NAN;
        };
        // Mirror symmetry: the clip box and the struts alike.
        let p = if *fold { p.abs() } else { p };
        // min(√d²ᵢ − r) = √(min d²ᵢ) − r, bit for bit (the square
        // root is monotone): one square root a point, not one a
        // strut (they were most of an FCC lattice's time).
        let mut d2 = f64::INFINITY;
        match grid.as_ref().and_then(|g| g.candidates(p)) {
            Some(list) => {
                for &k in list {
                    d2 = crate::fastmath::min_plain(d2, struts[k as usize].axis_dist2(p));
                }
            }
            None => {
                for s in struts {
                    d2 = crate::fastmath::min_plain(d2, s.axis_dist2(p));
                }
            }
        }
        let d = d2.sqrt() - r;
        match clip_h {
            Some(h) => d.max(sdf::rect_prism(p, DVec3::ZERO, *h)),
            None => d,
        }
    }

    /// The bits of a sphere, box, cylinder or strut (kind, parameters,
    /// material): two leaves with the same key are the same node.
    pub fn leaf_key(&self) -> Option<[u64; 9]> {
        let v = |a: DVec3| [a.x.to_bits(), a.y.to_bits(), a.z.to_bits()];
        let (kind, a, b, r, m) = match self {
            PNode::Sphere { c, r, m } => (0, v(*c), [0; 3], *r, *m),
            PNode::Box { c, h, m } => (1, v(*c), v(*h), 0.0, *m),
            PNode::Cylinder { c, r, hh, m } => (2, v(*c), [hh.to_bits(), 0, 0], *r, *m),
            PNode::Strut { s, m } => (3, v(s.a), v(s.ab), s.r, *m),
            _ => return None,
        };
        Some([
            kind,
            a[0],
            a[1],
            a[2],
            b[0],
            b[1],
            b[2],
            r.to_bits(),
            u64::from(m),
        ])
    }
}

impl NAry {
    /// The capsule a child's distance reduces to, if any.
    pub fn capsule_of(child: &PNode) -> Option<Capsule> {
        match child {
            PNode::Strut { s, .. } => Some(*s),
            PNode::FGrade(g) => match &*g.child {
                PNode::Strut { s, .. } => Some(*s),
                _ => None,
            },
            _ => None,
        }
    }

    /// Distance of child `i` (inline for capsules).
    #[inline(always)]
    pub fn child_dist(&self, i: usize, p: DVec3) -> f64 {
        match self.capsules.get(i) {
            Some(LineCapsule(c)) if !c.r.is_nan() => c.dist(p),
            _ => self.children[i].dist(p),
        }
    }

    /// Minimum (or pyvcad's smooth minimum, folded in child order).
    pub fn union_dist(&self, p: DVec3) -> f64 {
        if let Some(index) = &self.index {
            return self.indexed_min(index, p);
        }
        self.fold_dist(p, f64::min, sdf::smooth_min)
    }

    /// The children's distances folded in child order by `sharp`, or by
    /// `smooth` with radius `self.smooth` when it is positive (pyvcad folds
    /// its smooth union and intersection pairwise in this order).
    #[inline]
    fn fold_dist(
        &self,
        p: DVec3,
        sharp: impl Fn(f64, f64) -> f64,
        smooth: impl Fn(f64, f64, f64) -> f64,
    ) -> f64 {
        let mut d = self.children[0].leaf_or_dist(p);
        for c in &self.children[1..] {
            let e = c.leaf_or_dist(p);
            d = if self.smooth > 0.0 {
                smooth(d, e, self.smooth)
            } else {
                sharp(d, e)
            };
        }
        d
    }

    /// Sharp minimum through the spatial index (see `union_index`): the
    /// children with infinite boxes, then `p`'s cell list in order of lower
    /// bound until a bound reaches the best value so far, then the BVH when
    /// the cell cannot prove the minimum (best ≥ margin, or `p` outside the
    /// grid). `union_eval` walks the same way.
    fn indexed_min(&self, index: &UnionIndex, p: DVec3) -> f64 {
        // Speed copy of core/src/model/fractions.rs::NAry::union_eval: through a shared closure-taking walk `best` would leave registers (docs/PERFORMANCE.md, "Speed copies").
        let mut best = f64::INFINITY;
        for &i in index.always() {
            best = best.min(self.child_dist(i as usize, p));
        }
        if let Candidates::Cell {
            entries,
            margin,
            centre,
            ..
        } = index.candidates(p)
        {
            let slack = self.slack(index, p, centre);
            for e in entries {
                if f64::from(e.lo) + slack >= best {
                    break; // the rest are bounded below by lo ≥ best
                }
                best = best.min(self.child_dist(e.child as usize, p));
            }
            if best < margin {
                return best;
            }
        }
        index.bvh().nearest(p, best, |i| {
            let d = self.child_dist(i as usize, p);
            best = best.min(d);
            best
        });
        best
    }

    /// The per-point tightening of the cell bounds, for 1-Lipschitz
    /// children only (their bounds are `d(centre) − r`; see `prepare`).
    #[inline]
    pub(super) fn slack(&self, index: &UnionIndex, p: DVec3, centre: DVec3) -> f64 {
        if self.lipschitz {
            index.slack(p, centre)
        } else {
            0.0
        }
    }
}

/// `p` reflected across the plane through `point` with unit `normal`.
#[inline]
pub fn reflect(p: DVec3, point: DVec3, normal: DVec3) -> DVec3 {
    p - normal * (2.0 * normal.dot(p - point))
}

/// pyvcad's Tile mapping: `p − c·floor(p/c) − c/2` puts the child's origin
/// at every cell centre `(k + ½)·c`.
#[inline]
pub fn tile_local(p: DVec3, cell: DVec3) -> DVec3 {
    p - cell * crate::fastmath::floor3(p / cell) - cell * 0.5
}

/// Fill the coordinate slots an expression reads: x y z always, the derived
/// cylindrical and spherical ones only when `used` asks for them.
#[inline]
pub fn coord_slots(p: DVec3, used: u64, slots: &mut [f64]) {
    slots[0] = p.x;
    slots[1] = p.y;
    slots[2] = p.z;
    if used & DERIVED_MASK != 0 {
        crate::expr::fill_derived_coords_used(slots, used);
    }
}
