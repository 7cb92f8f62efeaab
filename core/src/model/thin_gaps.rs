//! Gaps between parts that the design's tree states: the clearance between
//! two children of a `Union` that are spheres, struts, boxes or cylinders
//! (moved, turned, mirrored and scaled uniformly; boxes and cylinders
//! only moved and scaled, so they stay aligned with the axes), and the
//! width of a slot or hole that a `Difference` cuts with one of them.
//!
//! An export samples the design on a grid: a gap narrower than about two
//! cells can fall between the cell centres and close, joining the parts on
//! either side. The exports compare the narrowest gap with their cell size
//! before sampling, as they do walls and struts ([`Model::thinnest_feature`]).
//!
//! A gap counts only when the whole design agrees: a point just inside each
//! side is inside the design and the middle is outside (a third child that
//! fills the gap, or an `Intersection` that trims a side away, leaves no
//! gap). Gaps of geometry the tree does not state (meshes, `Function`s) are
//! measured by sampling ([`Model::sampled_thinnest`]); gaps between other
//! children (lattices, rotated boxes, text) are not measured.
//!
//! The number of separate parts is known when the whole design is one such
//! union (of at most [`MAX_PARTS`] children): children whose clearance is
//! not positive touch, and the parts are the groups of touching children.

use std::collections::HashSet;
use std::sync::Arc;

use glam::{DMat3, DVec3};

use super::Model;
use super::pnode::PNode;
use crate::aabb::Aabb;

/// Most children of one union whose gaps are measured (pairs are tested
/// against each other: about half a million pairs at most).
pub const MAX_PARTS: usize = 1024;

/// Steps of the alternating projection between two convex solids: it
/// converges linearly, and within a few steps for the solids' usual
/// placements (face to face, centre to centre).
const PROJECTIONS: usize = 100;

/// Gaps verified per union, narrowest first (a filled gap is rejected and
/// the next narrowest tried).
const VERIFIED: usize = 64;

/// A gap between two parts, or a slot cut into one.
#[derive(Clone, Debug, PartialEq)]
pub struct Gap {
    /// Its width in mm (the clearance between the two sides).
    pub width: f64,
    /// What it is, for messages: "between a sphere and a box".
    pub what: String,
    /// Its middle, in mm.
    pub at: DVec3,
}

/// What the tree states about the design's gaps.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct StatedGaps {
    /// The narrowest stated gap below the asked width, if any.
    pub narrowest: Option<Gap>,
    /// The number of separate parts, when the design is one union of
    /// solids whose clearances are all known.
    pub parts: Option<usize>,
}

/// A frame: `world = m · local + o`, `m` a similarity of scale `s`.
#[derive(Clone, Copy, Debug)]
struct Frame {
    m: DMat3,
    o: DVec3,
    s: f64,
}

impl Frame {
    const IDENTITY: Frame = Frame {
        m: DMat3::IDENTITY,
        o: DVec3::ZERO,
        s: 1.0,
    };

    fn apply(&self, p: DVec3) -> DVec3 {
        self.m * p + self.o
    }

    /// The frame of a child evaluated at `a · p + t` (`p` in this frame);
    /// `None` unless `a` is a similarity (a non-uniform scale has no
    /// stated gaps).
    fn inner(&self, a: DMat3, t: DVec3) -> Option<Frame> {
        let ata = a.transpose() * a;
        let s2 = (ata.x_axis.x + ata.y_axis.y + ata.z_axis.z) / 3.0;
        let off = ata - DMat3::from_diagonal(DVec3::splat(s2));
        let flat = off.to_cols_array();
        if !(s2 > 0.0 && s2.is_finite()) || flat.iter().any(|v| v.abs() > 1e-9 * s2) {
            return None;
        }
        let inv = a.inverse();
        Some(Frame {
            m: self.m * inv,
            o: self.o - self.m * (inv * t),
            s: self.s / s2.sqrt(),
        })
    }

    /// True when `m` is `s` times the identity: boxes and cylinders stay
    /// aligned with the axes.
    fn is_aligned(&self) -> bool {
        let off = self.m - DMat3::from_diagonal(DVec3::splat(self.s));
        off.to_cols_array().iter().all(|v| v.abs() <= 1e-9 * self.s)
    }

    fn key(&self) -> [u64; 12] {
        let mut k = [0u64; 12];
        for (slot, v) in k
            .iter_mut()
            .zip(self.m.to_cols_array().into_iter().chain(self.o.to_array()))
        {
            *slot = v.to_bits();
        }
        k
    }
}

/// The frame of the child of a move, turn, mirror or scale; `None` for
/// any other node or a scale that is not uniform.
fn child_frame<'a>(node: &'a PNode, f: &Frame) -> Option<(Frame, &'a Arc<PNode>)> {
    match node {
        PNode::Translate { t, child } => Some((f.inner(DMat3::IDENTITY, -*t)?, child)),
        PNode::Rotate {
            to_local,
            around,
            child,
        } => Some((f.inner(*to_local, *around - *to_local * *around)?, child)),
        PNode::Scale { inv, child, .. } => {
            Some((f.inner(DMat3::from_diagonal(*inv), DVec3::ZERO)?, child))
        }
        PNode::Affine(a) => Some((f.inner(a.m, a.t)?, &a.child)),
        PNode::Mirror {
            point,
            normal,
            child,
        } => {
            let h = DMat3::IDENTITY - 2.0 * outer(*normal, *normal);
            Some((f.inner(h, 2.0 * *normal * normal.dot(*point))?, child))
        }
        _ => None,
    }
}

fn outer(a: DVec3, b: DVec3) -> DMat3 {
    DMat3::from_cols(a * b.x, a * b.y, a * b.z)
}

/// A convex solid in a union's frame.
#[derive(Clone, Copy, Debug)]
enum Solid {
    /// A strut from `a` to `b` of radius `r` (a sphere when `a == b`).
    Ball { a: DVec3, b: DVec3, r: f64 },
    /// A box of half sides `h`.
    Cuboid { c: DVec3, h: DVec3 },
    /// A z-axis cylinder.
    Cyl { c: DVec3, r: f64, hh: f64 },
}

impl Solid {
    /// The solid a leaf is, in the frame `f` maps its frame into.
    fn of(node: &PNode, f: &Frame) -> Option<Solid> {
        match node {
            PNode::Sphere { c, r, .. } => {
                let c = f.apply(*c);
                Some(Solid::Ball {
                    a: c,
                    b: c,
                    r: r * f.s,
                })
            }
            PNode::Strut { s, .. } => Some(Solid::Ball {
                a: f.apply(s.a),
                b: f.apply(s.a + s.ab),
                r: s.r * f.s,
            }),
            PNode::Box { c, h, .. } if f.is_aligned() => Some(Solid::Cuboid {
                c: f.apply(*c),
                h: *h * f.s,
            }),
            PNode::Cylinder { c, r, hh, .. } if f.is_aligned() => Some(Solid::Cyl {
                c: f.apply(*c),
                r: r * f.s,
                hh: hh * f.s,
            }),
            _ => None,
        }
    }

    fn name(&self) -> &'static str {
        match self {
            Solid::Ball { a, b, .. } if a == b => "a sphere",
            Solid::Ball { .. } => "a strut",
            Solid::Cuboid { .. } => "a box",
            Solid::Cyl { .. } => "a cylinder",
        }
    }

    fn bbox(&self) -> Aabb {
        match *self {
            Solid::Ball { a, b, r } => Aabb::new(a.min(b) - DVec3::splat(r), a.max(b) + r),
            Solid::Cuboid { c, h } => Aabb::new(c - h, c + h),
            Solid::Cyl { c, r, hh } => {
                let h = DVec3::new(r, r, hh);
                Aabb::new(c - h, c + h)
            }
        }
    }

    /// Its thinnest extent, and the direction and middle of the slot it
    /// cuts when it is a `Difference`'s subtrahend.
    fn slot(&self) -> (f64, DVec3, DVec3) {
        match *self {
            Solid::Ball { a, b, r } => {
                let across = (b - a)
                    .try_normalize()
                    .map_or(DVec3::X, |u| u.any_orthonormal_vector());
                (2.0 * r, across, 0.5 * (a + b))
            }
            Solid::Cuboid { c, h } => {
                let i = (0..3).fold(0, |m, i| if h[i] < h[m] { i } else { m });
                (2.0 * h[i], DVec3::AXES[i], c)
            }
            Solid::Cyl { c, r, hh } if r <= hh => (2.0 * r, DVec3::X, c),
            Solid::Cyl { c, hh, .. } => (2.0 * hh, DVec3::Z, c),
        }
    }

    /// The point of the solid nearest `p`.
    fn project(&self, p: DVec3) -> DVec3 {
        match *self {
            Solid::Ball { a, b, r } => {
                let ab = b - a;
                let l2 = ab.length_squared();
                let t = if l2 > 0.0 {
                    ((p - a).dot(ab) / l2).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                let q = a + ab * t;
                let v = p - q;
                let l = v.length();
                if l <= r { p } else { q + v * (r / l) }
            }
            Solid::Cuboid { c, h } => p.clamp(c - h, c + h),
            Solid::Cyl { c, r, hh } => {
                let v = (p - c).truncate();
                let l = v.length();
                let v = if l <= r { v } else { v * (r / l) };
                c + v.extend((p.z - c.z).clamp(-hh, hh))
            }
        }
    }
}

/// The clearance between two convex solids and the nearest points on each,
/// by alternating projection (von Neumann): it converges to the nearest
/// pair of disjoint convex sets, and to a common point of overlapping ones.
fn clearance(a: &Solid, b: &Solid) -> (f64, DVec3, DVec3) {
    let mut pb = b.project(a.bbox().center());
    let mut pa = a.project(pb);
    for _ in 0..PROJECTIONS {
        let nb = b.project(pa);
        let na = a.project(nb);
        let moved = (nb - pb).length() + (na - pa).length();
        (pa, pb) = (na, nb);
        if moved <= 1e-13 * (1.0 + pa.length()) {
            break;
        }
    }
    ((pb - pa).length(), pa, pb)
}

/// The smallest of a solid's sizes (a sphere's diameter, a box's side).
fn thickness(s: &Solid) -> f64 {
    s.slot().0
}

/// The leaves of a union, flattened through nested unions and moves:
/// solids in the union's frame, and the other children with the frames
/// that map them into it; `None` past [`MAX_PARTS`].
type Flat<'a> = (Vec<Solid>, Vec<(&'a Arc<PNode>, Frame)>);

fn flatten(children: &[Arc<PNode>]) -> Option<Flat<'_>> {
    let mut solids = Vec::new();
    let mut others = Vec::new();
    let mut stack: Vec<(&Arc<PNode>, Frame)> = children
        .iter()
        .rev()
        .map(|c| (c, Frame::IDENTITY))
        .collect();
    while let Some((node, f)) = stack.pop() {
        if solids.len() + others.len() >= MAX_PARTS {
            return None;
        }
        if let Some(s) = Solid::of(node, &f) {
            solids.push(s);
            continue;
        }
        match node.as_ref() {
            PNode::Union(n) if n.smooth == 0.0 && !n.blend => {
                stack.extend(n.children.iter().rev().map(|c| (c, f)))
            }
            PNode::FGrade(g) => stack.push((&g.child, f)),
            PNode::AttrGrade { child, .. } => stack.push((child, f)),
            other => match child_frame(other, &f) {
                Some((cf, child)) => stack.push((child, cf)),
                None => others.push((node, f)),
            },
        }
    }
    Some((solids, others))
}

/// Minimal union-find over part indices.
fn root(parent: &mut [usize], mut i: usize) -> usize {
    while parent[i] != i {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    i
}

/// A gap between solids `i` and `j` of a union: its width and the nearest
/// points on each.
type PairGap = (f64, usize, usize, DVec3, DVec3);

/// Gaps of one union's solids below `below` (mm in the union's frame),
/// narrowest first, and the number of groups of touching solids.
fn union_gaps(solids: &[Solid], below: f64) -> (Vec<PairGap>, usize) {
    let boxes: Vec<Aabb> = solids.iter().map(Solid::bbox).collect();
    let mut parent: Vec<usize> = (0..solids.len()).collect();
    let mut gaps = Vec::new();
    for i in 0..solids.len() {
        for j in i + 1..solids.len() {
            let apart = boxes[i]
                .min
                .sub_gap(boxes[j].max)
                .max(boxes[j].min.sub_gap(boxes[i].max));
            if apart.length() >= below.max(f64::MIN_POSITIVE) {
                continue;
            }
            let (g, pa, pb) = clearance(&solids[i], &solids[j]);
            // Touching within rounding of the solids' sizes.
            let tol = 1e-9 * (1.0 + thickness(&solids[i]).max(thickness(&solids[j])));
            if g <= tol {
                let (a, b) = (root(&mut parent, i), root(&mut parent, j));
                parent[a] = b;
            } else if g < below {
                gaps.push((g, i, j, pa, pb));
            }
        }
    }
    gaps.sort_by(|a, b| a.0.total_cmp(&b.0).then((a.1, a.2).cmp(&(b.1, b.2))));
    let groups = (0..solids.len())
        .filter(|&i| root(&mut parent, i) == i)
        .count();
    (gaps, groups)
}

/// How far each box lies beyond the other, per axis (negative overlap is
/// clamped to zero).
trait SubGap {
    fn sub_gap(self, other: DVec3) -> DVec3;
}

impl SubGap for DVec3 {
    fn sub_gap(self, other: DVec3) -> DVec3 {
        (self - other).max(DVec3::ZERO)
    }
}

/// A gap the tree states, to be checked against the whole design: in the
/// frame `frame`, the points `inside` must be inside the design and `mid`
/// outside.
struct Candidate {
    width: f64,
    frame: Frame,
    inside: [DVec3; 2],
    mid: DVec3,
    /// The two solids' names (a gap between them), or the cutter's alone.
    what: (&'static str, Option<&'static str>),
}

impl Candidate {
    /// A gap between two solids of a union, nearest points `pa` and `pb`
    /// (`g` apart) in the union's frame `f`.
    fn between(a: &Solid, b: &Solid, (g, pa, pb): (f64, DVec3, DVec3), f: Frame) -> Candidate {
        let u = (pb - pa) / g;
        let e = 0.25 * g.min(thickness(a)).min(thickness(b));
        Candidate {
            width: g * f.s,
            frame: f,
            inside: [pa - u * e, pb + u * e],
            mid: 0.5 * (pa + pb),
            what: (a.name(), Some(b.name())),
        }
    }

    /// The slot or hole a `Difference` cuts with `b`, when `b` is one solid.
    fn slot(b: &Arc<PNode>, f: Frame) -> Option<Candidate> {
        let (solids, others) = flatten(std::slice::from_ref(b))?;
        let ([s], true) = (solids.as_slice(), others.is_empty()) else {
            return None;
        };
        let (w, across, c) = s.slot();
        let reach = across * (0.75 * w);
        Some(Candidate {
            width: w * f.s,
            frame: f,
            inside: [c + reach, c - reach],
            mid: c,
            what: (s.name(), None),
        })
    }
}

impl Model {
    /// The design's narrowest stated gap below `below` mm and its number of
    /// separate parts where the tree states them (see the module doc).
    /// Walks the tree with an explicit stack, each shared subtree once per
    /// frame; checks at most `VERIFIED` gaps against the whole design,
    /// narrowest first.
    pub fn stated_gaps(&self, below: f64) -> StatedGaps {
        let (candidates, parts) = self.gap_candidates(below);
        let narrowest = candidates.into_iter().take(VERIFIED).find_map(|c| {
            let f = &c.frame;
            let open = c.inside.iter().all(|&p| self.distance(f.apply(p)) <= 0.0)
                && self.distance(f.apply(c.mid)) > 0.0;
            open.then(|| Gap {
                width: c.width,
                what: match c.what {
                    (a, Some(b)) => format!("between {a} and {b}"),
                    (cutter, None) => format!("a slot or hole cut by {cutter}"),
                },
                at: f.apply(c.mid),
            })
        });
        StatedGaps { narrowest, parts }
    }

    /// Every stated gap below `below` mm, narrowest first (ties in the
    /// walk's order), and the number of parts when the design is one union
    /// of solids.
    fn gap_candidates(&self, below: f64) -> (Vec<Candidate>, Option<usize>) {
        let mut out = Vec::new();
        let mut parts = None;
        let mut seen: HashSet<(*const PNode, [u64; 12])> = HashSet::new();
        // (node, its frame, whether it is the design's top after moves)
        let mut stack: Vec<(&Arc<PNode>, Frame, bool)> = vec![(&self.root, Frame::IDENTITY, true)];
        while let Some((node, f, top)) = stack.pop() {
            if !seen.insert((Arc::as_ptr(node), f.key())) {
                continue;
            }
            if Solid::of(node, &Frame::IDENTITY).is_some() {
                parts = parts.or(top.then_some(1));
                continue;
            }
            match node.as_ref() {
                PNode::Union(n) => {
                    let Some((solids, others)) = flatten(&n.children) else {
                        continue;
                    };
                    let (gaps, groups) = union_gaps(&solids, below / f.s);
                    if top && others.is_empty() && n.smooth == 0.0 && !n.blend {
                        parts = Some(groups);
                    }
                    out.extend(gaps.into_iter().map(|(g, i, j, pa, pb)| {
                        Candidate::between(&solids[i], &solids[j], (g, pa, pb), f)
                    }));
                    for (child, cf) in others {
                        stack.push((child, compose(&f, &cf), false));
                    }
                }
                PNode::Intersection(n) => stack.extend(n.children.iter().map(|c| (c, f, false))),
                PNode::Difference { a, b, .. } => {
                    out.extend(Candidate::slot(b, f).filter(|c| c.width < below));
                    stack.push((a, f, false));
                }
                PNode::FGrade(g) => stack.push((&g.child, f, top)),
                PNode::AttrGrade { child, .. } => stack.push((child, f, top)),
                other => {
                    if let Some((cf, child)) = child_frame(other, &f) {
                        stack.push((child, cf, top));
                    }
                }
            }
        }
        // Stable: equal widths keep the walk's order.
        out.sort_by(|a, b| a.width.total_cmp(&b.width));
        (out, parts)
    }
}

/// The frame `inner` (a child's, relative to a union) seen from the world
/// through the union's frame `outer`.
fn compose(outer: &Frame, inner: &Frame) -> Frame {
    Frame {
        m: outer.m * inner.m,
        o: outer.apply(inner.o),
        s: outer.s * inner.s,
    }
}

#[cfg(test)]
mod tests {
    use crate::script::{ScriptOptions, model_of};

    fn gaps(src: &str, below: f64) -> super::StatedGaps {
        model_of(src, "t.rhai", &ScriptOptions::default())
            .expect("design prepares")
            .stated_gaps(below)
    }

    #[test]
    fn two_spheres_a_fifth_of_a_millimetre_apart() {
        let g = gaps(
            r#"let m = default_materials();
Union(false, [Sphere(Vec3(0,0,0), 2, m.id("gray")), Sphere(Vec3(4.2,0,0), 2, m.id("gray"))])"#,
            1.0,
        );
        let n = g.narrowest.expect("the gap");
        assert!((n.width - 0.2).abs() < 1e-9, "{n:?}");
        assert!(
            (n.at - glam::DVec3::new(2.1, 0.0, 0.0)).length() < 1e-9,
            "{n:?}"
        );
        assert_eq!(g.parts, Some(2));
    }

    #[test]
    fn a_filled_gap_touching_boxes_and_a_slot() {
        // A third sphere fills the gap: no gap, one part.
        let g = gaps(
            r#"let m = default_materials();
Union(false, [Sphere(Vec3(0,0,0), 2, m.id("gray")), Sphere(Vec3(4.2,0,0), 2, m.id("gray")), Sphere(Vec3(2.1,0,0), 0.5, m.id("gray"))])"#,
            1.0,
        );
        assert_eq!((g.narrowest, g.parts), (None, Some(1)));
        // An L of two boxes that share a face: one part, no gap.
        let g = gaps(
            r#"let m = default_materials();
Union(false, [RectPrism(Vec3(0,0,0), Vec3(10,2,2), m.id("gray")), RectPrism(Vec3(-4,4,0), Vec3(2,6,2), m.id("gray"))])"#,
            1.0,
        );
        assert_eq!((g.narrowest, g.parts), (None, Some(1)));
        // A 0.3 mm slot across a plate, scaled by 2.
        let g = gaps(
            r#"let m = default_materials();
Scale(2, 2, 2, Difference(RectPrism(Vec3(0,0,0), Vec3(10,10,2), m.id("gray")), RectPrism(Vec3(0,0,0), Vec3(0.15,20,4), m.id("gray"))))"#,
            1.0,
        );
        let n = g.narrowest.expect("the slot");
        assert!((n.width - 0.3).abs() < 1e-9, "{n:?}");
        assert!(n.what.contains("a box"), "{n:?}");
        assert_eq!(g.parts, None);
    }
}
