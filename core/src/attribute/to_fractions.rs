//! The prepared scalar -> fractions conversion ([`super::FracConv`]): the
//! distance tree's node for `Convert(child, from, fractions([a, b]),
//! table)` asks this for its fractions. It evaluates `from` with an
//! attribute evaluator of the child's subtree (the child's frame is the
//! node's) and writes the inverted table's mix.
//!
//! Which fractions win: this node's, over everything below it (a
//! material, an FGrade), as a parent's fractions replace its children's
//! everywhere else (an FGrade over this node replaces them in turn).
//! Where `from` has no value (no node below defines it there, or a value
//! a common name refuses), the child's own fractions stay.

use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};

use glam::DVec3;

use super::prepared::{ANode, Evaluator, Op, OwnSrc, PConv};
use super::{AttributeKind, FracConv, MixTable};
use crate::aabb::Aabb;
use crate::interval::Interval;
use crate::material::MaterialId;
use crate::model::{PrepareError, SubPreparer};
use crate::node::Node;

/// A node's scalar -> fractions conversion, ready to evaluate.
pub(crate) struct FractionSource {
    tree: Arc<ANode>,
    index: usize,
    table: Arc<MixTable>,
    /// Dense fraction slots of the materials mixed, in the table's order.
    slots: Vec<u16>,
    /// Samples whose value was outside the table (clamped).
    clamped: AtomicU64,
    describe: String,
    from: String,
}

impl std::fmt::Debug for FractionSource {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("FractionSource")
            .field("from", &self.from)
            .field("slots", &self.slots)
            .finish()
    }
}

/// The materials a node's scalar -> fractions conversion mixes (none
/// without one), for the design's material list.
pub(crate) fn fraction_materials(n: &Node) -> &[MaterialId] {
    n.attributes()
        .and_then(|a| a.to_fractions.as_ref())
        .map_or(&[], |c| &c.materials[..])
}

impl FractionSource {
    /// The conversion `conv` of node `n` over its `child`; `slots` are the
    /// dense slots of `conv.materials`.
    pub(crate) fn build(
        n: &Node,
        conv: &FracConv,
        child: &Node,
        materials: &[MaterialId],
        slots: Vec<u16>,
        sub: SubPreparer,
    ) -> Result<FractionSource, PrepareError> {
        let from = conv.from.as_str();
        let err = |message: String| PrepareError {
            node: n.describe(),
            message,
        };
        let set_it = format!("set it on the child: child.set_attribute(\"{from}\", value)");
        let Some(ev) = Evaluator::build(child, materials, sub)? else {
            return Err(err(format!(
                "converts \"{from}\" to fractions, but no node below it carries an attribute; {set_it}"
            )));
        };
        let Some(index) = ev.infos.iter().position(|i| i.name == from) else {
            let have: Vec<&str> = ev.infos.iter().map(|i| i.name.as_str()).collect();
            return Err(err(format!(
                "converts \"{from}\" to fractions, but no node below it sets \"{from}\"; below it are: {}; {set_it}",
                have.join(", ")
            )));
        };
        if ev.infos[index].kind != AttributeKind::Scalar {
            return Err(err(format!(
                "converts \"{from}\", a {}, to fractions; a mix table reads a number attribute",
                ev.infos[index].kind.name()
            )));
        }
        Ok(FractionSource {
            tree: ev.root,
            index,
            table: conv.table.clone(),
            slots,
            clamped: AtomicU64::new(0),
            describe: n.describe(),
            from: from.to_owned(),
        })
    }

    /// The mix at `p` (inside the node, its frame) added into `out` (the
    /// design's fractions, zeroed by the caller); false where `from` has
    /// no value there.
    #[inline]
    pub(crate) fn frac(&self, p: DVec3, out: &mut [f64]) -> bool {
        let mut v = [f64::NAN];
        match self.tree.eval(self.index, p, p, &mut v) {
            Ok(true) if !v[0].is_nan() => {}
            _ => return false,
        }
        let outside = self
            .table
            .mix(v[0], |m, f| out[usize::from(self.slots[m])] += f);
        if outside {
            self.clamped.fetch_add(1, Ordering::Relaxed);
        }
        true
    }

    /// Bounds of the mix at the inside points of `b` (the node's frame)
    /// that have a value of `from`, added to the dense fraction bounds
    /// `out` ([`MixTable::mix_bounds`]); `None` (and `out` untouched) when
    /// none has one, else whether every inside point has one (else some
    /// keep the child's fractions) and whether the mix is one value.
    pub(crate) fn mix_bounds(&self, b: &Aabb, out: &mut [Interval]) -> Option<(bool, bool)> {
        let v = self.tree.interval(self.index, b)?;
        self.table.mix_bounds(v, |m, f| {
            let o = &mut out[usize::from(self.slots[m])];
            *o = Interval::new(o.lo + f.lo, o.hi + f.hi);
        });
        Some((self.tree.covers(self.index, b), v.lo == v.hi))
    }

    /// The clamping warning, when samples so far were clamped.
    pub(crate) fn warning(&self) -> Option<String> {
        let k = self.clamped.load(Ordering::Relaxed);
        if k == 0 {
            return None;
        }
        let (lo, hi) = self.table.value_range();
        Some(format!(
            "{}: Convert to fractions: {k} samples of \"{}\" outside the mix table's {lo}..{hi} were clamped to its ends",
            self.describe, self.from
        ))
    }
}

impl ANode {
    /// True when every inside point of `b` (this node's frame) gets a
    /// value of scalar attribute `idx`: no point where nothing defines it,
    /// where it is NaN, or where a common name's range refuses it. Only a
    /// node's own values are judged (a union's children may leave points
    /// without one: false).
    ///
    /// An interval is `EVERYTHING` wherever a math string may give NaN
    /// (`expr::interval_eval`), so a finite one rules NaN out; a table
    /// gives NaN only for a NaN input, and an FEA column outside its mesh.
    pub(super) fn covers(&self, idx: usize, b: &Aabb) -> bool {
        match (self.own_of[idx], &self.op) {
            (Some(pos), _) => self.own_covers(usize::from(pos), b),
            (None, Op::Map(m, c)) => c.covers(idx, &m.apply_box(b)),
            (None, _) => false,
        }
    }

    fn own_covers(&self, pos: usize, b: &Aabb) -> bool {
        let own = &self.own[pos];
        let Some(v) = self.own_interval(pos, b) else {
            return false;
        };
        let in_range = own.range.is_none_or(|(lo, hi, _)| lo <= v.lo && v.hi <= hi);
        let finite = v.lo.is_finite() && v.hi.is_finite();
        in_range
            && finite
            && own
                .order
                .iter()
                .chain([&pos])
                .all(|&k| match &self.own[k].src {
                    OwnSrc::Comps(_) | OwnSrc::Points { .. } | OwnSrc::Image { .. } => true,
                    OwnSrc::Data { .. } => false,
                    OwnSrc::Convert {
                        from,
                        from_own,
                        map,
                        ..
                    } => match (map, from_own) {
                        (PConv::Mix { .. }, _) => false,
                        // An own input is among `order`, judged there.
                        (_, Some(_)) => true,
                        (_, None) => self.covers_below(*from, b),
                    },
                })
    }

    /// [`ANode::covers`] for what the children give.
    fn covers_below(&self, idx: usize, b: &Aabb) -> bool {
        match &self.op {
            Op::Map(m, c) => c.covers(idx, &m.apply_box(b)),
            _ => false,
        }
    }
}
