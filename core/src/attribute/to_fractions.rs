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

use super::prepared::{ANode, Evaluator};
use super::{AttributeKind, FracConv, MixTable};
use crate::material::MaterialId;
use crate::model::{PrepareError, SubPreparer};
use crate::node::Node;

/// A node's scalar -> fractions conversion, ready to evaluate.
pub(crate) struct FractionSource {
    tree: Arc<ANode>,
    index: usize,
    table: Arc<MixTable>,
    /// Dense fraction slots of the first and second material.
    slots: [u16; 2],
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
        slots: [u16; 2],
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
        let (s, outside) = self.table.share(v[0]);
        if outside {
            self.clamped.fetch_add(1, Ordering::Relaxed);
        }
        out[usize::from(self.slots[0])] += 1.0 - s;
        out[usize::from(self.slots[1])] += s;
        true
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
