//! Bounds of the material fractions over a box: every inside point of the
//! box has fractions within them.
//!
//! Why: a consumer that needs only a function of the fractions (a mesh
//! export's segment label: which range of one material's fraction, or
//! which material dominates) can skip evaluating every voxel of a region
//! where the bounds prove that function constant. The rules mirror
//! [`PNode::frac`]; nodes without a cheap bound (a blending union or
//! intersection) answer "unknown" and the caller samples as before.
//!
//! A `Blend` averages its child's fractions over stencil points within `r`
//! (per axis) of p, all inside the child: an average lies in the hull, so
//! the child's bounds over the box grown by `r` hold (widened by 10⁻¹² for
//! the rounding of the average). A smooth union gives a point the
//! fractions of the first child containing it or, in a fillet, of the
//! nearest child; inside the union that child is within `(n − 1)·k` (each
//! of the n − 1 folds of the smooth minimum lowers it by at most k), so the
//! hull is over the children whose interval starts below that. An FEA field
//! (`SimulationField`) is bounded through the nodal ranges of the
//! tetrahedra that meet the box (`SimField::bounds`).
//!
//! A scalar -> fractions conversion (`Convert(child, from, fractions([a,
//! b]), table)`) mixes by the inverted mix table, which is monotonic: the
//! share of b over the box lies between the shares of the ends of `from`'s
//! interval bound ([`crate::attribute::MixTable::mix_bounds`]; with more
//! materials, the path's rows between them too).
//! Points where `from` has no value keep the child's fractions, so unless
//! every inside point has one, the bound is the hull with the child's.
//!
//! FGrade (clamped, normalised expressions `vᵢ = max(eᵢ, 0)`,
//! `fᵢ = vᵢ / Σⱼ vⱼ`): with `vᵢ ∈ [aᵢ, bᵢ]`, `fᵢ` is increasing in `vᵢ` and
//! decreasing in every other `vⱼ`, so
//! `aᵢ / (aᵢ + Σ_{j≠i} bⱼ) ≤ fᵢ ≤ bᵢ / (bᵢ + Σ_{j≠i} aⱼ)` (0 when the
//! numerator is 0: an all-zero sum gives zero fractions).

use std::sync::Arc;

use glam::DVec3;

use super::MAX_MATERIALS;
use super::distance_interval::coord_intervals;
use super::pnode::{COORD_SLOTS, Grade, NAry, PNode, SimGrade, Slot};
use crate::aabb::Aabb;
use crate::attribute::FractionSource;
use crate::expr::Expr;
use crate::interval::Interval;

/// Most children of a union that may overlap a box before the bound gives up.
const MAX_OVERLAPPING: usize = 8;

/// `[0, 0]`.
pub(crate) const ZERO: Interval = Interval { lo: 0.0, hi: 0.0 };

impl PNode {
    /// The axes along which the fractions of inside points may vary: none
    /// for one material; those a grade's expressions read where they read
    /// `x`, `y` or `z` alone (a derived coordinate or the distance mixes
    /// the axes), through moves, per-axis scales, tiles, offsets and the
    /// first child of an intersection or difference (the fractions there
    /// are the child's at a point moved along each axis alone); every axis
    /// where this is not known.
    pub fn fraction_axes(&self) -> [bool; 3] {
        const ALL: [bool; 3] = [true; 3];
        if self.leaf_material().is_some() {
            return [false; 3];
        }
        match self {
            PNode::FGrade(g) if g.used & !0b111 == 0 => [0, 1, 2].map(|i| g.used & (1 << i) != 0),
            PNode::Translate { child, .. }
            | PNode::Scale { child, .. }
            | PNode::Tile { child, .. }
            | PNode::Offset { child, .. }
            | PNode::Shell { child, .. } => child.fraction_axes(),
            PNode::Intersection(n) if !n.blend => n.children[0].fraction_axes(),
            PNode::Difference { a, .. } => a.fraction_axes(),
            _ => ALL,
        }
    }

    /// Bounds of the fractions at the inside points of `b` into `out`
    /// (`[0, 0]` on entry); false when this node cannot bound them.
    pub fn frac_bounds(&self, b: &Aabb, out: &mut [Interval]) -> bool {
        if let Some(m) = self.leaf_material() {
            out[m as usize] = Interval::point(1.0);
            return true;
        }
        if let PNode::Offset { o, .. } = self
            && *o > 0.0
        {
            // Its inside points outside the child get the child's fractions
            // there, which the child's bounds (of its own inside points)
            // do not cover.
            return false;
        }
        if let Some((child, cb)) = self.fraction_child_box(b) {
            return child.frac_bounds(&cb, out);
        }
        match self {
            PNode::Union(u) if !u.blend && u.smooth <= 0.0 => u.union_bounds(b, out),
            PNode::Union(u) if !u.blend => u.smooth_union_bounds(b, out),
            PNode::Blend { r, child } => {
                // The stencil reaches r per axis (r·(1 + 1e-12): its offsets are rounded).
                let reach = DVec3::splat(*r * (1.0 + 1e-12));
                let grown = Aabb::new(b.min - reach, b.max + reach);
                if !child.frac_bounds(&grown, out) {
                    return false;
                }
                for o in out.iter_mut() {
                    *o = Interval::new(o.lo - 1e-12, o.hi + 1e-12);
                }
                true
            }
            PNode::Intersection(n) if !n.blend => n.children[0].frac_bounds(b, out),
            PNode::Difference { a, .. } => a.frac_bounds(b, out),
            PNode::FGrade(g) => g.bounds(b, out),
            PNode::SimField(g) => g.bounds(b, out),
            PNode::AttrGrade { child, src } => attr_grade_bounds(child, src, b, out),
            _ => false,
        }
    }
}

/// `Convert(child, from, fractions([a, b]), table)`: the mix where `from`
/// has a value, the child's own fractions where it has none, so the hull
/// of the two unless every inside point has a value (or none has).
fn attr_grade_bounds(child: &PNode, src: &FractionSource, b: &Aabb, out: &mut [Interval]) -> bool {
    let k = out.len();
    let mut mix = [ZERO; MAX_MATERIALS];
    let Some((every, _)) = src.mix_bounds(b, &mut mix[..k]) else {
        return child.frac_bounds(b, out);
    };
    if every {
        out.copy_from_slice(&mix[..k]);
        return true;
    }
    if !child.frac_bounds(b, out) {
        return false;
    }
    for (o, m) in out.iter_mut().zip(&mix[..k]) {
        *o = o.union(*m);
    }
    true
}

/// True when a conversion's fractions are the same at every inside point
/// of `b`: one mix everywhere, or no value anywhere and a constant child
/// ([`PNode::constant_fractions`]).
pub(super) fn attr_grade_constant(child: &PNode, src: &FractionSource, b: &Aabb) -> bool {
    let mut mix = [ZERO; MAX_MATERIALS];
    match src.mix_bounds(b, &mut mix) {
        None => child.constant_fractions(b),
        Some((every, one)) => every && one,
    }
}

impl PNode {
    /// True when some part's fractions depend on the point (see
    /// `Model::varying_fractions`).
    pub fn varying_fractions(&self) -> bool {
        if let PNode::Union(n) | PNode::Intersection(n) = self
            && n.blend
        {
            return true;
        }
        // Which child of a union or sum holds p changes: any varying child.
        if let Some(any) = self.any_fraction_part(PNode::varying_fractions) {
            return any;
        }
        match self {
            PNode::FGrade(g) => {
                g.exprs.iter().any(|e| e.constant().is_none()) || g.child.varying_fractions()
            }
            _ => true, // Blend, FEA fields
        }
    }

    /// True when some part's fractions are averages over many samples of
    /// a child (a `Blend`: 125 or 216 evaluations a point).
    pub fn averages_fractions(&self) -> bool {
        if let Some(any) = self.any_fraction_part(PNode::averages_fractions) {
            return any;
        }
        match self {
            PNode::FGrade(g) => g.child.averages_fractions(),
            PNode::AttrGrade { child, .. } => child.averages_fractions(),
            PNode::Blend { .. } => true,
            _ => false,
        }
    }

    /// The walk both questions above share: false at a leaf (one material),
    /// else whether `part` holds for a part whose fractions this node
    /// passes on (a transform's child, a union's, intersection's or sum's
    /// children, a difference's kept side); `None` for other nodes.
    fn any_fraction_part(&self, part: fn(&PNode) -> bool) -> Option<bool> {
        if self.leaf_material().is_some() {
            return Some(false);
        }
        if let Some(child) = self.fraction_child() {
            return Some(part(child));
        }
        match self {
            PNode::Union(n) | PNode::Intersection(n) => Some(n.children.iter().any(|c| part(c))),
            PNode::Sum { children, .. } => Some(children.iter().any(|c| part(c))),
            PNode::Difference { a, .. } => Some(part(a)),
            _ => None,
        }
    }
}

impl NAry {
    /// A sharp union gives a point the fractions of the first child that
    /// contains it: the hull over the children that may contain a point of
    /// `b`.
    fn union_bounds(&self, b: &Aabb, out: &mut [Interval]) -> bool {
        let k = out.len();
        let Some((ids, n)) = self.maybe_inside::<MAX_OVERLAPPING>(b) else {
            return false;
        };
        let mut tmp = [ZERO; MAX_MATERIALS];
        for (j, &i) in ids[..n].iter().enumerate() {
            tmp[..k].fill(ZERO);
            if !self.children[i].frac_bounds(b, &mut tmp[..k]) {
                return false;
            }
            for (o, t) in out.iter_mut().zip(&tmp[..k]) {
                *o = if j == 0 { *t } else { o.union(*t) };
            }
        }
        true
    }
}

impl NAry {
    /// A smooth union (no union index: those are built for sharp ones):
    /// the hull over the children within `(n − 1)·k` of `b` (module doc).
    /// A fillet point takes a child's fractions outside that child, which
    /// its bounds (of its own inside points) do not cover, so only
    /// children whose fractions are the same everywhere are bounded.
    fn smooth_union_bounds(&self, b: &Aabb, out: &mut [Interval]) -> bool {
        if self.index.is_some() {
            return false;
        }
        let reach = (self.children.len() - 1) as f64 * self.smooth;
        let k = out.len();
        let mut first = true;
        for (c, fixed) in self.children.iter().zip(&self.fixed) {
            if c.interval(b).lo > reach {
                continue;
            }
            let Some(fixed) = fixed else {
                return false;
            };
            let mut f = [0.0; MAX_MATERIALS];
            fixed.write(&mut f[..k]);
            for (o, v) in out.iter_mut().zip(&f[..k]) {
                let t = Interval::point(*v);
                *o = if first { t } else { o.union(t) };
            }
            first = false;
        }
        true
    }
}

impl Grade {
    fn bounds(&self, b: &Aabb, out: &mut [Interval]) -> bool {
        match self.slot_intervals(b) {
            None => true, // no inside point
            Some(slots) => normalised_bounds(&self.exprs, &self.mats, &slots, out),
        }
    }
}

impl SimGrade {
    /// As `Grade`, with the field's variables bounded over `b`
    /// (`SimField::bounds`); `d` is 0, as `SimGrade::frac` leaves it.
    fn bounds(&self, b: &Aabb, out: &mut [Interval]) -> bool {
        let n = COORD_SLOTS + self.field.variable_count();
        if n > 64 {
            return false;
        }
        let mut slots = [ZERO; 64];
        slots[..COORD_SLOTS].copy_from_slice(&coord_intervals(b, ZERO, self.used));
        self.field.bounds(b, &mut slots[COORD_SLOTS..n])
            && normalised_bounds(&self.exprs, &self.mats, &slots[..n], out)
    }
}

/// Grades of at most this many expressions bound them in a small array.
const SMALL_GRADE: usize = 8;

/// Bounds of clamped, normalised expressions (see the module docs) added
/// to their materials' entries of `out`; false when an expression has no
/// finite bound.
fn normalised_bounds(
    exprs: &[Arc<Expr>],
    mats: &[Slot],
    slots: &[Interval],
    out: &mut [Interval],
) -> bool {
    // (A few expressions use a small array: zeroing all MAX_MATERIALS
    // intervals, a kilobyte, for every run of a two-way grade is waste.)
    let n = exprs.len();
    let (mut small, mut all);
    let v: &mut [Interval] = if n <= SMALL_GRADE {
        small = [ZERO; SMALL_GRADE];
        &mut small[..n]
    } else {
        all = [ZERO; MAX_MATERIALS];
        &mut all[..n.min(MAX_MATERIALS)]
    };
    for (vi, e) in v.iter_mut().zip(exprs) {
        let i = e.eval_interval(slots);
        if !(i.lo.is_finite() && i.hi.is_finite()) {
            return false;
        }
        *vi = Interval::new(i.lo.max(0.0), i.hi.max(0.0));
    }
    let (sum_lo, sum_hi) = v.iter().fold((0.0, 0.0), |(l, h), x| (l + x.lo, h + x.hi));
    for (vi, &m) in v.iter().zip(mats) {
        let (others_lo, others_hi) = (sum_lo - vi.lo, sum_hi - vi.hi);
        let lo = if vi.lo > 0.0 {
            vi.lo / (vi.lo + others_hi.max(0.0))
        } else {
            0.0
        };
        let hi = if vi.hi > 0.0 {
            vi.hi / (vi.hi + others_lo.max(0.0))
        } else {
            0.0
        };
        // Rounding: widen by a few ulps' worth, the evaluator rounds too.
        let slack = 1e-12;
        let f = Interval::new((lo - slack).max(0.0), (hi + slack).min(1.0));
        let o = &mut out[m as usize];
        *o = Interval::new(o.lo + f.lo, o.hi + f.hi);
    }
    true
}

#[cfg(test)]
mod tests {
    use glam::DVec3;

    use super::*;
    use crate::Model;
    use crate::model::tests::model;

    /// Every inside sample of random boxes has fractions within the
    /// bounds; returns how many inside samples were checked.
    fn check(m: &Model, size: f64) -> usize {
        let k = m.materials().len();
        let bb = m.bbox();
        let mut rng = crate::trimesh::tests::Rng::new(3);
        let mut next = || rng.f64();
        let mut checked = 0;
        let mut iv = [ZERO; MAX_MATERIALS];
        let mut f = [0.0; MAX_MATERIALS];
        for _ in 0..400 {
            let c = bb.min + (bb.max - bb.min) * DVec3::new(next(), next(), next());
            let h = DVec3::new(next(), next(), next()) * size;
            let b = Aabb::new(c - h, c + h);
            if !m.fraction_bounds(&b, &mut iv[..k]) {
                continue;
            }
            for _ in 0..50 {
                let p = b.min + (b.max - b.min) * DVec3::new(next(), next(), next());
                if m.eval_into(p, &mut f[..k]) > 0.0 {
                    continue;
                }
                checked += 1;
                for (i, (b, v)) in iv[..k].iter().zip(&f[..k]).enumerate() {
                    assert!(
                        b.lo - 1e-9 <= *v && *v <= b.hi + 1e-9,
                        "fraction {i} = {v} outside [{}, {}] at {p} in {b:?}",
                        b.lo,
                        b.hi
                    );
                }
            }
        }
        checked
    }

    #[test]
    fn fraction_axes_follow_the_expressions_read() {
        let cases = [
            (
                r#"FGrade(["x/15+0.5", "-x/15+0.5"], [m.id("red"), m.id("blue")], true, RectPrism(Vec3(0,0,0), Vec3(15,10,5), m.id("gray")))"#,
                [true, false, false],
            ),
            (
                r#"Translate(1, 2, 3, Intersection(false, [FGrade(["z", "1 - z"], [m.id("red"), m.id("blue")], true, Sphere(Vec3(0,0,0), 4, m.id("gray"))), Sphere(Vec3(1,0,0), 4, m.id("gray"))]))"#,
                [false, false, true],
            ),
            (
                r#"Sphere(Vec3(0,0,0), 4, m.id("gray"))"#,
                [false, false, false],
            ),
            // Turned, a grade along x varies along every axis.
            (
                r#"Rotate(0, 0, 30, Vec3(0,0,0), FGrade(["x", "1 - x"], [m.id("red"), m.id("blue")], true, Sphere(Vec3(0,0,0), 4, m.id("gray"))))"#,
                [true; 3],
            ),
            // A derived coordinate or the distance mixes the axes.
            (
                r#"FGrade(["rho/4", "1 - rho/4"], [m.id("red"), m.id("blue")], true, Sphere(Vec3(0,0,0), 4, m.id("gray")))"#,
                [true; 3],
            ),
            (
                r#"FGrade(["-d", "1 + d"], [m.id("red"), m.id("blue")], true, Sphere(Vec3(0,0,0), 4, m.id("gray")))"#,
                [true; 3],
            ),
            // Which child's fractions hold depends on the point.
            (
                r#"Union(false, [FGrade(["x", "1 - x"], [m.id("red"), m.id("blue")], true, Sphere(Vec3(0,0,0), 4, m.id("gray"))), Sphere(Vec3(5,0,0), 4, m.id("green"))])"#,
                [true; 3],
            ),
        ];
        for (src, want) in cases {
            assert_eq!(model(src).fraction_axes(), want, "{src}");
        }
    }

    #[test]
    fn bounds_hold_inside_boxes() {
        let designs = [
            // The graded bar, and its grade turned and moved.
            r#"FGrade(["x/15+0.5", "-x/15+0.5"], [m.id("red"), m.id("blue")], true, RectPrism(Vec3(0,0,0), Vec3(15,10,5), m.id("gray")))"#,
            r#"Translate(1, 2, 0, Rotate(0, 30, 45, Vec3(0,0,0), FGrade(["x*x/50", "1 - y/10", "0.2"], [m.id("red"), m.id("blue"), m.id("green")], true, Sphere(Vec3(0,0,0), 6, m.id("gray")))))"#,
            // A union: the first containing child wins, one plain child.
            r#"Union(false, [FGrade(["z/4+0.5", "0.5-z/4"], [m.id("red"), m.id("blue")], true, Sphere(Vec3(0,0,0), 4, m.id("gray"))), RectPrism(Vec3(3,0,0), Vec3(6,6,6), m.id("green"))])"#,
            // A grade using the distance d.
            r#"FGrade(["-d", "1"], [m.id("red"), m.id("blue")], true, Sphere(Vec3(0,0,0), 5, m.id("gray")))"#,
            // A smooth union of two materials (fillets take the nearest
            // child's), and blends over a sharp and a smooth union.
            r#"Union(1.5, false, [Sphere(Vec3(-3,0,0), 4, m.id("red")), Sphere(Vec3(3,0,0), 4, m.id("blue")), RectPrism(Vec3(0,4,0), Vec3(3,3,3), m.id("green"))])"#,
            r#"Blend(0.8, Union(false, [Sphere(Vec3(-2,0,0), 4, m.id("red")), FGrade(["x/8+0.5", "0.5-x/8"], [m.id("yellow"), m.id("blue")], true, Sphere(Vec3(3,0,0), 4, m.id("gray")))]))"#,
            r#"Blend(0.5, Shell(-1.0, Union(1.0, false, [Sphere(Vec3(-2,0,0), 4, m.id("red")), Sphere(Vec3(2,0,0), 4, m.id("blue"))])))"#,
        ];
        for src in designs {
            let m = model(src);
            for size in [0.05, 0.5, 3.0] {
                let checked = check(&m, size);
                assert!(checked > 2000, "{src}: {checked} inside samples checked");
            }
        }
    }

    #[test]
    fn points_outside_a_child_are_not_misbounded() {
        // A smooth union's fillet takes a graded child's fractions outside
        // it; a growing offset's shell lies outside its child (a union, a
        // grade). Where bounds are given, they must hold there too.
        for src in [
            r#"Union(1.0, false, [FGrade(["x/8+0.5", "0.5-x/8"], [m.id("red"), m.id("blue")], true, Sphere(Vec3(-2,0,0), 4, m.id("gray"))), Sphere(Vec3(3,0,0), 4, m.id("green"))])"#,
            r#"Offset(1.0, Union(false, [Sphere(Vec3(-3,0,0), 2, m.id("red")), FGrade(["z/4+0.5", "0.5-z/4"], [m.id("yellow"), m.id("blue")], true, Sphere(Vec3(3,0,0), 2, m.id("gray")))]))"#,
            r#"Offset(0.8, FGrade(["x/8+0.5", "0.5-x/8"], [m.id("red"), m.id("blue")], true, Sphere(Vec3(0,0,0), 3, m.id("gray"))))"#,
        ] {
            let m = model(src);
            for size in [0.05, 0.5, 3.0] {
                check(&m, size);
            }
            // A box in a growing offset's shell is not "constant".
            let shell = Aabb::new(DVec3::new(-1.0, -0.5, 3.2), DVec3::new(1.0, 0.5, 3.6));
            if src.starts_with("Offset(0.8") {
                assert!(!m.constant_fractions(&shell));
            }
        }
        // The shell of a grown union has the nearest child's material (it
        // had none: a void shell inside the part).
        let m = model(
            r#"Offset(1.0, Union(false, [Sphere(Vec3(0,0,0), 2, m.id("red")), Sphere(Vec3(5,0,0), 2, m.id("blue"))]))"#,
        );
        let k = m.materials().len();
        let mut f = [0.0; MAX_MATERIALS];
        for (x, near) in [(2.2, 0), (2.8, 1)] {
            assert!(m.eval_into(DVec3::new(x, 0.0, 0.0), &mut f[..k]) < 0.0);
            let red = m.table().id("red").unwrap();
            let slot = m.materials().iter().position(|&i| i == red).unwrap();
            assert_eq!(f[slot], if near == 0 { 1.0 } else { 0.0 }, "at x = {x}");
            assert_eq!(f[..k].iter().sum::<f64>(), 1.0, "at x = {x}");
        }
    }

    #[test]
    fn bounds_are_tight_enough_to_decide_small_boxes() {
        let m = model(
            r#"FGrade(["x/15+0.5", "-x/15+0.5"], [m.id("red"), m.id("blue")], true, RectPrism(Vec3(0,0,0), Vec3(15,10,5), m.id("gray")))"#,
        );
        let k = m.materials().len();
        let mut iv = [ZERO; MAX_MATERIALS];
        let b = Aabb::new(DVec3::new(1.0, -1.0, -1.0), DVec3::new(1.1, 1.0, 1.0));
        assert!(m.fraction_bounds(&b, &mut iv[..k]));
        let red = m
            .materials()
            .iter()
            .position(|&i| i == m.table().id("red").unwrap())
            .unwrap();
        let exact = |x: f64| x / 15.0 + 0.5;
        assert!((iv[red].lo - exact(1.0)).abs() < 1e-9, "{:?}", iv[red]);
        assert!((iv[red].hi - exact(1.1)).abs() < 1e-9, "{:?}", iv[red]);
    }

    #[test]
    fn varying_fractions_only_where_a_grade_has_a_variable() {
        let fixed = model(
            r#"Union(false, [FGrade(["0.3", "0.7"], [m.id("red"), m.id("blue")], true, Sphere(Vec3(0,0,0), 2, m.id("gray"))), Translate(3, 0, 0, RectPrism(Vec3(0,0,0), Vec3(2,2,2), m.id("green")))])"#,
        );
        assert!(!fixed.varying_fractions());
        let graded = model(
            r#"Union(false, [FGrade(["0.3", "z"], [m.id("red"), m.id("blue")], true, Sphere(Vec3(0,0,0), 2, m.id("gray"))), RectPrism(Vec3(3,0,0), Vec3(2,2,2), m.id("green"))])"#,
        );
        assert!(graded.varying_fractions());
    }

    #[test]
    fn unknown_where_no_cheap_bound() {
        let m = model(
            r#"Union(true, [FGrade(["x", "1"], [m.id("red"), m.id("blue")], true, Sphere(Vec3(0,0,0), 3, m.id("gray"))), Sphere(Vec3(0,0,0), 2, m.id("green"))])"#,
        );
        let mut iv = [ZERO; MAX_MATERIALS];
        let b = Aabb::new(DVec3::splat(-0.1), DVec3::splat(0.1));
        assert!(!m.fraction_bounds(&b, &mut iv[..m.materials().len()]));
    }
}
