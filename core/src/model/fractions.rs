//! Material volume fractions of the prepared tree (pyvcad's `distribution`).
//!
//! `frac(p, out)` writes the fractions at `p` into `out` (one entry per
//! material the model uses, all zero on entry). Callers ask only where the
//! node's distance is ≤ 0; the rules per node follow pyvcad 2.3.4
//! (pyvcad 2.3.4) except where `docs/PYVCAD.md` says otherwise.

use crate::expr::ExprSet;
use glam::DVec3;

use super::MAX_MATERIALS;
use super::pnode::{
    COORD_SLOTS, D_SLOT, FixedFractions, Grade, NAry, PNode, SimGrade, Slot, coord_slots,
    tile_local,
};
use super::union_index::{Candidates, Entry};

impl PNode {
    /// Distance at `p`, and the fractions into `out` (zeroed by the caller)
    /// when it is ≤ 0. One pass where a node can share work between the two
    /// (a union finds its minimum and the first child containing `p` in the
    /// same loop over its candidates).
    pub fn eval(&self, p: DVec3, out: &mut [f64]) -> f64 {
        match self {
            PNode::Union(u) if !u.blend && u.smooth <= 0.0 => u.union_eval::<true>(p, out).0,
            PNode::Translate { t, child } => child.eval(p - *t, out),
            PNode::FGrade(g) => {
                let d = g.child.dist(p);
                if d <= 0.0 {
                    g.frac_with_d(p, d, out);
                }
                d
            }
            _ => {
                let d = self.dist(p);
                if d <= 0.0 {
                    self.frac(p, out);
                }
                d
            }
        }
    }

    /// [`PNode::eval`], and for a sharp union the index of the first child
    /// containing `p` (whose fractions it wrote; `usize::MAX` where none
    /// does or the node is not a sharp union): the attribute evaluator
    /// reads the same child's attribute without searching again.
    #[inline]
    pub(crate) fn eval_first(&self, p: DVec3, out: &mut [f64]) -> (f64, usize) {
        match self {
            PNode::Union(u) if !u.blend && u.smooth <= 0.0 => u.union_eval::<true>(p, out),
            _ => (self.eval(p, out), usize::MAX),
        }
    }

    /// Distance at `p` and, for a sharp union, the index of the first child
    /// containing it (as [`PNode::eval_first`], without the fractions).
    #[inline]
    pub(crate) fn dist_first(&self, p: DVec3) -> (f64, usize) {
        match self {
            PNode::Union(u) if !u.blend && u.smooth <= 0.0 => u.union_eval::<false>(p, &mut []),
            _ => (self.dist(p), usize::MAX),
        }
    }

    /// Fractions at `p` into `out` (zeroed by the caller).
    pub fn frac(&self, p: DVec3, out: &mut [f64]) {
        if let Some(m) = self.leaf_material() {
            out[m as usize] = 1.0;
            return;
        }
        match self {
            PNode::Translate { t, child } => child.frac(p - *t, out),
            PNode::Rotate {
                to_local,
                around,
                child,
            } => child.frac(*to_local * (p - *around) + *around, out),
            PNode::Mirror {
                point,
                normal,
                child,
            } => child.frac(super::pnode::reflect(p, *point, *normal), out),
            PNode::Scale { inv, child, .. } => child.frac(p * *inv, out),
            PNode::Affine(a) => a.child.frac(a.m * p + a.t, out),
            PNode::Union(u) => u.union_frac(p, out),
            PNode::Intersection(n) => {
                if n.blend {
                    average(n.children.iter().map(|c| &**c), p, out);
                } else {
                    n.children[0].frac(p, out);
                }
            }
            PNode::Difference { a, .. } => a.frac(p, out),
            PNode::Offset { child, .. } | PNode::Shell { child, .. } => child.frac(p, out),
            PNode::Tile { cell, child } => child.frac(tile_local(p, *cell), out),
            PNode::FGrade(g) => g.frac(p, out),
            PNode::AttrGrade { child, src } => {
                // Where the attribute has no value, the child's own.
                let converted = src.frac(p, out);
                if !converted {
                    child.frac(p, out);
                }
            }
            PNode::Blend { r, child } => blend_frac(child, *r, p, out),
            PNode::SimField(s) => s.frac(p, out),
            // pyvcad: the first child containing p, whatever the sum.
            PNode::Sum { children, .. } => {
                if let Some(c) = children.iter().find(|c| c.contains(p)) {
                    c.frac(p, out);
                }
            }
            _ => {} // leaves: above
        }
    }

    /// The child of a node whose fractions are its child's at a moved
    /// point (a move, rotation, scale, offset, shell or tile).
    #[inline]
    pub(super) fn fraction_child(&self) -> Option<&PNode> {
        match self {
            PNode::Translate { child, .. }
            | PNode::Rotate { child, .. }
            | PNode::Scale { child, .. }
            | PNode::Offset { child, .. }
            | PNode::Shell { child, .. }
            | PNode::Tile { child, .. }
            | PNode::Mirror { child, .. } => Some(child),
            PNode::Affine(a) => Some(&a.child),
            _ => None,
        }
    }

    /// The material of a leaf that assigns one material everywhere.
    #[inline]
    pub(super) fn leaf_material(&self) -> Option<Slot> {
        match self {
            PNode::Sphere { m, .. }
            | PNode::Box { m, .. }
            | PNode::Cylinder { m, .. }
            | PNode::Strut { m, .. }
            | PNode::Prism { m, .. }
            | PNode::Function { m, .. }
            | PNode::Tpms { m, .. }
            | PNode::Lattice { m, .. }
            | PNode::Mesh { m, .. }
            | PNode::Shape { m, .. }
            | PNode::Text { m, .. } => Some(*m),
            _ => None,
        }
    }
}

impl PNode {
    /// The node's fractions when they do not depend on the point; the
    /// values are computed exactly as `frac` computes them.
    pub fn fixed_fractions(&self) -> Option<FixedFractions> {
        if let Some(m) = self.leaf_material() {
            return Some(FixedFractions::one(m));
        }
        if let Some(child) = self.fraction_child() {
            return child.fixed_fractions();
        }
        match self {
            PNode::Difference { a, .. } => a.fixed_fractions(),
            PNode::Intersection(n) if !n.blend => n.children[0].fixed_fractions(),
            // A sharp union writes one child's fractions, so children that
            // all have the same fixed ones give them wherever it is asked
            // (a lattice of one material kept whole because it carries an
            // attribute: no search for the strut holding the point).
            PNode::Union(n) if !n.blend && n.smooth <= 0.0 => {
                let first = (*n.fixed.first()?)?;
                n.fixed
                    .iter()
                    .all(|f| f.is_some_and(|f| same_fixed(&f, &first)))
                    .then_some(first)
            }
            PNode::FGrade(g) if g.exprs.len() <= 4 => {
                if g.exprs.iter().any(|e| e.constant().is_none()) {
                    return None;
                }
                // The same arithmetic as `normalised`, so the values are
                // bit-identical to the evaluated ones.
                let mut out = [0.0; MAX_MATERIALS];
                let slots = [0.0; COORD_SLOTS];
                normalised::<4>(&g.set, &g.mats, &slots, &mut out);
                let mut f = FixedFractions {
                    len: 0,
                    slots: [0; 4],
                    values: [0.0; 4],
                };
                for &m in &g.mats {
                    if f.slots[..f.len as usize].contains(&m) {
                        continue;
                    }
                    f.slots[f.len as usize] = m;
                    f.values[f.len as usize] = out[m as usize];
                    f.len += 1;
                }
                Some(f)
            }
            _ => None,
        }
    }
}

/// True when `a` and `b` write the same values into the same slots.
fn same_fixed(a: &FixedFractions, b: &FixedFractions) -> bool {
    let n = a.len as usize;
    a.len == b.len
        && a.slots[..n] == b.slots[..n]
        && a.values[..n]
            .iter()
            .zip(&b.values[..n])
            .all(|(x, y)| x.to_bits() == y.to_bits())
}

impl NAry {
    /// Fractions of child `i` at `p` (a table read for fixed ones).
    #[inline]
    pub fn child_frac(&self, i: usize, p: DVec3, out: &mut [f64]) {
        match &self.fixed[i] {
            Some(f) => f.write(out),
            None => self.children[i].frac(p, out),
        }
    }

    /// Sharp, non-blending union: minimum and first containing child at
    /// once (the child's index is returned beside the minimum), and that
    /// child's fractions when `FRACTIONS`.
    fn union_eval<const FRACTIONS: bool>(&self, p: DVec3, out: &mut [f64]) -> (f64, usize) {
        let mut best = f64::INFINITY;
        let mut first = usize::MAX;
        let visit = |i: usize, best: &mut f64, first: &mut usize| {
            let d = self.child_dist(i, p);
            if d <= 0.0 && i < *first {
                *first = i;
            }
            if d < *best {
                *best = d;
            }
        };
        match &self.index {
            // Speed copy of core/src/model/pnode.rs::NAry::indexed_min, also
            // visiting every child that can contain p: through one shared
            // closure-taking walk `best` and `first` would leave registers
            // (docs/PERFORMANCE.md, "Speed copies" and "Large unions").
            Some(index) => {
                for &i in index.always() {
                    visit(i as usize, &mut best, &mut first);
                }
                let mut done = false;
                if let Candidates::Cell {
                    entries,
                    margin,
                    centre,
                    ..
                } = index.candidates(p)
                {
                    let slack = self.slack(index, p, centre);
                    for e in entries {
                        // Sorted by lower bound: once it is above both the
                        // best so far and 0, no later child is lower or
                        // contains p.
                        let lo = f64::from(e.lo) + slack;
                        if lo >= best && lo > 0.0 {
                            break;
                        }
                        visit(e.child as usize, &mut best, &mut first);
                    }
                    done = best < margin;
                }
                if !done {
                    // Exact minimum through the BVH; a containing child is
                    // always among the visited ones (its box holds p).
                    index.bvh().nearest(p, best, |i| {
                        visit(i as usize, &mut best, &mut first);
                        best
                    });
                }
            }
            None => {
                for i in 0..self.children.len() {
                    visit(i, &mut best, &mut first);
                }
            }
        }
        if best <= 0.0 && first != usize::MAX {
            if FRACTIONS {
                self.child_frac(first, p, out);
            }
            return (best, first);
        }
        (best, usize::MAX)
    }

    /// `blend = false`: the first child (in order) containing `p` wins.
    /// `blend = true`: the average over the children containing `p`.
    /// Where no child contains `p` (the fillet of a smooth union) the nearest
    /// child's fractions are used, as pyvcad does (measured on pyvcad 2.3.4).
    fn union_frac(&self, p: DVec3, out: &mut [f64]) {
        if let Some(index) = &self.index
            && let Candidates::Cell {
                entries,
                always,
                centre,
                ..
            } = index.candidates(p)
        {
            // Only children whose lower bound is ≤ 0 can contain p; they
            // come first. Visit them in child order. A linear scan finds
            // their end: they are few (a bunny-lattice voxel has 1 to 5 of
            // a cell's hundred or so), they are all visited after, and a
            // binary search's branches are unpredictable.
            let slack = self.slack(index, p, centre);
            let may_contain = |e: &Entry| f64::from(e.lo) + slack <= 0.0;
            let n = entries
                .iter()
                .position(|e| !may_contain(e))
                .unwrap_or(entries.len());
            let mut inside: [u32; 64] = [0; 64];
            if n <= inside.len() {
                for (o, e) in inside.iter_mut().zip(&entries[..n]) {
                    *o = e.child;
                }
                inside[..n].sort_unstable();
                let mut ids = merge_sorted(&inside[..n], always);
                return self.frac_among(&mut ids, p, out);
            }
            // More than 64 children may contain p (rare): same, on the heap.
            let mut sorted: Vec<u32> = entries[..n].iter().map(|e| e.child).collect();
            sorted.sort_unstable();
            let mut ids = merge_sorted(&sorted, always);
            return self.frac_among(&mut ids, p, out);
        }
        let mut all = (0..self.children.len() as u32).map(|i| i as usize);
        self.frac_among(&mut all, p, out)
    }

    fn frac_among(&self, ids: &mut dyn Iterator<Item = usize>, p: DVec3, out: &mut [f64]) {
        let mut nearest = (f64::INFINITY, usize::MAX);
        if self.blend {
            // Average over the children containing p; in a smooth union's
            // fillet (none contains p) fall through to the nearest child.
            let children = ids.map(|i| &*self.children[i]).filter(|c| c.contains(p));
            if average(children, p, out) > 0 {
                return;
            }
            for (i, c) in self.children.iter().enumerate() {
                let d = c.dist(p);
                if d < nearest.0 {
                    nearest = (d, i);
                }
            }
        } else {
            // Sharp unions: containment is enough (cheap for meshes); the
            // nearest child matters only in a smooth union's fillet, and
            // where a growing `Offset` asks about a point outside the union.
            let smooth = self.smooth > 0.0;
            for i in ids {
                let c = &self.children[i];
                if !smooth {
                    if c.contains(p) {
                        return self.child_frac(i, p, out);
                    }
                    continue;
                }
                let d = self.child_dist(i, p);
                if d <= 0.0 {
                    return c.frac(p, out);
                }
                if d < nearest.0 {
                    nearest = (d, i);
                }
            }
        }
        if !self.blend && self.smooth <= 0.0 {
            // No child holds p: it lies outside the union, inside a node
            // that grows it (`Offset` with a positive distance). It takes the
            // nearest child's fractions, as a smooth union's fillet does
            // (it had none: a void shell inside the part).
            nearest.1 = self.nearest_child(p);
        }
        if nearest.1 != usize::MAX {
            self.children[nearest.1].frac(p, out);
        }
    }

    /// The child nearest to `p` (`usize::MAX` for no children).
    fn nearest_child(&self, p: DVec3) -> usize {
        let mut best = (f64::INFINITY, usize::MAX);
        let visit = |i: usize, best: &mut (f64, usize)| {
            let d = self.child_dist(i, p);
            if d < best.0 || (d == best.0 && i < best.1) {
                *best = (d, i);
            }
        };
        match &self.index {
            Some(index) => {
                for &i in index.always() {
                    visit(i as usize, &mut best);
                }
                index.bvh().nearest(p, best.0, |i| {
                    visit(i as usize, &mut best);
                    best.0
                });
            }
            None => {
                for i in 0..self.children.len() {
                    visit(i, &mut best);
                }
            }
        }
        best.1
    }
}

/// Indices of `a` and `b` (both ascending) merged ascending.
fn merge_sorted<'a>(a: &'a [u32], b: &'a [u32]) -> impl Iterator<Item = usize> + 'a {
    let mut i = 0;
    let mut j = 0;
    std::iter::from_fn(move || {
        let next = match (a.get(i), b.get(j)) {
            (Some(&x), Some(&y)) if x <= y => {
                i += 1;
                x
            }
            (_, Some(&y)) => {
                j += 1;
                y
            }
            (Some(&x), None) => {
                i += 1;
                x
            }
            (None, None) => return None,
        };
        Some(next as usize)
    })
}

/// Average of the fractions of `nodes` into `out` (zero on entry); returns
/// how many were averaged.
fn average<'a>(nodes: impl Iterator<Item = &'a PNode>, p: DVec3, out: &mut [f64]) -> u32 {
    let k = out.len();
    let mut tmp = [0.0; MAX_MATERIALS];
    let mut count = 0u32;
    for c in nodes {
        tmp[..k].fill(0.0);
        c.frac(p, &mut tmp[..k]);
        for j in 0..k {
            out[j] += tmp[j];
        }
        count += 1;
    }
    if count > 1 {
        let inv = 1.0 / count as f64;
        for v in out.iter_mut() {
            *v *= inv;
        }
    }
    count
}

impl Grade {
    /// Values fᵢ(p) of the expressions (with `d` = the child's distance),
    /// negatives clamped to 0, then normalised by their sum when it is > 0.
    /// (pyvcad keeps negative values and normalises only positive sums; a
    /// negative fraction has no physical meaning, see docs/PYVCAD.md.)
    fn frac(&self, p: DVec3, out: &mut [f64]) {
        let d = if self.used & (1 << D_SLOT) != 0 {
            self.child.dist(p)
        } else {
            0.0
        };
        self.frac_with_d(p, d, out);
    }

    /// Fractions when the child's distance `d` is already known.
    fn frac_with_d(&self, p: DVec3, d: f64, out: &mut [f64]) {
        let mut slots = [0.0; COORD_SLOTS];
        coord_slots(p, self.used, &mut slots);
        slots[D_SLOT] = d;
        write_normalised(&self.set, &self.mats, &slots, out);
    }
}

impl SimGrade {
    fn frac(&self, p: DVec3, out: &mut [f64]) {
        // Few slots (the seat has 13) in a 16-slot scratch array: zeroing
        // all 64 per sample is a 512-byte memset.
        if COORD_SLOTS + self.field.variable_count() <= 16 {
            self.frac_in::<16>(p, out)
        } else {
            self.frac_in::<64>(p, out)
        }
    }

    #[inline(always)]
    fn frac_in<const N: usize>(&self, p: DVec3, out: &mut [f64]) {
        let n = COORD_SLOTS + self.field.variable_count();
        let mut slots = [0.0; N];
        let slots = &mut slots[..n];
        coord_slots(p, self.used, slots);
        if !self.field.sample(p, &mut slots[COORD_SLOTS..]) {
            return;
        }
        write_normalised(&self.set, &self.mats, slots, out);
    }
}

/// Evaluate `set`, clamp negatives to 0, normalise by the sum when > 0,
/// and add each to its material slot.
#[inline(always)]
fn write_normalised(set: &ExprSet, mats: &[Slot], slots: &[f64], out: &mut [f64]) {
    // A small scratch array for the usual few materials: zeroing 64 values
    // per voxel showed up as a memset in slice-stack profiles.
    if set.exprs().len() <= 4 {
        normalised::<4>(set, mats, slots, out)
    } else {
        normalised::<MAX_MATERIALS>(set, mats, slots, out)
    }
}

// Inlined into each grade's caller: it runs once per graded sample.
#[inline(always)]
fn normalised<const N: usize>(set: &ExprSet, mats: &[Slot], slots: &[f64], out: &mut [f64]) {
    let mut vals = [0.0; N];
    let vals = &mut vals[..set.exprs().len()];
    if set.is_fused() {
        set.eval_into(slots, vals);
    } else {
        for (v, e) in vals.iter_mut().zip(set.exprs()) {
            *v = e.eval(slots);
        }
    }
    let mut sum = 0.0;
    for v in vals.iter_mut() {
        *v = if *v > 0.0 { *v } else { 0.0 }; // also maps NaN to 0
        sum += *v;
    }
    let inv = if sum > 0.0 { 1.0 / sum } else { 0.0 };
    for (v, m) in vals.iter().zip(mats) {
        out[*m as usize] += v * inv;
    }
}

/// pyvcad 2.3.4's Blend stencil along one axis: offsets `−r + i·s` for
/// `i = 0 ..= ⌊2r / s⌋` with the step `s = 0.4·r` held in single precision.
/// Measured on pyvcad 2.3.4 (a red/blue step scanned in x at 200 radii
/// from 0.05 to 10; tests/blend.rs): 6 offsets {−r, −0.6r, −0.2r, 0.2r,
/// 0.6r, r} where the rounded step is at or below 0.4·r, 5 (without +r,
/// the asymmetric stencil older notes describe) where it rounds up.
pub fn blend_offsets(r: f64) -> ([f64; 6], usize) {
    let step = f64::from((0.4 * r) as f32);
    let n = if step > 0.0 {
        ((2.0 * r / step).floor() as usize + 1).min(6)
    } else {
        1
    };
    let mut o = [0.0; 6];
    for (i, v) in o.iter_mut().enumerate().take(n) {
        *v = -r + i as f64 * step;
    }
    (o, n)
}

/// pyvcad's Blend: the average of the child's fractions over the
/// [`blend_offsets`] stencil (per axis, all combinations) around `p`, over
/// the samples that have material.
fn blend_frac(child: &PNode, r: f64, p: DVec3, out: &mut [f64]) {
    let (s, n) = blend_offsets(r);
    let s = &s[..n];
    let k = out.len();
    let mut tmp = [0.0; MAX_MATERIALS];
    let mut count = 0u32;
    for &dx in s {
        for &dy in s {
            for &dz in s {
                let q = p + DVec3::new(dx, dy, dz);
                // One walk for the distance and the fractions (a union
                // finds the child that holds q while taking the minimum).
                tmp[..k].fill(0.0);
                if child.eval(q, &mut tmp[..k]) <= 0.0 {
                    for j in 0..k {
                        out[j] += tmp[j];
                    }
                    count += 1;
                }
            }
        }
    }
    if count == 0 {
        child.frac(p, out);
    } else {
        let inv = 1.0 / count as f64;
        for v in out.iter_mut() {
            *v *= inv;
        }
    }
}
